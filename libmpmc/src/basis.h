/* Basis functions (formulas.md): 1D weights and gradients, tensor products in 2D/3D.
 * Inline so that the transfer kernels, instantiated per (dim, basis) with compile-time
 * constants, fold the basis switch away. */
#ifndef MPMC_BASIS_H
#define MPMC_BASIS_H

#include <math.h>
#include <string.h>

#include "mpmc.h"

#define MPMC_ALWAYS_INLINE static inline __attribute__((always_inline))
#define MPMC_MAX_STENCIL 4

/* floor(s) as an int for |s| < 2^31: truncation corrected below zero.  libm's floor needs
 * SSE4.1 to be inlined (not in the x86-64 baseline); this is three instructions. */
MPMC_ALWAYS_INLINE int mpmc_ifloor(double s) {
  const int i = (int)s;
  return i - (s < (double)i);
}

/* nodes per axis in a point's support */
MPMC_ALWAYS_INLINE int mpmc_stencil(int basis) {
  return basis == MPMC_BASIS_LINEAR ? 2 : basis == MPMC_BASIS_BSPLINE3 ? 4 : 3;
}

/* uGIMP, branch-free: the weight of a node at cell-unit distance x from a point of
 * half-length l (cell units, 0 < l <= 1/2) is the hat N(y) = max(0, 1 - |y|) averaged over
 * the point, w = (1/2l) int_{x-l}^{x+l} N.  With u, v = x + l, x - l clamped to [-1, 1] (N is 0
 * beyond) the integrand is linear on [v, u] but for the kink at 0, so
 *   w = [(u - v) (N(u) + N(v)) / 2 + max(0, -u v)] / (2l),   w' = (N(u) - N(v)) / (2l)
 * (trapezoid plus the kink's share).  In this form a weight near the support's ends keeps
 * its relative accuracy (u - v and 1 - |u| are exact there), which matters: a node reached
 * only by such a tail divides a force ~ w' by a mass ~ w, and the antiderivative's difference
 * H(u) - H(v), whose absolute rounding error is 1e-17, inverted a point of the 2D Cook membrane.
 * The same values as formulas.md's four pieces (t201 compares them), without the branches
 * whose outcome changes from point to point.  Written over MPMC_MAX_STENCIL lanes (the fourth
 * node, at x <= -3/2, gets exactly 0, as do nodes outside the support) so that the loop
 * becomes whole vectors. */
typedef double mpmc_b4d __attribute__((vector_size(4 * sizeof(double))));
typedef long long mpmc_b4l __attribute__((vector_size(4 * sizeof(long long))));

/* Weights w[k] and gradients dw[k] (d/dx_p, per metre) of nodes base..base+S-1 along one
 * axis.  s = (x_p - origin)/h; l = uGIMP half-length / h. */
MPMC_ALWAYS_INLINE void mpmc_basis_1d(int basis, double s, double l, double inv_h, int *base,
                                      double *w, double *dw) {
  switch (basis) {
    case MPMC_BASIS_LINEAR: {
      const int b = mpmc_ifloor(s);
      const double f = s - b;
      *base = b;
      w[0] = 1.0 - f;
      w[1] = f;
      dw[0] = -inv_h;
      dw[1] = inv_h;
      break;
    }
    case MPMC_BASIS_BSPLINE2: {
      const int b = mpmc_ifloor(s - 0.5);
      const double f = s - b; /* in [0.5, 1.5) */
      const double x1 = f - 1.0;
      *base = b;
      w[0] = 0.5 * (1.5 - f) * (1.5 - f);
      w[1] = 0.75 - x1 * x1;
      w[2] = 0.5 * (f - 0.5) * (f - 0.5);
      dw[0] = -(1.5 - f) * inv_h;
      dw[1] = -2.0 * x1 * inv_h;
      dw[2] = (f - 0.5) * inv_h;
      break;
    }
    case MPMC_BASIS_BSPLINE3: {
      const int b = mpmc_ifloor(s) - 1;
      const double f = s - b; /* in [1, 2) */
      const double x0 = 2.0 - f, x1 = f - 1.0, x2 = 2.0 - f, x3 = f - 1.0;
      /* node 0 at distance f, 1 at f-1, 2 at 2-f (negative side), 3 at 3-f */
      *base = b;
      w[0] = x0 * x0 * x0 / 6.0;
      w[1] = 0.5 * x1 * x1 * x1 - x1 * x1 + 2.0 / 3.0;
      w[2] = 0.5 * x2 * x2 * x2 - x2 * x2 + 2.0 / 3.0;
      w[3] = x3 * x3 * x3 / 6.0;
      dw[0] = -0.5 * x0 * x0 * inv_h;
      dw[1] = (1.5 * x1 * x1 - 2.0 * x1) * inv_h;
      dw[2] = -(1.5 * x2 * x2 - 2.0 * x2) * inv_h;
      dw[3] = 0.5 * x3 * x3 * inv_h;
      break;
    }
    default: { /* MPMC_BASIS_UGIMP, requires 0 < l <= 1/2 (above) */
      const int b = mpmc_ifloor(s - 0.5);
      const double f = s - b;
      const double i2l = 0.5 / l, gi2l = i2l * inv_h;
      *base = b;
      const mpmc_b4d x = f - (mpmc_b4d){0.0, 1.0, 2.0, 3.0}, one = x * 0.0 + 1.0;
      const mpmc_b4l sign = (mpmc_b4l)(-(one * 0.0)); /* -0.0: the sign bits */
      mpmc_b4d u = x + l, v = x - l;
      /* clamp to [-1, 1] exactly (outside the support both ends clamp alike and w = dw = 0) */
#define CLAMP1_(y)                                                      \
  do {                                                                  \
    const mpmc_b4l hi_ = (y) > one, lo_ = (y) < -one;                   \
    y = (mpmc_b4d)((hi_ & (mpmc_b4l)one) | (~hi_ & (mpmc_b4l)(y)));     \
    y = (mpmc_b4d)((lo_ & (mpmc_b4l)(-one)) | (~lo_ & (mpmc_b4l)(y)));  \
  } while (0)
      CLAMP1_(u);
      CLAMP1_(v);
#undef CLAMP1_
      const mpmc_b4d nu = one - (mpmc_b4d)((mpmc_b4l)u & ~sign); /* N(u) = 1 - |u| */
      const mpmc_b4d nv = one - (mpmc_b4d)((mpmc_b4l)v & ~sign);
      const mpmc_b4d uv = u * v;
      const mpmc_b4d kink = (mpmc_b4d)((uv < x * 0.0) & (mpmc_b4l)(-uv));
      const mpmc_b4d wv = ((u - v) * (nu + nv) * 0.5 + kink) * i2l;
      const mpmc_b4d dv = (nu - nv) * gi2l;
      memcpy(w, &wv, sizeof wv);
      memcpy(dw, &dv, sizeof dv);
      break;
    }
  }
}

/* Out-of-line version for tests and non-hot callers (basis.c). */
void mpmc_basis_eval_1d(int basis, double s, double l, double inv_h, int *base, double *w,
                        double *dw);

#endif
