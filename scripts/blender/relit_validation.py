"""Issue 28's validation of the relit swap against Cycles (docs/blender.md, "Light parts").

    .venv/bin/python scripts/blender/relit_validation.py DIR [FIGURE.png]

DIR holds the `relit` scene's runs (scripts/blender/relit_validation.sh makes them), each
`glassdb blender render relit.blend --glass Glass_clear=1 --glass 'Tinted*=5' --samples 64`:

- C0, D0: glass clear.json / dark.json (fixtures/blender/relit), seed 0, light split on;
- C0off, D0off: the same with `--light-split off` (the old passes, lit through their glass);
- CR1, DR1: `--reference` with seed 1 (Cycles rendering the glass itself, the thin-pane
  shader seen by the camera, with light groups by source): the references, whose noise is
  independent of the seed-0 passes;

and the registries clear.json, dark.json and the glassdb binary used. The script composites
each run with the other registry (`glassdb blender compose`; the swaps), and prints PSNR over
the whole frame (peak 1, R, G, B) of every composite against the reference of the glass it
shows, then the error of the swaps by source and by region. The figure: per frame, reference
dark | swap clear→dark relit | swap clear→dark, old passes | pipeline rendered dark.
"""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenEXR

sys.path.insert(0, str(Path(__file__).resolve().parent.parent.parent / "python_oracle"))
from exr_oracle import write_png_rgb8  # noqa: E402

FRAMES = (1, 2)


def rgb(path, layer="ViewLayer.Combined"):
    """H×W×3 float64 of `layer` (or the bare R, G, B) of an EXR."""
    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        names = [f"{layer}.{c}" if f"{layer}.{c}" in ch else c for c in "RGB"]
        return np.stack([np.asarray(ch[n].pixels, dtype=np.float64) for n in names], axis=-1)


