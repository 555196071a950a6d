"""Build and save the scenes `glassdb blender render` is tested and validated on.

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/make_glassdb_scene.py -- --scene tiny --out tiny.blend [--index DIR]

- `tiny` (the test in tests/cli/blender.rs): 64 × 48, 16 samples, two glass panes
  (`Glass_clear`, pass index 1, in the plane y = 1; `Tinted_bronze`, pass index 5, in the plane
  x = 1.5), a floor, a wall and a box behind the glass, a red box on the camera's side (seen in
  the reflections), a sun and a grey-blue world; the camera moves over frames 1-2.
- `example` (docs/blender.md): 320 × 240, 64 samples, a room (floor, ceiling with a luminous panel,
  walls, a table and a cabinet) with a glazed facade (two `Glass_clear` panes either side of a
  mullion, plane y = 2) and a `Tinted_bronze` side window (plane x = 3), buildings outside,
  the sun shining in and a blue world; the camera moves and turns over frames 1-3.
- `relit` (docs/blender.md, "Light parts"): 160 × 120, 64 samples, a closed room lit only
  through two windows (`Glass_clear` in the plane y = 3, `Tinted_bronze` in the plane x = 3)
  by the sun and a blue world; frame 1 looks into the room from inside, frame 2 at the daylit
  room from outside through both windows.
- `lamps` (docs/blender.md "Lamps in reflections"; the test in tests/cli/blender.rs): 64 × 48,
  32 samples, one frame: a dusk facade, one `Glass_film` pane (pass index 10, a reflective
  bronze film) in the plane y = 1 seen from the street, with what it reflects made of lamps:
  a warm area lamp on the camera's side facing the glass, a low orange sun (8°) behind the
  camera whose glint falls on the pane, and inside the room a bulb (a point lamp the camera
  sees, `visible_camera`) that the glass's reflection must not show; a dim dusk world.

Every coordinate is a multiple of 1/8 (exact in float32 and in text). With `--index DIR` the
saved scene is also rendered once per frame with 1 sample through each pixel centre
(filter width 0.01 px) into DIR/index.000N.exr, whose Material Index pass is Cycles' own
answer to which glass each pixel sees (the test compares it with glassdb's mask); the .blend
file is saved before and is not changed by it. `--facts FILE` writes the glass panes'
corners and the frames as JSON.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402

# name: (rgb, roughness, pass index); glass materials are placeholders the pipeline replaces.
MATERIALS = {
    "Floor": ((0.40, 0.36, 0.30), 0.8, 0),
    "Wall": ((0.20, 0.35, 0.55), 0.9, 0),
    "Box_red": ((0.65, 0.10, 0.08), 0.6, 0),
    "Box_green": ((0.15, 0.50, 0.15), 0.7, 0),
    "Building": ((0.55, 0.52, 0.48), 0.9, 0),
    "Lamp": ((1.0, 0.95, 0.85), 4.0, 0),  # emission colour and strength
    "Plaster": ((0.70, 0.68, 0.64), 0.9, 0),
    "Glass_clear": ((1.0, 1.0, 1.0), 0.0, 1),
    "Tinted_bronze": ((0.55, 0.40, 0.25), 0.0, 5),
    "Glass_film": ((0.60, 0.45, 0.35), 0.0, 10),
}
GLASS_MATERIALS = ("Glass_clear", "Tinted_bronze", "Glass_film")


def box(x0, y0, z0, x1, y1, z1):
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return v, f


def quad(*corners):
    return list(corners), [(0, 1, 2, 3)]


def tiny():
    objects = [
        ("Floor", "Floor", quad((-6.0, -6.0, 0.0), (6.0, -6.0, 0.0), (6.0, 8.0, 0.0), (-6.0, 8.0, 0.0))),
        ("Wall", "Wall", quad((-6.0, 4.0, 0.0), (6.0, 4.0, 0.0), (6.0, 4.0, 3.0), (-6.0, 4.0, 3.0))),
        ("Box_out", "Box_green", box(-0.75, 2.25, 0.0, 0.0, 3.0, 1.25)),
        ("Box_in", "Box_red", box(-1.0, -2.5, 0.0, -0.25, -1.75, 0.75)),
        ("Pane_clear", "Glass_clear", quad((-1.0, 1.0, 0.25), (1.0, 1.0, 0.25), (1.0, 1.0, 1.75), (-1.0, 1.0, 1.75))),
        ("Pane_bronze", "Tinted_bronze", quad((1.5, -1.5, 0.25), (1.5, 0.5, 0.25), (1.5, 0.5, 1.5), (1.5, -1.5, 1.5))),
    ]
    cameras = {1: ((0.0, -4.5, 1.0), (0.25, 1.0, 0.875)), 2: ((0.25, -4.5, 1.0), (0.5, 1.0, 0.875))}
    return objects, cameras, (64, 48), 16, (40.0, 0.0, 30.0)


def example():
    objects = [
        ("Ground", "Floor", quad((-30.0, -30.0, 0.0), (30.0, -30.0, 0.0), (30.0, 40.0, 0.0), (-30.0, 40.0, 0.0))),
        # The room: floor at 0, ceiling at 3, facade at y = 2 (glazed), side wall x = 3 glazed.
        ("Ceiling", "Wall", quad((-4.0, -4.0, 3.0), (-4.0, 2.0, 3.0), (3.0, 2.0, 3.0), (3.0, -4.0, 3.0))),
        ("BackWall", "Wall", quad((-4.0, -4.0, 0.0), (3.0, -4.0, 0.0), (3.0, -4.0, 3.0), (-4.0, -4.0, 3.0))),
        ("LeftWall", "Wall", quad((-4.0, -4.0, 0.0), (-4.0, -4.0, 3.0), (-4.0, 2.0, 3.0), (-4.0, 2.0, 0.0))),
        ("RightWall", "Wall", quad((3.0, -4.0, 0.0), (3.0, -2.5, 0.0), (3.0, -2.5, 3.0), (3.0, -4.0, 3.0))),
        ("SideSill", "Building", box(3.0, -2.5, 0.0, 3.125, 2.0, 0.375)),
        # A luminous ceiling panel (an emissive mesh, which camera rays see too, unlike a
        # Cycles lamp object), so that the room shows in the glass's reflections.
        ("Lamp", "Lamp", quad((-1.75, -2.25, 2.875), (-0.25, -2.25, 2.875), (-0.25, -0.75, 2.875), (-1.75, -0.75, 2.875))),
        ("Table", "Box_red", box(-1.5, -1.5, 0.0, 0.0, -0.5, 0.75)),
        ("Cabinet", "Box_green", box(-3.75, -3.75, 0.0, -3.0, -2.0, 1.5)),
        # Facade mullions and sill (opaque), between the panes.
        ("Sill", "Building", box(-4.0, 2.0, 0.0, 3.0, 2.125, 0.375)),
        ("Mullion", "Building", box(-0.625, 2.0, 0.375, -0.375, 2.125, 3.0)),
        # Outside: buildings across the street.
        ("House_A", "Building", box(-9.0, 9.0, 0.0, -3.0, 14.0, 7.0)),
        ("House_B", "Box_green", box(-1.5, 10.0, 0.0, 4.0, 13.0, 4.5)),
        ("Tower", "Building", box(6.0, 6.0, 0.0, 10.0, 10.0, 12.0)),
    ]
    # Facade panes (y = 2) left and right of the mullion, and the side pane (x = 3).
    for k, (x0, x1) in enumerate(((-4.0, -0.625), (-0.375, 3.0))):
        objects.append(("Facade_%d" % k, "Glass_clear",
                        quad((x0, 2.0, 0.375), (x1, 2.0, 0.375), (x1, 2.0, 3.0), (x0, 2.0, 3.0))))
    objects.append(("Side_pane", "Tinted_bronze",
                    quad((3.0, -2.5, 0.375), (3.0, 2.0, 0.375), (3.0, 2.0, 3.0), (3.0, -2.5, 3.0))))
    cameras = {1: ((-2.5, -3.5, 1.5), (0.5, 2.0, 1.5)),
               2: ((-2.0, -3.5, 1.5), (1.25, 2.0, 1.5)),
               3: ((-1.5, -3.5, 1.5), (2.0, 2.0, 1.5))}
    return objects, cameras, (320, 240), 64, (50.0, 0.0, 200.0)


def relit():
    """A room lit by the sun through two windows of different glass (issue 28's validation of
    the relit swap): frame 1 looks into the room from inside, frame 2 at the daylit room from
    outside, through both windows."""
    objects = [
        ("Ground", "Floor", quad((-20.0, -20.0, 0.0), (20.0, -20.0, 0.0), (20.0, 20.0, 0.0), (-20.0, 20.0, 0.0))),
        ("Ceiling", "Plaster", quad((-3.0, -3.0, 3.0), (-3.0, 3.0, 3.0), (3.0, 3.0, 3.0), (3.0, -3.0, 3.0))),
        ("BackWall", "Plaster", quad((-3.0, -3.0, 0.0), (3.0, -3.0, 0.0), (3.0, -3.0, 3.0), (-3.0, -3.0, 3.0))),
        ("LeftWall", "Plaster", quad((-3.0, -3.0, 0.0), (-3.0, -3.0, 3.0), (-3.0, 3.0, 3.0), (-3.0, 3.0, 0.0))),
        ("Table", "Box_red", box(-1.25, -0.5, 0.0, 0.25, 0.75, 0.75)),
        ("Cabinet", "Box_green", box(-2.75, 1.75, 0.0, -2.0, 2.75, 1.5)),
        ("Tree", "Building", box(6.0, 7.0, 0.0, 7.0, 8.0, 4.0)),
    ]
    # Facade y = 3 with a window x in [-2, 0], z in [0.75, 2.5]; side wall x = 3 with a window
    # y in [-1.5, 1.5], z in [0.75, 2.5].
    for name, corners in (
        ("Front_below", ((-3.0, 3.0, 0.0), (3.0, 3.0, 0.0), (3.0, 3.0, 0.75), (-3.0, 3.0, 0.75))),
        ("Front_above", ((-3.0, 3.0, 2.5), (3.0, 3.0, 2.5), (3.0, 3.0, 3.0), (-3.0, 3.0, 3.0))),
        ("Front_left", ((-3.0, 3.0, 0.75), (-2.0, 3.0, 0.75), (-2.0, 3.0, 2.5), (-3.0, 3.0, 2.5))),
        ("Front_right", ((0.0, 3.0, 0.75), (3.0, 3.0, 0.75), (3.0, 3.0, 2.5), (0.0, 3.0, 2.5))),
        ("Side_below", ((3.0, -3.0, 0.0), (3.0, 3.0, 0.0), (3.0, 3.0, 0.75), (3.0, -3.0, 0.75))),
        ("Side_above", ((3.0, -3.0, 2.5), (3.0, 3.0, 2.5), (3.0, 3.0, 3.0), (3.0, -3.0, 3.0))),
        ("Side_left", ((3.0, -3.0, 0.75), (3.0, -1.5, 0.75), (3.0, -1.5, 2.5), (3.0, -3.0, 2.5))),
        ("Side_right", ((3.0, 1.5, 0.75), (3.0, 3.0, 0.75), (3.0, 3.0, 2.5), (3.0, 1.5, 2.5))),
    ):
        objects.append((name, "Plaster", quad(*corners)))
    objects.append(("Window_front", "Glass_clear",
                    quad((-2.0, 3.0, 0.75), (0.0, 3.0, 0.75), (0.0, 3.0, 2.5), (-2.0, 3.0, 2.5))))
    objects.append(("Window_side", "Tinted_bronze",
                    quad((3.0, -1.5, 0.75), (3.0, 1.5, 0.75), (3.0, 1.5, 2.5), (3.0, -1.5, 2.5))))
    cameras = {1: ((-2.5, -2.5, 1.75), (0.5, 1.5, 0.5)),
               2: ((5.0, 6.5, 1.6), (1.0, 1.5, 1.2))}
    # The sun from +x, +y, 40 degrees up: in through both windows onto the floor.
    return objects, cameras, (160, 120), 64, (50.0, 0.0, 135.0)


def lamps():
    objects = [
        ("Ground", "Floor", quad((-8.0, -8.0, 0.0), (8.0, -8.0, 0.0), (8.0, 8.0, 0.0), (-8.0, 8.0, 0.0))),
        ("BackWall", "Wall", quad((-6.0, 4.0, 0.0), (6.0, 4.0, 0.0), (6.0, 4.0, 3.0), (-6.0, 4.0, 3.0))),
        ("Box_out", "Box_green", box(0.25, 2.25, 0.0, 1.0, 3.0, 1.0)),
        ("Box_in", "Box_red", box(-2.0, -2.5, 0.0, -1.25, -1.75, 0.75)),
        ("Pane_film", "Glass_film", quad((-1.5, 1.0, 0.25), (1.5, 1.0, 0.25), (1.5, 1.0, 2.0), (-1.5, 1.0, 2.0))),
    ]
    cameras = {1: ((0.0, -4.5, 1.0), (0.0, 1.0, 1.125))}
    return objects, cameras, (64, 48), 32, (0.0, 0.0, 0.0)


def add_lamps(scene):
    """The `lamps` scene's lights: the sun low behind the camera (its glint on the pane at
    (-0.5, 1, 1.6), where the camera ray towards it reflects), a warm area lamp facing the glass
    on the camera's side (its image at about (0.52, 1, 1.52)), a bulb inside the room."""
    from mathutils import Vector
    sun = scene.objects["Sun"]
    sun.data.angle = math.radians(8.0)
    sun.data.energy = 2.0
    sun.data.color = (1.0, 0.55, 0.3)
    # A sun light shines along its local -Z: +Z points at the sun, the mirror image across
    # y = 1 of the camera's ray (-0.5, 5.5, 0.6) to the glint.
    sun.rotation_euler = Vector((-0.5, -5.5, 0.6)).to_track_quat("Z", "Y").to_euler()
    area = bpy.data.lights.new("Area", "AREA")
    area.size = 0.75
    area.energy = 30.0
    area.color = (1.0, 0.8, 0.6)
    ob = bpy.data.objects.new("Area", area)
    ob.location = (0.75, -1.5, 1.75)
    ob.rotation_euler = (math.radians(90.0), 0.0, 0.0)  # emits along +y, at the glass
    scene.collection.objects.link(ob)
    bulb = bpy.data.lights.new("Bulb", "POINT")
    bulb.shadow_soft_size = 0.125
    bulb.energy = 10.0
    ob = bpy.data.objects.new("Bulb", bulb)
    ob.location = (-0.75, 2.5, 1.25)
    ob.visible_camera = True
    scene.collection.objects.link(ob)
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.07, 0.12, 1.0)


