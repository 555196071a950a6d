"""The tables of docs/stack.md "Six real units": glassdb against LBNL's WINDOW engine (pywincalc
3.3.1) on six units built from the bundled glazing files, and the colour error of the two
shortcuts people take instead of a per-wavelength stack.

Usage (from the repository root, with the oracle Python):
    .venv/bin/python scripts/stack_table.py [--glassdb target/debug/glassdb] [--check]

Writes the tables between the `<!-- stack-table:begin -->` and `<!-- stack-table:end -->` lines
of docs/stack.md (with --check: fails when they differ from what it would write; the test
`stack::docs_table_is_current` runs that).

- glassdb: `glassdb stack LAYERS --angles 0,45,70 --json` with the default models (uncoated
  slab; coated layers: WINDOW-4 clear/bronze per wavelength, renormalised), photopic values
  (NFRC 300, D65 x CIE 1931 y-bar) and linear sRGB colours (CIE 1931, D65);
- pywincalc: python_oracle/stack_oracle.py's engine (its bronze curve on every coated layer)
  and its own colour (`GlazingSystem.color`: tristimulus values with the ASTM E308 CIE 1964
  10 degree observer under D65, turned into sRGB here by colour-science);
- shortcuts, against glassdb's per-wavelength unit, as CIEDE2000 differences of the colours
  (linear sRGB -> XYZ -> CIELAB with the D65 white of a perfect reflector): "RGB" combines the
  panes' RGB values with the same two-flux formulas (`--combine per-band`: each pane's colour
  at the angle from its per-wavelength model, as two registry glasses would be combined),
  "RGB, models per channel" also applies the panes' angle models to their RGB values
  (`--per-channel`), "outer pane only" takes the outer pane's own values (what a renderer with
  one pane shows).
"""

import argparse
import json
import pathlib
import subprocess
import sys
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402
import colour  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python_oracle"))
import stack_oracle  # noqa: E402
import pywincalc  # noqa: E402

colour.utilities.filter_warnings(colour_runtime_warnings=True, colour_usage_warnings=True)

ANGLES = [0, 45, 70]
BEGIN = "<!-- stack-table:begin -->"
END = "<!-- stack-table:end -->"

# name, glassdb layers (file[:options]) outside first, gaps
UNITS = [
    ("Double clear: clear 6 | 12.7 air | clear 6", ["CLEAR_6.DAT", "CLEAR_6.DAT"], "12.7"),
    ("Triple clear: clear 3 | 12.7 air | Optifloat 4.7 | 12.7 air | clear 6",
     ["CLEAR_3.DAT", "CLEAR5.LOF", "CLEAR_6.DAT"], "12.7"),
    ("Solarban R67 #2 | 12.7 argon | clear 6", ["igsdb_product_10693.json", "CLEAR_6.DAT"], "12.7:argon"),
    ("clear 6 | 12.7 argon | Energy Advantage low-e #3", ["CLEAR_6.DAT", "LOW-E_5.LOF"], "12.7:argon"),
    ("Stopray Titanium 34T #2 (turned round) | 12.7 argon | clear 6",
     ["nfrc_20748.oag:flip", "CLEAR_6.DAT"], "12.7:argon"),
    ("Laminate SB70 #2 on Pacifica / SGP / clear 6 | 12.7 argon | clear 6",
     ["igsdb_product_11148.json", "CLEAR_6.DAT"], "12.7:argon"),
]


def glazing(layer: str) -> str:
    name, sep, opts = layer.partition(":")
    return f"{ROOT / 'data' / 'glazing' / name}{sep}{opts}"


def stack(glassdb: str, layers: list, gap: str, extra=()) -> dict:
    cmd = [glassdb, "stack", *map(glazing, layers), "--gap", gap,
           "--angles", ",".join(map(str, ANGLES)), "--json", *extra]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def pywincalc_colours(layers: list) -> dict:
    """pywincalc's own sRGB colours (8-bit) of T and R out at 0 degrees."""
    standard = pywincalc.load_standard(str(pywincalc.standard_path / "W5_NFRC_2003.std"))
    solid, flips = [], []
    for layer in layers:
        name, _, opt = layer.partition(":")
        solid.append(pywincalc.convert_to_solid_layer(stack_oracle.product_of(ROOT / "data" / "glazing" / name)))
        flips.append(opt == "flip")
    gaps = [pywincalc.Layers.gap(thickness=0.0127) for _ in solid[1:]]
    system = pywincalc.GlazingSystem(optical_standard=standard, solid_layers=solid, gap_layers=gaps)
    for i, f in enumerate(flips):
        if f:
            system.flip_layer(i, True)
    res = system.color(theta=0).system_results.front
    hexes = {}
    for key, r in [("T", res.transmittance.direct_direct), ("Rf", res.reflectance.direct_direct)]:
        xyz = np.array([r.trichromatic.X, r.trichromatic.Y, r.trichromatic.Z]) / 100.0
        hexes[key] = srgb_hex(colour.XYZ_to_RGB(xyz, "sRGB"))
    return hexes


def srgb_hex(linear) -> str:
    encoded = colour.cctf_encoding(np.clip(np.asarray(linear, dtype=float), 0, 1), function="sRGB")
    return "#" + "".join("%02x" % int(round(v * 255)) for v in encoded)


