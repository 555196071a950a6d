#!/usr/bin/env bash
# Renders the bundled dusk facade (fixtures/dusk/, the README's first command) from
# scripts/blender/make_dusk_facade_scene.py with Debian's Blender 3.4 and `glassdb blender
# render`, and builds its two registries. Writes fixtures/dusk/ (passes, mask, planes.json,
# registry.json, registry_one_table.json); the runs stay in $WORK.
#
#   GLASSDB=target/release/glassdb bash scripts/blender/make_dusk_fixture.sh [SAMPLES] [WxH]
#
# Defaults: 128 samples, 960x540, seed 0, 2 threads. The scene (both light groups) is rendered
# once, by one `glassdb blender render --light sun=D65 --light warm=A --light-split off` run: each
# pass holds the layer `ViewLayer.Combined_<group>` of each of the scene's Cycles light groups,
# and make_dusk_repack.py keeps those layers (and nothing compose does not read) in the fixture.
# Needs: blender (3.4+), the venv's Python with OpenEXR (.venv, or $GLASSDB_PYTHON).
# Licence: same as the project, MIT OR Apache-2.0.
set -euo pipefail
cd "$(dirname "$0")/../.."
GLASSDB=${GLASSDB:-target/release/glassdb}
PY=${GLASSDB_PYTHON:-.venv/bin/python}
SAMPLES=${1:-128}
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

blender -b --factory-startup -noaudio --python-exit-code 1 \
    -P scripts/blender/make_dusk_facade_scene.py -- --out "$WORK/dusk.blend" \
    --size "$SIZE" --samples "$SAMPLES" > "$WORK/scene.log" 2>&1
rm -rf "$WORK/run"
"$GLASSDB" blender render "$WORK/dusk.blend" --glass 'Glass_tinted=14' --glass 'Glass_clear=11' \
    --registry "$OUT/registry.json" --light sun=D65 --light warm=A --light-split off \
    --samples "$SAMPLES" --seed 0 --threads "$THREADS" --no-composite --out-dir "$WORK/run"
"$PY" scripts/blender/make_dusk_repack.py "$OUT" "$WORK/run"
echo "wrote $OUT; the scene: $WORK/dusk.blend, the run: $WORK/run"
