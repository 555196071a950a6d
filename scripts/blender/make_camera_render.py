#!/usr/bin/env python3
"""A Blender render to check `glassdb mask` against, camera included (docs/scene.md).

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/make_camera_render.py -- --out fixtures/blender/camera_render

Builds a small scene procedurally (no .blend file): a glass pane (material `Glass`, pass index
1) and a box in front of it (material `Wall`, pass index 2), seen by a camera keyframed over two
frames with everything an architect may set: object scale, Focal Length, Sensor Fit Vertical
with a custom sensor height, Shift X / Y and pixel Aspect X 1.2. Writes into --out:

- `scene.obj`, `scene.mtl`: the scene, exported with Blender's default OBJ axes (Y up);
- `camera.json`: the camera of both frames, by scripts/blender/export_camera.py;
- `index_ma.json`: Cycles' Material Index pass of each frame (one sample per pixel at its
  centre: box filter of width 0.01), one string of digits per image row, top row first.

tests/cli/cameras.rs renders the mask with `glassdb mask` and compares the glass pixels.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import runpy
import sys

import bpy


def out_dir(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) != 2 or args[0] != "--out":
        sys.exit("usage: blender -b -P make_camera_render.py -- --out DIR")
    return os.path.abspath(args[1])


def build_scene(scene):
    for ob in list(bpy.data.objects):
        if ob.type != "CAMERA":
            bpy.data.objects.remove(ob)
    # The pane stands in Blender's XZ plane (Z up) at y = 0.
    bpy.ops.mesh.primitive_plane_add(size=2, location=(0, 0, 1), rotation=(math.radians(90), 0, 0))
    glass = bpy.data.materials.new("Glass")
    glass.pass_index = 1
    bpy.context.object.data.materials.append(glass)
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.5, -1.0, 0.6))
    wall = bpy.data.materials.new("Wall")
    wall.pass_index = 2
    bpy.context.object.data.materials.append(wall)

    cam_ob = scene.camera
    cam = cam_ob.data
    cam_ob.location = (1.5, -6, 1.4)
    cam_ob.rotation_euler = (math.radians(88), 0, math.radians(12))
    cam_ob.scale = (1.5, 1.5, 1.5)
    cam_ob.keyframe_insert("location", frame=1)
    cam_ob.location = (-1.0, -5, 1.2)
    cam_ob.keyframe_insert("location", frame=2)
    cam.lens = 40
    cam.sensor_fit = "VERTICAL"
    cam.sensor_height = 20
    cam.shift_x = 0.1
    cam.shift_y = 0.15
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 96, 64, 100
    r.pixel_aspect_x, r.pixel_aspect_y = 1.2, 1.0
    scene.frame_start, scene.frame_end = 1, 2


def main():
    out = out_dir(sys.argv)
    os.makedirs(out, exist_ok=True)
    scene = bpy.context.scene
    build_scene(scene)
    bpy.ops.wm.obj_export(filepath=os.path.join(out, "scene.obj"), export_materials=True)
    here = os.path.dirname(os.path.abspath(__file__))
    sys.argv = ["export_camera.py", "--", "--out", os.path.join(out, "camera.json")]
    runpy.run_path(os.path.join(here, "export_camera.py"))
    frames = {}
    for f in (scene.frame_start, scene.frame_end):
        scene.frame_set(f)
        exr = os.path.join(out, f"index_{f}.exr")
        frames[str(f)] = render_rows(scene, exr)
        os.remove(exr)
    doc = {
        "blender": bpy.app.version_string,
        "made_by": "scripts/blender/make_camera_render.py",
        "pass": "Material Index (IndexMA), one digit per pixel, rows top to bottom",
        "frames": frames,
    }
    with open(os.path.join(out, "index_ma.json"), "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print(f"wrote {out}")


def render_rows(scene, exr):
    """Renders the current frame; returns its Material Index pass as digit rows, top first."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 1
    scene.cycles.seed = 0
    scene.cycles.use_denoising = False
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 0.01
    scene.view_layers[0].use_pass_material_index = True
    # The pass is routed to the Composite output, written as a float EXR (no view transform:
    # EXR output is scene-linear) and read back.
    scene.view_settings.view_transform = "Standard"
    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    layers = tree.nodes.new("CompositorNodeRLayers")
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(layers.outputs["IndexMA"], composite.inputs["Image"])
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    scene.render.filepath = exr
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(exr)
    w, h = image.size
    px = list(image.pixels)  # RGBA floats, bottom row first
    bpy.data.images.remove(image)
    rows = []
    for y in reversed(range(h)):
        rows.append("".join(str(round(px[4 * (y * w + x)])) for x in range(w)))
    return rows


main()
