#!/usr/bin/env bash
# Renders the bundled dusk facade (fixtures/dusk/, the README's first command) from
# scripts/blender/make_dusk_facade_scene.py with Debian's Blender 3.4 and `glassdb blender
# render`, and builds its two registries. Writes fixtures/dusk/ (passes, mask, planes.json,
# registry.json, registry_one_table.json); the runs stay in $WORK.
#
#   GLASSDB=target/release/glassdb bash scripts/blender/make_dusk_fixture.sh [SAMPLES] [WxH]
#
# Defaults: 64 samples, 960x540, seed 0, 2 threads; ~20 min of CPU on two cores.
# The scene is rendered once per light group (`--only-group sun`, `--only-group warm`: the other
# group's lamps and emitters off), each a `glassdb blender render --light-split off` run with
# the same seed, and make_dusk_repack.py writes each run's RGB as that group's layer
# `ViewLayer.Combined_<group>` of every pass, the layers Cycles writes for a view layer's light
# groups. Needs: blender (3.4+), the venv's Python with OpenEXR (.venv, or $GLASSDB_PYTHON).
# Licence: same as the project, MIT OR Apache-2.0.
set -euo pipefail
cd "$(dirname "$0")/../.."
GLASSDB=${GLASSDB:-target/release/glassdb}
PY=${GLASSDB_PYTHON:-.venv/bin/python}
SAMPLES=${1:-64}
SIZE=${2:-960x540}
WORK=${WORK:-target/dusk-fixture}
OUT=${OUT:-fixtures/dusk}
THREADS=${THREADS:-2}

mkdir -p "$WORK" "$OUT"
# The registries: one table per light group (sun: D65, warm: tungsten, CIE A), and the one-table
# comparison (D65 for both groups: every pixel composited with the default D65 table). The
# camera is balanced to daylight (--white-balance D65): the scene's tungsten lamps are orange.
"$GLASSDB" registry build "$OUT/catalog.toml" --light sun=D65 --light warm=A \
    --white-balance D65 -o "$OUT/registry.json"
"$GLASSDB" registry build "$OUT/catalog.toml" --light sun=D65 --light warm=D65 \
    --white-balance D65 -o "$OUT/registry_one_table.json"

for group in sun warm; do
    blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P scripts/blender/make_dusk_facade_scene.py -- --out "$WORK/dusk_$group.blend" \
        --size "$SIZE" --samples "$SAMPLES" --only-group "$group" > "$WORK/scene_$group.log" 2>&1
    rm -rf "$WORK/run_$group"
    "$GLASSDB" blender render "$WORK/dusk_$group.blend" --glass 'Glass_tinted=14' \
        --glass 'Glass_clear=11' --registry "$OUT/registry.json" --light-split off \
        --samples "$SAMPLES" --seed 0 --threads "$THREADS" --no-composite \
        --out-dir "$WORK/run_$group"
done
"$PY" scripts/blender/make_dusk_repack.py "$OUT" --group "sun=$WORK/run_sun" --group "warm=$WORK/run_warm"
blender -b --factory-startup -noaudio --python-exit-code 1 \
    -P scripts/blender/make_dusk_facade_scene.py -- --out "$WORK/dusk.blend" \
    --size "$SIZE" --samples "$SAMPLES" > "$WORK/scene.log" 2>&1
echo "wrote $OUT; the scene with both groups: $WORK/dusk.blend"
