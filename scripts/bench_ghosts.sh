#!/usr/bin/env bash
# What the double image costs in compose (issue 27; docs/performance.md, "Units: pane-group
# passes"): a frame with PLANES glass windows (one plane each, 6 columns), each plane's
# reflection pass cropped to its window (one file per plane), composited
#   - with monolithic glass (ids 2 and 6): one group, one pass per plane (the baseline);
#   - with the bundled double units (ids 11 and 12): one more cropped pass per plane, its
#     pane group 1 (`--refl-group K.1=FILE`, one file each);
#   - the same units with `--surfaces 1` (one pass per plane, the inner panes folded in).
# Paired whole-process runs: every repetition runs each case once in a fixed order; medians of
# REPEATS, wall clock and peak RSS from /usr/bin/time -v. Goal (issue 27): the double units at
# most 2.1× the time and 1.6× the memory of the one-group frame.
#   SIZES="1280x1024 3840x2160" PLANES=17 REPEATS=5 scripts/bench_ghosts.sh
# Needs GNU time. Prints a Markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."

SIZES=${SIZES:-"1280x1024 3840x2160"}
PLANES=${PLANES:-17}
REPEATS=${REPEATS:-5}
TYPE=${TYPE:-half}
# shellcheck source=scripts/bench_common.sh
. scripts/bench_common.sh
build_compose_and_examples make_plane_bench_inputs
MAKE=$EXAMPLES/make_plane_bench_inputs
make_work_dir glassdb-ghosts

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'); $PLANES planes, $TYPE, ZIP, medians of $REPEATS paired runs; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| size | case | passes | compose (s) | RSS (MiB) | time vs one group | memory vs one group |"
echo "|---|---|---|---|---|---|---|"
for size in $SIZES; do
    w=${size%x*}
    h=${size#*x}
    d="$WORK/$size"
    mapfile -t rects < <("$MAKE" "$d" "$w" "$h" "$TYPE" zip "$PLANES" 2,6)
    "$MAKE" "$d/units" "$w" "$h" "$TYPE" zip "$PLANES" 11,12 >/dev/null
    crops=() groups=()
    for r in "${rects[@]}"; do
        read -r k _ <<<"$r"
        crops+=(--refl "$d/crop_$k.exr")
        groups+=(--refl-group "$k.1=$d/group_$k.exr")
    done
    declare -A runs=()
    for _ in $(seq "$REPEATS"); do
        runs[one]+="$(measure "$COMPOSE" "${crops[@]}" --trans "$d/trans.exr" --mask "$d/mask_planes.png" --compression zip -o "$d/c_one.exr")"$'\n'
        runs[double]+="$(measure "$COMPOSE" "${crops[@]}" "${groups[@]}" --trans "$d/trans.exr" --mask "$d/units/mask_planes.png" --compression zip -o "$d/c_double.exr")"$'\n'
        runs[s1]+="$(measure "$COMPOSE" "${crops[@]}" --surfaces 1 --trans "$d/trans.exr" --mask "$d/units/mask_planes.png" --compression zip -o "$d/c_s1.exr")"$'\n'
    done
    med() { median_field "${runs[$1]}" "$2"; }
    t1=$(med one 1) m1=$(med one 2)
    for case in one double s1; do
        label=$([ "$case" = one ] && echo "monolithic (one group)" || { [ "$case" = double ] && echo "double units, ghosts" || echo "double units, --surfaces 1"; })
        passes=$([ "$case" = double ] && echo "$((2 * PLANES))" || echo "$PLANES")
        t=$(med "$case" 1) m=$(med "$case" 2)
        echo "| ${w}×${h} | $label | $passes | $t | $m | $(ratio "$t" "$t1")× | $(ratio "$m" "$m1")× |"
    done
    unset runs
done
