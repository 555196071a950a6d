#!/usr/bin/env bash
# Regenerates the validation numbers of docs/blender.md: the example scene (a room with a glazed
# facade, buildings outside, sun and sky, a camera moving over 3 frames, 320 × 240) rendered by
# `glassdb blender render` and by Cycles modelling the glass itself (`--reference`), twice (seeds
# 0 and 1, to measure the noise), then a glass swap (`glassdb blender compose` with other
# glasses) timed with /usr/bin/time -v; scripts/blender_validation.py prints the tables.
#
#     scripts/blender_validation.sh [OUT_DIR] [SAMPLES]     (default target/blender-validation 64)
#
# Needs Blender 3.4+ on PATH, the project's .venv (numpy, OpenEXR) and /usr/bin/time. About
# 4 minutes on 2 shared cores at 64 samples.
source "$(dirname "$0")/blender_common.sh"
OUT=${1:-target/blender-validation}
SAMPLES=${2:-64}
prepare_scene_validation release example
for seed in 0 1; do
    rm -rf "$OUT/seed$seed"
    nice "$G" blender render "$OUT/example.blend" --glass 'Glass_clear=1' --glass 'Tinted*=5' \
        --out-dir "$OUT/seed$seed" --samples "$SAMPLES" --seed "$seed" --threads 2 --reference \
        | tee "$OUT/seed$seed.txt"
    cp "$OUT/seed$seed.txt" "$OUT/seed$seed/run.txt"
done
# A glass swap: the atrium's two glasses (same ids) instead of the bundled catalogue's.
"$G" registry build fixtures/atrium/catalog.toml -o "$OUT/other_glass.json" > /dev/null
rm -rf "$OUT/swap" && cp -r "$OUT/seed0" "$OUT/swap"
/usr/bin/time -v "$G" blender compose "$OUT/swap" --registry "$OUT/other_glass.json" \
    > "$OUT/swap.out" 2> "$OUT/swap.txt"
.venv/bin/python scripts/blender_validation.py "$OUT"
