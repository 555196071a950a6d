#!/bin/bash
# Times integrations/farm/slurm/ on a one-node Slurm cluster on this machine
# (scripts/slurm_local_cluster.sh, as root; the test suite runs docs/farm.md's command on the
# same cluster, farm::the_docs_slurm_submission_runs_on_a_localhost_cluster): submits the
# render and composite job arrays for frames 1-FRAMES of the atrium (the render step copies the
# fixture passes per frame, standing in for a renderer), waits, checks every frame and report,
# prints the timings, and stops the daemons it started.
#   sudo bash scripts/slurm_local_test.sh [FRAMES=12] [CHUNK=4]
# Needs Debian's slurm-wlm and munge, and a release build (cargo build --release).
set -euo pipefail
FRAMES=${1:-12}
CHUNK=${2:-4}
repo=$(cd "$(dirname "$0")/.." && pwd)
glassdb=${GLASSDB:-${CARGO_TARGET_DIR:-$repo/target}/release/glassdb}
[ -x "$glassdb" ] || { echo "no $glassdb: cargo build --release first" >&2; exit 1; }
D=$(mktemp -d /tmp/glassdb-slurm.XXXXXX)
mkdir -p "$D/shot"
cleanup() {
    bash "$repo/scripts/slurm_local_cluster.sh" stop "$D/cluster"
    echo "logs and outputs left in $D"
}
trap cleanup EXIT
# The one-node cluster (partition `render`) the test suite's Slurm test runs on.
mkdir -p "$D/cluster"
bash "$repo/scripts/slurm_local_cluster.sh" start "$D/cluster"
export SLURM_CONF=$D/cluster/slurm.conf
sinfo

a=$repo/fixtures/atrium
export FRAME_FIRST=1 FRAME_LAST=$FRAMES CHUNK_SIZE=$CHUNK WORK_DIR=$D/shot GLASSDB=$glassdb
export RENDER_COMMAND="for f in \$(seq \$FRAME_START \$FRAME_END); do n=\$(printf %04d \$f); for p in refl_0 refl_1 refl_2 trans; do cp $a/\$p.exr \$p.\$n.exr; done; cp $a/mask.png mask.\$n.png; done"
export COMPOSE_ARGS="--refl refl_0.####.exr --refl refl_1.####.exr --refl refl_2.####.exr --trans trans.####.exr --mask mask.####.png --planes $a/virtual/planes.json"
export OUTPUT=composite/out.####.exr
t0=$(date +%s.%N)
read -r _ render _ composite < <("$repo/integrations/farm/slurm/submit.sh")
echo "submitted render array $render, composite array $composite (aftercorr)"
squeue
while [ -n "$(squeue -h -j "$render,$composite" 2>/dev/null)" ]; do sleep 0.2; done
t1=$(date +%s.%N)
echo "both arrays finished in $(echo "$t1 - $t0" | bc) s (submit to last task out of the queue)"
# Each array task's state and times (one line per task), and the aftercorr order: composite
# task K starts no earlier than render task K ends.
times() {
    scontrol -o show job "$1" | tr ' ' '\n' |
        awk -F= '/^ArrayTaskId=/ {k=$2} /^JobState=/ {s=$2} /^StartTime=/ {a=$2}
                 /^EndTime=/ {print k, s, a, $2}' | sort -n
}
echo "render tasks (task state start end):"; times "$render" | tee "$D/render.times"
echo "composite tasks:"; times "$composite" | tee "$D/composite.times"
join "$D/render.times" "$D/composite.times" | while read -r k rs _ rend cs cstart _; do
    if [ "$rs" != COMPLETED ] || [ "$cs" != COMPLETED ] || [[ "$cstart" < "$rend" ]]; then
        echo "task $k: render $rs ended $rend, composite $cs started $cstart: wrong order" >&2
        exit 1
    fi
done

ok=1
for f in $(seq 1 "$FRAMES"); do
    out=$D/shot/composite/out.$(printf %04d "$f").exr
    [ -s "$out" ] || { echo "missing $out" >&2; ok=0; }
done
composed=$(cat "$D"/shot/reports/frames.*.json | grep -c '"status": "composed"' || true)
echo "reports: $(ls "$D/shot/reports" | tr '\n' ' ')"
echo "frames composed: $composed of $FRAMES"
[ "$composed" = "$FRAMES" ] || ok=0
grep -h '"wall"' "$D"/shot/reports/frames.*.json | awk '{s += $2; n++} END {printf "compose wall per frame: %.3f s mean over %d frames\n", s/n, n}'
[ $ok = 1 ] && echo "PASS" || { echo "FAIL"; exit 1; }
