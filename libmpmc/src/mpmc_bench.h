/* What the benchmarks (bench/) read of a simulation beyond the public API, through functions
 * so that they need not include the private mpmc_impl.h.  Not part of the public API: the
 * functions are in the internal archive (mpmc_internal), not exported by libmpmc.so; a
 * benchmark includes mpmc.h and this header and links mpmc_internal. */
#ifndef MPMC_BENCH_H
#define MPMC_BENCH_H

#include "mpmc.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The bytes a point costs in the particle store: the fields this simulation has allocated
 * (plastic state, F-bar's and the step's scratch among them), its material id, its slab in
 * P2G's order and its id once the points have been sorted; the grid excluded.  0 for NULL. */
double mpmc_bench_bytes_per_point(mpmc_sim sim);

#ifdef __cplusplus
}
#endif

#endif
