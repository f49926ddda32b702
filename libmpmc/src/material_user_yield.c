/* User yield surfaces: Hencky elasticity (E, nu) with the caller's yield function, flow
 * direction and hardening (mpmc_yield_fn, C or Fortran), returned to by the library's
 * closest-point projection (return_cpp.h: Newton on the 7x7 system, KINSOL as the fallback,
 * LAPACK loaded at the first plastic point).  The hardening variable alpha, the accumulated
 * plastic multiplier, is kept per point as eps_p.  When a return fails, the error names the
 * point, the reason and the derivative that a central-difference check finds wrong. */
#include <math.h>

#include "linalg.h"
#include "return_cpp.h"
#include "stress_return.h"

extern const mpmc_model mpmc_model_user_yield;

/* one point's return (stress_return.h), model: the material's mpmc_cpp_param */
static int uy_point(const void *model, mpmc_rm_ws *ws, int solver, double F[3][3],
                    double be[6], double *eps_p, double tau[6], mpmc_return_out *out) {
  mpmc_cpp_info info;
  info.plastic = info.fallback = 0;
  const int err = mpmc_cpp_return_map(ws, solver, model, F, be, eps_p, tau, &out->Je, &info);
  out->plastic = info.plastic;
  out->fallback = info.fallback;
  return err;
}

/* repeat the failed point alone, then check the function's derivatives at its trial state:
 * a wrong derivative is the usual cause */
static int uy_fail(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, const void *model,
                   mpmc_rm_ws *ws, mpmc_return_point *pt) {
  const mpmc_particles *p = &sim->p;
  const mpmc_cpp_param *cp = model;
  const int q = pt->q, solver = sim->cfg.solver;
  double tau[6], Je;
  mpmc_cpp_info info = {0};
  int err = mpmc_cpp_return_map(ws, solver, cp, pt->F, pt->be, &pt->eps_p, tau, &Je, &info);
  char deriv[200] = "";
  double btr[6], lam[3], Q[3][3], eps[3], t[3];
  for (int k = 0; k < 6; ++k) btr[k] = p->be[(size_t)q * 6 + k];
  mpmc_push_forward(pt->F, btr);
  mpmc_sym3_eig(btr, lam, Q);
  if (lam[0] > 0 && lam[1] > 0 && lam[2] > 0) {
    for (int a = 0; a < 3; ++a) eps[a] = 0.5 * log(lam[a]);
    const double tr = eps[0] + eps[1] + eps[2];
    for (int a = 0; a < 3; ++a) t[a] = mat->K * tr + 2.0 * mat->G * (eps[a] - tr / 3.0);
    double ttr[6], worst = 0;
    char name[64] = "";
    mpmc_sym3_compose(t, Q, ttr);
    if (!mpmc_cpp_check_derivatives(cp, ttr, p->eps_p[q], &worst, name, sizeof name) &&
        worst > 1e-4)
      snprintf(deriv, sizeof deriv,
               "; at the trial stress the function's %s differs from central differences by "
               "%.3g relative: check the yield function's derivatives",
               name, worst);
  }
  if (!err) err = MPMC_ERR_NUMERIC;
  return MPMC_ERROR(sim->ctx, err,
                    "step %lld, t = %g: user yield surface (material %d, solver %s) failed at "
                    "point %s (%g, %g, %g): %s%s",
                    (long long)sim->stats.steps, sim->time, id, mpmc_solver_name(solver),
                    pt->name, pt->x[0], pt->x[1], pt->x[2],
                    info.message[0] ? info.message : "non-finite stress", deriv);
}

static const mpmc_return_ops uy_return = {uy_point, uy_fail};

static int uy_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  const mpmc_cpp_param cp = {.K = mat->K, .G = mat->G, .fn = mat->yield_fn, .data = mat->user_data};
  return mpmc_return_update(sim, mat, id, &uy_return, &cp);
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
