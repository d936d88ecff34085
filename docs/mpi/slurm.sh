#!/usr/bin/env bash
# One grains run over several nodes under Slurm (an example to adapt: partition, modules, paths).
# Build first on the cluster with its MPI: `cargo build --release --features mpi`.
#SBATCH --job-name=grains
#SBATCH --nodes=2
#SBATCH --ntasks-per-node=2        # processes per node: each owns one slab of the domain
#SBATCH --cpus-per-task=8          # threads per process (grains --threads)
#SBATCH --time=12:00:00
#SBATCH --output=grains-%j.log
set -euo pipefail
# module load openmpi             # the MPI grains was built against
srun --cpu-bind=cores target/release/grains run scenes/pour.toml --out "out/pour-$SLURM_JOB_ID" --threads "$SLURM_CPUS_PER_TASK"
# A stopped job continues from its last checkpoint on any number of processes:
#   srun target/release/grains run --resume out/pour-JOBID --threads "$SLURM_CPUS_PER_TASK"
