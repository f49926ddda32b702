/* What the benchmarks (bench/) read of a simulation beyond the public API, through functions
 * so that they need not include the private mpmc_impl.h.  Not part of the public API: the
 * functions are in the internal archive (mpmc_internal), not exported by libmpmc.so; a
 * benchmark includes mpmc.h and this header and links mpmc_internal. */
#ifndef MPMC_BENCH_H
#define MPMC_BENCH_H

#include <stddef.h>

#include "mpmc.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The bytes a point costs in the particle store: the fields this simulation has allocated
 * (plastic state, F-bar's and the step's scratch among them), its material id, its slab in
 * P2G's order and its id once the points have been sorted; the grid excluded.  0 for NULL. */
double mpmc_bench_bytes_per_point(mpmc_sim sim);
/* The grid's active box, node indices [lo, hi) per axis (after a step: the nodes P2G
 * reached, over MPI this rank's with its halo), and the bytes a node holds: its record
 * (mass, momentum, force and F-bar's nodal sums, as the halo sends it) and that with its wall
 * flags.  0, or MPMC_ERR_ARG for NULL. */
int mpmc_bench_grid(mpmc_sim sim, int lo[3], int hi[3], size_t *record_bytes, size_t *node_bytes);
/* The grid nodes this rank holds (over MPI its slab's and MPMC_GHOST planes beyond each cut)
 * and the whole grid's.  0, or MPMC_ERR_ARG for NULL. */
int mpmc_bench_grid_held(mpmc_sim sim, size_t *held, size_t *whole);
/* The ghost cells the grid adds beyond the box on each side, and the fewest cells an MPI slab
 * may have. */
void mpmc_bench_layout(int *ghost_cells, int *min_slab_cells);

#ifdef __cplusplus
}
#endif

#endif
