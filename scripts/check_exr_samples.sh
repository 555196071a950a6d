#!/usr/bin/env bash
# Runs compose over OpenEXR's sample images and checks every composite with an independent reader
# (python_oracle/exr_oracle.py: OpenEXR's own Python bindings).
#
# Usage: scripts/check_exr_samples.sh DIR [COMPOSE_BIN] [--report FILE] [--id N]
#            [--registry REG.json] [--keep DIR] [--note TEXT] [--default-layer-only]
#   DIR          a copy of the openexr-images repository (its folders ScanLines, Tiles,
#                MultiResolution, MultiView, DisplayWindow, Beachball are used)
#   COMPOSE_BIN  default target/release/compose
#   --report     markdown report to write (default docs/exr-samples.md)
#   --id         glass id of the mask rectangle (default 5: a tinted glass, so R, G, B gains
#                differ); --registry: default data/registry.json
#   --keep       keep the masks, composites and logs there (default: a temporary folder, removed)
#   --note       text added to the report's first line (e.g. which build of compose was used)
#   --default-layer-only  one compose run per file; by default a file with several RGB layers
#                (parts, views) also gets one run per layer with `--layer NAME` (compose's name:
#                part name, then channel prefix), each a row of its own
# Python: $GLASSDB_PYTHON, else .venv/bin/python (scripts/test-all installs it), with OpenEXR.
#
# Per file: a mask the size of the display window (glass id N at cos θ = 1 on the middle third in
# x and y of the display window, or of its overlap with the data window when that is smaller),
# `compose --trans F --refl F --mask M --registry REG -o OUT.exr --data-type float`
# (bounded by `timeout 120`), then on success `exr_oracle.py check-composite` (on glass
# out = in·(r0 + t0), elsewhere out = in, windows kept), on failure its exit code and first error
# line. Exit status: 1 if any composite is WRONG, compose crashed (exit >= 101, a signal,
# "panicked" on stderr) or timed out, or the oracle could not read a file; refusals are fine.
set -uo pipefail

usage() { sed -n '2,/^set -uo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//' >&2; exit 2; }

