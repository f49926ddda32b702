#!/usr/bin/env bash
# `cmake --build build --target bench`: run the benchmarks with their default sizes.
set -euo pipefail
dir=${1:-build/bench}
echo "== the second core (two threads against one, without libmpmc)"; "$dir/bench_cores" 1
echo "== throughput (particle-steps per second)"; "$dir/bench_throughput" 20 1
echo "== return mapping (ns per call)"; OMP_NUM_THREADS=1 "$dir/bench_return_map"
echo "== water at rest, 5 s, 2D and 3D columns, every basis and K (about 4 min)"; OMP_NUM_THREADS=1 "$dir/water_at_rest"
