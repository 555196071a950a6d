#!/usr/bin/env python3
"""Renders the passes and the path-traced reference of `fixtures/atrium` with Mitsuba 3.

Run ONCE to make the committed fixtures; never in tests or CI (the tests read the EXRs).
Needs its own venv, outside the test path (versions as docs/validation.md records):

    python3 -m venv .venv-render
    .venv-render/bin/pip install mitsuba==3.9.1 numpy==2.4.6
    .venv-render/bin/python python_oracle/render_example.py all --glassdb target/release/glassdb

Steps (each a sub-command; `all` runs them in order):
- `catalog`: the angle tables of the two comparison glasses from the same formula as Mitsuba's
  `thindielectric` (src/bsdfs/thindielectric.cpp): the unpolarised single-surface Fresnel
  reflectance F = (Rs + Rp)/2 at n = 1.5, the multiple reflections summed on F (not per
  polarisation), r = 2F/(1+F), t = (1 - r)·τ with τ the `specular_transmittance` tint, which
  scales transmission only. Writes `catalog.toml` and `angles_*.csv` (the `glassdb fit` format).
- `passes`: `glassdb mirror` writes the virtual scene of each glass plane; Mitsuba renders the
  transmission pass (all glass removed) and one reflection pass per plane (the virtual scene with
  the glass removed, the sky and the sun mirrored by the plane's reflection matrix).
- `mask`: `glassdb mask` writes the mask; it is compared with Mitsuba's own camera rays (glass
  id, plane and cos θ at every pixel centre).
- `reference`: the full scene, glass as `thindielectric` (n = 1.5, no absorption, tint through
  `specular_transmittance`), integrator `volpath` (light passes the glass to shadow rays), two
  independent seeds so that the reference's own noise can be measured.
- `split`: the reference split at the first glass hit along each camera ray: the radiance that
  reaches the glass from behind (T_real) and from the mirror direction (R_real), both in the full
  scene with glass. They attribute the composite's error to its sources (docs/validation.md).
- `noise`: second seeds of the passes (for the composite's own noise).

Everything is written as half-float EXR into `fixtures/atrium/`, with the timings in
`fixtures/atrium/render_log.json`.
"""

import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
FIX = os.path.join(ROOT, "fixtures", "atrium")
PLANES_JSON = os.path.join(FIX, "virtual", "planes.json")  # written by `glassdb mirror`

ETA = 1.5  # thin-dielectric index, exterior 1.0 (Mitsuba's default exterior is air 1.000277)
GLASSES = {
    # material: (id, name, specular_transmittance tint per channel). The ids match the bundled
    # catalog's nearest products (1: clear float 3 mm, 5: green-tinted float), so that the README's
    # demo composes the same mask with data/catalog.toml and shows real products.
    "GlassClear": (1, "thin dielectric n=1.5, clear (Mitsuba thindielectric)", (1.0, 1.0, 1.0)),
    "GlassTinted": (5, "thin dielectric n=1.5, green-grey tint (Mitsuba thindielectric)", (0.55, 0.68, 0.62)),
}
MAX_DEPTH = 24

# ----------------------------------------------------------------------------- physics


def fresnel_unpolarised(cos_i, eta=ETA):
    """Mitsuba's `fresnel(cos_theta_i, eta)` reflectance: (Rs + Rp)/2 of one air→glass surface."""
    cos_i = np.clip(np.asarray(cos_i, dtype=np.float64), 0.0, 1.0)
    sin2_t = (1.0 - cos_i**2) / eta**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs**2 + rp**2)


def thin_r(cos_i):
    """thindielectric reflectance: r = F + T²F(1 + F² + …) summed on the unpolarised F: 2F/(1+F)."""
    f = fresnel_unpolarised(cos_i)
    return 2.0 * f / (1.0 + f)


def thin_t(cos_i, tint=1.0):
    """thindielectric transmittance: (1 - r)·τ (`specular_transmittance` scales it, not r)."""
    return (1.0 - thin_r(cos_i)) * tint


def slab_r_t_polarised(cos_i, eta=ETA):
    """The physically usual non-absorbing slab (what WINDOW does for uncoated glass): multiple
    reflections summed per polarisation, then averaged. Used to show the Fresnel-model error."""
    cos_i = np.clip(np.asarray(cos_i, dtype=np.float64), 0.0, 1.0)
    sin2_t = (1.0 - cos_i**2) / eta**2
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    rs = ((cos_i - eta * cos_t) / (cos_i + eta * cos_t)) ** 2
    rp = ((eta * cos_i - cos_t) / (eta * cos_i + cos_t)) ** 2
    r = 0.5 * (2 * rs / (1 + rs) + 2 * rp / (1 + rp))
    return r, 1.0 - r


def check_bsdf():
    """Checks the formula above against Mitsuba's own thindielectric at 0-89.5°: the null
    transmission it gives shadow rays and the reflection probability its `sample` uses."""
    import drjit as dr
    import mitsuba as mi

    ang = np.arange(0.0, 90.0, 0.5)
    c = np.cos(np.radians(ang))
    worst = 0.0
    for mat, (gid, _, tint) in GLASSES.items():
        d = {"type": "thindielectric", "int_ior": ETA, "ext_ior": 1.0}
        if tint != (1.0, 1.0, 1.0):
            d["specular_transmittance"] = {"type": "rgb", "value": list(tint)}
        bsdf = mi.load_dict(d)
        si = dr.zeros(mi.SurfaceInteraction3f, len(ang))
        si.wi = mi.Vector3f(np.sqrt(1 - c**2).astype(np.float32), np.zeros(len(ang), np.float32), c.astype(np.float32))
        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
        t = np.array(bsdf.eval_null_transmission(si))
        t = t if t.shape[0] == 3 else t.T
        bs, _ = bsdf.sample(mi.BSDFContext(), si, mi.Float(np.zeros(len(ang), np.float32)), mi.Point2f(0.5, 0.5))
        r = np.array(bs.pdf)
        et = np.abs(t - thin_t(c)[None, :] * np.asarray(tint)[:, None]).max()
        er = np.abs(r - thin_r(c)).max()
        worst = max(worst, et, er)
        print(f"{mat}: max |t - formula| = {et:.2e}, max |r - formula| = {er:.2e} (0-89.5°)")
    log_entry("bsdf_check_max_abs", float(worst))
    if worst > 1e-5:
        raise SystemExit("the formula does not match Mitsuba's thindielectric")