REPO="$(cd "$(dirname "$0")/.." && pwd)"
DIR="" BIN="" REPORT="$REPO/docs/exr-samples.md" GLASS_ID=5 REGISTRY="$REPO/data/registry.json"
KEEP="" NOTE="" EACH_LAYER=1
abs() { case "$1" in /*) printf '%s' "$1" ;; *) printf '%s/%s' "$PWD" "$1" ;; esac; }
while [ $# -gt 0 ]; do
    case "$1" in
        --report) REPORT="$(abs "$2")"; shift 2 ;;
        --id) GLASS_ID="$2"; shift 2 ;;
        --registry) REGISTRY="$(abs "$2")"; shift 2 ;;
        --keep) KEEP="$(abs "$2")"; shift 2 ;;
        --note) NOTE="$2"; shift 2 ;;
        --default-layer-only) EACH_LAYER=0; shift ;;
        -h|--help) usage ;;
        -*) echo "unknown option $1" >&2; usage ;;
        *) if [ -z "$DIR" ]; then DIR="$(abs "$1")"; elif [ -z "$BIN" ]; then BIN="$(abs "$1")"
           else usage; fi
           shift ;;
    esac
done
[ -n "$DIR" ] || usage
BIN="${BIN:-$REPO/target/release/compose}"
[ -d "$DIR" ] || { echo "no folder $DIR" >&2; exit 2; }
[ -x "$BIN" ] || { echo "no compose binary $BIN (cargo build --release --bin compose)" >&2; exit 2; }
DIR="$(cd "$DIR" && pwd)"
cd "$REPO"
PY="${GLASSDB_PYTHON:-$REPO/.venv/bin/python}"
ORACLE="$REPO/python_oracle/exr_oracle.py"
"$PY" -c 'import OpenEXR, numpy' 2>/dev/null || {
    echo "$PY lacks OpenEXR/numpy: run scripts/test-all (installs .venv) or set GLASSDB_PYTHON" >&2
    exit 2
}

if [ -n "$KEEP" ]; then
    mkdir -p "$KEEP" && WORK="$(cd "$KEEP" && pwd)"
else
    WORK="$(mktemp -d)"
    trap 'rm -rf "$WORK"' EXIT
fi

GAIN="$("$PY" "$ORACLE" gain --registry "$REGISTRY" --id "$GLASS_ID")" || exit 2
GLASS_NAME="$("$PY" -c 'import json,sys
for g in json.load(open(sys.argv[1]))["glasses"]:
    if g["id"] == int(sys.argv[2]): print(g["name"])' "$REGISTRY" "$GLASS_ID")"
VERSION="$("$BIN" --version 2>/dev/null | head -n 1)"
COMMIT="$(git -C "$REPO" rev-parse --short HEAD 2>/dev/null || echo unknown)"
DIRTY="$(git -C "$REPO" status --porcelain --untracked-files=no 2>/dev/null | grep -q . && echo ", uncommitted changes in the tree")"

# One table row's descriptive cells from the oracle's header JSON:
# "size|parts/layers|windows|W|H|x0,y0,x1,y1" (the rectangle: the middle third, display-relative).
describe() {
    "$PY" - "$1" <<'EOF'
import json, sys
doc = json.load(open(sys.argv[1]))
parts = doc["parts"]
def win(w):
    return f"({w[0]}, {w[1]})–({w[2]}, {w[3]})"
def layers(part):
    names = [c["name"] for c in part["channels"]]
    out = []
    for n in names:
        pre = "" if n == "R" else (n[:-2] if n.endswith(".R") else None)
        if pre is None:
            continue
        if all((f"{pre}.{c}" if pre else c) in names for c in "GB"):
            out.append(pre or "RGB")
    other = [n for n in names if n.split(".")[-1] not in "RGBA"]
    text = ", ".join(out) if out else "no RGB"
    if other:
        text += f" + {len(other)} other ch." if len(other) > 3 else " + " + ", ".join(other)
    return text
disp = parts[0]["display_window"]
w, h = disp[2] - disp[0] + 1, disp[3] - disp[1] + 1
p0 = parts[0]
attrs = p0["attributes"]
kind = "tiled" if attrs.get("type") == "tiledimage" or "tiles" in attrs else "scanline"
tiles = attrs.get("tiles")
if isinstance(tiles, dict) and tiles.get("mode") not in (None, "ONE_LEVEL"):
    kind += ", " + tiles["mode"].replace("_LEVELS", "").lower()
ctype = sorted({c["type"] or "?" for p in parts for c in p["channels"]})
size = f"{w}×{h}, {kind}, {'/'.join(t.lower() for t in ctype)}"
if len(parts) == 1:
    pl = "1 part"
    if p0["name"]:
        pl += f" named {p0['name']}"
    pl += ": " + layers(p0)
    if "multiView" in attrs:
        pl += "; views " + ", ".join(attrs["multiView"])
else:
    rgb = [p for p in parts if not layers(p).startswith("no RGB")]
    rest = [p for p in parts if p not in rgb]
    def pname(p):
        return (p["name"] or "#" + str(p["index"])) + (f" (view {p['view']})" if p["view"] else "")
    pl = f"{len(parts)} parts; with RGB: " + ", ".join(
        f"{pname(p)} = {layers(p)}" for p in rgb) if rgb else f"{len(parts)} parts; no RGB"
    if rest:
        pl += "; others: " + ", ".join(pname(p) for p in rest)
dws = {tuple(p["data_window"]) for p in parts}
disps = {tuple(p["display_window"]) for p in parts}
if len(parts) == 1 and tuple(p0["data_window"]) == tuple(disp):
    wins = f"equal {win(disp)}"
elif len(parts) == 1:
    wins = f"data {win(p0['data_window'])}, display {win(disp)}"
else:
    same = "equal in every part" if all(
        tuple(p["data_window"]) == tuple(p["display_window"]) for p in parts) else None
    wins = same + f" {win(disp)}" if same else (
        f"data {', '.join(win(d) for d in sorted(dws))}; display "
        f"{', '.join(win(d) for d in sorted(disps))}")
# The glass rectangle: the middle third of the display window, or where the RGB part's data
# window covers only part of the display window, the middle third of their overlap (so that
# glass lands on stored pixels); display-window-relative, inclusive.
rgb_parts = [p for p in parts if not layers(p).startswith("no RGB")] or parts
dw = rgb_parts[0]["data_window"]
box = [max(dw[0], disp[0]), max(dw[1], disp[1]), min(dw[2], disp[2]), min(dw[3], disp[3])]
if box[0] > box[2] or box[1] > box[3]:
    box = disp
bw, bh = box[2] - box[0] + 1, box[3] - box[1] + 1
x0, y0 = box[0] - disp[0] + bw // 3, box[1] - disp[1] + bh // 3
rect = f"{x0},{y0},{x0 + max(0, bw // 3 - 1)},{y0 + max(0, bh // 3 - 1)}"
# compose's names of the RGB layers (in a multi-part file the part name, then the channel
# prefix; a single part's name does not prefix its channels), when there are several
names = []
for p in parts:
    for lay in layers(p).split(" + ")[0].split(", "):
        if lay == "no RGB":
            continue
        pre = "" if lay == "RGB" else lay
        part_name = p["name"] if len(parts) > 1 else None
        names.append(".".join(x for x in (part_name, pre) if x))
several = ",".join(n for n in names if n) if len(names) > 1 else ""
print("|".join(s.replace("|", "\\|") for s in (size, pl, wins, str(w), str(h), rect, several)))
EOF
}

check_summary() {
    "$PY" - "$1" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
rel = max(s["max_rel_error"].values())
extra = ""
if s.get("other_channels_checked"):
    extra += f"; {s['other_channels_checked']} other channels kept unchanged"
dropped = [n for n in s["notes"] if n.endswith("not in the output")]
if dropped:
    extra += f"; {len(dropped)} input channels/parts not in the output"
extra += "".join("; " + n for n in s["notes"] if not n.endswith("not in the output"))
print(f"composited, pixels checked ({s['pixels_checked']}; {s['glass_pixels']} on glass; "
      f"max rel. error {rel:.1e}{extra})")
EOF
}

cell() { tr '\n' ' ' | sed -e "s#$WORK/##g" -e "s#$DIR/##g" -e 's/|/\\|/g' -e 's/ *$//'; }

# Runs compose on "$f" (with --layer $2 if not empty), checks the composite and appends a row
# that starts with $1 to $ROWS.
run_case() {
    local row="$1" layer="$2" t="$tag${2:+.layer_$2}" rc first summary
    local layer_args=()
    [ -n "$layer" ] && layer_args=(--layer "$layer")
    cases=$((cases + 1))
    timeout 120 "$BIN" --trans "$f" --refl "$f" --mask "$tag.mask.png" "${layer_args[@]}" \
        --registry "$REGISTRY" -o "$t.out.exr" --data-type float \
        > "$t.compose.out" 2> "$t.compose.err"
    rc=$?
    first="$(grep -m1 -i 'error' "$t.compose.err" || grep -m1 . "$t.compose.err")"
    if [ $rc -eq 0 ]; then
        if "$PY" "$ORACLE" check-composite --input "$f" --output "$t.out.exr" "${layer_args[@]}" \
                --mask "$tag.mask.png" --gain "$GAIN" > "$t.check.json" 2> "$t.check.err"; then
            ok=$((ok + 1))
            summary="$(check_summary "$t.check.json")"
            echo "$row $summary |" >> "$ROWS"
        elif grep -q '^exr_oracle: MISMATCH' "$t.check.err"; then
            wrong=$((wrong + 1))
            echo "$row WRONG: $(grep -m1 '^exr_oracle: MISMATCH' "$t.check.err" \
                | sed 's/^exr_oracle: MISMATCH: //' | cut -c1-400 | cell) |" >> "$ROWS"
        else
            oracle_err=$((oracle_err + 1))
            echo "$row ORACLE ERROR: check: $({ grep -m1 '^exr_oracle' "$t.check.err" \
                || grep -m1 . "$t.check.err"; } | cell) |" >> "$ROWS"
        fi
    elif [ $rc -eq 124 ]; then
        crashed=$((crashed + 1))
        echo "$row CRASH: timed out after 120 s |" >> "$ROWS"
    elif [ $rc -ge 101 ] || grep -q 'panicked' "$t.compose.err"; then
        crashed=$((crashed + 1))
        echo "$row CRASH: exit $rc: $(printf '%s' "$first" | cut -c1-300 | cell) |" >> "$ROWS"
    else
        refused=$((refused + 1))
        echo "$row refused (exit $rc): $(printf '%s' "$first" | cut -c1-300 | cell) |" >> "$ROWS"
    fi
}

ROWS="$WORK/rows.md"
: > "$ROWS"
n=0 cases=0 ok=0 refused=0 wrong=0 crashed=0 oracle_err=0
MISSING=()
for sub in ScanLines Tiles MultiResolution MultiView DisplayWindow Beachball; do
    [ -d "$DIR/$sub" ] || { MISSING+=("$sub/ (folder)"); continue; }
    for jpg in "$DIR/$sub"/*.jpg; do
        [ -e "$jpg" ] && [ ! -e "${jpg%.jpg}.exr" ] && MISSING+=("$sub/$(basename "${jpg%.jpg}").exr")
    done
    for f in "$DIR/$sub"/*.exr; do
        [ -e "$f" ] || continue
        n=$((n + 1))
        rel="$sub/$(basename "$f")"
        tag="$WORK/${sub}_$(basename "$f" .exr)"
        echo "== $rel" >&2
        if ! "$PY" "$ORACLE" header "$f" > "$tag.header.json" 2> "$tag.header.err"; then
            oracle_err=$((oracle_err + 1))
            echo "| $rel | ? | ? | ? | ORACLE ERROR: header: $(head -n 3 "$tag.header.err" | cell) |" >> "$ROWS"
            continue
        fi
        IFS='|' read -r size layers wins W H rect several < <(describe "$tag.header.json" | sed 's/\\|/\x01/g')
        restore() { printf '%s' "$1" | sed 's/\x01/\\|/g'; }
        size="$(restore "$size")" layers="$(restore "$layers")" wins="$(restore "$wins")"
        row="| $rel | $size | $layers | $wins |"
        if ! "$PY" "$ORACLE" mask-png --like "$f" --out "$tag.mask.png" --rect "$rect" \
                --id "$GLASS_ID" > "$tag.mask.json" 2> "$tag.mask.err"; then
            oracle_err=$((oracle_err + 1))
            echo "$row ORACLE ERROR: mask: $(head -n 3 "$tag.mask.err" | cell) |" >> "$ROWS"
            continue
        fi
        run_case "$row" ""
        if [ -n "$several" ] && [ "$EACH_LAYER" = 1 ]; then
            IFS=',' read -r -a each <<< "$several"
            for layer in "${each[@]}"; do
                run_case "| $rel \`--layer $layer\` | ″ | ″ | ″ |" "$layer"
            done
        fi
    done
done

SUMMARY="$n files, $cases compose runs: $ok composited and checked, $refused refused, $wrong WRONG, $crashed crashed, $oracle_err oracle errors"
{
    echo "# compose on OpenEXR's sample images"
    echo
    echo "Made by \`scripts/check_exr_samples.sh\` (${VERSION:-compose ?}, glassdb $COMMIT$DIRTY${NOTE:+; $NOTE})."
    echo "Each file is composited with itself as both passes, \`compose --trans F --refl F --mask M"
    echo "--registry ${REGISTRY#"$REPO"/} -o OUT.exr --data-type float\` (and for files with several RGB"
    echo "layers also once per layer with \`--layer NAME\`), where M is an 8-bit packed mask the size"
    echo "of the display window with glass id $GLASS_ID ($GLASS_NAME) at cos θ = 1 on the middle"
    echo "third (x and y) of the display window, or of its overlap with the data window where that"
    echo "is smaller (the display window when they do not overlap); the composite is checked by"
    echo "\`python_oracle/exr_oracle.py check-composite\` (OpenEXR's Python bindings): on glass"
    echo "out = in·(r0 + t0) = in·($GAIN) per channel, elsewhere out = in, over the input's data"
    echo "window in absolute pixel coordinates, the output keeping the input's data and display"
    echo "windows. Windows are inclusive (xmin, ymin)–(xmax, ymax)."
    echo
    echo "| file | size | parts / layers | data window vs display window | result |"
    echo "|---|---|---|---|---|"
    cat "$ROWS"
    echo
    echo "$SUMMARY."
    if [ ${#MISSING[@]} -gt 0 ]; then
        echo
        echo "Not in this copy of the samples (a preview .jpg without its .exr): ${MISSING[*]}."
    fi
} > "$REPORT.tmp" && mv "$REPORT.tmp" "$REPORT"
cat "$REPORT"
echo "$SUMMARY" >&2
[ $wrong -eq 0 ] && [ $crashed -eq 0 ] && [ $oracle_err -eq 0 ]
