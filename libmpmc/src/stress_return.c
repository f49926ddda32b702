/* The point-by-point stress update of the return-mapping materials (stress_return.h): the
 * loop the frictional models and the user yield surfaces share, with the model's return map
 * per point. */
#include <limits.h>
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "linalg.h"
#include "stress_return.h"

int mpmc_return_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                       const mpmc_return_ops *ops, const void *model) {
  mpmc_particles *p = &sim->p;
  const int d = sim->dim, solver = sim->solver;
  mpmc_rm_ws **ws;
  MPMC_CALL(mpmc_rm_sim_workspaces(sim, mpmc_max_threads(), &ws));
  const double *Jm = sim->fbar ? p->Jbar : p->J;
  const int region = (mat->model->flags & MPMC_MODEL_REGION) != 0;
  int64_t nret = 0, nfb = 0;
  int first_bad = INT_MAX;
#pragma omp parallel reduction(min : first_bad) reduction(+ : nret, nfb) if (p->n > MPMC_OMP_MIN)
  {
    int tid = 0;
#ifdef _OPENMP
    tid = omp_get_thread_num();
#endif
    mpmc_rm_ws *w = ws[tid];
#pragma omp for schedule(static)
    for (int q = 0; q < p->n; ++q) {
      if (p->mat[q] != id) continue;
      double F[3][3], be[6], tau[6], ep = p->eps_p[q];
      mpmc_embed(d, p->dF + (size_t)q * d * d, F);
      double *beq = p->be + (size_t)q * 6;
      for (int k = 0; k < 6; ++k) be[k] = beq[k];
      mpmc_return_out out = {0};
      const int err = ops->point(model, w, solver, F, be, &ep, tau, &out);
      if (err || !mpmc_stress_finite(tau) || !(Jm[q] > 0)) {
        if (q < first_bad) first_bad = q; /* its state is left as it was */
        continue;
      }
      if (region) {
        /* the plastic volume ratio: J_e,trial / J_e,new = det(dF) sqrt(det b_e^n) / J_e,new */
        if (p->Jp && out.plastic)
          p->Jp[q] *= mpmc_det3(F) * sqrt(mpmc_det_sym(beq)) / out.Je;
        p->region[q] = out.region;
      }
      for (int k = 0; k < 6; ++k) beq[k] = be[k];
      p->eps_p[q] = ep;
      double *s = p->stress + (size_t)q * 6;
      for (int k = 0; k < 6; ++k) s[k] = tau[k] / Jm[q];
      if (p->pw) /* effective to total stress under a water table (water.c) */
        for (int k = 0; k < 3; ++k) s[k] -= p->pw[q];
      nret += out.plastic;
      nfb += out.fallback;
    }
  }
  return mpmc_return_finish(sim, mat, id, ops->fail, model, ws, nret, nfb, first_bad);
}

int mpmc_return_finish(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                       mpmc_return_fail_fn fail, const void *model, mpmc_rm_ws **ws,
                       int64_t nret, int64_t nfb, int first_bad) {
  sim->stats.return_maps += nret;
  sim->stats.kinsol_fallbacks += nfb;
  if (first_bad == INT_MAX) return MPMC_SUCCESS;
  /* the failed point, for the model to repeat alone and report what went wrong */
  const mpmc_particles *p = &sim->p;
  const int d = sim->dim;
  const double *Jm = sim->fbar ? p->Jbar : p->J;
  mpmc_return_point pt = {.q = first_bad, .eps_p = p->eps_p[first_bad], .J = Jm[first_bad]};
  mpmc_embed(d, p->dF + (size_t)pt.q * d * d, pt.F);
  for (int k = 0; k < 6; ++k) pt.be[k] = p->be[(size_t)pt.q * 6 + k];
  for (int a = 0; a < d; ++a) pt.x[a] = p->x[(size_t)pt.q * d + a];
  mpmc_point_name(p, pt.q, pt.name);
  return fail(sim, mat, id, model, ws[0], &pt);
}
