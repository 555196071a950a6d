#!/usr/bin/env python3
"""Export colour-science's CIE illuminant tables and their white points to CSV.

Run from this folder with colour-science installed (the files here were written with
colour-science 0.4.7):

    python export_illuminants.py

Writes one `NAME.csv` per illuminant (header `wavelength_nm,power`, one row per wavelength,
ascending: the same format `glassdb spectral --illuminant FILE.csv` and `glassdb registry build
--light NAME=FILE.csv` read) and `whites.csv` (the white point in CIE xy of every illuminant for
both standard observers, as colour's `CCS_ILLUMINANTS` holds it). Values are written with the
shortest decimal string that round-trips to the same IEEE-754 double (numpy
format_float_positional, unique=True), so reading them back gives bit-identical numbers; the
script checks that round trip after writing.
"""
import sys
import warnings

warnings.filterwarnings("ignore")
import numpy as np  # noqa: E402

import colour  # noqa: E402

# The illuminants glassdb bundles, in its order: CIE D series, A, E, the F series FL1-FL12 and
# the CIE 15:2018 LED series.
NAMES = (
    ["D50", "D55", "D65", "D75", "A", "E"]
    + [f"FL{i}" for i in range(1, 13)]
    + ["LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1",
       "LED-V2"]
)
OBSERVERS = {
    "cie1931": "CIE 1931 2 Degree Standard Observer",
    "cie1964": "CIE 1964 10 Degree Standard Observer",
}


def fmt(x: float) -> str:
    return np.format_float_positional(float(x), unique=True, trim="-")


def main() -> int:
    for name in NAMES:
        sd = colour.SDS_ILLUMINANTS[name]
        assert sd.interpolator is colour.LinearInterpolator, name
        w, v = sd.wavelengths, sd.values
        fname = f"{name}.csv"
        with open(fname, "w", encoding="utf-8", newline="\n") as fh:
            fh.write("wavelength_nm,power\n")
            for wl, p in zip(w, v):
                fh.write(f"{fmt(wl)},{fmt(p)}\n")
        back = np.loadtxt(fname, delimiter=",", skiprows=1, ndmin=2)
        assert np.array_equal(back[:, 0], w) and np.array_equal(back[:, 1], v), fname
        print(f"{fname}: {w[0]:g}-{w[-1]:g} nm step {w[1] - w[0]:g}, {len(w)} rows, "
              f"power {v.min():g}-{v.max():g}")
    rows = []
    for name in NAMES:
        for key, observer in OBSERVERS.items():
            x, y = colour.CCS_ILLUMINANTS[observer][name]
            rows.append((name, key, float(x), float(y)))
    with open("whites.csv", "w", encoding="utf-8", newline="\n") as fh:
        fh.write("illuminant,observer,x,y\n")
        for name, key, x, y in rows:
            fh.write(f"{name},{key},{fmt(x)},{fmt(y)}\n")
    with open("whites.csv", encoding="utf-8") as fh:
        back = [line.strip().split(",") for line in fh.readlines()[1:]]
    assert [(n, o, float(x), float(y)) for n, o, x, y in back] == rows
    print(f"whites.csv: {len(rows)} rows; colour-science {colour.__version__}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
