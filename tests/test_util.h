/* Helpers shared by the C tests: lattice seeding of boxes and small checks. */
#ifndef MPMC_TEST_UTIL_H
#define MPMC_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "mpmc.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Fail the current cmocka test with the library's message when a call fails. */
/* The context whose last error TCALL prints (tests set it after creating one). */
static mpmc_context test_ctx __attribute__((unused));
#define TCALL(expr)                                                                   \
  do {                                                                                \
    int tcall_ierr_ = (expr);                                                         \
    if (tcall_ierr_)                                                                  \
      fail_msg("%s -> %d: %s", #expr, tcall_ierr_,                                    \
               test_ctx ? mpmc_context_last_error(test_ctx) : mpmc_error_string(tcall_ierr_)); \
  } while (0)

/* |got - want| <= tol, else fail with both values */
#define TCLOSE(got, want, tol)                                                              \
  do {                                                                                      \
    const double tg_ = (got), tw_ = (want), tt_ = (tol);                                    \
    if (!(fabs(tg_ - tw_) <= tt_))                                                          \
      fail_msg("%s = %.17g, expected %.17g (tolerance %g)", #got, tg_, tw_, tt_);           \
  } while (0)

/* Seed a box [lo, hi] (whole cells of size h) with ppc points per cell per axis.
 * Returns the number of points; x and vol are malloc'ed. */
static inline int test_lattice(int dim, const double *lo, const double *hi, double h, int ppc,
                               double **x, double **vol) {
  int nc[3] = {1, 1, 1}, np[3] = {1, 1, 1};
  for (int a = 0; a < dim; ++a) {
    nc[a] = (int)lround((hi[a] - lo[a]) / h);
    np[a] = nc[a] * ppc;
  }
  const int n = np[0] * np[1] * np[2];
  *x = malloc(sizeof(double) * (size_t)n * dim);
  *vol = malloc(sizeof(double) * (size_t)n);
  const double dx = h / ppc, v = pow(dx, dim);
  int q = 0;
  for (int k = 0; k < np[2]; ++k)
    for (int j = 0; j < np[1]; ++j)
      for (int i = 0; i < np[0]; ++i, ++q) {
        const int idx[3] = {i, j, k};
        for (int a = 0; a < dim; ++a) (*x)[q * dim + a] = lo[a] + (idx[a] + 0.5) * dx;
        (*vol)[q] = v;
      }
  return n;
}

#endif
