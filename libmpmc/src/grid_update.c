/* Grid update (eq 9): nodal velocities from momentum and forces, gravity, local damping,
 * wall constraints.  Leaves the new velocity in mom and the increment v^{n+1} - v^n in
 * force, which is what G2P's FLIP/PIC blend needs. */
#include "mpmc_impl.h"

static inline void update_impl(mpmc_sim sim, const int DIM, double dt) {
  mpmc_grid *g = &sim->grid;
  const double alpha = sim->damping;
  const double *gr = sim->gravity;
  double *restrict gm = g->mass, *restrict gp = g->mom, *restrict gf = g->force;
  const unsigned short *restrict fx = g->fixed;
  const long nn = (long)g->nn;
#pragma omp parallel for schedule(static)
  for (long i = 0; i < nn; ++i) {
    const double m = gm[i];
    if (m <= 0.0) continue;
    const double inv_m = 1.0 / m;
    double v0[3], f[3], v1[3];
    for (int a = 0; a < DIM; ++a) {
      v0[a] = gp[i * DIM + a] * inv_m;
      f[a] = gf[i * DIM + a] + m * gr[a];
    }
    if (alpha > 0.0) mpmc_damping_apply(alpha, f, v0, DIM);
    for (int a = 0; a < DIM; ++a) v1[a] = v0[a] + dt * f[a] * inv_m;
    const unsigned fl = fx[i];
    if (fl) {
      for (int a = 0; a < DIM; ++a) {
        if (fl & (1u << a)) v1[a] = 0.0;
        if ((fl & (8u << a)) && v1[a] < 0.0) v1[a] = 0.0;
        if ((fl & (64u << a)) && v1[a] > 0.0) v1[a] = 0.0;
      }
    }
    for (int a = 0; a < DIM; ++a) {
      gp[i * DIM + a] = v1[a];
      gf[i * DIM + a] = v1[a] - v0[a];
    }
  }
}

/** Phase 2 of the step. */
int mpmc_grid_update(mpmc_sim sim, double dt) {
  if (sim->walls_dirty) MPMC_CALL(mpmc_boundary_apply_flags(sim));
  if (sim->dim == 2)
    update_impl(sim, 2, dt);
  else
    update_impl(sim, 3, dt);
  return MPMC_SUCCESS;
}
