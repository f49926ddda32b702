/* What the benchmarks share: the wall clock, and reproducible random numbers (the tests'
 * xorshift64* of test_rand.h, seeded as the benchmarks always were unless a bench chooses). */
#ifndef MPMC_BENCH_UTIL_H
#define MPMC_BENCH_UTIL_H

#include <time.h>

#ifndef M_PI /* POSIX's, which ISO C mode leaves out */
#define M_PI 3.14159265358979323846
#endif
#ifndef TEST_RNG_SEED
#define TEST_RNG_SEED 88172645463325252ull
#endif
#include "test_rand.h"

/* seconds on the monotonic clock */
static inline double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
