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

/* What the loop keeps of point q's accepted return (F its dF-bar, be, ep, tau the results):
 * the region and plastic volume ratio, b_e, eps_p, sigma = tau / J less the pore pressure.
 * Returns 0, or 1 when the return failed or left a stress that is not finite or a J that is
 * not positive: then the point keeps its state. */
static inline int return_store(mpmc_particles *p, const double *Jm, int region, int q,
                               double F[3][3], const double be[6], double ep,
                               const double tau[6], const mpmc_return_out *out, int err) {
  if (err || !mpmc_stress_finite(tau) || !(Jm[q] > 0)) return 1;
  double *beq = p->be + (size_t)q * 6;
  if (region) {
    /* the plastic volume ratio: J_e,trial / J_e,new = det(dF) sqrt(det b_e^n) / J_e,new */
    if (p->Jp && out->plastic) p->Jp[q] *= mpmc_det3(F) * sqrt(mpmc_det_sym(beq)) / out->Je;
    p->region[q] = out->region;
  }
  for (int k = 0; k < 6; ++k) beq[k] = be[k];
  p->eps_p[q] = ep;
  double *s = p->stress + (size_t)q * 6;
  for (int k = 0; k < 6; ++k) s[k] = tau[k] / Jm[q];
  if (p->pw) /* effective to total stress under a water table (water.c) */
    for (int k = 0; k < 3; ++k) s[k] -= p->pw[q];
  return 0;
}

int mpmc_return_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                       const mpmc_return_ops *ops, const void *model) {
  return mpmc_return_update_blocks(sim, mat, id, ops, NULL, model);
}

int mpmc_return_update_blocks(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                              const mpmc_return_ops *ops, mpmc_return_block_fn block,
                              const void *model) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim, solver = sim->cfg.solver;
  mpmc_rm_ws **ws;
  MPMC_CALL(mpmc_rm_sim_workspaces(sim, mpmc_max_threads(), &ws));
  const double *Jm = sim->cfg.fbar ? p->Jbar : p->J;
  const int region = (mat->model->flags & MPMC_MODEL_REGION) != 0;
  const int nblk = (p->n + 3) / 4;
  int64_t nret = 0, nfb = 0;
  int first_bad = INT_MAX;
#pragma omp parallel reduction(min : first_bad) reduction(+ : nret, nfb) if (p->n > MPMC_OMP_MIN)
  {
    int tid = 0;
#ifdef _OPENMP
    tid = omp_get_thread_num();
#endif
    mpmc_rm_ws *w = ws[tid];
    /* blocks of four points fixed by the index (4k .. 4k + 3): a block of four points of
     * this material goes to block, the others one point at a time */
#pragma omp for schedule(static)
    for (int bk = 0; bk < nblk; ++bk) {
      const int q0 = 4 * bk;
      if (block && q0 + 3 < p->n && p->mat[q0] == id && p->mat[q0 + 1] == id &&
          p->mat[q0 + 2] == id && p->mat[q0 + 3] == id) {
        double F[4][3][3], be[4][6], tau[4][6], ep[4];
        mpmc_return_out out[4] = {{0}};
        int err[4];
        for (int l = 0; l < 4; ++l) {
          const int q = q0 + l;
          mpmc_embed(d, p->dF + (size_t)q * d * d, F[l]);
          for (int k = 0; k < 6; ++k) be[l][k] = p->be[(size_t)q * 6 + k];
          ep[l] = p->eps_p[q];
        }
        block(model, w, solver, F, be, ep, tau, out, err);
        for (int l = 0; l < 4; ++l) {
          const int q = q0 + l;
          if (return_store(p, Jm, region, q, F[l], be[l], ep[l], tau[l], &out[l], err[l])) {
            if (q < first_bad) first_bad = q; /* its state is left as it was */
            continue;
          }
          nret += out[l].plastic;
          nfb += out[l].fallback;
        }
        continue;
      }
      for (int q = q0; q < q0 + 4 && q < p->n; ++q) {
        if (p->mat[q] != id) continue;
        double F[3][3], be[6], tau[6], ep = p->eps_p[q];
        mpmc_embed(d, p->dF + (size_t)q * d * d, F);
        for (int k = 0; k < 6; ++k) be[k] = p->be[(size_t)q * 6 + k];
        mpmc_return_out out = {0};
        const int err = ops->point(model, w, solver, F, be, &ep, tau, &out);
        if (return_store(p, Jm, region, q, F, be, ep, tau, &out, err)) {
          if (q < first_bad) first_bad = q; /* its state is left as it was */
          continue;
        }
        nret += out.plastic;
        nfb += out.fallback;
      }
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
  const int d = sim->cfg.dim;
  const double *Jm = sim->cfg.fbar ? p->Jbar : p->J;
  mpmc_return_point pt = {.q = first_bad, .eps_p = p->eps_p[first_bad], .J = Jm[first_bad]};
  mpmc_embed(d, p->dF + (size_t)pt.q * d * d, pt.F);
  for (int k = 0; k < 6; ++k) pt.be[k] = p->be[(size_t)pt.q * 6 + k];
  for (int a = 0; a < d; ++a) pt.x[a] = p->x[(size_t)pt.q * d + a];
  mpmc_point_name(p, pt.q, pt.name);
  return fail(sim, mat, id, model, ws[0], &pt);
}
