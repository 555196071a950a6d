#!/bin/bash
# A one-node Slurm cluster on this machine, all of it in one folder (docs/farm.md, "Slurm"):
#   bash scripts/slurm_local_cluster.sh start DIR   # as root; then export SLURM_CONF=DIR/slurm.conf
#   bash scripts/slurm_local_cluster.sh stop DIR
#   bash scripts/slurm_local_cluster.sh logs DIR    # the last lines of each daemon's log
# `start` writes DIR/slurm.conf for localhost (partition `render`, free ports, state, spool and
# logs in DIR), starts its own munged (own key and socket), slurmctld and slurmd, and waits
# (at most 30 s) until the node is idle; if any of that fails it stops what it started, prints
# the daemons' logs and exits 1. `stop` ends those daemons (only processes whose command line
# names DIR) and waits for them to exit. Needs Debian's slurm-wlm and munge (22.05), as root:
# slurmd starts each job as its user.
set -euo pipefail
export PATH=/usr/sbin:/sbin:$PATH
cmd=${1:?start or stop}
D=$(cd "${2:?the cluster folder}" && pwd)

# The pid in pid file $1, if that process is alive and its command line names $D (ours).
ours() {
    local p
    p=$(cat "$1" 2>/dev/null) || return 0
    if [ -n "$p" ] && tr '\0' ' ' <"/proc/$p/cmdline" 2>/dev/null | grep -qF "$D"; then
        echo "$p"
    fi
}

# Whether process $1 runs (not gone, not a zombie: those have an empty command line).
alive() {
    [ -n "$(tr -d '\0' <"/proc/$1/cmdline" 2>/dev/null)" ]
}

# Its jobs cancelled, then each daemon in turn, slurmd first (it hangs on exit when slurmctld or munged went first): a
# SIGTERM, at most 5 s to exit, then SIGKILL.
stop() {
    local f p jobs
    # Jobs still queued or running (a test that failed or timed out) are cancelled first, so
    # that no job step outlives the cluster.
    if [ -n "$(ours "$D/slurmctld.pid")" ]; then
        export SLURM_CONF=$D/slurm.conf
        jobs=$(squeue -h -o %A 2>/dev/null | sort -u | tr '\n' ' ')
        if [ -n "$jobs" ]; then
            # shellcheck disable=SC2086 # one job id a word
            scancel $jobs 2>/dev/null || true
            for _ in $(seq 50); do
                [ -z "$(squeue -h 2>/dev/null)" ] && break
                sleep 0.2
            done
        fi
    fi
    for f in "$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/munged.pid"; do
        p=$(ours "$f")
        [ -z "$p" ] && continue
        kill "$p" 2>/dev/null || true
        for _ in $(seq 25); do
            alive "$p" || break
            sleep 0.2
        done
        if alive "$p"; then
            echo "slurm_local_cluster: $f's process $p did not exit in 5 s: killed" >&2
            kill -9 "$p" 2>/dev/null || true
        fi
    done
}

logs() {
    local f
    for f in "$D"/munge/munged.log "$D"/slurmctld.log "$D"/slurmd.log "$D"/*.stderr; do
        if [ -s "$f" ]; then
            echo "--- $f (last 40 lines)"
            tail -n 40 "$f"
        fi
    done
    return 0
}

fail() {
    echo "slurm_local_cluster: $*" >&2
    logs >&2
    stop
    exit 1
}

case $cmd in
stop)
    stop
    exit 0
    ;;
logs)
    logs
    exit 0
    ;;
start) ;;
*)
    echo "usage: $0 start|stop|logs DIR" >&2
    exit 2
    ;;
esac

[ "$(id -u)" = 0 ] || { echo "slurm_local_cluster: run as root (slurmd starts jobs as their user)" >&2; exit 1; }
for tool in munged slurmctld slurmd sbatch sinfo; do
    command -v "$tool" >/dev/null ||
        { echo "slurm_local_cluster: no $tool: apt-get install slurm-wlm munge" >&2; exit 1; }
done
mkdir -p "$D/state" "$D/spool" "$D/munge"
host=$(hostname -s)
# Two free TCP ports (the kernel's choice), so that clusters and system daemons do not clash.
read -r ctld_port d_port < <(python3 -c 'import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*(x.getsockname()[1] for x in s))')

# munge: its own key, socket and files under $D.
head -c 1024 /dev/urandom >"$D/munge/munge.key"
chmod 600 "$D/munge/munge.key"
munged --force --key-file="$D/munge/munge.key" --socket="$D/munge/munge.sock" \
    --pid-file="$D/munge/munged.pid" --log-file="$D/munge/munged.log" \
    --seed-file="$D/munge/munged.seed" </dev/null >"$D/munged.stderr" 2>&1 ||
    fail "munged did not start"

# At least the 2 CPUs a task of glassdb-chunk.sbatch asks for (config_overrides: the node is
# taken as configured even on a 1-CPU machine).
cpus=$(nproc)
((cpus >= 2)) || cpus=2
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
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmdParameters=config_overrides
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
PartitionName=render Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$D/slurm.conf
slurmctld -i -f "$SLURM_CONF" </dev/null >"$D/slurmctld.stderr" 2>&1 || fail "slurmctld did not start"
slurmd -N "$host" -f "$SLURM_CONF" </dev/null >"$D/slurmd.stderr" 2>&1 || fail "slurmd did not start"
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qx idle && exit 0
    sleep 0.5
done
fail "the node of $SLURM_CONF is not idle after 30 s: $(sinfo -h -o '%T %E' 2>&1)"
