#!/usr/bin/env bash
# slurm-array.sh: one posedrop run as a Slurm job array of shards and a merge
# job that waits for them (docs/batch.md).
#
#   scripts/slurm-array.sh -N SHARDS [-o DIR] [-c CPUS] [-b POSEDROP]
#                          [-s 'SBATCH-OPTIONS'] -- POSEDROP-OPTIONS... PART
#
# Submits, with sbatch:
#   1. an array of SHARDS tasks; task K runs
#        posedrop POSEDROP-OPTIONS --shard K/SHARDS -j CPUS PART > DIR/shard_K.csv
#   2. a job that starts once every task has succeeded (afterok) and runs
#        posedrop merge DIR/shard_1.csv ... DIR/shard_SHARDS.csv > DIR/result.csv
# DIR/result.csv is then byte for byte what posedrop POSEDROP-OPTIONS PART
# prints on one machine. Logs go to DIR/shard_K.log and DIR/merge.log.
# -s passes options to both sbatch calls (e.g. '--partition=short --time=1:00:00').
# Prints the two job ids. Both jobs run in the current directory, so a PART
# given by a relative path is found by the merge as by the shards.
set -euo pipefail
. "$(dirname "$0")/args.sh"

usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; }
nshards=""
outdir=posedrop-slurm
cpus=1
bin=""
extra=""
while [ $# -gt 0 ]; do
    case "$1" in
        -N) args_value "$@"; nshards=$2; shift 2 ;;
        -o) args_value "$@"; outdir=$2; shift 2 ;;
        -c) args_value "$@"; cpus=$2; shift 2 ;;
        -b) args_value "$@"; bin=$2; shift 2 ;;
        -s) [ $# -ge 2 ] || args_die "-s needs a value"; extra=$2; shift 2 ;;
        --help) usage; exit 0 ;;
        --) shift; break ;;
        *) echo "slurm-array.sh: unknown option '$1' (options for posedrop go after --)" >&2; exit 2 ;;
    esac
done
case "$nshards" in
    ''|*[!0-9]*|0) echo "slurm-array.sh: -N: expected a number of shards >= 1" >&2; exit 2 ;;
esac
case "$cpus" in
    ''|*[!0-9]*|0) echo "slurm-array.sh: -c: expected a number of CPUs per task >= 1" >&2; exit 2 ;;
esac
[ $# -gt 0 ] || { echo "slurm-array.sh: no posedrop options and PART after --" >&2; exit 2; }
command -v sbatch >/dev/null || { echo "slurm-array.sh: sbatch not found (is this a Slurm login node?)" >&2; exit 2; }
if [ -z "$bin" ]; then
    here=$(cd "$(dirname "$0")/.." && pwd)
    bin=$(ls -t "$here"/build/*/posedrop 2>/dev/null | head -n 1) || true
    [ -n "$bin" ] || bin=$(command -v posedrop) ||
        { echo "slurm-array.sh: posedrop not found (run make, or give -b)" >&2; exit 2; }
fi
mkdir -p "$outdir"
# Absolute, so that the jobs find them whatever node they run on (a shared
# file system is assumed, as for any array job).
outdir=$(cd "$outdir" && pwd)
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")

# Shell-quoted for --wrap; the task id stays a variable for Slurm to set.
args=$(printf ' %q' "$@")
qbin=$(printf '%q' "$bin")
qdir=$(printf '%q' "$outdir")
shard_cmd="$qbin$args --shard \${SLURM_ARRAY_TASK_ID}/$nshards -j $cpus > $qdir/shard_\${SLURM_ARRAY_TASK_ID}.csv"
files=""
for k in $(seq 1 "$nshards"); do files="$files $qdir/shard_$k.csv"; done
merge_cmd="$qbin merge$files > $qdir/result.csv"

# shellcheck disable=SC2086 # -s holds several options on purpose
array_id=$(sbatch --parsable $extra --job-name=posedrop-shards --chdir="$PWD" \
    --array=1-"$nshards" --cpus-per-task="$cpus" --output="$outdir/shard_%a.log" \
    --wrap="$shard_cmd")
array_id=${array_id%%;*} # --parsable prints "id" or "id;cluster"
# shellcheck disable=SC2086
merge_id=$(sbatch --parsable $extra --job-name=posedrop-merge --chdir="$PWD" \
    --dependency=afterok:"$array_id" --output="$outdir/merge.log" --wrap="$merge_cmd")
merge_id=${merge_id%%;*}
echo "shards: job $array_id (array 1-$nshards); merge: job $merge_id -> $outdir/result.csv"
