"""Copies what `compose --light-groups` needs of a `glassdb blender render` run into the bundled
dusk fixture (fixtures/dusk/, by scripts/blender/make_dusk_fixture.sh), as small as it can be
without changing a pixel that compose reads:

- every pass (trans, refl_K, refl_K_G of frame 1) keeps only its light-group layers
  `<prefix>Combined_<group>.R/G/B` (the beauty `Combined` is their sum and compose does not
  read it with --light-groups; alpha is dropped), as half floats, ZIP, with its data window
  (a reflection pass stays cropped where the run cropped it) and display window; in a
  reflection pass of plane K, the pixels that are not glass of plane K in the mask (mullions,
  spandrels, the other facade inside its rectangle) are zeroed, since compose reads a
  reflection pass on its plane's glass pixels only (the composite is the same, bit for bit, and
  zeros compress);
- the mask keeps its channels (id, cos_theta, plane, coverage) as half floats (ids and planes
  exact; cos θ within 2.5e-4, the half spacing below 1 halved; an eighth of the float file);
- planes.json is copied (compose reads each plane's side from it), its `source` made the
  relative name `scene.obj` (the run's absolute path means nothing in a clone).

Usage: .venv/bin/python scripts/blender/make_dusk_repack.py OUT_DIR RUN_DIR

RUN_DIR is a `glassdb blender render --light GROUP=ILLUMINANT … --light-split off` run: every
pass holds one layer `ViewLayer.Combined_<group>` per light group, as Cycles names them.
Writes OUT_DIR/trans.exr, refl_K.exr, refl_K_G.exr, mask.exr, planes.json; prints each file's
size and the groups found. Fails (exit 1) when a pass has no light-group layer, or when the
passes do not all have the same groups.

Licence: same as the project, MIT OR Apache-2.0.
"""

import json
import os
import re
import sys

import numpy as np
import OpenEXR

GROUP_CHANNEL = re.compile(r"^(?:(.*)\.)?Combined_([^.]+)\.([RGB])$")


def fail(message):
    sys.exit("make_dusk_repack.py: " + message)


def read(path):
    with OpenEXR.File(path, separate_channels=True) as f:
        header = dict(f.header())
        channels = {name: np.array(ch.pixels) for name, ch in f.channels().items()}
    return header, channels


def write(path, header, channels):
    out = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        "dataWindow": header["dataWindow"],
        "displayWindow": header["displayWindow"],
    }
    for key in ("pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "lineOrder", "chromaticities"):
        if key in header:
            out[key] = header[key]
    tmp = path + ".tmp.exr"
    with OpenEXR.File(out, channels) as f:
        f.write(tmp)
    os.replace(tmp, path)
    return os.path.getsize(path)


def group_layers(path):
    """The pass's light-group channels as half floats, and the sorted group names."""
    header, channels = read(path)
    kept, groups = {}, set()
    for name, pixels in channels.items():
        m = GROUP_CHANNEL.match(name)
        if m:
            kept[name] = np.ascontiguousarray(pixels, dtype=np.float16)
            groups.add(m.group(2))
    if not kept:
        fail("%s has no light-group layer (<prefix>Combined_<group>.R/G/B): channels %s"
             % (path, sorted(channels)))
    return header, kept, sorted(groups)


def zero_off_plane(kept, header, plane, ids, planes):
    """Zeroes the samples of a reflection pass of `plane` where the mask has no glass of that
    plane (the pass's data window placed in the mask's frame)."""
    x0, y0, x1, y1 = window(header)
    (dx0, dy0), _ = header["displayWindow"]
    rows = slice(y0 - int(dy0), y1 - int(dy0) + 1)
    cols = slice(x0 - int(dx0), x1 - int(dx0) + 1)
    off = (ids[rows, cols] == 0) | (planes[rows, cols] != plane)
    for name in kept:
        kept[name] = np.where(off, np.float16(0.0), kept[name])


def frame_of(run):
    with open(os.path.join(run, "glassdb-blender.json")) as fh:
        return json.load(fh)["frames"][0]


def pass_files(frame):
    """(file in the run, name in the fixture) of every pass of a run's frame."""
    passes = [(frame["trans"], "trans.exr")]
    passes += [(f, "refl_%d.exr" % k) for k, f in enumerate(frame["refl"])]
    passes += [(g["file"], "refl_%d_%d.exr" % (g["plane"], g["group"])) for g in frame.get("groups", [])]
    return passes


def window(header):
    lo, hi = header["dataWindow"]
    return [int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1])]


def main(argv):
    if len(argv) != 3:
        fail("usage: make_dusk_repack.py OUT_DIR RUN_DIR")
    out, run = argv[1], argv[2]
    frame = frame_of(run)
    os.makedirs(out, exist_ok=True)
    mask_header, mask = read(os.path.join(run, frame["mask"]))
    ids, planes = np.asarray(mask["id"]), np.asarray(mask["plane"])
    plane_of = {dst: int(dst.split("_")[1].split(".")[0]) for _, dst in pass_files(frame) if dst.startswith("refl_")}
    total, groups_seen = 0, None
    for src, dst in pass_files(frame):
        header, kept, groups = group_layers(os.path.join(run, src))
        if dst in plane_of:
            zero_off_plane(kept, header, plane_of[dst], ids, planes)
        if groups_seen is None:
            groups_seen = groups
        elif groups != groups_seen:
            fail("%s has groups %s, the transmission pass %s" % (src, groups, groups_seen))
        size = write(os.path.join(out, dst), header, kept)
        total += size
        print("%s <- %s: %d bytes" % (dst, src, size))
    header, channels = mask_header, mask
    channels = {k: np.ascontiguousarray(v, dtype=np.float16) for k, v in channels.items()}
    ids = np.rint(channels["id"].astype(np.float64))
    if np.any(ids != channels["id"]) or np.any(ids > 2048):
        fail("the mask's ids are not exact in half floats")
    size = write(os.path.join(out, "mask.exr"), header, channels)
    total += size
    print("mask.exr <- %s: %d bytes (%s)" % (frame["mask"], size, ", ".join(sorted(channels))))
    with open(os.path.join(run, "planes.json")) as fh:
        planes = json.load(fh)
    planes["source"] = "scene.obj"
    with open(os.path.join(out, "planes.json"), "w") as fh:
        json.dump(planes, fh, indent=2)
        fh.write("\n")
    print("groups: %s; passes + mask: %d bytes" % (",".join(groups_seen), total))


if __name__ == "__main__":
    main(sys.argv)
