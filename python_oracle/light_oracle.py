"""Oracle for glassdb's lights (docs/colour.md, "Lights"): the same numbers computed by
colour-science 0.4.7.

Usage:
    light_oracle.py illuminants DIR
        Checks DIR (data/illuminants) against colour's datasets: every NAME.csv equal to
        SDS_ILLUMINANTS[NAME] (wavelengths and values, bit for bit) and whites.csv equal to
        CCS_ILLUMINANTS. Prints {"checked": n, "mismatches": [...]}; exit 1 on a mismatch.

    light_oracle.py tables [--observer cie1931|cie1964] [--white-balance light|NAME]
                           --space S [--space S ...] --light NAME=ILLUMINANT [--light ...]
                           SOURCE [SOURCE ...]
        Per SOURCE, light and space, the colorimetric r, g, b of every quantity the source has:
        {SOURCE: {light: {space: {"transmittance": [r, g, b], "reflectance": ...,
        "reflectance_back": ...}}}}. SOURCE is a glazing file (read by spectral_oracle.py's own
        readers) or `stack:FILE.json`, the output of `glassdb stack --json --spectra` (its
        system spectra at the first angle: T, Rf, Rb).

    light_oracle.py emitter-pass --light ILLUMINANT [--white-balance W] [--space S]
                                 --size WxH [--scale K] --out PASS.exr
        A flat emitter: a float EXR (untagged, R G B) whose every pixel is the emitter's colour
        as the camera records it, T·XYZ(S)/Y(S) with T = M_space·CAT02(camera white → space
        white): white for a camera balanced to the light (the default), the light's own colour
        for one balanced to a fixed white (D65). --scale 0 gives a black pass.

    light_oracle.py delta-e --composite OUT.exr --mask MASK.png --light ILLUMINANT
                            [--white-balance W] [--space S] --glass ID=SOURCE [--glass ...]
        For each glass, the mean composite colour over its mask pixels against the emitter seen
        through the glass, T·XYZ(τ·S)/Y(S), both taken to CIE Lab (M_space⁻¹, reference white
        the space's) and compared by CIEDE2000: {ID: {"delta_e00": …, "composite": [r, g, b],
        "expected": [r, g, b], "pixels": n}}.

    light_oracle.py mask --ids 1,2,... --block N --out MASK.png
        An 8-bit packed mask (G = id, B = 255: normal incidence) of one N×N block per id, in a
        row; prints its size.

The light: a bundled CIE illuminant's name (SDS_ILLUMINANTS, its white CCS_ILLUMINANTS[observer])
or a `wavelength_nm,power` CSV file, read here as a SpectralDistribution with colour's
LinearInterpolator (as colour's own illuminant datasets are), its white the xy of a perfect
reflector under it. Integration: colour.sd_to_XYZ(method="Integration") with the CMFs trimmed to
360-780 nm at 1 nm, then colour.XYZ_to_RGB(XYZ, space, illuminant=<camera white>,
chromatic_adaptation_transform="CAT02"), divided channel by channel by the same for a perfect
reflector (spectral_oracle.py's colorimetric method, with the light as the illuminant).
"""

import argparse
import json
import pathlib
import sys
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import colour  # noqa: E402
import OpenEXR  # noqa: E402
from colour import MSDS_CMFS, SDS_ILLUMINANTS, SpectralDistribution, SpectralShape  # noqa: E402
from exr_oracle import read_layer, read_png, write_png_rgb8  # noqa: E402
from spectral_oracle import OBSERVERS, QUANTITIES, SPACES, read_any  # noqa: E402

colour.utilities.filter_warnings(colour_runtime_warnings=True, colour_usage_warnings=True)

NAMES = (
    ["D50", "D55", "D65", "D75", "A", "E"]
    + [f"FL{i}" for i in range(1, 13)]
    + ["LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1", "LED-RGB1", "LED-V1",
       "LED-V2"]
)


