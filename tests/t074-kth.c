/* The k-th smallest of the points' values without gathering them (mpi.c, mpmc_dd_kth: the
 * geostatic state's column width, the median spacing): a bisection over the bit patterns of
 * non-negative doubles, which over MPI counts over the ranks.  In one process it must give
 * the sorted array's k-th element for every k: values over 600 orders of magnitude with
 * duplicates, +0, subnormals and the largest double; a single value; all alike. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "test_util.h"

static int by_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* every k of v[0 .. n) against the sorted copy, to the bit */
static void check_all(mpmc_sim sim, const double *v, int n) {
  double *s = malloc(sizeof *s * (size_t)n);
  assert_non_null(s);
  memcpy(s, v, sizeof *s * (size_t)n);
  qsort(s, (size_t)n, sizeof *s, by_double);
  for (int k = 0; k < n; ++k) {
    const double got = mpmc_dd_kth(sim, v, n, k);
    if (memcmp(&got, &s[k], sizeof got))
      fail_msg("k = %d of %d: %.17g, the sorted array has %.17g", k, n, got, s[k]);
  }
  free(s);
}

static void test_kth(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  enum { N = 701 };
  double v[N];
  uint64_t r = 88172645463325252u; /* xorshift64 */
  for (int q = 0; q < N; ++q) {
    r ^= r << 13, r ^= r >> 7, r ^= r << 17;
    v[q] = ldexp((double)(r >> 11) / 9007199254740992.0, (int)(r % 2000) - 1000);
  }
  for (int q = 0; q < N; q += 7) v[q] = v[(q * 31) % N]; /* duplicates */
  v[3] = 0.0;
  v[5] = 4.9406564584124654e-324; /* the least subnormal */
  v[8] = 2.2250738585072009e-308; /* the largest subnormal */
  v[13] = 1.7976931348623157e308;
  check_all(sim, v, N);
  check_all(sim, v, 1);
  for (int q = 0; q < 40; ++q) v[q] = 0.25; /* all alike: the spacings of one lattice */
  check_all(sim, v, 40);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_kth)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
