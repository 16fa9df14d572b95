#!/usr/bin/env bash
# Submits an mcbench sweep to Slurm as N shards (one job-array task each) and a merge job that
# depends on all of them (afterok). See docs/src/scale-out.md.
#
#   scripts/slurm/submit.sh N NAME [mcbench run arguments...]
#
# NAME is the results folder to merge: the experiment's name, or a custom sweep's `name`.
#   scripts/slurm/submit.sh 8 transmittance transmittance --full
#   scripts/slurm/submit.sh 4 my-sweep --config my-sweep.toml --reps 256
# Environment: MCBENCH (binary, default `mcbench` on PATH), MCBENCH_RESULTS / MCBENCH_PLOTS
# (roots on a shared file system, default results/ and plots/ below the submission directory),
# SBATCH_EXTRA (extra sbatch options for both jobs, e.g. "--partition=long --time=2:00:00").
# Prints the two job ids: "<array job id> <merge job id>".
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [[ $# -lt 2 || ! "$1" =~ ^[1-9][0-9]*$ ]]; then
    echo "usage: $0 N NAME [mcbench run arguments...]   (N >= 1 shards)" >&2
    exit 2
fi
shards=$1 name=$2
shift 2
# shellcheck disable=SC2086
array=$(sbatch --parsable --export=ALL ${SBATCH_EXTRA:-} --array="1-$shards" "$here/shard.sbatch" "$@")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable --export=ALL ${SBATCH_EXTRA:-} --dependency="afterok:$array" \
    "$here/merge.sbatch" "$name" "$shards")
merge=${merge%%;*}
echo "$array $merge"
