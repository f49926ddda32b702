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

/* b <- F b F^T for symmetric b (Voigt): T = F b, then only the upper triangle of T F^T,
 * which is symmetric by construction (45 multiplications instead of 54). */
static inline void mpmc_push_forward(double F[3][3], double *b) {
  double B[3][3], T[3][3];
  mpmc_voigt_to_mat(b, B);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) T[i][j] = F[i][0] * B[0][j] + F[i][1] * B[1][j] + F[i][2] * B[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      b[mpmc_voigt(i, j)] = T[i][0] * F[j][0] + T[i][1] * F[j][1] + T[i][2] * F[j][2];
}

static inline double mpmc_det3(double A[3][3]) {
  return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
         A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
         A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
}

/* det s of a symmetric s (Voigt), written once for scalars (mpmc_det_sym) and batch4.h's four
 * lanes (det_sym4), so that both take the same operations in the same order */
#define MPMC_DET_SYM(s)                                                                  \
  ((s)[0] * ((s)[1] * (s)[2] - (s)[3] * (s)[3]) -                                        \
   (s)[5] * ((s)[5] * (s)[2] - (s)[3] * (s)[4]) + (s)[4] * ((s)[5] * (s)[3] - (s)[1] * (s)[4]))
static inline double mpmc_det_sym(const double *s) { return MPMC_DET_SYM(s); }

