/* The Neo-Hookean, Hencky and Newtonian stress updates (material_neo_hookean.c,
 * material_hencky.c, material_newtonian.c) over blocks of four points, one of the kernel
 * files compiled once per instruction set (mpmc_impl.h, MPMC_ISA):
 *   Neo-Hookean  b <- dF b dF^T,  J = sqrt(det b),  tau = mu (b - 1) + lambda ln J 1,
 *                sigma = tau / J  (plane strain: b_zz stays 1, dF embedded in 3 x 3);
 *   Hencky       b <- dF b dF^T,  eps = 1/2 ln b,  J = sqrt(det b),
 *                sigma = (K tr eps 1 + 2G dev eps) / J;
 *   Newtonian    sigma = K (J - 1) 1 + 2 mu dev(D),  D = sym(dF - 1) / dt, J the F-bar
 *                Jacobian when F-bar is on (the paper, section 4.3).
 * Four points of the material in a row (points 4k .. 4k + 3) go through them as vectors of
 * four doubles, lanes the points, with the operations of the point-by-point form in the same
 * order (batch4.h), so the same bits as one point alone in a set without contraction
 * (baseline, avx2: tests/t303, t413), but for the series: the Neo-Hookean's ln J by
 * mpmc_log_series' sum (linalg.h, within 2 ulp), to the number of terms that the block's
 * largest |J - 1| needs, and libm's log beyond its reach (|ln J| >~ 0.36); Hencky's ln b by
 * mpmc_sym3_log_series' to the degree of the block's largest strain (the terms beyond a
 * point's own degree are below its 2^-54 tolerance).  A block that holds another material's
 * points or the end of the arrays goes point by point.  The blocks are fixed by the index, so
 * the results do not depend on the thread count.  The updates keep the stress guard themselves
 * (ops->checks_stress: the lowest non-finite point into sim->scr.stress_bad, a pass over the
 * stresses less) and run F-bar's gather when the step leaves it to them (ops->gathers_fbar,
 * MPMC_BLOCKS). */
#include <limits.h>
#include <math.h>

#include "batch4.h"
#include "linalg.h"
#include "mpmc_impl.h"

/* the lowest point of the block q0 .. q0 + 3 whose stress s (lanes) is not finite
 * (mpmc_stress_finite's sum per lane), or INT_MAX */
static inline int block_guard(const v4 *s, int q0) {
  const v4 sum = s[0] + s[1] + s[2] + s[3] + s[4] + s[5], nf = sum - sum; /* 0 if finite */
  for (int l = 0; l < 4; ++l)
    if (!(nf[l] == 0.0)) return q0 + l;
  return INT_MAX;
}

/* The loop of the updates over material id's points: BLOCK (an expression of q0 and sc, the
 * lowest non-finite point of the block or INT_MAX) for four of them in a row, else POINT (of q
 * and s, 0 if its stress is not finite) one by one; the lowest non-finite point into
 * sim->scr.stress_bad.  sc: the block's F-bar factors of dF (sc[0..3]; NULL: none), s point q's
 * (1 for none).  With F-bar's gather left to the update (sim->fb.deferred, fbar.c) each thread
 * first gathers its chunks' points into sim->fb.scale (their factors; Jbar becomes Pi) and
 * then updates them, dF-bar = s dF formed as dF is loaded, as the Hencky-J2 blocks do
 * (stress_j2.c): the two loops' static schedules over the same chunks give a thread the same
 * points, so it reads only factors it wrote (nowait).  A macro, for the OpenMP region to see
 * BLOCK and POINT inlined (transfer.h, MPMC_KERNELS). */
