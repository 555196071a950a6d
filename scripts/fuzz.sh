#!/usr/bin/env bash
# Runs every cargo-fuzz target in fuzz/ for SECONDS each (default 60), from seed corpora made
# of the repository's fixtures, and prints one line per target: executions, corpus size, crashes.
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`); not run by CI.
# Findings land in fuzz/artifacts/TARGET/ (crash-*, timeout-*, oom-*): turn each into a
# deterministic regression test in tests/cli/ and note it in docs/reliability.md.
#
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(spectral registry_json catalog angle_table fit_json image mask cryptomatte obj camera planes cube)
fi

seeds=fuzz/seeds
rm -rf "$seeds"
mkdir -p "$seeds"
# Seeds: small fixture files of each kind (under 256 kB, so runs stay fast).
seed() { # seed TARGET FIND-ARGS...
    local t=$1; shift
    mkdir -p "$seeds/$t"
    find fixtures data "$@" -size -256k -type f -print0 2>/dev/null |
        while IFS= read -r -d '' f; do cp "$f" "$seeds/$t/$(echo "$f" | tr '/' '_')"; done
}
seed spectral \( -path '*glazing*' -o -path 'fixtures/spectral*' \)
seed registry_json -name '*registry*.json'
seed catalog -name '*.toml'
seed angle_table -name '*.csv'
seed fit_json \( -name '*fit*.json' -o -name '*.fit.json' \)
seed image \( -name '*.exr' -o -name '*.png' \)
seed mask \( -name '*mask*.png' -o -name '*mask*.exr' -o -name 'index*.exr' \)
seed cryptomatte \( -name 'beauty*.exr' -o -name 'multilayer*.exr' \)
seed camera -name 'camera*.json'
seed planes -name 'planes*.json'
seed cube -name '*.cube'
# Kinds the fixtures hold only large or not at all: the bundled registry, a fit file made by
# glassdb itself when a build is at hand, and a small .cube with a shaper.
cp data/registry.json "$seeds/registry_json/bundled.json"
for bin in target/release/glassdb target/debug/glassdb; do
    if [ -x "$bin" ]; then
        "$bin" fit fixtures/fit/two_glasses_percent.csv --percent -o "$seeds/fit_json/two.json" \
            >/dev/null 2>&1 || true
        break
    fi
done
cat > "$seeds/cube/shaper.cube" <<'CUBE'
TITLE "fuzz seed"
LUT_1D_SIZE 2
LUT_1D_INPUT_RANGE 0.0 4.0
LUT_3D_SIZE 2
0 0 0
1 1 1
0 0 0
1 0 0
0 1 0
1 1 0
0 0 1
1 0 1
0 1 1
1 1 1
CUBE
mkdir -p "$seeds/obj"
find fixtures -name '*.obj' -size -256k -print0 | while IFS= read -r -d '' f; do
    mtl="${f%.obj}.mtl"
    { cat "$f"; printf '\0'; [ -f "$mtl" ] && cat "$mtl"; } > "$seeds/obj/$(echo "$f" | tr '/' '_')"
done

printf '%-14s %10s %8s %8s %s\n' target executions corpus crashes seconds
for t in "${targets[@]}"; do
    mkdir -p "fuzz/corpus/$t" "fuzz/artifacts/$t"
    log="fuzz/artifacts/$t.log"
    set +e
    (cd fuzz && cargo +nightly fuzz run "$t" "corpus/$t" "../$seeds/$t" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=20 -max_len=1048576 \
        -print_final_stats=1 -close_fd_mask=3) > "$log" 2>&1
    set -e
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    corpus=$(find "fuzz/corpus/$t" -type f | wc -l)
    crashes=$(find "fuzz/artifacts/$t" -type f | wc -l)
    printf '%-14s %10s %8s %8s %s\n' "$t" "$execs" "$corpus" "$crashes" "$seconds"
done
