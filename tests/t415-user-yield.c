/* The closest-point projection for user yield surfaces (return_cpp.c):
 *  - J2 with exponential softening written as a user surface returns the built-in J2 map's
 *    stress, b_e and eps_p to 1e-10 on random b_e and F (large strains too), with every solver;
 *  - Drucker-Prager (perfect plasticity, associated and non-associated) as a user surface
 *    matches the closed-form cone return to 1e-10;
 *  - Newton and KINSOL agree to 1e-10, and LAPACK's dgesv and the hand-written solve too;
 *  - a wrong derivative never gives a wrong stress: the return fails with MPMC_ERR_SOLVER
 *    and names the derivative, or it converges to the right stress and the derivative check
 *    names the derivative; a function returning non-zero stops with MPMC_ERR_SOLVER, a
 *    non-finite one with MPMC_ERR_NUMERIC. */
#include <setjmp.h>
#include <stdarg.h>
#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "return_cpp.h"
#include "return_mc.h"
#include "return_map.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x5DEECE66Dull
#include "test_rand.h"

static const int solvers[3] = {MPMC_SOLVER_NEWTON, MPMC_SOLVER_KINSOL, MPMC_SOLVER_AUTO};

static double maxabs(const double *v, int n) {
  double a = 0;
  for (int k = 0; k < n; ++k) a = fmax(a, fabs(v[k]));
  return a;
}

/* deviator s of t, |s| (tensor norm), and n = s / |s| */
static double dev(const double *t, double *s) {
  const double p = (t[0] + t[1] + t[2]) / 3;
  for (int k = 0; k < 6; ++k) s[k] = t[k] - (k < 3 ? p : 0);
  return sqrt(mpmc_sym3_norm2(s));
}

/* d n / d tau in tensor components (Voigt): (P_dev - n n) / |s|, the symmetric identity's
 * shear entries 1/2 (mpmc.h's convention) */
static void dn_dtau(const double *n, double ns, double c, double *D) {
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      double v = (i == j) ? (i < 3 ? 1.0 : 0.5) : 0.0;
      if (i < 3 && j < 3) v -= 1.0 / 3.0;
      D[6 * i + j] = c * (v - n[i] * n[j]) / ns;
    }
}

/* ---- J2 with exponential softening as a user surface --------------------------------- */
/* A deliberate fault for the wrong-derivative tests */
enum { FAULT_NONE, FAULT_DFDTAU_SIGN, FAULT_DRDTAU_ZERO, FAULT_DFDALPHA_SIGN, FAULT_USER_ERR,
       FAULT_USER_ERR_LATER, FAULT_NAN };
typedef struct {
  mpmc_j2_param m;
  int fault;
  double alpha_n; /* FAULT_USER_ERR_LATER: fail once alpha moves */
} j2_user;

static int j2_fn(void *data, const double *tau, double alpha, mpmc_yield_eval *out) {
  const j2_user *u = data;
  const mpmc_j2_param *m = &u->m;
  if (u->fault == FAULT_USER_ERR) return 7;
  if (u->fault == FAULT_USER_ERR_LATER && alpha != u->alpha_n) return 9;
  double s[6];
  const double ns = dev(tau, s), c = sqrt(1.5);
  const double e = (m->kappa_p - m->kappa_r) * exp(-m->eta * alpha);
  out->f = c * ns - (m->kappa_r + e);
  out->dfdalpha = m->eta * e;
  for (int k = 0; k < 6; ++k) out->dfdtau[k] = out->r[k] = c * s[k] / ns;
  double n[6];
  for (int k = 0; k < 6; ++k) n[k] = s[k] / ns;
  dn_dtau(n, ns, c, out->drdtau);
  for (int k = 0; k < 6; ++k) out->drdalpha[k] = 0.0;
  if (u->fault == FAULT_DFDTAU_SIGN)
    for (int k = 0; k < 6; ++k) out->dfdtau[k] = -out->dfdtau[k];
  if (u->fault == FAULT_DRDTAU_ZERO)
    for (int k = 0; k < 36; ++k) out->drdtau[k] = 0.0;
  if (u->fault == FAULT_DFDALPHA_SIGN) out->dfdalpha = -out->dfdalpha;
  if (u->fault == FAULT_NAN) out->f = NAN;
  return 0;
}

