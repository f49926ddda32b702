/* The eigen-free small-strain path of the Hencky and Hencky-J2 updates (issue 6, linalg.h:
 * eps = 1/2 ln b = atanh((b - I)(b + I)^-1) and exp(M) as series) against references:
 *   - the Hencky strain and the exponential against a long-double eigen-decomposition of
 *     the same b (M) to 1e-13 of |eps| (|exp M|), on small (1e-8 .. 1e-2) and moderate
 *     strains, near-isotropic, strongly anisotropic and near-threshold b, and against the
 *     library's own eigen path to 1e-13 plus that path's round-off (~1e-16 on ln lambda);
 *   - the Hencky material's stress over 3,000 random deformations (series and eigen path)
 *     against the long-double closed form to 1e-13;
 *   - the Hencky-J2 return map: perfect plasticity against the long-double closed form
 *     (stress, b_e, eps_p to 1e-13), and with softening against the eigen path alone
 *     (mpmc_j2_return_map_eig) to 1e-13 plus the local solver's tolerance. */
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "mpmc_impl.h"
#include "return_map.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x853C49E6748FEA9Bull
#include "test_rand.h"

/* ---- long-double reference: cyclic Jacobi to round-off of long double --------------- */
typedef long double ld;

/* valgrind runs x87 long double at double precision: the long-double references are then
 * no references, and the tests that need them skip */
static int have_long_double(void) {
  volatile ld one = 1.0L, t = one + 0x1p-60L;
  return t != one;
}

/* f(s) = Q f(Lambda) Q^T for f = 1/2 ln (which = 0) or exp (which = 1).  The logarithm
 * decomposes s - I (exact) and takes 1/2 log1p: the eigenvalues of s - I carry round-off
 * relative to |s - I|, so the reference is accurate to ~1e-19 relative even for |eps| ~ 1e-8. */
static void ref_fun(const double *s, int which, ld *out) {
  ld A[3][3], Q[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      A[i][j] = (ld)s[mpmc_voigt(i, j)] - (which == 0 && i == j ? 1.0L : 0.0L);
      Q[i][j] = i == j;
    }
  for (int sweep = 0; sweep < 50; ++sweep) {
    const ld off = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
    if (off == 0) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        const ld apq = A[p][q];
        if (apq == 0) continue;
        const ld th = (A[q][q] - A[p][p]) / (2 * apq);
        const ld t = (th >= 0 ? 1.0L : -1.0L) / (fabsl(th) + sqrtl(th * th + 1));
        const ld c = 1 / sqrtl(t * t + 1), sn = t * c;
        for (int k = 0; k < 3; ++k) {
          const ld akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - sn * akq;
          A[k][q] = sn * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const ld apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - sn * aqk;
          A[q][k] = sn * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const ld qkp = Q[k][p], qkq = Q[k][q];
          Q[k][p] = c * qkp - sn * qkq;
          Q[k][q] = sn * qkp + c * qkq;
        }
      }
  }
  ld f[3];
  for (int a = 0; a < 3; ++a) f[a] = which ? expl(A[a][a]) : 0.5L * log1pl(A[a][a]);
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      out[mpmc_voigt(i, j)] = f[0] * Q[i][0] * Q[j][0] + f[1] * Q[i][1] * Q[j][1] + f[2] * Q[i][2] * Q[j][2];
}