/* mpmc_sym3_eig's Jacobi sweeps, for entries whose squares neither overflow nor underflow */
static inline void mpmc_sym3_jacobi(const double *s, double lam[3], double Q[3][3]) {
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

/* Eigen-decomposition of a symmetric 3x3 tensor (Voigt s): s = sum_a lam[a] q_a q_a^T with
 * q_a the column a of Q.  Cyclic Jacobi; converges quadratically, ~3-5 sweeps.  Its
 * convergence test squares the entries: beyond 2^500 (3e150) they would overflow to inf and
 * the sweeps stop at once with the diagonal as the eigenvalues, below 2^-500 underflow to 0.
 * There the tensor is scaled by a power of two first, which is exact, and the eigenvalues
 * back: the same bits as the unscaled sweeps would give without overflow. */
static inline void mpmc_sym3_eig(const double *s, double lam[3], double Q[3][3]) {
  double m = 0.0;
  for (int k = 0; k < 6; ++k) m = fmax(m, fabs(s[k]));
  if (!(m > 0x1p500 || (m < 0x1p-500 && m > 0.0)) || !isfinite(m)) {
    mpmc_sym3_jacobi(s, lam, Q);
    return;
  }
  int e;
  (void)frexp(m, &e);
  double t[6];
  for (int k = 0; k < 6; ++k) t[k] = ldexp(s[k], -e);
  mpmc_sym3_jacobi(t, lam, Q);
  for (int a = 0; a < 3; ++a) lam[a] = ldexp(lam[a], e);
}

/* The cross products x[k] of the rows (0,1), (0,2), (1,2) of C (3x3) and their squared
 * norms n2[k], shared by mpmc_sym3_eig_closed and batch4.h's four lanes (T double or v4). */
#define MPMC_SYM3_ROW_CROSSES(T, C, x, n2)                                                \
  do {                                                                                    \
    for (int k_ = 0; k_ < 3; ++k_) {                                                      \
      const T *a_ = (C)[k_ == 2 ? 1 : 0], *b_ = (C)[k_ == 0 ? 1 : 2];                     \
      (x)[k_][0] = a_[1] * b_[2] - a_[2] * b_[1];                                         \
      (x)[k_][1] = a_[2] * b_[0] - a_[0] * b_[2];                                         \
      (x)[k_][2] = a_[0] * b_[1] - a_[1] * b_[0];                                         \
      (n2)[k_] = (x)[k_][0] * (x)[k_][0] + (x)[k_][1] * (x)[k_][1] + (x)[k_][2] * (x)[k_][2]; \
    }                                                                                     \
  } while (0)
/* B (3x3, symmetric) in the orthonormal basis v, u, w, shared by mpmc_sym3_eig_closed and
 * batch4.h's four lanes (T double or v4): lv = v.Bv, and the 2x2 block a00 = u.Bu,
 * a11 = w.Bw, a01 = (u.Bw + w.Bu) / 2 on the complement of v (declared by the caller). */
#define MPMC_SYM3_IN_BASIS(T, B, v, u, w, lv, a00, a11, a01)                               \
  do {                                                                                     \
    T Bv_[3], Bu_[3], Bw_[3];                                                              \
    for (int i_ = 0; i_ < 3; ++i_) {                                                       \
      Bv_[i_] = (B)[i_][0] * (v)[0] + (B)[i_][1] * (v)[1] + (B)[i_][2] * (v)[2];           \
      Bu_[i_] = (B)[i_][0] * (u)[0] + (B)[i_][1] * (u)[1] + (B)[i_][2] * (u)[2];           \
      Bw_[i_] = (B)[i_][0] * (w)[0] + (B)[i_][1] * (w)[1] + (B)[i_][2] * (w)[2];           \
    }                                                                                      \
    (lv) = (v)[0] * Bv_[0] + (v)[1] * Bv_[1] + (v)[2] * Bv_[2];                            \
    (a00) = (u)[0] * Bu_[0] + (u)[1] * Bu_[1] + (u)[2] * Bu_[2];                           \
    (a11) = (w)[0] * Bw_[0] + (w)[1] * Bw_[1] + (w)[2] * Bw_[2];                           \
    (a01) = 0.5 * ((u)[0] * Bw_[0] + (u)[1] * Bw_[1] + (u)[2] * Bw_[2] + (w)[0] * Bu_[0] + \
                   (w)[1] * Bu_[1] + (w)[2] * Bu_[2]);                                     \
  } while (0)

/* The same decomposition in closed form, ~10x cheaper than the Jacobi sweeps (the eigen path
 * of a plastic frictional point, return_mc.c).  With m = tr(s)/3, B = s - m I, p^2 = B:B/6:
 *   the eigenvalues of B are 2p cos(phi - 2 pi k/3), phi = acos(det(B/p)/2)/3 in [0, pi/3];
 * acos loses ~sqrt(eps) near two repeated eigenvalues, but only in the two that meet there:
 * the third is on the flat of the cosine, accurate to round-off, and it is the one farthest
 * from the others (gap >= half the spread >= 1.5 p).  So: that isolated eigenvalue (the
 * largest for phi <= pi/6, else the smallest), its eigenvector as the largest cross product
 * of two rows of B - lambda I (rank 2, both nonzero eigenvalues >= 1.5 p: well conditioned),
 * its eigenvalue again as the Rayleigh quotient; then the other two from the 2x2 block of B
 * in an orthonormal basis of the complement, diagonalised by one Jacobi rotation (exact for
 * a double eigenvalue too).  No gap needs a fall-back: every step is conditioned by the
 * isolated gap alone (tests/t416 checks the error against LAPACK down to relative gaps of
 * 1e-16).  A zero deviator, a tiny one (p^2 < 1e-280) or a non-finite s goes to Jacobi.
 * Eigenvalues in no particular order, as mpmc_sym3_eig's. */
static inline void mpmc_sym3_eig_closed(const double *s, double lam[3], double Q[3][3]) {
  const double m = (s[0] + s[1] + s[2]) / 3.0;
  const double B[3][3] = {{s[0] - m, s[5], s[4]}, {s[5], s[1] - m, s[3]}, {s[4], s[3], s[2] - m}};
  const double p2 = (B[0][0] * B[0][0] + B[1][1] * B[1][1] + B[2][2] * B[2][2] +
                     2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])) / 6.0;
  if (s[3] == 0.0 && s[4] == 0.0 && s[5] == 0.0 && isfinite(p2)) { /* diagonal: exact */
    for (int i = 0; i < 3; ++i) {
      lam[i] = s[i];
      for (int j = 0; j < 3; ++j) Q[i][j] = (i == j);
    }
    return;
  }
  if (!(p2 >= 1e-280) || !(p2 <= 1e280) || !isfinite(m)) {
    mpmc_sym3_eig(s, lam, Q);
    return;
  }
  const double pp = sqrt(p2), ip = 1.0 / pp;
  double Bn[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Bn[i][j] = B[i][j] * ip;
  const double r = 0.5 * mpmc_det3(Bn);
  const double phi = acos(r >= 1.0 ? 1.0 : r <= -1.0 ? -1.0 : r) / 3.0;
  const double pi3 = 1.0471975511965976; /* pi/3 */
  /* the isolated eigenvalue of B/p: 2 cos(phi) (largest) or 2 cos(phi + 2 pi/3) (smallest) */
  const double li = phi <= 0.5 * pi3 ? 2.0 * cos(phi) : 2.0 * cos(phi + 2.0 * pi3);
  double C[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C[i][j] = Bn[i][j] - (i == j ? li : 0.0);
  double x[3][3], n2[3];
  MPMC_SYM3_ROW_CROSSES(double, C, x, n2);
  const int kb = n2[0] >= n2[1] ? (n2[0] >= n2[2] ? 0 : 2) : (n2[1] >= n2[2] ? 1 : 2);
  if (!(n2[kb] > 0.0)) { /* not reached for a finite s (the cross products are >= ~1) */
    mpmc_sym3_eig(s, lam, Q);
    return;
  }
  const double iv = 1.0 / sqrt(n2[kb]);
  const double v[3] = {x[kb][0] * iv, x[kb][1] * iv, x[kb][2] * iv};
  /* an orthonormal basis u, w of the complement of v */
  double u[3];
  if (fabs(v[0]) > fabs(v[1])) {
    const double iu = 1.0 / sqrt(v[0] * v[0] + v[2] * v[2]);
    u[0] = -v[2] * iu, u[1] = 0.0, u[2] = v[0] * iu;
  } else {
    const double iu = 1.0 / sqrt(v[1] * v[1] + v[2] * v[2]);
    u[0] = 0.0, u[1] = v[2] * iu, u[2] = -v[1] * iu;
  }
  const double w[3] = {v[1] * u[2] - v[2] * u[1], v[2] * u[0] - v[0] * u[2],
                       v[0] * u[1] - v[1] * u[0]};
  double lv, a00, a11, a01;
  MPMC_SYM3_IN_BASIS(double, B, v, u, w, lv, a00, a11, a01);
  double c = 1.0, sn = 0.0, t = 0.0; /* the rotation of mpmc_sym3_eig */
  if (a01 != 0.0) {
    const double theta = (a11 - a00) / (2.0 * a01);
    t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
    c = 1.0 / sqrt(t * t + 1.0);
    sn = t * c;
  }
  lam[0] = m + lv;
  lam[1] = m + (a00 - t * a01);
  lam[2] = m + (a11 + t * a01);
  for (int i = 0; i < 3; ++i) {
    Q[i][0] = v[i];
    Q[i][1] = c * u[i] - sn * w[i];
    Q[i][2] = sn * u[i] + c * w[i];
  }
}

/* s = sum_a d[a] q_a q_a^T (Voigt) */
static inline void mpmc_sym3_compose(const double d[3], double Q[3][3], double *s) {
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const double v = d[0] * Q[i][0] * Q[j][0] + d[1] * Q[i][1] * Q[j][1] + d[2] * Q[i][2] * Q[j][2];
      s[mpmc_voigt(i, j)] = v;
    }
}

