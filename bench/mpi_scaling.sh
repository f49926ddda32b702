#!/usr/bin/env bash
# The column over MPI (bench_mpi.c, docs/mpi.md): 1 and 2 ranks x 1 and 2 OpenMP threads a
# rank, for each scene (`column`, bench_throughput's as it is: all its points in rank 0's
# slab on 2 ranks; `centred`: the cube halved by the cut), the speed-ups, then the model
# (bench_mpi --model).  Needs an MPI build:
#   cmake -S . -B build-mpi -DCMAKE_BUILD_TYPE=Release -DMPMC_WITH_MPI=ON && cmake --build build-mpi
#   bench/mpi_scaling.sh build-mpi/bench [steps] [scene ...]
# Each configuration runs MPMC_BENCH_ROUNDS times (default 3), the four in turn, and its
# least time per step is quoted (the run least disturbed by other load), and the least time
# outside MPI calls of the busiest rank (the time in them is waiting: for the other ranks'
# work or, on a loaded machine, for their turn on a core); halo and migration figures are per
# rank and step, the busiest rank's.  The CPU time outside MPI calls (the least over the
# rounds) is the work whatever the load; with one thread a rank one rank's over the busiest
# rank's bounds the speed-up of 2 ranks on free cores.  Ranks are not bound to cores
# (--bind-to none: a rank's two threads may use both); 2 ranks x 2 threads oversubscribe a
# 2-core machine.
set -euo pipefail
dir=${1:-build-mpi/bench}
steps=${2:-200}
rounds=${MPMC_BENCH_ROUNDS:-3}
shift $(($# > 2 ? 2 : $#))
if [ $# -gt 0 ]; then scenes=("$@"); else scenes=(column centred); fi
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
mpi=(mpiexec --bind-to none --oversubscribe)
echo "load before: $(uptime)"
for scene in "${scenes[@]}"; do
  lines=()
  for ((r = 0; r < rounds; ++r)); do
    for cfg in "1 1" "1 2" "2 1" "2 2"; do
      read -r ranks threads <<<"$cfg"
      lines+=("$("${mpi[@]}" -n "$ranks" -x OMP_NUM_THREADS="$threads" "$dir/bench_mpi" "$steps" \
        "$threads" "$scene")")
    done
  done
  printf '%s\n' "${lines[@]}" | awk -v scene="$scene" -v rounds="$rounds" '
    { for (i = 1; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] }
      c = (NR - 1) % 4 + 1; ms = f["ms_per_step"]; out = f["outside_mpi_ms_per_step"]
      cpu = f["cpu_outside_mpi_ms_per_step"]; all = f["cpu_outside_mpi_all_ranks"]
      if (NR <= 4) { for (k in f) v[c, k] = f[k]; lo[c] = hi[c] = ms; wo[c] = out; cm[c] = cpu }
      if (cpu <= cm[c]) { cm[c] = cpu; ca[c] = all }
      if (ms < lo[c]) { lo[c] = ms; v[c, "Mpoint_steps_per_s"] = f["Mpoint_steps_per_s"] }
      if (ms > hi[c]) hi[c] = ms
      if (out < wo[c]) wo[c] = out }
    END {
      printf "== %s, %d points, %d steps, the best of %d rounds (range of ms/step)\n", scene,
        v[1, "points"], v[1, "steps"], rounds
      printf "%-11s %9s %17s %11s %11s %9s %14s %12s %9s %11s %9s\n", "ranks x thr",
        "ms/step", "(range)", "outside MPI", "CPU outside", "M/s", "points a rank", "halo B/step",
        "halo msgs", "migr B/step", "migr msgs"
      for (c = 1; c <= 4; ++c)
        printf "%-11s %9.3f %17s %11.3f %11.3f %9.3f %14s %12d %9.2f %11d %9.2f\n",
          v[c, "ranks"] " x " v[c, "threads"], lo[c], sprintf("(%.3f-%.3f)", lo[c], hi[c]), wo[c],
          cm[c], v[c, "Mpoint_steps_per_s"], v[c, "points_per_rank"], v[c, "halo_B"],
          v[c, "halo_msgs"], v[c, "migration_B"], v[c, "migration_msgs"]
      printf "2 ranks over 1 rank: %.2fx (1 thread a rank), %.2fx (2 threads); 2 ranks x 1 " \
        "thread against 1 rank x 2 threads: %.2fx\n", lo[1] / lo[3], lo[2] / lo[4], lo[2] / lo[3]
      printf "outside MPI (the busiest rank'"'"'s least): 2 ranks over 1 rank %.2fx (1 thread), " \
        "%.2fx (2 threads)\n", wo[1] / wo[3], wo[2] / wo[4]
      printf "CPU time outside MPI, 1 thread a rank (the work, whatever the load): 1 rank " \
        "%.3f ms, 2 ranks %.3f ms summed, the busiest %.3f ms: %.2fx the work, 2 ranks over 1 " \
        "rank on free cores at most %.2fx\n", cm[1], ca[3], cm[3], ca[3] / cm[1], cm[1] / cm[3]
    }'
done
"${mpi[@]}" -n 2 "$dir/bench_mpi" --model "$steps"
echo "load after: $(uptime)"
