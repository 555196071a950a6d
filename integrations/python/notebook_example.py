"""A notebook-style tour of glassdb from Python (run as a script, or cell by cell in Jupyter).

    python integrations/python/notebook_example.py OUT_DIR

1. Build an insulated unit from its layers (the stack engine, as `glassdb stack` does) and
   look at its photopic and RGB transmittance and reflectance against the angle.
2. Plot those curves (matplotlib when it is installed; otherwise the curves are written as a
   CSV table to plot elsewhere).
3. Composite the bundled atrium frame with the bundled registry, and again with the registry's
   other glass on every pane, and write both composites as .npy arrays.
"""

import csv
import sys
from pathlib import Path

import numpy as np

import glassdb

ROOT = Path(__file__).resolve().parents[2]


def unit_curves(angles_deg=tuple(range(0, 90, 5))):
    """# %% 1. A double-glazed unit: 6 mm clear, 12.7 mm argon, 3 mm clear."""
    layers = [ROOT / "fixtures/glazing/CLEAR_6.DAT", ROOT / "fixtures/glazing/CLEAR_3.DAT"]
    unit = glassdb.stack([str(p) for p in layers], gaps=["12.7:argon"], angles=list(angles_deg))
    return unit


def plot_curves(unit, out_dir):
    """# %% 2. Tv, Rv (outside) and T per RGB channel against the angle of incidence."""
    angles = unit["angles_deg"]
    rows = {
        "Tv": unit["photopic"]["T"],
        "Rv_out": unit["photopic"]["Rf"],
        "T_R": [t[0] for t in unit["rgb"]["T"]],
        "T_G": [t[1] for t in unit["rgb"]["T"]],
        "T_B": [t[2] for t in unit["rgb"]["T"]],
    }
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        path = Path(out_dir) / "unit_curves.csv"
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["angle_deg", *rows])
            for i, a in enumerate(angles):
                w.writerow([a, *(rows[k][i] for k in rows)])
        return path
    fig, ax = plt.subplots()
    for name, values in rows.items():
        ax.plot(angles, values, label=name)
    ax.set_xlabel("angle of incidence (°)")
    ax.legend()
    path = Path(out_dir) / "unit_curves.png"
    fig.savefig(path)
    return path


def read_packed_mask(path):
    """The atrium's packed mask PNG as uint8 (H, W, 3), with the oracles' PNG reader."""
    sys.path.insert(0, str(ROOT / "python_oracle"))
    from exr_oracle import read_png

    return np.ascontiguousarray(read_png(str(path))[..., :3].astype(np.uint8))


def composite_atrium(out_dir):
    """# %% 3. The atrium composited with its glasses, then with glass 2 everywhere."""
    a = ROOT / "fixtures/atrium"
    trans = glassdb.read_passes(a / "trans.exr")[0].pixels
    refl = [glassdb.read_passes(a / f"refl_{k}.exr")[0].pixels for k in range(3)]
    mask = read_packed_mask(a / "mask.png")
    registry = glassdb.Registry.load()
    planes = a / "virtual/planes.json"
    first = glassdb.compose(trans, refl, mask, registry=registry, planes=planes)
    swapped = mask.copy()
    swapped[..., 1] = np.where(swapped[..., 1] != 0, 2, 0)
    second = glassdb.compose(trans, refl, swapped, registry=registry, planes=planes)
    np.save(Path(out_dir) / "atrium.npy", first)
    np.save(Path(out_dir) / "atrium_glass2.npy", second)
    return first, second


def main(out_dir):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    unit = unit_curves()
    print("Tv at 0°:", round(unit["photopic"]["T"][0], 4), "plot:", plot_curves(unit, out))
    first, second = composite_atrium(out)
    print("mean composite:", first.mean(), "with glass 2 everywhere:", second.mean())


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "target/notebook_example")
