/* The frictional models' shared update: for every point of the material, b_e pushed forward
 * by dF (dF-bar with F-bar on), the return map of return_mc.c (mpmc_mc_update: an elastic
 * check without eigen-decomposition, the principal-space return for the plastic points),
 * then the Cauchy stress tau / J (J-bar with F-bar on).  The material's sines, cosines and
 * cut-off are worked out once per call (mpmc_mc_prepare).  Points in parallel, each thread
 * with its own return-map workspace (KINSOL memory). */
#include <limits.h>
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "linalg.h"
#include "material_frictional.h"
#include "return_mc.h"

int mpmc_frictional_setup(mpmc_context ctx, mpmc_material *m) {
  mpmc_material_elastic(m);
  const double *par = m->par;
  MPMC_CHECK(par[MPMC_FR_PSI_R] <= par[MPMC_FR_PHI_R], ctx, MPMC_ERR_ARG,
             "%s: residual dilation angle psi_r = %g deg must not exceed the residual friction "
             "angle phi_r = %g deg",
             m->model->name, par[MPMC_FR_PSI_R], par[MPMC_FR_PHI_R]);
  MPMC_CHECK(par[MPMC_FR_C] > 0 || par[MPMC_FR_PHI] > 0, ctx, MPMC_ERR_ARG,
             "%s: cohesion c = 0 and friction angle phi = 0 leave no strength: give c > 0 or "
             "phi > 0",
             m->model->name);
  m->plastic = 1;
  return MPMC_SUCCESS;
}

double mpmc_frictional_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

static mpmc_mc_param frictional_param(const mpmc_material *mat, int surface) {
  const double *par = mat->par;
  return (mpmc_mc_param){.K = mat->K,
                         .G = mat->G,
                         .c_p = par[MPMC_FR_C],
                         .c_r = par[MPMC_FR_C_R],
                         .phi_p = par[MPMC_FR_PHI] * MPMC_RAD,
                         .phi_r = par[MPMC_FR_PHI_R] * MPMC_RAD,
                         .psi_p = par[MPMC_FR_PSI] * MPMC_RAD,
                         .psi_r = par[MPMC_FR_PSI_R] * MPMC_RAD,
                         .eta = par[MPMC_FR_ETA],
                         .sigma_t = par[MPMC_FR_SIGMA_T],
                         .surface = surface};
}

int mpmc_frictional_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                           int surface) {
  mpmc_particles *p = &sim->p;
  const int d = sim->dim, solver = sim->solver;
  const mpmc_mc_param mp = frictional_param(mat, surface);
  mpmc_mc_pre pre;
  mpmc_mc_prepare(&mp, &pre);
  mpmc_rm_ws **ws;
  MPMC_CALL(mpmc_rm_sim_workspaces(sim, mpmc_max_threads(), &ws));
  const double *Jm = sim->fbar ? p->Jbar : p->J;
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
      double F[3][3], be[6], tau[6], Je, ep = p->eps_p[q];
      mpmc_embed(d, p->dF + (size_t)q * d * d, F);
      double *beq = p->be + (size_t)q * 6;
      for (int k = 0; k < 6; ++k) be[k] = beq[k];
      mpmc_mc_info info = {0};
      const int err = mpmc_mc_update(w, solver, &pre, F, be, &ep, tau, &Je, &info);
      if (err || !mpmc_stress_finite(tau) || !(Jm[q] > 0)) {
        if (q < first_bad) first_bad = q; /* its state is left as it was */
        continue;
      }
      /* the plastic volume ratio: J_e,trial / J_e,new = det(dF) sqrt(det b_e^n) / J_e,new */
      if (p->Jp && info.plastic)
        p->Jp[q] *= mpmc_det3(F) * sqrt(mpmc_det_sym(beq)) / Je;
      for (int k = 0; k < 6; ++k) beq[k] = be[k];
      p->eps_p[q] = ep;
      p->region[q] = info.region;
      double *s = p->stress + (size_t)q * 6;
      for (int k = 0; k < 6; ++k) s[k] = tau[k] / Jm[q];
      if (p->pw) /* effective to total stress under a water table (water.c) */
        for (int k = 0; k < 3; ++k) s[k] -= p->pw[q];
      nret += info.plastic;
      nfb += info.fallback;
    }
  }
  sim->stats.return_maps += nret;
  sim->stats.kinsol_fallbacks += nfb;
  if (first_bad == INT_MAX) return MPMC_SUCCESS;
  /* repeat the failed point alone to report what went wrong */
  const int q = first_bad;
  double F[3][3], be[6], tau[6], Je, ep = p->eps_p[q];
  mpmc_embed(d, p->dF + (size_t)q * d * d, F);
  for (int k = 0; k < 6; ++k) be[k] = p->be[(size_t)q * 6 + k];
  mpmc_mc_info info = {0};
  const int err = mpmc_mc_update(ws[0], solver, &pre, F, be, &ep, tau, &Je, &info);
  const double *x = p->x + (size_t)q * d;
  char nb[MPMC_POINT_NAME_LEN];
  return MPMC_ERROR(sim->ctx, err ? err : MPMC_ERR_NUMERIC,
                    "step %lld, t = %g: %s return map of point %s at (%g, %g, %g) (material %d, "
                    "solver %s) failed: region %d, eps_p = %g, dgamma = %g, |f| = %g Pa, "
                    "KINSOL flag %d, J = %g",
                    (long long)sim->stats.steps, sim->time, mat->model->name,
                    mpmc_point_name(p, q, nb), x[0], x[1], d == 3 ? x[2] : 0.0, id,
                    mpmc_solver_name(solver), info.region, p->eps_p[q], info.dgamma, info.residual,
                    info.kinsol_flag, Jm[q]);
}