static mpmc_cpp_param j2_param(j2_user *u) {
  return (mpmc_cpp_param){.K = u->m.K, .G = u->m.G, .fn = j2_fn, .data = u};
}

/* A random material with moderate to strong softening (eta (kappa_p - kappa_r) up to ~4 G). */
static void random_j2(mpmc_j2_param *m, double *ep) {
  const double E = loguni(1e5, 1e9), nu = 0.45 * urand();
  m->G = E / (2 * (1 + nu));
  m->K = E / (3 * (1 - 2 * nu));
  m->kappa_p = E * loguni(1e-4, 1e-2);
  m->kappa_r = m->kappa_p * loguni(1e-2, 1.0);
  m->eta = urand() < 0.2 ? 0.0 : loguni(0.1, 500.0);
  *ep = urand() < 0.3 ? 0.0 : loguni(1e-6, 1.0);
}

/* The user J2 against mpmc_j2_return_map_eig on random b_e and F: the same stress, b_e,
 * eps_p and J to 1e-10 with each solver; Newton, KINSOL and auto to 1e-10 of each other. */
static void test_j2_matches_builtin(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  TCALL(mpmc_rm_ws_create(&ws));
  const int N = 3000;
  int nplastic = 0, nlarge = 0, nfb = 0;
  double worst = 0;
  for (int q = 0; q < N; ++q) {
    j2_user u = {.fault = FAULT_NONE};
    double ep0;
    random_j2(&u.m, &ep0);
    const double big = q % 4 == 0 ? 0.6 : 0.05; /* stretches up to e^1.2: large strains */
    double be0[6], f[9], F[3][3];
    rand_spd(3, big * urand(), be0);
    rand_dF(3, (q % 4 == 0 ? 0.3 : 0.01) * urand(), f);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F[i][j] = f[3 * i + j];
    double be_ref[6], tau_ref[6], ep_ref = ep0, J_ref;
    memcpy(be_ref, be0, sizeof be0);
    mpmc_j2_info jinfo = {0};
    TCALL(mpmc_j2_return_map_eig(ws, MPMC_SOLVER_AUTO, &u.m, F, be_ref, &ep_ref, tau_ref, &J_ref,
                                 &jinfo));
    /* the yield check's edge: within 1e-9 of the surface the two may differ on plastic */
    if (fabs(jinfo.q_trial / jinfo.kappa - 1) < 1e-9) continue;
    nplastic += jinfo.plastic;
    double btr[6], lam[3], Q[3][3]; /* the trial stretches: log strains beyond 0.3 */
    memcpy(btr, be0, sizeof btr);
    mpmc_push_forward(F, btr);
    mpmc_sym3_eig(btr, lam, Q);
    if (jinfo.plastic && fmax(fabs(log(lam[0] / lam[1])), fabs(log(lam[0] / lam[2]))) > 0.6) ++nlarge;
    const mpmc_cpp_param p = j2_param(&u);
    const double ts = fmax(maxabs(tau_ref, 6), jinfo.kappa);
    double tau_s[3][6], ep_s[3];
    for (int s = 0; s < 3; ++s) {
      double be[6], tau[6], ep = ep0, J;
      memcpy(be, be0, sizeof be);
      mpmc_cpp_info info;
      const int err = mpmc_cpp_return_map(ws, solvers[s], &p, F, be, &ep, tau, &J, &info);
      if (err)
        fail_msg("state %d solver %d: error %d: %s (q_trial/kappa %g, eta %g, kappa_p/G %g)", q,
                 solvers[s], err, info.message, jinfo.q_trial / jinfo.kappa, u.m.eta,
                 u.m.kappa_p / u.m.G);
      if (info.plastic != jinfo.plastic)
        fail_msg("state %d solver %d: plastic %d, built-in J2 %d (q_trial/kappa = %.17g)", q,
                 solvers[s], info.plastic, jinfo.plastic, jinfo.q_trial / jinfo.kappa);
      if (s == 2) nfb += info.fallback;
      double d = 0;
      for (int k = 0; k < 6; ++k) d = fmax(d, fabs(tau[k] - tau_ref[k]) / ts);
      for (int k = 0; k < 6; ++k) d = fmax(d, fabs(be[k] - be_ref[k]) / maxabs(be_ref, 6));
      d = fmax(d, 2 * u.m.G * fabs(ep - ep_ref) / ts); /* eps_p in stress units */
      d = fmax(d, fabs(J - J_ref) / J_ref);
      worst = fmax(worst, d);
      if (!(d <= 1e-10))
        fail_msg("state %d solver %d: relative difference %.3g from the built-in J2 (expected "
                 "<= 1e-10): tau_xx %.17g vs %.17g, eps_p %.17g vs %.17g; q_trial/kappa %g, "
                 "eta %g, %d Newton, %d KINSOL iterations",
                 q, solvers[s], d, tau[0], tau_ref[0], ep, ep_ref, jinfo.q_trial / jinfo.kappa,
                 u.m.eta, info.newton_iters, info.kinsol_iters);
      memcpy(tau_s[s], tau, sizeof tau);
      ep_s[s] = ep;
    }
    for (int s = 1; s < 3; ++s) {
      double d = 2 * u.m.G * fabs(ep_s[s] - ep_s[0]) / ts;
      for (int k = 0; k < 6; ++k) d = fmax(d, fabs(tau_s[s][k] - tau_s[0][k]) / ts);
      if (!(d <= 1e-10))
        fail_msg("state %d: Newton and solver %d differ by %.3g (expected <= 1e-10)", q,
                 solvers[s], d);
    }
  }
  /* the random set must be mostly plastic, with large strains, or it tests little */
  if (nplastic < N / 2 || nlarge < N / 20)
    fail_msg("%d plastic, %d large-strain plastic states of %d (expected >= %d, %d)", nplastic,
             nlarge, N, N / 2, N / 20);
  (void)nfb;
  mpmc_rm_ws_destroy(&ws);
}

