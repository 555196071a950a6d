#!/usr/bin/env bash
# Issue 28's validation of the relit swap against Cycles (docs/blender.md, "Light parts"):
# renders the `relit` scene's runs into DIR and runs scripts/blender/relit_validation.py on them.
#
#     bash scripts/blender/relit_validation.sh DIR [FIGURE.png]
#
# Needs a built glassdb (target/release or target/debug) and Blender 3.4+ on PATH.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
dir=$1
figure=${2:-}
mkdir -p "$dir"
glassdb=$repo/target/release/glassdb
[ -x "$glassdb" ] || glassdb=$repo/target/debug/glassdb
cp "$glassdb" "$dir/glassdb"
cd "$dir"
blender -b --factory-startup -noaudio --python-exit-code 1 \
    -P "$repo/scripts/blender/make_glassdb_scene.py" -- --scene relit --out relit.blend >/dev/null
for k in clear dark; do
    ./glassdb registry build "$repo/fixtures/blender/relit/$k.toml" -o $k.json >/dev/null
done
run() {
    local name=$1 registry=$2 seed=$3
    shift 3
    rm -rf "$name"
    ./glassdb blender render relit.blend --glass Glass_clear=1 --glass 'Tinted*=5' \
        --registry $registry.json --out-dir "$name" --threads 2 --seed $seed --samples 64 "$@" \
        >"$name.out"
    grep -E "^Blender (export|CPU)" "$name.out" | sed "s/^/$name: /"
}
run C0 clear 0 --reference
run D0 dark 0 --reference
run C0off clear 0 --light-split off --reference
run D0off dark 0 --light-split off --reference
run CR1 clear 1 --light-split off --reference
run DR1 dark 1 --light-split off --reference
"$repo/.venv/bin/python" "$repo/scripts/blender/relit_validation.py" . ${figure:+"$figure"}