def write_catalog():
    angles = np.arange(0.0, 90.0 + 1e-9, 2.5)
    cos_a = np.cos(np.radians(angles))
    cos_a[-1] = 0.0
    entries = []
    for mat, (gid, name, tint) in GLASSES.items():
        fname = f"angles_{mat[5:].lower()}.csv"
        r = thin_r(cos_a)
        # The T column is the shape of t(θ); the tint is a constant factor per channel
        # (t = τ_c·(1 − r)), so the table holds the green channel's curve and t0 gives all three.
        t = thin_t(cos_a, tint[1])
        rows = ["angle_deg,R,T"] + [f"{a:.1f},{rv:.8f},{tv:.8f}" for a, rv, tv in zip(angles, r, t)]
        with open(os.path.join(FIX, fname), "w", encoding="utf-8") as f:
            f.write("\n".join(rows) + "\n")
        r0 = float(thin_r(1.0))
        t0 = [float(thin_t(1.0, c)) for c in tint]
        entries.append(
            f"[[glass]]\nid = {gid}\nname = \"{name}\"\n"
            f"r0 = [{r0:.8f}, {r0:.8f}, {r0:.8f}]\n"
            f"t0 = [{t0[0]:.8f}, {t0[1]:.8f}, {t0[2]:.8f}]\n"
            f"angles = \"{fname}\"\n"
        )
    head = (
        "# The glasses of the atrium's validation (docs/validation.md): exactly what the reference\n"
        "# renderer models (Mitsuba 3 `thindielectric`, n = 1.5, no absorption, tint through\n"
        "# `specular_transmittance`). Angle tables from the same formula; written by\n"
        "# python_oracle/render_example.py catalog.\n\n"
    )
    with open(os.path.join(FIX, "catalog.toml"), "w", encoding="utf-8") as f:
        f.write(head + "\n".join(entries))
    print("wrote catalog.toml and angle tables")


# ----------------------------------------------------------------------------- scene


def split_lines(path):
    """The whitespace-separated words of each non-blank line of a text file (OBJ, MTL)."""
    with open(path, encoding="utf-8") as f:
        for line in f:
            words = line.split()
            if words:
                yield words


def parse_obj(path):
    """Minimal OBJ reader: `v`, `f` (v, v/vt, v/vt/vn, v//vn; negative indices), `usemtl`.
    Returns {material: (vertices (N,3) float64, triangles (M,3) int)} (fan triangulation)."""
    verts = []
    faces = {}
    mat = "default"
    for parts in split_lines(path):
        if parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts[0] == "usemtl":
            mat = parts[1]
        elif parts[0] == "f":
            idx = []
            for p in parts[1:]:
                i = int(p.split("/")[0])
                idx.append(i - 1 if i > 0 else len(verts) + i)
            for k in range(1, len(idx) - 1):
                faces.setdefault(mat, []).append((idx[0], idx[k], idx[k + 1]))
    verts = np.array(verts, dtype=np.float64)
    out = {}
    for m, tris in faces.items():
        tris = np.array(tris, dtype=np.int64)
        used, inv = np.unique(tris.ravel(), return_inverse=True)
        out[m] = (verts[used], inv.reshape(-1, 3))
    return out


def read_mtl(path):
    kd = {}
    cur = None
    for p in split_lines(path):
        if p[0] == "newmtl":
            cur = p[1]
        elif p[0] == "Kd" and cur:
            kd[cur] = tuple(float(x) for x in p[1:4])
    return kd


def write_ply(path, verts, tris):
    with open(path, "wb") as f:
        f.write(
            (
                "ply\nformat binary_little_endian 1.0\n"
                f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
                f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n"
            ).encode("ascii")
        )
        f.write(np.asarray(verts, dtype="<f4").tobytes())
        rec = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"] = 3
        rec["i"] = tris
        f.write(rec.tobytes())


def load_lights():
    with open(os.path.join(FIX, "lights.json"), encoding="utf-8") as f:
        return json.load(f)


def look_at_dict(cam):
    import mitsuba as mi

    return mi.ScalarTransform4f().look_at(origin=cam["origin"], target=cam["target"], up=cam["up"])


def scene_dict(geometry, kd, tmpdir, *, with_glass, reflect=None, tag="s"):
    """A Mitsuba scene dict. `geometry`: {material: (verts, tris)}. Glass materials become
    `thindielectric` (or are dropped when `with_glass` is false). `reflect`: a 4×4 reflection
    matrix applied to the sky and the sun (the virtual scene of one plane)."""
    import mitsuba as mi

    with open(os.path.join(FIX, "camera.json"), encoding="utf-8") as f:
        cam = json.load(f)
    lights = load_lights()
    d = {
        "type": "scene",
        "sensor": {
            "type": "perspective",
            "fov": cam["fov_x_deg"],
            "fov_axis": "x",
            "to_world": look_at_dict(cam),
            "film": {
                "type": "hdrfilm",
                "width": cam["width"],
                "height": cam["height"],
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
        },
    }
    m3 = np.eye(3) if reflect is None else np.asarray(reflect, dtype=np.float64)[:3, :3]
    to_sun = m3 @ np.asarray(lights["sun"]["direction_to_sun"], dtype=np.float64)
    d["sun"] = {
        "type": "directional",
        "direction": (-to_sun).tolist(),
        "irradiance": {"type": "rgb", "value": lights["sun"]["irradiance_rgb"]},
    }
    env_to_world = np.eye(4)
    env_to_world[:3, :3] = m3
    d["sky"] = {
        "type": "envmap",
        "filename": os.path.join(FIX, lights["sky"]["file"]),
        "scale": lights["sky"]["scale"],
        "to_world": mi.ScalarTransform4f(env_to_world.tolist()),
    }
    for k, (mat, (v, t)) in enumerate(sorted(geometry.items())):
        if len(t) == 0:
            continue
        is_glass = mat in GLASSES
        if is_glass and not with_glass:
            continue
        ply = os.path.join(tmpdir, f"{tag}_{k}.ply")
        write_ply(ply, v, t)
        if is_glass:
            tint = GLASSES[mat][2]
            bsdf = {"type": "thindielectric", "int_ior": ETA, "ext_ior": 1.0}
            if tint != (1.0, 1.0, 1.0):
                bsdf["specular_transmittance"] = {"type": "rgb", "value": list(tint)}
        else:
            bsdf = {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(kd[mat])}}}
        d[f"shape_{k}_{mat}"] = {"type": "ply", "filename": ply, "face_normals": True, "bsdf": bsdf}
    return d


