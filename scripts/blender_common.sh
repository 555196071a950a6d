# Shared by the Blender validation scripts (sourced by scripts/*validation.sh): strict mode, the
# repository root as the working folder, building glassdb and running the repository's scene
# scripts.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

# Builds `glassdb` with the cargo profile $1 (`debug`, where Blender dominates and the composite
# is tiny, or `release`); sets G to the binary.
build_glassdb() {
    if [ "$1" = release ]; then
        cargo build --release --quiet --bin glassdb
    else
        cargo build --quiet --bin glassdb
    fi
    G=${CARGO_TARGET_DIR:-target}/$1/glassdb
}

# The start of a validation of a scene of scripts/blender/make_glassdb_scene.py: creates the
# output folder $OUT, builds `glassdb` with the cargo profile $1 (sets G) and builds scene $2 as
# $OUT/$2.blend (its log in $OUT/scene.log).
prepare_scene_validation() {
    mkdir -p "$OUT"
    build_glassdb "$1"
    run_blender_script make_glassdb_scene.py --scene "$2" --out "$OUT/$2.blend" > "$OUT/scene.log" 2>&1
}

# Runs scripts/blender/$1 in Blender in the background (factory settings, no audio, niced), with
# the remaining arguments after `--`; a Python error fails it.
run_blender_script() {
    local script=$1
    shift
    nice blender -b --factory-startup -noaudio --python-exit-code 1 \
        -P "scripts/blender/$script" -- "$@"
}
