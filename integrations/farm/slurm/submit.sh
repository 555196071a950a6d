#!/bin/bash
# Submits a shot to Slurm: a job array rendering the passes, one task per chunk of frames, and
# a job array compositing them whose task K starts when render task K has succeeded
# (--dependency=aftercorr). Prints both job ids. docs/farm.md.
#
#   FRAME_FIRST=1 FRAME_LAST=240 CHUNK_SIZE=8 WORK_DIR=/shots/atrium \
#   RENDER_COMMAND='./render_passes.sh $FRAME_START $FRAME_END' \
#   COMPOSE_ARGS='--refl refl_0.####.exr --trans trans.####.exr --mask mask.####.png --planes planes.json' \
#   OUTPUT=comp/out.####.exr [GLASSDB=glassdb] integrations/farm/slurm/submit.sh [sbatch options…]
#
# RENDER_COMMAND runs in WORK_DIR with FRAMES=first-last, FRAME_START and FRAME_END set; the
# composite runs `$GLASSDB compose $COMPOSE_ARGS -o $OUTPUT --frames $FRAMES --skip-existing
# --report reports/frames.$FRAMES.json` there (tested: tests/cli/farm.rs runs docs/farm.md's
# command on scripts/slurm_local_cluster.sh).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${FRAME_FIRST:?}" "${FRAME_LAST:?}" "${CHUNK_SIZE:?}" "${WORK_DIR:?}" "${RENDER_COMMAND:?}" \
    "${COMPOSE_ARGS:?}" "${OUTPUT:?}"
export FRAME_FIRST FRAME_LAST CHUNK_SIZE WORK_DIR RENDER_COMMAND COMPOSE_ARGS OUTPUT
export GLASSDB=${GLASSDB:-glassdb}
chunks=$(((FRAME_LAST - FRAME_FIRST) / CHUNK_SIZE))
render=$(sbatch --parsable --array="0-$chunks" --job-name=glassdb-render \
    --chdir="$WORK_DIR" --export=ALL "$@" "$here/glassdb-chunk.sbatch" render)
render=${render%%;*}
composite=$(sbatch --parsable --array="0-$chunks" --job-name=glassdb-composite \
    --dependency="aftercorr:$render" --kill-on-invalid-dep=yes \
    --chdir="$WORK_DIR" --export=ALL "$@" "$here/glassdb-chunk.sbatch" composite)
composite=${composite%%;*}
echo "render $render composite $composite"