/* LAPACK's dgesv for Newton's systems gives the hand-written elimination's stress */
static void test_lapack_flag(void **state) {
  (void)state;
  const char *why;
  if (mpmc_cpp_lapack_load(&why)) fail_msg("%s", why);
  for (int q = 0; q < 300; ++q) {
    j2_user u = {.fault = FAULT_NONE};
    double ep0;
    random_j2(&u.m, &ep0);
    double be0[6];
    rand_spd(3, 0.2 * urand(), be0);
    mpmc_cpp_param p = j2_param(&u);
    double tau[2][6], ep[2];
    for (int l = 0; l < 2; ++l) {
      double be[6];
      memcpy(be, be0, sizeof be);
      ep[l] = ep0;
      p.lapack = l;
      mpmc_cpp_info info;
      const int err = mpmc_cpp_return_map(NULL, MPMC_SOLVER_NEWTON, &p, NULL, be, &ep[l],
                                          tau[l], NULL, &info);
      if (err) fail_msg("state %d lapack %d: %s", q, l, info.message);
    }
    for (int k = 0; k < 6; ++k) TCLOSE(tau[1][k], tau[0][k], 1e-10 * maxabs(tau[0], 6));
    TCLOSE(ep[1], ep[0], 1e-10 * ep[0]);
  }
}

/* ---- Drucker-Prager as a user surface -------------------------------------------------- */
/* f = q + a p - k, flow potential g = q + b p (tension positive, p = tr tau / 3): b = a
 * associated, b < a non-associated. */
typedef struct {
  double a, b, k;
} dp_user;

static int dp_fn(void *data, const double *tau, double alpha, mpmc_yield_eval *out) {
  (void)alpha;
  const dp_user *u = data;
  double s[6], n[6];
  const double ns = dev(tau, s), c = sqrt(1.5), p = (tau[0] + tau[1] + tau[2]) / 3;
  for (int k = 0; k < 6; ++k) n[k] = s[k] / ns;
  out->f = c * ns + u->a * p - u->k;
  out->dfdalpha = 0.0;
  for (int k = 0; k < 6; ++k) {
    out->dfdtau[k] = c * n[k] + (k < 3 ? u->a / 3 : 0.0);
    out->r[k] = c * n[k] + (k < 3 ? u->b / 3 : 0.0);
    out->drdalpha[k] = 0.0;
  }
  dn_dtau(n, ns, c, out->drdtau);
  return 0;
}

