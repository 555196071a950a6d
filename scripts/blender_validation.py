"""The numbers of docs/blender.md ("Validation against Cycles"), from two runs of
`glassdb blender render … --reference` with seeds 0 and 1 (scripts/blender_validation.sh).

    .venv/bin/python scripts/blender_validation.py DIR [FIGURE.png]

DIR holds seed0/ and seed1/ (each with composite.####.exr, reference.####.exr,
mask.####.exr, glassdb-blender.json and the command's output in run.txt) and swap.txt (the
re-composite's `/usr/bin/time -v`). Prints Markdown tables and writes DIR/metrics.json.

PSNR has peak 1.0 on linear radiance (R, G, B), as docs/validation.md. Regions: glass = the
mask has an id at the pixel centre; edges = glass pixels whose 3 × 3 neighbourhood holds
another (id, plane); interior = the other glass pixels.

Error by source (mean squared error, in glass): the composite against the reference of the
other seed has MSE = σc² + σr² + bias², σc² and σr² the two images' own noise (half the MSE
between their two seeds); what remains is the method's systematic error, split into edges
and interior and, in the interior, per plane.

Needs numpy and OpenEXR (the project's .venv). Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import math
import os
import re
import sys

from pathlib import Path

import numpy as np
import OpenEXR

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python_oracle"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from exr_oracle import write_png_rgb8  # noqa: E402
from blender_example_figure import srgb8  # noqa: E402


def read(path, names):
    """The named channels as float64 arrays. OpenEXR 3.5 groups R, G, B(, A) into one array,
    keyed "RGBA" when bare and by the layer's name ("ViewLayer.Combined") when layered. A pass
    of a light-split run also holds a layer per light group (`ViewLayer.Combined_sun`, …);
    the beauty (the layer without a group suffix) is read, a group layer only where a channel
    has no other source."""
    with OpenEXR.File(path) as f:
        planes, group_planes = {}, {}
        for key, c in f.channels().items():
            px = np.asarray(c.pixels, dtype=np.float64)
            last = key.split(".")[-1]
            into = group_planes if last.startswith("Combined_") else planes
            if px.ndim == 3:
                letters = last
                if len(letters) != px.shape[-1] or not set(letters) <= set("RGBA"):
                    letters = "RGBA"[: px.shape[-1]]
                for i, letter in enumerate(letters):
                    into[letter] = px[..., i]
            else:
                into[last] = px
        return [planes[n] if n in planes else group_planes[n] for n in names]


def rgb(path):
    return np.stack(read(path, ["R", "G", "B"]), axis=-1)


def mse(a, b, sel):
    d = (a - b)[sel]
    return float(np.mean(d * d)) if d.size else float("nan")


def psnr(m):
    return 10.0 * math.log10(1.0 / m) if m > 0 else float("inf")


def edges(idm, plane):
    h, w = idm.shape
    key = idm * 65536 + plane
    pad = np.pad(key, 1, mode="edge")
    same = np.ones_like(key, dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            same &= pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] == key
    return ~same


def numbers_of(run_txt):
    text = open(run_txt).read()
    cpu = re.search(r"Blender CPU: passes ([0-9.]+) s, reference ([0-9.]+) s", text)
    wall = re.search(r"Blender export ([0-9.]+) s, passes ([0-9.]+) s, reference ([0-9.]+) s; "
                     r"planes and masks ([0-9.]+) s", text)
    comp = re.search(r"composited \d+ frame\(s\) in .* in ([0-9.]+) s", text)
    return {"passes_cpu_s": float(cpu.group(1)), "reference_cpu_s": float(cpu.group(2)),
            "export_wall_s": float(wall.group(1)), "passes_wall_s": float(wall.group(2)),
            "reference_wall_s": float(wall.group(3)), "masks_wall_s": float(wall.group(4)),
            "composite_wall_s": float(comp.group(1))}


def time_v(path):
    text = open(path).read()
    get = lambda label: float(re.search(re.escape(label) + r": ([0-9.:]+)", text).group(1))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([0-9:.]+)", text).group(1)
    parts = [float(p) for p in wall.split(":")]
    wall_s = sum(p * 60 ** (len(parts) - 1 - i) for i, p in enumerate(parts))
    return {"cpu_s": get("User time (seconds)") + get("System time (seconds)"), "wall_s": wall_s,
            "max_rss_kb": get("Maximum resident set size (kbytes)")}


def figure(runs, frame, out):
    """Frame `frame`: reference | composite | 4 × |error| (each the mean of its two seeds), sRGB
    clipped."""
    name = lambda run, stem: os.path.join(runs[run], "%s.%04d.exr" % (stem, frame))
    ref = (rgb(name(0, "reference")) + rgb(name(1, "reference"))) / 2
    comp = (rgb(name(0, "composite")) + rgb(name(1, "composite"))) / 2
    panels = [srgb8(ref), srgb8(comp), srgb8(4 * np.abs(comp - ref))]
    image = np.concatenate(panels, axis=1)
    write_png_rgb8(out, image)


def main():
    root = sys.argv[1]
    runs = [os.path.join(root, "seed%d" % s) for s in (0, 1)]
    record = json.load(open(os.path.join(runs[0], "glassdb-blender.json")))
    samples = record["samples"]
    rows, per_plane_rows = [], []
    totals = {}
    for f in record["frames"]:
        fr = f["frame"]
        name = lambda run, stem: os.path.join(runs[run], "%s.%04d.exr" % (stem, fr))
        idm, plane = read(name(0, "mask"), ["id", "plane"])
        comp = [rgb(name(k, "composite")) for k in (0, 1)]
        ref = [rgb(name(k, "reference")) for k in (0, 1)]
        glass = idm > 0
        edge = glass & edges(idm, plane)
        inner = glass & ~edge
        every = np.ones_like(glass)
        # Interior glass pixels at high-contrast detail (the 3 × 3 range of the two-seed mean
        # reference above 0.1 in some channel: edges of what is reflected or seen through).
        mean_ref = (ref[0] + ref[1]) / 2
        pad = np.pad(mean_ref, ((1, 1), (1, 1), (0, 0)), mode="edge")
        stack = np.stack([pad[1 + dy:1 + dy + mean_ref.shape[0], 1 + dx:1 + dx + mean_ref.shape[1]]
                          for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
        detail = (stack.max(axis=0) - stack.min(axis=0)).max(axis=-1) > 0.1
        inner_detail = inner & detail
        inner_smooth = inner & ~detail
        r = {"frame": fr, "pixels": int(glass.size), "glass_pixels": int(glass.sum()),
             "edge_pixels": int(edge.sum())}
        for region, sel in (("overall", every), ("glass", glass), ("edges", edge),
                            ("interior", inner), ("interior, detail", inner_detail),
                            ("interior, smooth", inner_smooth), ("outside", ~glass)):
            m = mse(comp[0], ref[1], sel)
            sc = mse(comp[0], comp[1], sel) / 2
            sr = mse(ref[0], ref[1], sel) / 2
            avg = mse((comp[0] + comp[1]) / 2, (ref[0] + ref[1]) / 2, sel)
            r[region] = {"psnr_db": psnr(m), "mse": m, "noise_composite": sc, "noise_reference": sr,
                         "bias2": m - sc - sr, "psnr_two_seed_mean_db": psnr(avg),
                         "reference_seeds_psnr_db": psnr(2 * sr)}
            t = totals.setdefault(region, [0.0, 0.0, 0.0, 0.0, 0])
            n = int(sel.sum())
            t[0] += m * n
            t[1] += sc * n
            t[2] += sr * n
            t[3] += avg * n
            t[4] += n
        for k in range(len(f["refl"])):
            sel = inner & (plane == k)
            if sel.sum() == 0:
                continue
            m = mse(comp[0], ref[1], sel)
            per_plane_rows.append((fr, k, int(sel.sum()), psnr(m), m - mse(comp[0], comp[1], sel) / 2
                                   - mse(ref[0], ref[1], sel) / 2))
        rows.append(r)
    summary = {region: {"psnr_db": psnr(t[0] / t[4]), "noise_composite": t[1] / t[4],
                        "noise_reference": t[2] / t[4], "bias2": (t[0] - t[1] - t[2]) / t[4],
                        "psnr_two_seed_mean_db": psnr(t[3] / t[4]), "pixels": t[4]}
               for region, t in totals.items()}
    cost = [numbers_of(os.path.join(run, "run.txt")) for run in runs]
    swap = time_v(os.path.join(root, "swap.txt"))
    g = summary["glass"]
    # Equal noise in the glass: the reference needs (σr/σc)² times the samples (1/√N noise).
    ratio = g["noise_reference"] / g["noise_composite"]
    passes_cpu = np.mean([c["passes_cpu_s"] for c in cost])
    reference_cpu = np.mean([c["reference_cpu_s"] for c in cost])
    metrics = {"samples": samples, "frames": rows, "summary": summary,
               "per_plane_interior": [dict(zip(("frame", "plane", "pixels", "psnr_db", "bias2"), p))
                                      for p in per_plane_rows],
               "cost": {"runs": cost, "swap": swap,
                        "glass_noise_variance_ratio_reference_over_composite": ratio,
                        "passes_cpu_s": passes_cpu, "reference_cpu_s": reference_cpu,
                        "reference_cpu_s_at_equal_glass_noise": reference_cpu * ratio}}
    if len(sys.argv) > 2:
        figure(runs, record["frames"][0]["frame"], sys.argv[2])
    with open(os.path.join(root, "metrics.json"), "w") as fh:
        json.dump(metrics, fh, indent=1)
    print("| frame | overall PSNR | glass PSNR | glass pixels (edges) | reference seeds, glass |")
    print("|---|---|---|---|---|")
    for r in rows:
        print("| %d | %.2f dB | %.2f dB | %d (%d) | %.2f dB |" % (
            r["frame"], r["overall"]["psnr_db"], r["glass"]["psnr_db"], r["glass_pixels"], r["edge_pixels"],
            r["glass"]["reference_seeds_psnr_db"]))
    print()
    print("| region | PSNR | two-seed means | MSE | σc² composite noise | σr² reference noise | bias² (systematic) |")
    print("|---|---|---|---|---|---|---|")
    for region in ("overall", "glass", "edges", "interior", "interior, detail",
                   "interior, smooth", "outside"):
        s = summary[region]
        print("| %s (%d) | %.2f dB | %.2f dB | %.3g | %.3g | %.3g | %.3g |" % (
            region, s["pixels"], s["psnr_db"], s["psnr_two_seed_mean_db"],
            s["noise_composite"] + s["noise_reference"] + s["bias2"], s["noise_composite"],
            s["noise_reference"], s["bias2"]))
    print()
    print("| frame | plane | interior pixels | PSNR | bias² |")
    print("|---|---|---|---|---|")
    for p in per_plane_rows:
        print("| %d | %d | %d | %.2f dB | %.3g |" % p)
    print()
    print("samples %s; Blender CPU s per run (3 frames): passes %.1f, reference %.1f; glass noise "
          "variance reference/composite %.2f -> reference at equal glass noise %.1f s; swap "
          "(glassdb blender compose, 3 frames) %.2f s CPU, %.2f s wall, %.0f MB peak" % (
              samples, passes_cpu, reference_cpu, ratio, reference_cpu * ratio, swap["cpu_s"],
              swap["wall_s"], swap["max_rss_kb"] / 1024))


if __name__ == "__main__":
    main()
