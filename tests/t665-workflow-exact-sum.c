/* The front end's exact sums (workflows/par.c, wf_xsum): the series' centre of mass and
 * hydrostatic error add each rank's own points and reduce, so the sum must not depend on the
 * order of the additions.  Checked: the same bits in any order, the exact sum rounded once
 * (cases where a running double sum is wrong), ties to even, subnormals, overflow and the
 * infinities and NaNs. */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "wf.h"

static double sum_of(const double *v, int n) {
  wf_xsum s;
  memset(&s, 0, sizeof s);
  for (int i = 0; i < n; ++i) wf_xsum_add(&s, v[i]);
  return wf_xsum_value(&s);
}

static uint64_t rng(uint64_t *st) { /* splitmix64 */
  uint64_t z = (*st += 0x9e3779b97f4a7c15u);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return z ^ (z >> 31);
}

/* 20,000 values over 2^-60 .. 2^60 of both signs: forwards, backwards, shuffled and the
 * halves summed apart and then together give the same bits; a running double sum does not */
static void test_any_order(void **state) {
  (void)state;
  enum { N = 20000 };
  static double v[N], w[N];
  uint64_t st = 42;
  for (int i = 0; i < N; ++i) {
    const double m = (double)(rng(&st) >> 11) / 9007199254740992.0; /* [0, 1) */
    v[i] = ldexp(m, (int)(rng(&st) % 121) - 60) * (rng(&st) & 1 ? -1 : 1);
  }
  const double a = sum_of(v, N);
  for (int i = 0; i < N; ++i) w[i] = v[N - 1 - i];
  assert_true(sum_of(w, N) == a);
  memcpy(w, v, sizeof w);
  for (int i = N - 1; i > 0; --i) { /* Fisher-Yates */
    const int j = (int)(rng(&st) % (uint64_t)(i + 1));
    const double t = w[i];
    w[i] = w[j];
    w[j] = t;
  }
  assert_true(sum_of(w, N) == a);
  double naive_f = 0, naive_b = 0;
  for (int i = 0; i < N; ++i) naive_f += v[i], naive_b += v[N - 1 - i];
  assert_true(naive_f != naive_b); /* the case is one where order matters */
  assert_true(fabs(naive_f - a) <= 1e-3 * fabs(a) + 1.0); /* and the exact sum is near both */
  /* the exact sum of the halves, each rounded, is not in general the exact sum: add the
     halves' digits instead, as the ranks' reduction does (integers, exact) */
  wf_xsum h[2];
  memset(h, 0, sizeof h);
  for (int i = 0; i < N; ++i) wf_xsum_add(&h[i < N / 3], v[i]);
  for (int k = 0; k < WF_XSUM_DIGITS; ++k) h[0].d[k] += h[1].d[k];
  assert_true(wf_xsum_value(&h[0]) == a);
}

static void test_exact_cases(void **state) {
  (void)state;
  const double big[] = {1e100, 1.0, -1e100};
  assert_true(sum_of(big, 3) == 1.0);
  double tenth[10], mtenth[10];
  for (int i = 0; i < 10; ++i) tenth[i] = 0.1, mtenth[i] = -0.1;
  assert_true(sum_of(tenth, 10) == 1.0); /* 1.0000000000000000555 rounded; a running sum: 1 - 1.1e-16 */
  assert_true(sum_of(mtenth, 10) == -1.0);
  const double p53 = 9007199254740992.0; /* 2^53 */
  const double twice[] = {p53, 1.0, 1.0};
  assert_true(sum_of(twice, 3) == p53 + 2.0); /* a running sum stays at 2^53 */
  const double tie_even[] = {p53, 1.0};     /* 2^53 + 1: a tie, to the even 2^53 */
  assert_true(sum_of(tie_even, 2) == p53);
  const double tie_up[] = {p53 + 2.0, 1.0}; /* 2^53 + 3: a tie, to the even 2^53 + 4 */
  assert_true(sum_of(tie_up, 2) == p53 + 4.0);
  const double above_tie[] = {p53, 1.0, ldexp(1.0, -60)}; /* just above a tie: up */
  assert_true(sum_of(above_tie, 3) == p53 + 2.0);
  const double tiny = ldexp(1.0, -1074); /* the least subnormal */
  const double sub[] = {tiny, tiny, tiny, -tiny, 3 * DBL_MIN, -DBL_MIN};
  assert_true(sum_of(sub, 6) == 2 * tiny + 2 * DBL_MIN);
  const double edges[] = {DBL_MAX, 1.0, -DBL_MAX};
  assert_true(sum_of(edges, 3) == 1.0);
  const double over[] = {DBL_MAX, DBL_MAX};
  assert_true(isinf(sum_of(over, 2)) && sum_of(over, 2) > 0);
  const double zeros[] = {0.0, -0.0};
  assert_true(sum_of(zeros, 2) == 0.0 && sum_of(NULL, 0) == 0.0);
  const double inf[] = {1.0, -INFINITY, 2.0};
  assert_true(isinf(sum_of(inf, 3)) && sum_of(inf, 3) < 0);
  const double both[] = {INFINITY, 1.0, -INFINITY};
  assert_true(isnan(sum_of(both, 3)));
  const double nan[] = {1.0, NAN};
  assert_true(isnan(sum_of(nan, 2)));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_any_order),
      cmocka_unit_test(test_exact_cases),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
