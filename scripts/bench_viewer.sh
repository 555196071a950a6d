#!/usr/bin/env bash
# The viewer's speed (docs/performance.md, "The viewer"): the time from a product choice to the
# new frame drawn, from a unit built on the page to its frame on screen (the server's stack
# engine and fit included), and the initial load, at the atrium's size (320×240) and at 1920×1080 (the
# atrium's passes and mask resampled to the closest pixel by oiiotool), in headless Chromium.
#
#   scripts/bench_viewer.sh            # WebGL2 on SwiftShader (CPU)
#   scripts/bench_viewer.sh --gpu      # the machine's GPU (Chromium's default GL)
#   SIZES=atrium scripts/bench_viewer.sh   # the atrium's size only
#
# A choice is timed in the page (performance.now()) from the call of its choose() hook to the
# frame drawn, a 1-pixel readPixels finishing the drawing; the load from the WebDriver's page
# request to the first frame drawn. Needs: cargo, oiiotool, chromium, chromium-driver, .venv
# (selenium; scripts/test-all installs it).
set -euo pipefail
cd "$(dirname "$0")/.."
GPU_FLAG=${1:-}
REPEAT=${REPEAT:-10}
PY=${GLASSDB_PYTHON:-.venv/bin/python}
cargo build --release --quiet
BIN=${CARGO_TARGET_DIR:-target}/release/glassdb
WORK=$(mktemp -d)
trap 'kill ${SERVER:-} 2>/dev/null || true; rm -rf "$WORK"' EXIT
A=fixtures/atrium

# SIZES=atrium measures the atrium's size only (no oiiotool needed).
SIZES=${SIZES:-atrium 1080p}
if [[ " $SIZES " == *" 1080p "* ]]; then
    mkdir -p "$WORK/1080p"
    for f in trans refl_0 refl_1 refl_2; do
        oiiotool "$A/$f.exr" --resample:interp=0 1920x1080 -o "$WORK/1080p/$f.exr"
    done
    oiiotool "$A/mask.png" --resample:interp=0 1920x1080 -o "$WORK/1080p/mask.png"
fi

PRODUCTS="AGC Stopray Titanium 34T on grey 8 mm (NFRC 20748)|AGC green-tinted float 4.8 mm (IGSDB 185)|Pilkington Solar-E Plus Arctic Blue 6 mm (NFRC 9962)"
# A unit built on the page (issue 26): Solarban R67 (coating #2) | argon | clear 6 mm, from the
# bundled catalog; the gap widened by 0.1 mm each time so that every build is a new one.
UNIT="6|12.7:argon|2"
for size in $SIZES; do
    dir=$A
    [ "$size" = 1080p ] && dir="$WORK/1080p"
    "$BIN" view --trans "$dir/trans.exr" --refl "$dir/refl_0.exr" --refl "$dir/refl_1.exr" \
        --refl "$dir/refl_2.exr" --mask "$dir/mask.png" --planes "$A/virtual/planes.json" \
        --port 0 > "$WORK/url" &
    SERVER=$!
    for _ in $(seq 100); do [ -s "$WORK/url" ] && break; sleep 0.1; done
    url=$(head -1 "$WORK/url" | sed 's/^serving //')
    echo "== $size ($url)"
    "$PY" python_oracle/viewer_driver.py bench "$url" --id 5 --products "$PRODUCTS" \
        --repeat "$REPEAT" --unit "$UNIT" $GPU_FLAG
    kill $SERVER
    wait $SERVER 2>/dev/null || true
done
