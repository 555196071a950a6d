# Shared by the compose benchmarks against oiiotool (sourced by scripts/bench_*.sh, which have
# already changed to the repository root): building, a work folder, and the Markdown they print.

# Builds `compose` (release) and the glassdb-compose examples named; sets COMPOSE and EXAMPLES.
build_compose_and_examples() {
    local target=${CARGO_TARGET_DIR:-target} examples=() name
    for name in "$@"; do examples+=(--example "$name"); done
    cargo build --release --quiet --bin compose
    cargo build --release --quiet -p glassdb-compose "${examples[@]}"
    COMPOSE=$target/release/compose
    EXAMPLES=$target/release/examples
}

# Sets WORK to a new folder under TMPDIR named after $1, removed when the script exits.
make_work_dir() {
    WORK=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")
    trap 'rm -rf "$WORK"' EXIT
}

# The machine and the peer: "N cores, CPU model, oiiotool VERSION".
machine_and_peer() {
    echo "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), oiiotool $(oiiotool --version)"
}

# A Markdown table's header row and separator, after a blank line: one argument a column.
markdown_header() {
    local cells="" rule="" column
    for column in "$@"; do
        cells+=" $column |"
        rule+="---|"
    done
    echo
    echo "|$cells"
    echo "|$rule"
}

# Largest |A − B| over all pixels and channels of two images (scaled by 1e6 because oiiotool's
# --printstats prints 6 decimals).
max_abs_diff() {
    oiiotool "$1" "$2" --absdiff --mulc 1e6 --printstats |
        awk '/Stats Max/ { m = 0; for (i = 3; i <= 5; i++) if ($i > m) m = $i; printf "%.2g", m / 1e6 }'
}

# A ÷ B to two decimals.
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }

# Runs "$@" (in $WORK, from make_work_dir); prints "SECONDS MAX_RSS_MIB" from GNU time's verbose report.
measure() {
    /usr/bin/time -v -o "$WORK/time" "$@" >/dev/null 2>"$WORK/stderr" || {
        cat "$WORK/stderr" "$WORK/time" >&2
        return 1
    }
    awk -F': ' '/Elapsed \(wall clock\)/ { n = split($2, t, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + t[i] }
                /Maximum resident set size/ { kb = $2 }
                END { printf "%.3f %.0f\n", s, kb / 1024 }' "$WORK/time"
}
# The median of the numbers on standard input, one a line (an even count: the mean of the middle two).
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# The median of field $2 (1: seconds, 2: MiB) of the lines "$1" that `measure` printed, one a run.
median_field() { printf '%s' "$1" | awk 'NF' | cut -d' ' -f"$2" | median; }
