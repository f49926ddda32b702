/* Basis functions (Bardenhagen & Kober 2004; Steffen et al. 2008): 1D weights and
 * gradients, tensor products in 2D/3D.  Inline so that the transfer kernels, instantiated
 * per (dim, basis) with compile-time constants, fold the basis switch away. */
#ifndef MPMC_BASIS_H
#define MPMC_BASIS_H

#include <math.h>
#include <string.h>

#include "mpmc.h"
#if defined(__AVX__)
#include <immintrin.h>
#endif

#define MPMC_ALWAYS_INLINE static inline __attribute__((always_inline))
#define MPMC_MAX_STENCIL 4

/* floor(s) as an int for |s| < 2^31: with SSE4.1 (the AVX2 kernel sets) libm's floor,
 * inlined as one rounding instruction; without it (the x86-64 baseline, where GCC calls
 * libm) the truncation corrected below zero, three instructions.  The same value. */
MPMC_ALWAYS_INLINE int mpmc_ifloor(double s) {
#if defined(__SSE4_1__)
  return (int)floor(s);
#else
  const int i = (int)s;
  return i - (s < (double)i);
#endif
}

/* nodes per axis in a point's support */
MPMC_ALWAYS_INLINE int mpmc_stencil(int basis) {
  return basis == MPMC_BASIS_LINEAR ? 2 : basis == MPMC_BASIS_BSPLINE3 ? 4 : 3;
}

/* The uGIMP weights of four points along one axis at once, the points in the lanes (the same
 * arithmetic on every lane: transfer.h's mpmc_point_weights4; mpmc_basis_1d puts one point in
 * every lane), in vectors of four doubles (one AVX2 register, two SSE2 ones).
 * s = (x_p - origin)/h and l = half-length / h per lane.  Writes the first stencil
 * node per lane into base, and w[k], dw[k] (d/dx_p, per metre) of the k-th node of each
 * axis's stencil, k < MPMC_MAX_STENCIL (0 for the fourth); dw may be a constant NULL (the
 * weights alone).  w and dw are 32-byte aligned tables (mpmc_pw4's), stored into directly.
 * off (may be a constant NULL) gets y below, from which mpmc_ugimp_at gives the same
 * weights again (F-bar's gather: transfer.h, mpmc_kept_weights4).
 *
 * uGIMP (0 < l <= 1/2): the hat N(x) = max(0, 1 - |x|) averaged over the point,
 * w = (1/2l) int_{x-l}^{x+l} N, with y the point's offset from the middle node of its three
 * (y in [-1/2, 1/2)) and c = y clamped to [-l, l]:
 *   w0 = (l - c)^2 / 4l + max(0, -l - y),   w2 = (l + c)^2 / 4l + max(0, y - l),
 *   w1 = 1 - (c^2 + l^2) / 2l - |y - c|,    w' = (c - l, -2c, c + l) / 2l
 * which are the uGIMP weight's pieces (Bardenhagen & Kober 2004) in each of the three
 * ranges of y (the point's support overlapping the middle node's kink, or not, on either
 * side), without branches.  A tail weight near the support's end keeps its relative
 * accuracy (l - c and l + c are exact there), which matters: a node reached only by such a
 * tail divides a force ~ w' by a mass ~ w; a difference of the hat's antiderivative, whose
 * absolute rounding error is 1e-17, inverted a point of the 2D Cook membrane (t201 checks
 * the tails).  Nodes outside the support get exactly 0. */
typedef double mpmc_b4d __attribute__((vector_size(4 * sizeof(double))));
typedef long long mpmc_b4l __attribute__((vector_size(4 * sizeof(long long))));
typedef int mpmc_b4i __attribute__((vector_size(4 * sizeof(int))));
/* the same as mpmc_b4d in memory that is also read as doubles (the weight tables) */
typedef double mpmc_b4da __attribute__((vector_size(4 * sizeof(double)), may_alias));

/* v[i][l] = r[l][i]: four rows of four doubles transposed (the J2 blocks' loads and stores,
 * stress_j2.c; F-bar's four row sums, fbar.c) */
MPMC_ALWAYS_INLINE void mpmc_transpose4(const mpmc_b4d *r, mpmc_b4d *v) {
  const mpmc_b4l ev = {0, 4, 2, 6}, od = {1, 5, 3, 7}, lo = {0, 1, 4, 5}, hi = {2, 3, 6, 7};
  const mpmc_b4d a0 = __builtin_shuffle(r[0], r[1], ev), a1 = __builtin_shuffle(r[0], r[1], od),
                 a2 = __builtin_shuffle(r[2], r[3], ev), a3 = __builtin_shuffle(r[2], r[3], od);
  v[0] = __builtin_shuffle(a0, a2, lo);
  v[1] = __builtin_shuffle(a1, a3, lo);
  v[2] = __builtin_shuffle(a0, a2, hi);
  v[3] = __builtin_shuffle(a1, a3, hi);
}

