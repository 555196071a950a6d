"""The integrations' examples run (scripts/test-all): the notebook-style tour and the Nuke
node's compositing function outside Nuke, against the `compose` command's output."""

import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "integrations" / "nuke"))
sys.path.insert(0, str(ROOT / "python_oracle"))

import glassdb_nuke  # noqa: E402


def test_notebook_example_runs(tmp_path):
    done = subprocess.run(
        [sys.executable, str(ROOT / "integrations/python/notebook_example.py"), str(tmp_path)],
        capture_output=True, text=True,
    )
    assert done.returncode == 0, done.stderr
    assert "Tv at 0°" in done.stdout
    first = np.load(tmp_path / "atrium.npy")
    second = np.load(tmp_path / "atrium_glass2.npy")
    assert first.shape == (240, 320, 3) and not np.array_equal(first, second)
    assert any((tmp_path / n).is_file() for n in ("unit_curves.png", "unit_curves.csv"))


def test_nuke_node_function_is_compose(tmp_path):
    import os

    a = ROOT / "fixtures/atrium"
    refl = [a / f"refl_{k}.exr" for k in range(3)]
    got = glassdb_nuke.composite_files(a / "trans.exr", refl, a / "mask.png", planes=a / "virtual/planes.json")
    out = tmp_path / "cli.exr"
    bin_dir = Path(os.environ.get("GLASSDB_BIN_DIR", ROOT / "target/debug"))
    subprocess.run(
        [str(bin_dir / "compose"), *[x for p in refl for x in ("--refl", str(p))], "--trans", str(a / "trans.exr"),
         "--mask", str(a / "mask.png"), "--planes", str(a / "virtual/planes.json"),
         "--data-type", "float", "--keep-channels", "none", "-o", str(out)],
        check=True, capture_output=True,
    )
    import OpenEXR

    with OpenEXR.File(str(out), separate_channels=True) as f:
        ch = f.channels()
        want = np.stack([ch[c].pixels for c in "RGB"], axis=-1).astype(np.float32)
    assert np.array_equal(got.view(np.uint32), want.view(np.uint32))
