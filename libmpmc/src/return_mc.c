/* The frictional return map (return_mc.h): Mohr-Coulomb and Drucker-Prager with a tension
 * cut-off, in principal Kirchhoff stress space (de Souza Neto, Peric & Owen 2008, sections
 * 8.2-8.3 for the multi-surface return; ch. 14 for the logarithmic-strain setting).
 *
 * One region = a set of n active surfaces.  The unknowns are y = (dgamma_1..dgamma_n, D),
 * D the increment of eps_p; the residuals, with every material parameter at eps_p^n + D,
 *   R_i = f_i(s),  s = s_trial - De sum_j dgamma_j N_j        (i < n; N_j = dg_j/ds)
 *   R_n = D - sqrt(2/3) |dev sum_j dgamma_j N_j|
 * For the planes of Mohr-Coulomb and of the cut-off, f_i is linear in s: with the parameters
 * frozen (perfect plasticity) the multipliers are one n x n linear solve.  Drucker-Prager's
 * cone is not a plane, but its return is radial in the deviator: with the cut-off's
 * multipliers fixed, s' = s_x (1 - G dgamma_D / sqrt(J2(s_x))) and p = p_x - K etab dgamma_D
 * (s_x, p_x: the trial less the cut-off's correction), so its residuals stay explicit. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "batch4.h"
#include "linalg.h"
#include "return_mc.h"

#define MC_MAX_ITERS 60
#define MC_NMAX 4 /* unknowns: <= 3 multipliers and D */

/* surfaces in the sorted principal space s1 >= s2 >= s3 */
enum { S_A = 0, S_B, S_C, S_T1, S_T2, S_T3, S_DP };
/* Mohr-Coulomb planes (s_I - s_J) + (s_I + s_J) sin(phi) = 2 c cos(phi): A main (1-3),
 * B compression edge partner (2-3), C extension edge partner (1-2) */
static const int mc_ij[3][2] = {{0, 2}, {1, 2}, {0, 1}};

typedef mpmc_mc_mat mc_mat; /* the material at eps_p (return_mc.h) */

/* One region's problem. */
typedef struct {
  const mpmc_mc_param *m;
  int dp, n, act[3];
  double str[3];  /* sorted trial stress                                  */
  double ep0;     /* eps_p^n                                              */
  int frozen;     /* parameters fixed at x_r + (x_p - x_r) e_frozen         */
  double e_frozen;
  mc_mat qf;      /* the material at e_frozen (sys_freeze): no sin, cos per evaluation */
  mc_mat q0;      /* the material at eps_p^n, e0 = e_of(eps_p^n)                        */
  double e0;
  double tolf;    /* tolerance on f [Pa]                                  */
  double yscale;  /* typical size of a multiplier (strain)                */
} mc_sys;

/* Drucker-Prager's eta_f, xi of one matching at an angle of sine s, cosine c and their
 * derivatives in the angle. */
static void dp_coef(int surface, double s, double c, double *eta, double *xi, double *deta,
                    double *dxi) {
  if (surface == MPMC_DP_PLANE_STRAIN) {
    const double ic = 1.0 / c, t = s * ic, w = 9.0 + 12.0 * t * t, sw = sqrt(w);
    const double isw = 1.0 / sw, iw = isw * isw * isw * ic * ic; /* 1 / (w sw c^2) */
    *eta = 3.0 * t * isw;
    *xi = 3.0 * isw;
    *deta = 27.0 * iw;
    *dxi = -36.0 * t * iw;
    return;
  }
  const double k = 3.4641016151377546; /* 6 / sqrt3 */
  const double g = surface == MPMC_DP_COMPRESSION ? 3.0 - s : 3.0 + s;
  const double dg = surface == MPMC_DP_COMPRESSION ? -c : c; /* dg/dphi */
  const double ig = 1.0 / g, kig = k * ig, kig2 = kig * ig;
  *eta = s * kig;
  *xi = c * kig;
  *deta = (c * g - s * dg) * kig2;
  *dxi = (-s * g - c * dg) * kig2;
}

/* sin x, cos x from those of a nearby x0 (the material at eps_p^n during a return, where
 * the angles move by ~eta D (phi_p - phi_r), D ~ 1e-3): the addition theorem with the
 * Taylor series of d = x - x0, whose first omitted terms d^11/11!, d^12/12! are below
 * 2^-53 |d|, 2^-53 for |d| <= 0.1 (a few times cheaper than libm's sincos; the same to
 * ~1 ulp); three terms each for |d| <= 2^-9.  Farther, libm.  Also the elastic check's
 * material at a point's eps_p, from the nearest of mpmc_mc_pre's. */
static inline void sin_cos_near(double x, double x0, double s0, double c0, double *s,
                                double *c) {
  const double d = x - x0;
  if (!(fabs(d) <= 0.1)) {
    *s = sin(x);
    *c = cos(x);
    return;
  }
  const double d2 = d * d;
  double sd, cm; /* sin d, 1 - cos d */
  if (fabs(d) <= 0x1p-9) { /* a Newton iterate's (eta D ~ 1e-3): d^7/7! < 2^-66 |d| */
    sd = d + d * d2 * (-1.0 / 6 + d2 * (1.0 / 120));
    cm = d2 * (0.5 + d2 * (-1.0 / 24 + d2 * (1.0 / 720)));
  } else {
    sd = d + d * d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880 + d2 * (-1.0 / 39916800)))));
    cm = d2 * (0.5 + d2 * (-1.0 / 24 + d2 * (1.0 / 720 + d2 * (-1.0 / 40320 + d2 * (1.0 / 3628800)))));
  }
  *s = s0 + (c0 * sd - s0 * cm);
  *c = c0 - (s0 * sd + c0 * cm);
}

/* x(eps_p) = x_r + (x_p - x_r) e with e = exp(-eta eps_p); derivative -eta (x_p - x_r) e.
 * ref: a material near this one (may be NULL), whose sines and cosines seed this one's. */
static inline __attribute__((always_inline)) void
mat_eval_in(const mpmc_mc_param *m, double e, int frozen, mc_mat *q, const mc_mat *ref) {
  const double de = frozen ? 0.0 : -m->eta * e; /* de/d eps_p */
  q->e = e;
  const double phi = m->phi_r + (m->phi_p - m->phi_r) * e;
  const double psi = m->psi_r + (m->psi_p - m->psi_r) * e;
  q->phi = phi;
  q->psi = psi;
  q->c = m->c_r + (m->c_p - m->c_r) * e;
  q->dc = (m->c_p - m->c_r) * de;
  q->dphi = (m->phi_p - m->phi_r) * de;
  const double dpsi = (m->psi_p - m->psi_r) * de;
  if (ref) {
    sin_cos_near(phi, ref->phi, ref->sf, ref->cf, &q->sf, &q->cf);
    sin_cos_near(psi, ref->psi, ref->ss, ref->cs, &q->ss, &q->cs);
  } else {
    q->sf = sin(phi);
    q->cf = cos(phi);
    q->ss = sin(psi);
    q->cs = cos(psi);
  }
  q->dsf = q->cf * q->dphi;
  q->dcf = -q->sf * q->dphi;
  q->dss = q->cs * dpsi;
  q->st = m->sigma_t;
  q->dst = 0.0;
  q->st_apex = 0;
  double apex = INFINITY, dapex = 0.0;
  if (m->surface == MPMC_MC_MOHR_COULOMB) {
    q->eta = q->xi = q->etab = q->deta = q->dxi = q->detab = 0.0;
    if (q->sf > 0.0) {
      const double isf = 1.0 / q->sf;
      apex = q->c * q->cf * isf;
      dapex = q->dc * q->cf * isf - q->c * q->dphi * (isf * isf);
    }
  } else {
    double dpe, dpx, dpb, unused;
    dp_coef(m->surface, q->sf, q->cf, &q->eta, &q->xi, &dpe, &dpx);
    dp_coef(m->surface, q->ss, q->cs, &q->etab, &unused, &dpb, &unused);
    q->deta = dpe * q->dphi;
    q->dxi = dpx * q->dphi;
    q->detab = dpb * dpsi;
    if (q->eta > 0.0) {
      const double ie = 1.0 / q->eta;
      apex = q->xi * q->c * ie;
      dapex = (q->dxi * q->c + q->xi * q->dc) * ie - apex * q->deta * ie;
    }
  }
  if (!(q->st < apex)) { /* also sigma_t = INFINITY with an apex */
    q->st = apex;
    q->dst = dapex;
    q->st_apex = isfinite(apex);
  }
}

static void mat_eval(const mpmc_mc_param *m, double e, int frozen, mc_mat *q, const mc_mat *ref) {
  mat_eval_in(m, e, frozen, q, ref);
}

static inline double e_of(const mpmc_mc_param *m, double ep) {
  return m->eta > 0.0 ? exp(-m->eta * ep) : 1.0;
}

/* e at eps_p^n + D: e0 exp(-eta D), the exponential of the small eta D (<= 1e-2: Newton's
 * iterates of a return, D ~ 1e-3) by return_map.h's polynomial (within ~2 ulp of libm's,
 * a few times cheaper), beyond it libm's exp(-eta (eps_p^n + D)) */
static inline double sys_e(const mc_sys *S, double D) {
  const double x = S->m->eta * D;
  if (fabs(x) <= MPMC_RM_EXP_SMALL) return S->e0 * MPMC_RM_EXP_NEG_POLY(x);
  return e_of(S->m, S->ep0 + D);
}

/* the material of S at eps_p^n + D: the cached one when frozen, else evaluated into *buf */
static inline const mc_mat *sys_mat(const mc_sys *S, double D, mc_mat *buf) {
  if (S->frozen) return &S->qf;
  mat_eval(S->m, sys_e(S, D), 0, buf, &S->q0);
  return buf;
}

/* fix S's parameters at e (the values mat_eval gives, computed once) */
static inline void sys_freeze(mc_sys *S, double e) {
  S->frozen = 1;
  S->e_frozen = e;
  if (e == S->e0)
    S->qf = S->q0;
  else
    mat_eval(S->m, e, 1, &S->qf, &S->q0);
}

/* De v in principal space */
static inline void de_mul(const mpmc_mc_param *m, const double v[3], double out[3]) {
  const double lam = m->K - 2.0 * m->G / 3.0, tr = v[0] + v[1] + v[2];
  for (int a = 0; a < 3; ++a) out[a] = lam * tr + 2.0 * m->G * v[a];
}

/* fmax (the larger, a NaN ignored), inlined: libm's is a call on x86-64's baseline */
static inline double max_nn(double a, double b) { return (a >= b || b != b) ? a : b; }

static inline double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A plane surface s: gradient a, flow N, their eps_p-derivatives, strength k (f = a.s - k) */
static inline __attribute__((always_inline)) void plane(int s, const mc_mat *q, double a[3],
                                                        double da[3], double N[3], double dN[3],
                                                        double *k, double *dk) {
  for (int i = 0; i < 3; ++i) a[i] = da[i] = N[i] = dN[i] = 0.0;
  if (s <= S_C) {
    const int I = mc_ij[s][0], J = mc_ij[s][1];
    a[I] = 1.0 + q->sf;
    a[J] = -(1.0 - q->sf);
    da[I] = da[J] = q->dsf;
    N[I] = 1.0 + q->ss;
    N[J] = -(1.0 - q->ss);
    dN[I] = dN[J] = q->dss;
    *k = 2.0 * q->c * q->cf;
    *dk = 2.0 * (q->dc * q->cf + q->c * q->dcf);
  } else {
    a[s - S_T1] = N[s - S_T1] = 1.0;
    *k = q->st;
    *dk = q->dst;
  }
}

/* Mohr-Coulomb yield function of plane (I, J) and Drucker-Prager's, at a stress s */
static inline double mc_f(const mc_mat *q, const double s[3], int I, int J) {
  return (s[I] - s[J]) + (s[I] + s[J]) * q->sf - 2.0 * q->c * q->cf;
}
static inline double dp_sqrtj2(const double s[3]) {
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  const double a = s[0] - p, b = s[1] - p, c = s[2] - p;
  return sqrt(0.5 * (a * a + b * b + c * c));
}
static inline double dp_f(const mc_mat *q, const double s[3]) {
  return dp_sqrtj2(s) + q->eta * (s[0] + s[1] + s[2]) / 3.0 - q->xi * q->c;
}

/* Residuals R[0..n], the Jacobian J (may be NULL) and the stress sig (may be NULL) of a
 * region of planes at y. */
static inline __attribute__((always_inline)) void
eval_planes_n(const mc_sys *S, const int n, const int *act, const mc_mat *q, const double *y,
              double *R, double J[MC_NMAX][MC_NMAX], double sig[3]) {
  const mpmc_mc_param *m = S->m;
  double a[3][3], da[3][3], N[3][3], dN[3][3], k[3], dk[3], M[3] = {0, 0, 0}, dM[3] = {0, 0, 0};
  for (int j = 0; j < n; ++j) {
    plane(act[j], q, a[j], da[j], N[j], dN[j], &k[j], &dk[j]);
    for (int i = 0; i < 3; ++i) {
      M[i] += y[j] * N[j][i];
      dM[i] += y[j] * dN[j][i];
    }
  }
  double DM[3], s[3];
  de_mul(m, M, DM);
  for (int i = 0; i < 3; ++i) s[i] = S->str[i] - DM[i];
  for (int i = 0; i < n; ++i) R[i] = dot3(a[i], s) - k[i];
  const double trM = (M[0] + M[1] + M[2]) / 3.0;
  double u[3] = {M[0] - trM, M[1] - trM, M[2] - trM};
  const double nd = sqrt(dot3(u, u)), c23 = sqrt(2.0 / 3.0);
  R[n] = y[n] - c23 * nd;
  if (sig)
    for (int i = 0; i < 3; ++i) sig[i] = s[i];
  if (!J) return;
  for (int i = 0; i < 3; ++i) u[i] = nd > 0.0 ? u[i] / nd : 0.0;
  double DdM[3];
  de_mul(m, dM, DdM);
  for (int j = 0; j < n; ++j) {
    double DN[3];
    de_mul(m, N[j], DN);
    for (int i = 0; i < n; ++i) J[i][j] = -dot3(a[i], DN);
    J[n][j] = -c23 * dot3(u, N[j]);
  }
  for (int i = 0; i < n; ++i) J[i][n] = dot3(da[i], s) - dk[i] - dot3(a[i], DdM);
  J[n][n] = 1.0 - c23 * dot3(u, dM);
}
static void eval_planes_q(const mc_sys *S, const mc_mat *q, const double *y, double *R,
                          double J[MC_NMAX][MC_NMAX], double sig[3]) {
  eval_planes_n(S, S->n, S->act, q, y, R, J, sig);
}
/* the same for an edge of Mohr-Coulomb (edge_solve: S_A and S_B or S_C): its loops of known
 * length and its planes known, so that their gradients and flows stay in registers */
