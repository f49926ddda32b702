/* Blocks of four points in vectors of four doubles, lanes the points (points 4k .. 4k + 3):
 * the loads and stores between the points' rows and such vectors, lane masks, and the
 * arithmetic that the batched stress updates share (stress_j2.c, stress_blocks.c; kernel
 * files, compiled once per instruction set: mpmc_impl.h, MPMC_ISA). */
#ifndef MPMC_BATCH4_H
#define MPMC_BATCH4_H

#include <math.h>

#include "basis.h"
#include "linalg.h"
#include "mpmc_impl.h"
#if defined(__AVX__)
#include <immintrin.h>
#endif

typedef double v4 __attribute__((vector_size(4 * sizeof(double))));
typedef double v4u __attribute__((vector_size(4 * sizeof(double)), aligned(8), may_alias));
typedef double v2u __attribute__((vector_size(2 * sizeof(double)), aligned(8), may_alias));
typedef long long l4 __attribute__((vector_size(4 * sizeof(long long))));

/* sqrt per lane (through pointers: vectors by value would change the baseline build's ABI) */
static inline void sqrt4(const v4 *x, v4 *r) {
#if defined(__AVX__)
  *r = (v4)_mm256_sqrt_pd((__m256d)*x);
#else
  for (int l = 0; l < 4; ++l) (*r)[l] = sqrt((*x)[l]);
#endif
}

/* v[k][l] = src[w l + k], k < 8: the first eight of four points' rows of w >= 8 doubles */
static inline void load_rows8(const double *src, int w, v4 *v) {
  v4 r[4];
  for (int l = 0; l < 4; ++l) r[l] = *(const v4u *)(src + w * l);
  mpmc_transpose4(r, v);
  for (int l = 0; l < 4; ++l) r[l] = *(const v4u *)(src + w * l + 4);
  mpmc_transpose4(r, v + 4);
}

/* v[k][l] = src[6 l + k]: four points' rows of six (store_rows6's inverse) */
static inline void load_rows6(const double *src, v4 *v) {
  v4 r[4];
  for (int l = 0; l < 4; ++l) r[l] = *(const v4u *)(src + 6 * l);
  mpmc_transpose4(r, v);
  const v4 x = {src[4], src[5], src[16], src[17]}, y = {src[10], src[11], src[22], src[23]};
  v[4] = __builtin_shuffle(x, y, (l4){0, 4, 2, 6});
  v[5] = __builtin_shuffle(x, y, (l4){1, 5, 3, 7});
}

/* The six components of four points, v[k][l], stored as the points' rows of six at dst
 * (dst + 6 l: point l's), by a transpose and two shuffles instead of 24 lane extractions */
static inline void store_rows6(const v4 *v, double *dst) {
  v4 r[4];
  mpmc_transpose4(v, r);
  const v4 t0 = __builtin_shuffle(v[4], v[5], (l4){0, 4, 2, 6}),
           t1 = __builtin_shuffle(v[4], v[5], (l4){1, 5, 3, 7});
  for (int l = 0; l < 4; ++l) *(v4u *)(dst + 6 * l) = r[l];
  *(v2u *)(dst + 4) = (v2u){t0[0], t0[1]};
  *(v2u *)(dst + 10) = (v2u){t1[0], t1[1]};
  *(v2u *)(dst + 16) = (v2u){t0[2], t0[3]};
  *(v2u *)(dst + 22) = (v2u){t1[2], t1[3]};
}

/* F[3 i + j][l] = dF-bar_ij = sc[l] dF_ij of the block's four points, their dF (dim x dim,
 * row-major) at f; in 2D the rest of the identity.  With F-bar's gather deferred, sc holds
 * its factors (stress_j2.c), else ones. */
static inline void load_dF4(const int d, const double *f, const v4 *scp, v4 *F) {
  const v4 sc = *scp;
  if (d == 3) {
    load_rows8(f, 9, F);
    F[8] = (v4){f[8], f[17], f[26], f[35]};
    for (int k = 0; k < 9; ++k) F[k] *= sc;
  } else { /* dF's 2 x 2 rows of four points, transposed: components xx, xy, yx, yy */
    v4 r[4], c[4];
    for (int l = 0; l < 4; ++l) r[l] = *(const v4u *)(f + 4 * l);
    mpmc_transpose4(r, c);
    for (int k = 0; k < 9; ++k) {
      const int i = k / 3, j = k % 3;
      F[k] = i < 2 && j < 2 ? c[2 * i + j] * sc : (v4){i == j, i == j, i == j, i == j};
    }
  }
}

/* det b of symmetric b (Voigt) per lane, in mpmc_det_sym's order (linalg.h), so the same bits
 * per lane (through a pointer, as sqrt4) */
static inline void det_sym4(const v4 *b, v4 *r) { *r = MPMC_DET_SYM(b); }