#define MPMC_BLOCKS(sim, id, BLOCK, POINT)                                                   \
  do {                                                                                       \
    const int n_ = (sim)->p.n, nblk_ = (n_ + 3) / 4, *restrict m_ = (sim)->p.mat;            \
    const int nch_ = (nblk_ + MPMC_BLOCK_CHUNK - 1) / MPMC_BLOCK_CHUNK;                       \
    const int gather_ = (sim)->fb.deferred;                                                    \
    double *const fs_ = (sim)->fb.scale;                                                     \
    int first_nf_ = INT_MAX;                                                                 \
    _Pragma("omp parallel reduction(min : first_nf_) if (n_ > MPMC_OMP_MIN)")                \
    {                                                                                        \
      if (gather_) {                                                                         \
        _Pragma("omp for schedule(static) nowait")                                           \
        for (int ch_ = 0; ch_ < nch_; ++ch_) fbar_gather_chunk((sim), (id), ch_, nblk_, n_);  \
      }                                                                                      \
      _Pragma("omp for schedule(static)")                                                    \
      for (int ch_ = 0; ch_ < nch_; ++ch_) {                                                 \
        const int b0_ = MPMC_BLOCK_CHUNK * ch_;                                              \
        const int b1_ = b0_ + MPMC_BLOCK_CHUNK < nblk_ ? b0_ + MPMC_BLOCK_CHUNK : nblk_;     \
        for (int blk_ = b0_; blk_ < b1_; ++blk_) {                                           \
          const int q0 = 4 * blk_;                                                           \
          const double *const sc = gather_ ? fs_ + q0 : NULL;                                \
          if (q0 + 3 < n_ && m_[q0] == (id) && m_[q0 + 1] == (id) && m_[q0 + 2] == (id) &&   \
              m_[q0 + 3] == (id)) {                                                          \
            const int bad_ = (BLOCK);                                                        \
            first_nf_ = bad_ < first_nf_ ? bad_ : first_nf_;                                 \
          } else {                                                                           \
            for (int q = q0; q < q0 + 4 && q < n_; ++q) {                                    \
              if (m_[q] != (id)) continue; /* (its factor not gathered) */                   \
              const double s = gather_ ? fs_[q] : 1.0;                                       \
              if (!(POINT) && q < first_nf_) first_nf_ = q;                                  \
            }                                                                                \
          }                                                                                  \
        }                                                                                    \
      }                                                                                      \
    }                                                                                        \
    if (first_nf_ < (sim)->scr.stress_bad) (sim)->scr.stress_bad = first_nf_; /* stress_update.c */ \
  } while (0)

/* the block's factors (ones for none) */
static inline void block_scale(const double *sc, v4 *f) {
  *f = sc ? (v4) * (const v4u *)sc : (v4){1.0, 1.0, 1.0, 1.0};
}

/* point q's dF-bar = s dF, embedded in 3 x 3 (as fbar.c's scale_dF, then mpmc_embed) */
static inline void point_dF(const mpmc_particles *p, const int d, int q, double s, double F[3][3]) {
  const double *f = p->dF + (size_t)q * d * d;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F[i][j] = i < d && j < d ? f[i * d + j] * s : (double)(i == j);
}

/* ---- Neo-Hookean ---------------------------------------------------------------------- */

/* ln x per lane by mpmc_log_series' sum (linalg.h) to the number of terms that the lanes'
 * largest s^2 needs (the terms beyond a lane's own number are below its 2^-54 tolerance),
 * libm's log in a lane beyond the series' reach */
static inline void ln_series4(const v4 *xp, v4 *lnx) {
  const v4 x = *xp, s = (x - 1.0) / (x + 1.0), s2 = s * s;
  double s2max = 0.0;
  int out = 0;
  for (int l = 0; l < 4; ++l) {
    out |= !(s2[l] <= mpmc_atanh_rho2_max[10]) << l; /* also NaN */
    s2max = s2[l] > s2max && !(out >> l & 1) ? s2[l] : s2max;
  }
  int n = 1;
  while (s2max > mpmc_atanh_rho2_max[n]) ++n;
  v4 p = s2 * 0.0 + mpmc_atanh_c[n - 1];
  for (int k = n - 2; k >= 0; --k) p = p * s2 + mpmc_atanh_c[k];
  *lnx = 2.0 * (s * p);
  for (int l = 0; out; ++l, out >>= 1)
    if (out & 1) (*lnx)[l] = log(x[l]);
}

/* point q alone; returns 0 if its stress is not finite */
static inline int nh_point(mpmc_particles *p, const int d, double mu, double lam, double sc,
                           int q) {
  double F[3][3];
  point_dF(p, d, q, sc, F);
  double *b = p->be + (size_t)q * 6;
  mpmc_push_forward(F, b);
  const double J = sqrt(mpmc_det_sym(b)), inv_J = 1.0 / J;
  double lnJ;
  if (mpmc_log_series(J, &lnJ)) lnJ = log(J);
  double *s = p->stress + (size_t)q * 6;
  for (int k = 0; k < 6; ++k) {
    const double tau = mu * (b[k] - (k < 3)) + (k < 3 ? lam * lnJ : 0.0);
    s[k] = tau * inv_J;
  }
  return mpmc_stress_finite(s);
}