static void eval_planes_2(const mc_sys *S, const mc_mat *q, const double *y, double *R,
                          double J[MC_NMAX][MC_NMAX], double sig[3]) {
  static const int ab[2] = {S_A, S_B}, ac[2] = {S_A, S_C};
  if (S->act[0] == S_A && S->act[1] == S_B)
    eval_planes_n(S, 2, ab, q, y, R, J, sig);
  else if (S->act[0] == S_A && S->act[1] == S_C)
    eval_planes_n(S, 2, ac, q, y, R, J, sig);
  else
    eval_planes_n(S, 2, S->act, q, y, R, J, sig);
}
static void eval_planes(const mc_sys *S, const double *y, double *R, double J[MC_NMAX][MC_NMAX],
                        double sig[3]) {
  mc_mat qb;
  eval_planes_q(S, sys_mat(S, y[S->n], &qb), y, R, J, sig);
}

/* The same for a region with Drucker-Prager's cone (and cut-off planes).  The Jacobian is
 * analytic for the cone alone (the hot path), by forward differences with the cut-off. */
static void eval_dp(const mc_sys *S, const double *y, double *R, double J[MC_NMAX][MC_NMAX],
                    double sig[3]) {
  const int n = S->n;
  const mpmc_mc_param *m = S->m;
  mc_mat qb;
  const mc_mat *q = sys_mat(S, y[n], &qb);
  int jd = -1; /* the cone's place in y; -1: cut-off planes only */
  double M[3] = {0, 0, 0}, x[3], DM[3];
  for (int j = 0; j < n; ++j) {
    if (S->act[j] == S_DP) {
      jd = j;
      continue;
    }
    M[S->act[j] - S_T1] += y[j];
  }
  de_mul(m, M, DM);
  for (int i = 0; i < 3; ++i) x[i] = S->str[i] - DM[i];
  const double px = (x[0] + x[1] + x[2]) / 3.0, yd = jd >= 0 ? y[jd] : 0.0;
  const double sx[3] = {x[0] - px, x[1] - px, x[2] - px};
  const double rj = sqrt(0.5 * dot3(sx, sx));
  const double ratio = rj > 0.0 ? 1.0 - m->G * yd / rj : 0.0;
  const double p = px - m->K * q->etab * yd;
  double s[3];
  for (int i = 0; i < 3; ++i) s[i] = p + ratio * sx[i];
  for (int j = 0; j < n; ++j)
    R[j] = S->act[j] == S_DP ? rj - m->G * yd + q->eta * p - q->xi * q->c : s[S->act[j] - S_T1] - q->st;
  /* plastic deviatoric strain: the cut-off's dev M and the cone's yd s_x / (2 sqrt J2) */
  const double trM = (M[0] + M[1] + M[2]) / 3.0;
  double u[3];
  for (int i = 0; i < 3; ++i) u[i] = M[i] - trM + (rj > 0.0 ? yd * sx[i] / (2.0 * rj) : 0.0);
  R[n] = y[n] - sqrt(2.0 / 3.0) * sqrt(dot3(u, u));
  if (sig)
    for (int i = 0; i < 3; ++i) sig[i] = s[i];
  if (!J) return;
  if (n == 1 && jd == 0) { /* the cone alone: R_n = D - |yd| / sqrt3 */
    J[0][0] = -m->G - m->K * q->eta * q->etab;
    J[0][1] = q->deta * p - q->eta * m->K * q->detab * yd - q->dxi * q->c - q->xi * q->dc;
    J[1][0] = (yd >= 0.0 ? -1.0 : 1.0) / sqrt(3.0);
    J[1][1] = 1.0;
    return;
  }
  for (int j = 0; j <= n; ++j) {
    double yp[MC_NMAX], Rp[MC_NMAX];
    memcpy(yp, y, sizeof yp);
    const double h = 1e-7 * (fabs(y[j]) + S->yscale);
    yp[j] += h;
    eval_dp(S, yp, Rp, NULL, NULL);
    for (int i = 0; i <= n; ++i) J[i][j] = (Rp[i] - R[i]) / h;
  }
}

static inline void sys_eval(const mc_sys *S, const double *y, double *R,
                            double J[MC_NMAX][MC_NMAX], double sig[3]) {
  int cone = 0;
  for (int j = 0; j < S->n; ++j) cone |= S->act[j] == S_DP;
  if (cone) /* the cut-off alone is planes for Drucker-Prager too */
    eval_dp(S, y, R, J, sig);
  else
    eval_planes(S, y, R, J, sig);
}

/* max of |R_i| / tol over the residuals (R_n in strain: times 2G) */
static inline double rnorm(const mc_sys *S, const double *R) {
  double r = 0.0;
  for (int i = 0; i < S->n; ++i) r = max_nn(r, fabs(R[i]));
  r = max_nn(r, 2.0 * S->m->G * fabs(R[S->n]));
  return isfinite(r) ? r / S->tolf : INFINITY;
}

/* Gaussian elimination with partial pivoting of A x = b (n <= 4); b <- x; returns det A. */
static inline __attribute__((always_inline)) double gauss_n(const int n,
                                                            double A[MC_NMAX][MC_NMAX],
                                                            double *b) {
  double det = 1.0;
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (fabs(A[i][k]) > fabs(A[p][k])) p = i;
    if (!(A[p][k] != 0.0)) return 0.0;
    if (p != k) {
      for (int j = 0; j < n; ++j) {
        const double t = A[k][j];
        A[k][j] = A[p][j];
        A[p][j] = t;
      }
      const double t = b[k];
      b[k] = b[p];
      b[p] = t;
      det = -det;
    }
    det *= A[k][k];
    for (int i = k + 1; i < n; ++i) {
      const double l = A[i][k] / A[k][k];
      for (int j = k; j < n; ++j) A[i][j] -= l * A[k][j];
      b[i] -= l * b[k];
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = b[i];
    for (int j = i + 1; j < n; ++j) s -= A[i][j] * b[j];
    b[i] = s / A[i][i];
  }
  return det;
}

static double gauss(int n, double A[MC_NMAX][MC_NMAX], double *b) { return gauss_n(n, A, b); }

