"""Writes several planes' reflection passes into one EXR with OpenEXR's own Python bindings (not
glassdb's writer), for `compose --refl planes.exr` tests (tests/cli/farm.rs).

Usage:
  plane_parts.py parts --mask MASK.png --out OUT.exr REFL_0.exr REFL_1.exr ...
      A multi-part file: part `planeK` holds REFL_K's R, G, B cropped to the rectangle of plane
      K's glass pixels in MASK (8-bit packed: R plane, G id), its data window that rectangle,
      ZIP; a plane without glass gets a 1×1 part at its top-left corner. With --pad N, 1×1
      parts of zeros follow up to N parts in all (planes no glass is on). Prints each part's
      data window as JSON.
  plane_parts.py layers [--first K] --out OUT.exr REFL_0.exr REFL_1.exr ...
      One part, full frame, channels planeK.R, planeK.G, planeK.B (K counted from --first, 0).
"""

import argparse
import json
import sys

import numpy as np
import OpenEXR

from exr_oracle import read_png


def _rgb(path):
    with OpenEXR.File(path, separate_channels=True) as f:
        h = dict(f.header())
        ch = f.channels()
        return h, {c: ch[c].pixels.copy() for c in ("R", "G", "B")}


def _window(x0, y0, x1, y1):
    return (np.array([x0, y0], dtype=np.int32), np.array([x1, y1], dtype=np.int32))


def cmd_parts(args):
    rgb = read_png(args.mask)
    plane, ident = rgb[..., 0], rgb[..., 1]
    parts, windows = [], []
    for k, path in enumerate(args.refl):
        h, ch = _rgb(path)
        (dx0, dy0), _ = h["dataWindow"]
        ys, xs = np.nonzero((ident != 0) & (plane == k))
        if len(xs):
            x0, y0, x1, y1 = int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())
        else:
            x0 = y0 = x1 = y1 = 0
        crop = {c: v[y0 - dy0:y1 - dy0 + 1, x0 - dx0:x1 - dx0 + 1].copy() for c, v in ch.items()}
        header = {
            "compression": OpenEXR.ZIP_COMPRESSION,
            "type": OpenEXR.scanlineimage,
            "dataWindow": _window(x0, y0, x1, y1),
            "displayWindow": h["displayWindow"],
        }
        parts.append(OpenEXR.Part(header, crop, f"plane{k}"))
        windows.append([x0, y0, x1, y1])
    display = header["displayWindow"]
    for k in range(len(parts), args.pad):
        header = {
            "compression": OpenEXR.ZIP_COMPRESSION,
            "type": OpenEXR.scanlineimage,
            "dataWindow": _window(0, 0, 0, 0),
            "displayWindow": display,
        }
        zeros = {c: np.zeros((1, 1), dtype=np.float16) for c in ("R", "G", "B")}
        parts.append(OpenEXR.Part(header, zeros, f"plane{k}"))
        windows.append([0, 0, 0, 0])
    with OpenEXR.File(parts) as f:
        f.write(args.out)
    json.dump(windows, sys.stdout)
    sys.stdout.write("\n")


def cmd_layers(args):
    channels, display = {}, None
    for k, path in enumerate(args.refl, start=args.first):
        h, ch = _rgb(path)
        display = h["displayWindow"]
        for c, v in ch.items():
            channels[f"plane{k}.{c}"] = v
    header = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        "dataWindow": display,
        "displayWindow": display,
    }
    with OpenEXR.File(header, channels) as f:
        f.write(args.out)


def main():
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("parts")
    a.add_argument("--mask", required=True)
    a.add_argument("--out", required=True)
    a.add_argument("--pad", type=int, default=0)
    a.add_argument("refl", nargs="+")
    b = sub.add_parser("layers")
    b.add_argument("--out", required=True)
    b.add_argument("--first", type=int, default=0)
    b.add_argument("refl", nargs="+")
    args = p.parse_args()
    {"parts": cmd_parts, "layers": cmd_layers}[args.cmd](args)


if __name__ == "__main__":
    main()
