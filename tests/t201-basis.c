/* Bases (issue 2, test 1): for every basis in 2D and 3D at random points, partition of unity
 * and linear reproduction to 1e-13, gradients summing to zero, and gradients consistent with
 * the weights (central differences). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "basis.h"
#include "test_util.h"

static double urand(unsigned *s) {
  *s = *s * 1664525u + 1013904223u;
  return (*s >> 8) * (1.0 / 16777216.0);
}

static void check_basis(int dim, int basis) {
  const double h = 0.37, origin = -1.3;
  unsigned seed = 12345u + 17u * (unsigned)(dim * 4 + basis);
  const int S = mpmc_stencil(basis);
  for (int trial = 0; trial < 2000; ++trial) {
    double x[3], lp = 0.0;
    for (int a = 0; a < dim; ++a) x[a] = origin + h * (5.0 + 10.0 * urand(&seed));
    if (basis == MPMC_BASIS_UGIMP) lp = h * (0.05 + 0.45 * urand(&seed)); /* 1 to 10 ppc */
    int base[3];
    double w[3][MPMC_MAX_STENCIL], dw[3][MPMC_MAX_STENCIL];
    for (int a = 0; a < dim; ++a)
      mpmc_basis_eval_1d(basis, (x[a] - origin) / h, lp / h, 1.0 / h, &base[a], w[a], dw[a]);
    double sum = 0.0, rep[3] = {0, 0, 0}, gsum[3] = {0, 0, 0}, grep[3][3] = {{0}};
    const int nk = dim == 3 ? S : 1;
    for (int k = 0; k < nk; ++k)
      for (int j = 0; j < S; ++j)
        for (int i = 0; i < S; ++i) {
          const int idx[3] = {i, j, k};
          double wn = 1.0, g[3] = {1, 1, 1}, xi[3];
          for (int a = 0; a < dim; ++a) {
            wn *= w[a][idx[a]];
            xi[a] = origin + h * (base[a] + idx[a]);
            for (int b = 0; b < dim; ++b) g[b] *= (a == b) ? dw[a][idx[a]] : w[a][idx[a]];
          }
          sum += wn;
          for (int a = 0; a < dim; ++a) {
            rep[a] += wn * xi[a];
            gsum[a] += g[a];
            for (int b = 0; b < dim; ++b) grep[a][b] += xi[a] * g[b];
          }
        }
    if (fabs(sum - 1.0) > 1e-13) fail_msg("dim %d basis %d: sum of weights %.17g, expected 1", dim, basis, sum);
    for (int a = 0; a < dim; ++a) {
      if (fabs(rep[a] - x[a]) > 1e-13 * (1 + fabs(x[a])))
        fail_msg("dim %d basis %d: sum w x_i = %.17g, expected x_p = %.17g", dim, basis, rep[a], x[a]);
      if (fabs(gsum[a]) > 1e-12 / h)
        fail_msg("dim %d basis %d: sum of gradients[%d] = %g, expected 0", dim, basis, a, gsum[a]);
      for (int b = 0; b < dim; ++b)
        if (fabs(grep[a][b] - (a == b)) > 1e-12)
          fail_msg("dim %d basis %d: sum x_i grad w [%d][%d] = %.17g, expected %d", dim, basis, a, b,
                   grep[a][b], a == b);
    }
    /* gradient of each 1D weight against a central difference of the weight */
    const double e = 1e-6 * h;
    for (int a = 0; a < dim; ++a) {
      int bp, bm;
      double wp[MPMC_MAX_STENCIL], wm[MPMC_MAX_STENCIL], d1[MPMC_MAX_STENCIL];
      mpmc_basis_eval_1d(basis, (x[a] + e - origin) / h, lp / h, 1.0 / h, &bp, wp, d1);
      mpmc_basis_eval_1d(basis, (x[a] - e - origin) / h, lp / h, 1.0 / h, &bm, wm, d1);
      if (bp != base[a] || bm != base[a]) continue; /* too close to a stencil shift */
      for (int k = 0; k < S; ++k) {
        const double fd = (wp[k] - wm[k]) / (2 * e);
        if (fabs(fd - dw[a][k]) > 1e-5 / h)
          fail_msg("dim %d basis %d: d w/dx = %.10g, central difference %.10g", dim, basis, dw[a][k], fd);
      }
    }
  }
}

