"""The dusk facade's figures and its colour numbers (README, docs/colour.md "The dusk frame"):
the composite with one table per light group beside the one-table composite, and the CIEDE2000
difference between the two over the glass, as a heat map and its distribution.

    .venv/bin/python scripts/blender/make_dusk_figures.py --per-group target/dusk.exr \
        --one-table target/dusk_one_table.exr --mask fixtures/dusk/mask.exr \
        --out-dir docs/figures [--json target/dusk_delta_e.json]

(the two composites: the README's first command with `-o target/dusk.exr`, and the same with
`--registry fixtures/dusk/registry_one_table.json -o target/dusk_one_table.exr`; a composite
may be given as `A.exr+B.exr`, summed, e.g. groups composited one by one, and `FILE:LAYER`
picks a layer).

Writes `dusk_facade.png` (left: per-group tables, right: one D65 table; each resampled to 2/3
of its size by area in linear light, then the `standard` view, sRGB transfer, clipped, as
compose writes PNG), `dusk_delta_e.png` (ΔE00 over the glass, at 2/3 of the size too, 0
black through purple and orange to 4 and more pale yellow, a scale bar at the bottom in steps
of 1; the frame outside the glass dimmed grey), and prints (and with --json writes) ΔE00's
median, 95th percentile, maximum and mean over the glass pixels of full coverage, per glass id
and all together.

ΔE00: each composite's linear Rec.709 RGB to XYZ (IEC 61966-2-1's matrix, D65 white), CIE
L*a*b* on D65 (Y = 1 is L* = 100; lamps brighter than white keep L* > 100), CIEDE2000 by
colour-science 0.4.7 (`colour.delta_E(..., method="CIE 2000")`).

Licence: same as the project, MIT OR Apache-2.0.
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import OpenEXR

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python_oracle"))
from exr_oracle import write_png_rgb8  # noqa: E402

import colour  # noqa: E402

REC709_TO_XYZ = np.array([[0.4124564, 0.3575761, 0.1804375],
                          [0.2126729, 0.7151522, 0.0721750],
                          [0.0193339, 0.1191920, 0.9503041]])
D65_XY = np.array([0.3127, 0.3290])
SCALE_MAX = 4.0
# Heat map anchors (ΔE00 / SCALE_MAX -> sRGB-encoded colour): black, purple, red, orange, pale yellow.
ANCHORS = [(0.0, (0, 0, 0)), (0.25, (80, 18, 123)), (0.5, (183, 55, 121)),
           (0.75, (251, 136, 97)), (1.0, (252, 253, 191))]


def channels(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        header = dict(f.header())
        chans = {name: np.asarray(ch.pixels, dtype=np.float64) for name, ch in f.channels().items()}
    (x0, y0), (x1, y1) = header["dataWindow"]
    (dx0, dy0), (dx1, dy1) = header["displayWindow"]
    if (x0, y0, x1, y1) != (dx0, dy0, dx1, dy1):
        sys.exit("%s: its data window is not its display window" % path)
    return chans


def rgb(spec):
    """A composite's RGB (`FILE:LAYER`, else bare R, G, B, else `ViewLayer.Combined`), or the
    sum of `A+B+…`."""
    total = None
    for item in spec.split("+"):
        path, _, layer = item.partition(":")
        chans = channels(path)
        for prefix in ([layer + "."] if layer else ["", "ViewLayer.Combined."]):
            if all(prefix + c in chans for c in "RGB"):
                img = np.stack([chans[prefix + c] for c in "RGB"], axis=-1)
                break
        else:
            sys.exit("%s has no RGB (bare or ViewLayer.Combined): %s" % (path, sorted(chans)))
        total = img if total is None else total + img
    return total


def standard_view(linear):
    v = np.clip(linear, 0.0, 1.0)
    enc = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return np.round(enc * 255).astype(np.uint8)


def two_thirds(img):
    """Area resampling to 2/3 of the size in each direction (linear light): every 3 × 3 block
    of pixels becomes 2 × 2, each output pixel the area-weighted mean of the 1.5 × 1.5 input
    pixels it covers. Odd rows or columns left over at the edges are cut."""
    h, w = (img.shape[0] // 3) * 3, (img.shape[1] // 3) * 3
    img = img[:h, :w]

    def axis(a, k):
        a = np.moveaxis(a, k, 0)
        a0, a1, a2 = a[0::3], a[1::3], a[2::3]
        out = np.empty((2 * a0.shape[0],) + a0.shape[1:])
        out[0::2] = (2 * a0 + a1) / 3
        out[1::2] = (a1 + 2 * a2) / 3
        return np.moveaxis(out, 0, k)

    return axis(axis(img, 0), 1)


def lab(linear):
    xyz = linear @ REC709_TO_XYZ.T
    return colour.XYZ_to_Lab(xyz, D65_XY)


def heat(values):
    """ΔE00 values to the heat map's 8-bit colours."""
    f = np.clip(values / SCALE_MAX, 0.0, 1.0)
    pos = np.array([a for a, _ in ANCHORS])
    cols = np.array([c for _, c in ANCHORS], dtype=np.float64)
    out = np.stack([np.interp(f, pos, cols[:, k]) for k in range(3)], axis=-1)
    return np.round(out).astype(np.uint8)