/* c = a b for symmetric a, b that commute (functions of one tensor), so that a b is
 * symmetric: only its upper triangle is formed (Voigt).  Written once for scalars (T double,
 * mpmc_sym3_mul) and batch4.h's four lanes (T v4, sym_mul4); c may be a or b. */
#define MPMC_SYM3_MUL(T, a, b, c)                                                        \
  do {                                                                                   \
    const T xx_ = (a)[0] * (b)[0] + (a)[5] * (b)[5] + (a)[4] * (b)[4];                   \
    const T yy_ = (a)[5] * (b)[5] + (a)[1] * (b)[1] + (a)[3] * (b)[3];                   \
    const T zz_ = (a)[4] * (b)[4] + (a)[3] * (b)[3] + (a)[2] * (b)[2];                   \
    const T yz_ = (a)[5] * (b)[4] + (a)[1] * (b)[3] + (a)[3] * (b)[2];                   \
    const T xz_ = (a)[0] * (b)[4] + (a)[5] * (b)[3] + (a)[4] * (b)[2];                   \
    const T xy_ = (a)[0] * (b)[5] + (a)[5] * (b)[1] + (a)[4] * (b)[3];                   \
    (c)[0] = xx_, (c)[1] = yy_, (c)[2] = zz_, (c)[3] = yz_, (c)[4] = xz_, (c)[5] = xy_;  \
  } while (0)
