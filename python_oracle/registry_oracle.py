"""Oracle for `glassdb registry`: LBNL's WINDOW engine (pywincalc 3.3.1) computes photopic
(NFRC 300 / W5_NFRC_2003 standard: D65 x CIE 1931 y-bar, 380-780 nm) transmittance and front and
back reflectance of single glazing layers at given angles of incidence, with its own angular
models (uncoated: Fresnel slab from T0/R0 per wavelength; coated: WINDOW-4 polynomials).

Usage: registry_oracle.py ANGLES_CSV FILE [FILE ...]
    ANGLES_CSV: comma-separated angles in degrees, e.g. 0,10,20
Prints JSON: {"<file name>": {"angle_deg": [...], "T": [...], "Rf": [...], "Rb": [...],
                              "type": "<product type pywincalc sees>"}}
"""

import json
import pathlib
import sys

import pywincalc


def layer_of(path: pathlib.Path):
    if path.suffix.lower() == ".json":
        return pywincalc.parse_json_file(str(path))
    return pywincalc.parse_optics_file(str(path))


def main() -> None:
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    angles = [float(a) for a in sys.argv[1].split(",")]
    standard = pywincalc.load_standard(str(pywincalc.standard_path / "W5_NFRC_2003.std"))
    out = {}
    for name in sys.argv[2:]:
        path = pathlib.Path(name)
        layer = layer_of(path)
        system = pywincalc.GlazingSystem(optical_standard=standard, solid_layers=[layer])
        rows = {"angle_deg": angles, "T": [], "Rf": [], "Rb": []}
        for theta in angles:
            res = system.optical_method_results("PHOTOPIC", theta=theta).system_results
            rows["T"].append(res.front.transmittance.direct_direct)
            rows["Rf"].append(res.front.reflectance.direct_direct)
            rows["Rb"].append(res.back.reflectance.direct_direct)
        rows["type"] = str(layer.material_type) if hasattr(layer, "material_type") else ""
        out[path.name] = rows
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
