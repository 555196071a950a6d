"""Prints docs/colour.md's table: a real tinted glass's r0 and t0 in every RGB space, from
`glassdb registry build --space …` and from colour-science 0.4.7 (python_oracle/spectral_oracle.py)
side by side.

Usage (from the repository root, after `cargo build --release` and with the oracle venv):
    .venv/bin/python scripts/colour_table.py > /tmp/table.md
"""

import json
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SPECTRUM = ROOT / "data/glazing/913.json"
SPACES = ["srgb", "rec2020", "acescg", "aces2065-1", "display-p3", "xyz"]
NAMES = {"srgb": "linear Rec.709 / sRGB", "rec2020": "linear Rec.2020", "acescg": "ACEScg (AP1)",
         "aces2065-1": "ACES2065-1 (AP0)", "display-p3": "linear Display P3", "xyz": "CIE XYZ"}


def main():
    with tempfile.TemporaryDirectory() as d:
        catalog = pathlib.Path(d) / "catalog.toml"
        catalog.write_text(f'[[glass]]\nid = 5\nname = "green"\nspectral = "{SPECTRUM}"\n'
                           'model = "uncoated"\n')
        out = pathlib.Path(d) / "reg.json"
        subprocess.run([ROOT / "target/release/glassdb", "registry", "build", catalog,
                        "--space", ",".join(SPACES), "-o", out], check=True,
                       capture_output=True)
        reg = json.loads(out.read_text())
    oracle = json.loads(subprocess.run(
        [sys.executable, ROOT / "python_oracle/spectral_oracle.py", SPECTRUM], check=True,
        capture_output=True, text=True).stdout)[str(SPECTRUM)]
    print("| space | | glassdb R, G, B | colour-science R, G, B | max diff |")
    print("|---|---|---|---|---|")
    for table, space in zip(reg["tables"], SPACES):
        assert table["spectral"]["space"] == space
        glass = table["glasses"][0]
        for key, quantity in [("t0", "transmittance"), ("r0", "reflectance")]:
            ours = glass[key]
            theirs = oracle[quantity]["colorimetric"]["cie1931"]["D65"][space]
            diff = max(abs(a - b) for a, b in zip(ours, theirs))
            fmt = lambda v: ", ".join(f"{x:.6f}" for x in v)  # noqa: E731
            print(f"| {NAMES[space]} (`{space}`) | {key} | {fmt(ours)} | {fmt(theirs)} | "
                  f"{diff:.1e} |")


if __name__ == "__main__":
    main()