def render(scene, spp, seed, integrator=None):
    import drjit as dr
    import mitsuba as mi

    if integrator is None:
        integrator = mi.load_dict({"type": "volpath", "max_depth": MAX_DEPTH, "rr_depth": 8})
    t0 = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=seed, integrator=integrator)
    arr = np.array(img, dtype=np.float32)
    dr.sync_thread()
    return arr[:, :, :3], time.perf_counter() - t0


def write_exr(path, arr):
    import mitsuba as mi

    bmp = mi.Bitmap(np.ascontiguousarray(arr[:, :, :3], dtype=np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB)
    bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float16, srgb_gamma=False)
    tmp = path + ".tmp.exr"
    bmp.write(tmp)
    os.replace(tmp, path)


def read_exr(path):
    import mitsuba as mi

    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False))


def log_entry(key, value):
    path = os.path.join(FIX, "render_log.json")
    log = {}
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            log = json.load(f)
    log[key] = value
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        json.dump(log, f, indent=2, sort_keys=True)
        f.write("\n")
    os.replace(path + ".tmp", path)


# ----------------------------------------------------------------------------- mirror (checks)


def reflect_points(p, n, d):
    """Eqs. 4-7: X' = X - 2·n·(n·X + d), n unit."""
    return p - 2.0 * np.outer(p @ n + d, n)


