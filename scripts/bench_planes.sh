#!/usr/bin/env bash
# Cost follows the glass, not the planes (docs/performance.md, "Many planes, cropped passes"):
# times `compose` on a frame with PLANES glass windows (one plane each) whose reflection passes
# are full frames (one file per plane), cropped to each plane's window (EXR data windows, one
# file per plane), or every crop in one multi-part file (parts plane0, plane1, …), against one
# plane carrying the same glass with one full-frame pass, and against oiiotool doing the same
# composite (the crops summed over the frame, `--add`, then the compositor's own tables as
# colormaps, as in scripts/bench_compose_vs_oiiotool.sh).
#
# Paired whole-process runs: every repetition runs each command once, in a fixed order, so all
# see the same machine state; medians of REPEATS, wall clock and peak RSS from /usr/bin/time -v.
#   SIZES="1280x1024 3840x2160" TYPES="half float" PLANES=17 REPEATS=5 scripts/bench_planes.sh
# Needs oiiotool (Debian: openimageio-tools) and GNU time. Prints a Markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."

SIZES=${SIZES:-"1280x1024 3840x2160"}
TYPES=${TYPES:-"half float"}
PLANES=${PLANES:-17}
REPEATS=${REPEATS:-5}
THREADS=${THREADS:-$(nproc)}
# shellcheck source=scripts/bench_common.sh
. scripts/bench_common.sh

build_compose_and_examples make_plane_bench_inputs oiiotool_colormaps
make_work_dir glassdb-planes
eval "$("$EXAMPLES/oiiotool_colormaps" 6)"


echo "machine: $(machine_and_peer), threads $THREADS, $PLANES planes, ZIP, medians of $REPEATS paired runs; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
markdown_header size samples case "compose (s)" "compose RSS (MiB)" "oiiotool (s)" \
    "oiiotool RSS (MiB)" speed-up "max abs diff to oiiotool"
for size in $SIZES; do
    w=${size%x*}
    h=${size#*x}
    for type in $TYPES; do
        d="$WORK/$size-$type"
        mapfile -t rects < <("$EXAMPLES/make_plane_bench_inputs" "$d" "$w" "$h" "$type" zip "$PLANES")
        full=() crop=() oiio_full=() oiio_crop=() parts=()
        for r in "${rects[@]}"; do
            read -r k x y cw ch <<<"$r"
            oiiotool "$d/refl.exr" --crop "${cw}x${ch}+${x}+${y}" -d "$type" --compression zip -o "$d/crop_$k.exr"
            # One file per plane, as renders are: a file named twice would be decoded once by
            # oiiotool's image cache, a saving no real frame offers.
            cp "$d/refl.exr" "$d/refl_$k.exr"
            full+=(--refl "$d/refl_$k.exr")
            crop+=(--refl "$d/crop_$k.exr")
            parts+=("$d/crop_$k.exr" --attrib oiio:subimagename "plane$k")
            oiio_full+=("$d/refl_$k.exr" --crop "${cw}x${ch}+${x}+${y}")
            oiio_crop+=("$d/crop_$k.exr")
            [ "$k" = 0 ] || { oiio_full+=(--add); oiio_crop+=(--add); }
        done
        oiiotool "${parts[@]}" --siappendall -d "$type" --compression zip -o "$d/planes.exr"
        composite=(--chsum:weight="$CHSUM_WEIGHTS" --dup --colormap "$R_KNOTS")
        declare -A runs=()
        for _ in $(seq "$REPEATS"); do
            runs[one]+="$(measure "$COMPOSE" --refl "$d/refl.exr" --trans "$d/trans.exr" --mask "$d/mask_one.png" --compression zip -o "$d/c_one.exr")"$'\n'
            runs[full]+="$(measure "$COMPOSE" "${full[@]}" --trans "$d/trans.exr" --mask "$d/mask_planes.png" --compression zip -o "$d/c_full.exr")"$'\n'
            runs[crop]+="$(measure "$COMPOSE" "${crop[@]}" --trans "$d/trans.exr" --mask "$d/mask_planes.png" --compression zip -o "$d/c_crop.exr")"$'\n'
            runs[parts]+="$(measure "$COMPOSE" --refl "$d/planes.exr" --trans "$d/trans.exr" --mask "$d/mask_planes.png" --compression zip -o "$d/c_parts.exr")"$'\n'
            runs[o_one]+="$(measure oiiotool --threads "$THREADS" "$d/mask_one.png" "${composite[@]}" "$d/refl.exr" --mul --swap --colormap "$T_KNOTS" "$d/trans.exr" --mul --add -d "$type" --compression zip -o "$d/o_one.exr")"$'\n'
            runs[o_full]+="$(measure oiiotool --threads "$THREADS" "$d/mask_planes.png" "${composite[@]}" "${oiio_full[@]}" --mul --swap --colormap "$T_KNOTS" "$d/trans.exr" --mul --add -d "$type" --compression zip -o "$d/o_full.exr")"$'\n'
            runs[o_crop]+="$(measure oiiotool --threads "$THREADS" "$d/mask_planes.png" "${composite[@]}" "${oiio_crop[@]}" --mul --swap --colormap "$T_KNOTS" "$d/trans.exr" --mul --add -d "$type" --compression zip -o "$d/o_crop.exr")"$'\n'
        done
        med() { median_field "${runs[$1]}" "$2"; }
        row() { # LABEL COMPOSE_KEY OIIO_KEY COMPOSE_OUT OIIO_OUT
            local cs cr os or
            cs=$(med "$2" 1) cr=$(med "$2" 2) os=$(med "$3" 1) or=$(med "$3" 2)
            echo "| ${w}×${h} | $type | $1 | $cs | $cr | $os | $or | $(ratio "$os" "$cs")× | $(max_abs_diff "$4" "$5") |"
        }
        row "1 plane, 1 full-frame pass (same glass)" one o_one "$d/c_one.exr" "$d/o_one.exr"
        row "$PLANES planes, full-frame passes" full o_full "$d/c_full.exr" "$d/o_full.exr"
        row "$PLANES planes, cropped passes" crop o_crop "$d/c_crop.exr" "$d/o_crop.exr"
        row "$PLANES planes, one multi-part file of the crops" parts o_crop "$d/c_parts.exr" "$d/o_crop.exr"
        echo "|  |  | cropped ÷ 1 plane: time $(ratio "$(med crop 1)" "$(med one 1)")×, memory $(ratio "$(med crop 2)" "$(med one 2)")×; multi-part ÷ 1 plane: time $(ratio "$(med parts 1)" "$(med one 1)")×, memory $(ratio "$(med parts 2)" "$(med one 2)")× |  |  |  |  |  |  |"
        unset runs
        rm -rf "$d"
    done
done
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
