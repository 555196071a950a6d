#!/usr/bin/env python3
"""Regenerates the CSV fixtures made from CLEAR_3.DAT (see fixtures/glazing/README.md).

    python3 python_oracle/make_instrument_csv.py [DIR]     (default: fixtures/glazing)

The same 111 rows of LBNL's Generic Clear Glass 3 mm (CLEAR_3.DAT, NFRC 102: wavelength in um,
T, Rf, Rb as fractions with 4 decimals) written four ways. Numbers are converted in decimal
arithmetic, so every file holds exactly the same values:

1. CLEAR_3.csv: glassdb's own CSV, `wavelength_um,T,Rf,Rb`, the rows as written in the DAT file.
2. CLEAR_3_cary.csv: laid out as spectrophotometer software exports a scan (the layout of Agilent
   Cary WinUV's CSV): a title line, quoted headers with units `"Wavelength (nm)","%T","%R"`, a
   trailing comma on every line, values in percent, rows from long to short wavelength, and a
   metadata block after a blank line.
3. CLEAR_3_semicolon.csv: a European spreadsheet export: a title line, `;` separators, decimal
   commas, headers `Wavelength [nm];T [%];R [%];Rb [%]`, CRLF line ends.
4. CLEAR_3_tab.txt: tab-separated, header `Wavelength (um)` with the micro sign in Windows-1252
   (byte 0xB5), fractions; a .txt name, so the content decides the format.

Only the layout imitates instruments; the data are CLEAR_3.DAT's, not a measurement.
"""

import os
import sys
from decimal import Decimal


def read_dat(path):
    rows = []
    for line in open(path, "rb").read().decode("cp1252").splitlines():
        s = line.strip()
        if not s or "{" in s:
            continue
        rows.append(s.split())
    return rows


def percent(text):
    return f"{Decimal(text) * 100:.2f}"


def nm(text):
    return f"{Decimal(text) * 1000:.1f}"


def main(argv):
    out = argv[1] if len(argv) > 1 else "fixtures/glazing"
    rows = read_dat(os.path.join(out, "CLEAR_3.DAT"))
    assert len(rows) == 111 and all(len(r) == 4 for r in rows)

    plain = ["# Generic Clear Glass 3 mm (LBNL CLEAR_3.DAT, NFRC 102) as glassdb CSV", "wavelength_um,T,Rf,Rb"]
    plain += [",".join(r) for r in rows]
    with open(os.path.join(out, "CLEAR_3.csv"), "w", newline="\n") as f:
        f.write("\n".join(plain) + "\n")

    cary = ["CLEAR_3 Generic Clear Glass 3 mm,,,", '"Wavelength (nm)","%T","%R",']
    cary += [f"{nm(w)},{percent(t)},{percent(rf)}," for w, t, rf, _ in reversed(rows)]
    cary += [
        "",
        "Source: LBNL CLEAR_3.DAT (NFRC 102) in the layout of a spectrophotometer export,,,",
        "Collection Time: not measured,,,",
    ]
    with open(os.path.join(out, "CLEAR_3_cary.csv"), "w", newline="\n") as f:
        f.write("\n".join(cary) + "\n")

    semicolon = ["Probe: CLEAR_3 (Generic Clear Glass 3 mm)", "Wavelength [nm];T [%];R [%];Rb [%]"]
    semicolon += [";".join([nm(w), percent(t), percent(rf), percent(rb)]).replace(".", ",") for w, t, rf, rb in rows]
    with open(os.path.join(out, "CLEAR_3_semicolon.csv"), "w", newline="\r\n") as f:
        f.write("\n".join(semicolon) + "\n")

    tab = ["Wavelength (\u00b5m)\tT\tRf\tRb"] + ["\t".join(r) for r in rows]
    with open(os.path.join(out, "CLEAR_3_tab.txt"), "wb") as f:
        f.write(("\n".join(tab) + "\n").encode("cp1252"))


if __name__ == "__main__":
    main(sys.argv)
