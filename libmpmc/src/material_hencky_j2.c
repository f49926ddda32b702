/* Hencky elasticity with von Mises (J2) plasticity and exponential softening, return
 * mapping in principal logarithmic strain space (de Souza Neto et al. 2008, ch. 14; the
 * paper's footing and landslide models):
 *   trial  b_e = dF b_e^n dF^T  (dF-bar with F-bar on), b_e = sum lam_a n_a n_a^T,
 *          eps_a = 1/2 ln lam_a,  tau_a = K tr(eps) + 2G dev(eps)_a,
 *   yield  q = sqrt(3/2) |dev tau| <= kappa(eps_p) = kappa_r + (kappa_p - kappa_r) e^(-eta eps_p),
 *   return radial on the deviator: dev eps <- (1 - 3G dgamma / q_trial) dev eps,
 *          eps_p <- eps_p + dgamma, dgamma from return_map.c.
 * The volumetric part is untouched (isochoric flow), so J = exp(tr eps) is the Jacobian the
 * material sees (J-bar with F-bar) and sigma = tau / J. */
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include "linalg.h"
#include "return_map.h"

/* The trial state's record in info; 0 for a finite trial stress, MPMC_ERR_NUMERIC else. */
static inline int trial_info(mpmc_j2_info *info, double qtr, double k0) {
  info->q_trial = qtr;
  info->kappa = k0;
  info->plastic = 0;
  info->dgamma = 0.0;
  return isfinite(qtr) ? 0 : MPMC_ERR_NUMERIC;
}

/* The eigen path: principal logarithmic strains of any positive definite trial b (the
 * fast path's fallback for |eps| >~ 0.18). */
static int return_map_eig(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, const double *b,
                          double *be, double *eps_p, double *tau, double *J_out,
                          mpmc_j2_info *info) {
  double lam[3], Q[3][3], eps[3], e[3], s[3];
  mpmc_sym3_eig(b, lam, Q);
  for (int a = 0; a < 3; ++a)
    if (!(lam[a] > 0.0) || !isfinite(lam[a])) return MPMC_ERR_NUMERIC;
  for (int a = 0; a < 3; ++a) eps[a] = 0.5 * log(lam[a]);
  const double tr = eps[0] + eps[1] + eps[2];
  double ss = 0.0;
  for (int a = 0; a < 3; ++a) {
    e[a] = eps[a] - tr / 3.0;
    s[a] = 2.0 * m->G * e[a];
    ss += s[a] * s[a];
  }
  const double qtr = sqrt(1.5 * ss);
  const double k0 = mpmc_j2_kappa(m, *eps_p);
  MPMC_CALL(trial_info(info, qtr, k0));
  double t[3];
  if (qtr > k0) {
    double dg, qn;
    info->plastic = 1;
    MPMC_CALL(mpmc_rm_solve(ws, solver, m, qtr, *eps_p, &dg, &qn, info));
    const double f = qn / qtr; /* radial return: = 1 - 3G dgamma / q_trial */
    double lnew[3];
    for (int a = 0; a < 3; ++a) {
      e[a] *= f;
      s[a] *= f;
      lnew[a] = exp(2.0 * (e[a] + tr / 3.0));
    }
    mpmc_sym3_compose(lnew, Q, be);
    *eps_p += dg;
  } else {
    for (int k = 0; k < 6; ++k) be[k] = b[k]; /* elastic: keep b_e as pushed forward */
  }
  for (int a = 0; a < 3; ++a) t[a] = m->K * tr + s[a];
  mpmc_sym3_compose(t, Q, tau);
  if (J_out) *J_out = exp(tr);
  return MPMC_SUCCESS;
}

/**
 * @brief The return map of one point by the eigen path alone (return_map.h): the reference
 * the tests compare the fast path with.
 */
int mpmc_j2_return_map_eig(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double F[3][3],
                           double *be, double *eps_p, double *tau, double *J_out,
                           mpmc_j2_info *info) {
  mpmc_j2_info local = {0};
  if (!info) info = &local;
  double b[6];
  for (int k = 0; k < 6; ++k) b[k] = be[k];
  if (F) mpmc_push_forward(F, b);
  return return_map_eig(ws, solver, m, b, be, eps_p, tau, J_out, info);
}

/* tau = K tr(eps) I + 2G e and J = exp(tr eps) of the series path (e: dev eps) */
static inline void series_tau(const mpmc_j2_param *m, const double *e, double tr, double *tau,
                              double *J_out) {
  for (int k = 0; k < 6; ++k) tau[k] = 2.0 * m->G * e[k];
  for (int k = 0; k < 3; ++k) tau[k] += m->K * tr;
  if (J_out) *J_out = exp(tr);
}

/* The plastic part of the tensor-form return (return_map.h): from the trial b, its
 * deviatoric Hencky strain e (scaled in place to the returned one), tr eps, q_trial > k0. */
