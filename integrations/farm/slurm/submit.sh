#!/bin/bash
# Submits a shot to Slurm: a job array rendering the passes, one task per chunk of frames, and
# a job array compositing them whose task K starts when render task K has succeeded
# (--dependency=aftercorr). Prints both job ids. docs/farm.md.
#
#   FRAME_FIRST=1 FRAME_LAST=240 CHUNK_SIZE=8 WORK_DIR=/shots/atrium \
#   RENDER_COMMAND='glassdb blender render scene.blend --frames $FRAMES' \
#   COMPOSE_ARGS='--refl refl_0.####.exr --trans trans.####.exr --mask mask.####.exr' \
#   OUTPUT=composite/out.####.exr GLASSDB=glassdb  integrations/farm/slurm/submit.sh [sbatch options…]
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
