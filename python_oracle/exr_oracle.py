"""Independent EXR reader for checking `compose` (OpenEXR's own Python bindings, OpenEXR 3.5.3,
and numpy; nothing of glassdb's codecs or of the `exr` crate).

Usage:
  exr_oracle.py header FILE
      JSON on stdout, per part: name, view, data_window and display_window
      ([xmin, ymin, xmax, ymax], inclusive, absolute EXR pixel coordinates), channels
      [{name, type, x_sampling, y_sampling}] and the header's other attributes (strings, numbers,
      lists; enums by name; tile descriptions as objects; anything else as
      {"unserialised": TYPE}).
  exr_oracle.py check-composite --input IN.exr --output OUT.exr --mask MASK.png --gain R,G,B
                                [--layer PREFIX] [--rtol 2e-3]
      Checks a composite that compose made with --trans IN --refl IN: on glass pixels of the mask
      (G != 0; the mask must have cos θ = 1 there, B = max, and plane R = 0) out = in·gain per
      channel, elsewhere out = in. Also: OUT's display window equals IN's, OUT's data window
      equals IN's (of the part holding the chosen RGB layer), alpha (if IN's layer has one) is
      kept. The mask covers IN's display window, its pixel (0, 0) at the display window's
      top-left; data-window pixels outside the mask image are not glass. Tolerance per sample:
      rtol·|expected| plus half a unit in the last place of a half (if OUT's channel is half) or
      of a float. OUT's layer is the
      one with IN's layer's part name and prefix when OUT has it (compose keeps the other layers
      and parts), else OUT's first RGB layer (bare R, G, B preferred). Channels outside those
      layers that both files have (matched by part name) must be unchanged. Prints a JSON summary
      and exits 0; on any mismatch prints "exr_oracle: MISMATCH: reason" on stderr and exits 1
      (2 for usage errors or unreadable inputs, 3 for an internal error).
  exr_oracle.py mask-png --like IN.exr --out MASK.png --rect X0,Y0,X1,Y1 --id N
      Writes an 8-bit RGB packed mask (R plane 0, G id, B round(cos θ·255) = 255) the size of
      IN's display window (of its first part): id N inside the rectangle (display-window-relative
      pixel coordinates, inclusive, clipped to the image), zeros elsewhere.
  exr_oracle.py gain --registry REGISTRY.json --id N [--space SPACE]
      Prints r(id, θ=0) + t(id, θ=0) per channel (r0·C_r(cos θ = 1) + t0·C_t(cos θ = 1), the
      curves evaluated from their powers and coefficients) as "R,G,B", from the registry's table
      in SPACE (schema 3; default its first table).
  exr_oracle.py check-display --exr COMPOSITE.exr --png OUT.png --space SPACE [--tol 1.5]
      Checks a `standard`-view PNG: the EXR's RGB (un-premultiplied) converted from SPACE to
      linear sRGB by colour-science's RGB_to_RGB (CAT02), sRGB-encoded, clipped, quantised to
      the PNG's depth; every sample within --tol codes (exit 1 otherwise).

RGB layers: channels PREFIX.R, PREFIX.G, PREFIX.B (PREFIX "" for bare R, G, B) in one part;
--layer PREFIX matches PREFIX itself or "PARTNAME.PREFIX" (a part's name qualifies its channels,
as compose does). Without --layer: the bare R, G, B of the first part that has them, else the only
RGB layer, else the only one whose prefix ends in "Combined", else an error listing them.
"""

import argparse
import json
import math
import struct
import sys
import zlib

import numpy as np
import OpenEXR


class OracleError(Exception):
    """A usage or input problem (exit 2)."""


class Mismatch(Exception):
    """The composite is wrong (exit 1)."""


# ---------------------------------------------------------------------------------------------
# EXR reading


def _window(value):
    lo, hi = value
    return [int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1])]


def _enum_name(value):
    name = getattr(value, "name", None)
    if isinstance(name, str):
        return name
    text = str(value)
    return text.split(".", 1)[1] if "." in text else text