static inline void mpmc_sym3_mul(const double *a, const double *b, double *c) {
  MPMC_SYM3_MUL(double, a, b, c);
}

/* |s|^2 = s : s (Voigt, tensor shear components) */
static inline double mpmc_sym3_norm2(const double *s) {
  return s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
}

/* Hencky strain eps = 1/2 ln b of a symmetric b (Voigt) near the identity, without an
 * eigen-decomposition (issue 6: the geotechnical norm is |eps| ~ 1e-3, where the Jacobi
 * sweeps and three logs made an elastic J2 point ~6x dearer, bench_return_map):
 *   eps = atanh(Z) = Z sum_k Z^(2k) / (2k+1),  Z = (b - I)(b + I)^-1,
 * Z a function of b, so every product commutes.  An eigenvalue z of Z leaves the truncated
 * series a relative error below rho^(2N) / ((2N+1)(1 - rho^2)), rho = |Z|_F >= |z|; N is
 * the least number of terms that makes this <= 2^-54 (the table holds the largest rho^2
 * for each N).  The error is relative per principal strain, where the eigen path's
 * 1/2 ln(lambda) carries an absolute error of ~1e-16 (round-off of lambda ~ 1).
 * Returns 0, or 1 when |Z|_F > 0.179 (|eps| >~ 0.18: use the eigen path) or b is not
 * finite; a b with eigenvalues <= 0 gives |z| >= 1 or a singular b + I, so also 1. */
/* the series' tables: the largest |Z|^2 for n terms, and the coefficients 1/(2k+1) (also
 * batch4.h's, which sums the same series four points at a time) */
static const double mpmc_atanh_rho2_max[11] = {0.0,        1.665e-16,  1.666e-08, 7.297e-06,
                                               1.4949e-04, 9.0589e-04, 2.9934e-03, 7.0039e-03,
                                               1.3216e-02, 2.1619e-02, 3.2007e-02};
static const double mpmc_atanh_c[10] = {1.0,        1.0 / 3.0,  1.0 / 5.0,  1.0 / 7.0,  1.0 / 9.0,
                                        1.0 / 11.0, 1.0 / 13.0, 1.0 / 15.0, 1.0 / 17.0, 1.0 / 19.0};
/* The series' two halves, written once for scalars (T double, MUL mpmc_sym3_mul) and for
 * batch4.h's four lanes (T v4, MUL sym_mul4), so that both do the same operations:
 * Z = (b - I)(b + I)^-1 = (b - I) adj(b + I) / det(b + I) into z[6], and, for n >= 2 terms,
 * eps = Z p(W) by Horner in W = Z^2: p = c_{n-1} W + c_{n-2} I, then p <- W p + c_k I. */
