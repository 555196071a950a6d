#!/usr/bin/env python3
"""Render Blender Cycles fixtures for checking `glassdb mask`, and export the exact scene.

One procedurally built scene (no .blend file): a floor, a back wall, two boxes and three glass
panes (pane 0 `Glass_clear`, a rectangle; pane 1 `Glass_clear`, a concave U-shaped n-gon in a
perpendicular plane; pane 2 `Tinted_bronze`, a tilted rectangle), a sun and a grey world, seen
by a level 30 mm camera with lens shift that moves and turns over frames 1-3. Three steps, one
script:

1. Render (needs Blender; under Blender's own Python or under the `bpy` module):

       blender -b --factory-startup -noaudio --python-exit-code 1 \\
           -P scripts/blender/make_mask_fixtures.py -- \\
           --out fixtures/blender/masks/b34 --geometry fixtures/blender/masks --write-geometry
       /work/bpyvenv/bin/python scripts/blender/make_mask_fixtures.py \\
           --out fixtures/blender/masks/b50 --geometry fixtures/blender/masks

   writes into --out: index.0001-0003.exr, index_portrait.exr, beauty.0001.exr, trans.0001.exr
   and a first check.json (Blender version, render settings). The scene (scene.obj,
   scene.mtl) and the cameras (camera.000N.json, camera_portrait.json, cameras.json), taken
   from Blender's objects, are written to --geometry with --write-geometry; without it they
   are compared with the files already there, and the run fails (exit 1) if any text differs.
   `--working-space NAME` (Blender 5.0+, e.g. ACEScg; default: Blender's, Linear Rec.709)
   sets the blend file's working colour space once the scene is built, with Blender
   converting every colour in it, so that the same scene is rendered in that space.

2. Check (plain Python with numpy and the `OpenEXR` package, pip OpenEXR==3.5.3; no Blender):

       python scripts/blender/make_mask_fixtures.py --check \\
           --out fixtures/blender/masks/b34 --geometry fixtures/blender/masks

   reads the EXRs back and completes check.json: the file layouts (parts, channels,
   Cryptomatte manifest), per index render the pixel counts of ids 1 and 5, the agreement
   with an independent numpy ray cast of scene.obj through the camera JSON (pixel centres,
   Blender's sensor fit / shift / pixel aspect rules), that the U pane's notch is not id 1,
   and for beauty.0001.exr the Cryptomatte coverage of the glass materials against the
   `glass_coverage` AOV. It fails (exit 1) when a check does not hold.

3. Preview (numpy only): `python make_mask_fixtures.py --preview` prints the ray cast of
   frame 1 as text (used to lay out the scene).

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402

# --------------------------------------------------------------------------------------------
# The scene, as plain data (metres, z up). Every coordinate is a multiple of 1/8, so it is
# exact in Blender's float32 and in the OBJ text.
# --------------------------------------------------------------------------------------------

WIDTH, HEIGHT = 160, 120
PORTRAIT = {"width": 96, "height": 128, "pixel_aspect_x": 2.0, "pixel_aspect_y": 1.0,
            "sensor_fit": "VERTICAL", "sensor_height": 24.0}
FRAMES = (1, 2, 3)
LENS_MM, SENSOR_W_MM, SENSOR_H_MM = 30.0, 36.0, 24.0
SHIFT_X, SHIFT_Y = -0.05, 0.12
INDEX_SAMPLES, BEAUTY_SAMPLES = 1, 16
INDEX_FILTER_WIDTH = 0.01
CRYPTO_LEVELS = 6

# Linear Rec.709 -> ACEScg as Blender 5.0.1 applies it when it converts a file's colours
# (bpy.ops.wm.set_working_color_space, convert_colors=True): its OCIO config's Rec.709 -> CIE XYZ
# D65, then OCIO's builtin ACES-AP1_to_CIE-XYZ-D65_BFD inverted (Bradford D65 -> ACES white).
# Measured by converting (1, 0, 0), (0, 1, 0), (0, 0, 1); rows for column vectors.
REC709_TO_ACESCG = ((0.61310, 0.33952, 0.04738),
                    (0.07019, 0.91635, 0.01345),
                    (0.02062, 0.10957, 0.86981))

# Camera keyframes: body level (rotation x = 90°, no roll), moving sideways to the right while
# turning a little to the left.
CAMERA_KEYS = {
    1: {"location": (-1.75, -5.5, 1.25), "yaw_deg": -24.0},
    2: {"location": (-1.5, -5.5, 1.25), "yaw_deg": -23.0},
    3: {"location": (-1.25, -5.5, 1.25), "yaw_deg": -22.0},
}

# name: (kind, rgb, material pass index)
MATERIALS = {
    "Floor": ("diffuse", (0.35, 0.33, 0.30), 0),
    "Wall": ("diffuse", (0.15, 0.35, 0.60), 0),
    "Box_red": ("diffuse", (0.60, 0.12, 0.10), 0),
    "Box_green": ("diffuse", (0.15, 0.50, 0.15), 0),
    "Glass_clear": ("glass", (0.85, 0.95, 0.95), 1),
    "Tinted_bronze": ("glass", (0.55, 0.38, 0.18), 5),
}
GLASS_IDS = {"Glass_clear": 1, "Tinted_bronze": 5}


def _box(x0, y0, x1, y1, h):
    verts = [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0),
             (x0, y0, h), (x1, y0, h), (x1, y1, h), (x0, y1, h)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return verts, faces


def _u_pane(x, y0, y1, z0, z1, ya, yb, zn):
    """A U (opening upwards) in the plane x = const: outer y0..y1 × z0..z1, notch ya..yb × zn..z1."""
    verts = [(x, y0, z0), (x, y1, z0), (x, y1, z1), (x, yb, z1),
             (x, yb, zn), (x, ya, zn), (x, ya, z1), (x, y0, z1)]
    return verts, [tuple(range(8))]


# Objects in OBJ order: opaque ones first, then the panes in plane order 0, 1, 2.
# (name, material, object pass index, plane or None, (verts, faces))
OBJECTS = [
    ("Floor", "Floor", 0, None,
     ([(-8.0, -4.0, 0.0), (16.0, -4.0, 0.0), (16.0, 5.0, 0.0), (-8.0, 5.0, 0.0)],
      [(0, 1, 2, 3)])),
    ("BackWall", "Wall", 0, None,
     ([(-8.0, 5.0, 0.0), (16.0, 5.0, 0.0), (16.0, 5.0, 4.5), (-8.0, 5.0, 4.5)],
      [(0, 3, 2, 1)])),
    # Box A stands in front of the lower right of pane 0 and hides part of it.
    ("Box_A", "Box_red", 0, None, _box(0.25, 0.0, 1.0, 0.625, 0.875)),
    ("Box_B", "Box_green", 0, None, _box(2.75, 2.5, 3.75, 3.25, 1.5)),
    # Pane 0: large vertical rectangle in the plane y = 1.
    ("Pane0_clear", "Glass_clear", 1, 0,
     ([(-0.5, 1.0, 0.5), (1.5, 1.0, 0.5), (1.5, 1.0, 2.5), (-0.5, 1.0, 2.5)],
      [(0, 1, 2, 3)])),
    # Pane 1: concave U (opening upwards) in the plane x = 2.5, perpendicular to pane 0.
    ("Pane1_clear_U", "Glass_clear", 2, 1,
     _u_pane(2.5, -1.5, 0.5, 0.375, 2.5, -0.875, -0.125, 1.375)),
    # Pane 2: small rectangle leaning back (a third plane), left of pane 0.
    ("Pane2_bronze", "Tinted_bronze", 3, 2,
     ([(-2.0, -0.25, 0.5), (-1.25, -0.75, 0.5), (-1.0, -0.375, 1.5), (-1.75, 0.125, 1.5)],
      [(0, 1, 2, 3)])),
]


def shortest_f32(x):
    """The shortest decimal text that reads back as the same float32 as x (so that float32
    values from Blender are written the same way by every version)."""
    x = float(x)
    if x == 0.0:
        return "0.0"
    target = struct.pack("<f", x)
    for digits in range(1, 10):
        s = "%.*g" % (digits, x)
        if struct.pack("<f", float(s)) == target:
            if "e" not in s and "." not in s:
                s += ".0"
            return s
    return repr(x)


# --------------------------------------------------------------------------------------------
# Writers shared by the render step (from Blender's data) and the tests of the data itself.
# --------------------------------------------------------------------------------------------

def obj_text(objects):
    """objects: [(name, material, [(x, y, z) world], [(i, j, k, ...) 0-based])]."""
    lines = ["# glassdb mask fixture scene (metres, z up), written by "
             "scripts/blender/make_mask_fixtures.py",
             "# world-space positions; one polygon per Blender face; glass panes last, in plane "
             "order 0, 1, 2",
             "mtllib scene.mtl"]
    base = 1
    for name, material, verts, faces in objects:
        lines.append("o %s" % name)
        for v in verts:
            lines.append("v %s %s %s" % tuple(shortest_f32(c) for c in v))
        lines.append("usemtl %s" % material)
        for f in faces:
            lines.append("f " + " ".join(str(base + i) for i in f))
        base += len(verts)
    return "\n".join(lines) + "\n"


def mtl_text():
    lines = ["# materials of scene.obj; only the names matter to glassdb"]
    for name, (kind, rgb, _index) in MATERIALS.items():
        lines.append("newmtl %s" % name)
        lines.append("Kd %s %s %s" % tuple(shortest_f32(c) for c in rgb))
        if kind == "glass":
            lines.append("d 0.25")
    return "\n".join(lines) + "\n"


def camera_json_obj(matrix_rows, sensor_fit, width, height, aspx, aspy):
    return {
        "matrix_world": [[float(shortest_f32(v)) for v in row] for row in matrix_rows],
        "focal_length_mm": float(shortest_f32(LENS_MM)),
        "sensor_width_mm": float(shortest_f32(SENSOR_W_MM)),
        "sensor_height_mm": float(shortest_f32(SENSOR_H_MM)),
        "sensor_fit": sensor_fit,
        "shift_x": float(shortest_f32(SHIFT_X)),
        "shift_y": float(shortest_f32(SHIFT_Y)),
        "pixel_aspect": aspx / aspy,
        "width": width,
        "height": height,
    }


def camera_text(cam):
    """Camera JSON text: one row of the matrix per line."""
    parts = []
    for key, value in cam.items():
        if key == "matrix_world":
            rows = ",\n    ".join(json.dumps(r) for r in value)
            parts.append('  "matrix_world": [\n    %s\n  ]' % rows)
        else:
            parts.append("  %s: %s" % (json.dumps(key), json.dumps(value)))
    return "{\n" + ",\n".join(parts) + "\n}\n"


def cameras_text(frames):
    out = ['{\n  "frames": {']
    items = []
    for f, cam in frames.items():
        body = camera_text(cam).rstrip("\n").replace("\n", "\n    ")
        items.append('    "%d": %s' % (f, body))
    out.append(",\n".join(items))
    out.append("  }\n}\n")
    return "\n".join(out)


# --------------------------------------------------------------------------------------------
# Arguments
# --------------------------------------------------------------------------------------------

def parse_args(argv):
    opts = fixture_scene.parse_options(
        argv, "make_mask_fixtures.py", __doc__,
        {"out": None, "geometry": None, "write_geometry": False, "mode": "render",
         "working_space": None},
        paths=("out", "geometry"), values=("working-space",),
        flags={"--write-geometry": ("write_geometry", True), "--check": ("mode", "check"),
               "--preview": ("mode", "preview")})
    if opts["mode"] != "preview" and not (opts["out"] and opts["geometry"]):
        sys.exit("make_mask_fixtures.py: --out DIR and --geometry DIR are required")
    return opts


# --------------------------------------------------------------------------------------------
# Step 1: render (bpy)
# --------------------------------------------------------------------------------------------

def set_working_space(bpy, name, mats):
    """Make `name` the blend file's working colour space (Blender 5.0+). The file's colours
    are Linear Rec.709 (the factory working space); Blender's operator converts every colour
    in the file (material and world node sockets, viewport colours, lights) through CIE XYZ
    into the new space, so the scene stays the same. `bpy.data.colorspace.working_space` is
    read-only. Returns what it did, for check.json; exits when the colours were not
    converted (for ACEScg: not by REC709_TO_ACESCG within 1e-4)."""
    if tuple(bpy.app.version) < (5, 0, 0) or not hasattr(bpy.data, "colorspace"):
        sys.exit("--working-space needs Blender 5.0 or later")
    cs = bpy.data.colorspace
    before = cs.working_space
    if bpy.ops.wm.set_working_color_space(working_space=name,
                                          convert_colors=True) != {"FINISHED"} \
            or cs.working_space != name:
        sys.exit("working space %r not set (it is %r)" % (name, cs.working_space))
    colours = {}
    for mname, mat in mats.items():
        bsdf = [n for n in mat.node_tree.nodes
                if n.bl_idname in ("ShaderNodeBsdfDiffuse", "ShaderNodeBsdfPrincipled")][0]
        sock = bsdf.inputs["Color" if "Color" in bsdf.inputs else "Base Color"]
        rgb = MATERIALS[mname][1]
        got = tuple(sock.default_value)[:3]
        colours[mname] = {"rec709": list(rgb), "converted": list(got)}
        if name == "ACEScg":
            want = [sum(REC709_TO_ACESCG[i][j] * rgb[j] for j in range(3)) for i in range(3)]
            if max(abs(got[i] - want[i]) for i in range(3)) > 1e-4:
                sys.exit("%s: colour %r, expected %r from Rec.709 %r" % (mname, got, want, rgb))
        elif max(abs(got[i] - rgb[i]) for i in range(3)) < 1e-4:
            sys.exit("%s: colour not converted to %s" % (mname, name))
    return {"name": name, "was": before, "interop_id": cs.working_space_interop_id,
            "set_by": "bpy.ops.wm.set_working_color_space(working_space=%r, "
                      "convert_colors=True), after the scene was built" % name,
            "material_colours": colours,
            # grey and white stay grey and white (each row of the matrix sums to 1)
            "world_background_colour": [list(n.inputs["Color"].default_value)[:3]
                                        for w in bpy.data.worlds for n in w.node_tree.nodes
                                        if n.bl_idname == "ShaderNodeBackground"],
            "light_colours": {lt.name: list(lt.color) for lt in bpy.data.lights}}


def render_all(out_dir, geo_dir, write_geometry, working_space=None):
    import bpy
    import bmesh

    os.makedirs(out_dir, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    version = tuple(bpy.app.version)
    scene = bpy.context.scene

    def input_named(node, *names):
        for n in names:
            if n in node.inputs:
                return node.inputs[n]
        sys.exit("%s has none of the inputs %r" % (node.bl_idname, names))

    # Materials. Glass: Principled BSDF with full transmission (not a Transparent BSDF, which
    # would let the index passes through to the surface behind). Glass materials also write
    # the AOVs facing = |N.I|, plane = object pass index - 1, glass_coverage = 1; other
    # materials have no AOV node (their samples add 0).
    mats = {}
    for name, (kind, rgb, pass_index) in MATERIALS.items():
        mat, nt, out = fixture_scene.new_material(name, pass_index)
        if kind == "glass":
            bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
            bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
            bsdf.inputs["Roughness"].default_value = 0.0
            bsdf.inputs["IOR"].default_value = 1.5
            input_named(bsdf, "Transmission Weight", "Transmission").default_value = 1.0
            fixture_scene.facing_aov(nt, at=(-200, -300))
            info = fixture_scene.new_node(nt, "ShaderNodeObjectInfo", (-800, -600))
            sub = fixture_scene.new_node(nt, "ShaderNodeMath", (-400, -600), "SUBTRACT")
            sub.inputs[1].default_value = 1.0
            nt.links.new(info.outputs["Object Index"], sub.inputs[0])
            plane_aov = fixture_scene.aov_output(nt, "plane", (-200, -600))
            nt.links.new(sub.outputs["Value"], plane_aov.inputs["Value"])
            cov = fixture_scene.aov_output(nt, "glass_coverage", (-200, -900))
            cov.inputs["Value"].default_value = 1.0
        else:
            bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
            bsdf.inputs["Color"].default_value = (*rgb, 1.0)
        nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
        mats[name] = mat

    # Geometry: one mesh object per entry, identity transform, world-space vertices; every
    # face one bmesh face (the U pane one 8-corner n-gon, which Blender triangulates itself).
    glass_objects = []
    for name, material, obj_index, plane, (verts, faces) in OBJECTS:
        mesh = bpy.data.meshes.new(name)
        bm = bmesh.new()
        bverts = [bm.verts.new(v) for v in verts]
        for f in faces:
            bm.faces.new([bverts[i] for i in f])
        bm.to_mesh(mesh)
        bm.free()
        mesh.materials.append(mats[material])
        obj = bpy.data.objects.new(name, mesh)
        obj.pass_index = obj_index
        scene.collection.objects.link(obj)
        if plane is not None:
            glass_objects.append(obj)

    # Sun.
    sun_data = bpy.data.lights.new("Sun", type="SUN")
    sun_data.energy = 3.0
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (math.radians(40), math.radians(15), math.radians(30))
    scene.collection.objects.link(sun)

    # World: grey.
    bg = fixture_scene.grey_world(scene)

    # Camera, keyframed on frames 1-3 (linear; at the keyed frames the value is the key's).
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = LENS_MM
    cam_data.sensor_width = SENSOR_W_MM
    cam_data.sensor_height = SENSOR_H_MM
    cam_data.sensor_fit = "AUTO"
    cam_data.shift_x = SHIFT_X
    cam_data.shift_y = SHIFT_Y
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    for f in FRAMES:
        key = CAMERA_KEYS[f]
        cam.location = key["location"]
        cam.rotation_euler = (math.radians(90.0), 0.0, math.radians(key["yaw_deg"]))
        cam.keyframe_insert("location", frame=f)
        cam.keyframe_insert("rotation_euler", frame=f)
    fcurves = None
    if cam.animation_data and cam.animation_data.action:
        action = cam.animation_data.action
        fcurves = getattr(action, "fcurves", None)
        if fcurves is None:  # Blender 5.0: layered actions (layers/strips/channelbags)
            fcurves = []
            for layer in action.layers:
                for strip in layer.strips:
                    for bag in strip.channelbags:
                        fcurves.extend(bag.fcurves)
    for fc in fcurves or []:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
    scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]

    # Working colour space: only when asked (--working-space); the colours above are
    # Linear Rec.709 and Blender converts them.
    space_info = None
    if working_space is not None:
        space_info = set_working_space(bpy, working_space, mats)

    # Render settings common to all renders.
    r = fixture_scene.fixed_cycles(scene)
    r.film_transparent = False
    r.use_border = False
    vl = scene.view_layers[0]

    def set_resolution(w, h, aspx, aspy):
        r.resolution_x, r.resolution_y = w, h
        r.pixel_aspect_x, r.pixel_aspect_y = aspx, aspy

    def set_passes(combined=False, index=False, normal=False, position=False, crypto=False,
                   aovs=()):
        vl.use_pass_combined = combined
        vl.use_pass_z = False
        vl.use_pass_mist = False
        vl.use_pass_normal = normal
        vl.use_pass_position = position
        vl.use_pass_material_index = index
        vl.use_pass_object_index = index
        vl.use_pass_cryptomatte_material = crypto
        vl.use_pass_cryptomatte_object = False
        vl.use_pass_cryptomatte_asset = False
        vl.pass_cryptomatte_depth = CRYPTO_LEVELS
        # Blender 3.4 cannot remove an AOV from Python, so the renders are ordered so that
        # the AOVs are only ever added (beauty last).
        have = [a.name for a in vl.aovs]
        if have and have != list(aovs):
            sys.exit("AOVs %r already on the view layer, %r wanted" % (have, aovs))
        for name in aovs[len(have):]:
            aov = vl.aovs.add()
            aov.name = name
            aov.type = "VALUE"

    im = r.image_settings

    def set_format(half):
        fixture_scene.set_exr_format(im, multilayer=True, half=half)

    def render_to(name, frame):
        scene.frame_set(frame)
        fixture_scene.render_still(scene, out_dir, name)

    # Geometry and cameras, from Blender's own data.
    def f32_rows(m):
        return [[m[i][j] for j in range(4)] for i in range(4)]

    export = []
    for name, material, _obj_index, _plane, _geom in OBJECTS:
        obj = bpy.data.objects[name]
        mw = obj.matrix_world
        verts = [tuple(mw @ v.co) for v in obj.data.vertices]
        faces = [tuple(p.vertices) for p in obj.data.polygons]
        export.append((name, obj.data.materials[0].name, verts, faces))
    texts = {"scene.obj": obj_text(export), "scene.mtl": mtl_text()}
    expected_obj = obj_text([(n, m, g[0], g[1]) for n, m, _i, _p, g in OBJECTS])
    if texts["scene.obj"] != expected_obj:
        sys.exit("Blender's meshes differ from the scene data (vertex or corner order changed)")
    frames = {}
    for f in FRAMES:
        scene.frame_set(f)
        frames[f] = camera_json_obj(f32_rows(cam.matrix_world), "auto", WIDTH, HEIGHT, 1.0, 1.0)
        texts["camera.%04d.json" % f] = camera_text(frames[f])
    texts["cameras.json"] = cameras_text(frames)
    scene.frame_set(1)
    portrait = camera_json_obj(f32_rows(cam.matrix_world), "vertical", PORTRAIT["width"],
                               PORTRAIT["height"], PORTRAIT["pixel_aspect_x"],
                               PORTRAIT["pixel_aspect_y"])
    texts["camera_portrait.json"] = camera_text(portrait)
    os.makedirs(geo_dir, exist_ok=True)
    differs = []
    for fname, text in texts.items():
        path = os.path.join(geo_dir, fname)
        if write_geometry:
            with open(path, "w", newline="\n") as fh:
                fh.write(text)
            print("wrote", path)
        else:
            with open(path) as fh:
                old = fh.read()
            if old != text:
                differs.append(fname)
                with open(os.path.join(out_dir, "_differs_" + fname), "w") as fh:
                    fh.write(text)
    if differs:
        sys.exit("geometry/camera text differs from %s: %s" % (geo_dir, ", ".join(differs)))

    # 1. Index renders: 1 sample, pixel filter 0.01 px, Material and Object Index. Cycles
    # always writes a Combined pass (use_pass_combined = False is ignored): film exposure 0
    # makes it black (alpha 1), so that it compresses to almost nothing, and it is half float.
    scene.cycles.samples = INDEX_SAMPLES
    scene.cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    scene.cycles.filter_width = INDEX_FILTER_WIDTH
    index_filter_kept = scene.cycles.filter_width
    scene.cycles.film_exposure = 0.0
    set_passes(index=True)
    set_format(half=True)
    set_resolution(WIDTH, HEIGHT, 1.0, 1.0)
    for f in FRAMES:
        render_to("index.%04d.exr" % f, f)
    # Portrait still (frame 1 pose): vertical sensor fit, 96 x 128, pixel aspect 2:1.
    cam_data.sensor_fit = PORTRAIT["sensor_fit"]
    cam_data.sensor_height = PORTRAIT["sensor_height"]
    set_resolution(PORTRAIT["width"], PORTRAIT["height"], PORTRAIT["pixel_aspect_x"],
                   PORTRAIT["pixel_aspect_y"])
    portrait_error = None
    try:
        render_to("index_portrait.exr", 1)
    except RuntimeError as e:
        # Blender 5.0.1 cannot write any multi-part EXR with non-square pixels ("Conflicting
        # attributes found for header :: ViewLayer.Object Index 'pixelAspectRatio'"); pixel
        # aspect has a hard minimum of 1, so 1 : 0.5 is no way out (it becomes 1 : 1).
        # index_portrait_emission.exr below carries the same ids in a single-part file.
        portrait_error = str(e).strip().splitlines()[0]
        for old in os.listdir(out_dir):
            if old.startswith("_render_index_portrait"):
                os.remove(os.path.join(out_dir, old))
        print("index_portrait.exr not written: %s" % portrait_error)
    cam_data.sensor_fit = "AUTO"
    set_resolution(WIDTH, HEIGHT, 1.0, 1.0)
    scene.cycles.film_exposure = 1.0

    # 2. Transmission pass: the glass invisible to camera rays, Combined only, 16 samples,
    # default filter.
    scene.cycles.samples = BEAUTY_SAMPLES
    scene.cycles.filter_width = 1.5
    for obj in glass_objects:
        obj.visible_camera = False
    set_passes(combined=True)
    render_to("trans.0001.exr", 1)
    for obj in glass_objects:
        obj.visible_camera = True

    # 3. Beauty: 16 samples, default filter, all the passes the checks need.
    set_passes(combined=True, index=True, normal=True, position=True, crypto=True,
               aovs=("facing", "plane", "glass_coverage"))
    vl.use_pass_object_index = False
    render_to("beauty.0001.exr", 1)

    # 4. The portrait again, ids as emission in the Combined pass of a single-part EXR
    # (R = material pass index, G = object pass index, B = 1 on any surface, 0 on the world),
    # which Blender 5.0.1 can write with non-square pixels. Every material's surface becomes
    # an Emission shader (nothing scatters, so one camera-ray sample gives the exact value),
    # the world black. Done last: it changes the materials.
    for mat in mats.values():
        nt = mat.node_tree
        out = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial"][0]
        info = nt.nodes.new("ShaderNodeObjectInfo")
        rgb = nt.nodes.new("ShaderNodeCombineColor")
        rgb.inputs[0].default_value = float(mat.pass_index)
        rgb.inputs[2].default_value = 1.0
        nt.links.new(info.outputs["Object Index"], rgb.inputs[1])
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Strength"].default_value = 1.0
        nt.links.new(rgb.outputs[0], em.inputs["Color"])
        nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    bg.inputs["Strength"].default_value = 0.0
    scene.cycles.samples = INDEX_SAMPLES
    scene.cycles.filter_width = INDEX_FILTER_WIDTH
    set_passes(combined=True, aovs=("facing", "plane", "glass_coverage"))
    cam_data.sensor_fit = PORTRAIT["sensor_fit"]
    cam_data.sensor_height = PORTRAIT["sensor_height"]
    set_resolution(PORTRAIT["width"], PORTRAIT["height"], PORTRAIT["pixel_aspect_x"],
                   PORTRAIT["pixel_aspect_y"])
    if hasattr(im, "media_type"):
        im.media_type = "IMAGE"
    im.file_format = "OPEN_EXR"
    im.color_mode = "RGBA"
    im.color_depth = "32"
    im.exr_codec = "ZIP"
    render_to("index_portrait_emission.exr", 1)

    build_hash = getattr(bpy.app, "build_hash", b"")
    if isinstance(build_hash, bytes):
        build_hash = build_hash.decode("ascii", "replace")
    info = {
        "blender": {
            "version_string": bpy.app.version_string,
            "version": list(version),
            "build_hash": str(build_hash),
            "python": sys.version.split()[0],
            "as_module": "--" not in sys.argv,
        },
        "render": {
            "engine": "CYCLES", "device": "CPU", "threads": 2, "seed": 0, "denoising": False,
            "adaptive_sampling": False, "film_transparent": False,
            "index": {"files": ["index.%04d.exr" % f for f in FRAMES]
                      + (["index_portrait.exr"] if portrait_error is None else []),
                      "samples": INDEX_SAMPLES, "filter_type": scene.cycles.pixel_filter_type,
                      "filter_width_asked": INDEX_FILTER_WIDTH,
                      "filter_width_kept": index_filter_kept,
                      "passes": ["Combined (black: film_exposure 0)", "Material Index",
                                 "Object Index"], "color_depth": "16",
                      "codec": "ZIP"},
            "portrait": {"file": "index_portrait.exr", "frame": 1,
                         "resolution": [PORTRAIT["width"], PORTRAIT["height"]],
                         "sensor_fit": PORTRAIT["sensor_fit"],
                         "sensor_height": PORTRAIT["sensor_height"],
                         "pixel_aspect": [PORTRAIT["pixel_aspect_x"],
                                          PORTRAIT["pixel_aspect_y"]],
                         "written": portrait_error is None,
                         "write_error": portrait_error and (
                             portrait_error + " (the console names the cause: Conflicting "
                             "attributes found for header :: ViewLayer.Object Index "
                             "'pixelAspectRatio'; see README.md)")},
            "portrait_emission": {
                "file": "index_portrait_emission.exr", "frame": 1,
                "format": "OPEN_EXR (single part), RGBA, float32, ZIP",
                "encoding": "R = material pass index, G = object pass index, B = 1 on a "
                            "surface, 0 on the world (every material an Emission shader)",
                "samples": INDEX_SAMPLES, "filter_width": INDEX_FILTER_WIDTH},
            "beauty": {"file": "beauty.0001.exr", "samples": BEAUTY_SAMPLES,
                       "filter": "BLACKMAN_HARRIS 1.5 px (default)",
                       "passes": ["Combined", "Material Index", "Normal", "Position",
                                  "Cryptomatte Material (levels %d)" % CRYPTO_LEVELS,
                                  "AOV facing", "AOV plane", "AOV glass_coverage"],
                       "color_depth": "16", "codec": "ZIP"},
            "trans": {"file": "trans.0001.exr", "samples": BEAUTY_SAMPLES,
                      "filter": "BLACKMAN_HARRIS 1.5 px (default)",
                      "glass_visible_camera": False, "passes": ["Combined"],
                      "color_depth": "16", "codec": "ZIP"},
        },
    }
    if space_info is not None:
        info["working_space"] = space_info
    fixture_scene.write_json(os.path.join(out_dir, "check.json"), info)


# --------------------------------------------------------------------------------------------
# Reference ray cast (numpy): what a pixel-centre camera sees of scene.obj
# --------------------------------------------------------------------------------------------

def read_obj(path):
    """Polygons of an OBJ written by obj_text: [(object, material, [corner xyz])]."""
    verts, polys = [], []
    obj = mat = None
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if t[0] == "v":
                verts.append(tuple(float(c) for c in t[1:4]))
            elif t[0] == "o":
                obj = t[1]
            elif t[0] == "usemtl":
                mat = t[1]
            elif t[0] == "f":
                polys.append((obj, mat, [verts[int(i.split("/")[0]) - 1] for i in t[1:]]))
    return polys


def camera_rays(cam):
    """Origin and unit ray directions (H, W, 3) through the pixel centres, following Blender
    and Cycles: the sensor covers the fitted side of the frame measured in pixels times pixel
    aspect; AUTO fits the longer side with the sensor width, HORIZONTAL the width with the
    sensor width, VERTICAL the height with the sensor height; shift is in units of the fitted
    side; the camera looks down its local -Z with +Y up."""
    import numpy as np

    w, h = cam["width"], cam["height"]
    asp = cam["pixel_aspect"]
    wp, hp = w * asp, h * 1.0  # the frame in units of one pixel's height
    fit = cam["sensor_fit"]
    if fit == "auto":
        horizontal = wp >= hp
        sensor = cam["sensor_width_mm"]
    elif fit == "horizontal":
        horizontal, sensor = True, cam["sensor_width_mm"]
    else:
        horizontal, sensor = False, cam["sensor_height_mm"]
    extent = wp if horizontal else hp
    scale = sensor / extent / cam["focal_length_mm"]  # tan per unit
    i = (np.arange(w) + 0.5) * asp - wp / 2 + cam["shift_x"] * extent
    j = hp / 2 - (np.arange(h) + 0.5) + cam["shift_y"] * extent
    x, y = np.meshgrid(i * scale, j * scale)
    d = np.stack([x, y, -np.ones_like(x)], axis=-1)
    m = np.array(cam["matrix_world"], dtype=np.float64)
    dw = d @ m[:3, :3].T
    dw /= np.linalg.norm(dw, axis=-1, keepdims=True)
    return m[:3, 3], dw


def ray_cast(polys, cam):
    """Per pixel: index into polys of the nearest polygon hit by the centre ray (-1: none),
    its distance, and per polygon its in-plane hit mask (for the notch test)."""
    import numpy as np

    o, d = camera_rays(cam)
    h, w = d.shape[:2]
    best = np.full((h, w), np.inf)
    which = np.full((h, w), -1, dtype=np.int64)
    for k, (_obj, _mat, pts) in enumerate(polys):
        p = np.array(pts, dtype=np.float64)
        n = np.zeros(3)
        for a in range(len(p)):  # Newell normal
            b = p[(a + 1) % len(p)]
            n += np.cross(p[a], b)
        n /= np.linalg.norm(n)
        denom = d @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((p[0] - o) @ n) / denom
        ok = np.isfinite(t) & (t > 1e-9)
        hit = o + d * t[..., None]
        ax = int(np.argmax(np.abs(n)))
        u_ax, v_ax = [c for c in range(3) if c != ax]
        hu, hv = hit[..., u_ax], hit[..., v_ax]
        pu, pv = p[:, u_ax], p[:, v_ax]
        inside = np.zeros((h, w), dtype=bool)
        for a in range(len(p)):  # even-odd crossing test, fine for concave polygons
            b = (a + 1) % len(p)
            cond = (pv[a] > hv) != (pv[b] > hv)
            with np.errstate(divide="ignore", invalid="ignore"):
                xc = pu[a] + (hv - pv[a]) * (pu[b] - pu[a]) / (pv[b] - pv[a])
            inside ^= cond & (hu < xc)
        sel = ok & inside & (t < best)
        best[sel] = t[sel]
        which[sel] = k
    return which, best


def notch_pixels(polys, cam, pane_index):
    """Pixels whose centre ray meets pane 1's plane inside the bounding rectangle of the U but
    in its notch, with nothing nearer: there the U must not show."""
    import numpy as np

    which, best = ray_cast(polys, cam)
    _o, _m, pts = polys[pane_index]
    p = np.array(pts)
    lo, hi = p.min(axis=0), p.max(axis=0)
    box = [(lo[0], lo[1], lo[2]), (lo[0], hi[1], lo[2]), (lo[0], hi[1], hi[2]),
           (lo[0], lo[1], hi[2])]  # the U lies in a plane x = const
    wb, tb = ray_cast([("box", "box", box)], cam)
    in_box = (wb == 0) & (tb < best + 1e-9)
    return in_box & (which != pane_index)


def preview():
    import numpy as np

    polys = [(n, m, [g[0][i] for i in f]) for n, m, _i, _p, g in OBJECTS for f in g[1]]
    for f in FRAMES:
        key = CAMERA_KEYS[f]
        yaw = math.radians(key["yaw_deg"])
        rx = math.radians(90.0)
        # matrix_world = T * Rz(yaw) * Rx(90)
        cz, sz, cx, sx = math.cos(yaw), math.sin(yaw), math.cos(rx), math.sin(rx)
        rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
        rxm = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
        m = np.eye(4)
        m[:3, :3] = rz @ rxm
        m[:3, 3] = key["location"]
        cam = camera_json_obj(m.tolist(), "auto", WIDTH, HEIGHT, 1.0, 1.0)
        which, _ = ray_cast(polys, cam)
        chars = {}
        for k, (obj, mat, _pts) in enumerate(polys):
            chars[k] = {"Glass_clear": "0" if obj.startswith("Pane0") else "1",
                        "Tinted_bronze": "2"}.get(mat, mat[0].lower())
        print("frame", f)
        for row in range(0, HEIGHT, 3):
            print("".join(chars.get(int(which[row, c]), " ") for c in range(0, WIDTH, 2)))
        for k, (obj, mat, _p) in enumerate(polys):
            if mat in GLASS_IDS:
                ys, xs = np.nonzero(which == k)
                print(obj, len(ys), "rows", ys.min(), ys.max(), "cols", xs.min(), xs.max())


# --------------------------------------------------------------------------------------------
# Step 2: check (numpy + OpenEXR)
# --------------------------------------------------------------------------------------------

def murmur3_32(data, seed=0):
    c1, c2 = 0xCC9E2D51, 0x1B873593
    h = seed
    n = len(data) // 4
    for i in range(n):
        k = struct.unpack_from("<I", data, 4 * i)[0]
        k = (k * c1) & 0xFFFFFFFF
        k = ((k << 15) | (k >> 17)) & 0xFFFFFFFF
        k = (k * c2) & 0xFFFFFFFF
        h ^= k
        h = ((h << 13) | (h >> 19)) & 0xFFFFFFFF
        h = (h * 5 + 0xE6546B64) & 0xFFFFFFFF
    tail = data[4 * n:]
    k = 0
    if len(tail) >= 3:
        k ^= tail[2] << 16
    if len(tail) >= 2:
        k ^= tail[1] << 8
    if len(tail) >= 1:
        k ^= tail[0]
        k = (k * c1) & 0xFFFFFFFF
        k = ((k << 15) | (k >> 17)) & 0xFFFFFFFF
        k = (k * c2) & 0xFFFFFFFF
        h ^= k
    h ^= len(data)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & 0xFFFFFFFF
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & 0xFFFFFFFF
    h ^= h >> 16
    return h


def cryptomatte_hash(name):
    """Cryptomatte's id of a name: MurmurHash3_32 (seed 0) of its UTF-8 bytes, with the
    exponent kept away from 0 and 255 so that the bits are a finite, normal float32."""
    h = murmur3_32(name.encode("utf-8"))
    exp = (h >> 23) & 0xFF
    if exp == 0 or exp == 255:
        h ^= 1 << 23
    return h


def read_exr(path):
    """{channel: array}, [(part name, [channel names], dtypes)], header of part 0."""
    import OpenEXR

    f = OpenEXR.File(path, separate_channels=True)
    chans, parts = {}, []
    for part in f.parts:
        names = list(part.channels)
        for n, ch in part.channels.items():
            chans[n] = ch.pixels
        pname = part.name() if callable(getattr(part, "name", None)) else None
        parts.append({"name": pname, "channels": names,
                      "types": [str(part.channels[n].pixels.dtype) for n in names]})
    header = {k: f.parts[0].header[k] for k in f.parts[0].header}
    return chans, parts, header


def _find(chans, *suffixes):
    for s in suffixes:
        for n in chans:
            if n.endswith(s):
                return n
    return None


def _simple_header(header):
    import numpy as np

    out = {}
    for k, v in header.items():
        if k in ("channels",):
            continue
        if isinstance(v, bytes):
            v = v.decode("utf-8", "replace")
        if isinstance(v, (str, int, float, bool)):
            out[k] = v
        elif isinstance(v, np.ndarray) and v.size <= 16:
            out[k] = v.tolist()
        elif isinstance(v, (tuple, list)) and len(v) <= 4:
            try:
                out[k] = json.loads(json.dumps(v, default=lambda x: np.asarray(x).tolist()))
            except TypeError:
                out[k] = repr(v)
        elif hasattr(v, "name") and not callable(v.name):
            out[k] = v.name
    return out


def check_all(out_dir, geo_dir):
    import numpy as np
    import OpenEXR

    with open(os.path.join(out_dir, "check.json")) as fh:
        report = json.load(fh)
    report["reader"] = {"package": "OpenEXR (python)", "version": OpenEXR.__version__,
                        "numpy": np.__version__, "python": sys.version.split()[0]}
    problems = []
    polys = read_obj(os.path.join(geo_dir, "scene.obj"))
    pane_poly = {}
    for k, (obj, mat, _p) in enumerate(polys):
        if mat in GLASS_IDS:
            pane_poly[len(pane_poly)] = k
    mat_index = {m: v[2] for m, v in MATERIALS.items()}
    files = {}
    index_report = {}
    cases = [("index.%04d.exr" % f, "camera.%04d.json" % f, str(f)) for f in FRAMES]
    if os.path.exists(os.path.join(out_dir, "index_portrait.exr")):
        cases.append(("index_portrait.exr", "camera_portrait.json", "portrait"))
    elif report["render"]["portrait"]["written"]:
        problems.append("index_portrait.exr is missing")
    cases.append(("index_portrait_emission.exr", "camera_portrait.json", "portrait_emission"))
    id_maps = {}
    for fname, cname, key in cases:
        path = os.path.join(out_dir, fname)
        chans, parts, header = read_exr(path)
        files[fname] = {"size_bytes": os.path.getsize(path), "parts": parts,
                        "header": _simple_header(header)}
        if key == "portrait_emission":  # R = material index, G = object index, B = surface
            ma, ob, surf = chans["R"], chans["G"], chans["B"]
            bad = ~np.isin(surf, (0.0, 1.0)) | ((surf == 0) & ((ma != 0) | (ob != 0)))
            if np.any(bad) or not np.all(np.isin(ma, (0.0, 1.0, 5.0))):
                problems.append("%s: values are not exact ids" % fname)
        else:
            ma = chans[_find(chans, "IndexMA.X", "Material Index.X")]
            ob = chans[_find(chans, "IndexOB.X", "Object Index.X")]
        id_maps[key] = (ma, ob)
        with open(os.path.join(geo_dir, cname)) as fh:
            cam = json.load(fh)
        which, _ = ray_cast(polys, cam)
        ref = np.array([mat_index[p[1]] for p in polys] + [0])[which]
        agree = ref == ma
        rgb = [chans[n] for n in chans if ".Combined." in n and n[-1] in "RGB"]
        entry = {
            "camera": cname,
            "combined_rgb_nonzero_pixels": int(sum(np.count_nonzero(c) for c in rgb)),
            "width": int(ma.shape[1]), "height": int(ma.shape[0]),
            "material_index_values": sorted(float(v) for v in np.unique(ma)),
            "pixels_id_1": int(np.count_nonzero(ma == 1)),
            "pixels_id_5": int(np.count_nonzero(ma == 5)),
            "pixels_per_pane": {str(p): int(np.count_nonzero(ob == p + 1)) for p in range(3)},
            "reference_ray_cast": {
                "pixels_id_1": int(np.count_nonzero(ref == 1)),
                "pixels_id_5": int(np.count_nonzero(ref == 5)),
                "agreeing_fraction": float(np.count_nonzero(agree)) / agree.size,
                "disagreeing_pixels": [[int(y), int(x), float(ma[y, x]), int(ref[y, x])]
                                       for y, x in np.argwhere(~agree)][:50],
            },
        }
        for gid in (1, 5):
            where = np.argwhere(ma == gid)
            if len(where) == 0:
                problems.append("%s: no pixel with id %d" % (fname, gid))
            else:
                entry["id_%d_rows" % gid] = [int(where[:, 0].min()), int(where[:, 0].max())]
                entry["id_%d_cols" % gid] = [int(where[:, 1].min()), int(where[:, 1].max())]
                if (where[:, 0].min() < 2 or where[:, 1].min() < 2
                        or where[:, 0].max() > ma.shape[0] - 3
                        or where[:, 1].max() > ma.shape[1] - 3):
                    problems.append("%s: id %d touches the frame edge" % (fname, gid))
        notch = notch_pixels(polys, cam, pane_poly[1])
        # Notch pixels well inside (3x3 neighbourhood all notch): not one of them may be the U.
        inner = fixture_scene.interior(notch, 1)
        entry["u_notch"] = {
            "pixels": int(np.count_nonzero(notch)),
            "interior_pixels": int(np.count_nonzero(inner)),
            "pixels_showing_pane_1": int(np.count_nonzero(notch & (ob == 2))),
            "interior_pixels_showing_pane_1": int(np.count_nonzero(inner & (ob == 2))),
        }
        if entry["u_notch"]["interior_pixels"] < 10:
            problems.append("%s: the U notch covers too few pixels" % fname)
        if entry["u_notch"]["interior_pixels_showing_pane_1"]:
            problems.append("%s: the U notch shows pane 1" % fname)
        if entry["reference_ray_cast"]["agreeing_fraction"] < 0.999:
            problems.append("%s: reference ray cast agrees on only %.5f" %
                            (fname, entry["reference_ray_cast"]["agreeing_fraction"]))
        if key == "portrait_emission":
            entry["pixel_aspect_ratio_attribute"] = _simple_header(header).get("pixelAspectRatio")
            entry["surface_pixels"] = int(np.count_nonzero(chans["B"] == 1))
            if "portrait" in id_maps:
                pm, po = id_maps["portrait"]
                entry["identical_to_index_portrait"] = bool(np.array_equal(pm, ma)
                                                            and np.array_equal(po, ob))
                if not entry["identical_to_index_portrait"]:
                    problems.append("%s differs from index_portrait.exr" % fname)
        index_report[key] = entry

    # Beauty: Cryptomatte against the glass_coverage AOV.
    path = os.path.join(out_dir, "beauty.0001.exr")
    chans, parts, header = read_exr(path)
    files["beauty.0001.exr"] = {"size_bytes": os.path.getsize(path), "parts": parts,
                                "header": _simple_header(header)}
    crypto = {}
    for k, v in header.items():
        if k.startswith("cryptomatte/"):
            crypto[k] = v.decode() if isinstance(v, bytes) else v
    manifest_key = [k for k in crypto if k.endswith("/manifest")]
    if len(manifest_key) != 1:
        problems.append("beauty: %d Cryptomatte manifests" % len(manifest_key))
        manifest = {}
    else:
        manifest = json.loads(crypto[manifest_key[0]])
    for name in GLASS_IDS:
        if name not in manifest:
            problems.append("beauty: manifest lacks %s" % name)
    hash_check = {n: {"manifest": h, "murmur3": "%08x" % cryptomatte_hash(n)}
                  for n, h in manifest.items()}
    for n, v in hash_check.items():
        if v["manifest"] != v["murmur3"]:
            problems.append("beauty: manifest hash of %s is not MurmurHash3 of the name" % n)
    layers = sorted({n.rsplit(".", 1)[0] for n in chans if ".CryptoMaterial" in n})
    glass_hashes = {int(manifest[n], 16) for n in GLASS_IDS if n in manifest}
    cov_sum = np.zeros(next(iter(chans.values())).shape, dtype=np.float64)
    rank_total = np.zeros_like(cov_sum)
    for layer in layers:
        for id_c, cov_c in (("r", "g"), ("b", "a")):
            ids = chans[layer + "." + id_c].astype(np.float32).view(np.uint32)
            cov = chans[layer + "." + cov_c].astype(np.float64)
            rank_total += cov
            is_glass = np.isin(ids, list(glass_hashes)) & (cov > 0)
            cov_sum += np.where(is_glass, cov, 0.0)
    aov = chans[_find(chans, "glass_coverage.X", "glass_coverage.V")].astype(np.float64)
    diff = np.abs(cov_sum - aov)
    ma_b = chans[_find(chans, "IndexMA.X", "Material Index.X")]
    facing = chans[_find(chans, "facing.X", "facing.V")].astype(np.float64)
    plane = chans[_find(chans, "plane.X", "plane.V")].astype(np.float64)
    # Pixels fully covered by one pane (glass_coverage exactly 1 and, in the ray cast of
    # frame 1, the same pane at the pixel centre and its 8 neighbours): there the plane AOV is
    # the pane's plane index and facing is close to |cos theta| at the pixel centre (the AOVs
    # are filter-weighted averages of the samples, like every pass of the beauty render).
    with open(os.path.join(geo_dir, "camera.0001.json")) as fh:
        cam1 = json.load(fh)
    which1, _ = ray_cast(polys, cam1)
    _o1, d1 = camera_rays(cam1)
    cos_ref = np.zeros_like(facing)
    pane_of = np.full(which1.shape, -1)
    for p, k in pane_poly.items():
        pts = np.array(polys[k][2])
        n = np.zeros(3)
        for a in range(len(pts)):
            n += np.cross(pts[a], pts[(a + 1) % len(pts)])
        n /= np.linalg.norm(n)
        sel = which1 == k
        cos_ref[sel] = np.abs(d1[sel] @ n)
        pane_of[sel] = p
    pad = np.pad(pane_of, 1, constant_values=-2)
    inner = (pane_of >= 0) & (aov == 1.0)
    for dy in range(3):
        for dx in range(3):
            inner &= pad[dy:dy + pane_of.shape[0], dx:dx + pane_of.shape[1]] == pane_of
    # The transmission pass: the same as the beauty render where no glass is in the pixel
    # footprint (same seed, same camera rays), different where glass covers the pixel.
    tchans, tparts, theader = read_exr(os.path.join(out_dir, "trans.0001.exr"))
    rgb_b = np.stack([chans[_find(chans, "Combined." + c)].astype(np.float64) for c in "RGB"])
    rgb_t = np.stack([tchans[_find(tchans, "Combined." + c)].astype(np.float64) for c in "RGB"])
    tdiff = np.abs(rgb_b - rgb_t).max(axis=0)
    no_glass, full_glass = aov == 0, aov == 1
    beauty = {
        "cryptomatte_headers": {k: (v if not k.endswith("/manifest") else json.loads(v))
                                for k, v in crypto.items()},
        "cryptomatte_layers": layers,
        "manifest_attribute": manifest_key[0] if manifest_key else None,
        "manifest_hash_check": hash_check,
        "glass_coverage_vs_cryptomatte": {
            "max_abs_difference": float(diff.max()),
            "mean_abs_difference": float(diff.mean()),
            "pixels_differing_over_1e-3": int(np.count_nonzero(diff > 1e-3)),
            "pixels_with_glass_coverage": int(np.count_nonzero(aov > 0)),
            "pixels_full_coverage": int(np.count_nonzero(aov == 1)),
            "pixels_fractional_coverage": int(np.count_nonzero((aov > 0) & (aov < 1))),
            "coverage_values_are_multiples_of_1_16": bool(np.all(aov * 16 == np.round(aov * 16))),
        },
        "cryptomatte_all_ranks_coverage_sum": {
            "min": float(rank_total.min()), "max": float(rank_total.max()),
            # The world (sky) has no material: pixels seeing only sky sum to 0.
            "pixels_sum_0": int(np.count_nonzero(rank_total == 0)),
            "pixels_sum_below_1": int(np.count_nonzero(rank_total < 1 - 1e-6)),
            "pixels_sum_0_where_ray_cast_hits_nothing": int(np.count_nonzero(
                (rank_total == 0) & (which1 < 0))),
        },
        "material_index_values": sorted(float(v) for v in np.unique(ma_b)),
        "full_coverage_interior_pixels": {str(p): int(np.count_nonzero(inner & (pane_of == p)))
                                          for p in range(3)},
        "plane_aov_on_full_coverage_interior": {
            str(p): sorted(float(v) for v in np.unique(plane[inner & (pane_of == p)]))
            for p in range(3)},
        "facing_vs_reference_cos_on_full_coverage_interior_max_abs":
            float(np.abs(facing - cos_ref)[inner].max()),
        # The AOVs are written by the glass only, so their filtered value is value x
        # coverage: divided by glass_coverage they give the glass's own value again.
        "aov_divided_by_coverage_on_all_glass_pixels": {
            "plane_max_distance_to_an_integer": float(np.abs(
                plane[aov > 0] / aov[aov > 0] - np.round(plane[aov > 0] / aov[aov > 0])).max()),
            "plane_values": sorted({float(v) for v in np.round(plane[aov > 0] / aov[aov > 0])}),
            "facing_vs_reference_cos_max_abs_where_centre_on_glass":
                float(np.abs(facing / np.where(aov > 0, aov, 1) - cos_ref)[
                    (aov > 0) & (pane_of >= 0)].max()),
        },
        "trans_vs_beauty_combined_rgb": {
            "pixels_without_glass": int(np.count_nonzero(no_glass)),
            "identical_there": int(np.count_nonzero(no_glass & (tdiff == 0))),
            "max_abs_difference_there": float(tdiff[no_glass].max()),
            "pixels_full_glass": int(np.count_nonzero(full_glass)),
            "differing_there": int(np.count_nonzero(full_glass & (tdiff > 0))),
        },
    }
    for p in range(3):
        if beauty["plane_aov_on_full_coverage_interior"][str(p)] != [float(p)]:
            problems.append("beauty: plane AOV on pane %d is %r" %
                            (p, beauty["plane_aov_on_full_coverage_interior"][str(p)]))
    if diff.max() > 1e-3:
        problems.append("beauty: glass_coverage and Cryptomatte differ by %g" % diff.max())
    trans_path = os.path.join(out_dir, "trans.0001.exr")
    files["trans.0001.exr"] = {"size_bytes": os.path.getsize(trans_path), "parts": tparts,
                               "header": _simple_header(theader)}
    report["index"] = index_report
    report["beauty"] = beauty
    report["files"] = files
    report["problems"] = problems
    path = os.path.join(out_dir, "check.json")
    fixture_scene.write_json(path, report)
    if problems:
        sys.exit("check failed: " + "; ".join(problems))


def main():
    opts = parse_args(sys.argv)
    if opts["mode"] == "preview":
        preview()
    elif opts["mode"] == "check":
        check_all(opts["out"], opts["geometry"])
    else:
        render_all(opts["out"], opts["geometry"], opts["write_geometry"], opts["working_space"])


if __name__ == "__main__":
    main()