/* det of the leading n x n block (n <= 3) */
static double det_lead(int n, double J[MC_NMAX][MC_NMAX]) {
  if (n == 1) return J[0][0];
  if (n == 2) return J[0][0] * J[1][1] - J[0][1] * J[1][0];
  return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
         J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
         J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

/* Newton on the region's (n+1) x (n+1) system from y.  strict (auto): plain full steps, and
 * return 1 ("unsafe") at the first sign of trouble: softening that flips the sign of the
 * Jacobian's determinant against its elastic-perfectly-plastic part (the softening modulus
 * beats the elastic one: the residual is not monotone and the full step may run away), a
 * stall, or a non-finite value.  strict = 0 (newton): steps shortened by backtracking on
 * |R|^2 (Armijo), so that it converges wherever the root is unique.  0 when converged. */
static int newton(const mc_sys *S, int strict, double *y, mpmc_mc_info *info) {
  const int n1 = S->n + 1;
  double prev = INFINITY;
  for (int it = 0; it < MC_MAX_ITERS; ++it) {
    double R[MC_NMAX], J[MC_NMAX][MC_NMAX], dx[MC_NMAX];
    sys_eval(S, y, R, J, NULL);
    const double nr = rnorm(S, R);
    if (nr <= 1.0) return 0;
    if (!isfinite(nr)) return 1;
    if (strict && it >= 3 && nr > 0.5 * prev) return 1;
    const double detyy = det_lead(S->n, J);
    for (int i = 0; i < n1; ++i) dx[i] = -R[i];
    const double det = gauss(n1, J, dx);
    if (!(det != 0.0) || !isfinite(det)) return 1;
    if (strict && !S->frozen && det * detyy <= 0.0) return 1;
    info->newton_iters++;
    if (strict) {
      for (int i = 0; i < n1; ++i) y[i] += dx[i];
    } else {
      double t = 1.0, yt[MC_NMAX] = {0, 0, 0, 0}, Rt[MC_NMAX];
      /* keep D >= 0: below eps_p^n the strengths grow without bound */
      if (y[S->n] + dx[S->n] < 0.0) t = 0.5 * y[S->n] / -dx[S->n];
      int ok = 0;
      for (int ls = 0; ls < 40 && !ok; ++ls, t *= 0.5) {
        for (int i = 0; i < n1; ++i) yt[i] = y[i] + t * dx[i];
        sys_eval(S, yt, Rt, NULL, NULL);
        const double nt = rnorm(S, Rt);
        /* sufficient decrease of |R|^2 in the max norm's terms, or converged */
        ok = nt <= 1.0 || nt <= (1.0 - 1e-4 * t) * nr;
      }
      if (!ok) return 1;
      memcpy(y, yt, sizeof yt);
    }
    prev = nr;
  }
  return 1;
}

/* The perfect-plasticity solution of the region with the parameters frozen at
 * x_r + (x_p - x_r) e: planes in one linear solve (the multipliers do not depend on D),
 * then D = sqrt(2/3) |dev dEps^p|; with Drucker-Prager's cone and the cut-off, Newton. */
static int solve_frozen(const mc_sys *S0, double e, double *y, mpmc_mc_info *info) {
  mc_sys S = *S0;
  sys_freeze(&S, e);
  const int n = S.n;
  for (int i = 0; i < MC_NMAX; ++i) y[i] = 0.0;
  if (S.dp && n > 1) return newton(&S, 0, y, info);
  double R[MC_NMAX], J[MC_NMAX][MC_NMAX];
  sys_eval(&S, y, R, J, NULL);
  for (int i = 0; i < n; ++i) y[i] = -R[i];
  const double det = gauss(n, J, y);
  if (!(det != 0.0) || !isfinite(det)) return 1;
  y[n] = 0.0;
  sys_eval(&S, y, R, NULL, NULL);
  y[n] = -R[n];
  return 0;
}

/* ---- KINSOL, one memory per thread in the workspace's slot -------------------------- */
typedef struct {
  SUNContext ctx;
  void *kmem;
  N_Vector u, us, fs;
  SUNMatrix A;
  SUNLinearSolver LS;
  const mc_sys *sys;
} mc_kin;

static void mc_kin_free(void *p) {
  mc_kin *k = p;
  if (!k) return;
  if (k->kmem) KINFree(&k->kmem);
  if (k->LS) SUNLinSolFree(k->LS);
  if (k->A) SUNMatDestroy(k->A);
  if (k->u) N_VDestroy(k->u);
  if (k->us) N_VDestroy(k->us);
  if (k->fs) N_VDestroy(k->fs);
  if (k->ctx) SUNContext_Free(&k->ctx);
  free(k);
}

/* The system padded to MC_NMAX unknowns (R = u on the unused ones), so one memory serves
 * every region. */
static int mc_kin_f(N_Vector u, N_Vector f, void *data) {
  const mc_kin *k = data;
  const int n1 = k->sys->n + 1;
  double y[MC_NMAX], R[MC_NMAX];
  for (int i = 0; i < MC_NMAX; ++i) y[i] = NV_Ith_S(u, i);
  sys_eval(k->sys, y, R, NULL, NULL);
  int ok = 1;
  for (int i = 0; i < MC_NMAX; ++i) {
    NV_Ith_S(f, i) = i < n1 ? R[i] : y[i];
    ok &= isfinite(NV_Ith_S(f, i));
  }
  return ok ? 0 : 1; /* > 0: recoverable, KINSOL shortens the step */
}

static int mc_kin_jac(N_Vector u, N_Vector fu, SUNMatrix Jm, void *data, N_Vector t1,
                      N_Vector t2) {
  (void)fu;
  (void)t1;
  (void)t2;
  const mc_kin *k = data;
  const int n1 = k->sys->n + 1;
  double y[MC_NMAX], R[MC_NMAX], J[MC_NMAX][MC_NMAX];
  for (int i = 0; i < MC_NMAX; ++i) y[i] = NV_Ith_S(u, i);
  sys_eval(k->sys, y, R, J, NULL);
  int ok = 1;
  for (int i = 0; i < MC_NMAX; ++i)
    for (int j = 0; j < MC_NMAX; ++j) {
      const double v = i < n1 && j < n1 ? J[i][j] : (double)(i == j);
      SM_ELEMENT_D(Jm, i, j) = v;
      ok &= isfinite(v);
    }
  return ok ? 0 : 1;
}

static void mc_kin_err(int code, const char *module, const char *fn, char *msg, void *d) {
  (void)code;
  (void)module;
  (void)fn;
  (void)msg;
  (void)d;
}
static void mc_kin_info(const char *module, const char *fn, char *msg, void *d) {
  (void)module;
  (void)fn;
  (void)msg;
  (void)d;
}

static int mc_kin_get(mpmc_rm_ws *ws, mc_kin **out) {
  void **slot = mpmc_rm_ws_slot(ws, MPMC_RM_SLOT_MC, mc_kin_free);
  if (!slot) return MPMC_ERR_ARG;
  if (*slot) {
    *out = *slot;
    return MPMC_SUCCESS;
  }
  mc_kin *k = calloc(1, sizeof *k);
  if (!k) return MPMC_ERR_MEMORY;
  int ok = SUNContext_Create(NULL, &k->ctx) == 0;
  if (ok) {
    k->u = N_VNew_Serial(MC_NMAX, k->ctx);
    k->us = N_VNew_Serial(MC_NMAX, k->ctx);
    k->fs = N_VNew_Serial(MC_NMAX, k->ctx);
    k->A = SUNDenseMatrix(MC_NMAX, MC_NMAX, k->ctx);
    ok = k->u && k->us && k->fs && k->A;
  }
  if (ok) {
    k->LS = SUNLinSol_Dense(k->u, k->A, k->ctx);
    k->kmem = KINCreate(k->ctx);
    ok = k->LS && k->kmem;
  }
  if (ok) {
    N_VConst(0.0, k->u);
    ok = KINInit(k->kmem, mc_kin_f, k->u) == KIN_SUCCESS &&
         KINSetErrHandlerFn(k->kmem, mc_kin_err, NULL) == KIN_SUCCESS &&
         KINSetInfoHandlerFn(k->kmem, mc_kin_info, NULL) == KIN_SUCCESS &&
         KINSetPrintLevel(k->kmem, 0) == KIN_SUCCESS &&
         KINSetUserData(k->kmem, k) == KIN_SUCCESS &&
         KINSetLinearSolver(k->kmem, k->LS, k->A) == KIN_SUCCESS &&
         KINSetJacFn(k->kmem, mc_kin_jac) == KIN_SUCCESS &&
         /* a fresh Jacobian every iteration (return_map.c: KINSOL's default reuse fails) */
         KINSetMaxSetupCalls(k->kmem, 1) == KIN_SUCCESS &&
         KINSetNumMaxIters(k->kmem, MC_MAX_ITERS) == KIN_SUCCESS &&
         /* fscale = 1/tol: fnormtol 1 means |R| <= tol */
         KINSetFuncNormTol(k->kmem, 1.0) == KIN_SUCCESS &&
         KINSetScaledStepTol(k->kmem, 4.0 * DBL_EPSILON) == KIN_SUCCESS;
  }
  if (!ok) {
    mc_kin_free(k);
    return MPMC_ERR_MEMORY;
  }
  *slot = k;
  *out = k;
  return MPMC_SUCCESS;
}

/* KINSOL with line search from y; 0 converged, 1 not, or an error code (< 0 never: codes
 * are positive, MPMC_ERR_MEMORY/ARG when KINSOL cannot be set up) */
static int solve_kinsol(mpmc_rm_ws *ws, const mc_sys *S, double *y, mpmc_mc_info *info,
                        int *err) {
  mc_kin *k;
  *err = ws ? mc_kin_get(ws, &k) : MPMC_ERR_ARG;
  if (*err) return 1;
  double R[MC_NMAX];
  sys_eval(S, y, R, NULL, NULL);
  if (rnorm(S, R) <= 1.0) return 0; /* KINSOL accepts a guess only at 0.01 fnormtol */
  k->sys = S;
  const int n = S->n;
  for (int i = 0; i < MC_NMAX; ++i) {
    NV_Ith_S(k->u, i) = i <= n ? y[i] : 0.0;
    NV_Ith_S(k->us, i) = 1.0 / S->yscale;
    NV_Ith_S(k->fs, i) = i < n ? 1.0 / S->tolf : i == n ? 2.0 * S->m->G / S->tolf : 1.0;
  }
  const int flag = KINSol(k->kmem, k->u, KIN_LINESEARCH, k->us, k->fs);
  long nni = 0;
  KINGetNumNonlinSolvIters(k->kmem, &nni);
  info->kinsol_iters += (int)nni;
  info->kinsol_flag = flag;
  for (int i = 0; i <= n; ++i) y[i] = NV_Ith_S(k->u, i);
  sys_eval(S, y, R, NULL, NULL);
  /* a line search that stalls at round-off after reaching the tolerance is a success */
  return rnorm(S, R) <= 1.0 ? 0 : 1;
}

/* Solve one region: 0 converged (y), 1 no solution found, or an error code via *err. */
static int solve_region(mpmc_rm_ws *ws, int solver, const mc_sys *S, int perfect, double *y,
                        mpmc_mc_info *info, int *err) {
  *err = 0;
  const double e0 = S->e0;
  if (perfect) {
    if (solve_frozen(S, e0, y, info)) return 1;
    double R[MC_NMAX];
    mc_sys Sf = *S;
    sys_freeze(&Sf, e0);
    sys_eval(&Sf, y, R, NULL, NULL);
    return rnorm(&Sf, R) <= 1.0 ? 0 : 1;
  }
  if (solver != MPMC_SOLVER_KINSOL) {
    /* from the perfect-plasticity predictor at eps_p^n */
    if (solve_frozen(S, e0, y, info))
      for (int i = 0; i < MC_NMAX; ++i) y[i] = 0.0;
    if (!newton(S, solver == MPMC_SOLVER_AUTO, y, info)) return 0;
    if (solver == MPMC_SOLVER_NEWTON) { /* again from the largest return (below) */
      if (solve_frozen(S, 0.0, y, info)) return 1;
      return newton(S, 0, y, info);
    }
    info->fallback = 1;
  }
  /* KINSOL from the predictor at eps_p^n; failing that, from the predictor with the residual
   * strengths: the largest return, from which the Newton steps of a concave residual approach
   * the root monotonically (return_map.c) */
  if (solve_frozen(S, e0, y, info))
    for (int i = 0; i < MC_NMAX; ++i) y[i] = 0.0;
  if (!solve_kinsol(ws, S, y, info, err) || *err) return *err ? 1 : 0;
  if (solve_frozen(S, 0.0, y, info)) return 1;
  return solve_kinsol(ws, S, y, info, err);
}

/* The returned stress s (at eps_p^n + D, parameters q) of region S: multipliers >= 0 and no
 * surface violated. */
static int admissible(const mc_sys *S, const double *y, const double s[3], const mc_mat *q) {
  double ys = 0.0;
  for (int j = 0; j < S->n; ++j) ys += fabs(y[j]);
  for (int j = 0; j < S->n; ++j)
    if (!(y[j] >= -1e-9 * ys)) return 0;
  if (!(y[S->n] >= -1e-12 * S->yscale)) return 0;
  const double tol = 8.0 * S->tolf;
  for (int a = 0; a < 3; ++a)
    if (!(s[a] <= q->st + tol)) return 0;
  if (S->dp) {
    if (!(dp_f(q, s) <= tol)) return 0;
    /* the cone's return may not overshoot the axis */
    for (int j = 0; j < S->n; ++j)
      if (S->act[j] == S_DP) {
        double x[3], M[3] = {0, 0, 0}, DM[3];
        for (int i = 0; i < S->n; ++i)
          if (S->act[i] != S_DP) M[S->act[i] - S_T1] += y[i];
        de_mul(S->m, M, DM);
        for (int i = 0; i < 3; ++i) x[i] = S->str[i] - DM[i];
        if (!(S->m->G * y[j] <= dp_sqrtj2(x) * (1.0 + 1e-12))) return 0;
      }
  } else {
    for (int I = 0; I < 3; ++I)
      for (int J = 0; J < 3; ++J)
        if (I != J && !(mc_f(q, s, I, J) <= tol)) return 0;
  }
  return 1;
}

/* The first region alone -- Mohr-Coulomb's main plane (S_A) or Drucker-Prager's cone (S_DP),
 * where most plastic points return -- with residuals and Jacobian written out for its one
 * multiplier (eval_planes and eval_dp for n = 1): R (2), J (may be NULL) and the stress s
 * at y with the material q. */
static void single_eval(const mc_sys *S, const mc_mat *q, const double *y, double R[2],
                        double J[2][2], double s[3]) {
  const mpmc_mc_param *m = S->m;
  const double c23 = sqrt(2.0 / 3.0), g = y[0];
  if (S->dp) { /* eval_dp's cone alone */
    const double *x = S->str;
    const double px = (x[0] + x[1] + x[2]) / 3.0;
    const double sx[3] = {x[0] - px, x[1] - px, x[2] - px};
    const double rj = sqrt(0.5 * dot3(sx, sx));
    const double ratio = rj > 0.0 ? 1.0 - m->G * g / rj : 0.0;
    const double p = px - m->K * q->etab * g;
    for (int i = 0; i < 3; ++i) s[i] = p + ratio * sx[i];
    R[0] = rj - m->G * g + q->eta * p - q->xi * q->c;
    double u[3];
    for (int i = 0; i < 3; ++i) u[i] = rj > 0.0 ? g * sx[i] / (2.0 * rj) : 0.0;
    R[1] = y[1] - c23 * sqrt(dot3(u, u));
    if (!J) return;
    J[0][0] = -m->G - m->K * q->eta * q->etab;
    J[0][1] = q->deta * p - q->eta * m->K * q->detab * g - q->dxi * q->c - q->xi * q->dc;
    J[1][0] = (g >= 0.0 ? -1.0 : 1.0) / sqrt(3.0);
    J[1][1] = 1.0;
    return;
  }
  /* eval_planes' main plane: a = (1 + sf, 0, -(1 - sf)), N = (1 + ss, 0, -(1 - ss)) */
  const double lam = m->K - 2.0 * m->G / 3.0, G2 = 2.0 * m->G;
  const double a0 = 1.0 + q->sf, a2 = -(1.0 - q->sf), N0 = 1.0 + q->ss, N2 = -(1.0 - q->ss);
  const double M0 = g * N0, M2 = g * N2, trM = M0 + M2;
  s[0] = S->str[0] - (lam * trM + G2 * M0);
  s[1] = S->str[1] - lam * trM;
  s[2] = S->str[2] - (lam * trM + G2 * M2);
  R[0] = a0 * s[0] + a2 * s[2] - 2.0 * q->c * q->cf;
  const double t3 = trM / 3.0;
  double u[3] = {M0 - t3, -t3, M2 - t3};
  const double nd = sqrt(dot3(u, u));
  R[1] = y[1] - c23 * nd;
  if (!J) return;
  for (int i = 0; i < 3; ++i) u[i] = nd > 0.0 ? u[i] / nd : 0.0;
  const double trN = N0 + N2, dM = g * q->dss; /* dM = (dM, 0, dM) */
  J[0][0] = -(a0 * (lam * trN + G2 * N0) + a2 * (lam * trN + G2 * N2));
  J[1][0] = -c23 * (u[0] * N0 + u[2] * N2);
  const double DdM0 = lam * 2.0 * dM + G2 * dM; /* De dM, components 0 and 2 */
  J[0][1] = q->dsf * (s[0] + s[2]) - 2.0 * (q->dc * q->cf + q->c * q->dcf) - (a0 + a2) * DdM0;
  J[1][1] = 1.0 - c23 * (u[0] + u[2]) * dM;
}

/* solve_region and admissible for the first region alone, with newton's strict rules (its
 * checks, in the same order) and solve_frozen's predictor.  Returns 0 with y, the stress s,
 * the material q there and R0 = f when the region holds; 1 when its solution is not
 * admissible; 2 when Newton gave up (the general loop then tries it again, with KINSOL). */
static int single_solve(const mc_sys *S, int perfect, double *y, double s[3], mc_mat *q,
                        double *R0, mpmc_mc_info *info) {
  double R[2], J[2][2];
  const int iters0 = info->newton_iters;
  /* the perfect-plasticity predictor at eps_p^n: R_0 is linear in the multiplier */
  const double yz[2] = {0.0, 0.0};
  single_eval(S, &S->q0, yz, R, J, s);
  y[0] = -R[0] / J[0][0];
  y[1] = 0.0;
  if (!(J[0][0] != 0.0) || !isfinite(y[0])) {
    if (perfect) return 2;
    y[0] = 0.0;
  } else {
    single_eval(S, &S->q0, y, R, NULL, s);
    y[1] = -R[1];
  }
  if (perfect) {
    *q = S->q0;
    single_eval(S, q, y, R, NULL, s);
    if (!(max_nn(fabs(R[0]), 2.0 * S->m->G * fabs(R[1])) <= S->tolf)) return 2;
  } else {
    double prev = INFINITY;
    int ok = 0;
    for (int it = 0; it < MC_MAX_ITERS && !ok; ++it) {
      mat_eval(S->m, sys_e(S, y[1]), 0, q, &S->q0);
      single_eval(S, q, y, R, J, s);
      const double nr = rnorm(S, R);
      if (nr <= 1.0) {
        ok = 1;
        break;
      }
      if (!isfinite(nr) || (it >= 3 && nr > 0.5 * prev)) break;
      const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
      if (!(det != 0.0) || !isfinite(det) || det * J[0][0] <= 0.0) break;
      info->newton_iters++;
      y[0] += (-R[0] * J[1][1] + R[1] * J[0][1]) / det;
      y[1] += (-R[1] * J[0][0] + R[0] * J[1][0]) / det;
      prev = nr;
    }
    if (!ok) {
      info->newton_iters = iters0;
      return 2;
    }
    /* the derivatives are not needed any more: q as the frozen material there */
    q->dc = q->dphi = q->dsf = q->dcf = q->dss = q->deta = q->dxi = q->detab = q->dst = 0.0;
  }
  *R0 = R[0];
  return admissible(S, y, s, q) ? 0 : 1;
}

/* solve_region and admissible for an edge of Mohr-Coulomb (S->n = 2 planes, S->act set) as
 * single_solve for the main plane: solve_frozen's predictor at eps_p^n (a 2 x 2 solve, by
 * Cramer's rule), newton's strict iteration on the 3 x 3 system with the material
 * evaluated once per iterate, without the copies of the system that the general loop
 * makes.  Returns 0 with y, s, q, the largest |f| in *res; 1 not admissible; 2 not solved
 * here (the general loop tries it again, with KINSOL). */
static int edge_solve(const mc_sys *S, int perfect, double *y, double s[3], mc_mat *q,
                      double *res, mpmc_mc_info *info) {
  double R[MC_NMAX], J[MC_NMAX][MC_NMAX];
  const int iters0 = info->newton_iters;
  for (int i = 0; i < MC_NMAX; ++i) y[i] = 0.0;
  eval_planes_2(S, &S->q0, y, R, J, NULL);
  const double d0 = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  const double y0 = (-R[0] * J[1][1] + R[1] * J[0][1]) / d0;
  const double y1 = (-R[1] * J[0][0] + R[0] * J[1][0]) / d0;
  if (!(d0 != 0.0) || !isfinite(y0) || !isfinite(y1)) {
    if (perfect) return 2;
  } else {
    y[0] = y0;
    y[1] = y1;
    eval_planes_2(S, &S->q0, y, R, NULL, NULL);
    y[2] = -R[2];
  }
  if (perfect) {
    *q = S->q0;
    eval_planes_2(S, q, y, R, NULL, s);
    if (!(rnorm(S, R) <= 1.0)) return 2;
  } else {
    double prev = INFINITY;
    int ok = 0;
    for (int it = 0; it < MC_MAX_ITERS; ++it) {
      double dx[MC_NMAX];
      mat_eval_in(S->m, sys_e(S, y[2]), 0, q, &S->q0); /* inlined: the edges' hot loop */
      eval_planes_2(S, q, y, R, J, s);
      const double nr = rnorm(S, R);
      if (nr <= 1.0) {
        ok = 1;
        break;
      }
      if (!isfinite(nr) || (it >= 3 && nr > 0.5 * prev)) break;
      const double detyy = det_lead(2, J);
      for (int i = 0; i < 3; ++i) dx[i] = -R[i];
      const double det = gauss_n(3, J, dx); /* its loops of known length */
      if (!(det != 0.0) || !isfinite(det) || det * detyy <= 0.0) break;
      info->newton_iters++;
      for (int i = 0; i < 3; ++i) y[i] += dx[i];
      prev = nr;
    }
    if (!ok) {
      info->newton_iters = iters0;
      return 2;
    }
    q->dc = q->dphi = q->dsf = q->dcf = q->dss = q->deta = q->dxi = q->detab = q->dst = 0.0;
  }
  *res = max_nn(fabs(R[0]), fabs(R[1]));
  return admissible(S, y, s, q) ? 0 : 1;
}

typedef struct {
  int n, act[3], region;
} mc_region;
static const mc_region mc_regions[] = {
    {1, {S_A, 0, 0}, MPMC_MC_PLANE},
    {2, {S_A, S_B, 0}, MPMC_MC_EDGE_COMPRESSION},
    {2, {S_A, S_C, 0}, MPMC_MC_EDGE_EXTENSION},
    {1, {S_T1, 0, 0}, MPMC_MC_TENSION},
    {2, {S_A, S_T1, 0}, MPMC_MC_TENSION_EDGE},
    {2, {S_T1, S_T2, 0}, MPMC_MC_TENSION_EDGE},
    {3, {S_A, S_C, S_T1}, MPMC_MC_TENSION_CORNER},
    /* s1 = s2 = sigma_t on the surface: four generators, so every triple (Caratheodory) */
    {3, {S_A, S_B, S_T1}, MPMC_MC_TENSION_CORNER},
    {3, {S_A, S_T1, S_T2}, MPMC_MC_TENSION_CORNER},
    {3, {S_B, S_T1, S_T2}, MPMC_MC_TENSION_CORNER},
    {3, {S_A, S_B, S_T2}, MPMC_MC_TENSION_CORNER},
};
static const mc_region dp_regions[] = {
    {1, {S_DP, 0, 0}, MPMC_MC_PLANE},
    {1, {S_T1, 0, 0}, MPMC_MC_TENSION},
    {2, {S_DP, S_T1, 0}, MPMC_MC_TENSION_EDGE},
    {2, {S_T1, S_T2, 0}, MPMC_MC_TENSION_EDGE},
    {3, {S_DP, S_T1, S_T2}, MPMC_MC_TENSION_CORNER},
};

/* Whether the regions with the cut-off can hold.  Without a user cut-off the cap at the apex
 * is the cut-off, and on Mohr-Coulomb's surface s1 = c cot(phi) holds at the apex alone
 * (there f = (1 - sin phi)(c cot(phi) - s3)); on Drucker-Prager's cone likewise whenever
 * 2 eta_f / sqrt3 < 1 (s1 - p <= 2 sqrt(J2 / 3), so sqrt(J2) <= eta_f (s1 - p) only at
 * J2 = 0), eta_f at the larger friction angle.  Then no region with the cut-off holds but at
 * the apex, which principal's hydrostatic point gives: they are not tried (an apex return
 * tried all eleven of Mohr-Coulomb's regions). */
static int tension_regions(const mpmc_mc_param *m, const mc_mat *q0) {
  if (isfinite(m->sigma_t)) return 1;
  if (!isfinite(q0->st) || m->surface == MPMC_MC_MOHR_COULOMB) return 0;
  const double phm = max_nn(m->phi_p, m->phi_r);
  double eta, xi, deta, dxi;
  dp_coef(m->surface, sin(phm), cos(phm), &eta, &xi, &deta, &dxi);
  return !(2.0 * eta < 1.7320508075688772 * (1.0 - 1e-6));
}

#if !defined(MPMC_ISA_AVX2)
/* the material is one mpmc_mc_return_principal accepts */
static int param_ok(const mpmc_mc_param *m) {
  return m->K > 0 && m->G > 0 && m->c_r >= 0 && m->c_p >= m->c_r && m->eta >= 0 &&
         m->phi_p >= 0 && m->phi_r >= 0 && m->phi_p < 0.5 * acos(-1.0) &&
         m->phi_r < 0.5 * acos(-1.0) && fabs(m->psi_p) <= m->phi_p &&
         fabs(m->psi_r) <= m->phi_r && !isnan(m->sigma_t) &&
         m->surface >= MPMC_MC_MOHR_COULOMB && m->surface <= MPMC_DP_PLANE_STRAIN &&
         isfinite(m->K) && isfinite(m->G) && isfinite(m->c_p) && isfinite(m->eta);
}

/**
 * @brief c, phi and psi of the softened material at eps_p (return_mc.h).
 */
void mpmc_mc_soften(const mpmc_mc_param *m, double eps_p, double *c, double *phi, double *psi) {
  const double e = e_of(m, eps_p);
  if (c) *c = m->c_r + (m->c_p - m->c_r) * e;
  if (phi) *phi = m->phi_r + (m->phi_p - m->phi_r) * e;
  if (psi) *psi = m->psi_r + (m->psi_p - m->psi_r) * e;
}
#endif


/**
 * @brief The tolerance on the yield functions [Pa] for a trial stress: 1e-12 of the largest
 * of |tau_trial|, c_p and a finite sigma_t (the round-off of the returned stress is ~1e-16
 * of |tau_trial|).
 */
static inline double tolerance(const mpmc_mc_param *m, const double t[3]) {
  double s = max_nn(max_nn(fabs(t[0]), fabs(t[1])), max_nn(fabs(t[2]), m->c_p));
  if (isfinite(m->sigma_t)) s = max_nn(s, fabs(m->sigma_t));
  return 1e-12 * s + DBL_MIN;
}
#if !defined(MPMC_ISA_AVX2)
double mpmc_mc_tolerance(const mpmc_mc_param *m, const double t[3]) { return tolerance(m, t); }
#endif

static int principal(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, const double eps_tr[3],
                     double *eps_p, double eps[3], double tau[3], mpmc_mc_info *info,
                     const mc_mat *q0in);

#if !defined(MPMC_ISA_AVX2)
/**
 * @brief Frictional return map of one point in principal space (return_mc.h).
 * @param ws      per-thread workspace (KINSOL's memory; may be NULL for MPMC_SOLVER_NEWTON
 *                and for perfect plasticity)
 * @param solver  MPMC_SOLVER_AUTO, _NEWTON or _KINSOL (as for J2, return_map.c)
 * @param m       material
 * @param eps_tr  trial principal elastic log strains, any order
 * @param eps_p   accumulated plastic deviatoric strain, in/out
 * @param eps     returned principal elastic log strains (order of eps_tr)
 * @param tau     returned principal Kirchhoff stresses (order of eps_tr)
 * @param info    statistics (may be NULL)
 * @return 0, MPMC_ERR_ARG (bad material), MPMC_ERR_NUMERIC (non-finite input),
 *         MPMC_ERR_SOLVER (no region converged and admissible), MPMC_ERR_MEMORY; on failure
 *         eps_p, eps and tau are left unchanged.
 */
int mpmc_mc_return_principal(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m,
                             const double eps_tr[3], double *eps_p, double eps[3],
                             double tau[3], mpmc_mc_info *info) {
  mpmc_mc_info local;
  if (!info) info = &local;
  memset(info, 0, sizeof *info);
  if (!m || !eps_tr || !eps_p || !eps || !tau) return MPMC_ERR_ARG;
  if (!param_ok(m)) return MPMC_ERR_ARG;
  return principal(ws, solver, m, eps_tr, eps_p, eps, tau, info, NULL);
}
#endif

/* principal's point between its set-up and its regions (mpmc_mc_update4 solves the first
 * region of four points at once in between) */
typedef struct {
  mc_sys S;
  int perm[3]; /* perm[k] = the input index of the k-th largest */
  int perfect;
} mc_point;

/* principal's set-up: the sorted trial stress, the tolerances, the material at eps_p.
 * Returns an error code, or 0 with *done = 1 when the point is elastic (eps, tau written), or
 * 0 with *done = 0 and P set up (info->plastic = 1). */
static int principal_begin(const mpmc_mc_param *m, const double eps_tr[3], const double *eps_p,
                           double eps[3], double tau[3], mpmc_mc_info *info,
                           const mc_mat *q0in, mc_point *P, int *done) {
  *done = 0;
  if (!(isfinite(eps_tr[0]) && isfinite(eps_tr[1]) && isfinite(eps_tr[2]) && isfinite(*eps_p) &&
        *eps_p >= 0))
    return MPMC_ERR_NUMERIC;
  /* sort: perm[k] = the input index of the k-th largest */
  /* a bubble sort's three compares and swaps, in registers (conditional moves) */
  int p0 = 0, p1 = 1, p2 = 2;
  double v0 = eps_tr[0], v1 = eps_tr[1], v2 = eps_tr[2];
#define MC_SWAP_LT(pa, va, pb, vb)                                                         \
  do {                                                                                   \
    const int lt_ = va < vb, pt_ = pa;                                                   \
    const double vt_ = va;                                                               \
    pa = lt_ ? pb : pa, va = lt_ ? vb : va;                                              \
    pb = lt_ ? pt_ : pb, vb = lt_ ? vt_ : vb;                                            \
  } while (0)
  MC_SWAP_LT(p0, v0, p1, v1);
  MC_SWAP_LT(p1, v1, p2, v2);
  MC_SWAP_LT(p0, v0, p1, v1);
#undef MC_SWAP_LT
  int *perm = P->perm;
  perm[0] = p0, perm[1] = p1, perm[2] = p2;
  const double tr = eps_tr[0] + eps_tr[1] + eps_tr[2];
  mc_sys *const S = &P->S; /* not zeroed as a whole: ~0.5 kB, a tenth of a fast return */
  S->m = m;
  S->dp = m->surface != MPMC_MC_MOHR_COULOMB;
  S->n = S->act[0] = S->act[1] = S->act[2] = S->frozen = 0;
  S->ep0 = *eps_p;
  S->e_frozen = 0.0;
  for (int k = 0; k < 3; ++k) S->str[k] = m->K * tr + 2.0 * m->G * (eps_tr[perm[k]] - tr / 3.0);
  if (!(isfinite(S->str[0]) && isfinite(S->str[2]))) return MPMC_ERR_NUMERIC;
  S->tolf = tolerance(m, S->str);
  S->yscale = max_nn(fabs(S->str[0]), fabs(S->str[2])) / m->G + 1e-300;
  S->e0 = q0in ? q0in->e : e_of(m, S->ep0);
  if (q0in) {
    if (q0in != &S->q0) S->q0 = *q0in; /* mpmc_mc_update4 leaves it in place */
  } else
    mat_eval(m, S->e0, 1, &S->q0, NULL);
  const mc_mat *q0 = &S->q0;
  const double f0 = S->dp ? dp_f(q0, S->str) : mc_f(q0, S->str, 0, 2);
  if (f0 <= S->tolf && S->str[0] <= q0->st + S->tolf) { /* elastic */
    for (int a = 0; a < 3; ++a) {
      eps[a] = eps_tr[a];
      tau[a] = m->K * tr + 2.0 * m->G * (eps_tr[a] - tr / 3.0);
    }
    *done = 1;
    return MPMC_SUCCESS;
  }
  info->plastic = 1;
  P->perfect = m->eta == 0.0 ||
               (m->c_p == m->c_r && m->phi_p == m->phi_r && m->psi_p == m->psi_r);
  S->n = 1; /* the first region, Mohr-Coulomb's main plane or Drucker-Prager's cone */
  S->act[0] = S->dp ? S_DP : S_A;
  return MPMC_SUCCESS;
}

/* principal after its first region: fs what single_solve gave (0 solved, 1 not
 * admissible, 2 not solved; -1 not tried) with y, s, q, R0; then the other regions in order
 * and the result as principal's. */
static int principal_end(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, double *eps_p,
                         double eps[3], double tau[3], mpmc_mc_info *info, mc_point *P, int fs,
                         const double *y, double s[3], const mc_mat *qs, double R0) {
  mc_sys *const S = &P->S;
  const int *perm = P->perm;
  const int perfect = P->perfect;
  const mc_region *regs = S->dp ? dp_regions : mc_regions;
  const int nreg = S->dp ? (int)(sizeof dp_regions / sizeof dp_regions[0])
                         : (int)(sizeof mc_regions / sizeof mc_regions[0]);
  double ep_new = S->ep0;
  int found = 0, r0 = 0;
  if (fs == 0) {
    found = 1;
    info->region = regs[0].region;
    info->dgamma = y[0];
    info->residual = fabs(R0);
    ep_new = S->ep0 + y[1];
    if (qs->st_apex && s[0] - s[2] <= 8.0 * S->tolf) info->region = MPMC_MC_APEX;
  } else if (fs == 1) {
    r0 = 1; /* converged but not admissible: the general loop from the next region */
  }
  /* the regions in order, but Mohr-Coulomb's extension edge before the compression edge when
   * the main plane's return breaks s2 >= s3 more than s1 >= s2 (an edge return tried both) */
  int order[16];
  for (int r = 0; r < nreg; ++r) order[r] = r;
  if (r0 == 1 && !S->dp && s[2] - s[1] > s[1] - s[0]) order[1] = 2, order[2] = 1;
  if (r0 == 1 && !S->dp) /* the edges, that order, by edge_solve while it decides */
    for (; r0 < 3 && !found; ++r0) {
      const mc_region *rg = &regs[order[r0]];
      double y[MC_NMAX], res;
      mc_mat q;
      S->n = rg->n;
      memcpy(S->act, rg->act, sizeof S->act);
      const int es = edge_solve(S, perfect, y, s, &q, &res, info);
      if (es == 2) break; /* the general loop from this region */
      if (es == 1) continue;
      found = 1;
      info->region = rg->region;
      info->dgamma = y[0] + y[1];
      info->residual = res;
      ep_new = S->ep0 + y[2];
      if (q.st_apex && s[0] - s[2] <= 8.0 * S->tolf) info->region = MPMC_MC_APEX;
    }
  for (int ro = r0; ro < nreg && !found; ++ro) {
    const int r = order[ro];
    int uses_t = 0;
    for (int j = 0; j < regs[r].n; ++j) uses_t |= regs[r].act[j] >= S_T1 && regs[r].act[j] <= S_T3;
    if (uses_t && !tension_regions(m, &S->q0)) continue;
    S->n = regs[r].n;
    memcpy(S->act, regs[r].act, sizeof S->act);
    double y[MC_NMAX] = {0, 0, 0, 0}, R[MC_NMAX];
    int err = 0;
    const int fail = solve_region(ws, solver, S, perfect, y, info, &err);
    if (err) return err;
    if (fail) continue;
    mc_mat q = S->q0; /* the material at the solution, and the stress and residuals there */
    if (!perfect) mat_eval(m, sys_e(S, y[S->n]), 1, &q, &S->q0);
    mc_sys Se = *S;
    Se.frozen = 1;
    Se.e_frozen = perfect ? S->e0 : q.e;
    Se.qf = q;
    sys_eval(&Se, y, R, NULL, s);
    if (!admissible(S, y, s, &q)) {
      if (ro == 0 && !S->dp && s[2] - s[1] > s[1] - s[0]) order[1] = 2, order[2] = 1;
      continue;
    }
    found = 1;
    info->region = regs[r].region;
    info->dgamma = 0.0;
    info->residual = 0.0;
    for (int j = 0; j < S->n; ++j) {
      info->dgamma += y[j];
      info->residual = fmax(info->residual, fabs(R[j]));
    }
    ep_new = S->ep0 + y[S->n];
    /* a return to the apex through a cut-off capped there is the apex */
    if (q.st_apex && s[0] - s[2] <= 8.0 * S->tolf) info->region = MPMC_MC_APEX;
  }
  if (!found) {
    /* the hydrostatic point s = sigma_c 1, sigma_c the cut-off or the apex: D follows from
     * the trial deviator alone, D = sqrt(2/3) |dev s_tr| / 2G */
    const double p = (S->str[0] + S->str[1] + S->str[2]) / 3.0;
    const double dv[3] = {S->str[0] - p, S->str[1] - p, S->str[2] - p};
    const double D = sqrt(2.0 / 3.0) * sqrt(dot3(dv, dv)) / (2.0 * m->G);
    mc_mat q = S->q0;
    if (!perfect) mat_eval(m, sys_e(S, D), 1, &q, &S->q0);
    /* the volume must shrink back (the apex is reached by a volumetric plastic expansion) */
    if (!isfinite(q.st) || !(p >= q.st - S->tolf)) return MPMC_ERR_SOLVER;
    s[0] = s[1] = s[2] = q.st;
    ep_new = S->ep0 + D;
    info->region = q.st_apex ? MPMC_MC_APEX : MPMC_MC_TENSION_CORNER;
    info->dgamma = (p - q.st) / m->K + D; /* volumetric and deviatoric parts, for the record */
    info->residual = 0.0;
  }
  if (!(isfinite(s[0]) && isfinite(s[1]) && isfinite(s[2]) && isfinite(ep_new)))
    return MPMC_ERR_SOLVER;
  const double p = (s[0] + s[1] + s[2]) / 3.0;
  for (int k = 0; k < 3; ++k) {
    tau[perm[k]] = s[k];
    eps[perm[k]] = (s[k] - p) / (2.0 * m->G) + p / (3.0 * m->K);
  }
  *eps_p = ep_new;
  return MPMC_SUCCESS;
}

/* mpmc_mc_return_principal for a material that passed param_ok, info zeroed; q0in: the
 * material at *eps_p when the caller has it (mpmc_mc_update), else NULL. */
/* principal after principal_begin: the first region in closed form, then principal_end */
static int principal_rest(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, double *eps_p,
                          double eps[3], double tau[3], mpmc_mc_info *info, mc_point *P) {
  double y[MC_NMAX] = {0, 0, 0, 0}, s[3], R0 = 0.0;
  mc_mat q;
  int fs = -1;
  if (P->perfect || solver == MPMC_SOLVER_AUTO)
    fs = single_solve(&P->S, P->perfect, y, s, &q, &R0, info);
  return principal_end(ws, solver, m, eps_p, eps, tau, info, P, fs, y, s, &q, R0);
}

static int principal(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, const double eps_tr[3],
                     double *eps_p, double eps[3], double tau[3], mpmc_mc_info *info,
                     const mc_mat *q0in) {
  mc_point P;
  int done;
  MPMC_CALL(principal_begin(m, eps_tr, eps_p, eps, tau, info, q0in, &P, &done));
  if (done) return MPMC_SUCCESS;
  return principal_rest(ws, solver, m, eps_p, eps, tau, info, &P);
}

/* The eigen path from the trial state: b its b_e, or (lg) eps = 1/2 ln b_e already formed by
 * the series, whose eigen-decomposition gives the principal strains without three logs; then
 * btr is the trial b_e itself, and the returned b_e's eigenvalues are its own, q_a.b q_a,
 * times exp(2 (eps_a - eps_tr,a)) (a small correction: return_map.h's polynomial; libm's
 * exp beyond it), J likewise sqrt(det b) exp(tr(eps - eps_tr)): four exps less. */
static int return_decomposed(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m,
                             double lam[3], double Q[3][3], const double *btr, double *be,
                             double *eps_p, double *tau, double *J_out, mpmc_mc_info *info,
                             const mc_mat *q0);

static int return_eig(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, const double *b,
                      const double *btr, double *be, double *eps_p, double *tau, double *J_out,
                      mpmc_mc_info *info, const mc_mat *q0) {
  double lam[3], Q[3][3];
  if (btr) /* the update's plastic points: closed form (the Jacobi sweeps cost ~5x the return) */
    mpmc_sym3_eig_closed(b, lam, Q);
  else /* the reference path of mpmc_mc_return_map_eig, and strains beyond the series */
    mpmc_sym3_eig(b, lam, Q);
  return return_decomposed(ws, solver, m, lam, Q, btr, be, eps_p, tau, J_out, info, q0);
}

/* return_eig from the decomposition lam, Q of its b (of eps when btr is given) */
static int return_decomposed(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m,
                             double lam[3], double Q[3][3], const double *btr, double *be,
                             double *eps_p, double *tau, double *J_out, mpmc_mc_info *info,
                             const mc_mat *q0) {
  const int lg = btr != NULL;
  double etr[3], e[3], t[3];
  for (int a = 0; a < 3; ++a) {
    if (lg) {
      etr[a] = lam[a];
      continue;
    }
    if (!(lam[a] > 0.0) || !isfinite(lam[a])) return MPMC_ERR_NUMERIC;
    etr[a] = 0.5 * log(lam[a]);
  }
  double ep = *eps_p;
  if (q0) { /* mpmc_mc_update: m passed param_ok, q0 the material at eps_p */
    mpmc_mc_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    MPMC_CALL(principal(ws, solver, m, etr, &ep, e, t, info, q0));
  } else {
    MPMC_CALL(mpmc_mc_return_principal(ws, solver, m, etr, &ep, e, t, info));
  }
  for (int a = 0; a < 3; ++a) {
    const double d = 2.0 * (etr[a] - e[a]);
    if (!lg || !(fabs(d) <= MPMC_RM_EXP_SMALL)) {
      lam[a] = exp(2.0 * e[a]);
      continue;
    }
    const double x = Q[0][a], y = Q[1][a], z = Q[2][a]; /* q_a . btr q_a */
    const double lt = x * (btr[0] * x + btr[5] * y + btr[4] * z) +
                      y * (btr[5] * x + btr[1] * y + btr[3] * z) +
                      z * (btr[4] * x + btr[3] * y + btr[2] * z);
    lam[a] = lt * MPMC_RM_EXP_NEG_POLY(d);
  }
  mpmc_sym3_compose(lam, Q, be);
  mpmc_sym3_compose(t, Q, tau);
  if (J_out) {
    const double d = (etr[0] + etr[1] + etr[2]) - (e[0] + e[1] + e[2]);
    *J_out = lg && fabs(d) <= MPMC_RM_EXP_SMALL ? sqrt(mpmc_det_sym(btr)) * MPMC_RM_EXP_NEG_POLY(d)
                                                : exp(e[0] + e[1] + e[2]);
  }
  *eps_p = ep;
  return MPMC_SUCCESS;
}

#if !defined(MPMC_ISA_AVX2)
/**
 * @brief The frictional return map of one point in tensor form by the eigen-decomposition
 * of the trial b_e for every point (return_mc.h; the principal directions are kept).
 * @param F     relative deformation gradient, or NULL when be is already the trial state
 * @param be    elastic left Cauchy-Green tensor (Voigt), in/out
 * @param eps_p accumulated plastic deviatoric strain, in/out
 * @param tau   Kirchhoff stress out (Voigt); J_out = sqrt(det b_e) (may be NULL)
 * @return 0, MPMC_ERR_NUMERIC (b_e not positive definite or not finite) or the principal
 *         return's code; on failure be, eps_p and tau are unchanged.
 */
int mpmc_mc_return_map_eig(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, double F[3][3],
                           double *be, double *eps_p, double *tau, double *J_out,
                           mpmc_mc_info *info) {
  double b[6];
  for (int k = 0; k < 6; ++k) b[k] = be[k];
  if (F) mpmc_push_forward(F, b);
  return return_eig(ws, solver, m, b, NULL, be, eps_p, tau, J_out, info, NULL);
}

/**
 * @brief The per-material part of the elastic check (return_mc.h): the peak strengths of
 * mat_eval at eps_p = 0, the very values mpmc_mc_return_principal starts from.
 */
void mpmc_mc_prepare(const mpmc_mc_param *m, mpmc_mc_pre *pre) {
  pre->m = *m;
  pre->valid = param_ok(m);
  pre->perfect = m->eta == 0.0 || (m->c_p == m->c_r && m->phi_p == m->phi_r && m->psi_p == m->psi_r);
  mc_mat q;
  mat_eval(m, e_of(m, 0.0), 1, &q, NULL);
  pre->sf = q.sf;
  pre->k = m->surface == MPMC_MC_MOHR_COULOMB ? 2.0 * q.c * q.cf : q.xi * q.c;
  pre->eta = q.eta;
  pre->gmax = sqrt(1.0 + q.sf * q.sf / 3.0);
  pre->st = q.st;
  pre->q0 = q;
  for (int i = 0; i < MPMC_MC_NREF; ++i)
    mat_eval(m, (double)i / (MPMC_MC_NREF - 1), 1, &pre->ref[i], NULL);
}

/* The elastic check of the trial b without eigenvectors.  Hencky strain eps by the series,
 * tau = K tr(eps) I + 2G dev(eps), p = tr(tau)/3, s = dev(tau), J2 = s:s / 2.  With the
 * deviator's principal values s_k = 2 sqrt(J2/3) cos(a - 2 pi (k-1)/3) (s1 >= s2 >= s3 for
 * a = acos((3 sqrt3 / 2) J3 / J2^(3/2)) / 3 in [0, pi/3]; J3 = det s):
 *   Mohr-Coulomb  f = (s1 - s3) - s2 sin(phi) + 2p sin(phi) - 2c cos(phi), whose deviatoric
 *     part is 2 sqrt(J2) (cos b - sin b sin(phi)/sqrt3), b = a - pi/6, at most
 *     2 sqrt(J2) sqrt(1 + sin^2(phi)/3) (no trigonometry when that bound is enough);
 *   Drucker-Prager f = sqrt(J2) + eta_f p - xi c;  cut-off p + s1 <= sigma_t, s1 <= 2 sqrt(J2/3).
 * A point counts as elastic here only when every f is below -1e-6 of the stress scale: far
 * beyond the round-off of either path (the trigonometric s_k lose ~1e-8 near repeated
 * values), so that it is elastic in the eigen path too.  Returns 1 with be = b, tau, J
 * written; 0 leaves the point to the eigen path (plastic, near a surface, or |eps| >~ 0.18),
 * with eps in *eps_out (and 1 in *lg) when the series gave it. */
static int elastic_check(const mpmc_mc_pre *pre, const double *b, const double *eps,
                         double eps_p, double *be, double *tau, double *J_out, mc_mat *qout);

static int elastic_fast(const mpmc_mc_pre *pre, const double *b, double eps_p, double *eps_out,
                        int *lg, double *be, double *tau, double *J_out, mc_mat *qout) {
  *lg = 0;
  if (mpmc_sym3_log_series(b, eps_out)) return 0;
  *lg = 1;
  return elastic_check(pre, b, eps_out, eps_p, be, tau, J_out, qout);
}
#endif

/* elastic_check's material at eps_p: *qout for the return, and what the check needs of it,
 * c = (sin phi, k, eta_f, sqrt(1 + sin^2(phi) / 3), the capped cut-off) */
static inline void check_mat(const mpmc_mc_pre *pre, double eps_p, mc_mat *qout, double c[5]) {
  const mpmc_mc_param *m = &pre->m;
  c[0] = pre->sf, c[1] = pre->k, c[2] = pre->eta, c[3] = pre->gmax, c[4] = pre->st;
  if (pre->perfect || eps_p == 0.0) {
    *qout = pre->q0;
    if (pre->perfect && eps_p != 0.0 && m->eta > 0.0) qout->e = e_of(m, eps_p);
  } else {
    /* the sines and cosines from those of the nearest of pre's materials (sin_cos_near),
     * written in place (a copy of the struct just written would wait on its stores) */
    mc_mat *q = qout;
    const double ee = e_of(m, eps_p);
    const int kr = (int)(ee * (MPMC_MC_NREF - 1) + 0.5);
    mat_eval(m, ee, 1, q, &pre->ref[kr < 0 ? 0 : kr > MPMC_MC_NREF - 1 ? MPMC_MC_NREF - 1 : kr]);
    c[0] = q->sf;
    c[1] = m->surface == MPMC_MC_MOHR_COULOMB ? 2.0 * q->c * q->cf : q->xi * q->c;
    c[2] = q->eta;
    c[3] = sqrt(1.0 + c[0] * c[0] / 3.0);
    c[4] = q->st;
  }
}

/* elastic_check's decision by the principal stresses from the invariants of the deviator s
 * (J2 = j2, sqrt(J2) = rj), where its bounds left ok_f or ok_t open: 1 elastic */
static int check_trig(const double s[6], double j2, double rj, double p, double sf, double k,
                      double st, double margin, int ok_f, int ok_t) {
  const double r3 = 1.7320508075688772;
  /* the largest and smallest principal deviatoric stresses from the invariants */
  const double x = j2 > 0.0 ? 1.5 * r3 * mpmc_det_sym(s) / (j2 * rj) : 1.0;
  const double a = acos(!(x > -1.0) ? -1.0 : x >= 1.0 ? 1.0 : x) / 3.0, ca = cos(a), sa = sin(a);
  const double R = 2.0 * rj / r3, s1 = R * ca, s3 = R * (-0.5 * ca - 0.5 * r3 * sa);
  if (!ok_f) ok_f = (s1 - s3) + (2.0 * p + s1 + s3) * sf - k < -margin;
  if (!ok_t) ok_t = p + s1 < st - margin;
  return ok_f && ok_t;
}

#if !defined(MPMC_ISA_AVX2)
/* elastic_fast's check from the series strain eps of b (mpmc_mc_update4 takes its steps
 * four lanes at a time) */
static int elastic_check(const mpmc_mc_pre *pre, const double *b, const double *eps,
                         double eps_p, double *be, double *tau, double *J_out, mc_mat *qout) {
  const mpmc_mc_param *m = &pre->m;
  double e[6];
  for (int k = 0; k < 6; ++k) e[k] = eps[k];
  const double tr = e[0] + e[1] + e[2], G2 = 2.0 * m->G, p = m->K * tr;
  for (int k = 0; k < 3; ++k) e[k] -= tr / 3.0;
  double s[6];
  for (int k = 0; k < 6; ++k) s[k] = G2 * e[k];
  const double j2 = 0.5 * mpmc_sym3_norm2(s), rj = sqrt(j2);
  double c[5];
  check_mat(pre, eps_p, qout, c);
  const double sf = c[0], k = c[1], eta = c[2], gmax = c[3], st = c[4];
  const double margin = 1e-6 * (fabs(p) + rj + k);
  const int mc = m->surface == MPMC_MC_MOHR_COULOMB;
  const double r3 = 1.7320508075688772;
  int ok_f = mc ? 2.0 * rj * gmax + 2.0 * p * sf - k < -margin : rj + eta * p - k < -margin;
  if (!mc && !ok_f) return 0; /* Drucker-Prager's f is exact: not elastic by the margin */
  /* Mohr-Coulomb's deviatoric part is at least sqrt(J2) (sqrt3 - sin(phi)/sqrt3) (at
   * s1 = s2): beyond the surface by the margin with that, the point is plastic */
  if (mc && !ok_f && rj * (r3 - sf / r3) + 2.0 * p * sf - k > margin) return 0;
  int ok_t = p + 2.0 * rj / r3 < st - margin;
  if (!(ok_f && ok_t) && !check_trig(s, j2, rj, p, sf, k, st, margin, ok_f, ok_t)) return 0;
  for (int i = 0; i < 6; ++i) be[i] = b[i]; /* elastic: keep b_e as pushed forward */
  for (int i = 0; i < 6; ++i) tau[i] = s[i];
  for (int i = 0; i < 3; ++i) tau[i] += p;
  if (J_out) *J_out = exp(tr);
  return 1;
}
#endif

/* Drucker-Prager's plastic point without eigenvectors (as J2's, material_hencky_j2.c).  The
 * cone's return is radial in the deviator: its principal problem sees the trial stress only
 * through p and J2 (eval_dp), so the principal values from the invariants (elastic_fast's
 * trigonometric form, ~1e-8 off near repeated values but with p and J2 to round-off) give
 * the eigen path's multipliers and eps_p.  Then, with dev(tau) = ratio dev(tau_trial),
 *   tau = p I + ratio 2G dev(eps),  b_e = exp(2 eps_new) = b exp(2 (ratio - 1) dev(eps))
 *   exp(2 (tr eps_new - tr eps) / 3)
 * (b and the correction commute).  Only a return to the cone (region 1) or to the
 * hydrostatic point (s1 = s2 = s3) whose largest principal stress stays 1e-6 of the stress
 * scale clear of the cut-off is taken here (the trigonometric s1 decides nothing else);
 * returns 1 with nothing written for the rest, which take the eigen path. */
static int dp_radial(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, const double *b,
                     const double *eps, const mc_mat *q0, double *be, double *eps_p,
                     double *tau, double *J_out, mpmc_mc_info *info) {
  const mpmc_mc_param *m = &pre->m;
  const double tr = eps[0] + eps[1] + eps[2], r3 = 1.7320508075688772;
  double e[6];
  for (int k = 0; k < 6; ++k) e[k] = eps[k];
  for (int k = 0; k < 3; ++k) e[k] -= tr / 3.0;
  const double j2 = 0.5 * mpmc_sym3_norm2(e), rj = sqrt(j2); /* of dev eps */
  if (!(rj > 0.0)) return 1;
  const double x = 1.5 * r3 * mpmc_det_sym(e) / (j2 * rj);
  const double a = acos(!(x > -1.0) ? -1.0 : x >= 1.0 ? 1.0 : x) / 3.0, ca = cos(a), sa = sin(a);
  const double R = 2.0 * rj / r3;
  const double etr[3] = {tr / 3.0 + R * ca, tr / 3.0 + R * (-0.5 * ca + 0.5 * r3 * sa),
                         tr / 3.0 + R * (-0.5 * ca - 0.5 * r3 * sa)};
  double ep = *eps_p, en[3], t[3];
  mpmc_mc_info loc = {0};
  if (principal(ws, solver, m, etr, &ep, en, t, &loc, q0)) return 1;
  const double pn = (t[0] + t[1] + t[2]) / 3.0, sc = fabs(t[0]) + fabs(t[2]) + m->c_p;
  double st = q0->st, ratio;
  if (!(pre->perfect || ep == *eps_p)) {
    mc_mat q;
    const double x = m->eta * (ep - *eps_p); /* e0 exp(-x) for a small x, as sys_e */
    mat_eval(m, fabs(x) <= MPMC_RM_EXP_SMALL ? q0->e * MPMC_RM_EXP_NEG_POLY(x) : e_of(m, ep), 1,
             &q, q0);
    st = q.st;
  }
  const int k = fabs(etr[2] - tr / 3.0) > fabs(etr[0] - tr / 3.0) ? 2 : 0; /* largest |dev| */
  if (loc.region == MPMC_MC_PLANE && t[0] < st - 1e-6 * sc)
    ratio = (t[k] - pn) / (2.0 * m->G * (etr[k] - tr / 3.0));
  else if (loc.region == MPMC_MC_APEX && t[0] == t[1] && t[1] == t[2])
    ratio = 0.0;
  else
    return 1;
  const double trn = en[0] + en[1] + en[2];
  double c[6], E[6];
  for (int k = 0; k < 6; ++k) c[k] = 2.0 * (ratio - 1.0) * e[k];
  if (mpmc_sym3_exp_series(c, E)) return 1;
  mpmc_sym3_mul(b, E, be);
  /* the volume's factors exp(2 dtr / 3) and J = sqrt(det b) exp(dtr): polynomials of the
   * small plastic dtr = tr(eps_new - eps) (return_map.h), libm's exp beyond */
  const double dtr = trn - tr;
  const int small = fabs(dtr) <= MPMC_RM_EXP_SMALL;
  const double fv = small ? MPMC_RM_EXP_NEG_POLY(-2.0 * dtr / 3.0) : exp(2.0 * dtr / 3.0);
  for (int k = 0; k < 6; ++k) be[k] *= fv;
  for (int k = 0; k < 6; ++k) tau[k] = 2.0 * m->G * ratio * e[k];
  for (int k = 0; k < 3; ++k) tau[k] += pn;
  if (J_out) *J_out = small ? sqrt(mpmc_det_sym(b)) * MPMC_RM_EXP_NEG_POLY(-dtr) : exp(trn);
  *eps_p = ep;
  if (info) *info = loc;
  return 0;
}

#if !defined(MPMC_ISA_AVX2)
/**
 * @brief The frictional return map of one point in tensor form (return_mc.h): the elastic
 * check without eigenvectors (elastic_fast), the eigen path for the rest.
 * @param pre   the material, from mpmc_mc_prepare
 * Other parameters and the return value as mpmc_mc_return_map_eig's.
 */
int mpmc_mc_update(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, double F[3][3],
                   double *be, double *eps_p, double *tau, double *J_out, mpmc_mc_info *info) {
  double b[6], eps[6];
  int lg = 0;
  mc_mat q0;
  for (int k = 0; k < 6; ++k) b[k] = be[k];
  if (F) mpmc_push_forward(F, b);
  if (pre->valid && *eps_p >= 0.0 && isfinite(*eps_p) &&
      elastic_fast(pre, b, *eps_p, eps, &lg, be, tau, J_out, &q0)) {
    if (info) memset(info, 0, sizeof *info);
    return MPMC_SUCCESS;
  }
  /* lg: the series gave eps and elastic_fast the material at eps_p */
  if (lg && pre->m.surface != MPMC_MC_MOHR_COULOMB &&
      !dp_radial(ws, solver, pre, b, eps, &q0, be, eps_p, tau, J_out, info))
    return MPMC_SUCCESS;
  return return_eig(ws, solver, &pre->m, lg ? eps : b, lg ? b : NULL, be, eps_p, tau, J_out,
                    info, lg ? &q0 : NULL);
}
#endif

/* Lane-wise compares: AVX's own; on the baseline build batch4.h's mask table (CMP4) */
#if defined(__AVX__)
#define MC_CMP4(a, op, b) ((l4)((a)op(b)))
#else
#define MC_CMP4(a, op, b) CMP4(a, op, b)
#endif
/* the lanes of x that are finite */
#define MC_FINITE4(x) MC_CMP4((x) - (x), ==, ((v4){0.0, 0.0, 0.0, 0.0}))
/* max_nn per lane */
#define MC_MAX_NN4(a, b) SEL4(MC_CMP4(a, >=, b) | MC_CMP4(b, !=, b), a, b)

/* Mohr-Coulomb's material of mat_eval's operations per lane for single_solve's Newton
 * (frozen = 0, ref the lane's material at eps_p^n): the fields single_eval reads, from e */
typedef struct {
  v4 e, phi, psi, c, dc, dphi, sf, cf, ss, cs, dsf, dcf, dss;
} mc_mat4;

/* sin_cos_near per lane (lanes of m; libm where |d| > 0.1) */
static inline void sin_cos_near4(const v4 *xp, const v4 *x0, const v4 *s0p, const v4 *c0p, int m,
                                 v4 *s, v4 *c) {
  const v4 x = *xp, s0 = *s0p, c0 = *c0p, d = x - *x0, ad = ABS4(d), d2 = d * d;
  const v4 t = {0x1p-9, 0x1p-9, 0x1p-9, 0x1p-9}, f = {0.1, 0.1, 0.1, 0.1};
  v4 sd = d + d * d2 * (-1.0 / 6 + d2 * (1.0 / 120));
  v4 cm = d2 * (0.5 + d2 * (-1.0 / 24 + d2 * (1.0 / 720)));
  const l4 small = MC_CMP4(ad, <=, t);
  if (m & ~mask_bits(&small)) {
    const v4 sd6 = d + d * d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880 + d2 * (-1.0 / 39916800)))));
    const v4 cm6 = d2 * (0.5 + d2 * (-1.0 / 24 + d2 * (1.0 / 720 + d2 * (-1.0 / 40320 + d2 * (1.0 / 3628800)))));
    sd = SEL4(small, sd, sd6);
    cm = SEL4(small, cm, cm6);
  }
  *s = s0 + (c0 * sd - s0 * cm);
  *c = c0 - (s0 * sd + c0 * cm);
  const l4 nearm = MC_CMP4(ad, <=, f);
  const int far = m & ~mask_bits(&nearm);
  for (int l = 0; l < 4; ++l)
    if (far >> l & 1) {
      (*s)[l] = sin(x[l]);
      (*c)[l] = cos(x[l]);
    }
}

