"""glassdb's Blender side: export a scene for `glassdb blender render`, render its passes, and
a panel that runs the whole pipeline from Blender (docs/blender.md).

One file, used two ways:

- by the `glassdb` binary, which embeds it and runs it headless:

      blender -b scene.blend --python-exit-code 1 -P glassdb_blender.py -- export --out DIR \
          [--frames 1,2,3] [--resolution WxH]
      blender -b scene.blend --python-exit-code 1 -P glassdb_blender.py -- render --job JOB.json

  `export` writes the evaluated scene in world coordinates (Blender's Z-up axes) as
  DIR/scene.obj + DIR/scene.mtl (one `usemtl` per material slot, named as in Blender), the
  scene camera of every frame as DIR/camera.json (glassdb's camera JSON, docs/scene.md, in the
  `frames` form) and DIR/export.json (Blender's version, the frames, the materials).
  `render` renders what JOB.json (written by glassdb) asks: per frame the transmission pass and
  one reflection pass per glass plane, as single-layer RGBA EXRs.

- as an add-on (Edit > Preferences > Add-ons > Install… this file): Render Properties >
  glassdb holds the same settings as the command line and a button that saves the file and
  runs `glassdb blender render` on it.

How the passes are made:

- Glass materials (the ones glassdb matched to a registry id) become a thin pane: Glossy
  (roughness 0, colour r(θ)) + Transparent (colour t(θ)), r and t per channel from the
  registry's curves through a 32-stop Color Ramp over |N·I| (front or back reflectance by the
  Backfacing output), so sunlight through the window is filtered and reflected by the glass;
  except for camera rays where glassdb adds the glass itself: a clear Transparent BSDF on the
  first glass the camera meets (transmission pass) or on and behind the mirror's plane
  (reflection pass), so that glass seen through glass or in a mirror stays a pane.
- Reflection pass of plane n·x + d = 0: a copy of the camera with matrix R @ matrix_world (R the
  reflection about the plane, determinant −1); every other material mixes in a Transparent BSDF
  where Is Camera Ray and the shading point lies on the far side of the plane from the real
  camera; a render border of the plane's screen rectangle, cropped. Lamps (which camera rays
  do not see by default) are made visible to camera rays in it when a glossy ray of the real
  glass could see them from the camera's side of the plane, so that the glass reflects them.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import os
import shlex
import subprocess
import sys

import bpy

bl_info = {
    "name": "glassdb",
    "author": "glassdb",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > glassdb",
    "description": "Physically based glazing by compositing: run `glassdb blender render` on this file",
    "category": "Render",
}

# Node names of what this script adds, so that a second run finds them.
CLIP_PREFIX = "glassdb_clip"
MIRROR_CAMERA = "glassdb_mirror_camera"
# Exporting: object types that have a mesh when evaluated.
MESH_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT"}


def fail(message):
    """Stops with a message glassdb shows; exit code 3 marks an error in the scene itself."""
    sys.stderr.write("glassdb_blender: error: %s\n" % message)
    sys.stderr.flush()
    sys.exit(3)


def parse_cli(argv):
    """(mode, options) from the words after `--`."""
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if not args or args[0] not in ("export", "render"):
        fail("usage: -- export --out DIR [--frames 1,2] [--resolution WxH] | render --job FILE")
    mode, rest = args[0], args[1:]
    opts = {}
    while rest:
        flag = rest.pop(0)
        if not flag.startswith("--") or not rest:
            fail("option %s needs a value" % flag)
        opts[flag[2:]] = rest.pop(0)
    return mode, opts


def set_resolution(scene, resolution):
    """`WxH` at 100 %, or the scene's own when None."""
    if resolution:
        w, _, h = resolution.partition("x")
        scene.render.resolution_x, scene.render.resolution_y = int(w), int(h)
        scene.render.resolution_percentage = 100


def camera_json(scene, to_file=None):
    """The scene camera now, as glassdb's camera JSON in Blender's world axes (or in the axes
    of a file: `to_file` @ matrix_world; scripts/blender/export_camera.py uses this too)."""
    ob = scene.camera
    cam = ob.data
    if cam.type != "PERSP":
        fail("camera %s is %s: glassdb's camera is a perspective (pinhole) one" % (ob.name, cam.type))
    r = scene.render
    matrix = ob.matrix_world if to_file is None else to_file @ ob.matrix_world
    return {
        "matrix_world": [list(row) for row in matrix],
        "focal_length_mm": cam.lens,
        "sensor_width_mm": cam.sensor_width,
        "sensor_height_mm": cam.sensor_height,
        "sensor_fit": cam.sensor_fit.lower(),
        "shift_x": cam.shift_x,
        "shift_y": cam.shift_y,
        "pixel_aspect": r.pixel_aspect_x / r.pixel_aspect_y,
        "width": r.resolution_x * r.resolution_percentage // 100,
        "height": r.resolution_y * r.resolution_percentage // 100,
    }


def exported_objects(scene):
    return [ob for ob in scene.objects if ob.type in MESH_TYPES and not ob.hide_render]


