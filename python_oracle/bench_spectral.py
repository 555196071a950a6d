"""Side-by-side speed of glassdb-spectral and colour-science 0.4.7 on 1000 real-shaped spectra.

Usage (from the repository root): .venv/bin/python python_oracle/bench_spectral.py [--no-cargo]

The spectra: the irregular 300-2500 nm grid of fixtures/glazing/CLEAR5.LOF (369 samples) with
its transmittance times a smooth factor, spectrum k:  T(l) * (0.6 + 0.4 sin(0.37 k + l / (150 +
k mod 50))), the same formula as crates/spectral/benches/integrate.rs.

Measured in one run, all single-threaded CPU time:
1. colour.sd_to_XYZ(sd, cmfs, D65, method="Integration") called per spectrum (the ordinary path,
   SpectralDistribution built per spectrum; colour's cache of the reshaped CMFs stays on);
2. colour's batched path: one MultiSpectralDistributions of all 1000 spectra through
   sd_to_XYZ (best of 3, the data nudged each time so that colour's cache cannot answer);
3. `cargo bench -p glassdb-spectral --bench integrate` (criterion, --warm-up-time 1
   --measurement-time 3), read back from target/criterion: Integrator::channels on the same
   1000 spectra, colorimetric method (CIE 1931, D65, sRGB), i.e. more work than XYZ alone;
   once with all spectra on the file's wavelengths (the spline kernel is reused) and once with
   every spectrum on its own, shifted wavelength array (no reuse: the worst case).
"""

import json
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402

import colour  # noqa: E402
from colour import MSDS_CMFS, SDS_ILLUMINANTS, MultiSpectralDistributions, SpectralDistribution, SpectralShape  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from spectral_oracle import read_optics  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
N = 1000


def spectra():
    d = read_optics(str(ROOT / "fixtures/glazing/CLEAR5.LOF"))
    wl, t = d["wl"], d["transmittance"]
    k = np.arange(N)[:, None]
    values = t[None, :] * (0.6 + 0.4 * np.sin(0.37 * k + wl[None, :] / (150.0 + (k % 50))))
    return wl, values


def main(argv):
    wl, values = spectra()
    cmfs = MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().trim(SpectralShape(360, 780, 1))
    ill = SDS_ILLUMINANTS["D65"]

    # Warm colour's caches of the reshaped CMFs/illuminant (the ordinary steady state).
    colour.sd_to_XYZ(SpectralDistribution(values[0] * 0.5, wl), cmfs, ill, method="Integration")
    t0 = time.process_time()
    xyz_per = [colour.sd_to_XYZ(SpectralDistribution(v, wl), cmfs, ill, method="Integration") for v in values]
    per_spectrum_s = (time.process_time() - t0) / N

    batched = []
    for rep in range(3):
        data = values * (1.0 + 1e-9 * (rep + 1))
        t0 = time.process_time()
        msds = MultiSpectralDistributions(data.T, wl)
        xyz_batch = colour.sd_to_XYZ(msds, cmfs, ill, method="Integration")
        batched.append((time.process_time() - t0) / N)
    batched_s = min(batched)
    # Sanity: both colour paths agree (so that they time the same computation).
    assert np.allclose(np.array(xyz_per), xyz_batch, rtol=1e-6), "colour paths disagree"

    rust_s = None
    if "--no-cargo" not in argv:
        subprocess.run(
            [
                "cargo", "bench", "-p", "glassdb-spectral", "--bench", "integrate", "--",
                "--warm-up-time", "1", "--measurement-time", "3", "spectral_1000/colorimetric",
            ],
            cwd=ROOT,
            check=True,
            stdout=sys.stderr,
        )
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    est = target / "criterion/spectral_1000/colorimetric/new/estimates.json"
    if est.exists():
        rust_s = json.loads(est.read_text())["mean"]["point_estimate"] * 1e-9 / N
    est = target / "criterion/spectral_1000/colorimetric_distinct_grids/new/estimates.json"
    rust_fresh_s = None
    if est.exists():
        rust_fresh_s = json.loads(est.read_text())["mean"]["point_estimate"] * 1e-9 / N

    print(f"1000 spectra, {len(wl)} samples each ({wl[0]:g}-{wl[-1]:g} nm, irregular)")
    print(f"colour.sd_to_XYZ per spectrum      : {per_spectrum_s * 1e6:10.1f} us / spectrum")
    print(f"colour MultiSpectralDistributions  : {batched_s * 1e6:10.1f} us / spectrum")
    if rust_s is not None:
        print(f"glassdb Integrator::channels       : {rust_s * 1e6:10.2f} us / spectrum")
        print(f"speed-up vs per-spectrum colour    : {per_spectrum_s / rust_s:10.0f} x")
        print(f"speed-up vs batched colour         : {batched_s / rust_s:10.1f} x")
    if rust_fresh_s is not None:
        print(f"glassdb, every spectrum on its own wavelength array (no kernel reuse):")
        print(f"glassdb Integrator::channels       : {rust_fresh_s * 1e6:10.2f} us / spectrum")
        print(f"speed-up vs per-spectrum colour    : {per_spectrum_s / rust_fresh_s:10.0f} x")
        print(f"speed-up vs batched colour         : {batched_s / rust_fresh_s:10.1f} x")
    print(
        json.dumps(
            {
                "colour_per_spectrum_us": per_spectrum_s * 1e6,
                "colour_batched_us": batched_s * 1e6,
                "glassdb_us": None if rust_s is None else rust_s * 1e6,
                "glassdb_distinct_grids_us": None if rust_fresh_s is None else rust_fresh_s * 1e6,
            }
        )
    )


if __name__ == "__main__":
    main(sys.argv[1:])