def stats(values):
    if values.size == 0:
        return {"pixels": 0}
    return {
        "pixels": int(values.size),
        "median": round(float(np.median(values)), 3),
        "p95": round(float(np.percentile(values, 95)), 3),
        "max": round(float(values.max()), 3),
        "mean": round(float(values.mean()), 3),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--per-group", required=True)
    ap.add_argument("--one-table", required=True)
    ap.add_argument("--mask", required=True)
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--json")
    args = ap.parse_args()

    per_group, one_table = rgb(args.per_group), rgb(args.one_table)
    if per_group.shape != one_table.shape:
        sys.exit("the composites differ in size: %s, %s" % (per_group.shape, one_table.shape))
    mask = channels(args.mask)
    ids = np.rint(mask["id"]).astype(np.int64)
    coverage = mask.get("coverage", np.ones_like(mask["id"]))
    if ids.shape != per_group.shape[:2]:
        sys.exit("the mask is %s, the composites %s" % (ids.shape, per_group.shape[:2]))
    glass = (ids > 0) & (coverage >= 1.0)

    de = np.asarray(colour.delta_E(lab(per_group), lab(one_table), method="CIE 2000"))
    report = {"all glass": stats(de[glass])}
    for gid in sorted(set(ids[glass].tolist())):
        report["id %d" % gid] = stats(de[glass & (ids == gid)])
    report["outside the glass (max)"] = round(float(np.abs(per_group - one_table)[~(ids > 0)].max()), 6)

    out = Path(args.out_dir)
    small = [two_thirds(per_group), two_thirds(one_table)]
    gap = np.full((small[0].shape[0], 6, 3), 255, dtype=np.uint8)
    side_by_side = np.concatenate([standard_view(small[0]), gap, standard_view(small[1])], axis=1)
    write_png_rgb8(str(out / "dusk_facade.png"), side_by_side, paeth=True)

    # At 2/3 of the size too: ΔE00 averaged by area, a pixel shown as glass where most of
    # the pixels it covers are.
    grey = standard_view(0.25 * (two_thirds(per_group) @ REC709_TO_XYZ[1])[..., None].repeat(3, axis=-1))
    shown = two_thirds(glass.astype(np.float64)[..., None])[..., 0] >= 0.5
    de_small = two_thirds(np.where(glass, de, 0.0)[..., None])[..., 0]
    weight = two_thirds(glass.astype(np.float64)[..., None])[..., 0]
    de_small = np.where(weight > 0, de_small / np.maximum(weight, 1e-12), 0.0)
    img = np.where(shown[..., None], heat(de_small), grey)
    h, w = de_small.shape
    bar_h = max(12, h // 30)
    ramp = np.linspace(0.0, SCALE_MAX, w)[None, :].repeat(bar_h, axis=0)
    bar = heat(ramp)
    for k in range(int(SCALE_MAX) + 1):   # white ticks at every whole ΔE00
        x = min(w - 1, int(round(k / SCALE_MAX * (w - 1))))
        bar[: bar_h // 2, max(0, x - 1): x + 1] = 255
    write_png_rgb8(str(out / "dusk_delta_e.png"), np.concatenate([img, bar], axis=0), paeth=True)

    text = json.dumps(report, indent=1)
    print(text)
    if args.json:
        Path(args.json).write_text(text + "\n")


if __name__ == "__main__":
    main()
