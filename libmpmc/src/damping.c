/* Damping for quasi-static stages.
 * Local damping (Cundall; Al-Kafaji 2013): per node and component
 *   f_damp = -alpha |f_int + f_ext| sign(v).
 * Kinetic damping (Cundall 1976; Topping & Khan, dynamic relaxation): the motion is left
 * undamped, the total kinetic energy of the points is tracked every step, and when it has
 * fallen after rising (a peak: the lowest mode passes its equilibrium) every point velocity
 * is set to zero and the tracking restarts from rest.
 * Adaptive viscous damping (adaptive dynamic relaxation: Underwood 1983; Papadrakakis 1981):
 * the grid update applies mass-proportional damping c m v with c = 2 zeta omega (zeta = 1:
 * critical for the lowest mode) in the central-difference form
 * (2 + c dt) v^{n+1} = (2 - c dt) v^n + 2 dt f/m.
 * omega^2 is a Rayleigh quotient dx.K dx / dx.M dx with dx = v dt and K dx = f^{n-1} - f^n,
 * the change of a node's out-of-balance force between two steps.  A Rayleigh quotient bounds
 * the lowest eigenvalue from above, exactly for a one-mode motion (t506's column: c within
 * 0.1 % of 2 omega_1); with several modes in the motion it overdamps the lowest, hence the
 * scenes' zeta 0.7 (docs/workflows.md).  The grid is rebuilt every step, but its nodes are
 * fixed in space: the quotient takes the nodes that held mass in both steps (a node store
 * of the last step's force, stamped with its step), which in a quasi-static stage is all of
 * them but the few the points leave or enter.  Over points it would need a second
 * interpolation a step (G2P's cost) for the same quotient.  Both sums run on the free
 * velocity components of those nodes, row by row, and add in row order: the same bits for
 * any thread count.  The per-step quotient is noisy (MPM's mapping, the start from rest),
 * so omega^2 is the ratio of the sums' exponential running means (num and den apart, so a
 * step with little motion weighs little), at least 0; the grid update caps c dt at 2 (the
 * update then never reverses a velocity).  Memory: (1 + dim) doubles a grid node. */
#include <math.h>
#include <stdlib.h>

#include "mpmc_impl.h"
#ifdef MPMC_HAVE_MPI
#include "mpmc_mpi.h"
#endif

/* the running means' memory: a step's sums weigh 1 - ADR_KEEP */
#define ADR_KEEP 0.9

void mpmc_damping_apply(double alpha, double *restrict f, const double *restrict v, int dim) {
  for (int a = 0; a < dim; ++a) {
    const double s = v[a] > 0.0 ? 1.0 : v[a] < 0.0 ? -1.0 : 0.0;
    f[a] -= alpha * (f[a] < 0 ? -f[a] : f[a]) * s;
  }
}

/* One O(n d) pass a step, against hundreds of flops a point in P2G and G2P.  The grid holds
 * no velocity from one step to the next (P2G rebuilds the momentum from the points, and
 * FLIP's increment dv is taken against that), so zero point velocities are the whole
 * restart. */
void mpmc_kinetic_damping(struct mpmc_sim_s *sim) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  double e = mpmc_points_kinetic_energy(sim); /* MPI: over the ranks, the same bits on each */
  if (sim->kd_ke >= 0.0 && e < sim->kd_ke) { /* past the peak */
    const size_t nv = (size_t)p->n * (size_t)d;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
    for (size_t k = 0; k < nv; ++k) p->v[k] = 0.0;
    sim->scr.v2max = 0.0; /* G2P's max |v|^2 (stability.c) */
    e = 0.0;
  }
  sim->kd_ke = e;
}

int mpmc_adaptive_damping_prepare(struct mpmc_sim_s *sim, long nrow) {
  const size_t need = sim->grid.nn * (size_t)(1 + sim->cfg.dim);
  if (sim->adr_nf != need) { /* a new grid: no node held mass in the last step */
    double *f = realloc(sim->adr_f, need * sizeof *f);
    MPMC_CHECK(f, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate adaptive damping's node store");
    for (size_t k = 0; k < need; ++k) f[k] = -2.0;
    sim->adr_f = f;
    sim->adr_nf = need;
  }
  if (sim->scr.adr_nrows < (size_t)nrow) {
    double *r = realloc(sim->scr.adr_rows, 2 * (size_t)nrow * sizeof *r);
    MPMC_CHECK(r, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate adaptive damping's row sums");
    sim->scr.adr_rows = r;
    sim->scr.adr_nrows = (size_t)nrow;
  }
  mpmc_adaptive_damping_own(sim, sim->adr_own);
  return MPMC_SUCCESS;
}

void mpmc_adaptive_damping_own(const struct mpmc_sim_s *sim, int own[3]) {
  own[0] = -1;
#ifdef MPMC_HAVE_MPI
  /* over MPI a halo node holds the same sums on both ranks (mpi.c): it counts on the rank
   * whose slab holds the cell above it, the top plane on the last rank; planes of the held
   * nodes (grid.off).  The ranks' planes cover the grid's, each once. */
  int rank, nranks, axis, lo, hi;
  if (sim->dd && !mpmc_sim_get_mpi_slab(sim, &rank, &nranks, &axis, &lo, &hi)) {
    const int off = sim->grid.off[axis]; /* the held nodes' planes */
    own[0] = axis;
    own[1] = lo - off;
    own[2] = (rank == nranks - 1 ? sim->grid.ng[axis] : hi) - off;
  }
#else
  (void)sim;
#endif
}

void mpmc_adaptive_damping_finish(struct mpmc_sim_s *sim, long nrow) {
  double num = 0.0, den = 0.0;
  for (long r = 0; r < nrow; ++r) {
    num += sim->scr.adr_rows[2 * r];
    den += sim->scr.adr_rows[2 * r + 1];
  }
  double both[2] = {num, den};
  mpmc_dd_sum(sim, both, 2); /* MPI: over the ranks, in rank order (the same c on each) */
  num = both[0];
  den = both[1];
  sim->adr_sum[0] = ADR_KEEP * sim->adr_sum[0] + (1.0 - ADR_KEEP) * num;
  sim->adr_sum[1] = ADR_KEEP * sim->adr_sum[1] + (1.0 - ADR_KEEP) * den;
  if (!(sim->adr_sum[1] > 0.0)) return; /* no motion yet: c stays */
  const double w2 = sim->adr_sum[0] / sim->adr_sum[1];
  sim->adr_c = w2 > 0.0 ? 2.0 * sim->cfg.adr_zeta * sqrt(w2) : 0.0;
}