def coverage(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        return np.asarray(ch["coverage"].pixels, dtype=np.float64)


def mse(a, b, sel=None):
    d = (a - b) ** 2
    return float(d[sel].mean()) if sel is not None else float(d.mean())


def psnr(m):
    return 10.0 * np.log10(1.0 / m) if m > 0 else float("inf")


def compose(glassdb, run, registry, out):
    """A copy of `run` composited with `registry` (`glassdb blender compose`)."""
    if out.exists():
        shutil.rmtree(out)
    shutil.copytree(run, out)
    subprocess.run([glassdb, "blender", "compose", str(out), "--registry", str(registry)],
                   check=True, capture_output=True)
    return out


def only_source(run, source, out):
    """A copy of the split run `run` whose part layers of every other source are zero."""
    if out.exists():
        shutil.rmtree(out)
    shutil.copytree(run, out)
    for frame in FRAMES:
        parts = json.loads((out / ("light_parts.%04d.json" % frame)).read_text())["parts"]
        drop = {p["group"] for p in parts if p["source"]["kind"] != source}
        for name in ["trans.%04d.exr" % frame] + ["refl_%d.%04d.exr" % (k, frame) for k in (0, 1)]:
            path = out / name
            with OpenEXR.File(str(path), separate_channels=True) as f:
                ch = f.channels()
                for n in ch:
                    layer = n.rsplit(".", 1)[0]
                    if layer.startswith("ViewLayer.Combined_") and \
                            layer[len("ViewLayer.Combined_"):] in drop:
                        ch[n].pixels = np.zeros_like(ch[n].pixels)
                f.write(str(path))
    return out


def srgb8(linear):
    v = np.clip(linear, 0.0, 1.0)
    enc = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return np.round(enc * 255).astype(np.uint8)


def main():
    d = Path(sys.argv[1])
    figure = Path(sys.argv[2]) if len(sys.argv) > 2 else None
    glassdb = str((d / "glassdb").resolve())
    clear, dark = d / "clear.json", d / "dark.json"
    work = d / "composed"
    work.mkdir(exist_ok=True)
    runs = {
        "swap clear->dark, relit": compose(glassdb, d / "C0", dark, work / "C0_dark"),
        "swap dark->clear, relit": compose(glassdb, d / "D0", clear, work / "D0_clear"),
        "swap clear->dark, old passes": compose(glassdb, d / "C0off", dark, work / "C0off_dark"),
        "swap dark->clear, old passes": compose(glassdb, d / "D0off", clear, work / "D0off_clear"),
        "pipeline rendered dark": d / "D0",
        "pipeline rendered clear": d / "C0",
        "pipeline rendered dark, old passes": d / "D0off",
        "pipeline rendered clear, old passes": d / "C0off",
    }
    print("Whole-frame PSNR (dB, peak 1) against Cycles with the composited glass (seed 1):")
    print("%-40s %s" % ("", "  ".join("frame %d" % f for f in FRAMES)))
    for name, run in runs.items():
        target = "clear" if ("->clear" in name or name.startswith("pipeline rendered clear")) \
            else "dark"
        ref = d / ("CR1" if target == "clear" else "DR1")
        vals = [psnr(mse(rgb(run / ("composite.%04d.exr" % f)), rgb(ref / ("reference.%04d.exr" % f))))
                for f in FRAMES]
        print("%-40s %s" % (name, "  ".join("%7.1f" % v for v in vals)))
    noise = [psnr(mse(rgb(d / "DR1" / ("reference.%04d.exr" % f)),
                      rgb(d / "D0" / ("reference.%04d.exr" % f)))) for f in FRAMES]
    print("%-40s %s" % ("noise: reference dark seed 0 vs seed 1", "  ".join("%7.1f" % v for v in noise)))

    print()
    print("Error of the swap clear->dark by source and region (MSE ×1e6; PSNR dB):")
    per_source = {s: compose(glassdb, only_source(d / "C0", s, work / ("C0_" + s)), dark,
                             work / ("C0_%s_dark" % s)) for s in ("sun", "sky")}
    pipe_source = {s: compose(glassdb, only_source(d / "D0", s, work / ("D0_" + s)), dark,
                              work / ("D0_%s_dark" % s)) for s in ("sun", "sky")}
    for f in FRAMES:
        ref = d / "DR1" / ("reference.%04d.exr" % f)
        cov = coverage(d / "C0" / ("mask.%04d.exr" % f))
        regions = {"away from glass": cov == 0, "glass (reflections)": cov == 1,
                   "pane edges": (cov > 0) & (cov < 1)}
        swap = rgb(runs["swap clear->dark, relit"] / ("composite.%04d.exr" % f))
        pipe = rgb(d / "D0" / ("composite.%04d.exr" % f))
        old = rgb(runs["swap clear->dark, old passes"] / ("composite.%04d.exr" % f))
        refimg = rgb(ref)
        print("frame %d (%s):" % (f, "interior" if f == 1 else "exterior"))
        for s in ("sun", "sky"):
            rs = rgb(ref, "ViewLayer.Combined_" + s)
            cs = rgb(per_source[s] / ("composite.%04d.exr" % f))
            ps = rgb(pipe_source[s] / ("composite.%04d.exr" % f))
            print("  %-22s swap %8.1f (%5.1f dB)  pipeline %8.1f (%5.1f dB)  mean ref %.4f swap %.4f"
                  % ("source " + s, 1e6 * mse(cs, rs), psnr(mse(cs, rs)), 1e6 * mse(ps, rs),
                     psnr(mse(ps, rs)), rs.mean(), cs.mean()))
        for r, sel in regions.items():
            n = int(sel.sum())
            if n == 0:
                continue
            share = mse(swap, refimg, sel) * n / (mse(swap, refimg) * sel.size)
            print("  %-22s swap %8.1f (%5.1f dB, %3.0f %% of its error)  pipeline %8.1f (%5.1f dB)"
                  "  old swap %8.1f (%5.1f dB)  [%d px]"
                  % (r, 1e6 * mse(swap, refimg, sel), psnr(mse(swap, refimg, sel)), 100 * share,
                     1e6 * mse(pipe, refimg, sel), psnr(mse(pipe, refimg, sel)),
                     1e6 * mse(old, refimg, sel), psnr(mse(old, refimg, sel)), n))

    if figure:
        rows = []
        for f in FRAMES:
            panels = [rgb(d / "DR1" / ("reference.%04d.exr" % f)),
                      rgb(runs["swap clear->dark, relit"] / ("composite.%04d.exr" % f)),
                      rgb(runs["swap clear->dark, old passes"] / ("composite.%04d.exr" % f)),
                      rgb(d / "D0" / ("composite.%04d.exr" % f))]
            gap = np.full((panels[0].shape[0], 3, 3), 1.0)
            row = panels[0]
            for p in panels[1:]:
                row = np.concatenate([row, gap, p], axis=1)
            rows.append(row)
            rows.append(np.full((3, row.shape[1], 3), 1.0))
        image = np.concatenate(rows[:-1], axis=0)
        write_png_rgb8(figure, srgb8(image))
        print("wrote", figure)


if __name__ == "__main__":
    main()
