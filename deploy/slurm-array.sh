#!/usr/bin/env bash
# One campaign split over 8 Slurm array tasks: task i runs shard i of 8 into
# $RESULTS/shard-i. Submit, then merge when every task has finished:
#   RESULTS=/scratch/$USER/robustness sbatch deploy/slurm-array.sh
#   sbatch --dependency=afterok:JOBID --wrap "marsupial merge $RESULTS/shard-{1..8} \
#       --out $RESULTS/merged --scenario scenarios/bujold-robustness.toml"
# Run from the repository (the scenario's profile and photo paths are relative to it).
# A requeued task resumes its shard (--resume keeps its finished runs).
#SBATCH --job-name=marsupial-shards
#SBATCH --array=1-8
#SBATCH --cpus-per-task=2
#SBATCH --mem=2G
#SBATCH --time=02:00:00
#SBATCH --requeue
set -euo pipefail
: "${RESULTS:?set RESULTS to a folder every node can write}"
SCENARIO=${SCENARIO:-scenarios/bujold-robustness.toml}
N=${SLURM_ARRAY_TASK_COUNT:-8}
marsupial trials "$SCENARIO" --shard "${SLURM_ARRAY_TASK_ID}/${N}" \
    --jobs "${SLURM_CPUS_PER_TASK:-2}" --resume --out "$RESULTS/shard-${SLURM_ARRAY_TASK_ID}"