def run(cmd, cwd=None):
    print("+", " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
    if r.returncode != 0:
        raise SystemExit(f"command failed ({r.returncode}): {' '.join(cmd)}\n{r.stdout}\n{r.stderr}")
    return r.stdout


def own_glass_planes(geo, eye, tol_n=1e-5, tol_d=1e-4):
    """Distinct planes of the glass faces, each normal turned towards the eye (fallback and
    cross-check of `glassdb mirror`)."""
    planes = []
    for mat in GLASSES:
        if mat not in geo:
            continue
        v, t = geo[mat]
        for tri in t:
            a, b, c = v[tri[0]], v[tri[1]], v[tri[2]]
            n = np.cross(b - a, c - a)
            n /= np.linalg.norm(n)
            d = -float(n @ a)
            if n @ eye + d < 0:
                n, d = -n, -d
            for q in planes:
                if np.abs(q["n"] - n).max() < tol_n and abs(q["d"] - d) < tol_d:
                    q["materials"].add(mat)
                    break
            else:
                planes.append({"n": n, "d": d, "materials": {mat}})
    out = []
    for k, q in enumerate(planes):
        n, d = q["n"], q["d"]
        m = np.eye(4)
        m[:3, :3] -= 2.0 * np.outer(n, n)
        m[:3, 3] = -2.0 * d * n
        out.append({"index": k, "equation": [*n.tolist(), d], "materials": sorted(q["materials"]),
                    "reflection_matrix": m.tolist()})
    return out


def own_mirror(geo, n, d):
    """Eqs. 4-7 with the front half-space kept (n·X + d ≥ 0, n towards the eye), triangles that
    cross the plane clipped, glass dropped, winding reversed."""
    out = {}
    for mat, (v, t) in geo.items():
        if mat in GLASSES:
            continue
        verts, tris = [], []
        for tri in t:
            poly = [v[i] for i in tri]
            dist = [float(p @ n + d) for p in poly]
            clipped = []
            for i in range(3):
                p0, p1, s0, s1 = poly[i], poly[(i + 1) % 3], dist[i], dist[(i + 1) % 3]
                if s0 >= 0:
                    clipped.append(p0)
                if (s0 >= 0) != (s1 >= 0):
                    clipped.append(p0 + (p1 - p0) * (s0 / (s0 - s1)))
            if len(clipped) < 3:
                continue
            base = len(verts)
            verts.extend(reflect_points(np.array(clipped), n, d))
            for k in range(1, len(clipped) - 1):
                tris.append((base, base + k + 1, base + k))
        if tris:
            out[mat] = (np.array(verts), np.array(tris, dtype=np.int64))
    return out


def virtual_scenes(glassdb, tmpdir, own=False):
    """Runs `glassdb mirror` (or, with `own`, the fallback above) and returns
    [(plane record, geometry)] in plane-index order, and the plane records."""
    if own:
        with open(os.path.join(FIX, "camera.json"), encoding="utf-8") as f:
            eye = np.asarray(json.load(f)["origin"], dtype=np.float64)
        geo = parse_obj(os.path.join(FIX, "atrium.obj"))
        planes = own_glass_planes(geo, eye)
        res = []
        for p in planes:
            n, d = np.asarray(p["equation"][:3]), p["equation"][3]
            res.append((p, own_mirror(geo, n, d)))
        return res, planes
    with open(os.path.join(FIX, "camera.json"), encoding="utf-8") as f:
        cam = json.load(f)
    out = os.path.join(FIX, "virtual")
    eye = ",".join(str(x) for x in cam["origin"])
    # Paths relative to the repository root: they are recorded in the committed planes.json.
    run([glassdb, "mirror", os.path.relpath(os.path.join(FIX, "atrium.obj"), ROOT), "--glass-material", "Glass*",
         "--out-dir", os.path.relpath(out, ROOT), "--eye", eye], cwd=ROOT)
    with open(os.path.join(out, "planes.json"), encoding="utf-8") as f:
        planes = json.load(f)
    if isinstance(planes, dict):
        planes = planes.get("planes", planes)
    result = []
    for p in sorted(planes, key=lambda q: q["index"]):
        geo = parse_obj(os.path.join(out, p["file"]))
        result.append((p, geo))
    return result, planes


def plane_matrix(p):
    for key in ("reflection_matrix", "matrix", "reflection"):
        if key in p:
            m = np.asarray(p[key], dtype=np.float64)
            return m.reshape(4, 4)
    raise SystemExit(f"planes.json entry without a reflection matrix: {sorted(p)}")


def plane_equation(p):
    for key in ("equation", "plane"):
        if key in p:
            e = p[key]
            if isinstance(e, dict):
                return np.array([e["a"], e["b"], e["c"]], dtype=np.float64), float(e["d"])
            return np.array(e[:3], dtype=np.float64), float(e[3])
    raise SystemExit(f"planes.json entry without an equation: {sorted(p)}")


# ----------------------------------------------------------------------------- sub-commands


def cmd_passes(args, tmpdir, seed_offset=0, suffix=""):
    """The transmission pass and one reflection pass per plane; with a suffix (second seeds, for
    the noise measurement) they go to `analysis/`."""
    import mitsuba as mi

    geo = parse_obj(os.path.join(FIX, "atrium.obj"))
    kd = read_mtl(os.path.join(FIX, "atrium.mtl"))
    scene = mi.load_dict(scene_dict(geo, kd, tmpdir, with_glass=False, tag="trans"))
    img, dt = render(scene, args.spp_pass, 1000 + seed_offset)
    outdir = os.path.join(FIX, "analysis") if suffix else FIX
    write_exr(os.path.join(outdir, f"trans{suffix}.exr"), img)
    log_entry(f"trans{suffix}", {"spp": args.spp_pass, "seconds": dt, "seed": 1000 + seed_offset})
    print(f"trans{suffix}: {dt:.1f} s", flush=True)
    virt, planes = virtual_scenes(args.glassdb, tmpdir, own=args.own_mirror)
    for p, vgeo in virt:
        k = p["index"]
        m = plane_matrix(p)
        scene = mi.load_dict(scene_dict(vgeo, kd, tmpdir, with_glass=False, reflect=m, tag=f"refl{k}"))
        img, dt = render(scene, args.spp_pass, 2000 + 10 * k + seed_offset)
        write_exr(os.path.join(outdir, f"refl_{k}{suffix}.exr"), img)
        log_entry(f"refl_{k}{suffix}", {"spp": args.spp_pass, "seconds": dt, "seed": 2000 + 10 * k + seed_offset})
        print(f"refl_{k}{suffix}: {dt:.1f} s", flush=True)
    if args.own_mirror and not suffix:
        os.makedirs(os.path.dirname(PLANES_JSON), exist_ok=True)
        with open(PLANES_JSON, "w", encoding="utf-8") as f:
            json.dump({"format": "render_example.py own mirror", "planes": planes}, f, indent=2)
            f.write("\n")


def cmd_reference(args, tmpdir):
    import mitsuba as mi

    geo = parse_obj(os.path.join(FIX, "atrium.obj"))
    kd = read_mtl(os.path.join(FIX, "atrium.mtl"))
    scene = mi.load_dict(scene_dict(geo, kd, tmpdir, with_glass=True, tag="ref"))
    for name, seed, outdir in (("reference", 1, FIX), ("reference_b", 2, os.path.join(FIX, "analysis"))):
        img, dt = render(scene, args.spp_ref, seed)
        write_exr(os.path.join(outdir, f"{name}.exr"), img)
        log_entry(name, {"spp": args.spp_ref, "seconds": dt, "seed": seed, "integrator": f"volpath max_depth={MAX_DEPTH} rr_depth=8"})
        print(f"{name}: {dt:.1f} s", flush=True)


def make_split_integrator(mode):
    """A wrapper of `volpath` that continues each camera ray at its first glass hit either
    straight through (mode 'trans') or in the mirror direction (mode 'refl'); the scene keeps its
    glass everywhere else."""
    import drjit as dr
    import mitsuba as mi

    inner = mi.load_dict({"type": "volpath", "max_depth": MAX_DEPTH, "rr_depth": 8})

    class Split(mi.SamplingIntegrator):
        def __init__(self, props):
            super().__init__(props)

        def sample(self, scene, sampler, ray, medium=None, active=True):
            si = scene.ray_intersect(mi.Ray3f(ray), active)
            flags = si.bsdf().flags()
            glass = si.is_valid() & mi.has_flag(flags, mi.BSDFFlags.Null) & active
            n = si.n
            d = mi.Vector3f(ray.d)
            if mode == "refl":
                d2 = d - 2.0 * dr.dot(d, n) * n
            else:
                d2 = d
            new = mi.RayDifferential3f(si.spawn_ray(d2))
            r2 = mi.RayDifferential3f(ray)
            r2.o = dr.select(glass, new.o, ray.o)
            r2.d = dr.select(glass, new.d, ray.d)
            r2.has_differentials = False
            L, valid, aov = inner.sample(scene, sampler, r2, medium, active)
            return L, valid, []

        def aov_names(self):
            return []

    return Split(mi.Properties())


def cmd_split(args, tmpdir):
    import mitsuba as mi

    geo = parse_obj(os.path.join(FIX, "atrium.obj"))
    kd = read_mtl(os.path.join(FIX, "atrium.mtl"))
    scene = mi.load_dict(scene_dict(geo, kd, tmpdir, with_glass=True, tag="split"))
    for mode in ("trans", "refl"):
        img, dt = render(scene, args.spp_pass, 3000 + (mode == "refl"), integrator=make_split_integrator(mode))
        write_exr(os.path.join(FIX, "analysis", f"{mode}_real.exr"), img)
        log_entry(f"{mode}_real", {"spp": args.spp_pass, "seconds": dt})
        print(f"{mode}_real: {dt:.1f} s", flush=True)


def mitsuba_camera_mask(scene_geo, kd, tmpdir, planes):
    """Glass id, plane index and cos θ at every pixel centre from Mitsuba's own camera rays."""
    import drjit as dr
    import mitsuba as mi

    with open(os.path.join(FIX, "camera.json"), encoding="utf-8") as f:
        cam = json.load(f)
    w, h = cam["width"], cam["height"]
    # One shape per glass material, so that the hit shape tells the id.
    d = scene_dict(scene_geo, kd, tmpdir, with_glass=True, tag="mask")
    scene = mi.load_dict(d)
    sensor = scene.sensors()[0]
    jj, ii = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    pos = mi.Point2f(((ii + 0.5) / w).ravel().astype(np.float32), ((jj + 0.5) / h).ravel().astype(np.float32))
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(ray)
    valid = np.array(si.is_valid())
    n = np.array(si.n)
    p = np.array(si.p)
    rd = np.array(ray.d)
    if n.shape[0] == 3:
        n, p, rd = n.T, p.T, rd.T
    cos = np.abs(np.sum(n * rd, axis=1))
    flags = np.array(si.bsdf().flags())
    glass = valid & ((flags & int(mi.BSDFFlags.Null)) != 0)
    # Which glass material: the shape ids carry the material name.
    shapes = scene.shapes()
    ids = np.zeros(w * h, dtype=np.int32)
    plane_idx = np.full(w * h, -1, dtype=np.int32)
    shape_ptr = np.array(dr.reinterpret_array(mi.UInt32, si.shape) if hasattr(dr, "reinterpret_array") else si.shape)
    ptr_to_mat = {}
    for s in shapes:
        ptr_to_mat[int(np.array(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(s)))[0])] = s.id()
    for k in np.nonzero(glass)[0]:
        sid = ptr_to_mat.get(int(shape_ptr[k]), "")
        for mat, (gid, _, _) in GLASSES.items():
            if sid.endswith(mat):
                ids[k] = gid
    for q in planes:
        nq, dq = plane_equation(q)
        on = glass & (np.abs(p @ nq + dq) < 1e-3)
        plane_idx[on] = q["index"]
    # Rays that meet a second glass surface after the first (glass seen through glass).
    ray2 = si.spawn_ray(ray.d)
    si2 = scene.ray_intersect(ray2)
    second = glass & np.array(si2.is_valid()) & ((np.array(si2.bsdf().flags()) & int(mi.BSDFFlags.Null)) != 0)
    mitsuba_camera_mask.second_glass = second.reshape(h, w)
    return ids.reshape(h, w), plane_idx.reshape(h, w), np.where(glass, cos, 0.0).reshape(h, w)


