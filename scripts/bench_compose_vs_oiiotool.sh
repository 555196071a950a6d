#!/usr/bin/env bash
# Times `compose` against oiiotool (OpenImageIO) doing the same composite, in one run, on the
# same inputs, and checks that both produce the same image.
#
# oiiotool computes it exactly as compose does: the packed 8-bit mask becomes one coordinate
# 256·id + code (--chsum), which indexes the compositor's own 256-entry r and t tables
# (--colormap with one knot per entry; crates/compose/examples/oiiotool_colormaps.rs), then
# out = refl·r + trans·t. Inputs: crates/compose/examples/make_bench_inputs.rs (gradients plus
# render-like noise, half the frame glass, ids 2 and 6 of the bundled catalog).
#
# Usage: scripts/bench_compose_vs_oiiotool.sh            (all sizes and pass types)
#   SIZES="1280x1024" CASES="half:none" REPEATS=5 scripts/bench_compose_vs_oiiotool.sh
# Needs oiiotool (Debian: apt-get install openimageio-tools) and GNU time. Prints a Markdown
# table (times are the best of REPEATS wall-clock runs; RSS is the peak of the best run).
set -euo pipefail
cd "$(dirname "$0")/.."

SIZES=${SIZES:-"3840x2160 1280x1024"}
CASES=${CASES:-"half:none float:none half:zip float:zip"}
REPEATS=${REPEATS:-3}
THREADS=${THREADS:-$(nproc)}

for tool in oiiotool /usr/bin/time; do
    command -v "$tool" >/dev/null || {
        echo "error: $tool not found (Debian: apt-get install openimageio-tools time)" >&2
        exit 2
    }
done

# shellcheck source=scripts/bench_common.sh
. scripts/bench_common.sh

build_compose_and_examples make_bench_inputs oiiotool_colormaps
make_work_dir glassdb-bench

# CHSUM_WEIGHTS, R_KNOTS, T_KNOTS for ids 0…6.
eval "$("$EXAMPLES/oiiotool_colormaps" 6)"

# Runs "$@" and prints "SECONDS MAX_RSS_MB" (wall clock from a monotonic clock).
timed() {
    local t0 t1
    t0=$(date +%s%N)
    /usr/bin/time -f '%M' -o "$WORK/rss" "$@" >/dev/null 2>"$WORK/stderr" || {
        cat "$WORK/stderr" >&2
        return 1
    }
    t1=$(date +%s%N)
    awk -v ns=$((t1 - t0)) -v kb="$(tail -1 "$WORK/rss")" 'BEGIN { printf "%.3f %.0f\n", ns / 1e9, kb / 1024 }'
}

# Keeps the smaller time of "SECONDS RSS" pairs read on stdin.
best() { sort -n | head -1; }

echo "machine: $(machine_and_peer), threads $THREADS"
markdown_header size passes "compose (s)" "oiiotool (s)" speed-up "compose RSS (MB)" \
    "oiiotool RSS (MB)" "max abs diff"
for size in $SIZES; do
    w=${size%x*}
    h=${size#*x}
    for case in $CASES; do
        type=${case%:*}
        comp=${case#*:}
        dir="$WORK/$size-$type-$comp"
        "$EXAMPLES/make_bench_inputs" "$dir" "$w" "$h" "$type" "$comp" >/dev/null
        c_runs=()
        o_runs=()
        for _ in $(seq "$REPEATS"); do
            # Interleaved, so that both see the same machine state.
            c_runs+=("$(timed "$COMPOSE" --refl "$dir/refl.exr" --trans "$dir/trans.exr" \
                --mask "$dir/mask.png" --compression "$comp" -o "$dir/compose.exr")")
            o_runs+=("$(timed oiiotool --threads "$THREADS" "$dir/mask.png" \
                --chsum:weight="$CHSUM_WEIGHTS" --dup --colormap "$R_KNOTS" \
                "$dir/refl.exr" --mul --swap --colormap "$T_KNOTS" \
                "$dir/trans.exr" --mul --add \
                -d "$type" --compression "$comp" -o "$dir/oiiotool.exr")")
        done
        read -r c_s c_rss < <(printf '%s\n' "${c_runs[@]}" | best)
        read -r o_s o_rss < <(printf '%s\n' "${o_runs[@]}" | best)
        max_diff=$(max_abs_diff "$dir/compose.exr" "$dir/oiiotool.exr")
        speedup=$(ratio "$o_s" "$c_s")
        echo "| ${w}×${h} | $type, $comp | $c_s | $o_s | ${speedup}× | $c_rss | $o_rss | ${max_diff:-?} |"
        rm -rf "$dir"
    done
done
