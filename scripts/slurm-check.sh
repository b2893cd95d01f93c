#!/usr/bin/env bash
# A sharded bake on a real Slurm (issue 40): one local node, examples/slurm/bake-array.sbatch
# submitted unchanged (only its SHARDS and OUT paths are set, through the environment it reads),
# and the merged tables compared byte for byte with the same bake unsharded.
#
#   scripts/slurm-check.sh [path/to/kiln]
#
# Installs Debian's slurmctld, slurmd, slurm-client and munge when missing (as root), starts
# munged, slurmctld and slurmd under a configuration of its own in a temporary directory (a node
# that claims the 8 CPUs the script asks per task, so its eight tasks run in turn on a small
# machine), waits at most KILN_SLURM_TIMEOUT seconds (default 600) and stops its daemons however
# it ends. Exits non-zero if any step fails or the tables differ.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$PWD"
kiln="$(realpath "${1:-target/release/kiln}")"
timeout_seconds="${KILN_SLURM_TIMEOUT:-600}"
test -x "$kiln" || { echo "slurm-check: no kiln binary at $kiln (cargo build --release)" >&2; exit 1; }

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
    || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    echo "slurm-check: installing slurmctld slurmd slurm-client munge"
    export DEBIAN_FRONTEND=noninteractive
    packages=(slurmctld slurmd slurm-client munge)
    apt-get install -y --no-install-recommends "${packages[@]}" >/dev/null \
        || { apt-get update >/dev/null \
            && apt-get install -y --no-install-recommends "${packages[@]}" >/dev/null; }
fi

work="$(mktemp -d /tmp/kiln-slurm.XXXXXX)"
chmod 755 "$work"
pids=()
cleanup() {
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    sleep 1
    for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null || true; done
    rm -rf "$work"
}
trap cleanup EXIT

# munge: a key and a socket of our own.
mkdir -p "$work/munge" "$work/spool/ctld" "$work/spool/d" "$work/log" "$work/job"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$work/munge"
chmod 400 "$work/munge/munge.key"
socket="$work/munge/munge.socket"
munged --key-file="$work/munge/munge.key" --socket="$socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/seed" --force --foreground 2>>"$work/log/munged.err" &
pids+=($!)

host="$(hostname -s)"
cat >"$work/slurm.conf" <<EOF
ClusterName=kiln-check
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
StateSaveLocation=$work/spool/ctld
SlurmdSpoolDir=$work/spool/d
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
NodeName=$host CPUs=8 State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$work/slurm.conf"

# Wait until munge answers.
for _ in $(seq 50); do
    munge --socket="$socket" -n </dev/null >/dev/null 2>&1 && break
    sleep 0.2
done
slurmctld -D -i -f "$SLURM_CONF" 2>>"$work/log/slurmctld.err" &
pids+=($!)
slurmd -D -f "$SLURM_CONF" 2>>"$work/log/slurmd.err" &
pids+=($!)

deadline=$((SECONDS + timeout_seconds))
until sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; do
    if ((SECONDS > deadline)); then
        echo "slurm-check: the node never came up" >&2
        tail -n 20 "$work/log/slurmctld.log" "$work/log/slurmd.log" >&2 || true
        exit 1
    fi
    sleep 0.5
done
echo "slurm-check: node $host up ($(sinfo -h -o '%c CPUs, %T'))"

# The array, unchanged: kiln on the PATH, the shard and output directories through the
# environment the script reads (sbatch passes the environment on).
export PATH="$(dirname "$kiln"):$PATH"
export SHARDS="$work/job/shards" OUT="$work/job/tables"
cd "$work/job"
array_job="$(sbatch --parsable "$repo/examples/slurm/bake-array.sbatch")"
echo "slurm-check: submitted array job $array_job"

# Wait for the array and the merge it submits: no job left in the queue, and a merge log.
started=$SECONDS
while :; do
    if ((SECONDS > deadline)); then
        echo "slurm-check: timed out after ${timeout_seconds} s" >&2
        squeue >&2 || true
        exit 1
    fi
    sleep 1
    if [ -z "$(squeue -h -o '%i' 2>/dev/null)" ] && ls kiln-merge-*.log >/dev/null 2>&1; then
        break
    fi
done
echo "slurm-check: array and merge finished in $((SECONDS - started)) s"
for log in kiln-shard-*.log kiln-merge-*.log; do
    if grep -qi 'error' "$log"; then
        echo "slurm-check: $log:" >&2
        cat "$log" >&2
        exit 1
    fi
done

# The same bake unsharded, with the script's own arguments.
bake_args="$(sed -n 's/^BAKE_ARGS=(\(.*\))$/\1/p' "$repo/examples/slurm/bake-array.sbatch")"
test -n "$bake_args" || { echo "slurm-check: no BAKE_ARGS line in the script" >&2; exit 1; }
# shellcheck disable=SC2086
"$kiln" bake $bake_args --out "$work/job/unsharded" --quiet
merged=$(find "$OUT" -type f | wc -l)
test "$merged" -gt 0 || { echo "slurm-check: the merge wrote nothing to $OUT" >&2; exit 1; }
(cd "$work/job/unsharded" && find . -type f | sort) >"$work/unsharded.list"
(cd "$OUT" && find . -type f | sort) >"$work/merged.list"
diff "$work/unsharded.list" "$work/merged.list" >&2 \
    || { echo "slurm-check: the merge wrote other files than the bake" >&2; exit 1; }
while read -r file; do
    cmp "$work/job/unsharded/$file" "$OUT/$file"
done <"$work/unsharded.list"
echo "slurm-check: $merged merged files byte-identical to the unsharded bake"