/* check_mat of Mohr-Coulomb's softened lanes (lanes of L: eps_p > 0, softening), mat_eval's
 * operations per lane (frozen, seeded by the nearest of pre's materials) into P[l].S.q0 and
 * the lanes of c */
static void check_mat4(const mpmc_mc_pre *pre, const double *eps_p, int L, mc_point P[4],
                       v4 c[5]) {
  const mpmc_mc_param *m = &pre->m;
  const v4 zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0};
  v4 e = one, rphi, rsf, rcf, rpsi, rss, rcs;
  for (int l = 0; l < 4; ++l) {
    const mc_mat *r = &pre->ref[MPMC_MC_NREF - 1];
    if (L >> l & 1) {
      e[l] = e_of(m, eps_p[l]);
      const int kr = (int)(e[l] * (MPMC_MC_NREF - 1) + 0.5);
      r = &pre->ref[kr < 0 ? 0 : kr > MPMC_MC_NREF - 1 ? MPMC_MC_NREF - 1 : kr];
    }
    rphi[l] = r->phi, rsf[l] = r->sf, rcf[l] = r->cf, rpsi[l] = r->psi, rss[l] = r->ss;
    rcs[l] = r->cs;
  }
  const double de = 0.0; /* frozen */
  const v4 phi = m->phi_r + (m->phi_p - m->phi_r) * e, psi = m->psi_r + (m->psi_p - m->psi_r) * e;
  const v4 cc = m->c_r + (m->c_p - m->c_r) * e;
  const double dc = (m->c_p - m->c_r) * de, dphi = (m->phi_p - m->phi_r) * de;
  const double dpsi = (m->psi_p - m->psi_r) * de;
  v4 sf, cf, ss, cs;
  sin_cos_near4(&phi, &rphi, &rsf, &rcf, L, &sf, &cf);
  sin_cos_near4(&psi, &rpsi, &rss, &rcs, L, &ss, &cs);
  const v4 dsf = cf * dphi, dcf = -sf * dphi, dss = cs * dpsi;
  const l4 pos = MC_CMP4(sf, >, zero);
  const v4 isf = 1.0 / SEL4(pos, sf, one);
  const v4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
  const v4 apex = SEL4(pos, cc * cf * isf, inf);
  const v4 dapex = SEL4(pos, dc * cf * isf - cc * dphi * (isf * isf), zero);
  const v4 st0 = {m->sigma_t, m->sigma_t, m->sigma_t, m->sigma_t};
  const l4 lt = MC_CMP4(st0, <, apex), fa = MC_FINITE4(apex);
  const v4 st = SEL4(lt, st0, apex), dst = SEL4(lt, zero, dapex);
  v4 g2 = 1.0 + sf * sf / 3.0, gmax;
  sqrt4(&g2, &gmax);
  const v4 k = 2.0 * cc * cf;
  for (int l = 0; l < 4; ++l) {
    if (!(L >> l & 1)) continue;
    mc_mat *q = &P[l].S.q0;
    q->e = e[l], q->phi = phi[l], q->psi = psi[l], q->c = cc[l], q->dc = dc, q->dphi = dphi;
    q->sf = sf[l], q->cf = cf[l], q->ss = ss[l], q->cs = cs[l];
    q->dsf = dsf[l], q->dcf = dcf[l], q->dss = dss[l];
    q->eta = q->xi = q->etab = q->deta = q->dxi = q->detab = 0.0;
    q->st = st[l], q->dst = dst[l];
    q->st_apex = !lt[l] && fa[l];
    c[0][l] = sf[l], c[1][l] = k[l], c[2][l] = 0.0, c[3][l] = gmax[l], c[4][l] = st[l];
  }
}