def scene_obj_lines(objects, materials):
    """The OBJ body (vertices in world coordinates, faces by material) of `objects` as
    evaluated now, and each object's own lines by name (to say which moved); adds the
    materials used to `materials`."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    lines = []
    blocks = {}
    base = 1
    for ob in objects:
        ev = ob.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        if mesh is None:
            continue
        m = ev.matrix_world
        block = ["o %s" % ob.name.replace(" ", "_")]
        for v in mesh.vertices:
            p = m @ v.co
            block.append("v %r %r %r" % (p.x, p.y, p.z))
        names = [s.material.name if s.material else None for s in ev.material_slots]
        current = "unset"
        for poly in mesh.polygons:
            name = names[poly.material_index] if poly.material_index < len(names) else None
            name = name or "glassdb_no_material"
            if name != current:
                block.append("usemtl %s" % name)
                materials.add(name)
                current = name
            block.append("f " + " ".join(str(base + i) for i in poly.vertices))
        base += len(mesh.vertices)
        ev.to_mesh_clear()
        lines += block
        blocks[ob.name] = [l for l in block if l.startswith("v ")]
    return lines, blocks


def export(opts):
    out = opts.get("out") or fail("export needs --out DIR")
    scene = bpy.context.scene
    if scene.camera is None:
        fail("the scene has no camera")
    set_resolution(scene, opts.get("resolution"))
    if "frames" in opts:
        frames = [int(f) for f in opts["frames"].split(",")]
    else:
        frames = list(range(scene.frame_start, scene.frame_end + 1))
    cameras = {}
    # Every object rendered in some frame (one hidden at first and shown later too), by name
    # in the order first seen.
    all_objects = {}
    # Every frame's geometry; a frame whose objects differ from the first frame's (a moving
    # object, a sliding door, a deforming mesh) gets its own OBJ, scene.NNNN.obj.
    first_lines = None
    moving = {}
    materials = set()
    os.makedirs(out, exist_ok=True)
    for f in frames:
        scene.frame_set(f)
        cameras[str(f)] = camera_json(scene)
        # Visibility is per frame: an object shown from frame 2 on (a car driving in) is in
        # that frame's scene and mask, one hidden from then on is not.
        objects = exported_objects(scene)
        all_objects.update((ob.name, ob) for ob in objects if ob.name not in all_objects)
        lines, names = scene_obj_lines(objects, materials)
        if first_lines is None:
            first_lines, first_names = lines, names
            name = "scene.obj"
        elif lines == first_lines:
            continue
        else:
            name = "scene.%04d.obj" % f
            moved = [n for n, block in names.items() if first_names.get(n) != block]
            moved += [n for n in first_names if n not in names]
            moving[str(f)] = {"obj": name, "objects": moved}
        header = ["# glassdb_blender.py export of %s, frame %d, world coordinates (Z up)"
                  % (bpy.data.filepath, f), "mtllib scene.mtl"]
        with open(os.path.join(out, name), "w") as fh:
            fh.write("\n".join(header + lines) + "\n")
    scene.frame_set(frames[0])
    for name in materials:
        if any(c.isspace() for c in name):
            fail("material %r has a space in its name, which an OBJ file cannot hold" % name)
    with open(os.path.join(out, "scene.mtl"), "w") as fh:
        for name in sorted(materials):
            fh.write("newmtl %s\nKd 0.8 0.8 0.8\n\n" % name)
    with open(os.path.join(out, "camera.json"), "w") as fh:
        json.dump({"frames": cameras}, fh, indent=1)
        fh.write("\n")
    info = {
        "blender": bpy.app.version_string,
        # Settings the passes override (render's honest_passes), as the scene has them.
        "denoising": bool(scene.cycles.use_denoising),
        "motion_blur": bool(scene.render.use_motion_blur),
        "blender_version": list(bpy.app.version),
        "file": bpy.data.filepath,
        "frames": frames,
        "materials": sorted(materials),
        "objects": list(all_objects),
        # Frames whose geometry differs from the first frame's: their OBJ and what moved.
        "moving": moving,
        # The scene's own light groups (issue 29): glassdb asks each one's spectrum.
        "light_groups": scene_light_groups(scene),
    }
    with open(os.path.join(out, "export.json"), "w") as fh:
        json.dump(info, fh, indent=1)
        fh.write("\n")
    print("glassdb_blender: exported %d objects, %d frames" % (len(objects), len(frames)))
    for f, m in moving.items():
        print("glassdb_blender: frame %s: %s moved (%s)" % (f, ", ".join(m["objects"]), m["obj"]))


LIGHT_PROPERTY = "glassdb_light"


def emits(ob):
    """Whether a rendered object gives light: a lamp of non-zero power, or a mesh whose
    material has an Emission shader or a Principled BSDF with emission (a fair guess: a
    material that emits through another node is not seen)."""
    if ob.type == "LIGHT":
        return ob.data.energy > 0.0
    for slot in getattr(ob, "material_slots", []):
        mat = slot.material
        if mat is None or not mat.use_nodes or mat.node_tree is None:
            continue
        for node in mat.node_tree.nodes:
            if node.bl_idname == "ShaderNodeEmission":
                strength = node.inputs["Strength"]
                if strength.is_linked or strength.default_value > 0.0:
                    return True
            elif node.bl_idname == "ShaderNodeBsdfPrincipled":
                strength = node.inputs.get("Emission Strength")
                colour = node.inputs.get("Emission") or node.inputs.get("Emission Color")
                if strength is None or colour is None:
                    continue
                bright = colour.is_linked or any(c > 0.0 for c in colour.default_value[:3])
                if bright and (strength.is_linked or strength.default_value > 0.0):
                    return True
    return False


def world_emits(world):
    """Whether the world gives light: any Background node not set to zero strength or black."""
    if world is None:
        return False
    if not world.use_nodes or world.node_tree is None:
        return any(c > 0.0 for c in world.color)
    for node in world.node_tree.nodes:
        if node.bl_idname == "ShaderNodeBackground":
            strength, colour = node.inputs["Strength"], node.inputs["Color"]
            if (strength.is_linked or strength.default_value > 0.0) and (
                    colour.is_linked or any(c > 0.0 for c in colour.default_value[:3])):
                return True
    return False


def light_property(holder):
    """A `glassdb_light` custom property (an illuminant's name, or an SPD CSV's path: absolute
    or `//` relative to the .blend file), or None."""
    value = holder.get(LIGHT_PROPERTY) if holder is not None else None
    if value is None:
        return None
    value = str(value).strip()
    return bpy.path.abspath(value) if value.startswith("//") else value


def scene_light_groups(scene):
    """The scene's own Cycles light groups (the view layer's order first): the groups its
    rendered objects and its world name, the emitters in none, and the `glassdb_light`
    properties of each group's objects, lamps and world (crates/blender/src/scene_lights.rs
    reads this)."""
    vl = bpy.context.view_layer
    order = [lg.name for lg in vl.lightgroups]
    used, ungrouped, properties = set(), [], []
    for ob in scene.objects:
        if ob.hide_render:
            continue
        group = ob.lightgroup
        what = "lamp %s" % ob.name if ob.type == "LIGHT" else "object %s" % ob.name
        if group:
            used.add(group)
            for holder in (ob, ob.data if ob.type == "LIGHT" else None):
                value = light_property(holder)
                if value:
                    properties.append({"group": group, "holder": what, "value": value})
        elif ob.type in MESH_TYPES or ob.type == "LIGHT":
            if emits(ob):
                ungrouped.append(what if ob.type == "LIGHT" else what + " (emissive material)")
    world = scene.world
    if world is not None:
        if world.lightgroup:
            used.add(world.lightgroup)
            value = light_property(world)
            if value:
                properties.append({"group": world.lightgroup, "holder": "world %s" % world.name,
                                   "value": value})
        elif world_emits(world):
            ungrouped.append("world %s" % world.name)
    groups = [g for g in order if g in used] + sorted(used - set(order))
    return {"groups": groups, "ungrouped": ungrouped if groups else [],
            "properties": properties}


def new_node(nt, kind, operation, name=None, location=None):
    """A new node of `kind` (a Math or Vector Math node) in the node tree nt doing `operation`,
    with its name and location when given."""
    node = nt.nodes.new(kind)
    node.operation = operation
    if name is not None:
        node.name = name
    if location is not None:
        node.location = location
    return node


def plane_side_nodes(nt, name_prefix=None):
    """The Geometry, dot and add nodes whose output is n·P + d at the shading point P, linked
    (n on `dot`, d on `add`, set per pass): its sign says on which side of the plane P lies.
    With name_prefix the dot and add nodes are named PREFIX_dot and PREFIX_add."""
    names = (name_prefix + "_dot", name_prefix + "_add") if name_prefix else (None, None)
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    dot = new_node(nt, "ShaderNodeVectorMath", "DOT_PRODUCT", name=names[0])
    add = new_node(nt, "ShaderNodeMath", "ADD", name=names[1])
    nt.links.new(geo.outputs["Position"], dot.inputs[0])
    nt.links.new(dot.outputs["Value"], add.inputs[0])
    return geo, dot, add


def output_node(nt):
    outs = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    active = [n for n in outs if n.is_active_output]
    return (active or outs or [None])[0]


def colour_ramp(nt, cos_values, colours, location):
    """A Color Ramp node: colours[k] (RGB) at position cos_values[k], linear between."""
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.location = location
    els = ramp.color_ramp.elements
    while len(els) > 1:
        els.remove(els[-1])
    els[0].position = cos_values[0]
    els[0].color = tuple(colours[0]) + (1.0,)
    for c, rgb in zip(cos_values[1:], colours[1:]):
        e = els.new(c)
        e.color = tuple(rgb) + (1.0,)
    ramp.color_ramp.interpolation = "LINEAR"
    return ramp


def make_thin_pane(mat, glass, camera_sees_through):
    """Replaces mat's surface by the thin pane of `glass` (cos, r_front, r_back, t tables);
    with camera_sees_through, camera rays pass the glass untouched where set_clip says (and
    the GlassClip returned holds the nodes it sets)."""
    mat.use_nodes = True
    nt = mat.node_tree
    for node in list(nt.nodes):
        nt.nodes.remove(node)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.location = (900, 0)
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    geo.location = (-900, 0)
    dot = new_node(nt, "ShaderNodeVectorMath", "DOT_PRODUCT", location=(-700, 0))
    nt.links.new(geo.outputs["Normal"], dot.inputs[0])
    nt.links.new(geo.outputs["Incoming"], dot.inputs[1])
    absn = new_node(nt, "ShaderNodeMath", "ABSOLUTE", location=(-500, 0))
    nt.links.new(dot.outputs["Value"], absn.inputs[0])
    cos = glass["cos"]
    r_front = colour_ramp(nt, cos, glass["r_front"], (-300, 300))
    r_back = colour_ramp(nt, cos, glass["r_back"], (-300, 0))
    t = colour_ramp(nt, cos, glass["t"], (-300, -300))
    for ramp in (r_front, r_back, t):
        nt.links.new(absn.outputs["Value"], ramp.inputs["Fac"])
    side = nt.nodes.new("ShaderNodeMixRGB")
    side.location = (0, 200)
    nt.links.new(geo.outputs["Backfacing"], side.inputs["Fac"])
    nt.links.new(r_front.outputs["Color"], side.inputs["Color1"])
    nt.links.new(r_back.outputs["Color"], side.inputs["Color2"])
    glossy = nt.nodes.new("ShaderNodeBsdfGlossy")
    glossy.location = (200, 200)
    glossy.inputs["Roughness"].default_value = 0.0
    nt.links.new(side.outputs["Color"], glossy.inputs["Color"])
    through = nt.nodes.new("ShaderNodeBsdfTransparent")
    through.location = (200, -200)
    nt.links.new(t.outputs["Color"], through.inputs["Color"])
    add = nt.nodes.new("ShaderNodeAddShader")
    add.location = (400, 0)
    nt.links.new(glossy.outputs[0], add.inputs[0])
    nt.links.new(through.outputs[0], add.inputs[1])
    if not camera_sees_through:
        nt.links.new(add.outputs[0], out.inputs["Surface"])
        return None
    # Clear for camera rays: in the transmission pass where no transparent surface was crossed
    # yet (the first glass the camera sees; glass behind it stays a pane); in the reflection
    # pass of plane K on or behind plane K (the mirror itself, and what is clipped), so that
    # other glass seen in the mirror stays a pane. set_clip chooses the pass.
    lp = nt.nodes.new("ShaderNodeLightPath")
    lp.location = (400, 600)
    first = new_node(nt, "ShaderNodeMath", "LESS_THAN")
    first.inputs[1].default_value = 0.5
    nt.links.new(lp.outputs["Transparent Depth"], first.inputs[0])
    enable_trans = new_node(nt, "ShaderNodeMath", "MULTIPLY")
    nt.links.new(first.outputs[0], enable_trans.inputs[0])
    dot_p = new_node(nt, "ShaderNodeVectorMath", "DOT_PRODUCT")
    nt.links.new(geo.outputs["Position"], dot_p.inputs[0])
    add_p = new_node(nt, "ShaderNodeMath", "ADD")
    nt.links.new(dot_p.outputs["Value"], add_p.inputs[0])
    behind = new_node(nt, "ShaderNodeMath", "GREATER_THAN",
                      name=CLIP_PREFIX + "_glass_tolerance")
    nt.links.new(add_p.outputs["Value"], behind.inputs[0])
    enable_refl = new_node(nt, "ShaderNodeMath", "MULTIPLY")
    nt.links.new(behind.outputs[0], enable_refl.inputs[0])
    either = new_node(nt, "ShaderNodeMath", "MAXIMUM")
    nt.links.new(enable_trans.outputs[0], either.inputs[0])
    nt.links.new(enable_refl.outputs[0], either.inputs[1])
    camera = new_node(nt, "ShaderNodeMath", "MULTIPLY")
    nt.links.new(lp.outputs["Is Camera Ray"], camera.inputs[0])
    nt.links.new(either.outputs[0], camera.inputs[1])
    for k, node in enumerate((first, enable_trans, dot_p, add_p, behind, enable_refl, either,
                              camera)):
        node.location = (-900 + 150 * k, 700)
    clear = nt.nodes.new("ShaderNodeBsdfTransparent")
    clear.location = (400, -300)
    clear.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.location = (650, 0)
    nt.links.new(camera.outputs[0], mix.inputs["Fac"])
    nt.links.new(add.outputs[0], mix.inputs[1])
    nt.links.new(clear.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    return GlassClip(dot_p, add_p, behind, enable_refl, enable_trans)


class GlassClip:
    """The nodes of a glass material that set_clip sets per pass."""

    def __init__(self, dot, add, behind, enable_refl, enable_trans):
        self.dot, self.add, self.behind = dot, add, behind
        self.enable_refl, self.enable_trans = enable_refl, enable_trans


def add_clip(mat):
    """Mixes a Transparent BSDF into mat's surface for camera rays on the far side of a plane
    (set later by set_clip); returns the (dot, add, enable) nodes that hold the plane."""
    nt = mat.node_tree
    out = output_node(nt)
    if out is None or not out.inputs["Surface"].links:
        return None
    source = out.inputs["Surface"].links[0].from_socket
    geo, dot, add = plane_side_nodes(nt, CLIP_PREFIX)
    gt = new_node(nt, "ShaderNodeMath", "GREATER_THAN")
    gt.inputs[1].default_value = 0.0
    lp = nt.nodes.new("ShaderNodeLightPath")
    mul = new_node(nt, "ShaderNodeMath", "MULTIPLY")
    enable = new_node(nt, "ShaderNodeMath", "MULTIPLY", name=CLIP_PREFIX + "_enable")
    tr = nt.nodes.new("ShaderNodeBsdfTransparent")
    tr.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    mix = nt.nodes.new("ShaderNodeMixShader")
    x, y = out.location
    for k, node in enumerate((geo, dot, add, gt, lp, mul, enable, tr, mix)):
        node.location = (x - 1400 + 150 * k, y + 500)
    nt.links.new(add.outputs["Value"], gt.inputs[0])
    nt.links.new(lp.outputs["Is Camera Ray"], mul.inputs[0])
    nt.links.new(gt.outputs["Value"], mul.inputs[1])
    nt.links.new(mul.outputs["Value"], enable.inputs[0])
    nt.links.new(enable.outputs["Value"], mix.inputs["Fac"])
    nt.links.new(source, mix.inputs[1])
    nt.links.new(tr.outputs["BSDF"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return dot, add, enable


def set_clip(clips, glass_clips, plane, tolerance=0.0):
    """Camera rays see through what lies on the far side of `plane` ((a, b, c, d) with the
    real camera on the positive side) and through glass on or behind it (within `tolerance`),
    or, when plane is None (the transmission pass), nothing is clipped and camera rays see
    through the first glass they meet."""
    for g in glass_clips:
        if plane is None:
            g.enable_refl.inputs[1].default_value = 0.0
            g.enable_trans.inputs[1].default_value = 1.0
            continue
        a, b, c, d = plane
        g.dot.inputs[1].default_value = (-a, -b, -c)
        g.add.inputs[1].default_value = -d
        g.behind.inputs[1].default_value = -tolerance
        g.enable_refl.inputs[1].default_value = 1.0
        g.enable_trans.inputs[1].default_value = 0.0
    for dot, add, enable in clips:
        if plane is None:
            enable.inputs[1].default_value = 0.0
            continue
        a, b, c, d = plane
        dot.inputs[1].default_value = (-a, -b, -c)
        add.inputs[1].default_value = -d
        enable.inputs[1].default_value = 1.0


def set_exr_output(scene):
    im = scene.render.image_settings
    if hasattr(im, "media_type"):  # Blender 5.0: the media type first, then the format
        im.media_type = "IMAGE"
    im.file_format = "OPEN_EXR"
    im.color_mode = "RGBA"
    im.color_depth = "16"
    im.exr_codec = "ZIP"
    scene.render.use_file_extension = False


def render_still(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    if not os.path.isfile(path):
        fail("Blender wrote no image at %s" % path)


def reflection_matrix(plane):
    from mathutils import Matrix

    a, b, c, d = plane
    n = (a, b, c)
    rows = [[(1.0 if i == j else 0.0) - 2.0 * n[i] * n[j] for j in range(3)] + [-2.0 * d * n[i]]
            for i in range(3)]
    rows.append([0.0, 0.0, 0.0, 1.0])
    return Matrix(rows)


class ReflectedLamp:
    """A lamp of the scene and its own camera visibility, which the passes change and restore."""

    def __init__(self, ob):
        self.ob = ob
        self.visible_camera = ob.visible_camera
        data = ob.data
        cyc = getattr(data, "cycles", None)
        # What a glossy ray of the real glass can see: Cycles finds a lamp from a glossy bounce
        # only when the lamp is visible to glossy rays and takes part in MIS (and a portal
        # emits nothing).
        self.seen_by_glossy = (ob.visible_glossy
                               and getattr(cyc, "use_multiple_importance_sampling", True)
                               and not getattr(cyc, "is_portal", False))


def reflected_lamps(scene):
    """The scene's lamp objects (point, spot, area, sun), with their camera visibility."""
    return [ReflectedLamp(ob) for ob in scene.objects if ob.type == "LIGHT"]


