#!/usr/bin/env bash
# `glassdb blender render --bpy-python` against Debian's Blender 3.4 on the tiny test scene
# (docs/blender.md, "Supported"): both render it (seed 0, SAMPLES samples, --reference); prints
# whether the exported OBJ, planes and masks are the same, and each composite's PSNR against its
# own Blender's reference (oiiotool --diff, R, G, B, A), and the two references' against each other.
#   scripts/blender_bpy_check.sh /path/to/venv-with-bpy/bin/python [WORKDIR] [SAMPLES]
# Needs blender, oiiotool and a Python with the `bpy` wheel (e.g. pip install bpy==4.2.0).
set -euo pipefail
cd "$(dirname "$0")/.."
BPY_PYTHON=${1:?usage: $0 PYTHON_WITH_BPY [WORKDIR] [SAMPLES]}
W=${2:-$(mktemp -d "${TMPDIR:-/tmp}/glassdb-bpy.XXXXXX")}
SAMPLES=${3:-64}
cargo build --quiet --release --bin glassdb
G=${CARGO_TARGET_DIR:-target}/release/glassdb
mkdir -p "$W"
blender -b --factory-startup -noaudio --python-exit-code 1 -P scripts/blender/make_glassdb_scene.py \
    -- --scene tiny --out "$W/tiny.blend" --facts "$W/facts.json" --index "$W/index" >/dev/null
for who in blender bpy; do
    extra=()
    [ "$who" = bpy ] && extra=(--bpy-python "$BPY_PYTHON")
    "$G" blender render "$W/tiny.blend" --glass Glass_clear=1 --glass 'Tinted*=5' \
        --out-dir "$W/$who" --reference --threads 2 --seed 0 --samples "$SAMPLES" "${extra[@]}" >/dev/null
done
for who in blender bpy; do
    python3 -c 'import json, sys; print(sys.argv[2], "Blender", ".".join(map(str, json.load(open(sys.argv[1]))["blender_version"])))' \
        "$W/$who/export.json" "$who"
done
cmp -s "$W/blender/scene.obj" "$W/bpy/scene.obj" && echo "scene.obj: identical" || echo "scene.obj: DIFFERS"
diff <(grep -v '"source"' "$W/blender/planes.json") <(grep -v '"source"' "$W/bpy/planes.json") >/dev/null \
    && echo "planes.json: identical but for its source path" || echo "planes.json: DIFFERS"
for f in "$W"/blender/mask.*.exr; do
    n=$(basename "$f")
    echo "$n: $(oiiotool "$f" "$W/bpy/$n" --diff 2>&1 | tail -1)"
done
psnr() { oiiotool "$1" "$2" --diff 2>&1 | awk '/Peak SNR/ { print $4 " dB" }'; }
for c in "$W"/blender/composite.*.exr; do
    n=$(basename "$c")
    r=${n/composite/reference}
    echo "$n against its own Blender's $r: Blender $(psnr "$c" "$W/blender/$r"), bpy $(psnr "$W/bpy/$n" "$W/bpy/$r"); the two references: $(psnr "$W/blender/$r" "$W/bpy/$r")"
done
