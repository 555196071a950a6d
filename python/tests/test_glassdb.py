"""The Python package against the commands on the bundled fixtures (scripts/test-all runs it).

Every function is compared with what the `glassdb` and `compose` commands give for the same
inputs: composites bit for bit (float EXR output read with OpenEXR's own bindings), registry,
stack and spectral values exactly. The commands are the workspace's build (GLASSDB_BIN_DIR,
default target/debug).
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenEXR
import pytest

import glassdb

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("GLASSDB_BIN_DIR", ROOT / "target" / "debug"))
ATRIUM = ROOT / "fixtures" / "atrium"
B34 = ROOT / "fixtures" / "blender" / "masks" / "b34"
GLAZING = ROOT / "fixtures" / "glazing"
sys.path.insert(0, str(ROOT / "python_oracle"))
from exr_oracle import read_png, write_png_rgb8  # noqa: E402  (the oracles' PNG codec, not glassdb's)


def run(tool, *args):
    """Runs a command of the workspace's build; returns its stdout."""
    exe = BIN / tool
    assert exe.is_file(), f"{exe} is missing: build the workspace first (cargo build)"
    done = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout


def exr_channels(path):
    """Every channel of a one-part EXR, by name, as float32 (H, W)."""
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {k: np.asarray(c.pixels, dtype=np.float32) for k, c in f.channels().items()}


def compose_cli(tmp_path, *args):
    """`compose … --data-type float --keep-channels none -o out.exr`: its R, G, B (and A)."""
    out = tmp_path / "cli.exr"
    run("compose", *args, "--data-type", "float", "--keep-channels", "none", "-o", out)
    ch = exr_channels(out)
    names = [n for n in ("R", "G", "B", "A") if n in ch]
    return np.stack([ch[n] for n in names], axis=-1)


def assert_bits_equal(got, want):
    assert got.dtype == np.float32 and got.shape == want.shape, (got.shape, want.shape)
    differ = got.view(np.uint32) != want.view(np.uint32)
    assert not differ.any(), f"{differ.sum()} samples differ, first at {np.argwhere(differ)[0]}"


ATRIUM_REFL = [ATRIUM / f"refl_{k}.exr" for k in range(3)]
PLANES = ATRIUM / "virtual" / "planes.json"


def atrium_passes():
    trans = glassdb.read_passes(ATRIUM / "trans.exr")[0].pixels
    refl = [glassdb.read_passes(p)[0].pixels for p in ATRIUM_REFL]
    return trans, refl


def test_compose_atrium_packed_mask_bit_for_bit(tmp_path):
    want = compose_cli(
        tmp_path,
        *[a for p in ATRIUM_REFL for a in ("--refl", p)],
        "--trans", ATRIUM / "trans.exr", "--mask", ATRIUM / "mask.png", "--planes", PLANES,
    )
    trans, refl = atrium_passes()
    mask = np.ascontiguousarray(read_png(str(ATRIUM / "mask.png"))[..., :3].astype(np.uint8))
    got = glassdb.compose(trans, refl, mask, planes=PLANES)
    assert_bits_equal(got, want)
    # The arrays passed in are left as they were: the composite is a new array.
    assert not np.shares_memory(got, trans)


def test_compose_atrium_float_mask_and_own_registry_bit_for_bit(tmp_path):
    registry = tmp_path / "atrium.json"
    run("glassdb", "registry", "build", ATRIUM / "catalog.toml", "-o", registry)
    want = compose_cli(
        tmp_path,
        *[a for p in ATRIUM_REFL for a in ("--refl", p)],
        "--trans", ATRIUM / "trans.exr", "--mask", ATRIUM / "mask.exr", "--planes", PLANES,
        "--registry", registry,
    )
    ch = exr_channels(ATRIUM / "mask.exr")
    mask = {"id": ch["id"], "cos": ch["cos_theta"]}
    if "plane" in ch:
        mask["plane"] = ch["plane"]
    if "coverage" in ch:
        mask["coverage"] = ch["coverage"]
    trans, refl = atrium_passes()
    got = glassdb.compose(trans, refl, mask, registry=glassdb.Registry.load(registry), planes=PLANES)
    assert_bits_equal(got, want)