def read_mask_png(path):
    """8-bit RGB PNG mask (R = plane, G = id, B = round(cos·255)) via Mitsuba's PNG reader."""
    import mitsuba as mi

    b = np.array(mi.Bitmap(path), dtype=np.float64)
    if b.dtype != np.uint8 and b.max() <= 1.0 + 1e-6:
        b = np.round(b * 255.0)
    return b[:, :, 0].astype(int), b[:, :, 1].astype(int), b[:, :, 2].astype(int)


def cmd_mask(args, tmpdir):
    import mitsuba as mi

    geo = parse_obj(os.path.join(FIX, "atrium.obj"))
    kd = read_mtl(os.path.join(FIX, "atrium.mtl"))
    with open(PLANES_JSON, encoding="utf-8") as f:
        planes = json.load(f)
    planes = planes["planes"] if isinstance(planes, dict) else planes
    obj = os.path.join(FIX, "atrium.obj")
    camj = os.path.join(FIX, "camera.json")
    glass_args = []
    for mat, (gid, _, _) in GLASSES.items():
        glass_args += ["--glass", f"{mat}={gid}"]
    planes_arg = [] if args.own_mirror else ["--planes", PLANES_JSON]
    run([args.glassdb, "mask", obj, "--camera", camj] + planes_arg + glass_args + ["-o", os.path.join(FIX, "mask.png")])
    run([args.glassdb, "mask", obj, "--camera", camj] + planes_arg + glass_args + ["--samples", "4", "-o", os.path.join(FIX, "mask.exr")])
    ids, pl, cos = mitsuba_camera_mask(geo, kd, tmpdir, planes)
    r, g, b = read_mask_png(os.path.join(FIX, "mask.png"))
    n = ids.size
    id_agree = np.mean(ids == g)
    both = (ids > 0) & (g > 0)
    plane_agree = np.mean(pl[both] == r[both])
    cos_err = np.abs(np.round(cos * 255.0) - b)[both]
    report = {
        "pixels": int(n),
        "glass_pixels_mitsuba": int((ids > 0).sum()),
        "glass_pixels_glassdb": int((g > 0).sum()),
        "id_agreement": float(id_agree),
        "id_disagreeing_pixels": int((ids != g).sum()),
        "plane_agreement_on_common_glass": float(plane_agree),
        "cos_max_abs_diff_lsb": int(cos_err.max()) if cos_err.size else 0,
        "cos_pixels_off_by_one_lsb": int((cos_err == 1).sum()),
    }
    log_entry("mask_check", report)
    print(json.dumps(report, indent=2))
    np.save(os.path.join(tmpdir, "mitsuba_mask.npy"), np.stack([ids, pl, cos]))
    return report


