#!/usr/bin/env bash
# Slurm in the mini-cluster, with plain programs: srun runs a step on two
# nodes, Open MPI's mpirun inside an salloc allocation launches through
# Slurm onto the allocated nodes, and the allocation is gone afterwards.
source "$(dirname "$0")/lib.sh"
cluster_up
needs_slurm

note "srun -N 2 hostname runs on two compute hosts"
got=$(on h0 srun -N 2 hostname | sort | paste -sd' ')
case "$got" in
  "h1 h2" | "h1 h3" | "h2 h3") ;;
  *) fail "srun -N 2 hostname gave '$got'" ;;
esac

note "salloc -n 2 mpirun hostname: one rank on each of two hosts (one CPU per node)"
got=$(on h0 salloc -n 2 mpirun hostname 2>/dev/null | sort | paste -sd' ')
case "$got" in
  "h1 h2" | "h1 h3" | "h2 h3") ;;
  *) fail "salloc -n 2 mpirun hostname gave '$got'" ;;
esac

note "no job is left in the queue, no job process on any host"
for ((i = 0; i < 50; i++)); do
  jobs=$(on h0 squeue -h -o '%i %T')
  [ -z "$jobs" ] && break
  sleep 0.2
done
[ -z "$jobs" ] || fail "jobs left in the queue: $jobs"
no_job_processes_within 5
note "ok"
