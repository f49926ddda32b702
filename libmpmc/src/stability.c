/* Stable time step: dt = factor h / max_p (c_p + |v_p|), c_p the p-wave speed of the
 * point's material (fluids: sqrt(K/rho); viscosity limit h^2 rho / (2 mu) as well). */
#include <math.h>

#include "mpmc_impl.h"

double mpmc_stability_limit(const struct mpmc_sim_s *sim, double factor) {
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  double cmax = 0.0, visc = INFINITY;
  for (int m = 0; m < sim->nmat; ++m) {
    const double c = sim->mats[m].ops->wave_speed(&sim->mats[m]);
    if (c > cmax) cmax = c;
    if (sim->mats[m].mu > 0) {
      const double t = sim->grid.h * sim->grid.h * sim->mats[m].rho / (2.0 * sim->mats[m].mu);
      if (t < visc) visc = t;
    }
  }
  double vmax = 0.0;
  if (sim->scr.v2max_ok) {
    vmax = sim->scr.v2max; /* G2P's, the same sums (g2p.c) */
  } else {
#pragma omp parallel for reduction(max : vmax) schedule(static) if (p->n > MPMC_OMP_MIN)
    for (int q = 0; q < p->n; ++q) {
      double v2 = 0.0;
      for (int a = 0; a < d; ++a) v2 += p->v[(size_t)q * d + a] * p->v[(size_t)q * d + a];
      if (v2 > vmax) vmax = v2;
    }
  }
  mpmc_dd_max(sim, &vmax, 1); /* MPI: over the ranks (collective) */
  vmax = sqrt(vmax);
  double dt = cmax + vmax > 0 ? sim->grid.h / (cmax + vmax) : INFINITY;
  if (visc < dt) dt = visc;
  if (sim->bodies) {
    const double tc = mpmc_contact_stable_dt(sim);
    if (tc < dt) dt = tc;
  }
  return factor * dt;
}

/**
 * @brief The stable time step factor * h / max(c + |v|).
 * @param factor Courant factor in (0, 1] (the paper uses 0.3-0.4)
 */
int mpmc_sim_stable_dt(mpmc_sim sim, double factor, double *dt) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(dt, sim->ctx, MPMC_ERR_ARG, "dt pointer is NULL");
  MPMC_CHECK(isfinite(factor) && factor > 0 && factor <= 1, sim->ctx, MPMC_ERR_ARG,
             "time-step factor = %g must be in (0, 1]", factor);
  MPMC_CHECK(sim->grid.valid && sim->nmat > 0, sim->ctx, MPMC_ERR_STATE,
             "the stable time step needs a grid and a material");
  *dt = mpmc_stability_limit(sim, factor);
  return MPMC_SUCCESS;
}