def test_compose_refuses_a_unit_without_its_pane_group_passes_unless_surfaces_1(tmp_path):
    # The atrium's glass as id 11 of the bundled registry (double clear: a unit of two pane
    # groups). Arrays carry no pane-group passes: like `compose` without --refl-group, the
    # unit is refused, naming its plane and group, unless surfaces=1 folds its deeper group
    # into the plane's pass, as `compose --surfaces 1` does.
    mask = np.ascontiguousarray(read_png(str(ATRIUM / "mask.png"))[..., :3].astype(np.uint8))
    mask[..., 1] = np.where(mask[..., 1] > 0, 11, 0).astype(np.uint8)
    unit_mask = tmp_path / "unit_mask.png"
    write_png_rgb8(str(unit_mask), mask)
    trans, refl = atrium_passes()
    refl_args = [a for p in ATRIUM_REFL for a in ("--refl", p)]
    done = subprocess.run(
        [str(BIN / "compose"), *map(str, refl_args), "--trans", str(ATRIUM / "trans.exr"),
         "--mask", str(unit_mask), "--planes", str(PLANES), "-o", str(tmp_path / "out.exr")],
        capture_output=True, text=True,
    )
    assert done.returncode != 0
    with pytest.raises(glassdb.InvalidInput) as e:
        glassdb.compose(trans, refl, mask, planes=PLANES)
    assert "pane group 1" in str(e.value) and "glass 11" in str(e.value), str(e.value)
    assert done.stderr.splitlines()[0].startswith("error: mask ") and "pane group 1" in done.stderr
    want = compose_cli(tmp_path, *refl_args, "--trans", ATRIUM / "trans.exr", "--mask", unit_mask,
                       "--planes", PLANES, "--surfaces", "1")
    assert_bits_equal(glassdb.compose(trans, refl, mask, planes=PLANES, surfaces=1), want)
    with pytest.raises(glassdb.InvalidInput):
        glassdb.compose(trans, refl, mask, planes=PLANES, surfaces=0)


def test_compose_multi_plane_file_bit_for_bit(tmp_path):
    layers = tmp_path / "layers.exr"
    subprocess.run(
        [sys.executable, str(ROOT / "python_oracle" / "plane_parts.py"), "layers", "--out", str(layers),
         *map(str, ATRIUM_REFL)],
        check=True,
    )
    want = compose_cli(
        tmp_path, "--refl", layers, "--trans", ATRIUM / "trans.exr",
        "--mask", ATRIUM / "mask.png", "--planes", PLANES,
    )
    passes = glassdb.read_passes(layers)
    assert [p.layer for p in passes] == ["plane0", "plane1", "plane2"]
    trans = glassdb.read_passes(ATRIUM / "trans.exr")[0].pixels
    mask = np.ascontiguousarray(read_png(str(ATRIUM / "mask.png"))[..., :3].astype(np.uint8))
    got = glassdb.compose(trans, [p.pixels for p in passes], mask, planes=PLANES)
    assert_bits_equal(got, want)


def test_compose_cryptomatte_bit_for_bit_with_alpha(tmp_path):
    refl = [B34 / f"refl_{k}.0001.exr" for k in range(3)]
    want = compose_cli(
        tmp_path,
        "--trans", B34 / "trans.0001.exr", *[a for p in refl for a in ("--refl", p)],
        "--mask", B34 / "beauty.0001.exr", "--mask-cryptomatte",
        "--mask-glass", "Glass_clear=1", "--mask-glass", "Tinted*=5",
        "--mask-channels", "cos=facing,plane=plane",
    )
    mask = glassdb.cryptomatte_mask(
        B34 / "beauty.0001.exr", glass=[("Glass_clear", 1), ("Tinted*", 5)], cos="facing", plane="plane"
    )
    assert set(mask) >= {"id", "cos", "plane"}
    assert sorted(np.unique(mask["id"]).tolist()) == [0.0, 1.0, 5.0]
    trans = glassdb.read_passes(B34 / "trans.0001.exr")[0]
    assert trans.pixels.shape == (120, 160, 4) and trans.layer == "ViewLayer.Combined"
    got = glassdb.compose(trans.pixels, [glassdb.read_passes(p)[0].pixels for p in refl], mask)
    assert_bits_equal(got, want)


