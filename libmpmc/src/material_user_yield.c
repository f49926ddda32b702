/* User yield surfaces: Hencky elasticity (E, nu) with the caller's yield function, flow
 * direction and hardening (mpmc_yield_fn, C or Fortran), returned to by the library's
 * closest-point projection (return_cpp.h: Newton on the 7x7 system, KINSOL as the fallback,
 * LAPACK loaded at the first plastic point).  The hardening variable alpha, the accumulated
 * plastic multiplier, is kept per point as eps_p.  When a return fails, the error names the
 * point, the reason and the derivative that a central-difference check finds wrong. */
#include <limits.h>
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "linalg.h"
#include "return_cpp.h"

extern const mpmc_model mpmc_model_user_yield;

static int uy_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  mpmc_particles *p = &sim->p;
  const int d = sim->dim, solver = sim->solver;
  const mpmc_cpp_param cp = {.K = mat->K, .G = mat->G, .fn = mat->yield_fn, .data = mat->user_data};
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
      double F[3][3], tau[6], Je;
      mpmc_embed(d, p->dF + (size_t)q * d * d, F);
      mpmc_cpp_info info;
      info.plastic = info.fallback = 0;
      /* be and eps_p are left unchanged on failure */
      const int err = mpmc_cpp_return_map(w, solver, &cp, F, p->be + (size_t)q * 6,
                                          p->eps_p + q, tau, &Je, &info);
      if (err || !mpmc_stress_finite(tau) || !(Jm[q] > 0)) {
        if (q < first_bad) first_bad = q;
        continue;
      }
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
  /* repeat the failed point alone, then check the function's derivatives at its trial
   * state: a wrong derivative is the usual cause */
  const int q = first_bad;
  double F[3][3], be[6], tau[6], Je, alpha = p->eps_p[q];
  mpmc_embed(d, p->dF + (size_t)q * d * d, F);
  for (int k = 0; k < 6; ++k) be[k] = p->be[(size_t)q * 6 + k];
  mpmc_cpp_info info = {0};
  int err = mpmc_cpp_return_map(ws[0], solver, &cp, F, be, &alpha, tau, &Je, &info);
  char deriv[200] = "";
  double btr[6], lam[3], Q[3][3], eps[3], t[3];
  for (int k = 0; k < 6; ++k) btr[k] = p->be[(size_t)q * 6 + k];
  mpmc_push_forward(F, btr);
  mpmc_sym3_eig(btr, lam, Q);
  if (lam[0] > 0 && lam[1] > 0 && lam[2] > 0) {
    for (int a = 0; a < 3; ++a) eps[a] = 0.5 * log(lam[a]);
    const double tr = eps[0] + eps[1] + eps[2];
    for (int a = 0; a < 3; ++a) t[a] = mat->K * tr + 2.0 * mat->G * (eps[a] - tr / 3.0);
    double ttr[6], worst = 0;
    char name[64] = "";
    mpmc_sym3_compose(t, Q, ttr);
    if (!mpmc_cpp_check_derivatives(&cp, ttr, p->eps_p[q], &worst, name, sizeof name) &&
        worst > 1e-4)
      snprintf(deriv, sizeof deriv,
               "; at the trial stress the function's %s differs from central differences by "
               "%.3g relative: check the yield function's derivatives",
               name, worst);
  }
  const double *x = p->x + (size_t)q * d;
  char nb[MPMC_POINT_NAME_LEN];
  if (!err) err = MPMC_ERR_NUMERIC;
  return MPMC_ERROR(sim->ctx, err,
                    "step %lld, t = %g: user yield surface (material %d, solver %s) failed at "
                    "point %s (%g, %g, %g): %s%s",
                    (long long)sim->stats.steps, sim->time, id, mpmc_solver_name(solver),
                    mpmc_point_name(p, q, nb), x[0], x[1], d == 3 ? x[2] : 0.0,
                    info.message[0] ? info.message : "non-finite stress", deriv);
}

static double uy_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

static const mpmc_material_ops ops = {"user_yield", uy_update, uy_wave_speed, 0, 1};

static const mpmc_param_desc params[] = {MPMC_PARAMS_ELASTIC, MPMC_PARAM_RHO_SAT(2)};

static int uy_setup(mpmc_context ctx, mpmc_material *m) {
  (void)ctx;
  mpmc_material_elastic(m);
  return MPMC_SUCCESS;
}

const mpmc_model mpmc_model_user_yield = {
    .name = "user_yield",
    .doc = "Hencky elasticity with the caller's yield surface (closest-point return)",
    .nparam = 4,
    .nstore = 4,
    .param = params,
    .flags = MPMC_MODEL_SOLID | MPMC_MODEL_PLASTIC | MPMC_MODEL_CALLBACK | MPMC_MODEL_EFFECTIVE | MPMC_MODEL_HENCKY,
    .setup = uy_setup,
    .ops = &ops};

/**
 * @brief Add Hencky elasticity with the caller's yield surface fn (mpmc_yield_fn): the
 *        library does the implicit return (closest-point projection, docs/materials.md).
 * @param fn the yield function with its derivatives, not NULL; called from several threads
 * @param data passed back to fn (may be NULL)
 * @param E, nu, rho Young's modulus [Pa], Poisson's ratio, density [kg/m^3]
 */
int mpmc_sim_add_material_user_yield(mpmc_sim sim, mpmc_yield_fn fn, void *data, double E,
                                     double nu, double rho, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(fn, sim->ctx, MPMC_ERR_ARG, "user yield surface: function fn is NULL");
  const double par[] = {E, nu, rho, NAN};
  int mid;
  MPMC_CALL(mpmc_material_add(sim, &mpmc_model_user_yield, par, &mid));
  sim->mats[mid].yield_fn = fn;
  sim->mats[mid].user_data = data;
  if (id) *id = mid;
  return MPMC_SUCCESS;
}

/**
 * @brief Re-attach the yield function of user-yield material `material` after
 *        mpmc_sim_checkpoint_read (function pointers cannot be saved in a file).
 */
int mpmc_sim_set_material_yield_fn(mpmc_sim sim, int material, mpmc_yield_fn fn, void *data) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(material >= 0 && material < sim->nmat, sim->ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  mpmc_material *m = &sim->mats[material];
  MPMC_CHECK(m->model == &mpmc_model_user_yield, sim->ctx, MPMC_ERR_ARG,
             "material %d is a '%s' material, not a user yield surface", material,
             m->model->name);
  MPMC_CHECK(fn, sim->ctx, MPMC_ERR_ARG, "user yield surface %d: function fn is NULL", material);
  m->yield_fn = fn;
  m->user_data = data;
  m->ops = m->model->ops;
  return MPMC_SUCCESS;
}
