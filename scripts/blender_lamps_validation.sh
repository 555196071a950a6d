#!/usr/bin/env bash
# Regenerates the numbers of docs/blender.md "Lamps in reflections": the `lamps` scene (a dusk
# facade with a reflective film pane; a warm area lamp, a low sun behind the camera and a bulb
# inside; scripts/blender/make_glassdb_scene.py) rendered by `glassdb blender render
# --reference` with the lamps in the reflection passes (the default) and without
# (--no-lamps-in-reflections), seeds 0 and 1 each; scripts/blender_lamps_validation.py prints
# the table and writes the figure.
#
#     scripts/blender_lamps_validation.sh [OUT_DIR] [SAMPLES] [WxH]
#         (default target/blender-lamps 128 160x120)
#
# Needs Blender 3.4+ on PATH and the project's .venv (numpy, OpenEXR). About 3 minutes on 2
# shared cores at the defaults.
source "$(dirname "$0")/blender_common.sh"
OUT=${1:-target/blender-lamps}
SAMPLES=${2:-128}
SIZE=${3:-160x120}
prepare_scene_validation debug lamps
for variant in with without; do
    extra=()
    [ "$variant" = without ] && extra=(--no-lamps-in-reflections)
    for seed in 0 1; do
        rm -rf "$OUT/$variant/seed$seed"
        nice "$G" blender render "$OUT/lamps.blend" --glass 'Glass_film=10' \
            --out-dir "$OUT/$variant/seed$seed" --samples "$SAMPLES" --resolution "$SIZE" \
            --seed "$seed" --threads 2 --reference "${extra[@]}" > "$OUT/$variant.seed$seed.txt"
    done
done
.venv/bin/python scripts/blender_lamps_validation.py "$OUT" docs/figures/blender_lamps.png