def material(name):
    rgb, rough, index = MATERIALS[name]
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.pass_index = index
    nt = mat.node_tree
    if name == "Lamp":
        emit = nt.nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = rgb + (1.0,)
        emit.inputs["Strength"].default_value = rough
        nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        return mat
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = rgb + (1.0,)
    bsdf.inputs["Roughness"].default_value = rough
    if name in GLASS_MATERIALS:
        bsdf.inputs["Transmission" if "Transmission" in bsdf.inputs else "Transmission Weight"].default_value = 1.0
    return mat


def build(kind):
    objects, cameras, (w, h), samples, sun_rot = {"tiny": tiny, "example": example, "relit": relit, "lamps": lamps}[kind]()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    mats = {}
    for name, mat_name, (verts, faces) in objects:
        mesh = bpy.data.meshes.new(name)
        mesh.from_pydata(verts, [], faces)
        mesh.update()
        if mat_name not in mats:
            mats[mat_name] = material(mat_name)
        mesh.materials.append(mats[mat_name])
        ob = bpy.data.objects.new(name, mesh)
        scene.collection.objects.link(ob)
    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy = 3.0
    sun_data.angle = math.radians(1.0)
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = tuple(math.radians(a) for a in sun_rot)
    scene.collection.objects.link(sun)
    fixture_scene.plain_world(scene, (0.35, 0.45, 0.65))
    cam = fixture_scene.scene_camera(scene, 24.0)
    from mathutils import Vector
    for frame, (eye, target) in cameras.items():
        cam.location = eye
        direction = Vector(target) - Vector(eye)
        cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
        cam.keyframe_insert("location", frame=frame)
        cam.keyframe_insert("rotation_euler", frame=frame)
    scene.frame_start, scene.frame_end = min(cameras), max(cameras)
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, 100
    scene.cycles.samples = samples
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.seed = 0
    scene.view_settings.view_transform = "Standard"
    if kind == "lamps":
        add_lamps(scene)
    return objects, cameras