/* blocks of four that the batched updates hand to a thread at a time (stress_j2.c,
 * stress_blocks.c), also the chunks of F-bar's deferred gather */
#define MPMC_BLOCK_CHUNK 64

/* F-bar's deferred gather (fbar.c, grid.fb_gather) of chunk ch's points of material id, of
 * nblk blocks over n points: their factors into sim->fb_scale, which the update reads as it
 * loads dF */
static inline void fbar_gather_chunk(struct mpmc_sim_s *sim, int id, int ch, int nblk, int n) {
  const int b0 = ch * MPMC_BLOCK_CHUNK;
  const int b1 = b0 + MPMC_BLOCK_CHUNK < nblk ? b0 + MPMC_BLOCK_CHUNK : nblk;
  const int c0 = 4 * b0, c1 = 4 * b1 < n ? 4 * b1 : n;
  MPMC_ISA(mpmc_fbar_gather_range)(sim, id, c0, c1, sim->fb_scale + c0); /* [q - c0] */
}

/* bt = F b F^T (Voigt) in mpmc_push_forward's order (linalg.h), so the same bits per lane:
 * T = F B, then T F^T's upper half */
static inline void push_forward4(const v4 *F, const v4 *b, v4 *bt) {
  const v4 B[3][3] = {{b[0], b[5], b[4]}, {b[5], b[1], b[3]}, {b[4], b[3], b[2]}};
  v4 T[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      T[i][j] = F[3 * i] * B[0][j] + F[3 * i + 1] * B[1][j] + F[3 * i + 2] * B[2][j];
  static const int vi[6] = {0, 1, 2, 1, 0, 0}, vj[6] = {0, 1, 2, 2, 2, 1};
  for (int k = 0; k < 6; ++k) {
    const int i = vi[k], j = vj[k];
    bt[k] = T[i][0] * F[3 * j] + T[i][1] * F[3 * j + 1] + T[i][2] * F[3 * j + 2];
  }
}

/* lanes of a where mask m is set, else of b; |a| per lane; the mask's lanes as bits */
#define SEL4(m, a, b) ((v4)(((m) & (l4)(a)) | (~(m) & (l4)(b))))
#define ABS4(a) ((v4)((l4)(a) & ~(l4)(v4){-0.0, -0.0, -0.0, -0.0}))
static inline int mask_bits(const l4 *m) {
#if defined(__AVX__)
  return _mm256_movemask_pd((__m256d)*m);
#else
  return (int)(((*m)[0] & 1) | ((*m)[1] & 2) | ((*m)[2] & 4) | ((*m)[3] & 8));
#endif
}
/* the largest lane of r among those of mask m (0 for none; r's lanes are >= 0 or NaN) */
static inline double max_lane(const v4 *r, const l4 *m) {
  const v4 zero = {0.0, 0.0, 0.0, 0.0}, v = SEL4(*m, *r, zero);
  double x = 0.0;
  for (int l = 0; l < 4; ++l) x = v[l] > x ? v[l] : x;
  return x;
}

/* c = a b for symmetric a, b (Voigt) that commute, as mpmc_sym3_mul */
static inline void sym_mul4(const v4 *a, const v4 *b, v4 *c) { MPMC_SYM3_MUL(v4, a, b, c); }

/* |s|^2 (Voigt, tensor shear components), as mpmc_sym3_norm2 (through a pointer: a v4
 * returned by value would change the baseline build's ABI) */
static inline void norm2_4(const v4 *s, v4 *r) {
  *r = s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
}

/* The block's Hencky strain eps = 1/2 ln b (the trial b of Hencky-J2, the b of Hencky) by
 * linalg.h's series, mpmc_sym3_log_series' operations lane by lane (its macros
 * MPMC_SYM3_CAYLEY and MPMC_SYM3_ATANH_HORNER), at the degree the largest active lane (mask
 * am) needs.  fail: the lanes whose
 * strain the series cannot take (|Z|^2 above the table, or not finite). */
static inline void sym_log_series4(const v4 *b, const l4 *am, v4 *eps, l4 *fail) {
  const double *rho2_max = mpmc_atanh_rho2_max;
  v4 z[6];
  MPMC_SYM3_CAYLEY(v4, sym_mul4, b, z);
  v4 r2;
  norm2_4(z, &r2);
  /* fail: |Z|^2 beyond the table or not finite; the degree: that of the largest other lane */
  const l4 ok = *am & (r2 <= rho2_max[10]);
  *fail = *am & ~ok;
  int n = 1;
  const double rmax = max_lane(&r2, &ok);
  while (rmax > rho2_max[n]) ++n;
  if (n == 1) {
    for (int k = 0; k < 6; ++k) eps[k] = z[k];
    return;
  }
  MPMC_SYM3_ATANH_HORNER(v4, sym_mul4, z, n, eps);
}

#endif
