"""The numbers of docs/blender.md "Light groups", from the runs of
scripts/blender_groups_validation.sh.

    .venv/bin/python scripts/blender_groups_validation.py DIR

DIR holds groups/seed{0,1}/ (each group composited with the table of its light, the Cycles
reference rendered per group with the glass of its light) and one/seed{0,1}/ (the bundled
one-light registry: every group with the D65 table, as the one-group pipeline does, and a
one-table reference). Per frame, PSNR with peak 1.0 on linear radiance in glass (the mask has
an id) of the composite of seed 0 against the reference of seed 1 (independent noise):
groups vs the per-light reference, the one-group pipeline vs its own one-table reference
(today's figure), and the one-table composite vs the per-light reference (what a single table
gets wrong); the references' seeds against each other are the noise floor. Also the mean
signed error (reference − composite) in glass, per channel.

Needs numpy and OpenEXR (the project's .venv). Licence: same as the project, MIT OR Apache-2.0.
"""

import os
import sys

from pathlib import Path

import numpy as np
import OpenEXR

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_validation as bv  # noqa: E402


def psnr(a, b, sel):
    return bv.psnr(bv.mse(a, b, sel))


def layer_rgb(path, layer=""):
    """R, G, B of `layer` (the beauty `ViewLayer.Combined` of a multilayer file, or the plain
    channels of a single-layer one) as an (h, w, 3) array."""
    with OpenEXR.File(path) as f:
        ch = f.channels()
        prefix = layer + "." if layer else ""
        for key in (prefix + "RGBA", prefix + "RGB"):
            if key in ch:
                return np.asarray(ch[key].pixels, dtype=np.float64)[..., :3]
        return np.stack([np.asarray(ch[prefix + c].pixels, dtype=np.float64) for c in "RGB"],
                        axis=-1)


def glass_ids(path):
    with OpenEXR.File(path) as f:
        return np.asarray(f.channels()["id"].pixels, dtype=np.float64)


def main():
    root = sys.argv[1]
    path = lambda v, s, stem, f: os.path.join(root, v, "seed%d" % s, "%s.%04d.exr" % (stem, f))
    frames = sorted(int(n.split(".")[1]) for n in os.listdir(os.path.join(root, "groups", "seed0"))
                    if n.startswith("composite."))
    print("| frame | glass pixels | groups vs per-light reference | one-group pipeline vs its one-table reference (today) | one table vs per-light reference | references' seeds (per-light) | mean reference − composite in glass, groups | same, one table vs per-light |")
    print("|---|---|---|---|---|---|---|---|")
    for f in frames:
        glass = glass_ids(path("groups", 0, "mask", f)) > 0
        comp = {v: layer_rgb(path(v, 0, "composite", f)) for v in ("groups", "one")}
        ref = {(v, s): layer_rgb(path(v, s, "reference", f), "ViewLayer.Combined")
               for v in ("groups", "one") for s in (0, 1)}
        r = ref[("groups", 1)]
        bias = lambda c, r: ", ".join("%+.4f" % b for b in (r - c)[glass].mean(axis=0))
        print("| %d | %d | %.2f dB | %.2f dB | %.2f dB | %.2f dB | %s | %s |" % (
            f, glass.sum(), psnr(comp["groups"], r, glass),
            psnr(comp["one"], ref[("one", 1)], glass), psnr(comp["one"], r, glass),
            psnr(ref[("groups", 0)], r, glass), bias(comp["groups"], r), bias(comp["one"], r)))


if __name__ == "__main__":
    main()
