#!/usr/bin/env bash
# slurm.sh (make test-farm): farm/slurm-tiles.sh on a real one-node Slurm cluster on
# localhost: munged, slurmctld and slurmd started here with their config, key, sockets and
# state in a temporary directory (SlurmUser root, proctrack/linuxproc, task/none), a
# watchdog that kills them, the array of tiles x seeds and the merge that depends on it,
# and the merged image compared bit for bit with the same work done in one process.
# Skips (exit 77) where the daemons cannot be set up. Environment: GONIO, TESTTOOL.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$(dirname "$here")")
GONIO=$(realpath "${GONIO:-$root/build/gonio}") TESTTOOL=$(realpath "${TESTTOOL:-$root/build/release/testtool}")
export VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)}
skip() { echo "test-farm: skipped: $*"; exit 77; }
for c in munged slurmctld slurmd sbatch scontrol; do
    command -v $c >/dev/null || skip "$c is not installed (Debian: slurm-wlm, munge)"
done
[ "$(id -u)" = 0 ] || skip "the one-node cluster runs its daemons as root"
d=$(mktemp -d /tmp/gonio-slurm.XXXXXX)
chmod 755 "$d"
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
    sleep 1
    for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done
    [ -n "${watchdog:-}" ] && kill $(pgrep -P "$watchdog") "$watchdog" 2>/dev/null
    [ -n "${KEEP:-}" ] || rm -rf "$d"
}
trap cleanup EXIT
# The watchdog: whatever happens, the daemons are gone after 5 minutes.
( sleep 300; echo "test-farm: watchdog: killing the cluster" >&2; kill -9 "${pids[@]}" $$ ) >/dev/null 2>&1 &
watchdog=$!
port=$((20000 + RANDOM % 20000))
mkdir -p "$d/state" "$d/spool" "$d/work"
dd if=/dev/urandom of="$d/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$d/munge.key"
munged -f --key-file="$d/munge.key" --socket="$d/munge.sock" --pid-file="$d/munged.pid" \
    --log-file="$d/munged.log" --seed-file="$d/munge.seed" || skip "munged does not start: $(tail -n 3 "$d/munged.log" 2>/dev/null)"
sleep 0.5
pids+=("$(cat "$d/munged.pid")")
cpus=$(nproc)
cat >"$d/slurm.conf" <<CONF
ClusterName=gonio-test
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$d/munge.sock
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/slurmctld.log
SlurmdLogFile=$d/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=10 State=UP
CONF
export SLURM_CONF=$d/slurm.conf
slurmctld -D -i -f "$SLURM_CONF" >>"$d/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$SLURM_CONF" >>"$d/slurmd.out" 2>&1 &
pids+=($!)
up=
for _ in $(seq 60); do
    if scontrol show node localhost 2>/dev/null | grep -qE "State=(IDLE|MIXED)"; then up=1; break; fi
    sleep 0.5
done
[ -n "$up" ] || skip "the cluster did not come up: $(tail -n 5 "$d/slurmctld.log" "$d/slurmd.log" 2>/dev/null)"
echo "test-farm: cluster up (slurmctld port $port, $cpus CPUs, $(sinfo -V))"

t0=$(date +%s.%N)
ids=$(GONIO=$GONIO PARTS=$d/work/parts "$root/farm/slurm-tiles.sh" "$root/scenes/cornell.gltf" "$d/work/merged.exr" 2 2 2 4 48x32) \
    || { echo "test-farm: FAIL: sbatch: $ids"; exit 1; }
array=$(echo "$ids" | awk '{ print $2 }') merge=$(echo "$ids" | awk '{ print $4 }')
echo "test-farm: submitted array job $array (8 tasks: 2x2 tiles x 2 seeds), merge job $merge (afterok)"
state=
for _ in $(seq 240); do
    state=$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
    case $state in COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY) break ;; esac
    sleep 0.5
done
t1=$(date +%s.%N)
for k in $(seq 0 7); do
    echo "test-farm: job ${array}_$k: $(scontrol show job "${array}_$k" 2>/dev/null | grep -oE 'JobState=[A-Z_]+|RunTime=[0-9:]+' | tr '\n' ' ')"
done
echo "test-farm: job $merge (merge): $(scontrol show job "$merge" 2>/dev/null | grep -oE 'JobState=[A-Z_]+|RunTime=[0-9:]+' | tr '\n' ' ')"
echo "test-farm: wall time $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }') s from submission to the merge's end"
fails=0
if [ "$state" != COMPLETED ]; then
    echo "test-farm: FAIL: the merge job ended $state"; cat "$d"/work/parts/slurm-*.log 2>/dev/null | tail -n 20; fails=1
else
    # The same work in one process: the two seeds' whole renders, merged.
    for s in 0 1; do "$GONIO" render "$root/scenes/cornell.gltf" --size 48x32 --spp 4 --seed $s --quiet -o "$d/whole$s.exr"; done
    "$GONIO" merge "$d/whole0.exr" "$d/whole1.exr" -o "$d/whole.exr"
    if "$TESTTOOL" same "$d/whole.exr" "$d/work/merged.exr" && "$TESTTOOL" same "$d/work/merged.exr" "$d/whole.exr"; then
        echo "test-farm: the cluster's merged image equals the single-process render bit for bit"
    else
        echo "test-farm: FAIL: the cluster's image differs"; fails=1
    fi
fi
echo "test-farm: $((1 - fails)) passed, $fails failed"
exit $fails