/* floor per lane as doubles (|s| < 2^31), its int in *bi: with AVX the rounding
 * instruction, else truncation corrected below zero; the same values (vectors through
 * pointers: by value they would change the baseline build's ABI) */
MPMC_ALWAYS_INLINE void mpmc_floor4(const mpmc_b4d *s, mpmc_b4i *bi, mpmc_b4d *fl) {
#if defined(__AVX__)
  *fl = (mpmc_b4d)_mm256_floor_pd((__m256d)*s);
  *bi = (mpmc_b4i)_mm256_cvttpd_epi32((__m256d)*fl);
#else
  const mpmc_b4i i = __builtin_convertvector(*s, mpmc_b4i);
  const mpmc_b4d d = __builtin_convertvector(i, mpmc_b4d);
  const mpmc_b4l below = *s < d;
  *bi = i + __builtin_convertvector(below, mpmc_b4i);
  *fl = d - (mpmc_b4d)(below & (mpmc_b4l)(mpmc_b4d){1.0, 1.0, 1.0, 1.0});
#endif
}

/* mpmc_ugimp_axes's weights from the point's offset y from its middle node (in cells) */
MPMC_ALWAYS_INLINE void mpmc_ugimp_at(const mpmc_b4d *yp, const mpmc_b4d *lp, double inv_h,
                                      mpmc_b4da *w, mpmc_b4da *dw) {
  const mpmc_b4d zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0}, y = *yp, l = *lp;
  const mpmc_b4d i2l = 0.5 / l, i4l = 0.5 * i2l, gl = i2l * inv_h;
  const mpmc_b4d lo = zero - l, hi = zero + l;
/* lanes of a where mask m is set, else of b */
#define SEL4_(m, a, b) ((mpmc_b4d)(((m) & (mpmc_b4l)(a)) | (~(m) & (mpmc_b4l)(b))))
/* a > b ? a : b and a < b ? a : b per lane (NaN: b), as x86's max and min instructions */
#if defined(__AVX__)
#define MAX4_(a, b) ((mpmc_b4d)_mm256_max_pd((__m256d)(a), (__m256d)(b)))
#define MIN4_(a, b) ((mpmc_b4d)_mm256_min_pd((__m256d)(a), (__m256d)(b)))
#else
#define MAX4_(a, b) SEL4_((a) > (b), a, b)
#define MIN4_(a, b) SEL4_((a) < (b), a, b)
#endif
  const mpmc_b4d c0 = MAX4_(lo, y), c = MIN4_(hi, c0); /* y in [-l, l] */
  const mpmc_b4d a = l - c, e = l + c, t0 = lo - y, t2 = y - l;
  const mpmc_b4l sign = (mpmc_b4l)(mpmc_b4d){-0.0, -0.0, -0.0, -0.0}; /* the sign bits */
  const mpmc_b4d d = (mpmc_b4d)((mpmc_b4l)(y - c) & ~sign); /* |y - c| */
  w[0] = a * a * i4l + MAX4_(t0, zero);
  w[1] = one - (c * c + l * l) * i2l - d;
  w[2] = e * e * i4l + MAX4_(t2, zero);
  w[3] = zero;
#undef SEL4_
#undef MAX4_
#undef MIN4_
  if (dw) {
    dw[0] = (zero - a) * gl;
    dw[1] = -2.0 * c * gl;
    dw[2] = e * gl;
    dw[3] = zero;
  }
}

MPMC_ALWAYS_INLINE void mpmc_ugimp_axes(const mpmc_b4d *sp, const mpmc_b4d *lp, double inv_h,
                                        mpmc_b4i *base, mpmc_b4da *w, mpmc_b4da *dw,
                                        mpmc_b4da *off) {
  const mpmc_b4d s = *sp;
  mpmc_b4d fl;
  const mpmc_b4d sh = s - 0.5;
  mpmc_floor4(&sh, base, &fl);
  const mpmc_b4d y = (s - fl) - 1.0;
  if (off) *off = y;
  mpmc_ugimp_at(&y, lp, inv_h, w, dw);
}