/* the four points q0 .. q0 + 3, all of the material, as vectors: nh_point's operations;
 * returns block_guard's point */
static inline int nh_block(mpmc_particles *p, const int d, double mu, double lam,
                           const double *sc, int q0) {
  const v4 one = {1.0, 1.0, 1.0, 1.0}, zero = {0.0, 0.0, 0.0, 0.0};
  v4 F[9], b[6], bt[6], s[6], f;
  block_scale(sc, &f);
  load_dF4(d, p->dF + (size_t)q0 * d * d, &f, F);
  double *be = p->be + (size_t)q0 * 6;
  load_rows6(be, b);
  push_forward4(F, b, bt);
  v4 det, J;
  det_sym4(bt, &det);
  sqrt4(&det, &J);
  v4 lnJ;
  ln_series4(&J, &lnJ);
  const v4 inv_J = 1.0 / J;
  for (int k = 0; k < 6; ++k)
    s[k] = (mu * (bt[k] - (k < 3 ? one : zero)) + (k < 3 ? lam * lnJ : zero)) * inv_J;
  store_rows6(bt, be);
  store_rows6(s, p->stress + (size_t)q0 * 6);
  return block_guard(s, q0);
}

/** The stress update of material id's points (Neo-Hookean: mat->G, mat->lambda). */
int MPMC_ISA(mpmc_nh_batch)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const double mu = mat->G, lam = mat->lambda;
  MPMC_BLOCKS(sim, id, nh_block(p, d, mu, lam, sc, q0), nh_point(p, d, mu, lam, s, q));
  return MPMC_SUCCESS;
}

/* ---- Hencky elasticity ---------------------------------------------------------------- */

/* point q alone (kl = K - 2G/3): b <- dF b dF^T, eps = 1/2 ln b by the series or, beyond its
 * reach, the eigen path (linalg.h), J = sqrt(det b) (= exp(tr eps)); returns 0 if its stress
 * is not finite */
static inline int hencky_point(mpmc_particles *p, const int d, double G2, double kl, double sc,
                               int q) {
  double F[3][3];
  point_dF(p, d, q, sc, F);
  double *b = p->be + (size_t)q * 6, *s = p->stress + (size_t)q * 6;
  mpmc_push_forward(F, b);
  double eps[6];
  if (mpmc_sym3_log_series(b, eps)) mpmc_sym3_log_eig(b, eps);
  const double tr = eps[0] + eps[1] + eps[2];
  const double inv_J = 1.0 / sqrt(mpmc_det_sym(b)), p0 = kl * tr;
  /* sigma = (K tr eps 1 + 2G dev eps) / J */
  for (int k = 0; k < 6; ++k) s[k] = G2 * eps[k] * inv_J;
  for (int k = 0; k < 3; ++k) s[k] += p0 * inv_J;
  return mpmc_stress_finite(s);
}

/* the four points q0 .. q0 + 3, all of the material, as vectors: hencky_point's operations,
 * the series to the degree of the block's largest strain (batch4.h, sym_log_series4); a block
 * with a strain beyond the series goes point by point from its unchanged inputs.  Returns
 * block_guard's point. */
static inline int hencky_block(mpmc_particles *p, const int d, double G2, double kl,
                               const double *sc, int q0) {
  const l4 all = {-1, -1, -1, -1};
  v4 F[9], b[6], bt[6], eps[6], s[6], f;
  l4 fail;
  block_scale(sc, &f);
  load_dF4(d, p->dF + (size_t)q0 * d * d, &f, F);
  double *be = p->be + (size_t)q0 * 6;
  load_rows6(be, b);
  push_forward4(F, b, bt);
  sym_log_series4(bt, &all, eps, &fail);
  if (mask_bits(&fail)) {
    int bad = INT_MAX;
    for (int q = q0 + 3; q >= q0; --q)
      if (!hencky_point(p, d, G2, kl, sc ? sc[q - q0] : 1.0, q)) bad = q;
    return bad;
  }
  const v4 tr = eps[0] + eps[1] + eps[2];
  v4 det, J;
  det_sym4(bt, &det);
  sqrt4(&det, &J);
  const v4 inv_J = 1.0 / J, p0 = kl * tr;
  for (int k = 0; k < 6; ++k) s[k] = G2 * eps[k] * inv_J;
  for (int k = 0; k < 3; ++k) s[k] += p0 * inv_J;
  store_rows6(bt, be);
  store_rows6(s, p->stress + (size_t)q0 * 6);
  return block_guard(s, q0);
}

