/* Reproducible random numbers for the material tests (t401, t402, t411): xorshift64*, one
 * stream per test.  Define TEST_RNG_SEED (a non-zero 64-bit constant) before including. */
#ifndef MPMC_TEST_RAND_H
#define MPMC_TEST_RAND_H

#include <math.h>

#ifndef TEST_RNG_SEED
#error "define TEST_RNG_SEED before including test_rand.h"
#endif

static unsigned long long rng_state = TEST_RNG_SEED;

/* uniform in [0, 1) */
static inline double urand(void) {
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

/* log-uniform in [a, b), a, b > 0 */
static inline double loguni(double a, double b) { return a * pow(b / a, urand()); }

/* -1 or +1 */
static inline double sgn(void) { return urand() < 0.5 ? -1.0 : 1.0; }

/* A random rotation from a random unit quaternion. */
static inline void rand_rotation(double R[3][3]) {
  double q[4], n = 0;
  for (int i = 0; i < 4; ++i) {
    q[i] = 2 * urand() - 1;
    n += q[i] * q[i];
  }
  n = sqrt(n);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  R[0][0] = 1 - 2 * (y * y + z * z); R[0][1] = 2 * (x * y - z * w); R[0][2] = 2 * (x * z + y * w);
  R[1][0] = 2 * (x * y + z * w); R[1][1] = 1 - 2 * (x * x + z * z); R[1][2] = 2 * (y * z - x * w);
  R[2][0] = 2 * (x * z - y * w); R[2][1] = 2 * (y * z + x * w); R[2][2] = 1 - 2 * (x * x + y * y);
}

#endif