int mpmc_j2_plastic(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, const double *b,
                    double *e, double tr, double qtr, double k0, double *be, double *eps_p,
                    double *tau, double *J_out, mpmc_j2_info *info) {
  double dg, qn, en[6], bn[6];
  info->plastic = 1;
  MPMC_CALL(mpmc_rm_solve_k(ws, solver, m, qtr, *eps_p, k0, &dg, &qn, info));
  const double f = qn / qtr; /* radial return: = 1 - 3G dgamma / q_trial */
  /* b_e = exp(2 eps_new) = exp(2 eps_tr) exp(2 (f - 1) e) = b exp(2 (f - 1) e): b and the
   * correction commute (both functions of e), and the correction's series is short for
   * the small returns of most plastic steps (never longer than exp(2 e)'s) */
  for (int k = 0; k < 6; ++k) en[k] = 2.0 * (f - 1.0) * e[k];
  if (mpmc_sym3_exp_series(en, bn)) { /* not reached for |eps| < 0.18; stay safe */
    *info = (mpmc_j2_info){0};
    return return_map_eig(ws, solver, m, b, be, eps_p, tau, J_out, info);
  }
  mpmc_sym3_mul(b, bn, be);
  for (int k = 0; k < 6; ++k) e[k] *= f;
  *eps_p += dg;
  series_tau(m, e, tr, tau, J_out);
  return MPMC_SUCCESS;
}

/* The return in tensor form, without an eigen-decomposition, whenever the trial Hencky
 * strain eps = 1/2 ln b is small enough for the series of linalg.h (|eps| <~ 0.18):
 * tau = K tr(eps) I + 2G dev(eps) is coaxial with eps by construction, the radial return
 * scales dev(eps), and only a plastic point needs b_e = exp(2 tr/3) exp(2 dev eps_new).
 * Both paths agree to round-off (tests/t411).  The point-by-point reference of the blocks
 * of stress_j2.c. */
static inline int return_map_point(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m,
                                   double F[3][3], double *be, double *eps_p, double *tau,
                                   double *J_out, mpmc_j2_info *info) {
  double b[6], eps[6];
  for (int k = 0; k < 6; ++k) b[k] = be[k];
  if (F) mpmc_push_forward(F, b);
  if (mpmc_sym3_log_series(b, eps))
    return return_map_eig(ws, solver, m, b, be, eps_p, tau, J_out, info);
  const double tr = eps[0] + eps[1] + eps[2], G2 = 2.0 * m->G;
  double e[6];
  for (int k = 0; k < 6; ++k) e[k] = eps[k];
  for (int k = 0; k < 3; ++k) e[k] -= tr / 3.0;
  const double qtr = sqrt(1.5 * mpmc_sym3_norm2(e)) * G2;
  const double k0 = mpmc_j2_kappa(m, *eps_p);
  MPMC_CALL(trial_info(info, qtr, k0));
  if (qtr > k0) return mpmc_j2_plastic(ws, solver, m, b, e, tr, qtr, k0, be, eps_p, tau, J_out, info);
  for (int k = 0; k < 6; ++k) be[k] = b[k]; /* elastic: keep b_e as pushed forward */
  series_tau(m, e, tr, tau, J_out);
  return MPMC_SUCCESS;
}

/**
 * @brief Return map of one point (return_map.h); private, used by the tests and bench/.
 */
int mpmc_j2_return_map(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double F[3][3],
                       double *be, double *eps_p, double *tau, double *J_out,
                       mpmc_j2_info *info) {
  mpmc_j2_info local = {0};
  return return_map_point(ws, solver, m, F, be, eps_p, tau, J_out, info ? info : &local);
}

static int j2_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim, solver = sim->cfg.solver;
  const mpmc_j2_param par = {mat->K, mat->G, mat->kappa_p, mat->kappa_r, mat->eta};
  const int nthreads = mpmc_max_threads();
  mpmc_rm_ws **ws;
  MPMC_CALL(mpmc_rm_sim_workspaces(sim, nthreads, &ws));
  int64_t nret = 0, nfb = 0;
  int first_bad = INT_MAX;
  /* the points in blocks of four (stress_j2.c), in the sim's instruction set */
  MPMC_CALL(mpmc_kernels_j2_batch(sim)(sim, mat, id, ws, &nret, &nfb, &first_bad));
  sim->stats.return_maps += nret;
  sim->stats.kinsol_fallbacks += nfb;
  if (first_bad == INT_MAX) return MPMC_SUCCESS;
  /* a failed point's state is unchanged: repeat it alone to report what went wrong */
  const int q = first_bad;
  double F[3][3], tau[6], J, be[6], ep = p->eps_p[q];
  mpmc_j2_info info = {0};
  for (int k = 0; k < 6; ++k) be[k] = p->be[(size_t)q * 6 + k];
  mpmc_embed(d, p->dF + (size_t)q * d * d, F);
  const int err = mpmc_j2_return_map(ws[0], solver, &par, F, be, &ep, tau, &J, &info);
  const double *x = p->x + (size_t)q * d;
  char nb[MPMC_POINT_NAME_LEN];
  return MPMC_ERROR(sim->ctx, err ? err : MPMC_ERR_SOLVER,
                    "step %lld, t = %g: return map of point %s at (%g, %g, %g) (material %d, "
                    "solver %s) failed: trial q = %g, kappa = %g, eps_p = %g, dgamma = %g, "
                    "|g| = %g, KINSOL flag %d",
                    (long long)sim->stats.steps, sim->time, mpmc_point_name(p, q, nb), x[0], x[1],
                    d == 3 ? x[2] : 0.0, id, mpmc_solver_name(solver), info.q_trial, info.kappa, p->eps_p[q], info.dgamma,
                    info.residual, info.kinsol_flag);
}

