#!/usr/bin/env python3
"""Render the reflection passes of the `blender/masks` fixture scene, one per glass plane.

glassdb composes, per glass pixel, out = refl · r(θ) + trans · t(θ), where `refl` is the scene
as seen in the mirror of that pixel's glass plane, rendered without glass. This script makes
those passes for frame 1 of the scene built by `make_mask_fixtures.py` (imported as a module,
so the scene is the same object for object; that script is not changed):

For each glass plane k (n·x + d = 0, from pane k's mesh in world space, n pointing to the real
camera's side):

- the camera gets the matrix R_k @ matrix_world(frame 1), R_k the reflection about the plane
  (upper 3 × 3 I − 2nnᵀ, translation −2dn, determinant −1), after frame 1 was evaluated and
  the camera's animation removed (so nothing sets the matrix back). Cycles renders the
  virtual (mirror) camera's image as it is: lens, shift and sensor fit unchanged, no flip;
  the pixel where the real camera would see the mirror image R_k·Q of a point Q shows Q;
- the glass objects are hidden from the render (`hide_render`);
- every material becomes Mix Shader(its own BSDF, Transparent BSDF) with factor
  Is Camera Ray × [m·P + e > 0] (Geometry Position → Vector Math Dot Product with m → Math Add
  e → Math Greater Than 0 → Math Multiply with Light Path Is Camera Ray), m = −n, e = −d: what
  lies behind the mirror (on the side away from the real camera) is not seen by camera rays,
  but still casts light and shadows;
- film transparent off (the grey world where nothing is hit); the beauty's settings: 160 × 120,
  16 samples, seed 0, no denoising, 2 threads, Blackman-Harris 1.5 px, multilayer EXR with
  only Combined, half, ZIP.

Two steps, one script:

1. Render (Blender 3.4 binary or the bpy 5.0.1 module):

       blender -b --factory-startup -noaudio --python-exit-code 1 \\
           -P scripts/blender/make_reflection_passes.py -- \\
           --out fixtures/blender/masks/b34 --geometry fixtures/blender/masks --scratch DIR
       /work/bpyvenv/bin/python scripts/blender/make_reflection_passes.py \\
           --out fixtures/blender/masks/b50 --geometry fixtures/blender/masks --scratch DIR

   writes refl_0.0001.exr, refl_1.0001.exr, refl_2.0001.exr into --out (`--working-space NAME`,
   Blender 5.0+: the scene in that working colour space, as make_mask_fixtures.py's option of
   the same name makes it). Into --scratch (not
   committed): the whole fixture set again (`make_mask_fixtures.render_all` builds the scene
   and renders it; it also compares its scene.obj and cameras with --geometry and exits 1 on
   any difference), `trans_again.0001.exr` (the transmission pass rendered again after the
   scene was put back, to prove it is the fixtures' scene), `refl_index_k.exr` (the reflected
   camera, 1 sample at the pixel centre, Object Index with the opaque objects numbered 11-14),
   `refl_without_behind_k.exr` (the pass with the objects wholly behind plane k hidden) and
   `reflection_info.json` (planes, matrices as Blender read them back, determinants).

2. Check (plain Python with numpy and OpenEXR==3.5.3, no Blender):

       python scripts/blender/make_reflection_passes.py --check \\
           --out fixtures/blender/masks/b34 --geometry fixtures/blender/masks --scratch DIR

   prints a JSON report (also written to DIR/reflection_check.json) and exits 1 when a check
   fails: determinant −1 and mirrored camera position; the index render against a numpy ray
   cast of scene.obj's opaque polygons, clipped to the camera's side of the plane, mirrored
   and seen through the REAL camera (camera.0001.json); single points Q on the floor and boxes
   whose mirror image is projected through the real camera; the EXR layout; the world colour
   where nothing is hit; sunlit diffuse points equal to trans.0001.exr where the real camera
   sees them directly; shadows of objects behind the mirror; trans_again equal to the
   committed trans.0001.exr.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402
import make_mask_fixtures as mmf  # noqa: E402

PLANES = (0, 1, 2)
FRAME = 1
# Object pass indices for the check renders only (in the fixtures the opaque objects have 0).
CHECK_IDS = {"Floor": 11, "BackWall": 12, "Box_A": 13, "Box_B": 14}
REFL_NAME = "refl_%d.%04d.exr"


def parse_args(argv):
    opts = fixture_scene.parse_options(
        argv, "make_reflection_passes.py", __doc__,
        {"out": None, "geometry": None, "scratch": None, "mode": "render",
         "working_space": None},
        paths=("out", "geometry", "scratch"), values=("working-space",),
        flags={"--check": ("mode", "check")})
    if not (opts["out"] and opts["geometry"] and opts["scratch"]):
        sys.exit("make_reflection_passes.py: --out DIR, --geometry DIR and --scratch DIR are "
                 "required")
    return opts


def plane_of(points, camera_pos):
    """(n, d) of the plane through points (Newell normal, float64), n·x + d = 0, oriented so
    that the camera is on the positive side; and the largest |n·v + d| of the points."""
    n = [0.0, 0.0, 0.0]
    m = len(points)
    for a in range(m):
        p, q = points[a], points[(a + 1) % m]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    ln = math.sqrt(sum(c * c for c in n))
    n = [c / ln for c in n]
    c = [sum(p[i] for p in points) / m for i in range(3)]
    d = -sum(n[i] * c[i] for i in range(3))
    if sum(n[i] * camera_pos[i] for i in range(3)) + d < 0:
        n, d = [-x for x in n], -d
    off = max(abs(sum(n[i] * p[i] for i in range(3)) + d) for p in points)
    return n, d, off


def reflection_rows(n, d):
    """4 × 4 reflection about n·x + d = 0 (rows, for column vectors)."""
    rows = [[(1.0 if i == j else 0.0) - 2.0 * n[i] * n[j] for j in range(3)] + [-2.0 * d * n[i]]
            for i in range(3)]
    rows.append([0.0, 0.0, 0.0, 1.0])
    return rows


# --------------------------------------------------------------------------------------------
# Step 1: render (bpy)
# --------------------------------------------------------------------------------------------

def render_reflections(out_dir, geo_dir, scratch, working_space=None):
    import bpy
    from mathutils import Matrix, Vector

    os.makedirs(out_dir, exist_ok=True)
    fixtures_dir = os.path.join(scratch, "fixtures")
    os.makedirs(fixtures_dir, exist_ok=True)
    # The scene, exactly as make_mask_fixtures builds it (it renders its own fixtures into the
    # scratch folder on the way and fails if its scene.obj / cameras differ from geo_dir's).
    mmf.render_all(fixtures_dir, geo_dir, False, working_space)
    version = tuple(bpy.app.version)
    scene = bpy.context.scene
    r = scene.render
    cam = scene.camera
    cam_data = cam.data

    # render_all ends with every material's surface turned into an Emission of its ids and
    # the world at strength 0 (for its last render): put the shading back.
    bsdf_types = ("ShaderNodeBsdfPrincipled", "ShaderNodeBsdfDiffuse")
    for mat in bpy.data.materials:
        nt = mat.node_tree
        out = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial"][0]
        for node in list(nt.nodes):
            if node.bl_idname == "ShaderNodeCombineColor":
                for link in list(node.inputs[1].links):
                    nt.nodes.remove(link.from_node)  # the Object Info node added with it
        for node in list(nt.nodes):
            if node.bl_idname in ("ShaderNodeCombineColor", "ShaderNodeEmission"):
                nt.nodes.remove(node)
        bsdfs = [n for n in nt.nodes if n.bl_idname in bsdf_types]
        if len(bsdfs) != 1:
            sys.exit("%s: %d BSDF nodes" % (mat.name, len(bsdfs)))
        nt.links.new(bsdfs[0].outputs["BSDF"], out.inputs["Surface"])
    world_bg = [n for n in scene.world.node_tree.nodes if n.bl_idname == "ShaderNodeBackground"]
    world_bg[0].inputs["Strength"].default_value = 1.0

    # A fresh view layer named like the old one: Blender 3.4 cannot remove the AOVs that
    # render_all added, and only Combined is wanted.
    old_vl = scene.view_layers[0]
    vl = scene.view_layers.new("ReflectionLayer")
    scene.view_layers.remove(old_vl)
    vl.name = "ViewLayer"
    for attr in ("use_pass_z", "use_pass_mist", "use_pass_normal", "use_pass_position",
                 "use_pass_material_index", "use_pass_object_index",
                 "use_pass_cryptomatte_material", "use_pass_cryptomatte_object",
                 "use_pass_cryptomatte_asset"):
        setattr(vl, attr, False)
    vl.use_pass_combined = True
    if hasattr(vl, "cycles"):
        vl.cycles.use_denoising = False
    if len(vl.aovs):
        sys.exit("the new view layer has AOVs")

    # Render settings of the beauty / transmission passes (render_all left the portrait's).
    r.resolution_x, r.resolution_y = mmf.WIDTH, mmf.HEIGHT
    r.pixel_aspect_x, r.pixel_aspect_y = 1.0, 1.0
    r.resolution_percentage = 100
    r.film_transparent = False
    cam_data.sensor_fit = "AUTO"
    cam_data.sensor_width = mmf.SENSOR_W_MM
    cam_data.sensor_height = mmf.SENSOR_H_MM
    scene.cycles.samples = mmf.BEAUTY_SAMPLES
    scene.cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    scene.cycles.filter_width = 1.5
    scene.cycles.film_exposure = 1.0
    im = r.image_settings

    fixture_scene.set_exr_format(im, multilayer=True, half=True)

    def render_to(directory, name):
        return fixture_scene.render_still(scene, directory, name)

    glass = [bpy.data.objects[name] for name, _m, _i, plane, _g in mmf.OBJECTS
             if plane is not None]
    opaque = [bpy.data.objects[name] for name, _m, _i, plane, _g in mmf.OBJECTS
              if plane is None]

    # Proof that the scene is back to the fixtures' one: the transmission pass again, compared
    # (by --check) with the committed trans.0001.exr.
    scene.frame_set(FRAME)
    for obj in glass:
        obj.visible_camera = False
    render_to(scratch, "trans_again.0001.exr")
    for obj in glass:
        obj.visible_camera = True

    # The camera of frame 1, then no animation.
    scene.frame_set(FRAME)
    m_real = cam.matrix_world.copy()
    with open(os.path.join(geo_dir, "camera.%04d.json" % FRAME)) as fh:
        cam_json = json.load(fh)
    json_diff = max(abs(m_real[i][j] - cam_json["matrix_world"][i][j])
                    for i in range(4) for j in range(4))
    if json_diff > 1e-6:
        sys.exit("frame %d camera differs from camera.%04d.json by %g" % (FRAME, FRAME, json_diff))
    cam.animation_data_clear()
    scene.frame_set(FRAME)
    if cam.matrix_world != m_real:
        sys.exit("the camera moved when its animation was removed")
    c_real = m_real.translation.copy()

    # Glass out of the render.
    for obj in glass:
        obj.hide_render = True

    # Every material: its BSDF, or a Transparent BSDF for camera rays behind the mirror.
    half_space = []
    for mat in bpy.data.materials:
        nt = mat.node_tree
        out = [n for n in nt.nodes if n.bl_idname == "ShaderNodeOutputMaterial"][0]
        bsdf = [n for n in nt.nodes if n.bl_idname in bsdf_types][0]
        new_node = fixture_scene.new_node
        geo = new_node(nt, "ShaderNodeNewGeometry", (-1000, 400))
        dot = new_node(nt, "ShaderNodeVectorMath", (-800, 400), "DOT_PRODUCT")
        add = new_node(nt, "ShaderNodeMath", (-600, 400), "ADD")
        gt = new_node(nt, "ShaderNodeMath", (-400, 400), "GREATER_THAN")
        gt.inputs[1].default_value = 0.0
        lp = new_node(nt, "ShaderNodeLightPath", (-400, 700))
        mul = new_node(nt, "ShaderNodeMath", (-200, 400), "MULTIPLY")
        tr = new_node(nt, "ShaderNodeBsdfTransparent", (0, 200))
        tr.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        mix = new_node(nt, "ShaderNodeMixShader", (150, 0))
        nt.links.new(geo.outputs["Position"], dot.inputs[0])
        nt.links.new(dot.outputs["Value"], add.inputs[0])
        nt.links.new(add.outputs["Value"], gt.inputs[0])
        nt.links.new(lp.outputs["Is Camera Ray"], mul.inputs[0])
        nt.links.new(gt.outputs["Value"], mul.inputs[1])
        nt.links.new(mul.outputs["Value"], mix.inputs["Fac"])
        nt.links.new(bsdf.outputs["BSDF"], mix.inputs[1])
        nt.links.new(tr.outputs["BSDF"], mix.inputs[2])
        nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
        half_space.append((dot, add))

    planes = {}
    for name, _m, _i, plane, _g in mmf.OBJECTS:
        if plane is None:
            continue
        obj = bpy.data.objects[name]
        pts = [tuple(float(c) for c in (obj.matrix_world @ v.co)) for v in obj.data.vertices]
        n, d, off = plane_of(pts, tuple(c_real))
        if off > 1e-6:
            sys.exit("%s is not planar (%g)" % (name, off))
        planes[plane] = {"pane": name, "n": n, "d": d, "corner_offset_max": off,
                         "reflection": reflection_rows(n, d)}

    # Pass 1: the reflection passes. Pass 2 (below): the index renders for the check.
    info = {"blender": {"version_string": bpy.app.version_string, "version": list(version),
                        "as_module": "--" not in sys.argv},
            "camera_frame_%d" % FRAME: [list(row) for row in m_real],
            "camera_vs_json_max_abs_difference": json_diff,
            "planes": {}}
    if working_space is not None:
        info["working_space"] = {"name": bpy.data.colorspace.working_space,
                                 "interop_id": bpy.data.colorspace.working_space_interop_id}
    for k in PLANES:
        p = planes[k]
        rk = Matrix(p["reflection"])
        m_virtual = rk @ m_real
        cam.matrix_world = m_virtual
        bpy.context.view_layer.update()
        back = cam.matrix_world.copy()
        mirrored_c = rk @ Vector(c_real)
        for dot, add in half_space:
            # behind the mirror: (-n)·P + (-d) > 0
            dot.inputs[1].default_value = tuple(-c for c in p["n"])
            add.inputs[1].default_value = -p["d"]
        size = render_to(out_dir, REFL_NAME % (k, FRAME))
        info["planes"][str(k)] = {
            "pane": p["pane"], "n": p["n"], "d": p["d"],
            "corner_offset_max": p["corner_offset_max"],
            "behind_test": "(%s)·P + %r > 0" % (", ".join(repr(-c) for c in p["n"]), -p["d"]),
            "reflection": p["reflection"],
            "reflection_determinant": rk.determinant(),
            "camera_matrix_set": [list(row) for row in m_virtual],
            "camera_matrix_read_back": [list(row) for row in back],
            "read_back_max_abs_difference": max(abs(back[i][j] - m_virtual[i][j])
                                                for i in range(4) for j in range(4)),
            "camera_determinant_read_back": back.determinant(),
            "camera_position_read_back": list(back.translation),
            "mirror_of_real_camera_position": list(mirrored_c),
            "position_max_abs_difference": max(abs(back.translation[i] - mirrored_c[i])
                                               for i in range(3)),
            "file": REFL_NAME % (k, FRAME), "size_bytes": size,
        }
        print("plane %d: det %.6f, position %s (mirror of %s)" %
              (k, back.determinant(), tuple(back.translation), tuple(c_real)))

    # Check renders (not committed), 1: each pass again with the objects that lie wholly
    # behind the mirror hidden from the render, to show that in the pass they still cast
    # shadows (the check compares the floor in their shadow).
    sun = [o for o in scene.objects if o.type == "LIGHT"][0]
    sun_dir = sun.matrix_world.to_3x3() @ Vector((0.0, 0.0, -1.0))
    info["sun_direction"] = list(sun_dir.normalized())
    for k in PLANES:
        p = planes[k]
        behind = []
        for obj in opaque:
            s_max = max(sum(p["n"][i] * (obj.matrix_world @ v.co)[i] for i in range(3)) + p["d"]
                        for v in obj.data.vertices)
            if s_max < 0:
                behind.append(obj)
        info["planes"][str(k)]["wholly_behind"] = [o.name for o in behind]
        if not behind:
            continue
        cam.matrix_world = Matrix(p["reflection"]) @ m_real
        bpy.context.view_layer.update()
        for dot, add in half_space:
            dot.inputs[1].default_value = tuple(-c for c in p["n"])
            add.inputs[1].default_value = -p["d"]
        for obj in behind:
            obj.hide_render = True
        render_to(scratch, "refl_without_behind_%d.exr" % k)
        for obj in behind:
            obj.hide_render = False

    # Check renders, 2: same cameras and materials, opaque objects numbered,
    # 1 sample through the pixel centre (0.01 px filter), Object Index; Combined black.
    for obj in opaque:
        obj.pass_index = CHECK_IDS[obj.name]
    scene.cycles.samples = mmf.INDEX_SAMPLES
    scene.cycles.filter_width = mmf.INDEX_FILTER_WIDTH
    scene.cycles.film_exposure = 0.0
    vl.use_pass_object_index = True
    for k in PLANES:
        p = planes[k]
        cam.matrix_world = Matrix(p["reflection"]) @ m_real
        bpy.context.view_layer.update()
        for dot, add in half_space:
            dot.inputs[1].default_value = tuple(-c for c in p["n"])
            add.inputs[1].default_value = -p["d"]
        render_to(scratch, "refl_index_%d.exr" % k)
    info["check_ids"] = CHECK_IDS
    fixture_scene.write_json(os.path.join(scratch, "reflection_info.json"), info)


# --------------------------------------------------------------------------------------------
# Step 2: check (numpy + OpenEXR)
# --------------------------------------------------------------------------------------------

def clip_front(pts, n, d):
    """Sutherland-Hodgman: the part of a convex polygon with n·x + d >= 0."""
    out = []
    m = len(pts)
    for a in range(m):
        p, q = pts[a], pts[(a + 1) % m]
        sp = sum(n[i] * p[i] for i in range(3)) + d
        sq = sum(n[i] * q[i] for i in range(3)) + d
        if sp >= 0:
            out.append(p)
        if (sp >= 0) != (sq >= 0):
            t = sp / (sp - sq)
            out.append(tuple(p[i] + t * (q[i] - p[i]) for i in range(3)))
    return out if len(out) >= 3 else None


def project(cam, q):
    """Continuous pixel coordinates (column, row; row 0 at the top, pixel centres at .5) of a
    world point through the camera JSON model of make_mask_fixtures.camera_rays, and its depth."""
    import numpy as np

    m = np.array(cam["matrix_world"], dtype=np.float64)
    pc = np.linalg.solve(m, np.array(list(q) + [1.0]))[:3]
    w, h, asp = cam["width"], cam["height"], cam["pixel_aspect"]
    wp, hp = w * asp, float(h)
    extent = wp if wp >= hp else hp  # AUTO fit (the fixtures' cameras)
    scale = cam["sensor_width_mm"] / extent / cam["focal_length_mm"]
    x, y = pc[0] / -pc[2] / scale, pc[1] / -pc[2] / scale
    col = (x - cam["shift_x"] * extent + wp / 2) / asp
    row = hp / 2 + cam["shift_y"] * extent - y
    return col, row, -pc[2]


def check_reflections(out_dir, geo_dir, scratch):
    import numpy as np

    with open(os.path.join(scratch, "reflection_info.json")) as fh:
        info = json.load(fh)
    with open(os.path.join(geo_dir, "camera.%04d.json" % FRAME)) as fh:
        cam = json.load(fh)
    polys = mmf.read_obj(os.path.join(geo_dir, "scene.obj"))
    opaque = [(o, m, p) for o, m, p in polys if m not in mmf.GLASS_IDS]
    m_real = np.array(cam["matrix_world"], dtype=np.float64)
    c_real = m_real[:3, 3]
    problems = []
    report = {"blender": info["blender"], "planes": {}}

    # The scene is the fixtures' scene: the transmission pass rendered again after the
    # shading was put back equals the committed one.
    again, _p, _h = mmf.read_exr(os.path.join(scratch, "trans_again.0001.exr"))
    committed, _p, _h = mmf.read_exr(os.path.join(out_dir, "trans.0001.exr"))
    same = sorted(again) == sorted(committed) and all(
        np.array_equal(again[c], committed[c]) for c in again)
    report["trans_again_identical_to_committed_trans"] = bool(same)
    if not same:
        problems.append("trans_again.0001.exr differs from trans.0001.exr")

    for k in PLANES:
        pi = info["planes"][str(k)]
        n, d = np.array(pi["n"]), pi["d"]
        rk = np.array(pi["reflection"])
        entry = {"pane": pi["pane"], "n": pi["n"], "d": d}
        # (1) the virtual camera
        det = pi["camera_determinant_read_back"]
        pos = np.array(pi["camera_position_read_back"])
        mirror = c_real - 2.0 * (n @ c_real + d) * n
        entry["virtual_camera"] = {
            "determinant": det,
            "position": pos.tolist(),
            "mirror_of_real_position": mirror.tolist(),
            "position_error": float(np.abs(pos - mirror).max()),
            "midpoint_on_plane": float(n @ ((pos + c_real) / 2) + d),
            "matrix_read_back_error": pi["read_back_max_abs_difference"],
            "numpy_det_R_times_M": float(np.linalg.det(rk @ m_real)),
        }
        if abs(det + 1.0) > 1e-5:
            problems.append("plane %d: camera determinant %r" % (k, det))
        if entry["virtual_camera"]["position_error"] > 1e-5:
            problems.append("plane %d: camera not at the mirror position" % k)
        if pi["read_back_max_abs_difference"] > 1e-5:
            problems.append("plane %d: Blender did not keep the matrix" % k)

        # The committed pass: layout.
        path = os.path.join(out_dir, REFL_NAME % (k, FRAME))
        chans, parts, header = mmf.read_exr(path)
        entry["file"] = {"name": REFL_NAME % (k, FRAME), "size_bytes": os.path.getsize(path),
                         "parts": parts, "compression": str(header.get("compression"))}
        want = ["ViewLayer.Combined.%s" % c for c in "ABGR"]
        if sorted(chans) != want or any(str(chans[c].dtype) != "float16" for c in chans):
            problems.append("plane %d: channels %r" % (k, {c: str(v.dtype)
                                                           for c, v in chans.items()}))
        rgb = np.stack([chans["ViewLayer.Combined.%s" % c].astype(np.float64) for c in "RGB"],
                       axis=-1)
        alpha = chans["ViewLayer.Combined.A"].astype(np.float64)

        # (2) what the virtual camera sees = the mirror image of the clipped scene seen by the
        # REAL camera. Index render of Blender vs numpy ray cast.
        idx, _p, _h = mmf.read_exr(os.path.join(scratch, "refl_index_%d.exr" % k))
        ob = idx[mmf._find(idx, "IndexOB.X", "Object Index.X")]
        mirrored, unclipped, source = [], [], []
        for j, (o, m, pts) in enumerate(opaque):
            c = clip_front(pts, n, d)
            if c is not None:
                mirrored.append((o, m, [tuple(rk[:3, :3] @ np.array(p) + rk[:3, 3]) for p in c]))
                source.append(j)  # the polygon of `opaque` it was clipped from
            unclipped.append((o, m, [tuple(rk[:3, :3] @ np.array(p) + rk[:3, 3]) for p in pts]))
        ids = lambda ps: np.array([CHECK_IDS[o] for o, _m, _p in ps] + [0])  # noqa: E731
        which, dist = mmf.ray_cast(mirrored, cam)
        ref = ids(mirrored)[which]
        agree = ref == ob
        which_u, _ = mmf.ray_cast(unclipped, cam)
        ref_u = ids(unclipped)[which_u]
        entry["index_vs_ray_cast"] = {
            "agreeing_fraction": float(np.count_nonzero(agree)) / agree.size,
            "disagreeing_pixels": [[int(y), int(x), float(ob[y, x]), int(ref[y, x])]
                                   for y, x in np.argwhere(~agree)][:20],
            "pixels_per_id": {str(int(v)): int(np.count_nonzero(ob == v)) for v in np.unique(ob)},
            "without_clipping_agreeing_fraction":
                float(np.count_nonzero(ref_u == ob)) / agree.size,
            "real_camera_as_is_agreeing_fraction": None,
        }
        # Sensitivity: the unreflected scene seen by the real camera (what a missing reflection
        # would give) and a left-right flipped image.
        which_r, _ = mmf.ray_cast([(o, m, p) for o, m, p in opaque], cam)
        ref_r = ids(opaque)[which_r]
        entry["index_vs_ray_cast"]["real_camera_as_is_agreeing_fraction"] = \
            float(np.count_nonzero(ref_r == ob)) / agree.size
        entry["index_vs_ray_cast"]["flipped_left_right_agreeing_fraction"] = \
            float(np.count_nonzero(ref[:, ::-1] == ob)) / agree.size
        # What the pass shows where the real camera sees pane k (index.0001.exr's Object
        # Index = plane + 1), the only pixels a composite takes from it.
        fx, _p, _h = mmf.read_exr(os.path.join(out_dir, "index.%04d.exr" % FRAME))
        pane = fx[mmf._find(fx, "IndexOB.X", "Object Index.X")] == k + 1
        entry["index_vs_ray_cast"]["inside_pane_pixels"] = {
            str(int(v)): int(np.count_nonzero(pane & (ob == v))) for v in np.unique(ob[pane])}
        if entry["index_vs_ray_cast"]["agreeing_fraction"] < 0.999:
            problems.append("plane %d: index render agrees with the ray cast on %.5f" %
                            (k, entry["index_vs_ray_cast"]["agreeing_fraction"]))

        # Single points Q on the floor and the boxes in front of the plane (box faces: 20 % in
        # from each corner towards the face's centre; floor: a 0.125 m grid): the
        # mirror image R Q projected through the real camera; Blender's index at that pixel must
        # be Q's object when Q is visible in the mirror (no mirrored polygon nearer on the ray
        # through R Q) and the pixel centre's ray cast shows the same object (not an edge).
        cands = []
        for o, m, pts in opaque:
            if o in ("Box_A", "Box_B"):
                p = np.array(pts)
                cen = p.mean(axis=0)
                cands.extend((o, v + 0.2 * (cen - v)) for v in p)
        cands.extend(("Floor", np.array([x / 8.0, y / 8.0, 0.0]))
                     for x in range(-32, 33) for y in range(-32, 33))
        points = []
        for o, q in cands:
            if n @ q + d <= 0.05:
                continue  # behind (or on) the mirror
            rq = rk[:3, :3] @ q + rk[:3, 3]
            col, row, depth = project(cam, rq)
            if depth <= 0 or not (0.5 <= col < cam["width"] - 0.5
                                  and 0.5 <= row < cam["height"] - 0.5):
                continue
            ci, ri = int(math.floor(col)), int(math.floor(row))
            t_q = float(np.linalg.norm(rq - c_real))
            dirn = (rq - c_real) / t_q
            nearest = min([t for t in (_ray_polygon(c_real, dirn, np.array(pp))
                                       for _o, _m, pp in mirrored) if t is not None] + [t_q])
            visible = nearest >= t_q - 1e-6
            got = int(ob[ri, ci])
            centre = int(ref[ri, ci])
            points.append({
                "object": o, "Q": [round(float(c), 4) for c in q],
                "mirror_image": [round(float(c), 4) for c in rq],
                "pixel": [round(col, 3), round(row, 3)], "visible": bool(visible),
                "ray_cast_at_pixel_centre": centre, "index_there": got,
                "refl_rgb_there": [round(float(c), 4) for c in rgb[ri, ci]],
            })
            if visible and centre == CHECK_IDS[o] and got != CHECK_IDS[o]:
                problems.append("plane %d: %s point %r shows id %d at (%d, %d)" %
                                (k, o, points[-1]["Q"], got, ci, ri))
        entry["points_first_15"] = points[:15]
        tested = [p for p in points
                  if p["visible"] and p["ray_cast_at_pixel_centre"] == CHECK_IDS[p["object"]]]
        entry["points_summary"] = {
            "in_frame": len(points),
            "visible": sum(1 for p in points if p["visible"]),
            "tested (visible, not on an edge)": len(tested),
            "tested_matching": sum(1 for p in tested
                                   if p["index_there"] == CHECK_IDS[p["object"]]),
            "tested_per_object": {o: sum(1 for p in tested if p["object"] == o)
                                  for o in ("Floor", "Box_A", "Box_B")},
        }
        if len(tested) < 3:
            problems.append("plane %d: fewer than 3 tested points" % k)

        # Objects wholly behind the mirror still cast shadows into the pass: floor pixels whose
        # (unmirrored) point is in their shadow are darker than in the render without them;
        # elsewhere the two differ only by noise of paths that met them.
        hidden = pi["wholly_behind"]
        if hidden:
            wo, _p, _h = mmf.read_exr(os.path.join(scratch, "refl_without_behind_%d.exr" % k))
            rgb_wo = np.stack([wo["ViewLayer.Combined.%s" % c].astype(np.float64)
                               for c in "RGB"], axis=-1)
            o_, dirs = mmf.camera_rays(cam)
            floor = ref == CHECK_IDS["Floor"]
            floor_in = fixture_scene.interior(floor, 2)
            to_sun = -np.array(info["sun_direction"])
            occluders = [np.array(pp) for o, _m, pp in opaque if o in hidden]
            shadow = np.zeros_like(floor)
            for y, x in np.argwhere(floor_in):
                hit = o_ + dirs[y, x] * dist[y, x]
                q = rk[:3, :3] @ hit + rk[:3, 3]  # the floor point itself (R is its own inverse)
                shadow[y, x] = any(_ray_polygon(q, to_sun, pp) is not None for pp in occluders)
            lit = floor_in & ~shadow
            lum, lum_wo = rgb.mean(axis=-1), rgb_wo.mean(axis=-1)
            entry["shadows_of_objects_behind"] = {
                "objects": hidden,
                "floor_pixels_in_their_shadow": int(np.count_nonzero(shadow)),
                "mean_in_shadow_with": float(lum[shadow].mean()) if shadow.any() else None,
                "mean_in_shadow_without": float(lum_wo[shadow].mean()) if shadow.any() else None,
                "floor_pixels_lit": int(np.count_nonzero(lit)),
                "mean_lit_with": float(lum[lit].mean()) if lit.any() else None,
                "mean_lit_without": float(lum_wo[lit].mean()) if lit.any() else None,
                "pixels_identical_outside_shadow": int(np.count_nonzero(
                    np.all(rgb == rgb_wo, axis=-1) & ~shadow)),
                "pixels_outside_shadow": int(np.count_nonzero(~shadow)),
            }
            if (np.count_nonzero(shadow) >= 10
                    and lum[shadow].mean() > 0.7 * lum_wo[shadow].mean()):
                problems.append("plane %d: no shadow of %r in the pass" % (k, hidden))

        # Diffuse surfaces look the same from every side: where the pass shows a floor or box
        # point Q well inside a face (5 x 5 interior of that face in the mirrored ray cast) that
        # the real camera also sees directly (5 x 5 interior of the same face in a ray cast
        # without glass),
        # the pass should equal trans.0001.exr (glass invisible to camera rays) at Q's pixel,
        # up to noise and sub-pixel position, unless Q lies in the sun shadow of a pane (the
        # panes are hidden from the reflection renders entirely, so they cast no shadow there;
        # in trans they do).
        tr, _p, _h = mmf.read_exr(os.path.join(out_dir, "trans.%04d.exr" % FRAME))
        rgb_tr = np.stack([tr["ViewLayer.Combined.%s" % c].astype(np.float64) for c in "RGB"],
                          axis=-1)
        which_d, _ = mmf.ray_cast(opaque, cam)
        direct = ids(opaque)[which_d]
        o_, dirs = mmf.camera_rays(cam)
        to_sun = -np.array(info["sun_direction"])
        panes = [np.array(pp) for _o, m_, pp in polys if m_ in mmf.GLASS_IDS]

        def interior(img, value):
            return fixture_scene.interior(img == value, 2)

        # Per pixel of the pass: its point Q, and what shades Q from the sun (0 nothing, 1 an
        # opaque object, 2 a pane); pixels next to a different class are left out (shadow
        # edges fall inside pixels differently in the two views).
        cls = np.full(ob.shape, -1)
        qs = np.zeros(ob.shape + (3,))
        opaque_np = [np.array(pp) for _o, _m, pp in opaque]
        for y, x in np.argwhere(ref > 0):
            q = rk[:3, :3] @ (o_ + dirs[y, x] * dist[y, x]) + rk[:3, 3]
            qs[y, x] = q
            q_off = q + 1e-6 * to_sun
            if any(_ray_polygon(q_off, to_sun, pp) is not None for pp in panes):
                cls[y, x] = 2
            elif any(_ray_polygon(q_off, to_sun, pp) is not None for pp in opaque_np):
                cls[y, x] = 1
            else:
                cls[y, x] = 0
        pad_c = np.pad(cls, 1, constant_values=-2)
        clean = np.ones(ob.shape, dtype=bool)
        for dy in range(3):
            for dx in range(3):
                clean &= pad_c[dy:dy + ob.shape[0], dx:dx + ob.shape[1]] == cls
        names = {0: "sunlit", 1: "shadow_of_opaque_object", 2: "shadow_of_a_pane"}
        pairs = {v: [] for v in names.values()}
        # the same polygon (face), 5 x 5 inside it, in both views
        face_r = np.where(which >= 0, np.array(source + [-1])[which], -1)
        for j in range(len(opaque)):
            inner_r, inner_d = interior(face_r, j), interior(which_d, j)
            if not inner_r.any() or not inner_d.any():
                continue
            oid = CHECK_IDS[opaque[j][0]]
            for y, x in np.argwhere(inner_r & (ob == oid) & clean):
                col, row, depth = project(cam, qs[y, x])
                ci, ri = int(math.floor(col)), int(math.floor(row))
                if depth <= 0 or not (0 <= ci < cam["width"] and 0 <= ri < cam["height"]):
                    continue
                if not inner_d[ri, ci]:
                    continue
                pairs[names[int(cls[y, x])]].append((rgb[y, x], rgb_tr[ri, ci]))
        same_view = {}
        for key, pr in pairs.items():
            if not pr:
                same_view[key] = {"pixels": 0}
                continue
            a = np.array([p_[0] for p_ in pr])
            b = np.array([p_[1] for p_ in pr])
            rel = np.abs(a - b).mean(axis=-1) / np.maximum(b.mean(axis=-1), 1e-6)
            same_view[key] = {"pixels": len(pr),
                              "mean_rgb_refl": [round(float(c), 4) for c in a.mean(axis=0)],
                              "mean_rgb_trans": [round(float(c), 4) for c in b.mean(axis=0)],
                              "median_relative_difference": float(np.median(rel)),
                              "p90_relative_difference": float(np.percentile(rel, 90))}
        entry["refl_vs_trans_same_surface_point"] = same_view
        entry["refl_vs_trans_same_surface_point"]["inside_pane_pixels_by_sun_class"] = {
            v: int(np.count_nonzero(pane & (cls == c))) for c, v in names.items()}
        lit = same_view["sunlit"]
        if lit["pixels"] >= 10 and (lit["median_relative_difference"] > 0.05
                                    or lit["p90_relative_difference"] > 0.15):
            problems.append("plane %d: the pass's lit floor/boxes differ from trans" % k)

        # The world where nothing is hit: pixels whose 5 x 5 neighbourhood is all world in the
        # index render (the 1.5 px filter's samples stay well inside it) have exactly the
        # world colour in the pass; alpha 1 everywhere.
        world = ob == 0
        inner = fixture_scene.interior(world, 2)
        entry["combined"] = {
            "alpha_min": float(alpha.min()), "alpha_max": float(alpha.max()),
            "world_interior_pixels": int(np.count_nonzero(inner)),
            "world_interior_max_abs_from_0.5": float(np.abs(rgb[inner] - 0.5).max())
            if np.any(inner) else None,
            "rgb_min": float(rgb.min()), "rgb_max": float(rgb.max()),
            "mean_rgb": [round(float(c), 4) for c in rgb.reshape(-1, 3).mean(axis=0)],
        }
        if alpha.min() != 1.0:
            problems.append("plane %d: alpha below 1 (film transparent?)" % k)
        if np.any(inner) and entry["combined"]["world_interior_max_abs_from_0.5"] > 1e-3:
            problems.append("plane %d: world pixels are not the world colour" % k)
        report["planes"][str(k)] = entry

    report["problems"] = problems
    text = json.dumps(report, indent=1)
    print(text)
    with open(os.path.join(scratch, "reflection_check.json"), "w") as fh:
        fh.write(text + "\n")
    if problems:
        sys.exit("check failed: " + "; ".join(problems))


def _ray_polygon(o, dirn, p):
    """Distance along the ray o + t·dirn to the convex/concave planar polygon p, or None."""
    import numpy as np

    nrm = np.zeros(3)
    for a in range(len(p)):
        nrm += np.cross(p[a], p[(a + 1) % len(p)])
    nrm /= np.linalg.norm(nrm)
    den = dirn @ nrm
    if abs(den) < 1e-12:
        return None
    t = ((p[0] - o) @ nrm) / den
    if t <= 1e-9:
        return None
    hit = o + t * dirn
    ax = int(np.argmax(np.abs(nrm)))
    u, v = [c for c in range(3) if c != ax]
    inside = False
    for a in range(len(p)):
        b = (a + 1) % len(p)
        if (p[a][v] > hit[v]) != (p[b][v] > hit[v]):
            xc = p[a][u] + (hit[v] - p[a][v]) * (p[b][u] - p[a][u]) / (p[b][v] - p[a][v])
            if hit[u] < xc:
                inside = not inside
    return t if inside else None


def main():
    opts = parse_args(sys.argv)
    if opts["mode"] == "check":
        check_reflections(opts["out"], opts["geometry"], opts["scratch"])
    else:
        render_reflections(opts["out"], opts["geometry"], opts["scratch"],
                           opts["working_space"])


if __name__ == "__main__":
    main()
