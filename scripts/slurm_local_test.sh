#!/bin/bash
# Runs integrations/farm/slurm/ on a one-node Slurm cluster on this machine (not in CI): writes a
# slurm.conf for localhost in a temporary directory, starts munged, slurmctld and slurmd (as
# root), submits the render and composite job arrays for frames 1-FRAMES of the atrium (the
# render step copies the fixture passes per frame, standing in for a renderer), waits, checks
# every frame and report, prints the timings, and stops the daemons it started.
#   sudo bash scripts/slurm_local_test.sh [FRAMES=12] [CHUNK=4]
# Needs Debian's slurm-wlm and munge, and a release build (cargo build --release).
set -euo pipefail
FRAMES=${1:-12}
CHUNK=${2:-4}
repo=$(cd "$(dirname "$0")/.." && pwd)
glassdb=${GLASSDB:-${CARGO_TARGET_DIR:-$repo/target}/release/glassdb}
[ -x "$glassdb" ] || { echo "no $glassdb: cargo build --release first" >&2; exit 1; }
[ "$(id -u)" = 0 ] || { echo "run as root (slurmd starts jobs as their user)" >&2; exit 1; }
D=$(mktemp -d /tmp/glassdb-slurm.XXXXXX)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    sleep 1
    echo "logs and outputs left in $D"
}
trap cleanup EXIT
mkdir -p "$D/state" "$D/spool" "$D/shot" "$D/munge"
host=$(hostname -s)

# munge: its own key, socket and files under $D.
dd if=/dev/urandom bs=1 count=1024 of="$D/munge/munge.key" status=none
chmod 600 "$D/munge/munge.key"
munged --force --key-file="$D/munge/munge.key" --socket="$D/munge/munge.sock" \
    --pid-file="$D/munge/munged.pid" --log-file="$D/munge/munged.log" \
    --seed-file="$D/munge/munged.seed"
sleep 1
pids+=("$(cat "$D/munge/munged.pid")")

cpus=$(nproc)
mem=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2))
cat >"$D/slurm.conf" <<CONF
ClusterName=glassdb-local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$D/munge/munge.sock
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/slurmctld.log
SlurmdLogFile=$D/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$D/slurm.conf
slurmctld -i
slurmd
for _ in $(seq 50); do [ -s "$D/slurmctld.pid" ] && [ -s "$D/slurmd.pid" ] && break; sleep 0.2; done
pids+=("$(cat "$D/slurmctld.pid")" "$(cat "$D/slurmd.pid")")
for _ in $(seq 50); do sinfo -h -o %T | grep -q idle && break; sleep 0.5; done
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
