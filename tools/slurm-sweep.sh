#!/usr/bin/env bash
# tools/slurm-sweep.sh: runs `shadowlab sweep` as a Slurm job array of N shards, then a merge
# job that starts only when every shard succeeded (--dependency=afterok). Array task K runs
# `shadowlab sweep SCENE ... -o DIR --shard K/N` (with --resume when a requeued task finds its
# shard started), all into DIR on a file system every node sees; the merge job runs
# `shadowlab merge DIR`. See docs/sweep.md, "Sharded sweeps on Slurm".
#
# Usage: tools/slurm-sweep.sh -n N -o DIR [--only LIST] [--wait] [--sbatch "ARGS"] [--merge-sbatch "ARGS"] -- SCENE [sweep options]
#   -n N            shards (array tasks 0..N-1)
#   --only LIST     submit only these shards (a Slurm array list, e.g. "2,5" or "4-7"): reruns
#   -o DIR          the sweep's folder (shared file system); logs go to DIR/slurm/
#   --wait          return when the merge job has ended, with its exit status
#   --sbatch ARGS   extra sbatch options for the shard tasks (e.g. "-p batch -c 4 --time=2:00:00")
#   --merge-sbatch ARGS   extra sbatch options for the merge job
# Environment: SHADOWLAB, the program (default: app/shadowlab in SHADOWLAB_BUILD_DIR or build/ of
# this checkout).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
self="$root/tools/slurm-sweep.sh"
shadowlab="${SHADOWLAB:-${SHADOWLAB_BUILD_DIR:-$root/build}/app/shadowlab}"

# Inside the array: one shard. SLURM_ARRAY_TASK_COUNT is N for the whole array (older Slurm:
# MAX - MIN + 1); a rerun of some shards (--only) passes N, since its array is not all of them.
if [ "${1:-}" = "--task" ]; then
    dir="$2"
    n="$3"
    shift 3
    k="$SLURM_ARRAY_TASK_ID"
    [ "$n" = all ] && n="${SLURM_ARRAY_TASK_COUNT:-$((SLURM_ARRAY_TASK_MAX - SLURM_ARRAY_TASK_MIN + 1))}"
    resume=()
    [ -f "$dir/shard-$k-of-$n/results.jsonl" ] && resume=(--resume)
    echo "shadowlab shard $k/$n on $(hostname) (job $SLURM_JOB_ID, ${SLURM_CPUS_ON_NODE:-?} CPUs)"
    exec "$shadowlab" sweep "$@" -o "$dir" --shard "$k/$n" "${resume[@]}"
fi
if [ "${1:-}" = "--merge" ]; then
    shift
    exec "$shadowlab" merge "$1"
fi

usage() { sed -n '/^# Usage/,/^# Environment/p' "$self" | sed 's/^# \{0,1\}//' >&2; exit 2; }
n="" dir="" only="" wait=0 extra="" mergeExtra=""
while [ $# -gt 0 ]; do
    case "$1" in
        -n) n="$2"; shift 2 ;;
        -o) dir="$2"; shift 2 ;;
        --only) only="$2"; shift 2 ;;
        --wait) wait=1; shift ;;
        --sbatch) extra="$2"; shift 2 ;;
        --merge-sbatch) mergeExtra="$2"; shift 2 ;;
        --) shift; break ;;
        *) usage ;;
    esac
done
[ -n "$n" ] && [ -n "$dir" ] && [ $# -ge 1 ] || usage
[[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "slurm-sweep: -n must be a positive integer, got '$n'" >&2; exit 2; }
[ -x "$shadowlab" ] || { echo "slurm-sweep: $shadowlab is not built (tools/setup.sh) or set SHADOWLAB" >&2; exit 2; }
mkdir -p "$dir/slurm"
dir="$(cd "$dir" && pwd)"
# A job runs a copy of this script from Slurm's spool folder, where the checkout cannot be found
# from its path: the program's absolute path goes along in the environment.
shadowlab="$(cd "$(dirname "$shadowlab")" && pwd)/$(basename "$shadowlab")"
export SHADOWLAB="$shadowlab"

tasks="0-$((n - 1))" count=all
[ -n "$only" ] && { tasks="$only"; count="$n"; }
# shellcheck disable=SC2086  # ARGS are sbatch options, split on purpose
array=$(sbatch --parsable --export=ALL --array="$tasks" --job-name=shadowlab-sweep --chdir="$PWD" \
    --output="$dir/slurm/shard-%a.out" $extra "$self" --task "$dir" "$count" "$@")
array="${array%%;*}"
echo "slurm-sweep: shards: job array $array (tasks $tasks of $n), logs in $dir/slurm/"
waitArg=()
[ "$wait" = 1 ] && waitArg=(--wait)
# A shard that fails makes the dependency impossible: the merge job is cancelled, not left pending.
# shellcheck disable=SC2086
merge=$(sbatch --parsable --export=ALL --dependency="afterok:$array" --kill-on-invalid-dep=yes --job-name=shadowlab-merge \
    --chdir="$PWD" --output="$dir/slurm/merge.out" "${waitArg[@]}" $mergeExtra "$self" --merge "$dir") &&
    status=0 || status=$?
echo "slurm-sweep: merge: job ${merge%%;*}, after every shard succeeded$([ "$wait" = 1 ] && echo ", ended with status $status")"
exit "$status"
