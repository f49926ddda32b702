/* Local solvers of the Hencky-J2 return map (return_map.c) on 12,000 random trial states
 * over a wide range of materials: newton, kinsol and auto agree on dgamma to 1e-10 relative
 * or, where steep softening flattens the residual, as far as their tolerance fixes the root,
 * the returned state satisfies the consistency condition q = kappa(eps_p) to 1e-10 kappa,
 * and auto hands exactly the non-monotone cases to KINSOL; kappa's exp agrees with libm's. */
#include <setjmp.h>
#include <stdarg.h>
#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "return_map.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x2545F4914F6CDD1Dull
#include "test_rand.h"

/* von Mises stress of a Kirchhoff tensor (Voigt) */
static double vm(const double *t) {
  const double p = (t[0] + t[1] + t[2]) / 3;
  const double a = t[0] - p, b = t[1] - p, c = t[2] - p;
  return sqrt(1.5 * (a * a + b * b + c * c + 2 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])));
}

typedef struct {
  mpmc_j2_param m;
  double be[6], ep;
} trial;

/* A random material and a random plastic trial state with q_trial / kappa in [1, 1e4]. */
static void random_trial(trial *t) {
  const double E = loguni(1e3, 1e9), nu = 0.4999 * urand();
  t->m.G = E / (2 * (1 + nu));
  t->m.K = E / (3 * (1 - 2 * nu));
  t->m.kappa_p = E * loguni(1e-5, 1e-2);
  t->m.kappa_r = t->m.kappa_p * loguni(1e-2, 1.0);
  t->m.eta = urand() < 0.1 ? 0.0 : loguni(0.1, 5000.0);
  t->ep = urand() < 0.3 ? 0.0 : loguni(1e-6, 2.0);
  double ratio = loguni(1.0 + 1e-9, 1e4);
  if (urand() < 0.25) { /* strong softening near the peak: eta (kappa_p - kappa_r) > 3G */
    t->m.kappa_p = E * loguni(1e-3, 1e-2);
    t->m.kappa_r = t->m.kappa_p * loguni(1e-2, 0.5);
    t->m.eta = loguni(1e3, 5e3);
    t->ep = urand() < 0.5 ? 0.0 : loguni(1e-8, 1e-4);
    ratio = loguni(1.0 + 1e-9, 2.0);
  }
  const double kappa = mpmc_j2_kappa(&t->m, t->ep);
  /* random deviatoric direction, scaled so that q = sqrt(3/2) 2G |dev eps| = ratio kappa */
  double d[3] = {2 * urand() - 1, 2 * urand() - 1, 0};
  d[2] = -d[0] - d[1];
  const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double scale = ratio * kappa / (sqrt(1.5) * 2 * t->m.G * n);
  /* keep the trial log strains physical (|dev eps| <= 3, stretches below e^3 = 20):
     beyond, b_e's small eigenvalues fall under round-off of its large ones */
  if (scale * n > 3.0) scale = 3.0 / n;
  const double vol = 0.2 * (2 * urand() - 1);
  double lam[3], R[3][3];
  for (int a = 0; a < 3; ++a) lam[a] = exp(2 * (d[a] * scale + vol / 3));
  rand_rotation(R);
  mpmc_sym3_compose(lam, R, t->be);
}