static void test_bases_2d(void **state) {
  (void)state;
  for (int b = 0; b < 4; ++b) check_basis(2, b);
}

static void test_bases_3d(void **state) {
  (void)state;
  for (int b = 0; b < 4; ++b) check_basis(3, b);
}

/* Known values: quadratic B-spline at a node's own position is 3/4, cubic 2/3; uGIMP with
 * l = h/4 at zero distance is 1 - l/(2h) = 7/8. */
static void test_known_values(void **state) {
  (void)state;
  int base;
  double w[4], dw[4];
  mpmc_basis_eval_1d(MPMC_BASIS_BSPLINE2, 3.0, 0.0, 1.0, &base, w, dw);
  assert_int_equal(base, 2);
  TCLOSE(w[1], 0.75, 1e-15);
  TCLOSE(w[0], 0.125, 1e-15);
  mpmc_basis_eval_1d(MPMC_BASIS_BSPLINE3, 3.0, 0.0, 1.0, &base, w, dw);
  assert_int_equal(base, 2);
  TCLOSE(w[1], 2.0 / 3.0, 1e-15);
  TCLOSE(w[0], 1.0 / 6.0, 1e-15);
  mpmc_basis_eval_1d(MPMC_BASIS_UGIMP, 3.0, 0.25, 1.0, &base, w, dw);
  TCLOSE(w[1], 0.875, 1e-15);
  TCLOSE(w[0], 0.0625, 1e-15); /* (1 + l - 1)^2/(4 l) = l/4 */
}

/* The uGIMP weight (Bardenhagen & Kober 2004) in its four pieces (cell units: distance x,
 * half-length l) */
static double ugimp_ref(double x, double l) {
  const double a = fabs(x);
  if (a >= 1.0 + l) return 0.0;
  if (a > 1.0 - l) return (1.0 + l - a) * (1.0 + l - a) / (4.0 * l);
  if (a > l) return 1.0 - a;
  return 1.0 - (x * x + l * l) / (2.0 * l);
}

/* The library's uGIMP weights (basis.h computes them without branches, as an average of the
 * hat) against the pieces: to round-off, and to 1e-7 of themselves in the support's tails,
 * down to weights of 1e-15, where a node reached only by a tail divides a force by a mass ~ w
 * (an absolute error of 1e-17 in such a weight, which subtracting the hat's antiderivative at
 * the ends gives, is wrong by its own size there). */
static void test_ugimp_reference(void **state) {
  (void)state;
  unsigned seed = 99u;
  for (int trial = 0; trial < 20000; ++trial) {
    const double l = 0.02 + 0.48 * urand(&seed);
    double s = 10.0 + urand(&seed);
    if (trial % 2) { /* node 0 in its tail: s - b = f = 1 + l - delta */
      const double delta = pow(10.0, -2.0 - 5.0 * urand(&seed));
      s = 10.0 + (1.0 + l - delta);
    }
    int base;
    double w[MPMC_MAX_STENCIL], dw[MPMC_MAX_STENCIL];
    mpmc_basis_eval_1d(MPMC_BASIS_UGIMP, s, l, 1.0, &base, w, dw);
    for (int k = 0; k < 3; ++k) {
      const double ref = ugimp_ref(s - (base + k), l);
      if (!(fabs(w[k] - ref) <= 1e-7 * ref + 1e-300 && fabs(w[k] - ref) <= 1e-14))
        fail_msg("uGIMP s = %.17g, l = %.17g, node %d: w = %.17g, reference %.17g", s, l, k, w[k], ref);
    }
    if (w[3] != 0.0 || dw[3] != 0.0) fail_msg("uGIMP: the fourth lane is %g, %g (expected 0)", w[3], dw[3]);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bases_2d),
      cmocka_unit_test(test_bases_3d),
      cmocka_unit_test(test_known_values),
      cmocka_unit_test(test_ugimp_reference),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
