/* The symmetric 3x3 eigen-decomposition used in the return-map hot loop (mpmc_sym3_eig,
 * cyclic Jacobi in linalg.h) against LAPACK's dsyev: eigenvalues to 1e-13 of the spectral
 * radius, eigenvectors orthonormal, and the recomposition reproducing the tensor. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>
#include <lapacke.h>

#include "linalg.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x9E3779B97F4A7C15ull
#include "test_rand.h"

static void sort3(double *v) {
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (v[j] < v[i]) {
        const double t = v[i];
        v[i] = v[j];
        v[j] = t;
      }
}

static void check_one(const double *s, int k) {
  double lam[3], Q[3][3], A[9], w[3];
  mpmc_sym3_eig(s, lam, Q);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A[3 * i + j] = s[mpmc_voigt(i, j)];
  const int info = LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', 3, A, 3, w);
  assert_int_equal(info, 0);
  double l[3] = {lam[0], lam[1], lam[2]};
  sort3(l);
  const double scale = fmax(fmax(fabs(w[0]), fabs(w[2])), 1e-300);
  for (int a = 0; a < 3; ++a)
    if (fabs(l[a] - w[a]) > 1e-13 * scale)
      fail_msg("case %d: eigenvalue %d: Jacobi %.17g, dsyev %.17g (tolerance %.3g)", k, a, l[a],
               w[a], 1e-13 * scale);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double dot = Q[0][a] * Q[0][b] + Q[1][a] * Q[1][b] + Q[2][a] * Q[2][b];
      if (fabs(dot - (a == b)) > 1e-13)
        fail_msg("case %d: eigenvectors %d.%d = %.3g (expected %d)", k, a, b, dot, a == b);
    }
  double r[6];
  mpmc_sym3_compose(lam, Q, r);
  for (int c = 0; c < 6; ++c)
    if (fabs(r[c] - s[c]) > 1e-13 * scale)
      fail_msg("case %d: recomposed component %d = %.17g, expected %.17g", k, c, r[c], s[c]);
}

static void build(const double d[3], double R[3][3], double *s) { mpmc_sym3_compose(d, R, s); }

static void test_random(void **state) {
  (void)state;
  for (int k = 0; k < 20000; ++k) {
    double R[3][3], d[3], s[6];
    rand_rotation(R);
    for (int a = 0; a < 3; ++a) d[a] = exp(4.0 * (2 * urand() - 1)); /* b_e-like: > 0, wide */
    if (k % 4 == 1) d[1] = d[0];                       /* double eigenvalue */
    if (k % 4 == 2) d[1] = d[0] * (1 + 1e-9);          /* nearly double */
    if (k % 8 == 3) d[2] = d[1] = d[0];                /* isotropic */
    build(d, R, s);
    check_one(s, k);
  }
}

/* Plane-strain shaped tensors (zero yz, xz) and a diagonal one: no rotation needed. */
static void test_special(void **state) {
  (void)state;
  const double cases[][6] = {{1, 1, 1, 0, 0, 0},        {2, 3, 1, 0, 0, 0.5},
                             {1e-6, 1e6, 1, 0, 0, 1e-3}, {4, 4, 1, 0, 0, 1e-12},
                             {0, 0, 0, 0, 0, 0},         {-3, 2, 1, 0.5, -0.25, 0.125}};
  for (int k = 0; k < (int)(sizeof cases / sizeof cases[0]); ++k) check_one(cases[k], 100000 + k);
}

/* Tensors of magnitude 1e200 and 1e-200, whose squares overflow or underflow: the same
 * checks against dsyev relative to the spectral radius (the sweeps stopped at once on inf
 * and returned the diagonal). */
static void test_extreme(void **state) {
  (void)state;
  const double mags[] = {1e200, 1e-200, 1e300, 1e-300};
  for (int k = 0; k < 4000; ++k) {
    double R[3][3], d[3], s[6];
    rand_rotation(R);
    for (int a = 0; a < 3; ++a) d[a] = mags[k % 4] * (2 * urand() - 1);
    if (k % 8 == 5) d[1] = d[0];
    build(d, R, s);
    check_one(s, 200000 + k);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random),
      cmocka_unit_test(test_special),
      cmocka_unit_test(test_extreme),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
