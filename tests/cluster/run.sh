#!/bin/sh
# tests/cluster/run.sh BUILD_DIR (`make test-cluster`, not part of `make test`): a
# one-node Slurm in a temporary folder runs a sweep's job array. munged with a
# generated key and its own socket, slurmctld and slurmd with a generated slurm.conf
# (this host the only node, proctrack/linuxproc, task/none, state and spool in the
# folder, ports of their own), all in the background and stopped by the trap at the
# end; `sbatch --wait` runs DIR/sweep.slurm, then `wobble collect` must show every run
# ok with its output under runs/NNNN/. Needs root (the daemons run as root) and the
# Debian packages slurm-wlm and munge. Last line: "N passed, N failed".
BUILD=${1:-build}
cd "$(dirname "$0")/../.." || exit 2
W="$(pwd)/$BUILD/wobble"
F="$(pwd)/tests/cli/fixtures"
T=$(mktemp -d "${TMPDIR:-/tmp}/wobble-cluster.XXXXXX") || exit 2
chmod 755 "$T"   # munged wants its socket's folder searchable by all
TMP=$T
. tests/cli/lib.sh
pids=""
stop() {
    for p in $pids; do kill "$p" 2>/dev/null; done
    for p in $pids; do wait "$p" 2>/dev/null; done
    rm -rf "$T"
}
trap stop EXIT
trap 'exit 130' INT TERM

if [ "$(id -u)" != 0 ]; then
    echo "not ok 1 - the one-node Slurm needs root (its daemons run as root)"
    echo "0 passed, 1 failed"
    exit 1
fi
for prog in munged slurmctld slurmd sbatch sinfo; do
    if ! command -v $prog >/dev/null 2>&1; then
        echo "not ok 1 - $prog not found: install slurm-wlm and munge (make test-cluster does)"
        echo "0 passed, 1 failed"
        exit 1
    fi
done

# fail NAME: one failed check with the daemons' logs, then the end
fail() {
    result "$1" "see the logs below"
    for f in "$T"/*.log; do [ -e "$f" ] && tail -n 20 "$f" | sed "s|^|  # $(basename "$f"): |"; done
    echo "$passed passed, $failed failed"
    exit 1
}

# munge: a key of our own, its own socket
dd if=/dev/urandom of="$T/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$T/munge.key"
munged -F -f --key-file="$T/munge.key" --socket="$T/munge.sock" --pid-file="$T/munged.pid" \
    --log-file="$T/munged.log" --seed-file="$T/munge.seed" 2>>"$T/munged.log" &
pids="$!"
i=0
while [ ! -S "$T/munge.sock" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
[ -S "$T/munge.sock" ] && result "munged runs on its own socket" "" || fail "munged runs on its own socket"

# slurm.conf: this host as the only node; ports from the process id, so two of these
# tests (or a real Slurm on the default ports) do not meet
host=$(hostname -s)
port=$((20000 + $$ % 20000))
cpus=$(nproc)
mem=$(awk '/^MemTotal/ { m = int($2 / 1024) - 512; print (m > 1024 ? m : 1024) }' /proc/meminfo)
mkdir -p "$T/state" "$T/spool"
cat >"$T/slurm.conf" <<CONF
ClusterName=wobbletest
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge.sock
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=wobble Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$T/slurm.conf"
slurmctld -D -i -f "$T/slurm.conf" >>"$T/slurmctld.log" 2>&1 &
pids="$! $pids"
slurmd -D -f "$T/slurm.conf" >>"$T/slurmd.log" 2>&1 &
pids="$! $pids"
i=0
state=""
while [ $i -lt 60 ]; do
    state=$(sinfo -h -N -o %T 2>/dev/null | head -n 1)
    [ "$state" = idle ] && break
    for p in $pids; do kill -0 "$p" 2>/dev/null || fail "slurmctld and slurmd up (a daemon ended)"; done
    sleep 1
    i=$((i + 1))
done
[ "$state" = idle ] && result "slurmctld and slurmd up, the node idle" "" || fail "slurmctld and slurmd up, the node idle (state '$state')"

# the sweep: 2 x 2 runs of the tiny scene, with the limits that size the tasks
S=$T/sweep
"$W" sweep "$F/sweep_scene.lua" --grid g=1,2 --grid n=1,2 --out "$S" --time-limit 120 --memory-limit 256 \
    >"$T/out" 2>"$T/err"
code=$?
check "wobble sweep writes the array" 0 out "sbatch $S/sweep.slurm"
timeout 600 sbatch --wait "$S/sweep.slurm" >"$T/out" 2>"$T/err"
code=$?
check "sbatch --wait runs the array" 0 out "Submitted batch job"
"$W" collect "$S" --csv >"$T/out" 2>"$T/err"
code=$?
check "collect: every run of the array ended ok" 0 out "0001,ok,0,1,1," out "0002,ok,0,1,2," out "0003,ok,0,2,1," \
    out "0004,ok,0,2,2," !out ",missing," !out ",crashed,"
why=""
for r in 0001 0002 0003 0004; do [ -e "$S/runs/$r/output.txt" ] || why="${why:+$why; }no runs/$r/output.txt"; done
result "each task's output under runs/NNNN/" "$why"
ls "$S/slurm/"*_1.out >/dev/null 2>&1 && why="" || why="no slurm/JOB_1.out"
result "Slurm's own output in DIR/slurm/" "$why"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