def test_read_passes_matches_openexr():
    p = glassdb.read_passes(ATRIUM / "refl_1.exr")[0]
    ch = exr_channels(ATRIUM / "refl_1.exr")
    assert p.space is None and p.data_window == (0, 0, 320, 240)
    assert_bits_equal(p.pixels, np.stack([ch["R"], ch["G"], ch["B"]], axis=-1))


def test_registry_build_is_the_commands(tmp_path):
    out = tmp_path / "cli.json"
    run("glassdb", "registry", "build", ATRIUM / "catalog.toml", "-o", out, "--space", "srgb,acescg")
    built = glassdb.Registry.build(ATRIUM / "catalog.toml", spaces=["srgb", "acescg"])
    assert built.to_json() == out.read_text()
    assert built.spaces() == ["srgb", "acescg"]
    loaded = glassdb.Registry.load(out)
    data = json.loads(out.read_text())
    assert len(data["tables"]) == 2
    for space, table in zip(loaded.spaces(), data["tables"]):
        assert loaded.ids(space) == [g["id"] for g in table["glasses"]]
        for g in table["glasses"]:
            record = loaded.glass(g["id"], space)
            for key in ("name", "r0", "t0", "r0_back", "c_r", "c_t", "luminous", "unit"):
                assert record.get(key) == g.get(key), key
            assert record["tau_v"] == (g.get("luminous") or {}).get("transmittance")


LIGHT_GROUPS = ROOT / "fixtures" / "light_groups"
WARM_LED = ROOT / "fixtures" / "lights" / "warm_led.csv"


def light_catalog(tmp_path):
    """A catalog of the light-group fixture's glasses: Arctic Blue (id 9) and the bronze film
    (id 10), whose colours under D65 and A differ most (docs/colour.md, "Lights")."""
    text = "".join(
        f'[[glass]]\nid = {gid}\nname = "glass {gid}"\nspectral = "{GLAZING / name}"\n\n'
        for gid, name in ((9, "nfrc_9962.json"), (10, "nfrc_9223.json"))
    )
    catalog = tmp_path / "catalog.toml"
    catalog.write_text(text)
    return catalog


def test_registry_build_with_lights_is_the_commands(tmp_path):
    catalog = light_catalog(tmp_path)
    out = tmp_path / "cli.json"
    run("glassdb", "registry", "build", catalog, "-o", out, "--space", "srgb,acescg",
        "--light", "sun=D65", "--light", "warm=A", "--light", f"led={WARM_LED}")
    built = glassdb.Registry.build(
        catalog, spaces=["srgb", "acescg"], lights=["sun=D65", ("warm", "A"), ("led", WARM_LED)]
    )
    assert built.to_json() == out.read_text()
    tables = json.loads(built.to_json())["tables"]
    assert [t["light"] for t in tables] == ["sun", "sun", "warm", "warm", "led", "led"]
    # --white-balance as the command takes it
    out = tmp_path / "balanced.json"
    run("glassdb", "registry", "build", catalog, "-o", out, "--light", "warm=A", "--white-balance", "D65")
    assert glassdb.Registry.build(catalog, lights=[("warm", "A")], white_balance="D65").to_json() == out.read_text()
    # The command's refusals, with its messages.
    for args, kwargs in [
        (["--light", "sun"], {"lights": ["sun"]}),
        (["--light", "sun=D65", "--illuminant", "A"], {"lights": ["sun=D65"], "illuminant": "A"}),
        (["--light", "sun=D65", "--light", "sun=A"], {"lights": ["sun=D65", ("sun", "A")]}),
    ]:
        done = subprocess.run([str(BIN / "glassdb"), "registry", "build", str(catalog), "-o",
                               str(tmp_path / "no.json"), *args], capture_output=True, text=True)
        assert done.returncode != 0
        with pytest.raises(glassdb.InvalidInput) as e:
            glassdb.Registry.build(catalog, **kwargs)
        assert done.stderr.splitlines()[0] == f"error: {e.value}", args
    with pytest.raises(glassdb.InvalidInput):
        glassdb.Registry.build(catalog, lights=[("sun",)])


