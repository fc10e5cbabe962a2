#!/usr/bin/env bash
# tools/slurm-local-check.sh: runs tools/slurm-sweep.sh on a real single-node Slurm on this
# machine and checks the merged sweep against the unsharded one. It installs Debian's slurm-wlm
# and munge when missing (without starting their system services), writes a munge key and a
# slurm.conf into a temporary folder, starts munged, slurmctld and slurmd on localhost (free
# ports, nothing under /etc or /run), submits an N-task job array plus its dependent merge job,
# waits for it, compares rows, metrics and verdicts (not run times) with tests' sweep_equal, does
# the same after deleting one shard and rerunning it alone (--only), runs a four-frame path as a
# two-task array (`path --shard`) and checks its merge against the unsharded path, and
# stops the daemons and removes the folder whatever happens. Needs root (slurmd runs jobs as
# their user and munged guards its key). Usage: tools/slurm-local-check.sh [N]   (default 3);
# SLURM_CHECK_KEEP=1 keeps the folder (logs, both sweeps) for a look.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SHADOWLAB_BUILD_DIR:-$root/build}"
n="${1:-3}"
say() { echo "slurm check: $*" >&2; }

[ "$(id -u)" -eq 0 ] || { say "error: needs root (munged, slurmd)"; exit 2; }
for t in shadowlab sweep_equal; do
    [ -x "$build/app/$t" ] || [ -x "$build/tests/app/$t" ] || { say "error: build $t first (tools/setup.sh)"; exit 2; }
done
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge"
    # No service may start from the packages' scripts: this check starts its own daemons.
    policy=/usr/sbin/policy-rc.d
    made_policy=0
    if [ ! -e "$policy" ]; then
        printf '#!/bin/sh\nexit 101\n' >"$policy"
        chmod +x "$policy"
        made_policy=1
    fi
    export DEBIAN_FRONTEND=noninteractive
    { apt-get update -q && apt-get install -y -q --no-install-recommends slurm-wlm munge; } >&2 || status=$?
    [ "$made_policy" = 1 ] && rm -f "$policy"
    [ "${status:-0}" = 0 ] || { say "error: apt-get failed"; exit 2; }
fi

tmp="$(mktemp -d /tmp/shadowlab-slurm.XXXXXX)"
chmod 700 "$tmp"
pids=()
cleanup() {
    local status=$?
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true
    done
    if [ "$status" != 0 ]; then
        for log in "$tmp"/*.log "$tmp"/out/slurm/*.out; do
            [ -f "$log" ] && { echo "---- $log" >&2; tail -n 30 "$log" >&2; }
        done
    fi
    if [ -n "${SLURM_CHECK_KEEP:-}" ]; then say "kept $tmp"; else rm -rf "$tmp"; fi
    exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# A TCP port nothing listens on at 127.0.0.1 (bash's /dev/tcp connects or fails), picked at random
# so two checks at once rarely collide.
free_port() {
    local p
    for _ in $(seq 200); do
        p=$((20000 + RANDOM % 20000))
        (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null || { echo "$p"; return; }
    done
    say "error: no free port"; exit 1
}

# munge: its own key, socket, pid and log in the temporary folder.
dd if=/dev/urandom of="$tmp/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge.key"
munged --force --key-file="$tmp/munge.key" --socket="$tmp/munge.socket" --pid-file="$tmp/munged.pid" \
    --log-file="$tmp/munged.log" --seed-file="$tmp/munged.seed"
for _ in $(seq 50); do [ -s "$tmp/munged.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$tmp/munged.pid")")

host="$(hostname -s)"
cpus="$(nproc)"
mkdir -p "$tmp/state" "$tmp/spool"
cat >"$tmp/slurm.conf" <<CONF
ClusterName=shadowlab-check
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
AuthType=auth/munge
AuthInfo=socket=$tmp/munge.socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >"$tmp/slurmctld.stdout.log" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" >"$tmp/slurmd.stdout.log" 2>&1 &
pids+=($!)
for i in $(seq 200); do
    state="$(sinfo -h -n "$host" -o %t 2>/dev/null || true)"
    [ "$state" = idle ] && break
    [ "$i" = 200 ] && { say "error: the node did not come up within 60 s (state '${state:-none}')"; exit 1; }
    sleep 0.3
done
say "single-node Slurm up on $host ($cpus CPUs), $n shards"

# A tiny sweep: the quick grid of the seed scene at 48x27, one timed frame per row.
args=(seed --quick --resolution 48x27 --repetitions 1 --shadow-map-size 256)
"$build/app/shadowlab" sweep "${args[@]}" -o "$tmp/whole" 2>"$tmp/whole.log"
# A job that never starts (a node that went down) must not hang CI: ten minutes at most.
# The program found from the checkout, as a user runs it: not passed in SHADOWLAB.
env -u SHADOWLAB SHADOWLAB_BUILD_DIR="$build" timeout 600 "$root/tools/slurm-sweep.sh" -n "$n" -o "$tmp/out" --wait --sbatch "-c 1" \
    -- "${args[@]}"
for k in $(seq 0 $((n - 1))); do
    [ -f "$tmp/out/shard-$k-of-$n/shard.json" ] || { say "error: shard $k/$n left no folder"; exit 1; }
done
"$build/tests/app/sweep_equal" "$tmp/whole" "$tmp/out"
# A lost shard rerun alone (--only) and merged again.
rm -rf "$tmp/out/shard-1-of-$n" "$tmp/out/results.json"
env -u SHADOWLAB SHADOWLAB_BUILD_DIR="$build" timeout 600 "$root/tools/slurm-sweep.sh" -n "$n" -o "$tmp/out" --only 1 --wait \
    --sbatch "-c 1" -- "${args[@]}"
"$build/tests/app/sweep_equal" "$tmp/whole" "$tmp/out"
say "ok: the merged Slurm sweep equals the unsharded one, also after a shard rerun alone"

# A path sharded by frame (docs/temporal.md): two array tasks and the merge, against the unsharded path.
pargs=(seed --resolution 48x27 --shadow-map-size 256 --kind sun-azimuth --frames 4)
"$build/app/shadowlab" path "${pargs[@]}" -o "$tmp/path-whole" 2>"$tmp/path-whole.log"
timeout 300 sbatch --wait --array=0-1 -c 1 -o "$tmp/slurm-path-%a.out" \
    --wrap "'$build/app/shadowlab' path ${pargs[*]} -o '$tmp/path-out' --shard \$SLURM_ARRAY_TASK_ID/\$SLURM_ARRAY_TASK_COUNT" >/dev/null
"$build/app/shadowlab" merge "$tmp/path-out" 2>"$tmp/path-merge.log"
"$build/tests/app/sweep_equal" "$tmp/path-whole" "$tmp/path-out"
say "ok: the merged Slurm path equals the unsharded one"