/* single_eval's main plane per lane: R0, R1, the stress s and (J) the Jacobian */
static inline void single_eval4(const mpmc_mc_param *m, const v4 *str, const mc_mat4 *q,
                                const v4 *gp, const v4 *y1p, v4 *R0, v4 *R1, v4 J[2][2],
                                v4 s[3]) {
  const v4 g = *gp, y1 = *y1p;
  const double c23 = sqrt(2.0 / 3.0);
  const double lam = m->K - 2.0 * m->G / 3.0, G2 = 2.0 * m->G;
  const v4 a0 = 1.0 + q->sf, a2 = -(1.0 - q->sf), N0 = 1.0 + q->ss, N2 = -(1.0 - q->ss);
  const v4 M0 = g * N0, M2 = g * N2, trM = M0 + M2;
  s[0] = str[0] - (lam * trM + G2 * M0);
  s[1] = str[1] - lam * trM;
  s[2] = str[2] - (lam * trM + G2 * M2);
  *R0 = a0 * s[0] + a2 * s[2] - 2.0 * q->c * q->cf;
  const v4 t3 = trM / 3.0;
  v4 u[3] = {M0 - t3, -t3, M2 - t3}, nd;
  const v4 nn = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
  sqrt4(&nn, &nd);
  *R1 = y1 - c23 * nd;
  if (!J) return;
  const v4 zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0};
  const l4 pos = MC_CMP4(nd, >, zero);
  const v4 nds = SEL4(pos, nd, one);
  for (int i = 0; i < 3; i += 2) u[i] = SEL4(pos, u[i] / nds, zero);
  const v4 trN = N0 + N2, dM = g * q->dss;
  J[0][0] = -(a0 * (lam * trN + G2 * N0) + a2 * (lam * trN + G2 * N2));
  J[1][0] = -c23 * (u[0] * N0 + u[2] * N2);
  const v4 DdM0 = lam * 2.0 * dM + G2 * dM;
  J[0][1] = q->dsf * (s[0] + s[2]) - 2.0 * (q->dc * q->cf + q->c * q->dcf) - (a0 + a2) * DdM0;
  J[1][1] = 1.0 - c23 * (u[0] + u[2]) * dM;
}