def light_group_passes():
    """The fixture's passes as {group: float32 (H, W, 3)} (its `ViewLayer.Combined_<group>`)."""
    def groups(path):
        return {g: glassdb.read_passes(path, layer=f"ViewLayer.Combined_{g}")[0].pixels
                for g in ("sun", "warm")}
    mask = np.ascontiguousarray(read_png(str(LIGHT_GROUPS / "mask.png"))[..., :3].astype(np.uint8))
    return groups(LIGHT_GROUPS / "trans.exr"), groups(LIGHT_GROUPS / "refl.exr"), mask


def test_compose_light_groups_bit_for_bit(tmp_path):
    registry = tmp_path / "lights.json"
    run("glassdb", "registry", "build", light_catalog(tmp_path), "-o", registry,
        "--light", "sun=D65", "--light", "warm=A")
    out = tmp_path / "cli.exr"
    run("compose", "--registry", registry, "--trans", LIGHT_GROUPS / "trans.exr",
        "--refl", LIGHT_GROUPS / "refl.exr", "--mask", LIGHT_GROUPS / "mask.png",
        "--light-groups", "sun,warm", "--data-type", "float", "-o", out)
    ch = exr_channels(out)
    want = np.stack([ch[f"ViewLayer.Combined.{c}"] for c in "RGB"], axis=-1)
    trans, refl, mask = light_group_passes()
    reg = glassdb.Registry.load(registry)
    got = glassdb.compose(trans, refl, mask, registry=reg, light_groups=["sun", "warm"])
    assert_bits_equal(got, want)
    # the same with a list of reflection planes and the groups as one string
    assert_bits_equal(glassdb.compose(trans, [refl], mask, registry=reg, light_groups="sun,warm"), want)
    # Σ_g: each group alone under its own light's registry, summed in float32 in order
    alone = []
    for group, spec in (("sun", "D65"), ("warm", "A")):
        one = tmp_path / f"{group}.json"
        run("glassdb", "registry", "build", light_catalog(tmp_path), "-o", one, "--light", f"{group}={spec}")
        alone.append(glassdb.compose(trans[group], refl[group], mask, registry=glassdb.Registry.load(one)))
    assert_bits_equal(got, alone[0] + alone[1])
    # the warm group under its own table is not the sun's
    assert not np.array_equal(alone[1], glassdb.compose(trans["warm"], refl["warm"], mask, registry=reg))


def test_compose_light_groups_refuse_what_does_not_match(tmp_path):
    catalog = light_catalog(tmp_path)
    trans, refl, mask = light_group_passes()
    registry = tmp_path / "lights.json"
    run("glassdb", "registry", "build", catalog, "-o", registry,
        "--light", "sun=D65", "--light", "warm=A", "--light", "lamp=LED-B1")
    reg = glassdb.Registry.load(registry)
    # the warm group has no table given
    with pytest.raises(glassdb.InvalidInput) as e:
        glassdb.compose(trans, refl, mask, registry=reg, light_groups=["sun"])
    assert str(e.value) == "trans has light groups without a table: warm (the groups composited: sun)"
    # the lamp has a table but no pass
    with pytest.raises(glassdb.InvalidInput) as e:
        glassdb.compose(trans, refl, mask, registry=reg, light_groups=["sun", "warm", "lamp"])
    assert "lamp" in str(e.value) and "sun, warm" in str(e.value)
    with pytest.raises(glassdb.InvalidInput):
        glassdb.compose(trans, refl["sun"], mask, registry=reg, light_groups=["sun", "warm"])
    with pytest.raises(glassdb.InvalidInput):
        glassdb.compose(trans, refl, mask, registry=reg, light_groups=["sun", "sun"])
    # a group's array of another size, named by its group
    with pytest.raises(glassdb.InvalidInput) as e:
        glassdb.compose({**trans, "warm": trans["warm"][:4]}, refl, mask, registry=reg,
                        light_groups=["sun", "warm"])
    assert str(e.value).startswith('trans["warm"]: shape [4, 8, 3]'), str(e.value)
    # a registry without the warm light: the command's message
    sun_only = tmp_path / "sun.json"
    run("glassdb", "registry", "build", catalog, "-o", sun_only, "--light", "sun=D65")
    done = subprocess.run(
        [str(BIN / "compose"), "--registry", str(sun_only), "--trans", str(LIGHT_GROUPS / "trans.exr"),
         "--refl", str(LIGHT_GROUPS / "refl.exr"), "--mask", str(LIGHT_GROUPS / "mask.png"),
         "--light-groups", "sun,warm", "-o", str(tmp_path / "out.exr")],
        capture_output=True, text=True,
    )
    assert done.returncode != 0
    with pytest.raises(glassdb.InvalidInput) as e:
        glassdb.compose(trans, refl, mask, registry=glassdb.Registry.load(sun_only),
                        light_groups=["sun", "warm"])
    assert done.stderr.splitlines()[0] == f"error: {e.value}"


