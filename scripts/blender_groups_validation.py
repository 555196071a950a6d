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


def layer_rgb(path, layer="ViewLayer.Combined"):
    """R, G, B of `layer` (OpenEXR 3 groups a layer's R, G, B, A under its name; a
    single-layer file's under "RGBA") as an (h, w, 3) array."""
    with OpenEXR.File(path) as f:
        ch = f.channels()
        key = next(k for k in (layer, "RGBA", "RGB") if k in ch)
        return np.asarray(ch[key].pixels, dtype=np.float64)[..., :3]


def glass_ids(path):
    with OpenEXR.File(path) as f:
        return np.asarray(f.channels()["id"].pixels, dtype=np.float64)


def main():
    root = sys.argv[1]
    path = lambda v, s, stem, f: os.path.join(root, v, "seed%d" % s, "%s.%04d.exr" % (stem, f))
    frames = sorted(int(n.split(".")[1]) for n in os.listdir(os.path.join(root, "groups", "seed0"))
                    if n.startswith("composite."))
    print("PSNR in glass (all glass pixels / without the lamps' images, where the mean of the "
          "per-light reference's seeds exceeds 1):")
    print()
    print("| frame | glass pixels | groups vs per-light reference | one-group pipeline vs its one-table reference (today) | one table vs per-light reference | references' seeds (per-light) |")
    print("|---|---|---|---|---|---|")
    changes = []
    for f in frames:
        ids = glass_ids(path("groups", 0, "mask", f))
        glass = ids > 0
        comp = {(v, s): layer_rgb(path(v, s, "composite", f)) for v in ("groups", "one")
                for s in (0, 1)}
        ref = {(v, s): layer_rgb(path(v, s, "reference", f)) for v in ("groups", "one")
               for s in (0, 1)}
        r = ref[("groups", 1)]
        dim = glass & (((ref[("groups", 0)] + r) / 2).max(axis=-1) <= 1.0)
        both = lambda a, b: "%.2f / %.2f dB" % (psnr(a, b, glass), psnr(a, b, dim))
        print("| %d | %d / %d | %s | %s | %s | %s |" % (
            f, glass.sum(), dim.sum(), both(comp[("groups", 0)], r),
            both(comp[("one", 0)], ref[("one", 1)]), both(comp[("one", 0)], r),
            both(ref[("groups", 0)], r)))
        for i in sorted(set(ids[glass].astype(int))):
            sel = dim & (ids == i)
            cycles = (ref[("groups", 1)] - ref[("one", 1)])[sel].mean(axis=0)
            ours = (comp[("groups", 1)] - comp[("one", 1)])[sel].mean(axis=0)
            changes.append((f, i, sel.sum(), cycles, ours))
    print()
    print("Mean change in glass from one table to a table per light (seed 1 both: the same "
          "paths), Cycles' reference against the pipeline's composite:")
    print()
    print("| frame | glass id | pixels | Cycles (R, G, B) | pipeline (R, G, B) |")
    print("|---|---|---|---|---|")
    fmt = lambda v: ", ".join("%+.4f" % x for x in v)
    for f, i, n, cycles, ours in changes:
        print("| %d | %d | %d | %s | %s |" % (f, i, n, fmt(cycles), fmt(ours)))


if __name__ == "__main__":
    main()