/** The stress update of material id's points (Hencky: mat->K, mat->G). */
int MPMC_ISA(mpmc_hencky_batch)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                                double dt) {
  (void)dt;
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const double G2 = 2.0 * mat->G, kl = mat->K - G2 / 3.0;
  MPMC_BLOCKS(sim, id, hencky_block(p, d, G2, kl, sc, q0), hencky_point(p, d, G2, kl, s, q));
  return MPMC_SUCCESS;
}

/* ---- Newtonian fluid ------------------------------------------------------------------ */

/* s = pr 1 + mu2 dev D (trD = tr D / 3), Voigt, for scalars and vectors alike */
#define NEWTONIAN_STRESS(s, pr, mu2, D, trD)            \
  do {                                                  \
    (s)[0] = (pr) + (mu2) * ((D)[0][0] - (trD));        \
    (s)[1] = (pr) + (mu2) * ((D)[1][1] - (trD));        \
    (s)[2] = (pr) + (mu2) * ((D)[2][2] - (trD));        \
    (s)[3] = (mu2) * (D)[1][2];                         \
    (s)[4] = (mu2) * (D)[0][2];                         \
    (s)[5] = (mu2) * (D)[0][1];                         \
  } while (0)

/* point q alone (Jm: J or Jbar); returns 0 if its stress is not finite */
static inline int newtonian_point(mpmc_particles *p, const int d, double K, double mu2,
                                  double inv_dt, const double *Jm, double sc, int q) {
  double f[3][3], D[3][3] = {{0}};
  point_dF(p, d, q, sc, f);
  for (int a = 0; a < d; ++a)
    for (int b = 0; b < d; ++b) D[a][b] = 0.5 * (f[a][b] + f[b][a]) * inv_dt;
  for (int a = 0; a < d; ++a) D[a][a] -= inv_dt;
  const double trD = (D[0][0] + D[1][1] + D[2][2]) / 3.0;
  const double pr = K * (Jm[q] - 1.0);
  double *s = p->stress + (size_t)q * 6;
  NEWTONIAN_STRESS(s, pr, mu2, D, trD);
  return mpmc_stress_finite(s);
}

/* the four points q0 .. q0 + 3 as vectors: newtonian_point's operations; returns
 * block_guard's point */
static inline int newtonian_block(mpmc_particles *p, const int d, double K, double mu2,
                                  double inv_dt, const double *Jm, const double *sc, int q0) {
  const v4 zero = {0.0, 0.0, 0.0, 0.0};
  v4 F[9], D[3][3], s[6], f;
  block_scale(sc, &f);
  load_dF4(d, p->dF + (size_t)q0 * d * d, &f, F);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      D[a][b] = a < d && b < d ? 0.5 * (F[3 * a + b] + F[3 * b + a]) * inv_dt : zero;
  for (int a = 0; a < d; ++a) D[a][a] -= inv_dt;
  const v4 trD = (D[0][0] + D[1][1] + D[2][2]) / 3.0;
  const v4 pr = K * ((v4) * (const v4u *)(Jm + q0) - 1.0);
  NEWTONIAN_STRESS(s, pr, mu2, D, trD);
  store_rows6(s, p->stress + (size_t)q0 * 6);
  return block_guard(s, q0);
}

/** The stress update of material id's points (Newtonian fluid: mat->K, mat->mu). */
int MPMC_ISA(mpmc_newtonian_batch)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                                   double dt) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const double K = mat->K, mu2 = 2.0 * mat->mu, inv_dt = dt > 0 ? 1.0 / dt : 0.0;
  const double *Jm = sim->cfg.fbar ? p->Jbar : p->J;
  MPMC_BLOCKS(sim, id, newtonian_block(p, d, K, mu2, inv_dt, Jm, sc, q0),
              newtonian_point(p, d, K, mu2, inv_dt, Jm, s, q));
  return MPMC_SUCCESS;
}
