#!/usr/bin/env bash
# The relit swap's cost (docs/performance.md, "Relit swap"): `glassdb blender compose` on one
# synthetic frame with two windows of different glass (K = 2 ids), its passes split into 3 or 7
# light parts and composited with them, against the same frame as today's render writes it
# (one RGB layer per pass, composited without parts). Runs alternate (today, relit) pair by
# pair; prints each side's median wall seconds (whole process) and the median of the ratios.
#
# usage: bash scripts/bench_relight.sh [WIDTH HEIGHT PAIRS]   (default 1920 1080 7)
set -euo pipefail
cd "$(dirname "$0")/.."
width=${1:-1920} height=${2:-1080} pairs=${3:-7}
# shellcheck source=scripts/bench_common.sh
. scripts/bench_common.sh
python=${GLASSDB_PYTHON:-.venv/bin/python}
cargo build --release --quiet --bin glassdb
glassdb=${CARGO_TARGET_DIR:-target}/release/glassdb
work=$(mktemp -d "${TMPDIR:-/tmp}/bench_relight.XXXXXX")
trap 'rm -rf "$work"' EXIT

# Wall seconds of one `glassdb blender compose DIR`.
seconds() {
    local start end
    start=$(date +%s%N)
    "$glassdb" blender compose "$1" >/dev/null 2>&1
    end=$(date +%s%N)
    awk -v s="$start" -v e="$end" 'BEGIN { printf "%.4f\n", (e - s) / 1e9 }'
}

echo "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), ${width}x${height}, $pairs pairs"
echo
echo "| light parts | today (s) | relit (s) | relit / today |"
echo "|---|---|---|---|"
for parts in 3 7; do
    "$python" scripts/bench_relight.py "$work/p$parts" "$width" "$height" "$parts" 1 5
    seconds "$work/p$parts/today" >/dev/null # warm-up: the files in the page cache
    seconds "$work/p$parts/relit" >/dev/null
    : >"$work/a" ; : >"$work/b" ; : >"$work/r"
    for _ in $(seq "$pairs"); do
        a=$(seconds "$work/p$parts/today")
        b=$(seconds "$work/p$parts/relit")
        echo "$a" >>"$work/a"
        echo "$b" >>"$work/b"
        awk -v a="$a" -v b="$b" 'BEGIN { printf "%.4f\n", b / a }' >>"$work/r"
    done
    echo "| $parts | $(median <"$work/a") | $(median <"$work/b") | $(median <"$work/r") |"
done

# The viewer (docs/performance.md, "Relit swap"): a product choice to the frame drawn, on the
# same folders served by `glassdb view DIR` (headless Chromium, SwiftShader without a GPU),
# today's frame against the relit one (its parts' passes summed with their factors in the
# shader). VIEWER=0 skips it.
if [ "${VIEWER:-1}" != 0 ]; then
    products="AGC Stopray Titanium 34T on grey 8 mm (NFRC 20748)|AGC green-tinted float 4.8 mm (IGSDB 185)|Pilkington Solar-E Plus Arctic Blue 6 mm (NFRC 9962)"
    for parts in 3 7; do
        for side in today relit; do
            "$glassdb" view "$work/p$parts/$side" --port 0 >"$work/url" 2>/dev/null &
            server=$!
            # the server decodes the frame and its parts before it prints its URL (seconds
            # on a loaded machine)
            for _ in $(seq 600); do [ -s "$work/url" ] && break; sleep 0.1; done
            [ -s "$work/url" ] || { echo "glassdb view $work/p$parts/$side printed no URL in 60 s" >&2; exit 1; }
            url=$(head -1 "$work/url" | sed 's/^serving //')
            echo "== viewer, $parts light parts, $side"
            "$python" python_oracle/viewer_driver.py bench "$url" --id 1 --products "$products" \
                --repeat "${REPEAT:-10}"
            kill "$server"
            wait "$server" 2>/dev/null || true
        done
    done
fi
