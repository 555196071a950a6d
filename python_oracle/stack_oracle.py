"""Oracle for `glassdb stack` (docs/stack.md).

Usage:
    stack_oracle.py window ANGLES LAYER [LAYER ...]
        ANGLES: comma-separated angles of incidence in degrees, e.g. 0,10,20
        LAYER: a glazing file (Optics text or IGSDB JSON, v1 or v2), `FILE:flip` to turn it round
    stack_oracle.py rgb SPACE < STACK_JSON
        STACK_JSON: the output of `glassdb stack ... --json --spectra`

`window` runs LBNL's WINDOW engine (pywincalc 3.3.1, standard W5_NFRC_2003, the layers
separated by 12.7 mm air gaps, which do not change the optics) and prints
    {"angles_deg": [...],
     "PHOTOPIC": {"T": [...], "Rf": [...], "Rb": [...],
                  "absorptance_front": [[per layer, outside first] per angle],
                  "absorptance_back": [[per layer, outside first] per angle]},
     "SOLAR": {...}}
with the system's direct-direct values. pywincalc applies its own angle models: the Fresnel slab
to monolithic layers and WINDOW-4's bronze polynomial to every other layer (coated, laminate).
pywincalc 3.3.1 lists the back-side layer absorptances from the inside out (Windows-CalcEngine's
`CAbsorptancesMultiPane` walks the layers from the back for that side); they are put back in
layer order here.

`rgb` integrates the per-wavelength system spectra that glassdb prints with colour-science
0.4.7 (the colorimetric method of spectral_oracle.py: CIE 1931, D65, 360-780 nm at 1 nm, the
space's matrix with CAT02) and prints {"T": [[r, g, b] per angle], "Rf": ..., "Rb": ...}.
"""

import json
import pathlib
import sys

import pywincalc

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from spectral_oracle import colorimetric  # noqa: E402

from colour import SpectralDistribution  # noqa: E402

GAP_M = 0.0127
METHODS = ["PHOTOPIC", "SOLAR"]


def product_of(path: pathlib.Path):
    if path.suffix.lower() == ".json":
        return pywincalc.parse_json_file(str(path))
    return pywincalc.parse_optics_file(str(path))


def window(angles_arg: str, layer_args: list) -> dict:
    angles = [float(a) for a in angles_arg.split(",")]
    standard = pywincalc.load_standard(str(pywincalc.standard_path / "W5_NFRC_2003.std"))
    layers, flips = [], []
    for arg in layer_args:
        name, _, option = arg.partition(":")
        if option not in ("", "flip"):
            sys.exit(f"unknown layer option `{option}` in {arg}")
        layers.append(pywincalc.convert_to_solid_layer(product_of(pathlib.Path(name))))
        flips.append(option == "flip")
    gaps = [pywincalc.Layers.gap(thickness=GAP_M) for _ in layers[1:]]
    system = pywincalc.GlazingSystem(optical_standard=standard, solid_layers=layers, gap_layers=gaps)
    for i, flip in enumerate(flips):
        if flip:
            system.flip_layer(i, True)
    out = {"angles_deg": angles}
    for method in METHODS:
        rows = {"T": [], "Rf": [], "Rb": [], "absorptance_front": [], "absorptance_back": []}
        for theta in angles:
            res = system.optical_method_results(method, theta=theta)
            s = res.system_results
            rows["T"].append(s.front.transmittance.direct_direct)
            rows["Rf"].append(s.front.reflectance.direct_direct)
            rows["Rb"].append(s.back.reflectance.direct_direct)
            rows["absorptance_front"].append([l.front.absorptance.direct for l in res.layer_results])
            rows["absorptance_back"].append([l.back.absorptance.direct for l in res.layer_results][::-1])
        out[method] = rows
    return out


def rgb(space: str, stack: dict) -> dict:
    spectra = stack["spectra"]
    wl = spectra["wavelength_nm"]
    out = {}
    for key in ["T", "Rf", "Rb"]:
        out[key] = [
            [float(c) for c in colorimetric(SpectralDistribution(values, wl), "cie1931", "D65", space)]
            for values in spectra[key]
        ]
    return out


def main() -> None:
    if len(sys.argv) >= 4 and sys.argv[1] == "window":
        result = window(sys.argv[2], sys.argv[3:])
    elif len(sys.argv) == 3 and sys.argv[1] == "rgb":
        result = rgb(sys.argv[2], json.load(sys.stdin))
    else:
        sys.exit(__doc__)
    json.dump(result, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