static void test_agreement(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  assert_int_equal(mpmc_rm_ws_create(&ws), 0);
  const int N = 12000;
  int nfb = 0, nstiff = 0, nbis = 0;
  double worst_rel = 0, worst_cons = 0;
  for (int k = 0; k < N; ++k) {
    trial t;
    random_trial(&t);
    const int solvers[3] = {MPMC_SOLVER_NEWTON, MPMC_SOLVER_KINSOL, MPMC_SOLVER_AUTO};
    double be[3][6], ep[3], tau[3][6];
    mpmc_j2_info info[3];
    for (int s = 0; s < 3; ++s) {
      memset(&info[s], 0, sizeof info[s]);
      for (int c = 0; c < 6; ++c) be[s][c] = t.be[c];
      ep[s] = t.ep;
      const int err = mpmc_j2_return_map(ws, solvers[s], &t.m, NULL, be[s], &ep[s], tau[s], NULL,
                                         &info[s]);
      if (err)
        fail_msg("state %d solver %d: error %d (%s), q_trial/kappa = %g, eta = %g, KINSOL flag %d",
                 k, solvers[s], err, mpmc_error_string(err), info[s].q_trial / info[s].kappa,
                 t.m.eta, info[s].kinsol_flag);
      assert_int_equal(info[s].plastic, 1);
      /* consistency after return, from the returned stress itself */
      const double kap = mpmc_j2_kappa(&t.m, ep[s]);
      /* the deviator of a stored stress is resolved only to round-off of its pressure
         (K tr eps >> kappa for nu -> 1/2): allow that on top of 1e-10 kappa */
      const double pr = fabs(tau[s][0] + tau[s][1] + tau[s][2]) / 3;
      const double cons = fabs(vm(tau[s]) - kap) / (kap + 32 * DBL_EPSILON * 1e10 * pr);
      if (cons > worst_cons) worst_cons = cons;
      if (cons > 1e-10)
        fail_msg("state %d solver %d: q after return %.17g, kappa(eps_p) %.17g: |q - kappa| = "
                 "%.3g (kappa + 3.2e11 eps |p|) (expected <= 1e-10), p = %g; q_trial %g, |g| %g "
                 "(tolerance %g), eta %g, G %g",
                 k, solvers[s], vm(tau[s]), kap, cons, pr, info[s].q_trial, info[s].residual,
                 mpmc_rm_tolerance(&t.m, t.ep), t.m.eta, t.m.G);
    }
    /* the solvers agree on dgamma to 1e-10 relative, or as far as their tolerance on the
       residual g(dgamma) = q_trial - 3G dgamma - kappa(eps_p + dgamma) fixes the root:
       2 tol / |g'|, g' = -3G + eta (kappa - kappa_r), which steep softening brings near 0
       (e.g. eta 1407, q/kappa 1.00016: 3.8e-10 relative apart, both within tolerance) */
    const double kap1 = mpmc_j2_kappa(&t.m, t.ep + info[0].dgamma);
    const double gslope = fabs(-3 * t.m.G + t.m.eta * (kap1 - t.m.kappa_r));
    const double loose = 2 * mpmc_rm_tolerance(&t.m, t.ep) / gslope / info[0].dgamma;
    for (int s = 1; s < 3; ++s) {
      const double rel = fabs(info[s].dgamma - info[0].dgamma) / info[0].dgamma;
      const double excess = rel / (1e-10 + loose);
      if (excess > worst_rel) worst_rel = excess;
      if (excess > 1)
        fail_msg("state %d: dgamma newton %.17g, solver %d %.17g: relative difference %.3g "
                 "(expected <= 1e-10 + 2 tol / |g'| / dgamma = %.3g); eta %g, q/kappa %g",
                 k, info[0].dgamma, solvers[s], info[s].dgamma, rel, 1e-10 + loose, t.m.eta,
                 info[0].q_trial / info[0].kappa);
    }
    /* auto falls back exactly when plain Newton cannot be trusted; in particular whenever
       the slope at the starting point (the lower bracket end) is not negative */
    const double lo = (info[0].q_trial - info[0].kappa) / (3 * t.m.G);
    const double slope = -3 * t.m.G + t.m.eta * (t.m.kappa_p - t.m.kappa_r) * exp(-t.m.eta * (t.ep + lo));
    if (slope >= 0) {
      ++nstiff;
      if (!info[2].fallback)
        fail_msg("state %d: g'(start) = %g >= 0 (non-monotone) but auto did not use KINSOL", k,
                 slope);
    }
    nfb += info[2].fallback;
    nbis += info[0].bisections;
    assert_int_equal(info[0].fallback, 0);
  }
  /* the random set must contain stiff cases, or the fallback is not being tested */
  if (nstiff < 100) fail_msg("only %d non-monotone cases in %d (expected >= 100)", nstiff, N);
  if (nfb < nstiff) fail_msg("auto fell back %d times for %d non-monotone cases", nfb, nstiff);
  mpmc_rm_ws_destroy(&ws);
  assert_null(ws);
  (void)nbis;
}

