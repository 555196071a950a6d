"""The numbers of docs/blender.md "Lamps in reflections", from the runs of
scripts/blender_lamps_validation.sh.

    .venv/bin/python scripts/blender_lamps_validation.py DIR [FIGURE.png]

DIR holds with/seed{0,1}/ and without/seed{0,1}/ (each a `glassdb blender render --reference`
run of the `lamps` scene, frame 1). For each variant, the composite of seed 0 against the
Cycles reference of seed 1 (independent noise), PSNR with peak 1.0 on linear radiance (R, G,
B), as docs/validation.md, in glass (the mask has an id), over the reflected lamps (glass pixels
where the two-seed mean reference exceeds the composite without lamps by more than 0.05 in
some channel: the glint and the area lamp's image) and over the rest of the glass; and the mean
signed error (reference − composite) in glass per channel. The references' own PSNR (seed 0
against seed 1) is the noise floor. The figure: the reference (mean of its seeds) | without |
with, linear radiance shown sRGB-encoded and clipped.

Needs numpy and OpenEXR (the project's .venv). Licence: same as the project, MIT OR Apache-2.0.
"""

import math
import os
import sys

from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python_oracle"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from exr_oracle import write_png_rgb8  # noqa: E402
from blender_example_figure import srgb8  # noqa: E402
from blender_validation import read, rgb  # noqa: E402


def psnr(a, b, sel):
    d = (a - b)[sel]
    m = float(np.mean(d * d))
    return 10.0 * math.log10(1.0 / m) if m > 0 else float("inf")


def main():
    root = sys.argv[1]
    path = lambda variant, seed, stem: os.path.join(root, variant, "seed%d" % seed, "%s.0001.exr" % stem)
    (idm,) = read(path("with", 0, "mask"), ["id"])
    glass = idm > 0
    comp = {v: [rgb(path(v, s, "composite")) for s in (0, 1)] for v in ("with", "without")}
    ref = {v: [rgb(path(v, s, "reference")) for s in (0, 1)] for v in ("with", "without")}
    mean_ref = (ref["with"][0] + ref["with"][1]) / 2
    lamps = glass & ((mean_ref - (comp["without"][0] + comp["without"][1]) / 2).max(axis=-1) > 0.05)
    rest = glass & ~lamps
    print("%d glass pixels, %d of them reflecting lamps" % (glass.sum(), lamps.sum()))
    print()
    print("| lamps in the reflection passes | PSNR in glass | over the reflected lamps | rest of the glass | mean reference − composite in glass (R, G, B) | the references' seeds, in glass |")
    print("|---|---|---|---|---|---|")
    for v in ("without", "with"):
        c, r = comp[v][0], ref[v][1]
        bias = (r - c)[glass].mean(axis=0)
        print("| %s | %.2f dB | %.2f dB | %.2f dB | %s | %.2f dB |" % (
            v, psnr(c, r, glass), psnr(c, r, lamps), psnr(c, r, rest),
            ", ".join("%+.4f" % b for b in bias), psnr(ref[v][0], ref[v][1], glass)))
    if len(sys.argv) > 2:
        mean = lambda v: (comp[v][0] + comp[v][1]) / 2
        write_png_rgb8(sys.argv[2], np.concatenate(
            [srgb8(mean_ref), srgb8(mean("without")), srgb8(mean("with"))], axis=1))


main()
