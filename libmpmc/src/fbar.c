/* The F-bar projection (paper Algorithm 1, eqs 19-27), run only when enabled:
 *   scatter  V_i = sum w V_p,  (V J)_i = sum w V_p j_p                          (step 3)
 *   gather   Pi_p = sum w Jbar_i,  dFbar = (Pi_p / (Jbar_p^n dJ_p))^(1/dim) dF (step 4)
 * with j_p = Jbar_p^n dJ_p in MPMC_FBAR_PAPER (eq 26, Algorithm 1 as published) and
 * j_p = J_p^{n+1} = det F in MPMC_FBAR_TOTAL (eqs 18-21: the projection of the Jacobian
 * itself, inserted in eq 25).  The paper's recursion re-projects Jbar every step, so in a
 * long quasi-static run the smoothing of a non-uniform Jbar near boundaries accumulates
 * into a creep of the true volume (docs/theory.md); the total form has no such memory.
 * V_p is the volume at t^n, recovered as V0 J^{n+1} / dJ (G2P has already updated J).
 * Touches nothing but dF (handed to the material) and Jbar. */
#include <math.h>

#include "transfer.h"

/* Scatter point q: V^n and V^n j onto its nodes (Algorithm 1, step 3). */
MPMC_ALWAYS_INLINE void scatter_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  double *restrict gvol = g->vol, *restrict gjv = g->jv;
  mpmc_pw pw;
  mpmc_point_weights(DIM, BASIS, g, p->x + (size_t)q * DIM,
                     BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
  const double dJ = mpmc_det_dim(DIM, p->dF + (size_t)q * DIM * DIM);
  const double Vn = p->vol0[q] * p->J[q] / dJ;
  const double val = sim->fbar == MPMC_FBAR_TOTAL ? p->J[q] : p->Jbar[q] * dJ;
  const double Vv = Vn * val;
  MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, {
    gvol[node] += w * Vn;
    gjv[node] += w * Vv;
  });
}

/* r^(1/3) for r near 1 by Newton from 1 + (r-1)/3 (three steps: relative error below 1e-16
 * for |r - 1| < 0.05); libm's cbrt elsewhere. */
static inline double cbrt_near1(double r) {
  const double e = r - 1.0;
  if (!(fabs(e) < 0.05)) return cbrt(r);
  double x = 1.0 + e / 3.0;
  for (int i = 0; i < 3; ++i) x -= (x * x * x - r) / (3.0 * x * x);
  return x;
}

/* Gather point q: Pi = sum w Jbar_i, scale dF (Algorithm 1, step 4). */
MPMC_ALWAYS_INLINE void gather_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double *restrict gjb = g->jv;
  mpmc_pw pw;
  mpmc_point_weights(DIM, BASIS, g, p->x + (size_t)q * DIM,
                     BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
  double pi = 0.0;
  MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, { pi += w * gjb[node]; });
  double *dF = p->dF + (size_t)q * DIM * DIM;
  const double r = pi / (p->Jbar[q] * mpmc_det_dim(DIM, dF));
  const double scale = DIM == 2 ? sqrt(r) : cbrt_near1(r);
  for (int k = 0; k < DIM * DIM; ++k) dF[k] *= scale;
  p->Jbar[q] = pi;
}

/* scatter by the slabs of this step's P2G (positions unchanged since): race-free by parity */
#define FBAR_KERNELS(D, B)                                                                   \
  static void scatter_##D##_##B(mpmc_sim sim) {                                              \
    const int *restrict order = sim->order, *restrict start = sim->slab_start;               \
    for (int colour = 0; colour < 2; ++colour) {                                             \
      _Pragma("omp parallel for schedule(dynamic, 1) if (sim->p.n > MPMC_OMP_MIN)")          \
      for (int sl = colour; sl < sim->nslab; sl += 2)                                        \
        for (int k = start[sl]; k < start[sl + 1]; ++k) scatter_point(sim, D, B, order[k]);  \
    }                                                                                        \
  }                                                                                          \
  static void gather_##D##_##B(mpmc_sim sim) {                                               \
    _Pragma("omp parallel for schedule(static) if (sim->p.n > MPMC_OMP_MIN)")                \
    for (int q = 0; q < sim->p.n; ++q) gather_point(sim, D, B, q);                           \
  }
MPMC_KERNELS(FBAR_KERNELS)

/** Phase 4 of the step (only with F-bar on). */
int mpmc_fbar(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  MPMC_KERNEL_CALL(scatter_, sim, sim);
  /* nodal volume average (Algorithm 1 step 3) */
  const long nn = (long)g->nn;
#pragma omp parallel for schedule(static) if (nn > MPMC_OMP_MIN)
  for (long i = 0; i < nn; ++i) g->jv[i] = g->vol[i] > 0.0 ? g->jv[i] / g->vol[i] : 0.0;
  MPMC_KERNEL_CALL(gather_, sim, sim);
  /* the projection used the weights at x^n; now the points move (eq 17) */
  double *t = sim->p.x;
  sim->p.x = sim->p.xn;
  sim->p.xn = t;
  return MPMC_SUCCESS;
}