def lab(linear):
    xyz = colour.RGB_to_XYZ(np.asarray(linear, dtype=float), "sRGB")
    return colour.XYZ_to_Lab(xyz, colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"])


def delta_e(a, b) -> float:
    return float(colour.delta_E(lab(a), lab(b), method="CIE 2000"))


def fmt3(values) -> str:
    return " / ".join(f"{v:.3f}" for v in values)


def tables(glassdb: str) -> str:
    angles = ",".join(map(str, ANGLES))
    head = (
        f"| unit | engine | Tv at {ANGLES[0]}/{ANGLES[1]}/{ANGLES[2]}° | Rv out | Rv in "
        "| colour of T, R out at 0° (sRGB) |\n|---|---|---|---|---|---|\n"
    )
    rows, shortcut_rows, bronze_rows = [], [], []
    for name, layers, gap in UNITS:
        name = name.replace("|", "\\|")
        ours = stack(glassdb, layers, gap)
        theirs = stack_oracle.window(angles, [glazing(l) for l in layers])["PHOTOPIC"]
        p = ours["photopic"]
        rgb = ours["rgb"]
        rows.append(
            f"| {name} | glassdb | {fmt3(p['T'])} | {fmt3(p['Rf'])} | {fmt3(p['Rb'])} "
            f"| T `{srgb_hex(rgb['T'][0])}`, R `{srgb_hex(rgb['Rf'][0])}` |"
        )
        theirs_hex = pywincalc_colours(layers)
        rows.append(
            f"| | pywincalc 3.3.1 | {fmt3(theirs['T'])} | {fmt3(theirs['Rf'])} | {fmt3(theirs['Rb'])} "
            f"| T `{theirs_hex['T']}`, R `{theirs_hex['Rf']}` (10° observer) |"
        )
        bronze = stack(glassdb, [fix_model(l) for l in layers], gap)["photopic"]
        worst = max(abs(a - b) for q in ("T", "Rf", "Rb") for a, b in zip(bronze[q], theirs[q]))
        bronze_rows.append(f"| {name} | {worst:.4f} |")
        per_band = stack(glassdb, layers, gap, ["--combine", "per-band"])["rgb"]
        per_channel = stack(glassdb, layers, gap, ["--per-channel"])["rgb"]
        outer = stack(glassdb, layers[:1], gap)["rgb"]
        cells = []
        for shortcut, digits in [(per_band, 2), (per_channel, 2), (outer, 1)]:
            for q in ("Rf", "T"):
                cells.append(
                    " / ".join(f"{delta_e(rgb[q][i], shortcut[q][i]):.{digits}f}" for i in range(len(ANGLES)))
                )
        share = ours["photopic"]["group_shares"]["front"][0]
        inner = 1.0 - share[0] / ours["photopic"]["Rf"][0]
        shortcut_rows.append(f"| {name} | {' | '.join(cells)} | {100 * inner:.0f} % |")
    out = [
        "Photopic values (NFRC 300: D65 × CIE 1931 ȳ) at 0 / 45 / 70°, glassdb with its default models,",
        "pywincalc with its own (the bronze curve on every coated layer):",
        "",
        head + "\n".join(rows),
        "",
        "The largest |glassdb − pywincalc| of Tv, Rv out, Rv in at 0 / 45 / 70° with glassdb's coated layers",
        "forced to `coated-bronze` (pywincalc's rule), what remains being our renormalisation of the curve:",
        "",
        "| unit | max abs difference |\n|---|---|\n" + "\n".join(bronze_rows),
        "",
        "The shortcuts against the per-wavelength unit, CIEDE2000 at 0 / 45 / 70°, and the share of the",
        "unit's visible reflectance (at 0°) that comes from the panes behind the outer one:",
        "",
        "| unit | RGB: R out | RGB: T | RGB, models per channel: R out | RGB, models per channel: T "
        "| outer pane only: R out | outer pane only: T | inner panes' share of Rv out |\n"
        "|---|---|---|---|---|---|---|---|\n" + "\n".join(shortcut_rows),
    ]
    return "\n".join(out) + "\n"


def fix_model(layer: str) -> str:
    """The layer with a coated file's model forced to coated-bronze (uncoated files as they are)."""
    name = layer.partition(":")[0]
    uncoated = name in ("CLEAR_3.DAT", "CLEAR_6.DAT", "CLEAR5.LOF")
    return layer if uncoated else f"{layer}:model=coated-bronze"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--glassdb", default=str(ROOT / "target" / "debug" / "glassdb"))
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    doc_path = ROOT / "docs" / "stack.md"
    doc = doc_path.read_text(encoding="utf-8")
    if BEGIN not in doc or END not in doc:
        sys.exit(f"{doc_path}: no {BEGIN} … {END} block")
    before, rest = doc.split(BEGIN, 1)
    _, after = rest.split(END, 1)
    new = before + BEGIN + "\n" + tables(args.glassdb) + END + after
    if args.check:
        if new != doc:
            sys.exit("docs/stack.md's tables are not what scripts/stack_table.py writes; run it")
        return
    doc_path.write_text(new, encoding="utf-8")


if __name__ == "__main__":
    main()
