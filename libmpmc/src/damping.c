/* Damping for quasi-static stages.
 * Local damping (Cundall; Al-Kafaji 2013): per node and component
 *   f_damp = -alpha |f_int + f_ext| sign(v).
 * Kinetic damping (Cundall 1976; Topping & Khan, dynamic relaxation): the motion is left
 * undamped, the total kinetic energy of the points is tracked every step, and when it has
 * fallen after rising (a peak: the lowest mode passes its equilibrium) every point velocity
 * is set to zero and the tracking restarts from rest. */
#include "mpmc_impl.h"

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
  const int d = sim->dim;
  double e = 0.0;
#pragma omp parallel for reduction(+ : e) schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    double v2 = 0.0;
    for (int a = 0; a < d; ++a) v2 += p->v[(size_t)q * d + a] * p->v[(size_t)q * d + a];
    e += p->m[q] * v2;
  }
  mpmc_dd_sum(sim, &e, 1); /* MPI: over the ranks, the same bits on each */
  e *= 0.5;
  if (sim->kd_ke >= 0.0 && e < sim->kd_ke) { /* past the peak */
    const size_t nv = (size_t)p->n * (size_t)d;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
    for (size_t k = 0; k < nv; ++k) p->v[k] = 0.0;
    sim->v2max = 0.0; /* G2P's max |v|^2 (stability.c) */
    e = 0.0;
  }
  sim->kd_ke = e;
}