/* The closed-form return to the cone (not the apex): dgamma = f_trial / (3G + a b K),
 * q = q_trial - 3G dgamma, p = p_trial - K b dgamma, s = q / q_trial s_trial.  Returns 0 if
 * the state returns to the cone, 1 if elastic or to the apex. */
static int dp_closed_form(const dp_user *u, double K, double G, const double *ttr, double *tau,
                          double *dgamma) {
  double s[6];
  const double ns = dev(ttr, s), qtr = sqrt(1.5) * ns, ptr = (ttr[0] + ttr[1] + ttr[2]) / 3;
  const double ftr = qtr + u->a * ptr - u->k;
  if (ftr <= 0) return 1;
  const double dg = ftr / (3 * G + u->a * u->b * K), q = qtr - 3 * G * dg;
  if (!(q > 1e-3 * qtr)) return 1; /* apex, or too near it for a smooth cone */
  const double p = ptr - K * u->b * dg;
  for (int k = 0; k < 6; ++k) tau[k] = q / qtr * s[k] + (k < 3 ? p : 0.0);
  *dgamma = dg;
  return 0;
}

static void test_drucker_prager(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  TCALL(mpmc_rm_ws_create(&ws));
  int ncone = 0;
  for (int q = 0; q < 3000; ++q) {
    const double E = loguni(1e6, 1e9), nu = 0.45 * urand();
    const double G = E / (2 * (1 + nu)), K = E / (3 * (1 - 2 * nu));
    dp_user u = {.a = 1.5 * urand(), .k = E * loguni(1e-5, 1e-2)};
    u.b = q % 2 ? u.a : u.a * urand(); /* associated / non-associated (b < a, b >= 0) */
    /* a trial stress: random principal values around a pressure, random axes */
    double lam[3], R[3][3], ttr[6];
    const double p0 = u.k * (4 * urand() - 3) / fmax(u.a, 0.1);
    for (int a = 0; a < 3; ++a) lam[a] = p0 + u.k * loguni(0.1, 100) * (2 * urand() - 1);
    rand_rotation(R);
    mpmc_sym3_compose(lam, R, ttr);
    double tau_cf[6], dg_cf;
    if (dp_closed_form(&u, K, G, ttr, tau_cf, &dg_cf)) continue;
    ++ncone;
    const mpmc_cpp_param p = {.K = K, .G = G, .fn = dp_fn, .data = &u};
    const double ts = fmax(maxabs(ttr, 6), u.k);
    for (int s = 0; s < 3; ++s) {
      double tau[6], alpha = 0.25;
      mpmc_cpp_info info;
      const int err = mpmc_cpp_return_stress(ws, solvers[s], &p, ttr, &alpha, tau, &info);
      if (err) fail_msg("state %d solver %d: %s", q, solvers[s], info.message);
      /* dgamma in stress units (2G dgamma against the stress): a small dgamma is fixed only
         as far as the tolerance on f, relative to the stress, fixes it */
      double d = 2 * G * fabs(alpha - 0.25 - dg_cf) / ts;
      for (int k = 0; k < 6; ++k) d = fmax(d, fabs(tau[k] - tau_cf[k]) / ts);
      if (!(d <= 1e-10))
        fail_msg("state %d solver %d (a %g, b %g): relative difference %.3g from the closed "
                 "form (expected <= 1e-10): dgamma %.17g vs %.17g, tau_xx %.17g vs %.17g",
                 q, solvers[s], u.a, u.b, d, alpha - 0.25, dg_cf, tau[0], tau_cf[0]);
    }
  }
  if (ncone < 1000) fail_msg("only %d cone returns of 3000 (expected >= 1000)", ncone);
  mpmc_rm_ws_destroy(&ws);
}

/* Drucker-Prager as a user surface against the built-in model (return_mc.c, the compression
 * cone of mpmc_sim_add_material_drucker_prager): sqrt(J2) = q / sqrt(3), so the built-in
 * f = sqrt(J2) + eta_f p - xi c is the user's q + a p - k with a = sqrt(3) eta_f =
 * 6 sin(phi) / (3 - sin(phi)), k = 6 c cos(phi) / (3 - sin(phi)), b likewise from psi.  Trial
 * states from random principal Hencky strains; the cone region only (the user surface has no
 * apex return). */