def render_index(scene, out_dir):
    """Material Index through each pixel centre, per frame."""
    os.makedirs(out_dir, exist_ok=True)
    vl = scene.view_layers[0]
    vl.use_pass_material_index = True
    scene.cycles.samples = 1
    scene.cycles.filter_width = 0.01
    fixture_scene.set_exr_format(scene.render.image_settings, multilayer=True, half=False)
    for frame in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(frame)
        scene.render.filepath = os.path.join(out_dir, "index.%04d.exr" % frame)
        scene.render.use_file_extension = False
        bpy.ops.render.render(write_still=True)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    opts = dict(zip(argv[::2], argv[1::2]))
    kind = opts.get("--scene", "tiny")
    out = opts.get("--out") or sys.exit("--out FILE.blend is required")
    objects, cameras = build(kind)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))
    if "--facts" in opts:
        facts = {"panes": {name: {"material": m, "corners": verts}
                           for name, m, (verts, _f) in objects if m in GLASS_MATERIALS},
                 "frames": sorted(cameras),
                 "cameras": {str(f): {"eye": e, "target": t} for f, (e, t) in cameras.items()}}
        with open(opts["--facts"], "w") as fh:
            json.dump(facts, fh, indent=1)
    if "--index" in opts:
        render_index(bpy.context.scene, opts["--index"])


main()