#define MPMC_SYM3_CAYLEY(T, MUL, b, z)                                                   \
  do {                                                                                   \
    const T a_[6] = {(b)[0] - 1.0, (b)[1] - 1.0, (b)[2] - 1.0, (b)[3], (b)[4], (b)[5]};  \
    const T m_[6] = {(b)[0] + 1.0, (b)[1] + 1.0, (b)[2] + 1.0, (b)[3], (b)[4], (b)[5]};  \
    const T adj_[6] = {m_[1] * m_[2] - m_[3] * m_[3], m_[0] * m_[2] - m_[4] * m_[4],     \
                       m_[0] * m_[1] - m_[5] * m_[5], m_[4] * m_[5] - m_[0] * m_[3],     \
                       m_[5] * m_[3] - m_[1] * m_[4], m_[4] * m_[3] - m_[2] * m_[5]};    \
    const T det_ = m_[0] * adj_[0] + m_[5] * adj_[5] + m_[4] * adj_[4];                  \
    MUL(a_, adj_, (z));                                                                  \
    const T inv_det_ = 1.0 / det_;                                                       \
    for (int k_ = 0; k_ < 6; ++k_) (z)[k_] *= inv_det_;                                  \
  } while (0)
#define MPMC_SYM3_ATANH_HORNER(T, MUL, z, n, eps)                                        \
  do {                                                                                   \
    const double *c_ = mpmc_atanh_c;                                                     \
    T w_[6], p_[6];                                                                      \
    MUL((z), (z), w_);                                                                   \
    for (int k_ = 0; k_ < 6; ++k_) p_[k_] = c_[(n) - 1] * w_[k_];                        \
    for (int k_ = 0; k_ < 3; ++k_) p_[k_] += c_[(n) - 2];                                \
    for (int j_ = (n) - 3; j_ >= 0; --j_) {                                              \
      MUL(w_, p_, p_);                                                                   \
      for (int k_ = 0; k_ < 3; ++k_) p_[k_] += c_[j_];                                   \
    }                                                                                    \
    MUL((z), p_, (eps));                                                                 \
  } while (0)
static inline int mpmc_sym3_log_series(const double *b, double *eps) {
  const double *rho2_max = mpmc_atanh_rho2_max;
  double z[6];
  MPMC_SYM3_CAYLEY(double, mpmc_sym3_mul, b, z);
  const double r2 = mpmc_sym3_norm2(z);
  if (!(r2 <= rho2_max[10])) return 1; /* also NaN, Inf */
  int n = 1;
  while (r2 > rho2_max[n]) ++n;
  if (n == 1) {
    for (int k = 0; k < 6; ++k) eps[k] = z[k];
    return 0;
  }
  MPMC_SYM3_ATANH_HORNER(double, mpmc_sym3_mul, z, n, eps);
  return 0;
}

/* ln x for x near 1 by the same series, ln x = 2 atanh s = 2 s sum_k s^(2k) / (2k+1) with
 * s = (x - 1)/(x + 1), to the table's number of terms for s^2 (the Neo-Hookean ln J,
 * stress_blocks.c, which sums it four points at a time).  Returns 0, or 1 when s^2 is beyond
 * the table (|ln x| >~ 0.36) or x is not finite or <= 0: the caller takes libm's log. */
static inline int mpmc_log_series(double x, double *lnx) {
  const double s = (x - 1.0) / (x + 1.0), s2 = s * s;
  if (!(s2 <= mpmc_atanh_rho2_max[10])) return 1; /* also NaN */
  int n = 1;
  while (s2 > mpmc_atanh_rho2_max[n]) ++n;
  double p = mpmc_atanh_c[n - 1];
  for (int k = n - 2; k >= 0; --k) p = p * s2 + mpmc_atanh_c[k];
  *lnx = 2.0 * (s * p);
  return 0;
}