static double j2_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

static const mpmc_material_ops ops = {"hencky_j2", j2_update, j2_wave_speed, 1, 1};

enum { E_, NU_, RHO_, KAPPA_P, KAPPA_R, ETA, RHO_SAT };
static const mpmc_param_desc params[] = {
    MPMC_PARAMS_ELASTIC,
    MPMC_PARAM("kappa_p", "Pa", "peak strength (von Mises q at yield)", 0.0, INFINITY,
               MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, 0.0, -1, -1),
    MPMC_PARAM("kappa_r", "Pa", "residual strength", 0.0, INFINITY,
               MPMC_PARAM_OPTIONAL | MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, NAN, KAPPA_P,
               KAPPA_P),
    MPMC_PARAM("eta", "1", "softening rate", 0.0, INFINITY,
               MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, 0.0, -1, -1),
    MPMC_PARAM_RHO_SAT(RHO_),
    MPMC_ALIAS("su", "Pa", "peak undrained shear strength (kappa_p = sqrt(3) su)", 0.0, INFINITY,
               MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, KAPPA_P, 1.7320508075688772),
    MPMC_ALIAS("su_r", "Pa", "residual undrained shear strength (kappa_r = sqrt(3) su_r)", 0.0,
               INFINITY, MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, KAPPA_R, 1.7320508075688772)};

static int j2_setup(mpmc_context ctx, mpmc_material *m) {
  (void)ctx;
  mpmc_material_elastic(m);
  m->kappa_p = m->par[KAPPA_P];
  m->kappa_r = m->par[KAPPA_R];
  m->eta = m->par[ETA];
  return MPMC_SUCCESS;
}

const mpmc_model mpmc_model_hencky_j2 = {
    .name = "hencky_j2",
    .doc = "Hencky elasticity, von Mises plasticity with exponential softening (undrained clay)",
    .nparam = 9,
    .nstore = 7,
    .param = params,
    .flags = MPMC_MODEL_SOLID | MPMC_MODEL_PLASTIC | MPMC_MODEL_HENCKY,
    .strength = {[KAPPA_P] = MPMC_SRM_DIVIDE, [KAPPA_R] = MPMC_SRM_DIVIDE},
    .setup = j2_setup,
    .ops = &ops};

/**
 * @brief Add Hencky elasticity with von Mises plasticity and exponential softening.
 * @param kappa_p peak strength (von Mises equivalent stress q at yield) [Pa], > 0
 * @param kappa_r residual strength [Pa], 0 < kappa_r <= kappa_p
 * @param eta softening rate, >= 0 (0: perfect plasticity at kappa_p)
 */
int mpmc_sim_add_material_hencky_j2(mpmc_sim sim, double E, double nu, double rho, double kappa_p,
                                    double kappa_r, double eta, int *id) {
  const double par[] = {E, nu, rho, kappa_p, kappa_r, eta, NAN};
  return mpmc_material_add(sim, &mpmc_model_hencky_j2, par, id);
}

/**
 * @brief Add Hencky-J2 with the strengths given as undrained shear strengths su.
 *
 * For von Mises plasticity the shear strength is su = kappa / sqrt(3) (pure or simple
 * shear, in particular plane-strain shear, which is what the footing's "su under plane
 * strain" means), so kappa_p = sqrt(3) su_p and kappa_r = sqrt(3) su_r.
 * @param su_p peak undrained shear strength [Pa], > 0
 * @param su_r residual undrained shear strength [Pa], 0 < su_r <= su_p
 * @param eta softening rate, >= 0
 * @param[out] id the material's id (may be NULL)
 */
int mpmc_sim_add_material_hencky_j2_su(mpmc_sim sim, double E, double nu, double rho, double su_p,
                                       double su_r, double eta, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(isfinite(su_p) && su_p > 0, ctx, MPMC_ERR_ARG,
             "hencky_j2: peak undrained shear strength su_p = %g must be > 0", su_p);
  MPMC_CHECK(isfinite(su_r) && su_r > 0 && su_r <= su_p, ctx, MPMC_ERR_ARG,
             "hencky_j2: residual undrained shear strength su_r = %g must be in (0, su_p = %g]",
             su_r, su_p);
  const double s3 = sqrt(3.0);
  return mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, s3 * su_p, s3 * su_r, eta, id);
}
