/* The kernel sets (kernels.c): the phases of a step and the stress blocks of the built-in
 * materials, compiled once per instruction set; the sim runs the set mpmc_kernels_of gives. */
#ifndef MPMC_KERNELS_H
#define MPMC_KERNELS_H

#include "mpmc_impl.h"
#include "return_map.h"

typedef struct {
  int (*slabs)(mpmc_sim);
  int (*p2g)(mpmc_sim, double);
  int (*grid_update)(mpmc_sim, double);
  int (*g2p)(mpmc_sim, double);
  int (*fbar)(mpmc_sim, int);
  mpmc_j2_batch_fn j2_batch;
  mpmc_stress_batch_fn nh_batch, hencky_batch, newtonian_batch;
} mpmc_kernel_set;

/* the set the sim's step runs (mpmc_sim_set_kernels) */
const mpmc_kernel_set *mpmc_kernels_of(const struct mpmc_sim_s *sim);
/* the sim's set from MPMC_KERNELS (unset: auto), refused where it cannot run */
int mpmc_kernels_from_env(struct mpmc_sim_s *sim);
/* a checkpoint's set, where it runs and MPMC_KERNELS names none (kernels.c) */
int mpmc_kernels_restore(struct mpmc_sim_s *sim, int saved);

#endif