static ld norm_ld(const ld *s) {
  return sqrtl(s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}
static double dist_ld(const double *a, const ld *b) {
  ld d[6];
  for (int k = 0; k < 6; ++k) d[k] = (ld)a[k] - b[k];
  return (double)norm_ld(d);
}
static double dist(const double *a, const double *b) {
  double d[6];
  for (int k = 0; k < 6; ++k) d[k] = a[k] - b[k];
  return sqrt(mpmc_sym3_norm2(d));
}

/* b = R diag(exp(2 e)) R^T for principal strains e of kind k:
 *   0 small isotropic-random, 1 moderate, 2 near-isotropic, 3 anisotropic (one strain
 *   1e4 x the others), 4 near the series threshold |Z|_F ~ 0.179, 5 pure volumetric */
static void rand_b(int kind, double *b) {
  double e[3], R[3][3];
  rand_rotation(R);
  const double mag = kind == 1 ? loguni(1e-2, 0.17) : loguni(1e-8, 1e-2);
  for (int a = 0; a < 3; ++a) e[a] = sgn() * mag * urand();
  if (kind == 2) {
    const double e0 = sgn() * mag;
    for (int a = 0; a < 3; ++a) e[a] = e0 * (1 + 1e-9 * (2 * urand() - 1));
  } else if (kind == 3) {
    e[0] = sgn() * mag;
    e[1] = 1e-4 * mag * (2 * urand() - 1);
    e[2] = 1e-4 * mag * (2 * urand() - 1);
  } else if (kind == 4) {
    /* z = tanh(e): |Z|_F = 0.179 (1 +- 1e-3) */
    const double target = 0.179 * (1 + 1e-3 * (2 * urand() - 1));
    double z[3], n = 0;
    for (int a = 0; a < 3; ++a) {
      z[a] = 2 * urand() - 1;
      n += z[a] * z[a];
    }
    for (int a = 0; a < 3; ++a) e[a] = atanh(z[a] * target / sqrt(n));
  } else if (kind == 5) {
    e[1] = e[2] = e[0];
  }
  double lam[3];
  for (int a = 0; a < 3; ++a) lam[a] = exp(2 * e[a]);
  mpmc_sym3_compose(lam, R, b);
}

static void test_log_series(void **state) {
  (void)state;
  int used[6] = {0}, fell_back[6] = {0};
  const int ld_ok = have_long_double();
  double worst_ref = 0, worst_eig = 0;
  for (int k = 0; k < 60000; ++k) {
    const int kind = k % 6;
    double b[6], eps[6], eig[6];
    ld ref[6];
    rand_b(kind, b);
    if (mpmc_sym3_log_series(b, eps)) {
      ++fell_back[kind];
      continue;
    }
    ++used[kind];
    ref_fun(b, 0, ref);
    mpmc_sym3_log_eig(b, eig);
    const double n = sqrt(mpmc_sym3_norm2(eig));
    const double e_ref = dist_ld(eps, ref), e_eig = dist(eps, eig);
    if (e_ref / n > worst_ref) worst_ref = e_ref / n;
    if (e_eig / (1e-13 * n + 32 * DBL_EPSILON) > worst_eig) worst_eig = e_eig / (1e-13 * n + 32 * DBL_EPSILON);
    if (ld_ok && !(e_ref <= 1e-13 * n))
      fail_msg("case %d (kind %d): series ln b off the long-double reference by %.3g of |eps| = %.3g",
               k, kind, e_ref / n, n);
    /* the eigen path: 1/2 ln(lambda) with lambda ~ 1 carries ~1e-16 absolute */
    if (!(e_eig <= 1e-13 * n + 32 * DBL_EPSILON))
      fail_msg("case %d (kind %d): series and eigen path differ by %.3g, |eps| = %.3g", k, kind,
               e_eig, n);
  }
  for (int kind = 0; kind < 6; ++kind)
    if (used[kind] == 0) fail_msg("kind %d never took the series", kind);
  /* near the threshold both ways are taken; small strains (kinds 0, 2, 3, 5) never fall back */
  if (fell_back[4] == 0) fail_msg("no near-threshold b fell back to the eigen path");
  for (int kind = 0; kind < 6; ++kind)
    if (kind != 1 && kind != 4 && fell_back[kind]) fail_msg("kind %d: %d small-strain b fell back", kind, fell_back[kind]);
  (void)worst_ref;
  (void)worst_eig;
  if (getenv("T411_VERBOSE"))
    print_message("log: worst vs long double %.3g, vs eigen path (error / tolerance) %.3g; near threshold %d series, %d eigen\n",
                  worst_ref, worst_eig, used[4], fell_back[4]);
}

static void test_log_series_rejects(void **state) {
  (void)state;
  double eps[6];
  const double big[6] = {1.5, 1, 1, 0, 0, 0}; /* ln 1.5 / 2 = 0.2 > 0.18 */
  const double neg[6] = {-0.5, 1, 1, 0, 0, 0}, sing[6] = {-1, 1, 1, 0, 0, 0};
  const double nan_b[6] = {1, 1, NAN, 0, 0, 0}, inf_b[6] = {1, INFINITY, 1, 0, 0, 0};
  assert_int_equal(mpmc_sym3_log_series(big, eps), 1);
  assert_int_equal(mpmc_sym3_log_series(neg, eps), 1);
  assert_int_equal(mpmc_sym3_log_series(sing, eps), 1);
  assert_int_equal(mpmc_sym3_log_series(nan_b, eps), 1);
  assert_int_equal(mpmc_sym3_log_series(inf_b, eps), 1);
  const double id[6] = {1, 1, 1, 0, 0, 0};
  assert_int_equal(mpmc_sym3_log_series(id, eps), 0);
  for (int k = 0; k < 6; ++k) assert_true(eps[k] == 0.0);
}

/* ln x by the scalar series (mpmc_log_series: the Neo-Hookean ln J) against long double's
 * log1pl of x - 1 (exact for x in [0.5, 2]): x - 1 log-uniform from 1e-14 to past the table's
 * reach, both signs; within the reach 2 ulp of ln x; beyond it (and for x <= 0, NaN, Inf)
 * refused */
static void test_log_series_scalar(void **state) {
  (void)state;
  if (!have_long_double()) skip();
  double worst = 0.0;
  int used = 0, refused = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = 1.0 + sgn() * loguni(1e-14, 0.6);
    double y;
    if (mpmc_log_series(x, &y)) {
      ++refused;
      if (fabs(log(x)) < 0.35) fail_msg("x = %.17g (ln x = %g) refused", x, log(x));
      continue;
    }
    ++used;
    const ld ref = log1pl((ld)x - 1.0L);
    const double err = (double)(fabsl((ld)y - ref) / fabsl(ref));
    if (err > worst) worst = err;
    if (!(err <= 2.0 * DBL_EPSILON)) fail_msg("x = %.17g: ln x %.17g, reference %.20Lg", x, y, ref);
  }
  if (used < 10000 || refused < 200) fail_msg("weak mix: %d by the series, %d refused", used, refused);
  double y;
  const double bad[5] = {0.0, -0.5, NAN, INFINITY, 2.5};
  for (int k = 0; k < 5; ++k)
    if (!mpmc_log_series(bad[k], &y)) fail_msg("x = %g taken by the series", bad[k]);
  assert_int_equal(mpmc_log_series(1.0, &y), 0);
  assert_true(y == 0.0);
  if (getenv("T411_VERBOSE"))
    print_message("scalar log: worst %.3g relative (%d by the series, %d refused)\n", worst, used, refused);
}

