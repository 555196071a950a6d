"""glassdb inside Blender's Python: composite a Cycles render's passes with a glass product.

Run headless (the glassdb package on Blender's sys.path, e.g. `pip install --target DIR
./python` and `sys.path.insert(0, DIR)`; docs/python.md):

    blender -b --python integrations/blender/glassdb_python_example.py -- OUT.json [RENDER_DIR]

RENDER_DIR holds a frame rendered by Blender (fixtures/blender/masks/b34 by default):
`trans.0001.exr`, `refl_0..2.0001.exr` and `beauty.0001.exr` with its Cryptomatte and the
`facing` and `plane` AOVs. The script builds the mask from the Cryptomatte, composites with
the bundled registry, puts the composite into a Blender image `glassdb composite` (shown in
the Image Editor; saved as OUT.exr beside OUT.json) and writes a summary to OUT.json.
"""

import json
import sys
from pathlib import Path

import glassdb

GLASS = [("Glass_clear", 1), ("Tinted*", 5)]


def composite_frame(render_dir, registry=None):
    """The composite of frame 1 of RENDER_DIR (float32 (H, W, 4), premultiplied RGBA)."""
    d = Path(render_dir)
    mask = glassdb.cryptomatte_mask(d / "beauty.0001.exr", glass=GLASS, cos="facing", plane="plane")
    trans = glassdb.read_passes(d / "trans.0001.exr")[0].pixels
    refl = [glassdb.read_passes(d / f"refl_{k}.0001.exr")[0].pixels for k in range(3)]
    return glassdb.compose(trans, refl, mask, registry=registry or glassdb.Registry.load())


def to_blender_image(pixels, name="glassdb composite"):
    """The composite as a float Blender image (rows bottom-up, as Blender stores them)."""
    import bpy

    h, w, _ = pixels.shape
    image = bpy.data.images.get(name) or bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    if tuple(image.size) != (w, h):
        image.scale(w, h)
    image.pixels.foreach_set(pixels[::-1].reshape(-1))
    return image


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else argv[1:]
    out = Path(args[0])
    here = Path(__file__).resolve().parents[2]
    render_dir = Path(args[1]) if len(args) > 1 else here / "fixtures" / "blender" / "masks" / "b34"
    registry = glassdb.Registry.load()
    pixels = composite_frame(render_dir, registry)
    summary = {
        "python": sys.version.split()[0],
        "glassdb": glassdb.__version__,
        "ids": registry.ids(),
        "shape": list(pixels.shape),
        "composite_sum": float(pixels.astype("float64").sum()),
    }
    try:
        image = to_blender_image(pixels)
        image.filepath_raw = str(out.with_suffix(".exr"))
        image.file_format = "OPEN_EXR"
        image.save()
        summary["blender_image"] = image.name
    except ImportError:  # outside Blender: the summary alone
        pass
    out.write_text(json.dumps(summary))


if __name__ == "__main__":
    main(sys.argv)
