#!/usr/bin/env bash
# Regenerates the numbers of docs/blender.md "Light groups" (issue 29, validation item 3): the
# `relit` scene with its own light groups (two suns and the world in `sun`, a warm bulb and
# area lamp inside in `warm`; scripts/blender/make_light_groups_scene.py), frames 1 (inside,
# the warm room reflected in both windows) and 2 (outside, the warm room seen through them),
# rendered by `glassdb blender render --light sun=D65 --light warm=A --reference`, seeds 0 and
# 1, with a registry of the two lights (each group composited with its light's table; the
# Cycles reference rendered once per group with the glass of its light) and with the bundled
# one-light registry (today's one-group pipeline against its one-table reference);
# scripts/blender_groups_validation.py prints the table.
#
#     scripts/blender_groups_validation.sh [OUT_DIR] [SAMPLES] [WxH]
#         (default target/blender-groups 32 128x96)
#
# Needs Blender 3.4+ on PATH and the project's .venv (numpy, OpenEXR).
source "$(dirname "$0")/blender_common.sh"
OUT=${1:-target/blender-groups}
SAMPLES=${2:-32}
SIZE=${3:-128x96}
prepare_scene_validation debug relit
nice blender -b "$OUT/relit.blend" --python-exit-code 1 \
    -P scripts/blender/make_light_groups_scene.py -- --out "$OUT/groups.blend" >> "$OUT/scene.log" 2>&1
"$G" registry build data/catalog.toml -o "$OUT/lights.json" --light sun=D65 --light warm=A > /dev/null
for variant in groups one; do
    registry=()
    [ "$variant" = groups ] && registry=(--registry "$OUT/lights.json")
    for seed in 0 1; do
        rm -rf "$OUT/$variant/seed$seed"
        nice "$G" blender render "$OUT/groups.blend" --glass Glass_clear=1 --glass 'Tinted*=5' \
            --out-dir "$OUT/$variant/seed$seed" --samples "$SAMPLES" --resolution "$SIZE" \
            --seed "$seed" --threads 2 --reference --light sun=D65 --light warm=A \
            "${registry[@]}" > "$OUT/$variant.seed$seed.txt"
    done
done
.venv/bin/python scripts/blender_groups_validation.py "$OUT"