static void test_exp_series(void **state) {
  (void)state;
  if (!have_long_double()) skip();
  double worst = 0;
  for (int k = 0; k < 30000; ++k) {
    double R[3][3], d[3], M[6], E[6] = {0};
    ld ref[6];
    rand_rotation(R);
    const double mag = k % 3 == 0 ? loguni(1e-9, 1e-2) : loguni(1e-2, 0.4);
    for (int a = 0; a < 3; ++a) d[a] = mag * (2 * urand() - 1);
    if (k % 5 == 0) d[2] = -(d[0] + d[1]) / 2; /* deviatoric, as on the fast path */
    if (k % 5 == 0) d[0] /= 2, d[1] /= 2;
    mpmc_sym3_compose(d, R, M);
    assert_int_equal(mpmc_sym3_exp_series(M, E), 0);
    ref_fun(M, 1, ref);
    const double n = (double)norm_ld(ref), e = dist_ld(E, ref);
    if (e / n > worst) worst = e / n;
    if (!(e <= 1e-13 * n)) fail_msg("case %d: exp series off by %.3g of |exp M|, |M| = %.3g", k, e / n, mag);
  }
  const double big[6] = {0.8, 0, 0, 0, 0, 0}, nan_m[6] = {NAN, 0, 0, 0, 0, 0};
  double E[6];
  assert_int_equal(mpmc_sym3_exp_series(big, E), 1);
  assert_int_equal(mpmc_sym3_exp_series(nan_m, E), 1);
  if (getenv("T411_VERBOSE")) print_message("exp: worst vs long double %.3g\n", worst);
}

