/* Basis functions (formulas.md): 1D weights and gradients, tensor products in 2D/3D.
 * Inline so that the transfer kernels, instantiated per (dim, basis) with compile-time
 * constants, fold the basis switch away. */
#ifndef MPMC_BASIS_H
#define MPMC_BASIS_H

#include <math.h>

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

/* uGIMP weight of a node at cell-unit distance x from a point of half-length l (cell units). */
MPMC_ALWAYS_INLINE void mpmc_ugimp_1d(double x, double l, double *w, double *dw) {
  const double a = fabs(x), sg = x < 0 ? -1.0 : 1.0;
  if (a >= 1.0 + l) {
    *w = 0.0;
    *dw = 0.0;
  } else if (a > 1.0 - l) {
    const double r = 1.0 + l - a;
    *w = r * r / (4.0 * l);
    *dw = -sg * r / (2.0 * l);
  } else if (a > l) {
    *w = 1.0 - a;
    *dw = -sg;
  } else {
    *w = 1.0 - (x * x + l * l) / (2.0 * l);
    *dw = -x / l;
  }
}

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
    default: { /* MPMC_BASIS_UGIMP, requires l <= 1/2 */
      const int b = mpmc_ifloor(s - 0.5);
      const double f = s - b;
      *base = b;
      for (int k = 0; k < 3; ++k) {
        mpmc_ugimp_1d(f - k, l, &w[k], &dw[k]);
        dw[k] *= inv_h;
      }
      break;
    }
  }
}

/* Out-of-line version for tests and non-hot callers (basis.c). */
void mpmc_basis_eval_1d(int basis, double s, double l, double inv_h, int *base, double *w,
                        double *dw);

#endif