def show_lamps_in_reflection(lamps, plane):
    """Lamps in the reflection pass of `plane` ((a, b, c, d), real camera on the positive
    side) as the real glass shows them: a mirror-camera ray is the real glass's reflected ray,
    so every lamp a glossy ray could meet on the camera's side of the plane (a sun always, as
    a disc of its angle) is made visible to camera rays, and lamps on the far side, which the
    mirror does not show, are hidden from them. With plane None (the transmission pass and
    the reference) each lamp gets back the scene's own camera visibility."""
    for lamp in lamps:
        if plane is None:
            lamp.ob.visible_camera = lamp.visible_camera
            continue
        if not lamp.seen_by_glossy:
            lamp.ob.visible_camera = False
        elif lamp.ob.data.type == "SUN":
            lamp.ob.visible_camera = True
        else:
            a, b, c, d = plane
            x, y, z = lamp.ob.matrix_world.translation
            lamp.ob.visible_camera = a * x + b * y + c * z + d > 0.0


def honest_passes(scene):
    """Cycles' denoiser and motion blur off, whatever the scene says: the passes must carry
    Cycles' own noise (the composite's and the reference's error are compared with it; and
    Debian's Blender has no OpenImageDenoise), and glassdb's masks are of the frame's instant.
    glassdb records what was overridden (export.json says what the scene had)."""
    if scene.cycles.use_denoising:
        print("glassdb_blender: denoising off for the passes (the scene denoises)")
    scene.cycles.use_denoising = False
    if scene.render.use_motion_blur:
        print("glassdb_blender: motion blur off for the passes (the masks are of the frame's instant)")
    scene.render.use_motion_blur = False