def cmd_timing(args, tmpdir):
    """CPU seconds per sample per pixel of each render (the machine is shared, so process CPU
    time, not wall time): (t(144 spp) - t(16 spp)) / 128, which leaves out scene loading and
    kernel compilation; best of two rounds."""
    import drjit as dr
    import mitsuba as mi

    geo = parse_obj(os.path.join(FIX, "atrium.obj"))
    kd = read_mtl(os.path.join(FIX, "atrium.mtl"))
    scenes = {
        "reference": mi.load_dict(scene_dict(geo, kd, tmpdir, with_glass=True, tag="tref")),
        "trans": mi.load_dict(scene_dict(geo, kd, tmpdir, with_glass=False, tag="ttrans")),
    }
    virt, _ = virtual_scenes(args.glassdb, tmpdir)
    for p, vgeo in virt:
        k = p["index"]
        scenes[f"refl_{k}"] = mi.load_dict(scene_dict(vgeo, kd, tmpdir, with_glass=False, reflect=plane_matrix(p), tag=f"trefl{k}"))
    integrator = mi.load_dict({"type": "volpath", "max_depth": MAX_DEPTH, "rr_depth": 8})
    best = {}
    for _round in range(2):
        for name, sc in scenes.items():
            cpu = []
            for spp in (16, 144):
                t0 = time.process_time()
                img = mi.render(sc, spp=spp, seed=7, integrator=integrator)
                np.array(img)
                dr.sync_thread()
                cpu.append(time.process_time() - t0)
            per = (cpu[1] - cpu[0]) / 128.0
            best[name] = min(best.get(name, float("inf")), per)
            print(f"{name}: {per * 1000:.2f} ms CPU per spp ({cpu})", flush=True)
    log_entry("cpu_seconds_per_spp", best)


# ----------------------------------------------------------------------------- analysis


def stats(e):
    """PSNR (peak 1), mean |e|, max |e|, RMS and mean signed error per channel of an error array."""
    e = np.asarray(e, dtype=np.float64)
    if e.size == 0:
        return None
    mse = float(np.mean(e**2))
    return {
        "psnr_db": float(10 * np.log10(1.0 / mse)) if mse > 0 else float("inf"),
        "mean_abs": float(np.mean(np.abs(e))),
        "max_abs": float(np.max(np.abs(e))),
        "rms": float(np.sqrt(mse)),
        "mean_signed_rgb": [float(x) for x in np.mean(e.reshape(-1, 3), axis=0)],
        "pixels": int(e.reshape(-1, 3).shape[0]),
    }


def mask_regions(plane, gid):
    """Glass = id at the pixel centre; pane edge = (plane, id) changes in the 3×3 neighbourhood
    (the same definition as tests/cli/validation.rs)."""
    key = plane.astype(np.int64) * 65536 + gid
    h, w = key.shape
    edge = np.zeros((h, w), dtype=bool)
    pad = np.pad(key, 1, mode="edge")
    padv = np.pad(np.ones((h, w), bool), 1, constant_values=False)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            nb = pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
            valid = padv[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
            edge |= valid & (nb != key)
    return gid > 0, edge


def exact_composite(trans, refls, plane, gid, cos, model="thin"):
    """Eqs. 8-10 with the exact r, t of each glass at the given cos θ (no polynomial fit)."""
    out = trans.copy()
    by_id = {g: tint for (g, _, tint) in GLASSES.values()}
    for k, refl in enumerate(refls):
        for g, tint in by_id.items():
            m = (plane == k) & (gid == g)
            if not m.any():
                continue
            c = cos[m]
            if model == "thin":
                r = thin_r(c)
                t = 1.0 - r
            else:
                r, t = slab_r_t_polarised(c)
            out[m] = trans[m] * (t[:, None] * np.asarray(tint)[None, :]) + refl[m] * r[:, None]
    return out


def timed(cmd, repeat=5):
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        run(cmd)
        best = min(best, time.perf_counter() - t0)
    return best


def to_png(path, arr):
    import mitsuba as mi

    bmp = mi.Bitmap(np.ascontiguousarray(np.clip(arr, 0.0, None).astype(np.float32)), pixel_format=mi.Bitmap.PixelFormat.RGB)
    bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True)
    tmp = path + ".tmp.png"
    bmp.write(tmp)
    os.replace(tmp, path)