static void test_dp_matches_builtin(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  TCALL(mpmc_rm_ws_create(&ws));
  int ncone = 0;
  for (int q = 0; q < 3000; ++q) {
    const double E = loguni(1e6, 1e9), nu = 0.45 * urand();
    const double G = E / (2 * (1 + nu)), K = E / (3 * (1 - 2 * nu));
    const double phi = 0.7 * urand(), psi = q % 2 ? phi : phi * urand(), c = E * loguni(1e-5, 1e-2);
    const mpmc_mc_param mp = {.K = K, .G = G, .c_p = c, .c_r = c, .phi_p = phi, .phi_r = phi,
                              .psi_p = psi, .psi_r = psi, .eta = 0.0, .sigma_t = INFINITY,
                              .surface = MPMC_DP_COMPRESSION};
    const dp_user u = {.a = 6 * sin(phi) / (3 - sin(phi)), .b = 6 * sin(psi) / (3 - sin(psi)),
                       .k = 6 * c * cos(phi) / (3 - sin(phi))};
    double etr[3], eps[3], tb[3], ep = 0.0;
    const double s = c / E * loguni(0.1, 100);
    for (int a = 0; a < 3; ++a) etr[a] = s * (2 * urand() - 1) - 0.3 * s;
    mpmc_mc_info mi = {0};
    TCALL(mpmc_mc_return_principal(ws, MPMC_SOLVER_AUTO, &mp, etr, &ep, eps, tb, &mi));
    if (mi.region != MPMC_MC_PLANE) continue;
    const double tr = etr[0] + etr[1] + etr[2];
    double ttr[6] = {0}, tau[6], alpha = 0.0;
    for (int a = 0; a < 3; ++a) ttr[a] = K * tr + 2 * G * (etr[a] - tr / 3);
    double sd[6];
    if (!(sqrt(1.5) * dev(ttr, sd) > 0)) continue;
    const mpmc_cpp_param p = {.K = K, .G = G, .fn = dp_fn, .data = (void *)&u};
    mpmc_cpp_info info;
    const int err = mpmc_cpp_return_stress(ws, MPMC_SOLVER_AUTO, &p, ttr, &alpha, tau, &info);
    if (err) fail_msg("state %d: %s", q, info.message);
    ++ncone;
    const double ts = fmax(fmax(fabs(ttr[0]), fabs(ttr[1])), fmax(fabs(ttr[2]), c));
    double d = 0.0;
    for (int a = 0; a < 3; ++a) d = fmax(d, fabs(tau[a] - tb[a]) / ts);
    for (int k = 3; k < 6; ++k) d = fmax(d, fabs(tau[k]) / ts);
    if (!(d <= 1e-10))
      fail_msg("state %d (phi %g, psi %g): user and built-in Drucker-Prager differ by %.3g of the "
               "stress (expected <= 1e-10): %.17g %.17g %.17g vs %.17g %.17g %.17g",
               q, phi, psi, d, tau[0], tau[1], tau[2], tb[0], tb[1], tb[2]);
  }
  if (ncone < 500) fail_msg("only %d cone returns of 3000 (expected >= 500)", ncone);
  mpmc_rm_ws_destroy(&ws);
}

/* ---- faults ---------------------------------------------------------------------------- */
/* A J2 state well outside the surface, and the built-in's answer. */
static void j2_fault_case(j2_user *u, double *ttr, double *tau_ref, double *ep_ref) {
  u->m = (mpmc_j2_param){.K = 5e7, .G = 2e7, .kappa_p = 2e5, .kappa_r = 5e4, .eta = 20};
  u->alpha_n = 0.01;
  const double eps[6] = {0.02, -0.013, 0.001, 0.004, -0.003, 0.006}; /* Hencky strain */
  double mu[3], Q[3][3], b[6];
  mpmc_sym3_eig(eps, mu, Q);
  for (int a = 0; a < 3; ++a) mu[a] = exp(2 * mu[a]);
  mpmc_sym3_compose(mu, Q, b); /* b_e = exp(2 eps) */
  *ep_ref = u->alpha_n;
  TCALL(mpmc_j2_return_map_eig(NULL, MPMC_SOLVER_NEWTON, &u->m, NULL, b, ep_ref, tau_ref, NULL,
                               NULL));
  const double tr = eps[0] + eps[1] + eps[2]; /* the trial Kirchhoff stress */
  for (int k = 0; k < 6; ++k) ttr[k] = 2 * u->m.G * eps[k] + (k < 3 ? (u->m.K - 2 * u->m.G / 3) * tr : 0);
}

