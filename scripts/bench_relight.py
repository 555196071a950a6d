"""Writes two `glassdb blender` run folders of one synthetic frame for the relit-swap benchmark
(scripts/bench_relight.sh, docs/performance.md "Relit swap"): `today/` as `glassdb blender
render` writes a frame without the light split (each pass one RGB layer), and `relit/` with the
split (each pass its beauty and one `ViewLayer.Combined_<group>` layer per light part) and the
frame's light parts. Two windows of different glass (ids A and B, planes 0 and 1), each
reflection pass cropped to its window, half-float ZIP as the pipeline writes them.

usage: bench_relight.py OUT WIDTH HEIGHT PARTS ID_A ID_B
PARTS: 3 (sun and sky through window 0, interior) or 7 (sun and sky through each window, and
sun, sky and interior unglazed).
"""

import json
import os
import sys

import numpy as np
import OpenEXR


def write_exr(path, width, height, channels, window=None):
    """Half-float ZIP EXR of `channels` (name -> HxW array) over `window` (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = window or (0, 0, width - 1, height - 1)
    header = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        "dataWindow": (np.array([x0, y0], np.int32), np.array([x1, y1], np.int32)),
        "displayWindow": (np.array([0, 0], np.int32), np.array([width - 1, height - 1], np.int32)),
    }
    data = {n: np.ascontiguousarray(v.astype(np.float16)) for n, v in channels.items()}
    OpenEXR.File(header, data).write(path)


def smooth(rng, h, w, scale):
    """Positive noise with some structure (compresses like a render, not like a constant)."""
    y, x = np.mgrid[0:h, 0:w]
    base = 0.5 + 0.3 * np.sin(x / 37.0 + rng.uniform(0, 6)) * np.cos(y / 23.0)
    return (scale * (base + 0.05 * rng.standard_normal((h, w)))).astype(np.float32)


def layers(rng, groups, h, w, beauty_only):
    """The pass's channels: its beauty (the sum) and, unless `beauty_only`, each group's."""
    out = {}
    total = [np.zeros((h, w), np.float32) for _ in range(3)]
    for k, g in enumerate(groups):
        for c, ch in enumerate("RGB"):
            v = smooth(rng, h, w, 0.2 + 0.1 * k + 0.05 * c)
            total[c] += v
            if not beauty_only:
                out[f"ViewLayer.Combined_{g}.{ch}"] = v
    for c, ch in enumerate("RGB"):
        out[f"ViewLayer.Combined.{ch}"] = total[c]
    return out


def main():
    out, width, height, nparts, id_a, id_b = sys.argv[1:7]
    width, height, nparts, id_a, id_b = int(width), int(height), int(nparts), int(id_a), int(id_b)
    wall = [0.0, -1.0, 0.0]
    sun = {"kind": "sun", "direction_to_sun": [0.3, -0.8, 0.5]}
    sky = {"kind": "sky"}
    other = {"kind": "other"}
    through = lambda plane, gid: {"plane": plane, "normal": wall, "id": gid}
    parts = [
        {"group": "sun_p0_id%d" % id_a, "source": sun, "through": through(0, id_a)},
        {"group": "sky_p0_id%d" % id_a, "source": sky, "through": through(0, id_a)},
        {"group": "other", "source": other},
    ]
    if nparts == 7:
        parts += [
            {"group": "sun_p1_id%d" % id_b, "source": sun, "through": through(1, id_b)},
            {"group": "sky_p1_id%d" % id_b, "source": sky, "through": through(1, id_b)},
            {"group": "sun", "source": sun},
            {"group": "sky", "source": sky},
        ]
    elif nparts != 3:
        sys.exit("PARTS is 3 or 7")
    groups = [p["group"] for p in parts]
    # the windows: left and right thirds of the middle half
    windows = [
        (width // 12, height // 4, width // 12 + width // 3 - 1, 3 * height // 4 - 1),
        (7 * width // 12, height // 4, 7 * width // 12 + width // 3 - 1, 3 * height // 4 - 1),
    ]
    ids = np.zeros((height, width), np.float32)
    plane = np.zeros((height, width), np.float32)
    y, x = np.mgrid[0:height, 0:width]
    cos = (0.3 + 0.6 * x / width).astype(np.float32)
    for k, (gid, (x0, y0, x1, y1)) in enumerate(zip((id_a, id_b), windows)):
        inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        ids[inside] = gid
        plane[inside] = k
    for split in (False, True):
        folder = os.path.join(out, "relit" if split else "today")
        os.makedirs(folder, exist_ok=True)
        rng = np.random.default_rng(28)
        write_exr(os.path.join(folder, "trans.0001.exr"), width, height,
                  layers(rng, groups, height, width, not split))
        refl = []
        for k, (x0, y0, x1, y1) in enumerate(windows):
            name = "refl.0001.p%d.exr" % k
            h, w = y1 - y0 + 1, x1 - x0 + 1
            write_exr(os.path.join(folder, name), width, height,
                      layers(rng, groups, h, w, not split), (x0, y0, x1, y1))
            refl.append(name)
        write_exr(os.path.join(folder, "mask.0001.exr"), width, height,
                  {"id": ids, "cos_theta": cos, "plane": plane})
        frame = {
            "frame": 1, "trans": "trans.0001.exr", "mask": "mask.0001.exr", "refl": refl,
            "sides": ["front", "front"],
            "bounds": [{"x": x0, "y": y0, "width": x1 - x0 + 1, "height": y1 - y0 + 1}
                       for (x0, y0, x1, y1) in windows],
            "composite": "composite.0001.exr",
        }
        if split:
            frame["light_parts"] = "light_parts.0001.json"
            with open(os.path.join(folder, "light_parts.0001.json"), "w") as f:
                json.dump({"format": "glassdb-light-parts/1", "parts": parts}, f)
        record = {
            "format": "glassdb-blender/1", "blend": "synthetic.blend", "blender": "3.4.1",
            "glass": [], "samples": 16, "width": width, "height": height, "overrides": [],
            "frames": [frame], "lit_by": [],
        }
        with open(os.path.join(folder, "glassdb-blender.json"), "w") as f:
            json.dump(record, f)


if __name__ == "__main__":
    main()
