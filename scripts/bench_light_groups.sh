#!/usr/bin/env bash
# A frame split into G light groups (docs/performance.md, "Light groups"): `compose
# --light-groups g1,…,gG` on passes holding G group layers against G independent single-group
# composites of the same passes (`compose --light-groups gK` on files holding that group's
# layer only), G = 1, 2, 4; the goal is time and peak memory within 1.15× of the G single-group
# runs (their summed time; their largest peak, as run one after another).
#
# Paired whole-process runs: every repetition runs each command once, in a fixed order, so all
# see the same machine state; medians of REPEATS, wall clock and peak RSS from /usr/bin/time -v.
#   SIZE=3840x2160 TYPE=half GROUPS_LIST="1 2 4" REPEATS=5 scripts/bench_light_groups.sh
# Needs GNU time. Prints a Markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."

SIZE=${SIZE:-3840x2160}
TYPE=${TYPE:-half}
GROUPS_LIST=${GROUPS_LIST:-"1 2 4"}
REPEATS=${REPEATS:-5}
# shellcheck source=scripts/bench_common.sh
. scripts/bench_common.sh

build_compose_and_examples make_light_group_bench_inputs
cargo build --quiet --bin glassdb # the registry only
make_work_dir glassdb-light-groups
w=${SIZE%x*}
h=${SIZE#*x}

# Four lights, one per group: g1 = D65, g2 = A, g3 = D50, g4 = FL2.
"${CARGO_TARGET_DIR:-target}/debug/glassdb" registry build data/catalog.toml -o "$WORK/registry.json" \
    --light g1=D65 --light g2=A --light g3=D50 --light g4=FL2 >/dev/null

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), ${w}×${h} $TYPE ZIP passes, 8-bit PNG mask, ZIP half output, medians of $REPEATS paired runs; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
markdown_header G "--light-groups g1…gG (s)" "RSS (MiB)" "G single-group runs, summed (s)" \
    "largest single-group RSS (MiB)" "time ratio" "memory ratio"
for g in $GROUPS_LIST; do
    d="$WORK/g$g"
    "$EXAMPLES/make_light_group_bench_inputs" "$d" "$w" "$h" "$g" "$TYPE" zip >/dev/null
    names=$(seq -s, -f 'g%.0f' 1 "$g")
    common=(--registry "$WORK/registry.json" --mask "$d/mask.png" --compression zip)
    together="" singles=""
    for _ in $(seq "$REPEATS"); do
        together+="$(measure "$COMPOSE" "${common[@]}" --trans "$d/groups/trans.exr" \
            --refl "$d/groups/refl.exr" --light-groups "$names" -o "$d/together.exr")"$'\n'
        total=0 peak=0
        for k in $(seq "$g"); do
            read -r s m < <(measure "$COMPOSE" "${common[@]}" --trans "$d/g$k/trans.exr" \
                --refl "$d/g$k/refl.exr" --light-groups "g$k" -o "$d/alone_$k.exr")
            total=$(awk -v a="$total" -v b="$s" 'BEGIN { printf "%.3f", a + b }')
            peak=$((m > peak ? m : peak))
        done
        singles+="$total $peak"$'\n'
    done
    med() { median_field "$1" "$2"; }
    ts=$(med "$together" 1) tm=$(med "$together" 2) ss=$(med "$singles" 1) sm=$(med "$singles" 2)
    echo "| $g | $ts | $tm | $ss | $sm | $(ratio "$ts" "$ss")× | $(ratio "$tm" "$sm")× |"
done
