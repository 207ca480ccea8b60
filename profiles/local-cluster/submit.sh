#!/usr/bin/env bash
# A stand-in for sbatch/qsub: run the job script given as the last argument in the
# background and print a job id (its PID). Snakemake learns the outcome from the
# job's marker files, as with a real batch system.
set -euo pipefail
script="${!#}"
mkdir -p results/logs/cluster
nohup bash "$script" > "results/logs/cluster/$(basename "$script").log" 2>&1 &
echo $!
