/* Small dense tensors: symmetric 3x3 in Voigt order (xx yy zz yz xz xy), eigen-decomposition
 * by cyclic Jacobi (accurate to round-off, no branches on special cases). */
#ifndef MPMC_LINALG_H
#define MPMC_LINALG_H

/* 3x3 arrays are passed without const: C17 does not convert double (*)[3] to
   const double (*)[3]. */

#include <math.h>

/* Voigt index of the (i, j) component */
static inline int mpmc_voigt(int i, int j) {
  static const int v[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
  return v[i][j];
}

static inline void mpmc_voigt_to_mat(const double *s, double A[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A[i][j] = s[mpmc_voigt(i, j)];
}

static inline void mpmc_mat_to_voigt(double A[3][3], double *s) {
  s[0] = A[0][0];
  s[1] = A[1][1];
  s[2] = A[2][2];
  s[3] = 0.5 * (A[1][2] + A[2][1]);
  s[4] = 0.5 * (A[0][2] + A[2][0]);
  s[5] = 0.5 * (A[0][1] + A[1][0]);
}

/* Embed a dim x dim row-major matrix in 3x3 (identity in the unused directions). */
static inline void mpmc_embed(int dim, const double *f, double F[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F[i][j] = (i < dim && j < dim) ? f[i * dim + j] : (i == j);
}

/* b <- F b F^T for symmetric b (Voigt). */
static inline void mpmc_push_forward(double F[3][3], double *b) {
  double B[3][3], T[3][3], R[3][3];
  mpmc_voigt_to_mat(b, B);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) T[i][j] = F[i][0] * B[0][j] + F[i][1] * B[1][j] + F[i][2] * B[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = T[i][0] * F[j][0] + T[i][1] * F[j][1] + T[i][2] * F[j][2];
  mpmc_mat_to_voigt(R, b);
}

static inline double mpmc_det3(double A[3][3]) {
  return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
         A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
         A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
}

static inline double mpmc_det_sym(const double *s) {
  return s[0] * (s[1] * s[2] - s[3] * s[3]) - s[5] * (s[5] * s[2] - s[3] * s[4]) +
         s[4] * (s[5] * s[3] - s[1] * s[4]);
}

/* Eigen-decomposition of a symmetric 3x3 tensor (Voigt s): s = sum_a lam[a] q_a q_a^T with
 * q_a the column a of Q.  Cyclic Jacobi; converges quadratically, ~3-5 sweeps. */
static inline void mpmc_sym3_eig(const double *s, double lam[3], double Q[3][3]) {
  double A[3][3];
  mpmc_voigt_to_mat(s, A);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Q[i][j] = (i == j);
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
    const double diag = A[0][0] * A[0][0] + A[1][1] * A[1][1] + A[2][2] * A[2][2];
    if (off <= 1e-36 * diag || off == 0.0) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        const double apq = A[p][q];
        if (apq == 0.0) continue;
        const double theta = (A[q][q] - A[p][p]) / (2.0 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
        const double c = 1.0 / sqrt(t * t + 1.0), sn = t * c;
        for (int k = 0; k < 3; ++k) { /* A <- A J */
          const double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - sn * akq;
          A[k][q] = sn * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) { /* A <- J^T A */
          const double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - sn * aqk;
          A[q][k] = sn * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) { /* Q <- Q J */
          const double qkp = Q[k][p], qkq = Q[k][q];
          Q[k][p] = c * qkp - sn * qkq;
          Q[k][q] = sn * qkp + c * qkq;
        }
      }
    }
  }
  for (int a = 0; a < 3; ++a) lam[a] = A[a][a];
}

/* s = sum_a d[a] q_a q_a^T (Voigt) */
static inline void mpmc_sym3_compose(const double d[3], double Q[3][3], double *s) {
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const double v = d[0] * Q[i][0] * Q[j][0] + d[1] * Q[i][1] * Q[j][1] + d[2] * Q[i][2] * Q[j][2];
      s[mpmc_voigt(i, j)] = v;
    }
}

#endif