def _jsonable(value):
    """A JSON value for a header attribute, or None when it has no simple form."""
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.floating,)):
        return _jsonable(float(value))
    if isinstance(value, np.ndarray):
        return [_jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        items = [_jsonable(v) for v in value]
        return None if any(i is None and v is not None for i, v in zip(items, value)) else items
    if isinstance(value, dict):
        items = {str(k): _jsonable(v) for k, v in value.items()}
        return None if any(v is None for v in items.values()) else items
    type_name = type(value).__name__
    if type_name in ("Compression", "LineOrder", "Storage", "Envmap", "LevelMode",
                     "LevelRoundingMode", "PixelType"):
        return _enum_name(value)
    if type_name == "TileDescription":
        return {
            "x_size": int(value.xSize),
            "y_size": int(value.ySize),
            "mode": _enum_name(value.mode),
            "rounding_mode": _enum_name(value.roundingMode),
        }
    if type_name == "Rational":
        return [int(value.n), int(value.d)]
    return None


def _open(path, header_only=False):
    try:
        return OpenEXR.File(str(path), separate_channels=True, header_only=header_only)
    except Exception as e:  # the bindings raise RuntimeError / ValueError / their own types
        raise OracleError(f"{path}: OpenEXR cannot read it: {e}") from e


def header_json(path):
    """The `header` subcommand's document for one file."""
    read_error = None
    try:
        exr = _open(path)
    except OracleError as e:
        # Pixels unreadable: the header may still be; channel types then stay unknown.
        read_error = str(e)
        exr = _open(path, header_only=True)
    parts = []
    for part in exr.parts:
        h = part.header
        name = h.get("name")
        channels = []
        with_pixels = part.channels if read_error is None else {}
        for ch in h.get("channels", []):
            typed = with_pixels.get(ch.name)
            channels.append({
                "name": ch.name,
                "type": _enum_name(typed.type()) if typed is not None else None,
                "x_sampling": int(ch.xSampling),
                "y_sampling": int(ch.ySampling),
            })
        attributes = {}
        for key in sorted(h):
            if key in ("channels", "dataWindow", "displayWindow", "name", "view"):
                continue
            value = _jsonable(h[key])
            attributes[key] = value if value is not None else {
                "unserialised": type(h[key]).__name__}
        parts.append({
            "index": part.part_index,
            "name": name if isinstance(name, str) else None,
            "view": h.get("view") if isinstance(h.get("view"), str) else None,
            "data_window": _window(h["dataWindow"]),
            "display_window": _window(h["displayWindow"]),
            "channels": channels,
            "attributes": attributes,
        })
    doc = {"file": str(path), "parts": parts}
    if read_error is not None:
        doc["pixel_read_error"] = read_error
    return doc


def _rgb_layers(exr):
    """[(part index, part name or None, prefix, {R,G,B[,A]: channel name})] in file order."""
    layers = []
    for part in exr.parts:
        pname = part.header.get("name")
        pname = pname if isinstance(pname, str) and pname else None
        names = list(part.channels)
        for n in names:
            if n == "R":
                prefix = ""
            elif n.endswith(".R"):
                prefix = n[:-2]
            else:
                continue
            full = {c: (f"{prefix}.{c}" if prefix else c) for c in "RGBA"}
            if all(full[c] in part.channels for c in "RGB"):
                chans = {c: full[c] for c in "RGB"}
                if full["A"] in part.channels:
                    chans["A"] = full["A"]
                layers.append((part.part_index, pname, prefix, chans))
    return layers


def _layer_label(layer):
    _, pname, prefix, _ = layer
    label = prefix if prefix else "(R, G, B)"
    return f"{pname}:{label}" if pname else label


def choose_layer(exr, path, want=None):
    layers = _rgb_layers(exr)
    if not layers:
        raise OracleError(f"{path}: no RGB layer (R, G, B channels) in any part")
    if want is not None:
        want = want.rstrip(".")
        for layer in layers:
            _, pname, prefix, _ = layer
            qualified = f"{pname}.{prefix}" if pname and prefix else (pname or "")
            if want == prefix or (pname and want == qualified):
                return layer
        raise OracleError(f"{path}: no RGB layer {want!r} (has: "
                          f"{', '.join(_layer_label(l) for l in layers)})")
    bare = [l for l in layers if l[2] == ""]
    if bare:
        return bare[0]
    if len(layers) == 1:
        return layers[0]
    combined = [l for l in layers if l[2].endswith("Combined")]
    if len(combined) == 1:
        return combined[0]
    raise OracleError(f"{path}: several RGB layers ({', '.join(_layer_label(l) for l in layers)});"
                      " choose one with --layer")


def _plane(path, part, name, data_window):
    ch = part.channels[name]
    if ch.xSampling != 1 or ch.ySampling != 1:
        raise OracleError(f"{path}: channel {name} is subsampled "
                          f"({ch.xSampling}×{ch.ySampling}); not supported")
    width = data_window[2] - data_window[0] + 1
    height = data_window[3] - data_window[1] + 1
    pixels = np.asarray(ch.pixels)
    if pixels.shape != (height, width):
        raise OracleError(f"{path}: channel {name} has shape {pixels.shape}, the data window "
                          f"{data_window} is {height}×{width}")
    return pixels.astype(np.float64), _enum_name(ch.type())


class Layer:
    """One RGB layer of a file: windows, planes R, G, B (and A), their pixel types."""

    def __init__(self, path, exr, layer):
        self.path, self.exr, self.layer = path, exr, layer
        self.part = exr.parts[layer[0]]
        h = self.part.header
        self.part_name = layer[1]
        self.prefix = layer[2]
        self.data_window = _window(h["dataWindow"])
        self.display_window = _window(h["displayWindow"])
        self.label = _layer_label(layer)
        self.planes, self.types = {}, {}
        for c, name in layer[3].items():
            self.planes[c], self.types[c] = _plane(path, self.part, name, self.data_window)


def read_layer(path, want=None, like=None):
    """The RGB layer `want` (see choose_layer), or with `like` (a Layer of another file) the layer
    of the same part name and prefix when this file has it, else the first (bare preferred)."""
    exr = _open(path)
    if like is not None:
        for layer in _rgb_layers(exr):
            if layer[1] == like.part_name and layer[2] == like.prefix:
                return Layer(path, exr, layer)
    return Layer(path, exr, choose_layer(exr, path, want))


# ---------------------------------------------------------------------------------------------
# PNG (8/16-bit grey or RGB(A), non-interlaced; written without filters)


def _png_chunks(data, path):
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise OracleError(f"{path}: not a PNG")
    pos = 8
    while pos + 8 <= len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        yield kind, data[pos + 8:pos + 8 + length]
        pos += 12 + length


def _unfilter(raw, height, stride, bpp, path):
    out = np.zeros((height, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int64)
    row_len = stride + 1
    if len(raw) < height * row_len:
        raise OracleError(f"{path}: PNG data too short")
    for y in range(height):
        ftype = raw[y * row_len]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * row_len + 1)
        line = line.astype(np.int64)
        if ftype == 0:
            cur = line
        elif ftype == 1:  # Sub: cumulative per interleaved sample, modulo 256
            cur = line.copy()
            for i in range(bpp, stride):
                cur[i] = (cur[i] + cur[i - bpp]) & 0xFF
        elif ftype == 2:
            cur = (line + prev) & 0xFF
        elif ftype in (3, 4):
            cur = line.copy()
            for i in range(stride):
                a = int(cur[i - bpp]) if i >= bpp else 0
                b = int(prev[i])
                if ftype == 3:
                    cur[i] = (cur[i] + ((a + b) >> 1)) & 0xFF
                else:
                    c = int(prev[i - bpp]) if i >= bpp else 0
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                    cur[i] = (cur[i] + pred) & 0xFF
        else:
            raise OracleError(f"{path}: PNG row {y} has filter type {ftype}")
        out[y] = cur.astype(np.uint8)
        prev = cur
    return out


def read_png(path):
    """(height, width, channels) array of the PNG's samples as stored (uint8 or uint16)."""
    with open(path, "rb") as f:
        data = f.read()
    ihdr, idat = None, []
    for kind, body in _png_chunks(data, path):
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if ihdr is None:
        raise OracleError(f"{path}: PNG without IHDR")
    width, height, depth, color, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(color)
    if channels is None or depth not in (8, 16) or interlace:
        raise OracleError(f"{path}: unsupported PNG (colour type {color}, {depth}-bit, "
                          f"interlace {interlace})")
    bpp = channels * depth // 8
    raw = zlib.decompress(b"".join(idat))
    rows = _unfilter(raw, height, width * bpp, bpp, path)
    if depth == 16:
        rows = rows.reshape(height, width * channels, 2)
        samples = (rows[..., 0].astype(np.uint16) << 8) | rows[..., 1]
    else:
        samples = rows
    return samples.reshape(height, width, channels)


def _paeth_rows(rgb):
    """The rows of an 8-bit RGB image Paeth-filtered (PNG filter type 4), each led by its
    filter byte."""
    height, width, _ = rgb.shape
    x = rgb.reshape(height, width * 3).astype(np.int16)
    a = np.zeros_like(x)
    a[:, 3:] = x[:, :-3]
    b = np.zeros_like(x)
    b[1:] = x[:-1]
    c = np.zeros_like(x)
    c[1:, 3:] = x[:-1, :-3]
    p = a + b - c
    pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
    pred = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
    raw = np.empty((height, 1 + width * 3), dtype=np.uint8)
    raw[:, 0] = 4
    raw[:, 1:] = ((x - pred) % 256).astype(np.uint8)
    return raw


def write_png_rgb8(path, rgb, paeth=False):
    """An 8-bit RGB PNG, no colour chunks (masks are data); rows unfiltered, or with `paeth`
    Paeth-filtered and compressed harder (a rendered picture's noise to about two thirds)."""
    height, width, _ = rgb.shape
    if paeth:
        raw = _paeth_rows(rgb)
    else:
        raw = np.zeros((height, 1 + width * 3), dtype=np.uint8)
        raw[:, 1:] = rgb.reshape(height, width * 3)

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n"
           + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw.tobytes(), 9 if paeth else 6))
           + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(png)