def test_registry_eval_is_registry_show(tmp_path):
    out = tmp_path / "r.json"
    run("glassdb", "registry", "build", ATRIUM / "catalog.toml", "-o", out)
    shown = run("glassdb", "registry", "show", out)
    reg = glassdb.Registry.load(out)
    rows = [l.split() for l in shown.splitlines() if l.strip().endswith("") and "°" in l and l.strip()[0].isdigit()]
    per_glass = iter(rows)
    for gid in reg.ids():
        for deg in (0, 45, 60, 75):
            row = next(per_glass)
            assert row[0] == f"{deg}°"
            r, t = reg.eval(gid, float(np.cos(np.radians(float(deg)))))
            assert [f"{v:.4f}" for v in (*r, *t)] == row[1:7]
    r, t = reg.eval(reg.ids()[0], np.array([1.0, 0.5, 0.0]))
    assert r.shape == (3, 3) and t.shape == (3, 3)
    assert tuple(r[1]) == tuple(reg.eval(reg.ids()[0], 0.5)[0])


def test_stack_is_glassdb_stack_json():
    layers = [str(GLAZING / "CLEAR_6.DAT"), str(GLAZING / "CLEAR_3.DAT")]
    want = json.loads(run("glassdb", "stack", *layers, "--gap", "12.7:argon", "--angles", "0,30,60", "--json"))
    got = glassdb.stack(layers, gaps=["12.7:argon"], angles=[0, 30, 60])
    assert got == want
    assert glassdb.stack(layers, angles="0:60:30", gaps=["12.7:argon"]) == want


def test_spectral_is_glassdb_spectral_json():
    f = GLAZING / "CLEAR_3.DAT"
    for extra, kwargs in [((), {}), (("--space", "acescg", "--illuminant", "A"), {"space": "acescg", "illuminant": "A"})]:
        want = json.loads(run("glassdb", "spectral", f, *extra, "--json"))
        assert glassdb.spectral(f, **kwargs) == want