/* single_solve of Mohr-Coulomb's main plane for the lanes of L (P[l] set up by
 * principal_begin, S->n = 1): its operations lane by lane, Newton's iterates of all lanes
 * together, each lane stopping where single_solve stops.  Gives what single_solve gives
 * each lane but admissible's verdict: y, s, q, R0 and fs[l] (0, or 2 when not solved; then
 * admissible per lane makes 0 or 1); info[l].newton_iters as single_solve counts them. */
static void main_plane4(mc_point P[4], int L, mpmc_mc_info info[4], double y[4][MC_NMAX],
                        double s[4][3], mc_mat q[4], double R0[4], int fs[4]) {
  const mpmc_mc_param *m = P[__builtin_ctz((unsigned)L)].S.m;
  const int perfect = P[__builtin_ctz((unsigned)L)].perfect;
  const v4 zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0};
  v4 str[3], tolf, e0, ep0;
  mc_mat4 q0, qv;
  /* the lanes' systems (the other lanes: copies of the first of L), gathered by four
   * loads a vector (in registers, not through a store and a wider load) */
  const int l0 = __builtin_ctz((unsigned)L);
  const mc_sys *S0 = &P[L & 1 ? 0 : l0].S, *S1 = &P[L & 2 ? 1 : l0].S;
  const mc_sys *S2 = &P[L & 4 ? 2 : l0].S, *S3 = &P[L & 8 ? 3 : l0].S;
