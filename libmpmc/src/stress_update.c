/* Stress update: each material updates its points from dF (dF-bar with F-bar on, which the
 * built-in materials form themselves when the step left F-bar's gather to them: fbar.c),
 * batched over the particle arrays; then the step's guard against NaN/Inf stress. */
#include <limits.h>
#include <math.h>

#include "mpmc_impl.h"

/** Phase 5 of the step. */
int mpmc_stress_update(mpmc_sim sim, double dt) {
  int err = MPMC_SUCCESS, guarded = 1;
  sim->scr.stress_bad = INT_MAX;
  mpmc_water_update(sim); /* the pore pressure at the points' new positions (with a table) */
  for (int m = 0; m < sim->nmat && !err; ++m) {
    err = sim->mats[m].ops->stress_update(sim, &sim->mats[m], m, dt);
    guarded &= sim->mats[m].ops->checks_stress;
  }
  sim->fb.deferred = 0; /* the materials ran F-bar's gather if the step left it to them */
  if (err) return err;
  const mpmc_particles *p = &sim->p;
  /* the guard: in the materials' own loops where they all keep it (Hencky-J2: a pass over
   * the stresses less), else here */
  int first_bad = sim->scr.stress_bad;
  if (!guarded) {
#pragma omp parallel for schedule(static) reduction(min : first_bad) if (p->n > MPMC_OMP_MIN)
    for (int q = 0; q < p->n; ++q)
      if (!mpmc_stress_finite(p->stress + (size_t)q * 6) && q < first_bad) first_bad = q;
  }
  if (first_bad != INT_MAX) {
    const int q = first_bad, d = sim->cfg.dim;
    const double *x = p->x + (size_t)q * d;
    char nb[MPMC_POINT_NAME_LEN];
    return MPMC_ERROR(sim->ctx, MPMC_ERR_NUMERIC,
                      "step %lld, t = %g: point %s at (%g, %g, %g) (material %d) has a non-finite "
                      "stress after the stress update",
                      (long long)sim->stats.steps, sim->time, mpmc_point_name(p, q, nb), x[0], x[1],
                      d == 3 ? x[2] : 0.0,
                      p->mat[q]);
  }
  return MPMC_SUCCESS;
}