/* The Hencky material on 3,000 points, each a random deformation from the natural state:
 * sigma = (K tr eps I + 2G dev eps) / J, eps = 1/2 ln(F F^T), J = exp(tr eps) (the material's
 * sqrt(det b)), in blocks of four. */
static void test_hencky_material(void **state) {
  (void)state;
  if (!have_long_double()) skip();
  enum { N = 3000 };
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.5));
  const double E = 25e6, nu = 0.45, K = E / (3 * (1 - 2 * nu)), G = E / (2 * (1 + nu));
  int id;
  TCALL(mpmc_sim_add_material_hencky(sim, E, nu, 1000.0, &id));
  /* b to the bit: the baseline set has no contraction (t413 covers the others) */
  TCALL(mpmc_sim_set_kernels(sim, MPMC_KERNELS_BASELINE));
  static double x[3 * N], v[N];
  for (int q = 0; q < N; ++q) {
    for (int a = 0; a < 3; ++a) x[3 * q + a] = 0.1 + 0.8 * urand();
    v[q] = 1.0;
  }
  TCALL(mpmc_sim_add_particles(sim, N, x, v, id, NULL));
  TCALL(mpmc_sim_prepare(sim));
  static double F[N][3][3];
  for (int q = 0; q < N; ++q) {
    const double mag = q % 3 == 2 ? loguni(0.05, 0.3) : loguni(1e-7, 0.05);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F[q][i][j] = (i == j) + mag * (2 * urand() - 1);
    memcpy(sim->p.dF + 9 * q, F[q], sizeof F[q]);
  }
  TCALL(sim->mats[id].ops->stress_update(sim, &sim->mats[id], id, 1e-3));
  double worst = 0;
  for (int q = 0; q < N; ++q) {
    double b[6] = {1, 1, 1, 0, 0, 0};
    mpmc_push_forward(F[q], b);
    for (int k = 0; k < 6; ++k)
      if (b[k] != sim->p.be[6 * q + k]) fail_msg("point %d: b_e[%d] %.17g, expected %.17g", q, k, sim->p.be[6 * q + k], b[k]);
    ld eps[6], sig[6];
    ref_fun(b, 0, eps);
    const ld tr = eps[0] + eps[1] + eps[2], J = expl(tr);
    for (int k = 0; k < 6; ++k) sig[k] = 2 * (ld)G * eps[k] / J;
    for (int k = 0; k < 3; ++k) sig[k] += ((ld)K - 2 * (ld)G / 3) * tr / J;
    const double n = (double)norm_ld(sig), e = dist_ld(sim->p.stress + 6 * q, sig);
    if (e / n > worst) worst = e / n;
    if (!(e <= 1e-13 * n))
      fail_msg("point %d: Hencky stress off the long-double closed form by %.3g of |sigma| (|eps| = %.3g)",
               q, e / n, (double)norm_ld(eps));
  }
  if (getenv("T411_VERBOSE")) print_message("hencky: worst stress vs long double %.3g\n", worst);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

/* A random J2 material: landslide- to column-like */
static void rand_material(mpmc_j2_param *m, int perfect) {
  const double E = loguni(1e6, 1e8), nu = 0.3 + 0.1999 * urand();
  m->K = E / (3 * (1 - 2 * nu));
  m->G = E / (2 * (1 + nu));
  m->kappa_p = E * loguni(1e-5, 3e-3);
  m->kappa_r = perfect ? m->kappa_p : m->kappa_p * loguni(0.05, 1.0);
  m->eta = perfect ? 0.0 : loguni(0.1, 50.0);
}

