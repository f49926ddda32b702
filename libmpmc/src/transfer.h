/* Shared pieces of the particle-grid transfers, instantiated per (dim, basis) at compile
 * time: each phase writes one always-inline per-point body taking DIM and BASIS as constants
 * and a loop macro that MPMC_KERNELS expands once for each of the eight combinations. */
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

/* det of a dim x dim row-major matrix (the relative deformation gradient) */
MPMC_ALWAYS_INLINE double mpmc_det_dim(const int DIM, const double *F) {
  return DIM == 2 ? F[0] * F[3] - F[1] * F[2]
                  : F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                        F[2] * (F[3] * F[7] - F[4] * F[6]);
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

/* The eight (dim, basis) instances.  A kernel's loop, with its OpenMP pragma, is written in a
 * macro X(D, B) expanded by MPMC_KERNELS with literal constants: GCC outlines OpenMP regions
 * before inlining, so constants passed into a function holding the pragma would reach the
 * outlined loop as run-time values and the basis switch would stay in the hot loop. */
#define MPMC_KERNELS(X) X(2, 0) X(2, 1) X(2, 2) X(2, 3) X(3, 0) X(3, 1) X(3, 2) X(3, 3)

/* Call fn##D##_##B(args...) for the simulation's dimension and basis. */
#define MPMC_KERNEL_CALL(fn, sim, ...)                  \
  do {                                                  \
    switch ((sim)->dim * 4 + (sim)->basis) {            \
      case 8: fn##2_0(__VA_ARGS__); break;              \
      case 9: fn##2_1(__VA_ARGS__); break;              \
      case 10: fn##2_2(__VA_ARGS__); break;             \
      case 11: fn##2_3(__VA_ARGS__); break;             \
      case 12: fn##3_0(__VA_ARGS__); break;             \
      case 13: fn##3_1(__VA_ARGS__); break;             \
      case 14: fn##3_2(__VA_ARGS__); break;             \
      default: fn##3_3(__VA_ARGS__); break;             \
    }                                                   \
  } while (0)

#endif
