/* Reproducible random numbers for the material tests (t401, t402, t411-t413): xorshift64*, one
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

/* A random symmetric positive definite b (Voigt xx yy zz yz xz xy) = R diag(l) R^T, the
 * stretches l_a = exp(2 big (2u - 1)), R a random rotation; in 2D (plane strain) a rotation
 * about z, so that b keeps yz = xz = 0. */
static inline void rand_spd(int dim, double big, double *b) {
  double R[3][3], lam[3];
  rand_rotation(R);
  if (dim == 2) {
    const double t = 2.0 * M_PI * urand();
    const double R2[3][3] = {{cos(t), -sin(t), 0}, {sin(t), cos(t), 0}, {0, 0, 1}};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R[i][j] = R2[i][j];
  }
  for (int a = 0; a < 3; ++a) lam[a] = exp(2.0 * big * (2.0 * urand() - 1.0));
  static const int vi[6] = {0, 1, 2, 1, 0, 0}, vj[6] = {0, 1, 2, 2, 2, 1};
  for (int k = 0; k < 6; ++k) {
    double s = 0;
    for (int a = 0; a < 3; ++a) s += R[vi[k]][a] * lam[a] * R[vj[k]][a];
    b[k] = s;
  }
}

/* A random deformation gradient increment dF = 1 + s (2u - 1) per component (dim x dim,
 * row-major), its strain of magnitude s */
static inline void rand_dF(int dim, double s, double *dF) {
  for (int i = 0; i < dim; ++i)
    for (int j = 0; j < dim; ++j) dF[i * dim + j] = (i == j) + s * (2.0 * urand() - 1.0);
}

#endif
