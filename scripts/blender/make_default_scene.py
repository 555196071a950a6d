"""Scenes as people leave them, for tests/cli/blender.rs: Blender's factory settings, Cycles
chosen, a glass window added, saved. Nothing the pipeline needs is set by hand: the scene keeps
Cycles' defaults (denoising on, adaptive sampling, 4096 samples, 1920 × 1080), which the tests
override only through `glassdb blender render`'s own flags.

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/make_default_scene.py -- --scene defaults --out scene.blend

- `defaults`: the factory scene (cube, light, camera), Cycles, a 2 × 2 m window (material
  `Glass`, Principled BSDF with transmission 1) between the camera and the cube.
- `animated`: the same window sliding along itself (a sliding door) over frames 1-3, the cube
  moving across the view, the light moving, and a red box on the camera's side that moves
  (seen in the window's reflection), and a post in front of the window hidden from render in
  frame 1 and shown from frame 2 on; the camera is still. `--facts FILE` writes the frames.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import sys

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
opts = dict(zip(argv[::2], argv[1::2]))
kind = opts.get("--scene", "defaults")
out = opts.get("--out") or sys.exit("--out FILE.blend is required")

bpy.ops.wm.read_factory_settings(use_empty=False)
scene = bpy.context.scene
scene.render.engine = "CYCLES"
assert scene.cycles.use_denoising, "Blender's default scene denoises"
camera = scene.objects["Camera"]
cube = scene.objects["Cube"]
light = scene.objects["Light"]

# The window: a plane facing the camera, halfway from the cube to the camera.
eye = Vector(camera.location)
centre = eye * 0.45
bpy.ops.mesh.primitive_plane_add(size=2.0, location=centre)
window = bpy.context.active_object
window.name = "Window"
window.rotation_euler = (eye - centre).to_track_quat("Z", "Y").to_euler()
glass = bpy.data.materials.new("Glass")
glass.use_nodes = True
bsdf = glass.node_tree.nodes["Principled BSDF"]
bsdf.inputs["Transmission" if "Transmission" in bsdf.inputs else "Transmission Weight"].default_value = 1.0
bsdf.inputs["Roughness"].default_value = 0.0
window.data.materials.append(glass)

frames = [scene.frame_current]
if kind == "animated":
    frames = [1, 2, 3]
    scene.frame_start, scene.frame_end = 1, 3
    bpy.context.view_layer.update()
    # The window slides along its own x axis (a sliding door): the same plane every frame.
    along = window.matrix_world.to_3x3() @ Vector((1.0, 0.0, 0.0))
    red = bpy.data.materials.new("Red")
    red.use_nodes = True
    red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.7, 0.1, 0.08, 1.0)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=eye * 1.3 + Vector((0.0, 0.0, -2.0)))
    box = bpy.context.active_object
    box.name = "Box_behind_camera"
    box.data.materials.append(red)
    start = {ob.name: Vector(ob.location) for ob in (window, cube, light, box)}
    for f in frames:
        k = f - 1
        window.location = start["Window"] + along * (0.4 * k)
        cube.location = start["Cube"] + Vector((0.0, 1.0 * k, 0.0))
        light.location = start["Light"] + Vector((-2.0 * k, 0.0, 0.0))
        box.location = start["Box_behind_camera"] + Vector((1.0 * k, 0.0, 0.0))
        for ob in (window, cube, light, box):
            ob.keyframe_insert("location", frame=f)
    # A post between the camera and the window, hidden from render in frame 1 and shown from
    # frame 2 on (a car driving in): it hides part of the glass only in frames 2-3.
    door = centre + along * 0.4
    bpy.ops.mesh.primitive_cube_add(size=0.2, location=eye + (door - eye) * 0.5)
    post = bpy.context.active_object
    post.name = "Post"
    post.data.materials.append(red)
    for f, hidden in ((1, True), (2, False)):
        post.hide_render = hidden
        post.keyframe_insert("hide_render", frame=f)
    scene.frame_set(1)

bpy.ops.wm.save_as_mainfile(filepath=out)
if "--facts" in opts:
    with open(opts["--facts"], "w") as fh:
        json.dump({"frames": frames}, fh)