def test_errors_are_the_kinds_classes(tmp_path):
    trans, refl = atrium_passes()
    mask = np.ascontiguousarray(read_png(str(ATRIUM / "mask.png"))[..., :3].astype(np.uint8))
    # An id the registry lacks: the command's message names the ids and the registry.
    bad = mask.copy()
    bad[0, 0] = (0, 77, 255)
    with pytest.raises(glassdb.InvalidInput) as e:
        glassdb.compose(trans, refl, bad, planes=PLANES)
    assert "77" in str(e.value) and isinstance(e.value, ValueError)
    with pytest.raises(glassdb.InvalidInput):
        glassdb.compose(trans, refl[:1], mask)  # planes 1 and 2 have no pass
    with pytest.raises(glassdb.InvalidInput):
        glassdb.compose(trans, refl, mask[:10])
    with pytest.raises(glassdb.IoError) as e:
        glassdb.read_passes(tmp_path / "missing.exr")
    assert isinstance(e.value, OSError) and "missing.exr" in str(e.value)
    with pytest.raises(glassdb.IoError):
        glassdb.Registry.load(tmp_path / "none.json")
    future = tmp_path / "future.json"
    future.write_text('{"schema": 99, "tables": []}')
    with pytest.raises(glassdb.GlassdbError) as e:
        glassdb.Registry.load(future)
    assert e.value.kind in ("unsupported", "invalid")
    huge = tmp_path / "huge.png"
    # A PNG header claiming 100 000 × 100 000 pixels: refused from its header.
    import struct, zlib
    ihdr = struct.pack(">IIBBBBB", 100000, 100000, 8, 2, 0, 0, 0)
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    huge.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b""))
    with pytest.raises(glassdb.LimitExceeded):
        glassdb.read_passes(huge)
    with pytest.raises(glassdb.InvalidInput):
        glassdb.stack([str(GLAZING / "CLEAR_6.DAT")], angles="0:80:x")
    # The message is the command's.
    done = subprocess.run([str(BIN / "glassdb"), "spectral", str(tmp_path / "none.DAT")], capture_output=True, text=True)
    with pytest.raises(glassdb.IoError) as e:
        glassdb.spectral(tmp_path / "none.DAT")
    assert done.stderr.splitlines()[0] == f"error: {e.value}"


BLENDER = shutil.which("blender")


def test_blender_loads_the_wheel(tmp_path):
    """Debian's Blender (its system Python 3.11) imports the abi3 package and composites a
    Cycles render from its Cryptomatte (integrations/blender/glassdb_python_example.py)."""
    assert BLENDER, "blender is missing (scripts/test-all installs it)"
    site = tmp_path / "site"
    shutil.copytree(Path(glassdb.__file__).parent, site / "glassdb",
                    ignore=shutil.ignore_patterns("__pycache__"))
    script = ROOT / "integrations" / "blender" / "glassdb_python_example.py"
    out = tmp_path / "blender.json"
    done = subprocess.run(
        [BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr",
         f"import sys, runpy; sys.path.insert(0, {str(site)!r}); sys.argv = ['blender', '--', {str(out)!r}]; "
         f"runpy.run_path({str(script)!r}, run_name='__main__')"],
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0 and out.is_file(), done.stdout[-3000:] + done.stderr[-3000:]
    got = json.loads(out.read_text())
    assert got["python"].startswith("3.11") and got["blender_image"] == "glassdb composite"
    reg = glassdb.Registry.load()
    assert got["ids"] == reg.ids()
    sys.path.insert(0, str(script.parent))
    import glassdb_python_example as example
    want = example.composite_frame(B34, reg)
    assert got["composite_sum"] == float(want.astype(np.float64).sum())


def test_stubs_match_the_module():
    """Every public name of the extension is in its .pyi, with the same parameters, and has a
    docstring."""
    import ast
    import inspect

    from glassdb import _glassdb

    stub = ast.parse((Path(glassdb.__file__).parent / "_glassdb.pyi").read_text())
    declared = {}
    for node in stub.body:
        if isinstance(node, ast.FunctionDef):
            declared[node.name] = [a.arg for a in node.args.args + node.args.kwonlyargs]
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    args = [a.arg for a in item.args.args + item.args.kwonlyargs]
                    declared[f"{node.name}.{item.name}"] = [a for a in args if a != "self"]
            declared[node.name] = None
    public = [n for n in dir(_glassdb) if not n.startswith("_")]
    assert sorted(n for n in declared if "." not in n) == sorted(public)
    for name, params in declared.items():
        obj = _glassdb
        for part in name.split("."):
            obj = getattr(obj, part)
        assert (obj.__doc__ or "").strip(), f"{name} has no docstring"
        if params is None or isinstance(obj, property) or not callable(obj):
            continue
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        got = [p for p in sig.parameters if p not in ("self", "cls")]
        assert got == params, (name, got, params)
