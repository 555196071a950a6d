"""The numbers of docs/blender.md, "Units: the double image" (issue 27), from
scripts/ghost_validation.sh's runs in DIR: reference/ (Cycles, two real panes, many samples),
ghosts/ and surfaces1/ (`glassdb blender render` of the double unit, with each pane's
reflection at its depth and with `--surfaces 1`), direct/ (Cycles, two real panes, the
pipeline's samples).

    .venv/bin/python scripts/ghost_validation.py DIR [FIGURE.png]

In-glass PSNR (peak 1.0 on linear R, G, B, as docs/validation.md) of each against the
reference, over the glass pixels of the unit's mask whose 3 × 3 neighbourhood is glass (the
real panes lie 3 and 21 mm behind the unit's face). The ghost offset per bar: measured in the
ghost run's passes (the centroid of the bar's image in the outer and the inner pane's pass)
and in the reference (the shift s that best fits the reference's reflection row profile as
a·P(x) + b·P(x + s), P the outer pane's pass profile), against the mirror-geometry
prediction (Blender's projection of the bar mirrored about each pane's mid-plane, from the
scene's facts). Writes DIR/metrics.json and the figure: reference | ghosts | --surfaces 1 |
direct, the bars' region enlarged 3×, exposure 1/4, sRGB.

Needs numpy and OpenEXR (the project's .venv). Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import re
import sys
from pathlib import Path

import numpy as np
import OpenEXR

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python_oracle"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from exr_oracle import write_png_rgb8  # noqa: E402
from blender_example_figure import srgb8  # noqa: E402
from blender_validation import read, rgb  # noqa: E402

ROWS_FRACTION = (0.45, 0.55)  # rows of the bars' reflections (they span the frame's middle)


def frame_path(run, stem):
    return os.path.join(run, "%s.0001.exr" % stem)


def pass_luminance(run, record_bounds, stem, size):
    """R + G + B of a cropped pass placed in the frame."""
    w, h = size
    full = np.zeros((h, w))
    part = sum(read(frame_path(run, stem), [c])[0] for c in "RGB")
    x, y = record_bounds["x"], record_bounds["y"]
    full[y:y + part.shape[0], x:x + part.shape[1]] = part
    return full


def profile(lum, size):
    w, h = size
    r0, r1 = int(ROWS_FRACTION[0] * h), int(ROWS_FRACTION[1] * h)
    p = lum[r0:r1].mean(axis=0)
    return p - np.median(p)


def centroid(p, lo, hi):
    seg = np.clip(p[lo:hi], 0.0, None)
    return float(np.sum((np.arange(lo, hi) + 0.5) * seg) / np.sum(seg))


def fitted_shift(ref, template, lo, hi):
    """The s that best fits ref[lo:hi] as a·T(x) + b·T(x + s) (least squares in a, b): the
    deeper pane's image lies s pixels towards smaller x here (the camera looks from +x)."""
    x = np.arange(len(template), dtype=float)
    best = None
    for s in np.arange(0.0, 16.0, 0.02):
        shifted = np.interp(x + s, x, template, left=0.0, right=0.0)
        A = np.stack([template[lo:hi], shifted[lo:hi]], axis=1)
        coef, *_ = np.linalg.lstsq(A, ref[lo:hi], rcond=None)
        res = float(np.sum((A @ coef - ref[lo:hi]) ** 2))
        if best is None or res < best[0]:
            best = (res, s, coef)
    return best[1], best[2]


def numbers_of(run_txt):
    text = open(run_txt).read()
    cpu = re.search(r"Blender CPU: passes ([0-9.]+) s", text)
    wall = re.search(r"Blender export [0-9.]+ s, passes ([0-9.]+) s", text)
    return {"passes_cpu_s": float(cpu.group(1)), "passes_wall_s": float(wall.group(1))}