/* A wrong derivative: MPMC_ERR_SOLVER naming the derivative, or the right stress; the
 * derivative check names it either way.  Never a wrong stress. */
static void check_fault(mpmc_rm_ws *ws, int fault, const char *name, int must_fail) {
  j2_user u = {.fault = fault};
  double ttr[6], tau_ref[6], ep_ref;
  j2_fault_case(&u, ttr, tau_ref, &ep_ref);
  const mpmc_cpp_param p = j2_param(&u);
  double worst;
  char which[32];
  TCALL(mpmc_cpp_check_derivatives(&p, ttr, u.alpha_n, &worst, which, sizeof which));
  if (!(worst > 1e-2) || strncmp(which, name, strlen(name)))
    fail_msg("fault %d: the derivative check found %s off by %.3g (expected %s, > 1e-2)", fault,
             which, worst, name);
  for (int s = 0; s < 3; ++s) {
    double tau[6], alpha = u.alpha_n;
    mpmc_cpp_info info;
    const int err = mpmc_cpp_return_stress(ws, solvers[s], &p, ttr, &alpha, tau, &info);
    if (err) {
      if (err != MPMC_ERR_SOLVER || info.reason != MPMC_CPP_NO_CONVERGENCE ||
          !strstr(info.message, "did not converge") || !strstr(info.message, name))
        fail_msg("fault %d solver %d: error %d reason %d \"%s\" (expected MPMC_ERR_SOLVER, did "
                 "not converge, naming %s)", fault, solvers[s], err, info.reason, info.message,
                 name);
      continue;
    }
    if (must_fail)
      fail_msg("fault %d solver %d: converged (expected MPMC_ERR_SOLVER)", fault, solvers[s]);
    for (int k = 0; k < 6; ++k) TCLOSE(tau[k], tau_ref[k], 1e-10 * maxabs(tau_ref, 6));
    TCLOSE(alpha, ep_ref, 1e-10 * ep_ref);
  }
}

static void test_wrong_derivatives(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  TCALL(mpmc_rm_ws_create(&ws));
  /* the correct function passes the check */
  {
    j2_user u = {.fault = FAULT_NONE};
    double ttr[6], tau_ref[6], ep_ref, worst;
    j2_fault_case(&u, ttr, tau_ref, &ep_ref);
    const mpmc_cpp_param p = j2_param(&u);
    char which[32];
    TCALL(mpmc_cpp_check_derivatives(&p, ttr, u.alpha_n, &worst, which, sizeof which));
    if (!(worst < 1e-6)) fail_msg("correct J2: %s off by %.3g (expected < 1e-6)", which, worst);
    dp_user d = {.a = 0.6, .b = 0.2, .k = 1e5};
    const mpmc_cpp_param pd = {.K = 5e7, .G = 2e7, .fn = dp_fn, .data = &d};
    TCALL(mpmc_cpp_check_derivatives(&pd, ttr, 0.0, &worst, which, sizeof which));
    if (!(worst < 1e-6)) fail_msg("correct DP: %s off by %.3g (expected < 1e-6)", which, worst);
  }
  check_fault(ws, FAULT_DFDTAU_SIGN, "dfdtau", 1);
  check_fault(ws, FAULT_DRDTAU_ZERO, "drdtau", 0);
  check_fault(ws, FAULT_DFDALPHA_SIGN, "dfdalpha", 0);
  mpmc_rm_ws_destroy(&ws);
}

/* A function that returns non-zero stops the return with MPMC_ERR_SOLVER and its code; one
 * that gives NaN with MPMC_ERR_NUMERIC; tau and alpha stay as they were. */