# ---------------------------------------------------------------------------------------------
# subcommands


def cmd_header(args):
    json.dump(header_json(args.file), sys.stdout, indent=1)
    sys.stdout.write("\n")


def _ints(text, n, what):
    try:
        values = [int(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != n:
        raise OracleError(f"{what}: expected {n} comma-separated integers, got {text!r}")
    return values


def cmd_mask_png(args):
    x0, y0, x1, y1 = _ints(args.rect, 4, "--rect")
    if not 1 <= args.id <= 255:
        raise OracleError(f"--id {args.id}: an 8-bit packed mask holds ids 1-255")
    exr = _open(args.like, header_only=True)
    disp = _window(exr.parts[0].header["displayWindow"])
    width, height = disp[2] - disp[0] + 1, disp[3] - disp[1] + 1
    if width <= 0 or height <= 0:
        raise OracleError(f"{args.like}: empty display window {disp}")
    rgb = np.zeros((height, width, 3), dtype=np.uint8)
    xa, xb = max(x0, 0), min(x1, width - 1)
    ya, yb = max(y0, 0), min(y1, height - 1)
    if xa <= xb and ya <= yb:
        rgb[ya:yb + 1, xa:xb + 1, 1] = args.id
        rgb[ya:yb + 1, xa:xb + 1, 2] = 255
    write_png_rgb8(args.out, rgb)
    json.dump({"mask": str(args.out), "width": width, "height": height,
               "display_window": disp, "glass_pixels": int((rgb[..., 1] != 0).sum())},
              sys.stdout)
    sys.stdout.write("\n")


def _curve_at_normal(curve):
    """C(cos θ = 1) = Σ c_k · 1^p_k."""
    return float(sum(float(c) for c, _ in zip(curve["coefficients"], curve["powers"])))


def registry_table(doc, registry, space=None):
    """The glasses of one table: schema 3's table whose colorimetric space is `space` (default
    the first table), or schema 2's only table."""
    if "tables" not in doc:
        return doc.get("glasses", [])
    tables = doc["tables"]
    if space is None:
        return tables[0]["glasses"]
    for table in tables:
        if table["spectral"].get("method") == "colorimetric" and \
                table["spectral"].get("space", "srgb") == space:
            return table["glasses"]
    raise OracleError(f"{registry}: no table in {space}")


def registry_gain(registry, glass_id, space=None):
    with open(registry, encoding="utf-8") as f:
        doc = json.load(f)
    for glass in registry_table(doc, registry, space):
        if glass.get("id") == glass_id:
            return [float(glass["r0"][c]) * _curve_at_normal(glass["c_r"][c])
                    + float(glass["t0"][c]) * _curve_at_normal(glass["c_t"][c])
                    for c in range(3)]
    raise OracleError(f"{registry}: no glass with id {glass_id}")


def cmd_gain(args):
    print(",".join(repr(g) for g in registry_gain(args.registry, args.id, args.space)))


# colour-science's names of the spaces glassdb names.
COLOUR_SPACES = {"srgb": "sRGB", "rec2020": "ITU-R BT.2020", "acescg": "ACEScg",
                 "aces2065-1": "ACES2065-1", "display-p3": "Display P3"}


def cmd_check_display(args):
    """The PNG is the EXR's RGB (un-premultiplied where alpha > 0), converted from --space to
    linear sRGB by colour-science's RGB_to_RGB (CAT02), sRGB-encoded, clipped to 0-1 and
    quantised to the PNG's depth; within --tol codes."""
    import colour
    colour.utilities.filter_warnings(colour_runtime_warnings=True, colour_usage_warnings=True)
    src = read_layer(args.exr, args.layer)
    rgb = np.stack([src.planes[c] for c in "RGB"], axis=-1)
    if "A" in src.planes:
        a = src.planes["A"][..., None]
        rgb = np.where(a > 0, rgb / np.where(a > 0, a, 1.0), rgb)
    if args.space != "srgb":
        rgb = colour.RGB_to_RGB(rgb, COLOUR_SPACES[args.space], "sRGB",
                                chromatic_adaptation_transform="CAT02")
    encoded = np.clip(colour.models.eotf_inverse_sRGB(np.clip(rgb, 0.0, None)), 0.0, 1.0)
    png = read_png(args.png)
    top = 65535.0 if png.dtype == np.uint16 else 255.0
    if png.shape[:2] != encoded.shape[:2]:
        raise Mismatch(f"{args.png} is {png.shape[1]}×{png.shape[0]}, {args.exr}'s layer is "
                       f"{encoded.shape[1]}×{encoded.shape[0]}")
    diff = np.abs(png[..., :3].astype(np.float64) - encoded * top)
    worst = float(diff.max())
    y, x, c = np.unravel_index(int(diff.argmax()), diff.shape)
    summary = {"max_code_diff": worst, "at": [int(x), int(y), "RGB"[c]],
               "mean_code_diff": float(diff.mean())}
    print(json.dumps(summary))
    if worst > args.tol:
        raise Mismatch(f"{args.png} pixel (x {x}, y {y}) channel {'RGB'[c]}: {worst:.2f} codes "
                       f"from colour-science's {args.space} → sRGB (tolerance {args.tol})")


def _ulp_half(values):
    """Half a unit in the last place of binary16 at |values| (2^-25 in the subnormal range)."""
    mag = np.abs(values)
    with np.errstate(divide="ignore"):
        exp = np.floor(np.log2(np.where(mag > 0, mag, 1.0)))
    exp = np.maximum(exp, -14.0)
    return np.ldexp(0.5, (exp - 10).astype(np.int64))


def _ulp_float(values):
    return np.abs(np.spacing(np.abs(values).astype(np.float32)).astype(np.float64)) * 0.5


def cmd_check_composite(args):
    gain = [float(g) for g in args.gain.split(",")]
    if len(gain) != 3:
        raise OracleError(f"--gain: expected R,G,B, got {args.gain!r}")
    src = read_layer(args.input, args.layer)
    dst = read_layer(args.output, like=src)
    in_dw, in_disp, inp, in_label = src.data_window, src.display_window, src.planes, src.label
    out_dw, out_disp, out, out_types = dst.data_window, dst.display_window, dst.planes, dst.types
    out_label = dst.label
    if out_disp != in_disp:
        raise Mismatch(f"display window: output {out_disp}, input {in_disp} (layer {in_label})")
    if out_dw != in_dw:
        raise Mismatch(f"data window: output {out_dw} (layer {out_label}), input {in_dw} (layer "
                       f"{in_label}; display window {in_disp})")
    height, width = inp["R"].shape

    mask = read_png(args.mask)
    mh, mw = mask.shape[:2]
    disp_w, disp_h = in_disp[2] - in_disp[0] + 1, in_disp[3] - in_disp[1] + 1
    notes = []
    if (mw, mh) != (disp_w, disp_h):
        notes.append(f"mask is {mw}×{mh}, display window {disp_w}×{disp_h}")
    if mask.shape[2] < 3:
        raise OracleError(f"{args.mask}: not an RGB mask")
    full = 255 if mask.dtype == np.uint8 else 65535
    # The mask's pixel (mx, my) is EXR pixel (mx + dispxmin, my + dispymin).
    glass = np.zeros((height, width), dtype=bool)
    ids = np.zeros((height, width), dtype=np.int64)
    x_lo = max(in_dw[0], in_disp[0])
    x_hi = min(in_dw[2], in_disp[0] + mw - 1)
    y_lo = max(in_dw[1], in_disp[1])
    y_hi = min(in_dw[3], in_disp[1] + mh - 1)
    if x_lo <= x_hi and y_lo <= y_hi:
        sub = mask[y_lo - in_disp[1]:y_hi - in_disp[1] + 1, x_lo - in_disp[0]:x_hi - in_disp[0] + 1]
        sl = (slice(y_lo - in_dw[1], y_hi - in_dw[1] + 1),
              slice(x_lo - in_dw[0], x_hi - in_dw[0] + 1))
        on = sub[..., 1] != 0
        glass[sl] = on
        ids[sl] = sub[..., 1]
        if np.any(on & (sub[..., 2] != full)):
            raise OracleError(f"{args.mask}: glass pixels with B != {full}; check-composite "
                              "assumes cos θ = 1 on glass")
        if np.any(on & (sub[..., 0] != 0)):
            raise OracleError(f"{args.mask}: glass pixels on a plane other than 0")
    distinct = np.unique(ids[glass])
    if len(distinct) > 1:
        raise OracleError(f"{args.mask}: several glass ids {distinct.tolist()} in the data window; "
                          "--gain is for one")

    channels = ["R", "G", "B"] + (["A"] if "A" in inp else [])
    if "A" in inp and "A" not in out:
        raise Mismatch(f"the input layer {in_label} has alpha, the output ({out_label}) has none")
    summary = {
        "input_layer": in_label, "output_layer": out_label,
        "data_window": in_dw, "display_window": in_disp,
        "pixels_checked": int(height * width), "glass_pixels": int(glass.sum()),
        "glass_ids": distinct.tolist(), "gain": gain, "rtol": args.rtol,
        "output_types": out_types, "channels_checked": channels,
        "max_abs_error": {}, "max_rel_error": {}, "notes": notes,
    }
    failures = []
    for k, c in enumerate(channels):
        sample = inp[c]
        want = np.where(glass, sample * gain[k], sample) if c != "A" else sample
        got = out[c]
        ulp = _ulp_half(want) if out_types.get(c) == "HALF" else _ulp_float(want)
        allowed = args.rtol * np.abs(want) + ulp
        both_nan = np.isnan(want) & np.isnan(got)
        same_inf = np.isinf(want) & (want == got)
        with np.errstate(invalid="ignore"):
            err = np.abs(got - want)
        err = np.where(both_nan | same_inf, 0.0, err)
        err = np.where(np.isnan(err), np.inf, err)
        bad = err > allowed
        finite = np.isfinite(want) & (np.abs(want) > 0)
        rel = np.where(finite, err / np.where(finite, np.abs(want), 1.0), 0.0)
        summary["max_abs_error"][c] = float(err.max()) if err.size else 0.0
        summary["max_rel_error"][c] = float(rel.max()) if rel.size else 0.0
        if bad.any():
            ys, xs = np.nonzero(bad)
            y, x = int(ys[0]), int(xs[0])
            failures.append(
                f"channel {c}: {int(bad.sum())} samples off (glass: {int((bad & glass).sum())}); "
                f"first at EXR pixel ({x + in_dw[0]}, {y + in_dw[1]}) "
                f"{'on glass' if glass[y, x] else 'off glass'}: got {float(got[y, x])!r}, "
                f"want {float(want[y, x])!r} (input {float(sample[y, x])!r}, "
                f"allowed ±{float(allowed[y, x]):.3g})")
    kept, other_notes = _check_other_channels(src, dst, failures)
    summary["other_channels_checked"] = kept
    summary["notes"].extend(other_notes)
    json.dump(summary, sys.stdout)
    sys.stdout.write("\n")
    if failures:
        raise Mismatch("; ".join(failures))


def _check_other_channels(src, dst, failures):
    """Channels of the input outside the composited layer that the output also has outside its
    composited layer (same part name, or same index for unnamed parts, same channel name) must
    hold the same values. Returns
    (how many were compared, notes)."""
    compared, notes = 0, []
    layer_channels = set(src.layer[3].values())
    out_layer_channels = set(dst.layer[3].values())
    if (src.part_name, src.prefix) != (dst.part_name, dst.prefix):
        notes.append(f"the composite of input layer {src.label} is output layer {dst.label}")
    out_parts = {}
    for part in dst.exr.parts:
        name = part.header.get("name")
        out_parts[name if isinstance(name, str) and name else part.part_index] = part
    for part in src.exr.parts:
        name = part.header.get("name")
        key = name if isinstance(name, str) and name else part.part_index
        if len(src.exr.parts) == 1 and len(dst.exr.parts) == 1:
            other = dst.exr.parts[0]
        else:
            other = out_parts.get(key)
        if other is None:
            notes.append(f"input part {key} not in the output")
            continue
        dw_in = _window(part.header["dataWindow"])
        dw_out = _window(other.header["dataWindow"])
        for ch_name in part.channels:
            if part.part_index == src.layer[0] and ch_name in layer_channels:
                continue
            if other.part_index == dst.layer[0] and ch_name in out_layer_channels:
                continue  # the output's composited layer, checked above
            if ch_name not in other.channels:
                notes.append(f"channel {ch_name} of part {key} not in the output")
                continue
            if dw_in != dw_out:
                notes.append(f"part {key}: data window {dw_out} in the output, {dw_in} in the "
                             "input; its other channels not compared")
                break
            a, _ = _plane(src.path, part, ch_name, dw_in)
            b, b_type = _plane(dst.path, other, ch_name, dw_out)
            ulp = _ulp_half(a) if b_type == "HALF" else 0.0
            with np.errstate(invalid="ignore"):
                err = np.abs(a - b)
            same = (err <= ulp) | (np.isnan(a) & np.isnan(b)) | (np.isinf(a) & (a == b))
            compared += 1
            if not same.all():
                ys, xs = np.nonzero(~same)
                y, x = int(ys[0]), int(xs[0])
                failures.append(
                    f"channel {ch_name} of part {key} (not composited) changed at "
                    f"{int((~same).sum())} pixels; first at EXR pixel ({x + dw_in[0]}, "
                    f"{y + dw_in[1]}): got {float(b[y, x])!r}, input {float(a[y, x])!r}")
    return compared, notes


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("header", help="JSON description of every part of an EXR")
    p.add_argument("file")
    p.set_defaults(func=cmd_header)
    p = sub.add_parser("check-composite", help="check compose --trans IN --refl IN on a mask")
    p.add_argument("--input", required=True)
    p.add_argument("--output", required=True)
    p.add_argument("--mask", required=True)
    p.add_argument("--gain", required=True, help="R,G,B: r + t at cos θ = 1")
    p.add_argument("--layer", default=None, help="RGB layer prefix of the input")
    p.add_argument("--rtol", type=float, default=2e-3)
    p.set_defaults(func=cmd_check_composite)
    p = sub.add_parser("mask-png", help="8-bit packed mask with one glass rectangle")
    p.add_argument("--like", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--rect", required=True, help="x0,y0,x1,y1 (display-window-relative)")
    p.add_argument("--id", type=int, required=True)
    p.set_defaults(func=cmd_mask_png)
    p = sub.add_parser("gain", help="per-channel r + t at normal incidence from a registry")
    p.add_argument("--registry", required=True)
    p.add_argument("--id", type=int, required=True)
    p.add_argument("--space", default=None, help="the table in this colorimetric space")
    p.set_defaults(func=cmd_gain)
    p = sub.add_parser("check-display", help="a standard-view PNG against colour-science")
    p.add_argument("--exr", required=True)
    p.add_argument("--png", required=True)
    p.add_argument("--space", required=True, choices=list(COLOUR_SPACES))
    p.add_argument("--layer", default=None)
    p.add_argument("--tol", type=float, default=1.5)
    p.set_defaults(func=cmd_check_display)
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except Mismatch as e:
        print(f"exr_oracle: MISMATCH: {e}", file=sys.stderr)
        return 1
    except OracleError as e:
        print(f"exr_oracle: error: {e}", file=sys.stderr)
        return 2
    except Exception:  # a bug here or an input the bindings choke on: not a verdict on compose
        import traceback
        traceback.print_exc()
        print("exr_oracle: internal error (see the traceback above)", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
