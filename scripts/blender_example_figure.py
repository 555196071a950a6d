"""The README's Blender example figure: Cycles' transmission pass (glass invisible), glassdb's
composite of the Cycles passes through the Cryptomatte mask, and Cycles' own render of the same
frame (its glass a Principled BSDF, not the catalogue glass), side by side, 3x nearest upscale,
sRGB with clipping (the `standard` view).

Usage: .venv/bin/python scripts/blender_example_figure.py COMPOSITE.exr OUT.png
(COMPOSITE.exr: the README's compose command with -o COMPOSITE.exr.)
"""

import sys
from pathlib import Path

import numpy as np
import OpenEXR

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python_oracle"))
from exr_oracle import write_png_rgb8  # noqa: E402

FIXTURES = Path(__file__).resolve().parent.parent / "fixtures/blender/masks/b34"


def rgb(path, prefix):
    """The RGB of the layer `prefix` (or the bare R, G, B) of an EXR, as float64 H×W×3."""
    with OpenEXR.File(str(path), separate_channels=True) as f:
        channels = f.channels()
        names = [f"{prefix}.{c}" if prefix else c for c in "RGB"]
        return np.stack([np.asarray(channels[n].pixels, dtype=np.float64) for n in names], axis=-1)


def srgb8(linear):
    v = np.clip(linear, 0.0, 1.0)
    enc = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return np.round(enc * 255).astype(np.uint8)


def main():
    composite, out = Path(sys.argv[1]), Path(sys.argv[2])
    panels = [
        rgb(FIXTURES / "trans.0001.exr", "ViewLayer.Combined"),
        rgb(composite, "ViewLayer.Combined"),
        rgb(FIXTURES / "beauty.0001.exr", "ViewLayer.Combined"),
    ]
    gap = np.full((panels[0].shape[0], 4, 3), 1.0)
    row = np.concatenate([panels[0], gap, panels[1], gap, panels[2]], axis=1)
    big = np.repeat(np.repeat(srgb8(row), 3, axis=0), 3, axis=1)
    write_png_rgb8(out, big)


if __name__ == "__main__":
    main()
