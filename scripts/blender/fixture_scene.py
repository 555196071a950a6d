"""What the Blender scripts of this folder share: their command lines, and the parts of a
Blender scene each of them builds the same way (materials, nodes and AOVs on any Blender
version, the grey world, the EXR output format).

Imported by make_mask_fixtures.py, make_pass_fixtures.py, make_reflection_passes.py,
make_glassdb_scene.py and render_mask_aovs.py (each puts this folder on `sys.path`).
Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import os
import sys


def script_args(argv):
    """Arguments after `--` (inside blender) or all of argv[1:] (plain Python / bpy module)."""
    if "--" in argv:
        return argv[argv.index("--") + 1:]
    return argv[1:]


def parse_options(argv, script, doc, opts, paths=(), values=(), flags=None):
    """The options of a fixture script into `opts` (its defaults): `--NAME DIR` for NAME in
    `paths` (made absolute), `--NAME VALUE` for NAME in `values` (stored under NAME with `_`
    for `-`), `flags` {"--flag": (key, value)}; `-h` prints `doc`; anything else exits with a
    message naming `script`."""
    argv = script_args(argv)
    flags = flags or {}
    i = 0
    while i < len(argv):
        a = argv[i]
        name = a[2:] if a.startswith("--") else None
        if name in paths + values and i + 1 < len(argv):
            value = argv[i + 1]
            opts[name.replace("-", "_")] = os.path.abspath(value) if name in paths else value
            i += 2
            continue
        if a in flags:
            key, value = flags[a]
            opts[key] = value
        elif a in ("-h", "--help"):
            print(doc)
            sys.exit(0)
        else:
            sys.exit("%s: unknown argument %r" % (script, a))
        i += 1
    return opts


def set_use_nodes(idblock):
    """Gives a material or world its node tree (Blender 5.0 deprecates `use_nodes`: new
    materials and worlds always have one)."""
    import bpy

    if tuple(bpy.app.version) < (5, 0, 0):
        idblock.use_nodes = True
    if idblock.node_tree is None:
        sys.exit("%s has no node tree" % idblock.name)


def new_material(name, pass_index):
    """A material `name` with pass index `pass_index` and an emptied node tree holding only its
    Material Output (at (300, 0)); returns (material, node tree, output node)."""
    import bpy

    mat = bpy.data.materials.new(name)
    set_use_nodes(mat)
    mat.pass_index = pass_index
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    return mat, nt, out


def new_node(nt, kind, location, operation=None):
    """A node of type `kind` (`ShaderNodeMath`, …) in node tree `nt` at `location`, with its
    `operation` set when one is given."""
    node = nt.nodes.new(kind)
    if operation is not None:
        node.operation = operation
    node.location = location
    return node


def aov_output(nt, name, location):
    """An AOV Output node of node tree `nt` writing the AOV `name`."""
    aov = nt.nodes.new("ShaderNodeOutputAOV")
    aov.location = location
    if "aov_name" in aov.bl_rna.properties:
        aov.aov_name = name
    else:  # Blender 3.x: the node's `name` property is the AOV name
        aov.name = name
    return aov


def facing_aov(nt, at=(-200, -300)):
    """The AOV `facing` = |N . I| from a Geometry node, its output node at `at`."""
    x, y = at
    geo = new_node(nt, "ShaderNodeNewGeometry", (x - 600, y))
    dot = new_node(nt, "ShaderNodeVectorMath", (x - 400, y), "DOT_PRODUCT")
    ab = new_node(nt, "ShaderNodeMath", (x - 200, y), "ABSOLUTE")
    nt.links.new(geo.outputs["Normal"], dot.inputs[0])
    nt.links.new(geo.outputs["Incoming"], dot.inputs[1])
    nt.links.new(dot.outputs["Value"], ab.inputs[0])
    nt.links.new(ab.outputs["Value"], aov_output(nt, "facing", at).inputs["Value"])


def grey_world(scene):
    """A uniform grey world (0.5, strength 1) as the scene's; returns its Background node."""
    import bpy

    world = bpy.data.worlds.new("World")
    world.color = (0.5, 0.5, 0.5)
    set_use_nodes(world)
    bg = world.node_tree.nodes.get("Background")
    if bg is None:
        nt = world.node_tree
        nt.nodes.clear()
        bg = nt.nodes.new("ShaderNodeBackground")
        wo = nt.nodes.new("ShaderNodeOutputWorld")
        nt.links.new(bg.outputs["Background"], wo.inputs["Surface"])
    bg.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    return bg


def plain_world(scene, rgb):
    """A world of the one background colour `rgb` as the scene's."""
    import bpy

    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*rgb, 1.0)
    scene.world = world


def scene_camera(scene, lens_mm):
    """A camera of focal length `lens_mm` as the scene's camera; returns its object."""
    import bpy

    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = lens_mm
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def set_exr_format(im, multilayer=True, half=True):
    """RGBA OpenEXR, ZIP, half or float, multi-layer or one layer, on image settings `im`."""
    if hasattr(im, "media_type"):  # Blender 5.0: media type first, then the format
        im.media_type = "MULTI_LAYER_IMAGE" if multilayer else "IMAGE"
    im.file_format = "OPEN_EXR_MULTILAYER" if multilayer else "OPEN_EXR"
    im.color_mode = "RGBA"
    im.color_depth = "16" if half else "32"
    im.exr_codec = "ZIP"


def fixed_cycles(scene):
    """Cycles on the CPU rendering the same pixels every time: seed 0, no denoising, no
    adaptive sampling, two threads, no compositing or sequencer, resolution at 100 %, file
    extensions added. Returns the render settings."""
    r = scene.render
    r.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.seed = 0
    scene.cycles.use_animated_seed = False
    scene.cycles.use_denoising = False
    if hasattr(scene.cycles, "use_adaptive_sampling"):
        scene.cycles.use_adaptive_sampling = False
    r.resolution_percentage = 100
    r.threads_mode = "FIXED"
    r.threads = 2
    r.use_compositing = False
    r.use_sequencer = False
    r.use_file_extension = True
    vl = scene.view_layers[0]
    if hasattr(vl, "cycles"):
        vl.cycles.use_denoising = False
    return r


def interior(mask, radius):
    """The pixels of the boolean image `mask` whose whole (2·radius + 1)² neighbourhood is in
    `mask` (outside the image counts as outside the mask)."""
    import numpy as np

    pad = np.pad(mask, radius, constant_values=False)
    inner = np.ones_like(mask)
    for dy in range(2 * radius + 1):
        for dx in range(2 * radius + 1):
            inner &= pad[dy:dy + mask.shape[0], dx:dx + mask.shape[1]]
    return inner


def write_json(path, doc):
    """Writes `doc` to `path` as JSON indented by one space, with a final newline, and says so."""
    with open(path, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print("wrote", path)


def render_still(scene, directory, name):
    """Renders the scene's current frame to `directory/name` and returns the file's size.
    Blender decides whether a still's name gets a frame number (versions differ), so it renders
    to a scratch stem and moves the one file written there."""
    import bpy

    stem = "_render_" + name.split(".")[0]
    for old in os.listdir(directory):
        if old.startswith(stem):
            os.remove(os.path.join(directory, old))
    scene.render.filepath = os.path.join(directory, stem)
    bpy.ops.render.render(write_still=True)
    written = [f for f in os.listdir(directory) if f.startswith(stem)]
    if len(written) != 1:
        sys.exit("render of %s wrote %r" % (name, written))
    path = os.path.join(directory, name)
    os.replace(os.path.join(directory, written[0]), path)
    print("wrote", path, os.path.getsize(path))
    return os.path.getsize(path)
