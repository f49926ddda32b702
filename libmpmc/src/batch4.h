/* Blocks of four points in vectors of four doubles, lanes the points (points 4k .. 4k + 3):
 * the loads and stores between the points' rows and such vectors, and the arithmetic that
 * the batched stress updates share (stress_j2.c, stress_blocks.c; kernel files, compiled
 * once per instruction set: mpmc_impl.h, MPMC_ISA). */
#ifndef MPMC_BATCH4_H
#define MPMC_BATCH4_H

#include <math.h>

#include "basis.h"
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

#endif