#define MC_GATHER(f) ((v4){S0->f, S1->f, S2->f, S3->f})
  for (int k = 0; k < 3; ++k) str[k] = MC_GATHER(str[k]);
  tolf = MC_GATHER(tolf), e0 = MC_GATHER(e0), ep0 = MC_GATHER(ep0);
  q0.e = MC_GATHER(q0.e), q0.phi = MC_GATHER(q0.phi), q0.psi = MC_GATHER(q0.psi);
  q0.c = MC_GATHER(q0.c), q0.dc = MC_GATHER(q0.dc), q0.dphi = MC_GATHER(q0.dphi);
  q0.sf = MC_GATHER(q0.sf), q0.cf = MC_GATHER(q0.cf), q0.ss = MC_GATHER(q0.ss);
  q0.cs = MC_GATHER(q0.cs), q0.dsf = MC_GATHER(q0.dsf), q0.dcf = MC_GATHER(q0.dcf);
  q0.dss = MC_GATHER(q0.dss);
#undef MC_GATHER
  /* the perfect-plasticity predictor at eps_p^n */
  v4 R0v, R1v, J[2][2], sv[3], y0, y1 = zero, R0k;
  single_eval4(m, str, &q0, &zero, &zero, &R0v, &R1v, J, sv);
  y0 = -R0v / J[0][0];
  const l4 bad = ~(MC_CMP4(J[0][0], !=, zero) & MC_FINITE4(y0));
  int live = L, bbits = L & mask_bits(&bad);
  if (bbits) {
    if (perfect) {
      for (int l = 0; l < 4; ++l)
        if (bbits >> l & 1) {
          fs[l] = 2;
          for (int k = 0; k < 3; ++k) s[l][k] = sv[k][l];
          y[l][0] = y0[l], y[l][1] = 0.0, y[l][2] = y[l][3] = 0.0;
        }
      live &= ~bbits;
      if (!live) return;
    }
    y0 = SEL4(bad, zero, y0);
  }
  {
    v4 s2[3];
    single_eval4(m, str, &q0, &y0, &zero, &R0v, &R1v, NULL, s2);
    y1 = SEL4(bad, zero, -R1v);
    for (int k = 0; k < 3; ++k) sv[k] = SEL4(bad, sv[k], s2[k]);
  }
  int ok = 0;
  if (perfect) {
    single_eval4(m, str, &q0, &y0, &y1, &R0v, &R1v, NULL, sv);
    const v4 r = MC_MAX_NN4(ABS4(R0v), 2.0 * m->G * ABS4(R1v));
    const l4 rok = MC_CMP4(r, <=, tolf);
    ok = live & mask_bits(&rok);
    R0k = R0v;
  } else {
    const v4 eta = {m->eta, m->eta, m->eta, m->eta};
    const double G2 = 2.0 * m->G;
    v4 prev = {INFINITY, INFINITY, INFINITY, INFINITY};
    int act = live, iters[4] = {0, 0, 0, 0};
    /* the lanes that have stopped keep their y, so that each iterate gives them the values
     * of their last one again (libm too, where it takes over from the polynomials, in all
     * the lanes of live): the loop's last values are every lane's own */
    mc_mat4 qn;
    for (int it = 0; it < MC_MAX_ITERS && act; ++it) {
      /* mat_eval(m, sys_e(S, y1), 0, q, &S->q0) */
      const v4 x = m->eta * y1;
      qn.e = e0 * MPMC_RM_EXP_NEG_POLY(x);
      const v4 ax = ABS4(x), xs = {MPMC_RM_EXP_SMALL, MPMC_RM_EXP_SMALL, MPMC_RM_EXP_SMALL,
                                   MPMC_RM_EXP_SMALL};
      const l4 xsm = MC_CMP4(ax, <=, xs);
      const int big = live & ~mask_bits(&xsm);
      for (int l = 0; l < 4; ++l)
        if (big >> l & 1) qn.e[l] = exp(-m->eta * (ep0[l] + y1[l]));
      const v4 de = -eta * qn.e;
      qn.phi = m->phi_r + (m->phi_p - m->phi_r) * qn.e;
      qn.psi = m->psi_r + (m->psi_p - m->psi_r) * qn.e;
      qn.c = m->c_r + (m->c_p - m->c_r) * qn.e;
      qn.dc = (m->c_p - m->c_r) * de;
      qn.dphi = (m->phi_p - m->phi_r) * de;
      const v4 dpsi = (m->psi_p - m->psi_r) * de;
      sin_cos_near4(&qn.phi, &q0.phi, &q0.sf, &q0.cf, live, &qn.sf, &qn.cf);
      sin_cos_near4(&qn.psi, &q0.psi, &q0.ss, &q0.cs, live, &qn.ss, &qn.cs);
      qn.dsf = qn.cf * qn.dphi;
      qn.dcf = -qn.sf * qn.dphi;
      qn.dss = qn.cs * dpsi;
      single_eval4(m, str, &qn, &y0, &y1, &R0v, &R1v, J, sv);
      /* rnorm */
      v4 r = MC_MAX_NN4(zero, ABS4(R0v));
      r = MC_MAX_NN4(r, G2 * ABS4(R1v));
      const l4 rf = MC_FINITE4(r);
      const v4 nr = SEL4(rf, r / SEL4(rf, tolf, one), ((v4){INFINITY, INFINITY, INFINITY, INFINITY}));
      const l4 nok = MC_CMP4(nr, <=, one);
      const int conv = act & mask_bits(&nok);
      ok |= conv;
      act &= ~conv;
      const v4 half = 0.5 * prev;
      const l4 nf = MC_FINITE4(nr), ngrow = MC_CMP4(nr, >, half);
      int stop = ~mask_bits(&nf);
      if (it >= 3) stop |= mask_bits(&ngrow);
      const v4 det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
      const l4 dok = MC_CMP4(det, !=, zero) & MC_FINITE4(det), dneg = MC_CMP4(det * J[0][0], <=, zero);
      stop |= ~mask_bits(&dok) | mask_bits(&dneg);
      act &= ~stop;
      if (!act) break;
      const l4 an = mpmc_lane_mask[act];
      const v4 dets = SEL4(an, det, one);
      y0 = SEL4(an, y0 + (-R0v * J[1][1] + R1v * J[0][1]) / dets, y0);
      y1 = SEL4(an, y1 + (-R1v * J[0][0] + R0v * J[1][0]) / dets, y1);
      prev = SEL4(an, nr, prev);
      for (int l = 0; l < 4; ++l) iters[l] += act >> l & 1;
    }
    for (int l = 0; l < 4; ++l)
      if (ok >> l & 1) info[l].newton_iters += iters[l];
    qv = qn;
    R0k = R0v;
  }
  for (int l = 0; l < 4; ++l) {
    if (!(live >> l & 1)) continue;
    y[l][0] = y0[l], y[l][1] = y1[l], y[l][2] = y[l][3] = 0.0;
    for (int k = 0; k < 3; ++k) s[l][k] = sv[k][l];
    R0[l] = R0k[l];
    if (!(ok >> l & 1)) {
      fs[l] = 2;
      continue;
    }
    mc_mat *a = &q[l];
    if (perfect)
      *a = P[l].S.q0;
    else { /* mat_eval's other fields at the lane's e; the derivatives 0 (single_solve) */
      a->e = qv.e[l], a->phi = qv.phi[l], a->psi = qv.psi[l], a->c = qv.c[l];
      a->sf = qv.sf[l], a->cf = qv.cf[l], a->ss = qv.ss[l], a->cs = qv.cs[l];
      a->dc = a->dphi = a->dsf = a->dcf = a->dss = a->deta = a->dxi = a->detab = a->dst = 0.0;
      a->eta = a->xi = a->etab = 0.0;
      a->st = m->sigma_t;
      a->st_apex = 0;
      double apex = INFINITY;
      if (a->sf > 0.0) {
        const double isf = 1.0 / a->sf;
        apex = a->c * a->cf * isf;
      }
      if (!(a->st < apex)) {
        a->st = apex;
        a->st_apex = isfinite(apex);
      }
    }
    fs[l] = admissible(&P[l].S, y[l], s[l], a) ? 0 : 1;
  }
}

/**
 * @brief mpmc_mc_update of four points at once (return_mc.h): lane l of the block is point
 * F[l], be[l], eps_p[l], tau[l], J_out[l], info[l], err[l] (its return value), l < n <= 4.
 * The push-forward, the series Hencky strain, the elastic check's bounds (and Mohr-Coulomb's
 * softened material for it, check_mat4), the closed-form eigen-decomposition, Mohr-Coulomb's
 * main-plane return (main_plane4) and the recomposition of b_e and tau run as batch4.h
 * vectors, so the four points' latency chains (square roots, divisions) overlap; the elastic
 * check's principal stresses where its bounds decide nothing, principal's set-up and its
 * other regions per point.  Every lane takes mpmc_mc_update's operations (the series at its
 * own degree, the branches as masks, libm per lane), so each point gets its results to the
 * bit but for the sign of a zero (t414).  Also compiled for x86-64-v3
 * (mpmc_mc_update4_avx2, mpmc_mc_update4_for).
 */