def main():
    root = sys.argv[1]
    figure = sys.argv[2] if len(sys.argv) > 2 else None
    runs = {k: os.path.join(root, k) for k in ("reference", "ghosts", "surfaces1", "direct")}
    facts = json.load(open(os.path.join(root, "unit.json")))
    size = tuple(facts["size"])
    record = json.load(open(os.path.join(runs["ghosts"], "glassdb-blender.json")))
    idm, cov = read(frame_path(runs["ghosts"], "mask"), ["id", "coverage"])
    glass = (idm > 0) & (cov >= 1.0)
    pad = np.pad(glass, 1)
    keep = glass.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            keep &= pad[1 + dy:1 + dy + glass.shape[0], 1 + dx:1 + dx + glass.shape[1]]
    ref = rgb(frame_path(runs["reference"], "reference"))
    images = {"ghosts": rgb(frame_path(runs["ghosts"], "composite")),
              "surfaces1": rgb(frame_path(runs["surfaces1"], "composite")),
              "direct": rgb(frame_path(runs["direct"], "reference"))}
    metrics = {"size": size, "glass_pixels": int(keep.sum()),
               "samples": record["samples"],
               "reference_samples": json.load(open(os.path.join(
                   runs["reference"], "glassdb-blender.json")))["samples"]}
    print("| image (%d spp; reference %d spp) | in-glass PSNR (dB) |" % (
        metrics["samples"], metrics["reference_samples"]))
    print("|---|---|")
    for name, img in images.items():
        d = (img - ref)[keep]
        m = float(np.mean(d * d))
        metrics["psnr_" + name] = 10.0 * math.log10(1.0 / m)
        print("| %s | %.2f |" % (name, metrics["psnr_" + name]))
    frame = record["frames"][0]
    outer = profile(pass_luminance(runs["ghosts"], frame["bounds"][0], "refl_0", size), size)
    group = frame["groups"][0]
    inner = profile(pass_luminance(runs["ghosts"], group["bounds"], "refl_0_1", size), size)
    ref_profile = profile(ref.sum(axis=-1), size)
    w = size[0]
    print()
    print("| bar | predicted offset (px) | in the passes (px) | in the reference (px) |")
    print("|---|---|---|---|")
    bars = {}
    depths = facts["depths_mm"]
    for bar in facts["bars"]:
        pred = [facts["mirror_images_uv"]["%.4f" % d][bar][0] * w for d in depths]
        lo, hi = int(min(pred)) - 12, int(max(pred)) + 13
        measured = [centroid(outer, lo, hi), centroid(inner, lo, hi)]
        s, coef = fitted_shift(ref_profile, outer, lo, hi)
        bars[bar] = {"predicted_px": pred, "measured_px": measured,
                     "predicted_offset_px": pred[0] - pred[1],
                     "passes_offset_px": measured[0] - measured[1],
                     "reference_offset_px": float(s),
                     "reference_weights": [float(c) for c in coef]}
        print("| %s | %.2f | %.2f | %.2f |" % (bar, pred[0] - pred[1], measured[0] - measured[1], s))
    metrics["bars"] = bars
    metrics["ghosts_run"] = numbers_of(os.path.join(root, "ghosts.txt"))
    metrics["surfaces1_run"] = numbers_of(os.path.join(root, "surfaces1.txt"))
    print()
    print("Blender passes: ghosts %.1f s CPU, --surfaces 1 %.1f s CPU" % (
        metrics["ghosts_run"]["passes_cpu_s"], metrics["surfaces1_run"]["passes_cpu_s"]))
    with open(os.path.join(root, "metrics.json"), "w") as fh:
        json.dump(metrics, fh, indent=1)
        fh.write("\n")
    if figure:
        h = size[1]
        ys, xs = slice(int(0.35 * h), int(0.65 * h)), slice(int(0.25 * w), int(0.7 * w))
        panels = [ref] + list(images.values())
        # Exposure 1/4, so that the bars' reflections do not clip and both images show.
        crops = [np.repeat(np.repeat(srgb8(0.25 * p[ys, xs]), 3, axis=0), 3, axis=1)
                 for p in panels]
        gap = np.full((crops[0].shape[0], 4, 3), 255, dtype=np.uint8)
        row = []
        for c in crops:
            row += [c, gap]
        write_png_rgb8(figure, np.concatenate(row[:-1], axis=1))


if __name__ == "__main__":
    main()
