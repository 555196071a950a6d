"""Oracle for `glassdb spectral`: the same numbers computed by colour-science 0.4.7.

Usage: spectral_oracle.py [--percent] [--extrapolate] FILE...

Prints one JSON object keyed by the file path as given. For every quantity present in the file
(`transmittance`, `reflectance`, `reflectance_back`):

- `paper`: {cmf name: [r, g, b]}: the spectrum aligned by colour onto the RGB CMFs' own grid
  (`SpectralDistribution.align`), then sum(value * c) / sum(c) per channel (method.md eqs. 15-20);
- `colorimetric`: {observer: {illuminant: {space: [r, g, b]}}}: `colour.sd_to_XYZ(method=
  "Integration")` of the spectrum with the CMFs trimmed to 360-780 nm at 1 nm and the illuminant,
  then `colour.XYZ_to_RGB(XYZ, space, illuminant=CCS_ILLUMINANTS[observer][illuminant])` with
  colour's default chromatic adaptation (CAT02, from the illuminant's white to the space's;
  a no-op up to rounding where they are equal), divided channel by channel by the same for a
  perfect (1.0) spectrum, i.e. the illuminant itself; space `xyz` is XYZ itself;
- `luminous_iso`: Y / 100 with CMFs and D65 aligned to 380-780 nm at 10 nm (ISO 9050 grid);
- `luminous_1nm`: the same at 1 nm (D65 linearly interpolated by colour).

The file readers here are independent of the Rust ones (written from the format notes in
fixtures/glazing/README.md; IGSDB v2 JSON from the schema of LBNL's py_igsdb_base_data). Wavelengths in um become nm as round(um * 1000, 6), as the Rust
reader does, so that both sides see bit-identical inputs. With `--extrapolate`, a spectrum that
does not cover a grid is extended by colour's constant extrapolation (only used on spectra whose
ends lie on the integer grid, where colour is right).
"""

import json
import re
import sys
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402

import colour  # noqa: E402
from colour import MSDS_CMFS, SDS_ILLUMINANTS, SpectralDistribution, SpectralShape  # noqa: E402

colour.utilities.filter_warnings(colour_runtime_warnings=True, colour_usage_warnings=True)

RGB_CMFS = {
    "wright-guild-1931": "Wright & Guild 1931 2 Degree RGB CMFs",
    "stiles-burch-1955": "Stiles & Burch 1955 2 Degree RGB CMFs",
    "stiles-burch-1959": "Stiles & Burch 1959 10 Degree RGB CMFs",
}
OBSERVERS = {
    "cie1931": "CIE 1931 2 Degree Standard Observer",
    "cie1964": "CIE 1964 10 Degree Standard Observer",
}
ILLUMINANTS = ["D65", "A", "E"]
SPACES = {
    "srgb": "sRGB",
    "rec2020": "ITU-R BT.2020",
    "acescg": "ACEScg",
    "aces2065-1": "ACES2065-1",
    "display-p3": "Display P3",
    "xyz": None,
}
QUANTITIES = ["transmittance", "reflectance", "reflectance_back"]


def um_to_nm(um):
    return np.round(np.asarray(um, dtype=float) * 1000.0, 6)


def read_csv(path, percent):
    with open(path, encoding="utf-8-sig") as f:
        lines = [ln.strip() for ln in f if ln.strip() and not ln.strip().startswith("#")]
    header = [h.strip().lower() for h in lines[0].split(",")]
    rows = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    out = {}
    for i, h in enumerate(header):
        col = rows[:, i]
        if h == "wavelength_nm":
            out["wl"] = col
        elif h in ("wavelength_um", "wavelength_µm"):
            out["wl"] = um_to_nm(col)
        else:
            key = {"t": "transmittance", "r": "reflectance", "rf": "reflectance", "rb": "reflectance_back"}[h]
            out[key] = col / 100.0 if percent else col
    return out


def read_optics(path):
    text = open(path, "rb").read().decode("cp1252", errors="replace")
    microns = None
    rows = []
    for ln in text.splitlines():
        s = ln.strip()
        if not s:
            continue
        if "{" in s:
            m = re.match(r"\{\s*Units,\s*Wavelength Units\s*\}\s*(.*)", s)
            if m:
                microns = "micron" in m.group(1).lower()
            continue
        rows.append([float(v) for v in s.split()])
    rows = np.array(rows)
    if microns is None:
        microns = not np.all(rows[:, 0] >= 100)
    wl = um_to_nm(rows[:, 0]) if microns else rows[:, 0]
    return {"wl": wl, "transmittance": rows[:, 1], "reflectance": rows[:, 2], "reflectance_back": rows[:, 3]}


def read_json(path):
    d = json.load(open(path, encoding="utf-8"))
    if "spectral_data" not in d:
        return read_json_v2(d)
    sd = d["spectral_data"]
    rows = sd["spectral_data"] if isinstance(sd, dict) else sd
    out = {"wl": um_to_nm([r["wavelength"] for r in rows])}
    for key, q in (("T", "transmittance"), ("Rf", "reflectance"), ("Rb", "reflectance_back")):
        if any(r.get(key) is not None for r in rows):
            out[q] = np.array([r[key] for r in rows], dtype=float)
    return out