void MPMC_ISA(mpmc_mc_update4)(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, int n,
                               double F[][3][3], double be[][6], double *eps_p, double tau[][6],
                               double *J_out, mpmc_mc_info *info, int *err) {
  v4 Fv[9], bv[6], bt[6], eps[6];
  l4 sm = {0, 0, 0, 0}, sfail, eigm = {0, 0, 0, 0};
  for (int l = 0; l < 4; ++l) {
    if (l < n) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Fv[3 * i + j][l] = F[l][i][j];
      for (int k = 0; k < 6; ++k) bv[k][l] = be[l][k];
      /* elastic_fast's lanes: those mpmc_mc_update hands to it */
      sm[l] = -(long long)(pre->valid && eps_p[l] >= 0.0 && isfinite(eps_p[l]));
    } else { /* the identity: a finite dummy */
      for (int k = 0; k < 9; ++k) Fv[k][l] = (k % 4 == 0);
      for (int k = 0; k < 6; ++k) bv[k][l] = k < 3;
    }
  }
  push_forward4(Fv, bv, bt);
  sym_log_series4_lanes(bt, &sm, eps, &sfail);
  /* elastic_check's steps four lanes at a time (lanes ck): the material per lane, the
   * deviator, the bounds as vectors, the principal stresses from the invariants per lane
   * where they decide nothing */
  const int mc = pre->m.surface == MPMC_MC_MOHR_COULOMB;
  const int ck = mask_bits(&sm) & ~mask_bits(&sfail);
  mc_point P[4]; /* principal's points, their material at eps_p (P[l].S.q0) from the check */
  int elastic = 0;
  v4 sv[6], pv, trv;
  if (ck) {
    const mpmc_mc_param *m = &pre->m;
    v4 c[5];
    int soft = 0; /* Mohr-Coulomb's lanes with a softened material: check_mat4 */
    for (int l = 0; l < 4; ++l) {
      double cl[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
      if (mc && (ck >> l & 1) && !(pre->perfect || eps_p[l] == 0.0))
        soft |= 1 << l;
      else if (ck >> l & 1)
        check_mat(pre, eps_p[l], &P[l].S.q0, cl);
      for (int i = 0; i < 5; ++i) c[i][l] = cl[i];
    }
    if (soft) check_mat4(pre, eps_p, soft, P, c);
    const v4 sf = c[0], k = c[1], eta = c[2], gmax = c[3], st = c[4];
    const l4 ckm = mpmc_lane_mask[ck];
    const v4 zero = {0.0, 0.0, 0.0, 0.0};
    v4 e[6];
    for (int i = 0; i < 6; ++i) e[i] = SEL4(ckm, eps[i], zero); /* others' are not formed */
    trv = e[0] + e[1] + e[2];
    const double G2 = 2.0 * m->G;
    pv = m->K * trv;
    for (int i = 0; i < 3; ++i) e[i] -= trv / 3.0;
    for (int i = 0; i < 6; ++i) sv[i] = G2 * e[i];
    v4 j2, rj;
    norm2_4(sv, &j2);
    j2 = 0.5 * j2;
    sqrt4(&j2, &rj);
    const v4 margin = 1e-6 * (ABS4(pv) + rj + k);
    const double r3 = 1.7320508075688772;
    int ok_f, ok_t, open = 0;
    if (mc) {
      ok_f = mask_bits(&CMP4(2.0 * rj * gmax + 2.0 * pv * sf - k, <, -margin));
      /* plastic for sure by the lower bound */
      const int pl = mask_bits(&CMP4(rj * (r3 - sf / r3) + 2.0 * pv * sf - k, >, margin));
      open = ck & ~ok_f & ~pl;
    } else
      ok_f = mask_bits(&CMP4(rj + eta * pv - k, <, -margin));
    ok_t = mask_bits(&CMP4(pv + 2.0 * rj / r3, <, st - margin));
    elastic = ck & ok_f & ok_t;
    /* the lanes the bounds leave open: those of ok_f with ok_t open (either model), and
     * Mohr-Coulomb's between its bounds */
    open = (open | (ck & ok_f)) & ~elastic;
    for (int l = 0; l < 4; ++l) {
      if (!(open >> l & 1)) continue;
      const double sl[6] = {sv[0][l], sv[1][l], sv[2][l], sv[3][l], sv[4][l], sv[5][l]};
      if (check_trig(sl, j2[l], rj[l], pv[l], sf[l], k[l], st[l], margin[l], ok_f >> l & 1,
                     ok_t >> l & 1))
        elastic |= 1 << l;
    }
  }
  if (elastic) { /* b_e as pushed forward, tau = s + p I, J = exp(tr) */
    v4 tv[6];
    for (int i = 0; i < 6; ++i) tv[i] = i < 3 ? sv[i] + pv : sv[i];
    if (elastic == 15 && n == 4) {
      store_rows6(bt, be[0]);
      store_rows6(tv, tau[0]);
    } else
      for (int l = 0; l < 4; ++l)
        if (elastic >> l & 1)
          for (int i = 0; i < 6; ++i) {
            be[l][i] = bt[i][l];
            tau[l][i] = tv[i][l];
          }
    for (int l = 0; l < 4; ++l)
      if (elastic >> l & 1) {
        J_out[l] = exp(trv[l]);
        err[l] = MPMC_SUCCESS;
        if (info) memset(&info[l], 0, sizeof info[l]);
      }
  }
  for (int l = 0; l < n; ++l) {
    if (elastic >> l & 1) continue;
    double b[6], e[6];
    mpmc_mc_info *inf = info ? &info[l] : NULL;
    for (int k = 0; k < 6; ++k) b[k] = bt[k][l];
    if (!(ck >> l & 1)) { /* beyond the series, or not for elastic_fast: the eigen path */
      err[l] = return_eig(ws, solver, &pre->m, b, NULL, be[l], &eps_p[l], tau[l], &J_out[l],
                          inf, NULL);
      continue;
    }
    err[l] = MPMC_SUCCESS;
    for (int k = 0; k < 6; ++k) e[k] = eps[k][l];
    if (!mc && !dp_radial(ws, solver, pre, b, e, &P[l].S.q0, be[l], &eps_p[l], tau[l], &J_out[l], inf))
      continue;
    eigm[l] = -1;
  }
  if (!mask_bits(&eigm)) return;
  v4 lam[3], Q[9];
  l4 fb;
  sym3_eig_closed4(eps, &eigm, lam, Q, &fb);
  /* the principal return per lane (return_decomposed's), its strains and stresses e, t:
   * principal's set-up per lane, Mohr-Coulomb's main plane for the lanes that try it four at
   * a time (main_plane4), the other regions per lane */
  v4 ev[3], tv[3];
  double epn[4], el[4][3], tl[4][3];
  mpmc_mc_info loc[4];
  int done = 0, plane = 0, rest = 0;
  for (int bits = mask_bits(&eigm), l = 0; bits; bits >>= 1, ++l) {
    if (!(bits & 1)) continue;
    if (fb[l]) { /* a special case of the closed form: its scalar code */
      double e[6], lm[3], Ql[3][3];
      for (int k = 0; k < 6; ++k) e[k] = eps[k][l];
      mpmc_sym3_eig_closed(e, lm, Ql);
      for (int a = 0; a < 3; ++a) {
        lam[a][l] = lm[a];
        for (int i = 0; i < 3; ++i) Q[3 * i + a][l] = Ql[i][a];
      }
    }
    const double etr[3] = {lam[0][l], lam[1][l], lam[2][l]};
    mpmc_mc_info *inf = info ? &info[l] : &loc[l];
    memset(inf, 0, sizeof *inf);
    epn[l] = eps_p[l];
    int dn;
    err[l] = principal_begin(&pre->m, etr, &epn[l], el[l], tl[l], inf, &P[l].S.q0, &P[l], &dn);
    if (err[l]) continue;
    if (dn)
      done |= 1 << l;
    else if (mc && (P[l].perfect || solver == MPMC_SOLVER_AUTO))
      plane |= 1 << l;
    else
      rest |= 1 << l;
  }
  if (plane) {
    double y[4][MC_NMAX], sl[4][3], R0[4];
    mc_mat q[4];
    int fs[4];
    if (plane & (plane - 1)) /* two lanes or more */
      main_plane4(P, plane, info ? info : loc, y, sl, q, R0, fs);
    else
      for (int l = 0; l < 4; ++l)
        if (plane >> l & 1) {
          for (int i = 0; i < MC_NMAX; ++i) y[l][i] = 0.0;
          R0[l] = 0.0;
          fs[l] = single_solve(&P[l].S, P[l].perfect, y[l], sl[l], &q[l], &R0[l],
                               info ? &info[l] : &loc[l]);
        }
    for (int l = 0; l < 4; ++l) {
      if (!(plane >> l & 1)) continue;
      err[l] = principal_end(ws, solver, &pre->m, &epn[l], el[l], tl[l], info ? &info[l] : &loc[l],
                             &P[l], fs[l], y[l], sl[l], &q[l], R0[l]);
      if (!err[l]) done |= 1 << l;
    }
  }
  for (int l = 0; l < 4; ++l) {
    if (!(rest >> l & 1)) continue;
    err[l] = principal_rest(ws, solver, &pre->m, &epn[l], el[l], tl[l], info ? &info[l] : &loc[l],
                            &P[l]);
    if (!err[l]) done |= 1 << l;
  }
  for (int l = 0; l < 4; ++l) /* 0 in the lanes not done */
    for (int a = 0; a < 3; ++a) {
      ev[a][l] = done >> l & 1 ? el[l][a] : 0.0;
      tv[a][l] = done >> l & 1 ? tl[l][a] : 0.0;
    }
  if (!done) return;
  /* return_decomposed's recomposition, its operations lane by lane: b_e's eigenvalues
   * q_a.b q_a exp(2 (eps_a - eps_tr,a)) (libm's exp(2 eps_a) beyond the polynomial), b_e and
   * tau from them and Q, J */
  const l4 dm = mpmc_lane_mask[done];
  v4 lb[3], bev[6], tauv[6], Jv;
  for (int a = 0; a < 3; ++a) {
    const v4 etr = SEL4(dm, lam[a], ev[a]); /* d = 0 in the other lanes */
    const v4 d = 2.0 * (etr - ev[a]), ad = ABS4(d);
    const v4 x = Q[a], y = Q[3 + a], z = Q[6 + a];
    const v4 lt = x * (bt[0] * x + bt[5] * y + bt[4] * z) + y * (bt[5] * x + bt[1] * y + bt[3] * z) +
                  z * (bt[4] * x + bt[3] * y + bt[2] * z);
    lb[a] = lt * MPMC_RM_EXP_NEG_POLY(d);
    const int big = done & ~mask_bits(&CMP4(ad, <=, ((v4){MPMC_RM_EXP_SMALL, MPMC_RM_EXP_SMALL,
                                                          MPMC_RM_EXP_SMALL, MPMC_RM_EXP_SMALL})));
    for (int l = 0; l < 4; ++l)
      if (big >> l & 1) lb[a][l] = exp(2.0 * ev[a][l]);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const int k = mpmc_voigt(i, j);
      bev[k] = lb[0] * Q[3 * i] * Q[3 * j] + lb[1] * Q[3 * i + 1] * Q[3 * j + 1] +
               lb[2] * Q[3 * i + 2] * Q[3 * j + 2];
      tauv[k] = tv[0] * Q[3 * i] * Q[3 * j] + tv[1] * Q[3 * i + 1] * Q[3 * j + 1] +
                tv[2] * Q[3 * i + 2] * Q[3 * j + 2];
    }
  {
    const v4 etr0 = SEL4(dm, lam[0], ev[0]), etr1 = SEL4(dm, lam[1], ev[1]),
             etr2 = SEL4(dm, lam[2], ev[2]);
    const v4 d = (etr0 + etr1 + etr2) - (ev[0] + ev[1] + ev[2]), ad = ABS4(d);
    v4 det, sq;
    det_sym4(bt, &det);
    det = SEL4(dm, det, ((v4){1.0, 1.0, 1.0, 1.0}));
    sqrt4(&det, &sq);
    Jv = sq * MPMC_RM_EXP_NEG_POLY(d);
    const int big = done & ~mask_bits(&CMP4(ad, <=, ((v4){MPMC_RM_EXP_SMALL, MPMC_RM_EXP_SMALL,
                                                          MPMC_RM_EXP_SMALL, MPMC_RM_EXP_SMALL})));
    for (int l = 0; l < 4; ++l)
      if (big >> l & 1) Jv[l] = exp(ev[0][l] + ev[1][l] + ev[2][l]);
  }
  if (done == 15 && n == 4) {
    store_rows6(bev, be[0]);
    store_rows6(tauv, tau[0]);
    for (int l = 0; l < 4; ++l) {
      J_out[l] = Jv[l];
      eps_p[l] = epn[l];
    }
    return;
  }
  for (int l = 0; l < 4; ++l) {
    if (!(done >> l & 1)) continue;
    for (int k = 0; k < 6; ++k) {
      be[l][k] = bev[k][l];
      tau[l][k] = tauv[k][l];
    }
    J_out[l] = Jv[l];
    eps_p[l] = epn[l];
  }
}

#if !defined(MPMC_ISA_AVX2)
/**
 * @brief The frictional return map of one point in tensor form (return_mc.h): mpmc_mc_update
 * with the material prepared here (for the tests; a material's update prepares it once).
 */
int mpmc_mc_return_map(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, double F[3][3],
                       double *be, double *eps_p, double *tau, double *J_out,
                       mpmc_mc_info *info) {
  mpmc_mc_pre pre;
  mpmc_mc_prepare(m, &pre);
  return mpmc_mc_update(ws, solver, &pre, F, be, eps_p, tau, J_out, info);
}

/**
 * @brief The block update for a sim's kernel set (return_mc.h): mpmc_mc_update4 compiled for
 * x86-64-v3 (AVX2, no contraction: the same bits) where the build carries it, the processor
 * runs it and the set is not the baseline; else the baseline's.
 */
mpmc_mc_update4_fn mpmc_mc_update4_for(int kernels) {
#if defined(MPMC_HAVE_AVX2_KERNELS)
  if (kernels != MPMC_KERNELS_BASELINE && mpmc_kernels_avx2_available())
    return mpmc_mc_update4_avx2;
#else
  (void)kernels;
#endif
  return mpmc_mc_update4;
}

/**
 * @brief Strength reduction by factor (the SRM of slope stability): c_p, c_r, sigma_t
 * divided by it, and tan of phi_p, phi_r, psi_p, psi_r.
 */
void mpmc_mc_reduce(mpmc_mc_param *m, double factor) {
  m->c_p /= factor;
  m->c_r /= factor;
  m->sigma_t /= factor;
  m->phi_p = atan(tan(m->phi_p) / factor);
  m->phi_r = atan(tan(m->phi_r) / factor);
  m->psi_p = atan(tan(m->psi_p) / factor);
  m->psi_r = atan(tan(m->psi_r) / factor);
}
#endif