/* The weights of the polynomial bases from f, the point's offset (in cells) from its first
 * stencil node, written once for scalars (T double: mpmc_basis_1d) and for vectors (T
 * mpmc_b4d: mpmc_poly_lanes), so both make the same operations and the same bits. */
#define MPMC_LINEAR_W(T, f, w) ((w)[0] = 1.0 - (f), (w)[1] = (f))
#define MPMC_BSPLINE2_W(T, f, w)                                                  \
  do {                                                                            \
    const T x1_ = (f) - 1.0; /* f in [0.5, 1.5) */                                \
    (w)[0] = 0.5 * (1.5 - (f)) * (1.5 - (f));                                     \
    (w)[1] = 0.75 - x1_ * x1_;                                                    \
    (w)[2] = 0.5 * ((f) - 0.5) * ((f) - 0.5);                                     \
  } while (0)
#define MPMC_BSPLINE3_W(T, f, w)                                                  \
  do { /* f in [1, 2): node 0 at distance f, 1 at f - 1, 2 at 2 - f, 3 at 3 - f */ \
    const T x0_ = 2.0 - (f), x1_ = (f) - 1.0;                                     \
    (w)[0] = x0_ * x0_ * x0_ / 6.0;                                               \
    (w)[1] = 0.5 * x1_ * x1_ * x1_ - x1_ * x1_ + 2.0 / 3.0;                       \
    (w)[2] = 0.5 * x0_ * x0_ * x0_ - x0_ * x0_ + 2.0 / 3.0;                       \
    (w)[3] = x1_ * x1_ * x1_ / 6.0;                                               \
  } while (0)

/* The weights of the linear and B-spline bases, and with dw (may be a constant NULL) their
 * gradients, in the lanes of f, the points' offsets (in cells) from their first stencil
 * nodes: mpmc_basis_1d's operations per lane, so the same bits. */
MPMC_ALWAYS_INLINE void mpmc_poly_at(const int basis, const mpmc_b4d *fp, double inv_h,
                                     mpmc_b4da *w, mpmc_b4da *dw) {
  const mpmc_b4d f = *fp, zero = {0.0, 0.0, 0.0, 0.0};
  if (basis == MPMC_BASIS_LINEAR) {
    MPMC_LINEAR_W(mpmc_b4d, f, w);
    if (dw) {
      dw[0] = zero - inv_h;
      dw[1] = zero + inv_h;
    }
  } else if (basis == MPMC_BASIS_BSPLINE2) {
    MPMC_BSPLINE2_W(mpmc_b4d, f, w);
    if (dw) {
      const mpmc_b4d x1 = f - 1.0;
      dw[0] = -(1.5 - f) * inv_h;
      dw[1] = -2.0 * x1 * inv_h;
      dw[2] = (f - 0.5) * inv_h;
    }
  } else { /* cubic */
    MPMC_BSPLINE3_W(mpmc_b4d, f, w);
    if (dw) {
      const mpmc_b4d x0 = 2.0 - f, x1 = f - 1.0, x2 = 2.0 - f, x3 = f - 1.0;
      dw[0] = -0.5 * x0 * x0 * inv_h;
      dw[1] = (1.5 * x1 * x1 - 2.0 * x1) * inv_h;
      dw[2] = -(1.5 * x2 * x2 - 2.0 * x2) * inv_h;
      dw[3] = 0.5 * x3 * x3 * inv_h;
    }
  }
}

/* The linear and B-spline weights in the lanes of s = (x_p - origin)/h (four points along
 * one axis), the floor exact as mpmc_basis_1d's, and with dw (may be a constant NULL) their
 * gradients: mpmc_basis_1d's operations per lane, so the same bits.  off (may be a constant
 * NULL) gets the offsets f that mpmc_poly_at takes. */
MPMC_ALWAYS_INLINE void mpmc_poly_lanes(const int basis, const mpmc_b4d *sp, double inv_h,
                                        mpmc_b4i *base, mpmc_b4da *w, mpmc_b4da *dw,
                                        mpmc_b4da *off) {
  const mpmc_b4d s = *sp;
  mpmc_b4d fl, f;
  if (basis == MPMC_BASIS_LINEAR) {
    mpmc_floor4(&s, base, &fl);
    f = s - fl;
  } else if (basis == MPMC_BASIS_BSPLINE2) {
    const mpmc_b4d sh = s - 0.5;
    mpmc_floor4(&sh, base, &fl);
    f = s - fl;
  } else { /* cubic */
    mpmc_floor4(&s, base, &fl);
    *base -= 1;
    f = s - (fl - 1.0);
  }
  if (off) *off = f;
  mpmc_poly_at(basis, &f, inv_h, w, dw);
}