def render(opts):
    path = opts.get("job") or fail("render needs --job FILE")
    with open(path) as fh:
        job = json.load(fh)
    scene = bpy.context.scene
    if scene.camera is None:
        fail("the scene has no camera")
    if scene.render.engine != "CYCLES":
        scene.render.engine = "CYCLES"
    set_resolution(scene, job.get("resolution"))
    if job.get("samples"):
        scene.cycles.samples = int(job["samples"])
    scene.cycles.seed = int(job.get("seed", 0))
    if job.get("threads"):
        scene.render.threads_mode = "FIXED"
        scene.render.threads = int(job["threads"])
    honest_passes(scene)
    set_exr_output(scene)
    glass_by_name = {g["material"]: g for g in job["glass"]}
    missing = [m for m in glass_by_name if m not in bpy.data.materials]
    if missing:
        fail("no material %s in %s" % (", ".join(missing), bpy.data.filepath))
    clips = []
    glass_clips = []
    for mat in bpy.data.materials:
        if mat.name in glass_by_name:
            g = make_thin_pane(mat, glass_by_name[mat.name], not job.get("reference", False))
            if g is not None:
                glass_clips.append(g)
        elif mat.use_nodes and mat.node_tree is not None:
            nodes = add_clip(mat)
            if nodes:
                clips.append(nodes)
    split = LightSplit.of_job(scene, job)
    real = scene.camera
    lamps = reflected_lamps(scene) if job.get("lamps_in_reflections", True) else []
    mirror_data = None
    mirror = None
    r = scene.render
    for frame in job["frames"]:
        scene.frame_set(frame["frame"])
        scene.camera = real
        r.use_border = False
        set_clip(clips, glass_clips, None)
        show_lamps_in_reflection(lamps, None)
        if split is not None:
            split.start_frame(scene, frame)
        render_pass(scene, frame["trans"], split)
        m_real = real.matrix_world.copy()
        for plane in frame["planes"]:
            if mirror is None:
                mirror_data = real.data.copy()
                mirror = bpy.data.objects.new(MIRROR_CAMERA, mirror_data)
                scene.collection.objects.link(mirror)
            for attr in ("lens", "sensor_width", "sensor_height", "sensor_fit", "shift_x",
                         "shift_y", "clip_start", "clip_end", "type"):
                setattr(mirror_data, attr, getattr(real.data, attr))
            mirror.matrix_world = reflection_matrix(plane["equation"]) @ m_real
            scene.camera = mirror
            set_clip(clips, glass_clips, plane["equation"], plane["tolerance"])
            show_lamps_in_reflection(lamps, plane["equation"])
            x0, x1, y0, y1 = plane["border"]
            r.use_border = True
            r.use_crop_to_border = True
            r.border_min_x, r.border_max_x = x0, x1
            r.border_min_y, r.border_max_y = y0, y1
            render_pass(scene, plane["output"], split)
        scene.camera = real
        r.use_border = False
        show_lamps_in_reflection(lamps, None)
    print("glassdb_blender: rendered %d frames" % len(job["frames"]))


