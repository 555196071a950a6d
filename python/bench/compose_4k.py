"""Times `glassdb.compose` on a 4K frame held in numpy arrays: the frame of
crates/compose/benches/in_memory.rs (the same library calls from Rust), so that the two times
compare the Python binding with the library call (docs/performance.md).

    python python/bench/compose_4k.py [RUNS] [--no-hugepages]

Prints the median and the smallest of RUNS timed calls (after one warm-up call), in ms.
numpy asks for transparent huge pages for its large arrays (madvise); Rust's `Vec`s of the
criterion benchmark get plain 4 KiB pages. `--no-hugepages` turns numpy's request off, so that
both read their inputs from the same kind of memory.
"""

import statistics
import sys
import time

import numpy as np

import glassdb

W, H = 3840, 2160


def frame():
    i = np.arange(W * H, dtype=np.int64)
    x, y = i % W, i // W
    mask = np.empty((H, W, 3), dtype=np.uint8)
    mask[..., 0] = (x * 3 // W).reshape(H, W)
    mask[..., 1] = np.where(y % 2 == 0, x // 1280 + 1, 0).reshape(H, W)
    mask[..., 2] = (x * 255 // W).reshape(H, W)
    ramp = ((i % 977).astype(np.float32) * np.float32(1e-3)).reshape(H, W, 1)
    chan = (np.float32(0.01) * np.arange(3, dtype=np.float32)).reshape(1, 1, 3)

    def pass_(base):
        return np.ascontiguousarray(np.float32(base) + ramp + chan, dtype=np.float32)

    return pass_(0.1), [pass_(0.05 * (k + 1)) for k in range(3)], mask


def main(runs, hugepages=True):
    if not hugepages:
        from numpy._core import multiarray

        multiarray._set_madvise_hugepage(False)
    trans, refl, mask = frame()
    registry = glassdb.Registry.load()
    glassdb.compose(trans, refl, mask, registry=registry)
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        glassdb.compose(trans, refl, mask, registry=registry)
        times.append((time.perf_counter() - t0) * 1e3)
    print(f"glassdb.compose 4K: median {statistics.median(times):.1f} ms, min {min(times):.1f} ms over {runs} runs")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    main(int(args[0]) if args else 20, hugepages="--no-hugepages" not in sys.argv)
