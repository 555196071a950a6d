"""Oracle for `glassdb registry`: LBNL's WINDOW engine (pywincalc 3.3.1) computes photopic
(NFRC 300 / W5_NFRC_2003 standard: D65 x CIE 1931 y-bar, 380-780 nm) transmittance and front and
back reflectance of single glazing layers at given angles of incidence, with its own angular
models (uncoated: Fresnel slab from T0/R0 per wavelength; coated: WINDOW-4 polynomials).

Usage: registry_oracle.py ANGLES_CSV FILE [FILE ...]
    ANGLES_CSV: comma-separated angles in degrees, e.g. 0,10,20
Prints JSON: {"<file name>": {"angle_deg": [...], "T": [...], "Rf": [...], "Rb": [...],
                              "type": "<product type pywincalc sees>"}}

Usage: registry_oracle.py hemispherical FILE [FILE ...]
Prints JSON: {"<file name>": {"window": {"T": .., "Tb": .., "Rf": .., "Rb": ..},
                              "fine": {"T": .., "Rf": .., "Rb": ..}}}
"window": WINDOW's hemispherical (diffuse-diffuse) values: what the layer passes and reflects of
uniform light from the whole hemisphere, 2 * integral of x(theta) cos(theta) sin(theta) over
0..90 deg. WINDOW takes that integral by the trapezoidal rule on its direct-direct values at
0, 10, ..., 90 deg (reproduced to 1e-9 for CLEAR_3.DAT), 0.004-0.005 low for clear glass.
"fine": the same integral of the same direct-direct values by Simpson's rule at 1 deg steps, the
quadrature error gone (2 deg steps leave 4e-4 in R, which rises steeply near grazing).
"""

import json
import math
import pathlib
import sys

import pywincalc


def layer_of(path: pathlib.Path):
    if path.suffix.lower() == ".json":
        return pywincalc.parse_json_file(str(path))
    return pywincalc.parse_optics_file(str(path))


def hemispherical_fine(system) -> dict:
    """2 * integral of x cos sin over theta by Simpson's rule at 1 deg, for T, Rf, Rb."""
    steps = 90
    h = math.radians(1.0)
    sums = {"T": 0.0, "Rf": 0.0, "Rb": 0.0}
    for i in range(steps + 1):
        theta = i * h
        weight = 1 if i in (0, steps) else (4 if i % 2 else 2)
        w = weight * h / 3 * 2 * math.cos(theta) * math.sin(theta)
        res = system.optical_method_results("PHOTOPIC", theta=float(i)).system_results
        sums["T"] += w * res.front.transmittance.direct_direct
        sums["Rf"] += w * res.front.reflectance.direct_direct
        sums["Rb"] += w * res.back.reflectance.direct_direct
    return sums


def hemispherical(files) -> dict:
    """WINDOW's diffuse-diffuse values and the fine integral, per file."""
    out = {}
    for name in files:
        path = pathlib.Path(name)
        layer = layer_of(path)
        system = pywincalc.GlazingSystem(optical_standard=standard_nfrc(), solid_layers=[layer])
        res = system.optical_method_results("PHOTOPIC", theta=0).system_results
        out[path.name] = {
            "window": {
                "T": res.front.transmittance.diffuse_diffuse,
                "Tb": res.back.transmittance.diffuse_diffuse,
                "Rf": res.front.reflectance.diffuse_diffuse,
                "Rb": res.back.reflectance.diffuse_diffuse,
            },
            "fine": hemispherical_fine(system),
        }
    return out


def standard_nfrc():
    return pywincalc.load_standard(str(pywincalc.standard_path / "W5_NFRC_2003.std"))


def main() -> None:
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    if sys.argv[1] == "hemispherical":
        json.dump(hemispherical(sys.argv[2:]), sys.stdout, indent=1)
        sys.stdout.write("\n")
        return
    angles = [float(a) for a in sys.argv[1].split(",")]
    standard = standard_nfrc()
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