def split_path(path, state):
    """The pass `path` rendered in light-split state `state` (0: every aperture's glazing
    opaque to light rays; k: aperture k clear): `trans.0001.exr` -> `trans.0001.s2.exr`
    (crates/blender/src/light_split.rs names them the same way)."""
    stem, ext = os.path.splitext(path)
    return "%s.s%d%s" % (stem, state, ext)


def render_pass(scene, path, split):
    """One pass: as it is (no split), or once per light-split state."""
    if split is None:
        render_still(scene, path)
        return
    for state in range(len(split.apertures) + 1):
        split.set_state(state)
        render_still(scene, split_path(path, state))


def add_light_opening(mat):
    """Light rays (not camera rays) meet mat's glazing as a Transparent BSDF of colour `open`:
    1 (white, clear) where the shading point lies on the plane set by LightSplit.set_state and
    the material is that aperture's glass, else 0 (black: the glazing blocks light). Camera
    rays keep the surface the material has. Returns the nodes set per state."""
    nt = mat.node_tree
    out = output_node(nt)
    source = out.inputs["Surface"].links[0].from_socket
    geo, dot, add = plane_side_nodes(nt)
    dist = new_node(nt, "ShaderNodeMath", "ABSOLUTE")
    near = new_node(nt, "ShaderNodeMath", "LESS_THAN")
    enable = new_node(nt, "ShaderNodeMath", "MULTIPLY")
    enable.inputs[1].default_value = 0.0
    opening = nt.nodes.new("ShaderNodeBsdfTransparent")
    lp = nt.nodes.new("ShaderNodeLightPath")
    mix = nt.nodes.new("ShaderNodeMixShader")
    x, y = out.location
    for k, node in enumerate((geo, dot, add, dist, near, enable, opening, lp, mix)):
        node.location = (x - 1400 + 150 * k, y - 600)
    nt.links.new(add.outputs["Value"], dist.inputs[0])
    nt.links.new(dist.outputs["Value"], near.inputs[0])
    nt.links.new(near.outputs["Value"], enable.inputs[0])
    nt.links.new(enable.outputs["Value"], opening.inputs["Color"])
    nt.links.new(lp.outputs["Is Camera Ray"], mix.inputs["Fac"])
    nt.links.new(opening.outputs["BSDF"], mix.inputs[1])
    nt.links.new(source, mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return {"dot": dot, "add": add, "near": near, "enable": enable}


def set_light_groups(scene, names):
    """The view layer's light groups become `names` (written as the layers
    `ViewLayer.Combined_<group>` of multilayer EXRs)."""
    vl = bpy.context.view_layer
    scene.render.use_single_layer = True
    # Blender 3.4's collection has no remove(): the operator removes the active group.
    k = 0
    while k < len(vl.lightgroups):
        if vl.lightgroups[k].name in names:
            k += 1
            continue
        vl.active_lightgroup_index = k
        bpy.ops.scene.view_layer_remove_lightgroup()
    for name in names:
        if name not in vl.lightgroups:
            vl.lightgroups.add(name=name)
    scene.render.image_settings.file_format = "OPEN_EXR_MULTILAYER"


def source_light_groups(scene, scene_groups=()):
    """Cycles light groups by source: each sun lamp (`sun`, or `sun0`, `sun1`, ... for
    several), the world (`sky`) and every other emitter (`other`). With the scene's own light
    groups `scene_groups` (issue 29) each source is split by them too: `<source>_<group>`
    (`sun_sun`, `sky_sun`, `other_warm`), and its light is that group's; without them the
    scene's groups are replaced. Returns the sun lamps with their groups, and the sources
    (group, kind, scene group) in order."""
    suns = [ob for ob in scene.objects
            if ob.type == "LIGHT" and ob.data.type == "SUN" and not ob.hide_render]
    suns = [(ob, "sun" if len(suns) == 1 else "sun%d" % k) for k, ob in enumerate(suns)]
    if scene_groups:
        # The scene's groups, read before they are replaced; ungrouped objects emit nothing
        # (glassdb refused the scene otherwise) and stay in no group.
        own = {ob.name: ob.lightgroup for ob in scene.objects}
        world_group = scene.world.lightgroup if scene.world is not None else ""
        suns = [(ob, "%s_%s" % (n, own[ob.name])) for ob, n in suns if own[ob.name]]
        sources = [(n, "sun", own[ob.name]) for ob, n in suns]
        for g in scene_groups:
            if g == world_group:
                sources.append(("sky_%s" % g, "sky", g))
            sources.append(("other_%s" % g, "other", g))
    else:
        own, world_group = {}, ""
        sources = [(n, "sun", None) for _, n in suns] + [("sky", "sky", None),
                                                         ("other", "other", None)]
    names = [n for n, _, _ in sources]
    for lg in bpy.context.view_layer.lightgroups:
        if lg.name not in names and not scene_groups:
            print("glassdb_blender: light group %s replaced by the light split" % lg.name)
    set_light_groups(scene, names)
    by_sun = {ob.name: n for ob, n in suns}
    for ob in scene.objects:
        if ob.name in by_sun:
            ob.lightgroup = by_sun[ob.name]
        elif scene_groups:
            ob.lightgroup = "other_%s" % own[ob.name] if own.get(ob.name) else ""
        else:
            ob.lightgroup = "other"
    if scene.world is not None:
        scene.world.lightgroup = ("sky_%s" % world_group if world_group else "") \
            if scene_groups else "sky"
    return suns, sources


class LightSplit:
    """The passes split by the light's path (docs/blender.md, "Light parts"): Cycles light
    groups by source (each sun lamp, the world as `sky`, every other emitter as `other`),
    and each pass rendered once with all glazing opaque to light rays (state 0) and once per
    aperture (the glass of one id on one plane) with that glazing clear (state k). Camera rays
    see what they see without the split."""

    def __init__(self, scene, job):
        self.openings = {}
        for g in job["glass"]:
            self.openings[g["material"]] = add_light_opening(bpy.data.materials[g["material"]])
        self.apertures = []
        self.suns, self.sources = source_light_groups(scene, job.get("scene_groups", []))

    @staticmethod
    def of_job(scene, job):
        """The job's light split, or None; a reference job with `light_groups` gets the
        sources' light groups only (the validation's error by source); a job with the scene's
        light groups and no split renders a layer per scene group."""
        scene_groups = job.get("scene_groups", [])
        if job.get("light_groups"):
            source_light_groups(scene, scene_groups)
        elif scene_groups and not job.get("light_split"):
            set_light_groups(scene, scene_groups)
        return LightSplit(scene, job) if job.get("light_split") else None

    def start_frame(self, scene, frame):
        """This frame's apertures; writes its light sources (each sun's group and direction
        towards it, world axes) to frame["lights"]."""
        self.apertures = frame.get("apertures", [])
        from mathutils import Vector

        suns = []
        for ob, name in self.suns:
            # A sun lamp shines along its local -Z: +Z is towards the sun.
            d = ob.matrix_world.to_3x3() @ Vector((0.0, 0.0, 1.0))
            suns.append({"group": name, "direction_to_sun": list(d.normalized())})
        sources = [{"group": n, "kind": kind, "light": light} for n, kind, light in self.sources]
        with open(frame["lights"], "w") as fh:
            json.dump({"suns": suns, "sources": sources, "sky": scene.world is not None}, fh)

    def set_state(self, state):
        """0: every glazing opaque to light rays; k: aperture k - 1 clear, the others opaque."""
        ap = self.apertures[state - 1] if state > 0 else None
        for name, n in self.openings.items():
            on = ap is not None and name in ap["materials"]
            n["enable"].inputs[1].default_value = 1.0 if on else 0.0
            if on:
                a, b, c, d = ap["equation"]
                n["dot"].inputs[1].default_value = (a, b, c)
                n["add"].inputs[1].default_value = d
                n["near"].inputs[1].default_value = ap["tolerance"]


# ----------------------------------------------------------------------------------------------
# The add-on: the same settings as the command line, and a button that runs glassdb.
# ----------------------------------------------------------------------------------------------


class GlassdbSettings(bpy.types.PropertyGroup):
    binary: bpy.props.StringProperty(name="glassdb", default="glassdb", subtype="FILE_PATH",
                                     description="The glassdb program")
    glass: bpy.props.StringProperty(
        name="Glass", default="Glass*=1",
        description="Material patterns and registry ids, PATTERN=ID separated by spaces")
    frames: bpy.props.StringProperty(name="Frames", default="",
                                     description="e.g. 1-24; empty: the scene's frame range")
    out_dir: bpy.props.StringProperty(name="Output", default="//glassdb/", subtype="DIR_PATH")
    registry: bpy.props.StringProperty(name="Registry", default="", subtype="FILE_PATH",
                                       description="Registry JSON; empty: the bundled one")
    samples: bpy.props.IntProperty(name="Samples", default=0, min=0,
                                   description="0: the scene's Cycles samples")
    lights: bpy.props.StringProperty(
        name="Lights", default="",
        description="Each light group's spectrum, GROUP=ILLUMINANT separated by spaces "
                    "(e.g. sun=D65 warm=A); empty: the glassdb_light properties")


def addon_command(context):
    """The `glassdb blender render` command line for the current file and settings."""
    s = context.scene.glassdb
    cmd = [bpy.path.abspath(s.binary) if s.binary.startswith("//") else s.binary,
           "blender", "render", bpy.data.filepath,
           "--out-dir", bpy.path.abspath(s.out_dir), "--blender", bpy.app.binary_path]
    for g in s.glass.split():
        cmd += ["--glass", g]
    if s.frames:
        cmd += ["--frames", s.frames]
    if s.registry:
        cmd += ["--registry", bpy.path.abspath(s.registry)]
    if s.samples:
        cmd += ["--samples", str(s.samples)]
    for light in s.lights.split():
        cmd += ["--light", light]
    return cmd


class GLASSDB_OT_render(bpy.types.Operator):
    """Save the file and run glassdb blender render on it"""

    bl_idname = "glassdb.render"
    bl_label = "Render with glassdb"

    def execute(self, context):
        if not bpy.data.filepath:
            self.report({"ERROR"}, "save the .blend file first")
            return {"CANCELLED"}
        bpy.ops.wm.save_mainfile()
        cmd = addon_command(context)
        print("glassdb:", " ".join(shlex.quote(c) for c in cmd))
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            self.report({"ERROR"}, (done.stderr.strip() or "glassdb failed")[-400:])
            return {"CANCELLED"}
        self.report({"INFO"}, done.stdout.strip().splitlines()[-1] if done.stdout else "done")
        return {"FINISHED"}


class GLASSDB_PT_panel(bpy.types.Panel):
    bl_label = "glassdb"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        s = context.scene.glassdb
        col = self.layout.column()
        for prop in ("binary", "glass", "frames", "out_dir", "registry", "samples", "lights"):
            col.prop(s, prop)
        col.operator(GLASSDB_OT_render.bl_idname)


CLASSES = (GlassdbSettings, GLASSDB_OT_render, GLASSDB_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.glassdb = bpy.props.PointerProperty(type=GlassdbSettings)


def unregister():
    del bpy.types.Scene.glassdb
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)


def main():
    mode, opts = parse_cli(sys.argv)
    if mode == "export":
        export(opts)
    else:
        render(opts)


if __name__ == "__main__":
    main()
