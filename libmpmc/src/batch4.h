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

/* F-bar's deferred gather (fbar.c, sim->fb.deferred) of chunk ch's points of material id, of
 * nblk blocks over n points: their factors into sim->fb.scale, which the update reads as it
 * loads dF */
static inline void fbar_gather_chunk(struct mpmc_sim_s *sim, int id, int ch, int nblk, int n) {
  const int b0 = ch * MPMC_BLOCK_CHUNK;
  const int b1 = b0 + MPMC_BLOCK_CHUNK < nblk ? b0 + MPMC_BLOCK_CHUNK : nblk;
  const int c0 = 4 * b0, c1 = 4 * b1 < n ? 4 * b1 : n;
  MPMC_ISA(mpmc_fbar_gather_range)(sim, id, c0, c1, sim->fb.scale + c0); /* [q - c0] */
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

/* The series' start for a block: Z = (b - I)(b + I)^-1 (MPMC_SYM3_CAYLEY) and |Z|^2. */
static inline void cayley4(const v4 *b, v4 *z, v4 *r2) {
  MPMC_SYM3_CAYLEY(v4, sym_mul4, b, z);
  norm2_4(z, r2);
}

/* The block's Hencky strain eps = 1/2 ln b (the trial b of Hencky-J2, the b of Hencky) by
 * linalg.h's series, mpmc_sym3_log_series' operations lane by lane (its macros
 * MPMC_SYM3_CAYLEY and MPMC_SYM3_ATANH_HORNER), at the degree the largest active lane (mask
 * am) needs.  fail: the lanes whose
 * strain the series cannot take (|Z|^2 above the table, or not finite). */
static inline void sym_log_series4(const v4 *b, const l4 *am, v4 *eps, l4 *fail) {
  const double *rho2_max = mpmc_atanh_rho2_max;
  v4 z[6], r2;
  cayley4(b, z, &r2);
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

/* The mask of the lanes set in bits (bit l: lane l), and the bits of a lane-wise condition
 * evaluated on scalars: on a baseline (SSE2) build GCC lowers the compares of four-lane
 * vectors to scalar compares, conditional moves and a store and reload of the mask (a
 * store-forwarding stall per mask); a mask loaded from this table costs one load. */
static const l4 mpmc_lane_mask[16] = {
    {0, 0, 0, 0},    {-1, 0, 0, 0},    {0, -1, 0, 0},    {-1, -1, 0, 0},
    {0, 0, -1, 0},   {-1, 0, -1, 0},   {0, -1, -1, 0},   {-1, -1, -1, 0},
    {0, 0, 0, -1},   {-1, 0, 0, -1},   {0, -1, 0, -1},   {-1, -1, 0, -1},
    {0, 0, -1, -1},  {-1, 0, -1, -1},  {0, -1, -1, -1},  {-1, -1, -1, -1}};
static inline int bits4_of(const int c0, const int c1, const int c2, const int c3) {
  return (c0 != 0) | (c1 != 0) << 1 | (c2 != 0) << 2 | (c3 != 0) << 3;
}
/* the lanes where a > b, a >= b, a != b, a == b (NaN: false but for !=) as masks */
#define CMP4(a, op, b)                                                                     \
  mpmc_lane_mask[bits4_of((a)[0] op (b)[0], (a)[1] op (b)[1], (a)[2] op (b)[2],          \
                          (a)[3] op (b)[3])]

/* sym_log_series4 with each lane at its own degree, so that every lane gets
 * mpmc_sym3_log_series' bits (the frictional block update, return_mc.c, whose elastic check
 * and eigen path must decide as the point update does): Horner from the largest lane's top
 * term, a lane's coefficients 0 above its own top term, so its p stays 0 until there, where
 * W 0 + c I = c I starts it as the scalar c W + c' I does (the products by 0 add only zeros:
 * the same bits but for the sign of a zero).  A lane of one term gets Z I = Z.  eps as
 * sym_log_series4's; fail: the lanes of am whose |Z|^2 is beyond the table or not finite
 * (their eps is not formed). */
static inline void sym_log_series4_lanes(const v4 *b, const l4 *am, v4 *eps, l4 *fail) {
  const double *rho2_max = mpmc_atanh_rho2_max;
  v4 z[6], r2;
  cayley4(b, z, &r2);
  int deg[4], n = 1, fbits = 0;
  const int abits = mask_bits(am);
  for (int l = 0; l < 4; ++l) { /* each lane's number of terms, as mpmc_sym3_log_series' */
    deg[l] = 0;
    if (!(abits >> l & 1)) continue;
    if (!(r2[l] <= rho2_max[10])) {
      fbits |= 1 << l;
      continue;
    }
    int k = 1;
    while (r2[l] > rho2_max[k]) ++k;
    deg[l] = k;
    n = k > n ? k : n;
  }
  *fail = mpmc_lane_mask[fbits];
  if (n == 1) {
    for (int k = 0; k < 6; ++k) eps[k] = z[k];
    return;
  }
  v4 w[6], p[6];
  sym_mul4(z, z, w);
  for (int k = 0; k < 6; ++k) p[k] = (v4){0.0, 0.0, 0.0, 0.0};
  for (int j = n - 1; j >= 0; --j) {
    /* c_j in the lanes of degree > j, 0 in the others (a mask from the table: a vector
     * built from four scalars waits on their stores) */
    const double cj = mpmc_atanh_c[j];
    const int live = bits4_of(j < deg[0], j < deg[1], j < deg[2], j < deg[3]);
    const v4 c = (v4)(mpmc_lane_mask[live] & (l4)(v4){cj, cj, cj, cj});
    sym_mul4(w, p, p);
    for (int k = 0; k < 3; ++k) p[k] += c;
  }
  sym_mul4(z, p, eps);
}

/* mpmc_sym3_eig_closed of four symmetric tensors (lanes of s, Voigt), its operations lane by
 * lane in vectors and its branches as masks, so every lane gets its bits (acos and cos by
 * libm per lane).  lam[3] the eigenvalues, Q[3 i + a] the eigenvectors' components.  The
 * lanes of am that take one of its special cases (diagonal, a deviator too small or too
 * large, not finite) are not formed: *fb, for mpmc_sym3_eig_closed itself. */
static inline void sym3_eig_closed4(const v4 *s, const l4 *am, v4 *lam, v4 *Q, l4 *fb) {
  const v4 zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0};
  const v4 m = (s[0] + s[1] + s[2]) / 3.0;
  const v4 B[3][3] = {{s[0] - m, s[5], s[4]}, {s[5], s[1] - m, s[3]}, {s[4], s[3], s[2] - m}};
  const v4 p2 = (B[0][0] * B[0][0] + B[1][1] * B[1][1] + B[2][2] * B[2][2] +
                 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])) / 6.0;
  const v4 tiny = {1e-280, 1e-280, 1e-280, 1e-280}, huge = {1e280, 1e280, 1e280, 1e280};
  const v4 d2 = p2 - p2, dm = m - m;
  const l4 diag = CMP4(s[3], ==, zero) & CMP4(s[4], ==, zero) & CMP4(s[5], ==, zero) &
                  CMP4(d2, ==, zero);
  l4 ok = *am & ~diag & CMP4(p2, >=, tiny) & CMP4(p2, <=, huge) & CMP4(dm, ==, zero);
  const v4 p2s = SEL4(ok, p2, one); /* finite dummies in the other lanes */
  v4 pp;
  sqrt4(&p2s, &pp);
  const v4 ip = 1.0 / pp;
  v4 Bn[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Bn[i][j] = SEL4(ok, B[i][j] * ip, zero);
  const v4 r = 0.5 * (Bn[0][0] * (Bn[1][1] * Bn[2][2] - Bn[1][2] * Bn[2][1]) -
                      Bn[0][1] * (Bn[1][0] * Bn[2][2] - Bn[1][2] * Bn[2][0]) +
                      Bn[0][2] * (Bn[1][0] * Bn[2][1] - Bn[1][1] * Bn[2][0]));
  const double pi3 = 1.0471975511965976; /* pi/3 */
  v4 li = zero;
  for (int bits = mask_bits(&ok), l = 0; bits; bits >>= 1, ++l) {
    if (!(bits & 1)) continue;
    const double rl = r[l];
    const double phi = acos(rl >= 1.0 ? 1.0 : rl <= -1.0 ? -1.0 : rl) / 3.0;
    li[l] = phi <= 0.5 * pi3 ? 2.0 * cos(phi) : 2.0 * cos(phi + 2.0 * pi3);
  }
  v4 C[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) C[i][j] = i == j ? Bn[i][j] - li : Bn[i][j];
  v4 x[3][3], n2[3];
  MPMC_SYM3_ROW_CROSSES(v4, C, x, n2);
  const l4 c01 = CMP4(n2[0], >=, n2[1]), c02 = CMP4(n2[0], >=, n2[2]),
           c12 = CMP4(n2[1], >=, n2[2]);
  const l4 k0 = c01 & c02, k1 = ~c01 & c12; /* else row pair 2 */
  v4 xb[3];
  for (int i = 0; i < 3; ++i) xb[i] = SEL4(k0, x[0][i], SEL4(k1, x[1][i], x[2][i]));
  const v4 nb = SEL4(k0, n2[0], SEL4(k1, n2[1], n2[2]));
  ok &= CMP4(nb, >, zero);
  *fb = *am & ~ok;
  const v4 nbs = SEL4(ok, nb, one);
  v4 iv;
  sqrt4(&nbs, &iv);
  iv = 1.0 / iv;
  const v4 v[3] = {xb[0] * iv, xb[1] * iv, xb[2] * iv};
  /* an orthonormal basis u, w of the complement of v */
  const v4 av0 = ABS4(v[0]), av1 = ABS4(v[1]);
  const l4 cu = CMP4(av0, >, av1);
  v4 den = SEL4(cu, v[0] * v[0] + v[2] * v[2], v[1] * v[1] + v[2] * v[2]), iu;
  den = SEL4(ok, den, one);
  sqrt4(&den, &iu);
  iu = 1.0 / iu;
  const v4 u[3] = {SEL4(cu, -v[2] * iu, zero), SEL4(cu, zero, v[2] * iu),
                   SEL4(cu, v[0] * iu, -v[1] * iu)};
  const v4 w[3] = {v[1] * u[2] - v[2] * u[1], v[2] * u[0] - v[0] * u[2],
                   v[0] * u[1] - v[1] * u[0]};
  v4 lv, a00, a11, a01;
  MPMC_SYM3_IN_BASIS(v4, B, v, u, w, lv, a00, a11, a01);
  /* the rotation of mpmc_sym3_eig where a01 != 0, else c = 1, sn = t = 0 */
  const l4 nz = ok & CMP4(a01, !=, zero);
  const v4 a01s = SEL4(nz, a01, one);
  const v4 theta = (a11 - a00) / (2.0 * a01s);
  v4 h = theta * theta + 1.0, sh, sc;
  sqrt4(&h, &sh);
  const v4 t = SEL4(nz, SEL4(CMP4(theta, >=, zero), one, -one) / (ABS4(theta) + sh), zero);
  h = t * t + 1.0;
  sqrt4(&h, &sc);
  const v4 c = SEL4(nz, 1.0 / sc, one), sn = SEL4(nz, t * c, zero);
  lam[0] = m + lv;
  lam[1] = m + (a00 - t * a01);
  lam[2] = m + (a11 + t * a01);
  for (int i = 0; i < 3; ++i) {
    Q[3 * i] = v[i];
    Q[3 * i + 1] = c * u[i] - sn * w[i];
    Q[3 * i + 2] = sn * u[i] + c * w[i];
  }
}

#endif