def read_json_v2(d):
    """IGSDB v2: the specular tf, rf, rb of the angle block at incidence angle 0 (values may be
    decimal strings; w in um)."""
    blocks = d["physical_properties"]["optical_properties"]["optical_data"]["angle_blocks"]
    (normal,) = [b for b in blocks if float(b["incidence_angle"]) == 0.0]
    rows = normal["wavelength_data"]
    out = {"wl": um_to_nm([float(r["w"]) for r in rows])}
    for key, q in (("tf", "transmittance"), ("rf", "reflectance"), ("rb", "reflectance_back")):
        if any(r["specular"].get(key) is not None for r in rows):
            out[q] = np.array([float(r["specular"][key]) for r in rows])
    return out


def read_any(path, percent):
    low = path.lower()
    if low.endswith(".csv"):
        return read_csv(path, percent)
    if low.endswith(".json"):
        return read_json(path)
    return read_optics(path)


def shape_cmfs(name, shape):
    cmfs = MSDS_CMFS[name].copy()
    return cmfs.align(shape) if shape.interval != 1 else cmfs.trim(shape)


def paper(sd, cmf_name):
    cmfs = MSDS_CMFS[cmf_name]
    aligned = sd.copy().align(cmfs.shape)
    c = cmfs.values
    return list((aligned.values[:, None] * c).sum(axis=0) / c.sum(axis=0))


def colorimetric(sd, observer, illuminant, space):
    cmfs = shape_cmfs(OBSERVERS[observer], SpectralShape(360, 780, 1))
    ill = SDS_ILLUMINANTS[illuminant]
    XYZ = colour.sd_to_XYZ(sd, cmfs, ill, method="Integration")
    white = SpectralDistribution(np.ones(len(sd.wavelengths)), sd.wavelengths)
    XYZ_w = colour.sd_to_XYZ(white, cmfs, ill, method="Integration")
    cs = SPACES[space]
    if cs is None:
        return list(XYZ / XYZ_w)
    white = colour.CCS_ILLUMINANTS[OBSERVERS[observer]][illuminant]
    RGB = colour.XYZ_to_RGB(XYZ / 100, cs, illuminant=white)
    RGB_w = colour.XYZ_to_RGB(XYZ_w / 100, cs, illuminant=white)
    return list(RGB / RGB_w)


def luminous(sd, interval):
    shape = SpectralShape(380, 780, interval)
    cmfs = shape_cmfs(OBSERVERS["cie1931"], shape)
    ill = SDS_ILLUMINANTS["D65"].copy().align(shape)
    return float(colour.colorimetry.sd_to_XYZ_integration(sd, cmfs, ill)[1] / 100)


def off_grid(path):
    """Default colorimetric RGB (CIE 1931, D65, sRGB) of a uniform spectrum starting off the
    integer grid: `right` evaluates colour's own SpragueInterpolator at the grid's wavelengths
    (end values held outside the data); `colour` is what `colour.sd_to_XYZ` returns."""
    data = read_any(path, False)
    wl, v = data["wl"], data["transmittance"]
    cmfs = shape_cmfs(OBSERVERS["cie1931"], SpectralShape(360, 780, 1))
    ill = SDS_ILLUMINANTS["D65"].copy().align(cmfs.shape)
    grid = cmfs.wavelengths
    inside = (grid >= wl[0]) & (grid <= wl[-1])
    values = np.where(grid < wl[0], v[0], v[-1])
    values[inside] = colour.SpragueInterpolator(wl, v)(grid[inside])
    S = ill.values
    xyz = lambda r: (r * S) @ cmfs.values  # noqa: E731
    M = colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB
    right = (M @ xyz(values)) / (M @ xyz(np.ones_like(values)))
    sd = SpectralDistribution(v, wl)
    XYZ = colour.sd_to_XYZ(sd, cmfs, SDS_ILLUMINANTS["D65"], method="Integration")
    XYZ_w = colour.sd_to_XYZ(SpectralDistribution(np.ones_like(v), wl), cmfs, SDS_ILLUMINANTS["D65"], method="Integration")
    col = (M @ XYZ) / (M @ XYZ_w)
    return {"right": list(right), "colour": list(col)}


def main(argv):
    if argv and argv[0] == "--off-grid":
        json.dump(off_grid(argv[1]), sys.stdout)
        return
    percent = "--percent" in argv
    files = [a for a in argv if not a.startswith("--")]
    result = {}
    for path in files:
        data = read_any(path, percent)
        per_file = {}
        for q in QUANTITIES:
            if q not in data:
                continue
            sd = SpectralDistribution(data[q], data["wl"], name=q)
            per_file[q] = {
                "paper": {k: paper(sd, v) for k, v in RGB_CMFS.items()},
                "colorimetric": {
                    o: {i: {s: colorimetric(sd, o, i, s) for s in SPACES} for i in ILLUMINANTS} for o in OBSERVERS
                },
                "luminous_iso": luminous(sd, 10),
                "luminous_1nm": luminous(sd, 1),
            }
        result[path] = per_file
    json.dump(result, sys.stdout)


if __name__ == "__main__":
    main(sys.argv[1:])