/* eps = 1/2 ln b by the eigen-decomposition, for any b: the reference and the fallback of
 * mpmc_sym3_log_series.  A b that is not positive definite gives NaN (the callers' guards
 * report it). */
static inline void mpmc_sym3_log_eig(const double *b, double *eps) {
  double lam[3], Q[3][3];
  mpmc_sym3_eig(b, lam, Q);
  for (int a = 0; a < 3; ++a) lam[a] = 0.5 * log(lam[a]);
  mpmc_sym3_compose(lam, Q, eps);
}

/* exp's series tables: the largest |M|^2 for n terms, and the coefficients 1/k! (also
 * stress_j2.c's, which sums the series of a plastic return four points at a time) */
static const double mpmc_exp_rho2_max[17] = {
    0.0,        1.110e-16,  4.804e-11,  3.649e-08,  2.1326e-06, 3.4057e-05,
    2.5668e-04, 1.2021e-03, 4.0814e-03, 1.1030e-02, 2.5199e-02, 5.0682e-02,
    9.2330e-02, 1.5550e-01, 2.4586e-01, 3.6911e-01, 5.3089e-01};
static const double mpmc_exp_c[17] = {
    1.0,           1.0,           1.0 / 2.0,       1.0 / 6.0,        1.0 / 24.0,
    1.0 / 120.0,   1.0 / 720.0,   1.0 / 5040.0,    1.0 / 40320.0,    1.0 / 362880.0,
    1.0 / 3628800.0, 1.0 / 39916800.0, 1.0 / 479001600.0, 1.0 / 6227020800.0,
    1.0 / 87178291200.0, 1.0 / 1307674368000.0, 1.0 / 20922789888000.0};

/* p = the Taylor series of exp(M) to M^n / n! in Horner form, M symmetric (Voigt) of
 * doubles or batch4.h's four lanes and MUL its symmetric product: p = c_n M + c_{n-1} I,
 * then p <- M p + c_k I down to k = 0 (mpmc_sym3_exp_series, stress_j2.c's plastic lanes) */
#define MPMC_SYM3_EXP_HORNER(MUL, M, n, p)                                               \
  do {                                                                                   \
    const double *c_ = mpmc_exp_c;                                                       \
    for (int k_ = 0; k_ < 6; ++k_) (p)[k_] = c_[(n)] * (M)[k_];                          \
    for (int k_ = 0; k_ < 3; ++k_) (p)[k_] += c_[(n) - 1];                               \
    for (int j_ = (n) - 2; j_ >= 0; --j_) {                                              \
      MUL((M), (p), (p));                                                                \
      for (int k_ = 0; k_ < 3; ++k_) (p)[k_] += c_[j_];                                  \
    }                                                                                    \
  } while (0)

/* E = exp(M) of a symmetric M (Voigt) of small norm by its Taylor series in Horner form
 * (the returned b_e = exp(2 eps) of a plastic point on the fast path).  With rho = |M|_F the
 * tail after M^n / n! is below rho^(n+1) / (n+1)! e^rho, and E's smallest eigenvalue is
 * >= e^-rho, so the relative error is below rho^(n+1) / (n+1)! e^(2 rho); n is the least
 * that makes this <= 2^-54 (the table holds the largest rho^2 for each n).
 * Returns 0, or 1 when |M|_F > 0.728 or M is not finite. */
static inline int mpmc_sym3_exp_series(const double *M, double *E) {
  const double *rho2_max = mpmc_exp_rho2_max;
  const double r2 = mpmc_sym3_norm2(M);
  if (!(r2 <= rho2_max[16])) return 1;
  int n = 1;
  while (r2 > rho2_max[n]) ++n;
  double p[6];
  MPMC_SYM3_EXP_HORNER(mpmc_sym3_mul, M, n, p);
  for (int k = 0; k < 6; ++k) E[k] = p[k];
  return 0;
}

#endif
