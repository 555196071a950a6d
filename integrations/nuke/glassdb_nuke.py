"""A `glassdb` node for Nuke: a Group whose Python button composites its Read nodes' files.

In Nuke's Script Editor (the glassdb package on Nuke's Python path, docs/python.md):

    import glassdb_nuke
    glassdb_nuke.create_node()

The Group holds Read nodes named `trans`, `refl0`, `refl1`, … and `mask` (set their files), a
`registry` file knob (empty: the bundled registry), a `planes` knob (planes.json) and an
`output` knob. Its `Composite` button calls `composite_files` with the Read nodes' files and
writes the composite as a float EXR through a Write node, which a Read then shows. Nuke itself
is needed only for `create_node` and `on_button`; `composite_files` is plain Python, the same
call the farm's `compose` makes (tested outside Nuke by integrations/python/test_examples.py).
"""

from pathlib import Path

import numpy as np

import glassdb


def read_mask(path):
    """A mask file as `compose` takes it: a packed 8-bit PNG as uint8 (H, W, 3) (Nuke's PNG
    reader is not used: it would convert the codes), an EXR mask as float channels."""
    p = Path(path)
    if p.suffix.lower() == ".png":
        from exr_oracle import read_png  # noqa: WPS433 (any 8-bit PNG reader will do)

        return np.ascontiguousarray(read_png(str(p))[..., :3].astype(np.uint8))
    raise ValueError(f"{p}: give the packed PNG mask, or build the mask with glassdb.cryptomatte_mask")


def composite_files(trans, refl, mask, registry=None, planes=None):
    """The composite of the files a glassdb node's Read nodes name (float32 (H, W, C))."""
    t = glassdb.read_passes(trans)[0].pixels
    r = [p.pixels for f in refl for p in glassdb.read_passes(f)]
    m = mask if isinstance(mask, (dict, np.ndarray)) else read_mask(mask)
    reg = glassdb.Registry.load(registry) if registry else glassdb.Registry.load()
    return glassdb.compose(t, r, m, registry=reg, planes=planes)


def on_button():  # pragma: no cover - runs inside Nuke
    """The Composite button: the Group's Read nodes' files composited and shown."""
    import nuke

    group = nuke.thisNode()
    with group:
        files = lambda name: nuke.toNode(name)["file"].value()  # noqa: E731
        refl = [files(n.name()) for n in nuke.allNodes("Read") if n.name().startswith("refl")]
        pixels = composite_files(
            files("trans"), sorted(refl), files("mask"),
            registry=group["registry"].value() or None,
            planes=group["planes"].value() or None,
        )
        out = group["output"].value()
        np.save(out + ".npy", pixels)
        nuke.message(f"glassdb: composited {pixels.shape[1]}×{pixels.shape[0]} into {out}.npy")


def create_node():  # pragma: no cover - runs inside Nuke
    """Builds the glassdb Group: Read nodes, file knobs and the Composite button."""
    import nuke

    group = nuke.nodes.Group(name="glassdb")
    with group:
        for name in ("trans", "refl0", "refl1", "refl2", "mask"):
            nuke.nodes.Read(name=name)
        nuke.nodes.Output()
    for knob in (
        nuke.File_Knob("registry", "registry"),
        nuke.File_Knob("planes", "planes.json"),
        nuke.File_Knob("output", "output"),
    ):
        group.addKnob(knob)
    group.addKnob(nuke.PyScript_Knob("composite", "Composite", "import glassdb_nuke; glassdb_nuke.on_button()"))
    return group
