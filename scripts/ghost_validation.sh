#!/usr/bin/env bash
# Regenerates the numbers and figure of docs/blender.md, "Units: the double image" (issue 27):
# the double-unit window of scripts/blender/make_ghost_scene.py (256 × 192) rendered by
# `glassdb blender render` with each pane's reflection at its depth (the ghosts) and with
# `--surfaces 1`, and by Cycles directly with the window as two real panes, at equal samples
# (seed 1); the reference is Cycles with the two real panes at many samples (seed 0).
# scripts/ghost_validation.py prints the table and writes docs/figures/blender_ghosts.png.
#
#     [GLASSDB=path/to/glassdb] scripts/ghost_validation.sh [OUT_DIR] [SAMPLES] [REFERENCE_SAMPLES]
#         (default target/ghost-validation 64 1024)
#
# Needs Blender 3.4+ on PATH and the project's .venv (numpy, OpenEXR). About 6 minutes on 2
# shared cores with the defaults (the reference's run renders passes it does not need too).
source "$(dirname "$0")/blender_common.sh"
OUT=${1:-target/ghost-validation}
SAMPLES=${2:-64}
REF_SAMPLES=${3:-1024}
mkdir -p "$OUT"
# GLASSDB: a glassdb binary to use instead of building the release one.
if [ -z "${GLASSDB:-}" ]; then
    build_glassdb release
else
    G=$GLASSDB
fi
for panes in unit two; do
    run_blender_script make_ghost_scene.py --panes "$panes" --size 256x192 \
        --out "$OUT/$panes.blend" --facts "$OUT/$panes.json" > "$OUT/$panes.log" 2>&1
done
run() { # NAME BLEND GLASS ARGS…
    local name=$1 blend=$2 glass=$3
    shift 3
    rm -rf "${OUT:?}/$name"
    nice "$G" blender render "$OUT/$blend" --glass "$glass" --out-dir "$OUT/$name" \
        --threads 2 "$@" | tee "$OUT/$name.txt"
}
run reference two.blend Pane=2 --samples "$REF_SAMPLES" --seed 0 --reference --no-composite
run ghosts unit.blend Unit=11 --samples "$SAMPLES" --seed 1
run surfaces1 unit.blend Unit=11 --samples "$SAMPLES" --seed 1 --surfaces 1
run direct two.blend Pane=2 --samples "$SAMPLES" --seed 1 --reference --no-composite
.venv/bin/python scripts/ghost_validation.py "$OUT" docs/figures/blender_ghosts.png
