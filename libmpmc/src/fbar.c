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

static inline double det_dim(const int DIM, const double *F) {
  return DIM == 2 ? F[0] * F[3] - F[1] * F[2]
                  : F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                        F[2] * (F[3] * F[7] - F[4] * F[6]);
}

MPMC_ALWAYS_INLINE void scatter_impl(mpmc_sim sim, const int DIM, const int BASIS, int dummy) {
  (void)dummy;
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  double *restrict gvol = g->vol, *restrict gjv = g->jv;
  const int total = sim->fbar == MPMC_FBAR_TOTAL;
  /* the slabs of this step's P2G (positions unchanged since): race-free by parity */
  const int *restrict order = sim->order, *restrict start = sim->slab_start;
  for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(dynamic, 1) if (p->n > MPMC_OMP_MIN)
    for (int sl = colour; sl < sim->nslab; sl += 2) {
      for (int k = start[sl]; k < start[sl + 1]; ++k) {
        const int q = order[k];
        mpmc_pw pw;
        mpmc_point_weights(DIM, BASIS, g, p->x + (size_t)q * DIM,
                           BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
        const double dJ = det_dim(DIM, p->dF + (size_t)q * DIM * DIM);
        const double Vn = p->vol0[q] * p->J[q] / dJ;
        const double val = total ? p->J[q] : p->Jbar[q] * dJ;
        MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, {
          gvol[node] += w * Vn;
          gjv[node] += w * Vn * val;
        });
      }
    }
  }
}

MPMC_ALWAYS_INLINE void gather_impl(mpmc_sim sim, const int DIM, const int BASIS, int dummy) {
  (void)dummy;
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double *restrict gjb = g->jv;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    mpmc_pw pw;
    mpmc_point_weights(DIM, BASIS, g, p->x + (size_t)q * DIM,
                       BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
    double pi = 0.0;
    MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, { pi += w * gjb[node]; });
    double *dF = p->dF + (size_t)q * DIM * DIM;
    const double local = p->Jbar[q] * det_dim(DIM, dF);
    const double r = pi / local;
    const double scale = DIM == 2 ? sqrt(r) : cbrt(r);
    for (int k = 0; k < DIM * DIM; ++k) dF[k] *= scale;
    p->Jbar[q] = pi;
  }
}

/** Phase 4 of the step (only with F-bar on). */
int mpmc_fbar(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  MPMC_DISPATCH(scatter_impl, sim, 0);
  /* nodal volume average (Algorithm 1 step 3) */
  const long nn = (long)g->nn;
#pragma omp parallel for schedule(static) if (nn > MPMC_OMP_MIN)
  for (long i = 0; i < nn; ++i) g->jv[i] = g->vol[i] > 0.0 ? g->jv[i] / g->vol[i] : 0.0;
  MPMC_DISPATCH(gather_impl, sim, 0);
  /* the projection used the weights at x^n; now the points move (eq 17) */
  double *t = sim->p.x;
  sim->p.x = sim->p.xn;
  sim->p.xn = t;
  return MPMC_SUCCESS;
}
