"""Applies a .cube LUT with OpenColorIO, as a FileTransform at its default interpolation
(INTERP_DEFAULT: linear 1D, trilinear 3D), to RGB triples; the oracle of `compose --view`.

    python cube_oracle.py LUT.cube INPUT

INPUT is a text file of "r g b" lines (floats) or an EXR (its R, G, B channels, row-major).
Prints one "r g b" line per triple, each value with repr precision (float32 as OCIO's CPU
processor computes it).
"""

import sys

import numpy as np
import PyOpenColorIO as ocio


def read_input(path):
    if path.lower().endswith(".exr"):
        import OpenEXR

        with OpenEXR.File(path) as f:
            ch = f.channels()
            planes = [np.asarray(ch[n].pixels, dtype=np.float32).ravel() for n in "RGB"]
        return np.stack(planes, axis=1)
    rows = []
    with open(path) as f:
        for line in f:
            if line.strip():
                rows.append([float(v) for v in line.split()])
    return np.asarray(rows, dtype=np.float32).reshape(-1, 3)


def main():
    lut, src = sys.argv[1], sys.argv[2]
    rgb = np.ascontiguousarray(read_input(src), dtype=np.float32)
    config = ocio.Config.CreateRaw()
    transform = ocio.FileTransform(src=lut)
    assert transform.getInterpolation() == ocio.INTERP_DEFAULT
    proc = config.getProcessor(transform).getDefaultCPUProcessor()
    out = rgb.copy()
    proc.applyRGB(out)
    for r, g, b in out.reshape(-1, 3):
        print(f"{float(r)!r} {float(g)!r} {float(b)!r}")


if __name__ == "__main__":
    main()
