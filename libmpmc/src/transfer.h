/* Shared pieces of the particle-grid transfers, instantiated per (dim, basis) at compile
 * time: each phase writes one always-inline body taking DIM and BASIS as constants and
 * MPMC_DISPATCH expands it once for each of the eight combinations. */
#ifndef MPMC_TRANSFER_H
#define MPMC_TRANSFER_H

#include "basis.h"
#include "mpmc_impl.h"

/* GCC cannot see that mpmc_basis_1d fills exactly the stencil that the loops read. */
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

typedef struct {
  size_t node0;                         /* linear index of the stencil's first node */
  double w[3][MPMC_MAX_STENCIL];        /* 1D weights per axis                       */
  double dw[3][MPMC_MAX_STENCIL];       /* 1D gradients per axis (per metre)         */
} mpmc_pw;

MPMC_ALWAYS_INLINE void mpmc_point_weights(const int DIM, const int BASIS, const mpmc_grid *g,
                                           const double *x, double lp, mpmc_pw *pw) {
  int base[3] = {0, 0, 0};
  const double l = lp * g->inv_h;
  for (int a = 0; a < DIM; ++a) {
    const double s = (x[a] - g->origin[a]) * g->inv_h;
    mpmc_basis_1d(BASIS, s, l, g->inv_h, &base[a], pw->w[a], pw->dw[a]);
  }
  pw->node0 = (size_t)base[0] + (size_t)g->n[0] * ((size_t)base[1] + (size_t)g->n[1] * (size_t)base[2]);
}

/* Loop over the stencil: body sees `node` (linear index), `w` (weight) and `gw[DIM]`
 * (weight gradient). */
#define MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, body)                                          \
  do {                                                                                      \
    const int S_ = mpmc_stencil(BASIS);                                                     \
    const size_t sy_ = (size_t)(g)->n[0], sz_ = (size_t)(g)->n[0] * (size_t)(g)->n[1];      \
    for (int k_ = 0; k_ < (DIM == 3 ? S_ : 1); ++k_) {                                      \
      const double wz_ = DIM == 3 ? (pw).w[2][k_] : 1.0;                                    \
      const double dz_ = DIM == 3 ? (pw).dw[2][k_] : 0.0;                                   \
      for (int j_ = 0; j_ < S_; ++j_) {                                                     \
        const double wy_ = (pw).w[1][j_], dy_ = (pw).dw[1][j_];                            \
        for (int i_ = 0; i_ < S_; ++i_) {                                                   \
          const size_t node = (pw).node0 + (size_t)i_ + sy_ * (size_t)j_ + sz_ * (size_t)k_; \
          const double wx_ = (pw).w[0][i_], dx_ = (pw).dw[0][i_];                          \
          const double w = wx_ * wy_ * wz_;                                                 \
          double gw[3];                                                                     \
          gw[0] = dx_ * wy_ * wz_;                                                          \
          gw[1] = wx_ * dy_ * wz_;                                                          \
          gw[2] = wx_ * wy_ * dz_;                                                          \
          (void)gw;                                                                         \
          body                                                                              \
        }                                                                                   \
      }                                                                                     \
    }                                                                                       \
  } while (0)

#define MPMC_DISPATCH(impl, sim, ...)                                    \
  do {                                                                   \
    switch ((sim)->dim * 4 + (sim)->basis) {                             \
      case 8: impl(sim, 2, MPMC_BASIS_LINEAR, __VA_ARGS__); break;       \
      case 9: impl(sim, 2, MPMC_BASIS_UGIMP, __VA_ARGS__); break;        \
      case 10: impl(sim, 2, MPMC_BASIS_BSPLINE2, __VA_ARGS__); break;    \
      case 11: impl(sim, 2, MPMC_BASIS_BSPLINE3, __VA_ARGS__); break;    \
      case 12: impl(sim, 3, MPMC_BASIS_LINEAR, __VA_ARGS__); break;      \
      case 13: impl(sim, 3, MPMC_BASIS_UGIMP, __VA_ARGS__); break;       \
      case 14: impl(sim, 3, MPMC_BASIS_BSPLINE2, __VA_ARGS__); break;    \
      default: impl(sim, 3, MPMC_BASIS_BSPLINE3, __VA_ARGS__); break;    \
    }                                                                    \
  } while (0)

#endif