class Light:
    """A light's SPD and its white for an observer."""

    def __init__(self, spec, observer):
        self.cmfs = MSDS_CMFS[OBSERVERS[observer]].copy().trim(SpectralShape(360, 780, 1))
        self.observer = observer
        name = spec if spec.upper() in NAMES else None
        if name is None and spec.upper().startswith("F") and spec.upper()[1:].isdigit():
            name = "FL" + spec[1:]
        if name is not None:
            name = name.upper()
            self.sd = SDS_ILLUMINANTS[name]
            self.white = np.asarray(colour.CCS_ILLUMINANTS[OBSERVERS[observer]][name], float)
        else:
            with open(spec, encoding="utf-8") as f:
                rows = [line for line in f if line.strip() and not line.lstrip().startswith("#")]
            # the first row that is not a comment is the header (wavelength_nm,power)
            data = np.loadtxt(rows[1:], delimiter=",", ndmin=2)
            self.sd = SpectralDistribution(data[:, 1], data[:, 0], name=spec,
                                           interpolator=colour.LinearInterpolator)
            ones = SpectralDistribution(np.ones(len(self.cmfs.wavelengths)),
                                        self.cmfs.wavelengths)
            self.white = colour.XYZ_to_xy(self.xyz(ones))

    def xyz(self, sd):
        return colour.sd_to_XYZ(sd, self.cmfs, self.sd, method="Integration")

    def camera_white(self, white_balance):
        if white_balance == "light":
            return self.white
        return np.asarray(colour.CCS_ILLUMINANTS[OBSERVERS[self.observer]][white_balance], float)

    def camera(self, space, white_balance):
        """T: XYZ -> the camera's RGB (identity for xyz)."""
        if SPACES[space] is None:
            return np.identity(3)
        return colour.XYZ_to_RGB(np.identity(3), SPACES[space],
                                 illuminant=self.camera_white(white_balance),
                                 chromatic_adaptation_transform="CAT02").T

    def ratio(self, sd, space, white_balance):
        """The registry's factor: T·XYZ(value × S) / T·XYZ(S), per channel."""
        ones = SpectralDistribution(np.ones(len(sd.wavelengths)), sd.wavelengths)
        xyz, xyz_w = self.xyz(sd), self.xyz(ones)
        if SPACES[space] is None:
            return list(xyz / xyz_w)
        white = self.camera_white(white_balance)
        rgb = colour.XYZ_to_RGB(xyz / 100, SPACES[space], illuminant=white)
        rgb_w = colour.XYZ_to_RGB(xyz_w / 100, SPACES[space], illuminant=white)
        return list(rgb / rgb_w)


def source_spectra(source):
    """{quantity: SpectralDistribution} of a glazing file or `stack:FILE.json`."""
    if source.startswith("stack:"):
        with open(source[len("stack:"):], encoding="utf-8") as f:
            spectra = json.load(f)["spectra"]
        wl = np.asarray(spectra["wavelength_nm"], float)
        keys = {"T": "transmittance", "Rf": "reflectance", "Rb": "reflectance_back"}
        return {q: SpectralDistribution(np.asarray(spectra[k][0], float), wl)
                for k, q in keys.items()}
    data = read_any(source, False)
    return {q: SpectralDistribution(data[q], data["wl"]) for q in QUANTITIES if q in data}


def parse_lights(args):
    lights = []
    for arg in args:
        name, sep, spec = arg.partition("=")
        if not sep:
            sys.exit(f"--light {arg}: expected NAME=ILLUMINANT")
        lights.append((name, spec))
    return lights


def cmd_illuminants(args):
    folder = pathlib.Path(args.dir)
    mismatches, checked = [], 0
    for name in NAMES:
        data = np.loadtxt(folder / f"{name}.csv", delimiter=",", skiprows=1, ndmin=2)
        sd = SDS_ILLUMINANTS[name]
        if not (np.array_equal(data[:, 0], sd.wavelengths) and np.array_equal(data[:, 1], sd.values)):
            mismatches.append(f"{name}.csv")
        checked += 1
    with open(folder / "whites.csv", encoding="utf-8") as f:
        rows = [line.strip().split(",") for line in f.readlines()[1:] if line.strip()]
    seen = set()
    for name, observer, x, y in rows:
        want = colour.CCS_ILLUMINANTS[OBSERVERS[observer]][name]
        if float(x) != float(want[0]) or float(y) != float(want[1]):
            mismatches.append(f"whites.csv {name} {observer}")
        seen.add((name, observer))
        checked += 1
    missing = [f"whites.csv {n} {o}" for n in NAMES for o in OBSERVERS if (n, o) not in seen]
    mismatches += missing
    json.dump({"checked": checked, "mismatches": mismatches}, sys.stdout)
    sys.stdout.write("\n")
    return 1 if mismatches else 0


def cmd_tables(args):
    result = {}
    lights = [(name, Light(spec, args.observer)) for name, spec in parse_lights(args.light)]
    for source in args.sources:
        spectra = source_spectra(source)
        result[source] = {
            name: {space: {q: light.ratio(sd, space, args.white_balance)
                           for q, sd in spectra.items()}
                   for space in args.space}
            for name, light in lights
        }
    json.dump(result, sys.stdout)
    sys.stdout.write("\n")
    return 0


