/* The closed-form symmetric 3x3 eigen-decomposition (mpmc_sym3_eig_closed, linalg.h: the
 * eigen path of plastic frictional points) against LAPACK's dsyev and the Jacobi sweeps of
 * mpmc_sym3_eig: eigenvalues to 1e-14 of the deviator's spread, eigenvectors orthonormal to
 * 1e-14, the recomposition reproducing the tensor to 1e-14, and each eigenvector within
 * 4 eps |B| / gap of dsyev's -- for relative gaps from 1 down to 1e-16, repeated eigenvalues,
 * Hencky-strain sized tensors with a large mean part and the degenerate cases. */
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>
#include <lapacke.h>

#include "linalg.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x2545F4914F6CDD1Dull
#include "test_rand.h"

static void check_one(const double *s, int k) {
  double lam[3], Q[3][3], A[9], w[3];
  mpmc_sym3_eig_closed(s, lam, Q);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A[3 * i + j] = s[mpmc_voigt(i, j)];
  const int info = LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', 3, A, 3, w);
  assert_int_equal(info, 0);
  /* order ours ascending as dsyev's */
  int o[3] = {0, 1, 2};
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (lam[o[j]] < lam[o[i]]) {
        const int t = o[i];
        o[i] = o[j];
        o[j] = t;
      }
  const double mean = (s[0] + s[1] + s[2]) / 3.0;
  const double spread = w[2] - w[0];
  /* the input's own round-off: the mean part of s, eps |m|, and the deviator's */
  const double scale = spread + fabs(mean) + DBL_MIN;
  for (int a = 0; a < 3; ++a)
    if (!(fabs(lam[o[a]] - w[a]) <= 1e-14 * scale))
      fail_msg("case %d: eigenvalue %d: closed form %.17g, dsyev %.17g (spread %.3g)", k, a,
               lam[o[a]], w[a], spread);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double dot = Q[0][a] * Q[0][b] + Q[1][a] * Q[1][b] + Q[2][a] * Q[2][b];
      if (!(fabs(dot - (a == b)) <= 1e-14))
        fail_msg("case %d: eigenvectors %d.%d = %.3g (expected %d)", k, a, b, dot, a == b);
    }
  double r[6];
  mpmc_sym3_compose(lam, Q, r);
  for (int c = 0; c < 6; ++c)
    if (!(fabs(r[c] - s[c]) <= 1e-14 * scale))
      fail_msg("case %d: recomposed component %d = %.17g, expected %.17g", k, c, r[c], s[c]);
  /* each eigenvector against dsyev's, within its gap's conditioning */
  for (int a = 0; a < 3; ++a) {
    double gap = INFINITY;
    for (int b = 0; b < 3; ++b)
      if (b != a) gap = fmin(gap, fabs(w[b] - w[a]));
    if (!(gap > 0.0)) continue;
    const double *q = &Q[0][o[a]]; /* column o[a]: q[3 * i] */
    const double x0 = q[3] * A[6 + a] - q[6] * A[3 + a], x1 = q[6] * A[a] - q[0] * A[6 + a],
                 x2 = q[0] * A[3 + a] - q[3] * A[a];
    const double sin_ang = sqrt(x0 * x0 + x1 * x1 + x2 * x2);
    const double err = sin_ang * gap / scale;
    if (!(err <= 16 * DBL_EPSILON))
      fail_msg("case %d: eigenvector %d off dsyev's by sin %.3g with gap %.3g of %.3g", k, a,
               sin_ang, gap, scale);
  }
}

static void build(const double d[3], double R[3][3], double *s) { mpmc_sym3_compose(d, R, s); }

static void test_random_gaps(void **state) {
  (void)state;
  for (int k = 0; k < 40000; ++k) {
    double R[3][3], d[3], s[6];
    rand_rotation(R);
    for (int a = 0; a < 3; ++a) d[a] = 2 * urand() - 1;
    const double g = loguni(1e-16, 1.0); /* relative gap of a close pair */
    switch (k % 6) {
      case 1: d[1] = d[0] + g * fabs(d[0] - d[2]); break;   /* a close pair */
      case 2: d[1] = d[0]; break;                           /* a double eigenvalue */
      case 3: d[1] = d[0] * (1 + g), d[2] = d[0] * (1 - g); /* all three close */ break;
      case 4: d[2] = d[1] = d[0]; break;                    /* isotropic */
      case 5: /* Hencky-strain sized deviator on a large mean: b_e near I */
        for (int a = 0; a < 3; ++a) d[a] = 1.0 + 1e-3 * d[a];
        break;
      default: break;
    }
    build(d, R, s);
    check_one(s, k);
  }
}

/* the same against the Jacobi sweeps: the eigen path's results of the two agree */
static void test_vs_jacobi(void **state) {
  (void)state;
  for (int k = 0; k < 20000; ++k) {
    double R[3][3], d[3], s[6], l1[3], Q1[3][3], l2[3], Q2[3][3], r1[6], r2[6], e[3];
    rand_rotation(R);
    for (int a = 0; a < 3; ++a) d[a] = 1e-3 * (2 * urand() - 1);
    if (k % 3 == 1) d[1] = d[0] * (1 + loguni(1e-16, 1e-2));
    build(d, R, s);
    mpmc_sym3_eig_closed(s, l1, Q1);
    mpmc_sym3_eig(s, l2, Q2);
    /* a function of s (exp(2 s), as the return's b_e) recomposed from either */
    for (int a = 0; a < 3; ++a) e[a] = exp(2 * l1[a]);
    mpmc_sym3_compose(e, Q1, r1);
    for (int a = 0; a < 3; ++a) e[a] = exp(2 * l2[a]);
    mpmc_sym3_compose(e, Q2, r2);
    for (int c = 0; c < 6; ++c)
      if (!(fabs(r1[c] - r2[c]) <= 64 * DBL_EPSILON))
        fail_msg("case %d: exp(2 s)[%d] closed form %.17g, Jacobi %.17g", k, c, r1[c], r2[c]);
  }
}

static void test_special(void **state) {
  (void)state;
  const double cases[][6] = {{1, 1, 1, 0, 0, 0},        {2, 3, 1, 0, 0, 0.5},
                             {1e-6, 1e6, 1, 0, 0, 1e-3}, {4, 4, 1, 0, 0, 1e-12},
                             {0, 0, 0, 0, 0, 0},         {-3, 2, 1, 0.5, -0.25, 0.125},
                             {1, 1, 1, 1e-300, 0, 0},    {5, 5, 5, 1, 1, 1},
                             {1, 1, 1, 1e-9, 1e-9, 0},   {1e100, -1e100, 0, 1e99, 0, 0}};
  for (int k = 0; k < (int)(sizeof cases / sizeof cases[0]); ++k) check_one(cases[k], 100000 + k);
  /* not finite: NaN out, as the Jacobi sweeps give (the callers' guards report it) */
  const double bad[6] = {NAN, 1, 1, 0, 0, 0};
  double lam[3], Q[3][3];
  mpmc_sym3_eig_closed(bad, lam, Q);
  assert_true(isnan(lam[0]) || isnan(lam[1]) || isnan(lam[2]));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_gaps),
      cmocka_unit_test(test_vs_jacobi),
      cmocka_unit_test(test_special),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