/* A state b_e^n (up to |q| ~ 1.5 kappa, random volumetric strain), eps_p^n and an increment */
static void rand_state(const mpmc_j2_param *m, double *be, double *ep, double F[3][3]) {
  *ep = urand() < 0.3 ? 0.0 : loguni(1e-4, 2.0);
  const double kap = mpmc_j2_kappa(m, *ep);
  double d[3], R[3][3], n = 0;
  for (int a = 0; a < 3; ++a) d[a] = 2 * urand() - 1;
  const double mean = (d[0] + d[1] + d[2]) / 3;
  for (int a = 0; a < 3; ++a) {
    d[a] -= mean;
    n += d[a] * d[a];
  }
  /* q = sqrt(3/2) 2G |dev eps| */
  const double s = 1.5 * urand() * kap / (sqrt(1.5) * 2 * m->G * sqrt(n)), vol = 1e-3 * (2 * urand() - 1);
  for (int a = 0; a < 3; ++a) d[a] = exp(2 * (s * d[a] + vol / 3));
  rand_rotation(R);
  mpmc_sym3_compose(d, R, be);
  /* one in ten large enough for the eigen path (|eps| > 0.18) */
  const double u = urand();
  const double mag = u < 0.45 ? loguni(1e-6, 1e-3) : u < 0.9 ? loguni(1e-3, 0.05) : loguni(0.1, 0.3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F[i][j] = (i == j) + mag * (2 * urand() - 1);
}

static void test_j2_perfect_plasticity(void **state) {
  (void)state;
  if (!have_long_double()) skip();
  int plastic = 0, series = 0;
  double worst = 0;
  for (int k = 0; k < 20000; ++k) {
    mpmc_j2_param m;
    rand_material(&m, 1);
    double be[6], ep, F[3][3], tau[6], J, b[6];
    rand_state(&m, be, &ep, F);
    memcpy(b, be, sizeof b);
    mpmc_push_forward(F, b);
    double tmp[6];
    const int on_series = mpmc_sym3_log_series(b, tmp) == 0;
    series += on_series;
    const double ep0 = ep;
    mpmc_j2_info info = {0};
    TCALL(mpmc_j2_return_map(NULL, MPMC_SOLVER_NEWTON, &m, F, be, &ep, tau, &J, &info));
    plastic += info.plastic;
    /* long-double closed form: radial return onto q = kappa */
    ld eps[6], e[6], t[6], bn[6], qn2 = 0;
    ref_fun(b, 0, eps);
    const ld tr = eps[0] + eps[1] + eps[2];
    for (int c = 0; c < 6; ++c) e[c] = eps[c] - (c < 3 ? tr / 3 : 0);
    qn2 = 1.5L * 4 * (ld)m.G * m.G * norm_ld(e) * norm_ld(e);
    const ld q = sqrtl(qn2), f = q > m.kappa_p ? m.kappa_p / q : 1.0L;
    if ((q > m.kappa_p) != (info.plastic == 1)) continue; /* at the surface to round-off */
    for (int c = 0; c < 6; ++c) t[c] = 2 * (ld)m.G * f * e[c] + (c < 3 ? (ld)m.K * tr : 0);
    double tn = 0;
    const double e_tau = dist_ld(tau, t), n_tau = (double)norm_ld(t);
    if (info.plastic) {
      double M[6];
      for (int c = 0; c < 6; ++c) M[c] = (double)(2 * (f * e[c] + (c < 3 ? tr / 3 : 0)));
      ref_fun(M, 1, bn);
      tn = dist_ld(be, bn) / (double)norm_ld(bn);
      TCLOSE(ep, ep0 + (double)((q - m.kappa_p) / (3 * (ld)m.G)), 1e-13 * fmax(ep, 1e-300) + 1e-13 * (double)(q / (3 * m.G)));
    } else {
      for (int c = 0; c < 6; ++c)
        if (be[c] != b[c]) fail_msg("case %d: elastic b_e[%d] %.17g, expected %.17g", k, c, be[c], b[c]);
    }
    /* the eigen path's ln lambda carry ~1e-16 absolute (the series: relative) */
    const double rnd = on_series ? (double)norm_ld(eps) : 1.0 + (double)norm_ld(eps);
    TCLOSE(J, (double)expl(tr), (2 + 8 * rnd) * DBL_EPSILON * J);
    /* tr eps (any method) carries round-off ~1e-16 |eps|, which K >> G (nu -> 1/2) turns
       into K 1e-16 |eps| on tau: the conditioning of tau(b), allowed on top of 1e-13 */
    const double tol_tau = 1e-13 * n_tau + 16 * DBL_EPSILON * (3 * m.K + 2 * m.G) * rnd;
    if (e_tau / tol_tau > worst) worst = e_tau / tol_tau;
    if (!(e_tau <= tol_tau) || !(tn <= 1e-13))
      fail_msg("case %d (plastic %d): tau off by %.3g, b_e off by %.3g (relative)", k, info.plastic,
               e_tau / n_tau, tn);
  }
  if (plastic < 2000 || series < 15000 || series > 19500)
    fail_msg("too few plastic (%d), series (%d) or eigen-path cases", plastic, series);
  if (getenv("T411_VERBOSE"))
    print_message("j2 perfect: %d plastic, %d series of 20000; worst tau error / tolerance %.3g\n", plastic,
                  series, worst);
}

static void test_j2_softening_vs_eig(void **state) {
  (void)state;
  int plastic = 0, eigen = 0;
  double worst_tau = 0, worst_be = 0;
  for (int k = 0; k < 20000; ++k) {
    mpmc_j2_param m;
    rand_material(&m, 0);
    double be[6], ep, F[3][3];
    rand_state(&m, be, &ep, F);
    double be2[6], ep2 = ep, tau[6], tau2[6], J, J2;
    memcpy(be2, be, sizeof be);
    mpmc_j2_info i1 = {0}, i2 = {0};
    double b[6], tmp[6];
    memcpy(b, be, sizeof b);
    mpmc_push_forward(F, b);
    eigen += mpmc_sym3_log_series(b, tmp) != 0;
    TCALL(mpmc_j2_return_map(NULL, MPMC_SOLVER_NEWTON, &m, F, be, &ep, tau, &J, &i1));
    TCALL(mpmc_j2_return_map_eig(NULL, MPMC_SOLVER_NEWTON, &m, F, be2, &ep2, tau2, &J2, &i2));
    if (i1.plastic != i2.plastic) {
      if (fabs(i1.q_trial - i1.kappa) <= 1e-12 * i1.kappa) continue; /* at the surface */
      fail_msg("case %d: plastic %d (series) vs %d (eigen), q_trial %.17g, kappa %.17g", k, i1.plastic,
               i2.plastic, i1.q_trial, i1.kappa);
    }
    plastic += i1.plastic;
    /* the eigen path's round-off (~1e-16 on each ln lambda, times 3K + 2G), plus, when plastic,
       the scalar solve's tolerance on q_new (return_map.h) */
    const double n_tau = sqrt(mpmc_sym3_norm2(tau2));
    const double tol_q = i1.plastic ? 2 * mpmc_rm_tolerance(&m, ep2 - i2.dgamma) : 0;
    const double tol_tau = 1e-13 * n_tau + 32 * DBL_EPSILON * (3 * m.K + 2 * m.G) + 2 * tol_q;
    const double e_tau = dist(tau, tau2), e_be = dist(be, be2);
    if (e_tau / tol_tau > worst_tau) worst_tau = e_tau / tol_tau;
    if (e_be > worst_be) worst_be = e_be;
    if (!(e_tau <= tol_tau))
      fail_msg("case %d (plastic %d): tau series vs eigen differ by %.3g (tolerance %.3g, |tau| %.3g)", k,
               i1.plastic, e_tau, tol_tau, n_tau);
    const double tol_be = 1e-13 + 32 * DBL_EPSILON + (i1.plastic ? 2 * tol_q / m.G : 0);
    if (!(e_be <= tol_be)) fail_msg("case %d (plastic %d): b_e differs by %.3g (tolerance %.3g)", k, i1.plastic, e_be, tol_be);
    TCLOSE(ep, ep2, 1e-13 * ep2 + (i1.plastic ? 32 * DBL_EPSILON + 2 * tol_q / (3 * m.G) : 0));
    TCLOSE(J, J2, 32 * DBL_EPSILON * J2);
  }
  if (plastic < 2000 || eigen < 500) fail_msg("too few plastic (%d) or eigen-path (%d) cases", plastic, eigen);
  if (getenv("T411_VERBOSE"))
    print_message("j2 softening: %d plastic, %d eigen path of 20000; worst tau error / tolerance %.3g, b_e error %.3g\n", plastic, eigen,
                  worst_tau, worst_be);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_log_series),         cmocka_unit_test(test_log_series_rejects),
      cmocka_unit_test(test_log_series_scalar),
      cmocka_unit_test(test_exp_series),         cmocka_unit_test(test_hencky_material),
      cmocka_unit_test(test_j2_perfect_plasticity), cmocka_unit_test(test_j2_softening_vs_eig),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
