#!/usr/bin/env python3
"""Render tiny Blender Cycles pass fixtures and describe what Blender wrote.

Two steps, one script:

1. Render (needs Blender; runs under Blender's own Python or under the `bpy` module):

       blender -b --factory-startup -noaudio --python-exit-code 1 \
           -P scripts/blender/make_pass_fixtures.py -- --out fixtures/blender/b34
       python scripts/blender/make_pass_fixtures.py --out fixtures/blender/b50   # bpy venv

   builds a small scene procedurally (no .blend file) and writes into --out:
   multilayer.exr, border.exr, border_crop.exr, rgba.exr and a first layout.json holding the
   Blender version and the render settings.

2. Describe (plain Python with the `OpenEXR` package, pip OpenEXR==3.5.3; no Blender):

       python scripts/blender/make_pass_fixtures.py --describe --out fixtures/blender/b34

   reads the EXR files back with OpenEXR and completes layout.json with, per file and part, the
   name, data and display windows, channels (name, sample type, sampling), the simple header
   attributes, and a summary of pixel facts of the full-frame render. It fails (exit 1) when a
   render is blank (Combined all zero, or Material Index lacking id 1 or 5).

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fixture_scene  # noqa: E402

WIDTH, HEIGHT = 64, 48
SAMPLES = 4
BORDER = (0.25, 0.75, 0.25, 0.75)  # min x, max x, min y, max y
GLASS_IDS = {"Glass_clear": 1, "Tinted_bronze": 5}
OUTPUTS = ("multilayer.exr", "border.exr", "border_crop.exr", "rgba.exr")


def parse_args(argv):
    """Arguments after `--` (inside blender) or all of argv[1:] (plain Python / bpy module)."""
    argv = fixture_scene.script_args(argv)
    out, describe = None, False
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--out" and i + 1 < len(argv):
            out = argv[i + 1]
            i += 2
            continue
        if a.startswith("--out="):
            out = a.split("=", 1)[1]
        elif a == "--describe":
            describe = True
        elif a in ("-h", "--help"):
            print(__doc__)
            sys.exit(0)
        else:
            sys.exit("make_pass_fixtures.py: unknown argument %r (use --out DIR [--describe])" % a)
        i += 1
    if not out:
        sys.exit("make_pass_fixtures.py: --out DIR is required")
    return os.path.abspath(out), describe


# --------------------------------------------------------------------------------------------
# Step 1: render (bpy)
# --------------------------------------------------------------------------------------------

def render_all(out_dir):
    import bpy
    from mathutils import Vector

    os.makedirs(out_dir, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    version = tuple(bpy.app.version)
    scene = bpy.context.scene

    def make_material(name, rgb, pass_index, principled):
        mat, nt, out = fixture_scene.new_material(name, pass_index)
        if principled:
            bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
            bsdf.inputs["Base Color"].default_value = (*rgb, 1.0)
            bsdf.inputs["Roughness"].default_value = 0.05
        else:
            bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
            bsdf.inputs["Color"].default_value = (*rgb, 1.0)
        nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
        fixture_scene.facing_aov(nt)
        return mat

    def add_plane(name, size, location, rotation_deg, mat, pass_index):
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=location)
        obj = bpy.context.active_object
        obj.name = name
        obj.scale = (size[0], size[1], 1.0)
        obj.rotation_euler = [math.radians(a) for a in rotation_deg]
        obj.data.materials.append(mat)
        obj.pass_index = pass_index
        return obj

    # Materials.
    m_floor = make_material("Floor", (0.35, 0.33, 0.30), 0, principled=False)
    m_wall = make_material("Wall", (0.15, 0.35, 0.60), 0, principled=False)
    m_clear = make_material("Glass_clear", (0.80, 0.90, 0.90), GLASS_IDS["Glass_clear"], True)
    m_bronze = make_material("Tinted_bronze", (0.55, 0.40, 0.20), GLASS_IDS["Tinted_bronze"], True)

    # Geometry (metres, z up): floor, back wall, a large vertical pane facing the camera
    # obliquely, a smaller pane at another angle in front of it.
    add_plane("Floor", (8.0, 8.0), (0.0, 0.0, 0.0), (0, 0, 0), m_floor, 0)
    add_plane("BackWall", (8.0, 4.0), (0.0, 2.5, 2.0), (90, 0, 0), m_wall, 0)
    add_plane("Pane_clear", (3.6, 2.2), (-0.4, 0.6, 1.15), (90, 0, 15), m_clear, 1)
    add_plane("Pane_bronze", (1.0, 0.9), (0.8, -0.5, 0.6), (80, 0, -20), m_bronze, 5)

    # Sun.
    sun_data = bpy.data.lights.new("Sun", type="SUN")
    sun_data.energy = 3.0
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (math.radians(40), math.radians(15), math.radians(30))
    scene.collection.objects.link(sun)

    # Camera, oblique to both panes.
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = 30.0
    cam = bpy.data.objects.new("Camera", cam_data)
    cam.location = (2.9, -3.6, 1.6)
    target = Vector((0.1, 0.3, 0.75))
    cam.rotation_euler = (target - cam.location).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(cam)
    scene.camera = cam

    # World: grey.
    fixture_scene.grey_world(scene)

    # Render settings.
    r = fixture_scene.fixed_cycles(scene)
    scene.cycles.samples = SAMPLES
    r.resolution_x, r.resolution_y = WIDTH, HEIGHT
    r.film_transparent = True

    # Passes.
    vl = scene.view_layers[0]
    vl.use_pass_combined = True
    vl.use_pass_z = True
    vl.use_pass_normal = True
    has_position = hasattr(vl, "use_pass_position")
    if has_position:
        vl.use_pass_position = True
    vl.use_pass_material_index = True
    vl.use_pass_object_index = True
    vl.use_pass_cryptomatte_material = True
    vl.use_pass_cryptomatte_object = True
    vl.pass_cryptomatte_depth = 2
    aov = vl.aovs.add()
    aov.name = "facing"
    aov.type = "VALUE"

    im = r.image_settings

    def set_format(multilayer):
        fixture_scene.set_exr_format(im, multilayer=multilayer, half=True)

    def render_to(name, multilayer, border, crop):
        set_format(multilayer)
        r.use_border = border
        r.use_crop_to_border = crop
        r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = BORDER
        scene.frame_set(1)
        fixture_scene.render_still(scene, out_dir, name)

    render_to("multilayer.exr", True, False, False)
    render_to("border.exr", True, True, False)
    render_to("border_crop.exr", True, True, True)
    render_to("rgba.exr", False, False, False)

    info = {
        "blender": {
            "version_string": bpy.app.version_string,
            "version": list(version),
            "build_hash": getattr(bpy.app, "build_hash", b"").decode("ascii", "replace")
            if isinstance(getattr(bpy.app, "build_hash", b""), bytes)
            else str(getattr(bpy.app, "build_hash", "")),
            "binary_path": bpy.app.binary_path,
            "background": bpy.app.background,
            "python": sys.version.split()[0],
            "as_module": "--" not in sys.argv,
        },
        "render": {
            "engine": r.engine,
            "device": scene.cycles.device,
            "resolution": [WIDTH, HEIGHT],
            "resolution_percentage": 100,
            "samples": SAMPLES,
            "seed": 0,
            "denoising": False,
            "film_transparent": True,
            "threads": 2,
            "border": {"min_x": BORDER[0], "max_x": BORDER[1], "min_y": BORDER[2],
                       "max_y": BORDER[3]},
            "exr": {"color_depth": "16", "codec": "ZIP", "color_mode": "RGBA"},
            "passes": ["Combined", "Z", "Normal"] + (["Position"] if has_position else [])
            + ["IndexMA", "IndexOB", "CryptoMaterial", "CryptoObject", "AOV facing (VALUE)"],
            "position_pass_available": has_position,
            "cryptomatte_levels": 2,
        },
        "scene": {
            "glass_ids": {"Glass_clear": {"material_pass_index": 1, "object_pass_index": 1,
                                          "object": "Pane_clear"},
                          "Tinted_bronze": {"material_pass_index": 5, "object_pass_index": 5,
                                            "object": "Pane_bronze"}},
            "other_materials": {"Floor": 0, "Wall": 0},
            "world_color": [0.5, 0.5, 0.5],
        },
        "files": {
            "multilayer.exr": {"format": "OPEN_EXR_MULTILAYER", "use_border": False},
            "border.exr": {"format": "OPEN_EXR_MULTILAYER", "use_border": True,
                           "use_crop_to_border": False},
            "border_crop.exr": {"format": "OPEN_EXR_MULTILAYER", "use_border": True,
                                "use_crop_to_border": True},
            "rgba.exr": {"format": "OPEN_EXR", "use_border": False},
        },
    }
    fixture_scene.write_json(os.path.join(out_dir, "layout.json"), info)


# --------------------------------------------------------------------------------------------
# Step 2: describe (OpenEXR python package, no Blender)
# --------------------------------------------------------------------------------------------

def _simple(value):
    """JSON form of a simple header value, or None when it is not simple."""
    import numpy as np

    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float, str)):
        if isinstance(value, float) and not math.isfinite(value):
            return repr(value)
        return value
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        if value.size <= 16:
            return value.tolist()
        return None
    if hasattr(value, "name") and hasattr(value, "value") and not callable(value.name):
        return value.name  # enums (Compression, LineOrder, ...)
    if isinstance(value, (tuple, list)):
        items = [_simple(v) for v in value]
        if all(v is not None for v in items) and len(items) <= 16:
            return items
        return None
    return None


def _dtype_name(arr):
    import numpy as np

    return {np.dtype("float16"): "HALF", np.dtype("float32"): "FLOAT",
            np.dtype("uint32"): "UINT"}.get(arr.dtype, str(arr.dtype))


def _window(box):
    (x0, y0), (x1, y1) = [[int(v) for v in corner] for corner in box]
    return {"min": [x0, y0], "max": [x1, y1], "width": x1 - x0 + 1, "height": y1 - y0 + 1}


def raw_headers(path):
    """The version flags and, per part, the attributes exactly as stored (name, type, size), in
    file order, parsed from the bytes; independent of the OpenEXR library, which may add or
    normalise attributes (e.g. `type`, `name`) in what it returns."""
    import struct

    with open(path, "rb") as f:
        data = f.read()
    magic, version = struct.unpack_from("<ii", data, 0)
    if magic != 20000630:
        raise ValueError("%s: not an OpenEXR file" % path)
    flags = {"version": version & 0xFF, "tiled": bool(version & 0x200),
             "long_names": bool(version & 0x400), "deep": bool(version & 0x800),
             "multipart": bool(version & 0x1000)}
    pos, parts = 8, []

    def cstr(pos):
        end = data.index(b"\0", pos)
        return data[pos:end].decode("latin-1"), end + 1

    while True:
        attrs = []
        while data[pos] != 0:
            name, pos = cstr(pos)
            typ, pos = cstr(pos)
            (size,) = struct.unpack_from("<i", data, pos)
            pos += 4
            attr = [name, typ, size]
            if typ == "chlist":  # channel names and sample types, in stored order
                chans, q = [], pos
                while data[q] != 0:
                    cname, q = cstr(q)
                    ptype, plinear, xs, ys = struct.unpack_from("<iB3xii", data, q)
                    q += 16
                    chans.append([cname, {0: "UINT", 1: "HALF", 2: "FLOAT"}.get(ptype, ptype),
                                  xs, ys])
                attr.append(chans)
            attrs.append(attr)
            pos += size
        pos += 1  # end of this header
        parts.append(attrs)
        if not flags["multipart"] or data[pos] == 0:
            break
    return flags, parts


def describe_file(path):
    import OpenEXR

    flags, raw = raw_headers(path)
    f = OpenEXR.File(path, separate_channels=True)
    parts = []
    for index, part in enumerate(f.parts):
        header = part.header
        simple, others = {}, {}
        for key in header:
            if key == "channels":  # listed below, with the sample types
                continue
            value = header[key]
            s = _simple(value)
            if s is None:
                others[key] = type(value).__name__
            else:
                simple[key] = s
        channels = []
        for cname, ch in part.channels.items():
            channels.append({
                "name": cname,
                "type": _dtype_name(ch.pixels),
                "xSampling": int(getattr(ch, "xSampling", 1)),
                "ySampling": int(getattr(ch, "ySampling", 1)),
                "pLinear": bool(getattr(ch, "pLinear", False)),
            })
        stored = [a[3] for a in (raw[index] if index < len(raw) else []) if a[1] == "chlist"]
        if stored and [[c["name"], c["type"], c["xSampling"], c["ySampling"]]
                       for c in channels] != stored[0]:
            raise ValueError("%s part %d: OpenEXR's channel list differs from the stored one"
                             % (path, index))
        parts.append({
            "index": index,
            "name": part.name() if callable(getattr(part, "name", None)) else header.get("name"),
            "dataWindow": _window(header["dataWindow"]),
            "displayWindow": _window(header["displayWindow"]),
            "channel_count": len(channels),
            "channels": channels,
            "header": simple,
            "other_attributes": others,
            "attributes_in_file": raw[index] if index < len(raw) else None,
        })
    return {"size_bytes": os.path.getsize(path), "version_flags": flags,
            "part_count": len(parts), "parts": parts}


def _find_channel(channels, *patterns):
    """First channel name whose name (case-sensitive) matches one of the candidate forms."""
    for pat in patterns:
        for name in channels:
            if pat(name):
                return name
    return None


def pixel_summary(path):
    import numpy as np
    import OpenEXR

    f = OpenEXR.File(path, separate_channels=True)
    chans = {}
    for part in f.parts:
        for name, ch in part.channels.items():
            chans[name] = ch.pixels
    names = list(chans)
    ma = _find_channel(names, lambda n: n.endswith("IndexMA.X") or n.endswith("IndexMA.V"),
                       lambda n: "IndexMA" in n, lambda n: "Material Index" in n)
    ob = _find_channel(names, lambda n: "IndexOB" in n, lambda n: "Object Index" in n)
    facing = _find_channel(names, lambda n: n.endswith("facing.X") or n.endswith("facing.V"),
                           lambda n: "facing" in n)
    combined = [n for n in names if n.split(".")[-1] in "RGBA" and
                ("Combined" in n or "Image" in n or n in ("R", "G", "B", "A"))]
    alpha = _find_channel(combined, lambda n: n.endswith("A"))
    out = {"channels_used": {"material_index": ma, "object_index": ob, "facing": facing,
                             "combined": combined}}
    comb = np.stack([chans[n].astype(np.float64) for n in combined]) if combined else None
    out["combined_nonzero_pixels"] = int(np.count_nonzero(np.any(comb != 0, axis=0))) \
        if comb is not None else 0
    if alpha:
        a = chans[alpha].astype(np.float64)
        rgb = np.stack([chans[n].astype(np.float64) for n in combined if n != alpha])
        covered = np.argwhere(a > 0)
        out["alpha"] = {
            "min": float(a.min()), "max": float(a.max()),
            "pixels_eq_1": int(np.count_nonzero(a == 1.0)),
            "pixels_eq_0": int(np.count_nonzero(a == 0.0)),
            "pixels_fractional": int(np.count_nonzero((a > 0) & (a < 1))),
            # Premultiplied alpha: nothing where alpha is 0.
            "alpha0_pixels_with_nonzero_rgb": int(np.count_nonzero((a == 0) &
                                                                   np.any(rgb != 0, axis=0))),
            # Rows/columns (array indices, i.e. relative to the data window) with alpha > 0.
            "covered_rows": [int(covered[:, 0].min()), int(covered[:, 0].max())]
            if len(covered) else None,
            "covered_cols": [int(covered[:, 1].min()), int(covered[:, 1].max())]
            if len(covered) else None,
        }
    if ma:
        m = chans[ma].astype(np.float64)
        vals, counts = np.unique(m, return_counts=True)
        out["material_index_histogram"] = {repr(float(v)): int(c) for v, c in zip(vals, counts)}
        for gid in (1, 5):
            sel = m == gid
            entry = {"pixels": int(np.count_nonzero(sel))}
            where = np.argwhere(sel)
            if len(where):  # array indices: rows top to bottom, relative to the data window
                entry["rows"] = [int(where[:, 0].min()), int(where[:, 0].max())]
                entry["cols"] = [int(where[:, 1].min()), int(where[:, 1].max())]
            if facing and entry["pixels"]:
                fv = chans[facing].astype(np.float64)[sel]
                entry["facing_min"] = float(fv.min())
                entry["facing_max"] = float(fv.max())
            if facing and entry["pixels"]:
                # Interior: the 3x3 neighbourhood has the same id (no edge pixels, whose
                # facing value averages samples that hit other surfaces or nothing).
                inner = fixture_scene.interior(sel, 1)
                entry["interior_pixels"] = int(np.count_nonzero(inner))
                if entry["interior_pixels"]:
                    fi = chans[facing].astype(np.float64)[inner]
                    entry["interior_facing_min"] = float(fi.min())
                    entry["interior_facing_max"] = float(fi.max())
            if ob:
                entry["object_index_values"] = sorted(
                    float(v) for v in np.unique(chans[ob][sel]))
            out["material_index_%d" % gid] = entry
    return out


def describe_all(out_dir):
    import OpenEXR

    path = os.path.join(out_dir, "layout.json")
    with open(path) as f:
        layout = json.load(f)
    layout["reader"] = {"package": "OpenEXR (python)", "version": OpenEXR.__version__,
                        "python": sys.version.split()[0]}
    problems = []
    for name in OUTPUTS:
        p = os.path.join(out_dir, name)
        entry = layout.setdefault("files", {}).setdefault(name, {})
        entry.update(describe_file(p))
        if name != "rgba.exr":
            entry["pixel_summary"] = pixel_summary(p)
    summary = pixel_summary(os.path.join(out_dir, "multilayer.exr"))
    layout["full_frame_summary"] = summary
    if summary["combined_nonzero_pixels"] == 0:
        problems.append("multilayer.exr: Combined is all zero")
    for gid in (1, 5):
        if summary.get("material_index_%d" % gid, {}).get("pixels", 0) == 0:
            problems.append("multilayer.exr: no pixel with material index %d" % gid)
    rgba = pixel_summary(os.path.join(out_dir, "rgba.exr"))
    layout["files"]["rgba.exr"]["pixel_summary"] = {
        k: rgba[k] for k in ("channels_used", "combined_nonzero_pixels", "alpha") if k in rgba}
    if rgba["combined_nonzero_pixels"] == 0:
        problems.append("rgba.exr: all zero")
    fixture_scene.write_json(path, layout)
    if problems:
        sys.exit("blank render: " + "; ".join(problems))


def main():
    out_dir, describe = parse_args(sys.argv)
    if describe:
        describe_all(out_dir)
    else:
        render_all(out_dir)


if __name__ == "__main__":
    main()