def cmd_analyze(args, tmpdir):
    """Composes the atrium with the built binaries and measures the composite against the
    reference, overall, in the glass and at pane edges, and the error by source."""
    an = os.path.join(FIX, "analysis")
    with open(PLANES_JSON, encoding="utf-8") as f:
        planes = json.load(f)
    planes = planes["planes"] if isinstance(planes, dict) else planes
    nplanes = len(planes)
    ref = read_exr(os.path.join(FIX, "reference.exr"))
    ref_b = read_exr(os.path.join(an, "reference_b.exr"))
    trans = read_exr(os.path.join(FIX, "trans.exr"))
    refls = [read_exr(os.path.join(FIX, f"refl_{k}.exr")) for k in range(nplanes)]
    trans_b = read_exr(os.path.join(an, "trans_b.exr"))
    refls_b = [read_exr(os.path.join(an, f"refl_{k}_b.exr")) for k in range(nplanes)]
    t_real = read_exr(os.path.join(an, "trans_real.exr"))
    r_real = read_exr(os.path.join(an, "refl_real.exr"))
    mplane, mid, mcos8 = read_mask_png(os.path.join(FIX, "mask.png"))
    glass, edge = mask_regions(mplane, mid)
    cos8 = mcos8 / 255.0

    # The compositor, as the test runs it.
    registry = os.path.join(tmpdir, "registry.json")
    build = [args.glassdb, "registry", "build", os.path.join(FIX, "catalog.toml"), "-o", registry, "--mask", os.path.join(FIX, "mask.png")]
    t_registry = timed(build, 3)
    comp = os.path.join(tmpdir, "composite.exr")
    cmd = [args.compose]
    for k in range(nplanes):
        cmd += ["--refl", os.path.join(FIX, f"refl_{k}.exr")]
    cmd += ["--trans", os.path.join(FIX, "trans.exr"), "--mask", os.path.join(FIX, "mask.png"), "--registry", registry,
            "--planes", PLANES_JSON, "--data-type", "float", "-o", comp]
    t_compose = timed(cmd, 5)
    composite = read_exr(comp)
    # The same with the EXR mask of 4×4 sub-pixel rays (coverage at pane edges).
    comp_cov = os.path.join(tmpdir, "composite_cov.exr")
    cmd_cov = [c if c != os.path.join(FIX, "mask.png") else os.path.join(FIX, "mask.exr") for c in cmd]
    cmd_cov[-1] = comp_cov
    run(cmd_cov)
    composite_cov = read_exr(comp_cov)
    mask_cmd = [args.glassdb, "mask", os.path.join(FIX, "atrium.obj"), "--camera", os.path.join(FIX, "camera.json"),
                "--planes", PLANES_JSON]
    for mat, (g, _, _) in GLASSES.items():
        mask_cmd += ["--glass", f"{mat}={g}"]
    mask_cmd += ["-o", os.path.join(tmpdir, "mask.png")]
    t_mask = timed(mask_cmd, 3)

    # Exact-formula oracle on the same passes and mask (committed; the Rust test compares).
    oracle = exact_composite(trans, refls, mplane, mid, cos8)
    write_exr(os.path.join(an, "oracle_composite.exr"), oracle)
    oracle_h = read_exr(os.path.join(an, "oracle_composite.exr"))

    # Mitsuba's own camera rays: float cos θ, id and plane at the pixel centres.
    geo = parse_obj(os.path.join(FIX, "atrium.obj"))
    kd = read_mtl(os.path.join(FIX, "atrium.mtl"))
    mi_id, mi_plane, mi_cos = mitsuba_camera_mask(geo, kd, tmpdir, planes)
    agree = (mi_id == mid) & ((mi_id == 0) | (mi_plane == mplane))
    exact_float = exact_composite(trans, refls, mplane, mid, np.where(agree & glass, mi_cos, cos8))
    slab = exact_composite(trans, refls, mplane, mid, cos8, model="slab")
    comp_b = exact_composite(trans_b, refls_b, mplane, mid, cos8)

    # t, r per pixel (exact, 8-bit cos) for the split of the error by source.
    r_px = np.zeros(mid.shape)
    t_px = np.zeros(mid.shape + (3,))
    refl_px = np.zeros_like(trans)
    for k in range(nplanes):
        refl_px[mplane == k] = refls[k][mplane == k]
    for (g, _, tint) in GLASSES.values():
        m = mid == g
        r_px[m] = thin_r(cos8[m])
        t_px[m] = (1.0 - thin_r(cos8[m]))[:, None] * np.asarray(tint)[None, :]

    G, E, A = glass, edge, np.ones_like(glass)
    res = {
        "exposure": "1.0 (linear radiance as rendered; PSNR peak 1.0)",
        "size": [int(ref.shape[1]), int(ref.shape[0])],
        "regions_pixels": {"overall": int(A.sum()), "glass": int(G.sum()), "pane_edges": int(E.sum()),
                           "glass_interior": int((G & ~E).sum())},
        "composite_vs_reference": {name: stats((composite - ref)[sel]) for name, sel in
                                   (("overall", A), ("glass", G), ("pane_edges", E), ("glass_interior", G & ~E),
                                    ("non_glass", ~G))},
        "composite_with_coverage_mask_vs_reference": {name: stats((composite_cov - ref)[sel]) for name, sel in
                                                       (("overall", A), ("glass", G), ("pane_edges", E))},
        "oracle_vs_reference": {name: stats((oracle - ref)[sel]) for name, sel in (("overall", A), ("glass", G), ("pane_edges", E))},
        "composite_vs_oracle": stats(composite - oracle_h),
        "reference_noise": {
            "ref_a_vs_ref_b": stats(ref - ref_b),
            "sigma_per_channel": float(np.sqrt(np.mean((ref - ref_b) ** 2) / 2)),
            "psnr_bound_db": float(10 * np.log10(2.0 / np.mean((ref - ref_b) ** 2))),
            "sigma_glass": float(np.sqrt(np.mean((ref - ref_b)[G] ** 2) / 2)),
        },
        "composite_noise": {
            "sigma_per_channel": float(np.sqrt(np.mean((oracle - comp_b) ** 2) / 2)),
            "sigma_glass": float(np.sqrt(np.mean((oracle - comp_b)[G] ** 2) / 2)),
        },
        "by_source": {
            "fresnel_fit_polynomial_vs_exact (glass)": stats((composite - oracle_h)[G]),
            "fresnel_model_per_polarisation_slab_vs_thindielectric (glass)": stats((slab - oracle)[G]),
            "cos_8bit_vs_float (glass, masks agree)": stats((oracle - exact_float)[G & agree]),
            "transmitted_light_glass_removed_vs_real (glass)": stats(t_px[G] * (trans - t_real)[G]),
            "glass_removed_lighting_outside_glass (non-glass, trans pass vs reference)": stats((trans - ref)[~G]),
            "reflection_first_bounce_vs_real (glass)": stats(r_px[G][:, None] * (refl_px - r_real)[G]),
            "split_reference_vs_reference (glass: r·R_real + t·T_real, noise only)": stats(
                (r_px[..., None] * r_real + t_px * t_real - ref)[G & ~E]),
        },
        "mask_glassdb_vs_mitsuba": {
            "pixels_same_id_and_plane": int(agree.sum()),
            "pixels_differing": int((~agree).sum()),
            "differing_on_pane_edges": int((~agree & E).sum()),
            "cos_byte_max_abs_diff": int(np.max(np.abs(np.round(mi_cos * 255) - mcos8)[agree & G])),
        },
        "timings_s": {"compose_best_of_5": t_compose, "registry_build_best_of_3": t_registry,
                      "glassdb_mask_best_of_3": t_mask},
    }
    with open(os.path.join(FIX, "render_log.json"), encoding="utf-8") as f:
        log = json.load(f)
    res["render_log"] = log
    res["composite_vs_reference_per_plane"] = {
        f"plane {k} ({', '.join(planes[k].get('materials', []))})": stats((composite - ref)[G & (mplane == k)])
        for k in range(nplanes)}
    res["transmitted_light_per_plane (glass, t·(T_pass - T_real))"] = {
        f"plane {k}": stats((t_px * (trans - t_real))[G & (mplane == k)]) for k in range(nplanes)}
    res["transmission_pass_over_T_real_mean_brightness_per_plane"] = {
        f"plane {k}": [float(x) for x in trans[G & (mplane == k)].mean(axis=0) / t_real[G & (mplane == k)].mean(axis=0)]
        for k in range(nplanes)}
    # What rendering the transmission pass with the glass present for light (but not for the
    # camera) would recover: the composite with T_real in place of the pass.
    with_t_real = exact_composite(t_real, refls, mplane, mid, cos8)
    two = mitsuba_camera_mask.second_glass & G
    res["glass_behind_glass"] = {
        "pixels": int(two.sum()),
        "composite_vs_reference (glass seen through glass)": stats((composite - ref)[two]),
        "composite_vs_reference (one layer of glass)": stats((composite - ref)[G & ~two]),
        "transmitted_light (glass seen through glass)": stats((t_px * (trans - t_real))[two]),
        "transmitted_light (one layer of glass)": stats((t_px * (trans - t_real))[G & ~two]),
    }
    res["composite_with_T_real_vs_reference"] = {name: stats((with_t_real - ref)[sel]) for name, sel in
                                                 (("glass", G), ("overall", A))}

    # Cost at equal noise. Per pass i: the composite's noise variance it contributes at 1 spp,
    # v_i = mean over pixels of (weight·(P_a - P_b))²/2 · spp_i (weight 1 or t for the
    # transmission pass, r on plane k for reflection pass k), and its CPU cost c_i per spp.
    # Best allocation of spp for a target variance V: cost = (Σ sqrt(v_i·c_i))² / V; the
    # reference: v_ref·c_ref / V.
    cpu = log.get("cpu_seconds_per_spp")
    if cpu:
        spp_pass = log["trans"]["spp"]
        spp_ref = log["reference"]["spp"]
        w_t = np.where(G[..., None], t_px, 1.0)
        v = {"trans": float(np.mean((w_t * (trans - trans_b)) ** 2) / 2 * spp_pass)}
        for k in range(nplanes):
            w_r = np.where((G & (mplane == k))[..., None], r_px[..., None], 0.0)
            v[f"refl_{k}"] = float(np.mean((w_r * (refls[k] - refls_b[k])) ** 2) / 2 * spp_pass)
        v_ref = float(np.mean((ref - ref_b) ** 2) / 2 * spp_ref)
        target = v_ref / spp_ref  # the committed reference's own noise variance
        best_passes = sum(math.sqrt(v[i] * cpu[i]) for i in v) ** 2 / target
        s_sum = sum(math.sqrt(v[j] * cpu[j]) for j in v)
        alloc = {i: math.sqrt(v[i] / cpu[i]) * s_sum / target for i in v}
        equal_spp = sum(cpu[i] for i in v) * sum(v.values()) / target
        res["cost_at_equal_noise"] = {
            "target_sigma_per_channel": math.sqrt(target),
            "unit_variance_per_pass": v,
            "unit_variance_reference": v_ref,
            "cpu_s_per_spp": cpu,
            "reference_cpu_s": v_ref * cpu["reference"] / target,
            "passes_equal_spp_cpu_s": equal_spp,
            "passes_best_allocation_cpu_s": best_passes,
            "best_allocation_spp": alloc,
        }

    with open(os.path.join(an, "metrics.json"), "w", encoding="utf-8") as f:
        json.dump(res, f, indent=2)
        f.write("\n")
    figdir = os.path.join(ROOT, "docs", "figures")
    os.makedirs(figdir, exist_ok=True)
    err = np.abs(composite - ref) * 4.0
    to_png(os.path.join(figdir, "atrium_validation.png"), np.concatenate([ref, composite, err], axis=1))
    print(json.dumps(res, indent=1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("step", choices=["catalog", "check-bsdf", "passes", "mask", "reference", "split", "noise", "timing", "analyze", "all"])
    ap.add_argument("--compose", default=os.path.join(ROOT, "target", "debug", "compose"))
    ap.add_argument("--glassdb", default=os.path.join(ROOT, "target", "debug", "glassdb"))
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--spp-pass", type=int, default=256)
    ap.add_argument("--spp-ref", type=int, default=1024)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--own-mirror", action="store_true", help="mirror in this script (eqs. 4-7) instead of `glassdb mirror`")
    args = ap.parse_args()
    if args.step == "catalog":
        write_catalog()
        return
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(args.variant)
    if hasattr(dr, "set_thread_count"):
        dr.set_thread_count(args.threads)
    os.makedirs(os.path.join(FIX, "analysis"), exist_ok=True)
    with tempfile.TemporaryDirectory() as tmpdir:
        steps = ["check-bsdf", "passes", "mask", "reference", "split", "noise", "timing", "analyze"] if args.step == "all" else [args.step]
        if args.step == "all":
            write_catalog()
        for s in steps:
            if s == "check-bsdf":
                check_bsdf()
            elif s == "passes":
                cmd_passes(args, tmpdir)
            elif s == "mask":
                cmd_mask(args, tmpdir)
            elif s == "reference":
                cmd_reference(args, tmpdir)
            elif s == "split":
                cmd_split(args, tmpdir)
            elif s == "noise":
                cmd_passes(args, tmpdir, seed_offset=500, suffix="_b")
            elif s == "timing":
                cmd_timing(args, tmpdir)
            elif s == "analyze":
                cmd_analyze(args, tmpdir)


if __name__ == "__main__":
    main()