static void test_user_errors(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  TCALL(mpmc_rm_ws_create(&ws));
  const struct {
    int fault, code, err, reason;
    const char *text;
  } cases[] = {
      {FAULT_USER_ERR, 7, MPMC_ERR_SOLVER, MPMC_CPP_USER_ERROR, "returned 7"},
      {FAULT_USER_ERR_LATER, 9, MPMC_ERR_SOLVER, MPMC_CPP_USER_ERROR, "returned 9"},
      {FAULT_NAN, 0, MPMC_ERR_NUMERIC, MPMC_CPP_NON_FINITE, "non-finite"},
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c)
    for (int s = 0; s < 3; ++s) {
      j2_user u = {.fault = cases[c].fault};
      double ttr[6], tau_ref[6], ep_ref;
      j2_fault_case(&u, ttr, tau_ref, &ep_ref);
      const mpmc_cpp_param p = j2_param(&u);
      double tau[6] = {-1, -1, -1, -1, -1, -1}, alpha = u.alpha_n;
      mpmc_cpp_info info;
      const int err = mpmc_cpp_return_stress(ws, solvers[s], &p, ttr, &alpha, tau, &info);
      if (err != cases[c].err || info.reason != cases[c].reason ||
          info.user_code != cases[c].code || !strstr(info.message, cases[c].text))
        fail_msg("case %zu solver %d: error %d reason %d code %d \"%s\" (expected %d, %d, %d, "
                 "\"%s\")", c, solvers[s], err, info.reason, info.user_code, info.message,
                 cases[c].err, cases[c].reason, cases[c].code, cases[c].text);
      assert_true(alpha == u.alpha_n);
      for (int k = 0; k < 6; ++k) assert_true(tau[k] == -1);
    }
  /* a non-positive-definite trial b_e */
  j2_user u = {.fault = FAULT_NONE};
  double ttr[6], tau_ref[6], ep_ref;
  j2_fault_case(&u, ttr, tau_ref, &ep_ref);
  const mpmc_cpp_param p = j2_param(&u);
  double be[6] = {1, -0.5, 1, 0, 0, 0}, tau[6], alpha = 0;
  mpmc_cpp_info info;
  assert_int_equal(mpmc_cpp_return_map(ws, MPMC_SOLVER_AUTO, &p, NULL, be, &alpha, tau, NULL,
                                       &info), MPMC_ERR_NUMERIC);
  /* auto and kinsol need the workspace */
  alpha = u.alpha_n;
  assert_int_equal(mpmc_cpp_return_stress(NULL, MPMC_SOLVER_KINSOL, &p, ttr, &alpha, tau, &info),
                   MPMC_ERR_ARG);
  assert_int_equal(info.reason, MPMC_CPP_NO_WORKSPACE);
  mpmc_rm_ws_destroy(&ws);
}

/* Inside the surface nothing moves; on it (f = 0 to round-off) neither. */
static void test_elastic(void **state) {
  (void)state;
  j2_user u = {.fault = FAULT_NONE};
  double ttr[6], tau_ref[6], ep_ref;
  j2_fault_case(&u, ttr, tau_ref, &ep_ref);
  const mpmc_cpp_param p = j2_param(&u);
  for (int pass = 0; pass < 2; ++pass) {
    const double *t = pass ? tau_ref : ttr;
    double in[6], tau[6], alpha = pass ? ep_ref : u.alpha_n;
    const double a0 = alpha;
    for (int k = 0; k < 6; ++k) in[k] = pass ? t[k] : 0.1 * t[k];
    mpmc_cpp_info info;
    TCALL(mpmc_cpp_return_stress(NULL, MPMC_SOLVER_NEWTON, &p, in, &alpha, tau, &info));
    assert_int_equal(info.plastic, 0);
    assert_true(alpha == a0);
    for (int k = 0; k < 6; ++k) assert_true(tau[k] == in[k]);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_j2_matches_builtin), cmocka_unit_test(test_lapack_flag),
      cmocka_unit_test(test_drucker_prager),     cmocka_unit_test(test_wrong_derivatives),
      cmocka_unit_test(test_dp_matches_builtin),
      cmocka_unit_test(test_user_errors),        cmocka_unit_test(test_elastic),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