/* Weights w[k] and gradients dw[k] (d/dx_p, per metre) of nodes base..base+S-1 along one
 * axis.  s = (x_p - origin)/h; l = uGIMP half-length / h.  off (may be a constant NULL)
 * gets the offset that mpmc_basis_1d_at takes: a lane of mpmc_poly_lanes's or
 * mpmc_ugimp_axes's. */
MPMC_ALWAYS_INLINE void mpmc_basis_1d_off(int basis, double s, double l, double inv_h,
                                          int *base, double *w, double *dw, double *off) {
  switch (basis) {
    case MPMC_BASIS_LINEAR: {
      const int b = mpmc_ifloor(s);
      const double f = s - b;
      *base = b;
      if (off) *off = f;
      MPMC_LINEAR_W(double, f, w);
      dw[0] = -inv_h;
      dw[1] = inv_h;
      break;
    }
    case MPMC_BASIS_BSPLINE2: {
      const int b = mpmc_ifloor(s - 0.5);
      const double f = s - b; /* in [0.5, 1.5) */
      const double x1 = f - 1.0;
      *base = b;
      if (off) *off = f;
      MPMC_BSPLINE2_W(double, f, w);
      dw[0] = -(1.5 - f) * inv_h;
      dw[1] = -2.0 * x1 * inv_h;
      dw[2] = (f - 0.5) * inv_h;
      break;
    }
    case MPMC_BASIS_BSPLINE3: {
      const int b = mpmc_ifloor(s) - 1;
      const double f = s - b; /* in [1, 2) */
      const double x0 = 2.0 - f, x1 = f - 1.0, x2 = 2.0 - f, x3 = f - 1.0;
      *base = b;
      if (off) *off = f;
      MPMC_BSPLINE3_W(double, f, w);
      dw[0] = -0.5 * x0 * x0 * inv_h;
      dw[1] = (1.5 * x1 * x1 - 2.0 * x1) * inv_h;
      dw[2] = -(1.5 * x2 * x2 - 2.0 * x2) * inv_h;
      dw[3] = 0.5 * x3 * x3 * inv_h;
      break;
    }
    default: { /* MPMC_BASIS_UGIMP: one lane of mpmc_ugimp_axes, and the fourth node (0), as
                  its callers' arrays are that long */
      mpmc_b4da wv[MPMC_MAX_STENCIL], dv[MPMC_MAX_STENCIL], yv;
      mpmc_b4i b;
      const mpmc_b4d sv = {s, s, s, s}, lv = {l, l, l, l};
      mpmc_ugimp_axes(&sv, &lv, inv_h, &b, wv, dv, &yv);
      *base = b[0];
      if (off) *off = yv[0];
      for (int k = 0; k < MPMC_MAX_STENCIL; ++k) {
        w[k] = wv[k][0];
        dw[k] = dv[k][0];
      }
      break;
    }
  }
}

MPMC_ALWAYS_INLINE void mpmc_basis_1d(int basis, double s, double l, double inv_h, int *base,
                                      double *w, double *dw) {
  mpmc_basis_1d_off(basis, s, l, inv_h, base, w, dw, NULL);
}

/* The weights w[k] alone from the offset off that mpmc_basis_1d_off gave (l as there): the
 * same operations, so the same bits; and those of mpmc_poly_at and mpmc_ugimp_at per lane. */
MPMC_ALWAYS_INLINE void mpmc_basis_1d_at(int basis, double off, double l, double *w) {
  if (basis == MPMC_BASIS_LINEAR) {
    MPMC_LINEAR_W(double, off, w);
  } else if (basis == MPMC_BASIS_BSPLINE2) {
    MPMC_BSPLINE2_W(double, off, w);
  } else if (basis == MPMC_BASIS_BSPLINE3) {
    MPMC_BSPLINE3_W(double, off, w);
  } else {
    mpmc_b4da wv[MPMC_MAX_STENCIL];
    const mpmc_b4d yv = {off, off, off, off}, lv = {l, l, l, l};
    mpmc_ugimp_at(&yv, &lv, 1.0, wv, NULL);
    for (int k = 0; k < MPMC_MAX_STENCIL; ++k) w[k] = wv[k][0];
  }
}

/* Out-of-line version for tests and non-hot callers (basis.c). */
void mpmc_basis_eval_1d(int basis, double s, double l, double inv_h, int *base, double *w,
                        double *dw);

#endif