def emitter_rgb(light, space, white_balance, sd=None):
    """T·XYZ(τ·S)/Y(S): the camera's RGB of the emitter seen through `sd` (none: bare)."""
    ones = SpectralDistribution(np.ones(len(light.cmfs.wavelengths)), light.cmfs.wavelengths)
    xyz_w = light.xyz(ones)
    xyz = light.xyz(sd) if sd is not None else xyz_w
    return light.camera(space, white_balance) @ (xyz / xyz_w[1])


def write_exr(path, rgb, width, height):
    channels = {c: np.full((height, width), rgb[i], dtype=np.float32)
                for i, c in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(str(path))


def cmd_emitter_pass(args):
    width, height = (int(v) for v in args.size.split("x"))
    light = Light(args.light, "cie1931")
    rgb = emitter_rgb(light, args.space, args.white_balance) * args.scale
    write_exr(args.out, rgb, width, height)
    json.dump({"rgb": list(rgb)}, sys.stdout)
    sys.stdout.write("\n")
    return 0


def to_lab(rgb, space):
    """CIE Lab of a camera RGB, referenced to the space's white (XYZ = M_space⁻¹·RGB; for xyz,
    the equal-energy white)."""
    if SPACES[space] is None:
        return colour.XYZ_to_Lab(np.asarray(rgb, float), np.array([1 / 3, 1 / 3]))
    cs = colour.RGB_COLOURSPACES[SPACES[space]]
    xyz = np.linalg.solve(cs.matrix_XYZ_to_RGB, np.asarray(rgb, float))
    return colour.XYZ_to_Lab(xyz, cs.whitepoint)


def cmd_delta_e(args):
    light = Light(args.light, "cie1931")
    layer = read_layer(args.composite)
    composite = np.stack([layer.planes[c] for c in "RGB"], axis=-1)
    mask = read_png(args.mask)
    ids = mask[..., 1].astype(int)
    result = {}
    for arg in args.glass:
        gid, _, source = arg.partition("=")
        inside = ids == int(gid)
        if not inside.any():
            sys.exit(f"--glass {arg}: no pixel of id {gid} in {args.mask}")
        got = composite[inside].mean(axis=0)
        sd = source_spectra(source)["transmittance"]
        want = emitter_rgb(light, args.space, args.white_balance, sd)
        de = float(colour.delta_E(to_lab(got, args.space), to_lab(want, args.space),
                                  method="CIE 2000"))
        result[gid] = {"delta_e00": de, "composite": [float(v) for v in got],
                       "expected": [float(v) for v in want], "pixels": int(inside.sum())}
    json.dump(result, sys.stdout)
    sys.stdout.write("\n")
    return 0


def cmd_mask(args):
    ids = [int(v) for v in args.ids.split(",")]
    n = args.block
    rgb = np.zeros((n, n * len(ids), 3), dtype=np.uint8)
    for k, gid in enumerate(ids):
        rgb[:, k * n:(k + 1) * n, 1] = gid
        rgb[:, k * n:(k + 1) * n, 2] = 255
    write_png_rgb8(args.out, rgb)
    json.dump({"width": n * len(ids), "height": n}, sys.stdout)
    sys.stdout.write("\n")
    return 0


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("illuminants")
    s.add_argument("dir")
    s = sub.add_parser("tables")
    s.add_argument("--observer", default="cie1931", choices=list(OBSERVERS))
    s.add_argument("--white-balance", default="light")
    s.add_argument("--space", action="append", required=True, choices=list(SPACES))
    s.add_argument("--light", action="append", required=True)
    s.add_argument("sources", nargs="+")
    for name in ("emitter-pass", "delta-e"):
        s = sub.add_parser(name)
        s.add_argument("--light", required=True)
        s.add_argument("--white-balance", default="light")
        s.add_argument("--space", default="srgb", choices=list(SPACES))
        if name == "emitter-pass":
            s.add_argument("--size", required=True)
            s.add_argument("--scale", type=float, default=1.0)
            s.add_argument("--out", required=True)
        else:
            s.add_argument("--composite", required=True)
            s.add_argument("--mask", required=True)
            s.add_argument("--glass", action="append", required=True)
    s = sub.add_parser("mask")
    s.add_argument("--ids", required=True)
    s.add_argument("--block", type=int, default=4)
    s.add_argument("--out", required=True)
    args = p.parse_args(argv)
    commands = {"illuminants": cmd_illuminants, "tables": cmd_tables,
                "emitter-pass": cmd_emitter_pass, "delta-e": cmd_delta_e, "mask": cmd_mask}
    return commands[args.command](args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