/* Perfect plasticity has the closed form dgamma = (q_trial - kappa) / 3G. */
static void test_perfect_plasticity(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  assert_int_equal(mpmc_rm_ws_create(&ws), 0);
  const mpmc_j2_param m = {.K = 5e6, .G = 2e6, .kappa_p = 1e3, .kappa_r = 1e3, .eta = 7};
  const double qs[] = {1e3 * (1 + 1e-12), 1.5e3, 1e5, 1e7};
  for (int s = 0; s < 3; ++s)
    for (size_t i = 0; i < sizeof qs / sizeof qs[0]; ++i) {
      double dg = -1;
      assert_int_equal(mpmc_rm_solve(ws, s, &m, qs[i], 0.3, &dg, NULL, NULL), 0);
      const double expect = (qs[i] - 1e3) / 6e6;
      if (fabs(dg - expect) > 1e-12 * expect + 1e-14 * qs[i] / 6e6)
        fail_msg("solver %d q %g: dgamma %.17g, expected %.17g", s, qs[i], dg, expect);
    }
  mpmc_rm_ws_destroy(&ws);
}

/* The landslide material (paper 4.4) never needs KINSOL: eta (kappa_p - kappa_r) < 3G. */
static void test_landslide_no_fallback(void **state) {
  (void)state;
  const double E = 25e6, nu = 0.499;
  const mpmc_j2_param m = {E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu)), 40.82e3, 2.45e3, 5.0};
  mpmc_rm_ws *ws;
  assert_int_equal(mpmc_rm_ws_create(&ws), 0);
  for (int k = 0; k < 2000; ++k) {
    const double ep = k % 3 ? loguni(1e-8, 3.0) : 0.0;
    const double q = mpmc_j2_kappa(&m, ep) * loguni(1 + 1e-10, 1e4);
    double dg;
    mpmc_j2_info info = {0};
    assert_int_equal(mpmc_rm_solve(ws, MPMC_SOLVER_AUTO, &m, q, ep, &dg, NULL, &info), 0);
    if (info.fallback || info.newton_iters > 8)
      fail_msg("landslide q %g eps_p %g: fallback %d, %d Newton iterations (expected none, <= 8)",
               q, ep, info.fallback, info.newton_iters);
  }
  mpmc_rm_ws_destroy(&ws);
}

/* kappa's exp (return_map.h, mpmc_rm_expneg4) against libm's: within 1 ulp over [0, 708]
 * (uniform and log-uniform arguments), exactly 1 at 0, 0 beyond 708, NaN kept; the four lanes
 * each their own value. */
static void test_expneg(void **state) {
  (void)state;
  double worst = 0.0, at = 0.0;
  uint64_t r = 0x9E3779B97F4A7C15ull; /* its own generator: the other tests' states unchanged */
#define U01_() ((double)((r = r * 6364136223846793005ull + 1442695040888963407ull) >> 11) * 0x1p-53)
  for (int k = 0; k < 200000; ++k) {
    const mpmc_rm_v4 x = {708.0 * U01_(), 1e-300 * pow(708e300, U01_()), 20.0 * U01_(), U01_()};
    mpmc_rm_v4 e;
    mpmc_rm_expneg4(&x, &e);
    for (int l = 0; l < 4; ++l) {
      const double ref = exp(-x[l]), ulp = nextafter(ref, INFINITY) - ref;
      const double err = fabs(e[l] - ref) / ulp;
      if (err > worst) worst = err, at = x[l];
    }
  }
#undef U01_
  if (worst > 1.0) fail_msg("exp(-x) %.3f ulp from libm's at x = %.17g (at most 1)", worst, at);
  const mpmc_rm_v4 x = {0.0, 708.5, INFINITY, NAN};
  mpmc_rm_v4 e;
  mpmc_rm_expneg4(&x, &e);
  assert_true(e[0] == 1.0 && e[1] == 0.0 && e[2] == 0.0 && isnan(e[3]));
  /* mpmc_j2_kappa: kappa_p at eps_p = 0, kappa_r + (kappa_p - kappa_r) exp(-eta eps_p) */
  const mpmc_j2_param m = {1e7, 5e6, 40e3, 2e3, 5.0};
  assert_true(mpmc_j2_kappa(&m, 0.0) == 40e3);
  assert_true(fabs(mpmc_j2_kappa(&m, 0.3) - (2e3 + 38e3 * exp(-1.5))) <= 1e-11 * 40e3);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_expneg),
      cmocka_unit_test(test_agreement),
      cmocka_unit_test(test_perfect_plasticity),
      cmocka_unit_test(test_landslide_no_fallback),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
