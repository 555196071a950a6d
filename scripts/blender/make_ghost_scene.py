"""The double image (issue 27): a window of a double unit with bright bars in front of it, and
the same window as two real panes, for `glassdb blender render`'s pane-group passes and their
validation against Cycles (tests/cli/blender_ghosts.rs, docs/blender.md "Units: the double
image").

    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/make_ghost_scene.py -- --panes unit --out unit.blend \
        [--facts facts.json] [--size 128x96] [--samples 32]

- `--panes unit`: one face, material `Unit` (glass id 11 of the bundled registry, clear 6 |
  12.7 air | clear 6), in the plane y = 0 with its normal +y (outdoors, towards the camera):
  the unit's surface #1, as docs/scene.md's convention has it.
- `--panes two`: the same window as two real panes, material `Pane` (glass id 2, clear 6 mm),
  at the unit's pane mid-planes `--depths-mm` behind the face (default 2.8575 and 21.2725 mm,
  the registry's depths of unit 11): the reference, where Cycles makes both reflections and
  the interreflections between the panes itself.

Both: a 1.2 × 1.0 m window, two emissive vertical bars (warm and cool, 4 cm wide) 0.5 and
0.8 m in front of the glass whose reflections the camera sees in it, a dim room behind it (a
grey back wall 1.5 m in), a dim grey world; the camera 2.5 m from the window's centre at
θ = 50° from its normal, 100 mm lens. `--facts FILE` writes the bars, the window, the camera and,
per pane depth, where Blender's own projection puts each bar's mirror image (the centre of the
bar mirrored about the plane `depth` behind the face), as fractions of the frame (u right,
v up): the ghost offset's mirror-geometry prediction.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import sys

import bpy
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
opts = dict(zip(argv[::2], argv[1::2]))
panes = opts.get("--panes", "unit")
out = opts.get("--out") or sys.exit("--out FILE.blend is required")
if panes not in ("unit", "two"):
    sys.exit("--panes unit|two")
width, _, height = opts.get("--size", "128x96").partition("x")
depths = [float(d) * 1e-3 for d in opts.get("--depths-mm", "2.8575,21.2725").split(",")]

# The window: x in [-0.6, 0.6], z in [0.7, 1.7], normal +y.
WINDOW = (-0.6, 0.6, 0.7, 1.7)
CENTRE = Vector((0.0, 0.0, 1.2))
# Bars: (name, x on the glass where the camera sees its reflection, distance in front of the
# glass, rgb, emission strength); 4 cm square, z in [0.9, 1.5].
BAR_SPECS = [("Bar_warm", -0.15, 0.5, (1.0, 0.55, 0.25), 12.0),
             ("Bar_cool", 0.2, 0.8, (0.3, 0.6, 1.0), 12.0)]
BAR_HALF = 0.02
BAR_Z = (0.9, 1.5)
THETA_DEG = 50.0
DISTANCE = 2.5
EYE = CENTRE + Vector((DISTANCE * math.sin(math.radians(THETA_DEG)),
                       DISTANCE * math.cos(math.radians(THETA_DEG)), 0.0))
# Each bar's x: its mirror image (x, -y) seen from the eye through the glass at x_glass.
BARS = [(name, EYE.x + (x_glass - EYE.x) * (EYE.y + y) / EYE.y, y, rgb, strength)
        for name, x_glass, y, rgb, strength in BAR_SPECS]

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def mesh_object(name, verts, faces, mat):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    mesh.materials.append(mat)
    ob = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(ob)
    return ob


def diffuse(name, rgb):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = rgb + (1.0,)
    bsdf.inputs["Roughness"].default_value = 0.9
    return mat


def emissive(name, rgb, strength):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    emit = nt.nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = rgb + (1.0,)
    emit.inputs["Strength"].default_value = strength
    nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat


def glass(name):
    """A placeholder the pipeline replaces by the registry's thin pane."""
    mat = diffuse(name, (1.0, 1.0, 1.0))
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Transmission" if "Transmission" in bsdf.inputs else "Transmission Weight"].default_value = 1.0
    bsdf.inputs["Roughness"].default_value = 0.0
    return mat


def window_quad(y):
    """The window at y, wound so that its normal is +y."""
    x0, x1, z0, z1 = WINDOW
    return [(x0, y, z0), (x0, y, z1), (x1, y, z1), (x1, y, z0)], [(0, 1, 2, 3)]


def box(x0, y0, z0, x1, y1, z1):
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return v, f


if panes == "unit":
    mesh_object("Window", *window_quad(0.0), glass("Unit"))
else:
    pane = glass("Pane")
    for k, d in enumerate(depths):
        mesh_object("Pane_%d" % k, *window_quad(-d), pane)
room = diffuse("Room", (0.5, 0.5, 0.5))
mesh_object("Back_wall", [(-3.0, -1.5, 0.0), (3.0, -1.5, 0.0), (3.0, -1.5, 3.0), (-3.0, -1.5, 3.0)],
            [(0, 1, 2, 3)], room)
for name, x, y, rgb, strength in BARS:
    mesh_object(name, *box(x - BAR_HALF, y - BAR_HALF, BAR_Z[0], x + BAR_HALF, y + BAR_HALF, BAR_Z[1]),
                emissive(name, rgb, strength))

fixture_scene.plain_world(scene, (0.08, 0.08, 0.08))

cam = fixture_scene.scene_camera(scene, 100.0)
cam.location = EYE
cam.rotation_euler = (CENTRE - cam.location).to_track_quat("-Z", "Y").to_euler()

r = scene.render
r.engine = "CYCLES"
r.resolution_x, r.resolution_y, r.resolution_percentage = int(width), int(height), 100
scene.frame_start = scene.frame_end = 1
scene.cycles.samples = int(opts.get("--samples", "32"))
scene.cycles.use_adaptive_sampling = False
scene.cycles.use_denoising = False
scene.cycles.seed = 0
# Enough bounces for the light between the two panes (reflected, passed, reflected again).
scene.cycles.max_bounces = 16
scene.cycles.glossy_bounces = 8
scene.cycles.transparent_max_bounces = 16
scene.view_settings.view_transform = "Standard"
bpy.context.view_layer.update()

bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))

if "--facts" in opts:
    images = {}
    for d in [0.0] + depths:
        per_bar = {}
        for name, x, y, _rgb, _s in BARS:
            mirrored = Vector((x, -2.0 * d - y, 0.5 * (BAR_Z[0] + BAR_Z[1])))
            uv = world_to_camera_view(scene, cam, mirrored)
            per_bar[name] = [uv.x, uv.y]
        images["%.4f" % (d * 1e3)] = per_bar
    facts = {
        "panes": panes,
        "depths_mm": [d * 1e3 for d in depths],
        "window": WINDOW,
        "bars": {name: {"x": x, "y": y, "z": BAR_Z, "half_width": BAR_HALF}
                 for name, x, y, _rgb, _s in BARS},
        "camera": {"location": list(cam.location), "theta_deg": THETA_DEG, "lens_mm": cam.data.lens},
        "size": [r.resolution_x, r.resolution_y],
        # Per mirror-plane depth (mm behind the face): each bar's mirror image (u right, v up).
        "mirror_images_uv": images,
    }
    with open(opts["--facts"], "w") as fh:
        json.dump(facts, fh, indent=1)
        fh.write("\n")
