/* Grid to particle: velocity with the FLIP/PIC blend (eqs 11-13), relative deformation
 * gradient dF = 1 + dt sum v_i (x) grad w (eq 16), J <- J det(dF) so that V = J V0 (eq 15),
 * position (eq 17).  With F-bar the new positions go to xn: the projection still needs the
 * weights at x^n. */
#include <limits.h>
#include <math.h>

#include "transfer.h"

typedef struct {
  double eta;             /* FLIP/PIC blend                                             */
  double *xout;           /* new positions: x, or xn while F-bar needs x^n              */
  double xmin[3], xmax[3];/* points may drift up to one cell beyond the box (walls act on
                             the nodes there); further out the support leaves the grid   */
} g2p_ctx;

/* Gather point q; returns 0 if its volume inverted or it left the grid. */
MPMC_ALWAYS_INLINE int g2p_point(mpmc_sim sim, const int DIM, const int BASIS, double dt,
                                 const g2p_ctx *c, int q) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double *restrict gv = g->mom, *restrict gdv = g->force;
  const size_t qd = (size_t)q * DIM;
  mpmc_pw pw;
  mpmc_point_weights(DIM, BASIS, g, p->x + qd, BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
  double vpic[3] = {0, 0, 0}, dv[3] = {0, 0, 0}, L[3][3] = {{0}};
  MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, {
    for (int a = 0; a < DIM; ++a) {
      const double va = gv[node * DIM + a];
      vpic[a] += w * va;
      dv[a] += w * gdv[node * DIM + a];
      for (int b = 0; b < DIM; ++b) L[a][b] += va * gw[b];
    }
  });
  double *dF = p->dF + (size_t)q * DIM * DIM;
  for (int a = 0; a < DIM; ++a)
    for (int b = 0; b < DIM; ++b) dF[a * DIM + b] = (a == b) + dt * L[a][b];
  const double dJ = mpmc_det_dim(DIM, dF);
  p->J[q] *= dJ;
  int ok = dJ > 0.0 && isfinite(dJ);
  double *v = p->v + qd;
  for (int a = 0; a < DIM; ++a) {
    v[a] = c->eta * (v[a] + dv[a]) + (1.0 - c->eta) * vpic[a];
    const double xa = p->x[qd + a] + dt * vpic[a];
    c->xout[qd + a] = xa;
    ok &= xa >= c->xmin[a] && xa <= c->xmax[a];
  }
  return ok;
}

#define G2P_KERNEL(D, B)                                                                     \
  static void g2p_##D##_##B(mpmc_sim sim, double dt, const g2p_ctx *c, int *bad) {           \
    int first_bad = INT_MAX;                                                                 \
    _Pragma("omp parallel for schedule(static) reduction(min : first_bad) if (sim->p.n > MPMC_OMP_MIN)") \
    for (int q = 0; q < sim->p.n; ++q)                                                       \
      if (!g2p_point(sim, D, B, dt, c, q) && q < first_bad) first_bad = q;                   \
    *bad = first_bad == INT_MAX ? -1 : first_bad;                                            \
  }
MPMC_KERNELS(G2P_KERNEL)

static int report(mpmc_sim sim, int q) {
  const mpmc_particles *p = &sim->p;
  const int d = sim->dim;
  const double *x = (sim->fbar ? p->xn : p->x) + (size_t)q * d;
  const double *dF = p->dF + (size_t)q * d * d;
  const double dJ = d == 2 ? mpmc_det_dim(2, dF) : mpmc_det_dim(3, dF);
  if (!(p->J[q] > 0.0) || !isfinite(p->J[q]))
    return MPMC_ERROR(sim->ctx, MPMC_ERR_NUMERIC,
                      "step %lld, t = %g: point %d at (%g, %g, %g) inverted or lost its volume "
                      "(J = %g%s): reduce the time step",
                      (long long)sim->stats.steps, sim->time, q, x[0], x[1], d == 3 ? x[2] : 0.0,
                      p->J[q], dJ <= 0 ? ", dJ <= 0" : "");
  return MPMC_ERROR(sim->ctx, MPMC_ERR_OUTSIDE,
                    "step %lld, t = %g: point %d left the grid box at (%g, %g, %g)",
                    (long long)sim->stats.steps, sim->time, q, x[0], x[1], d == 3 ? x[2] : 0.0);
}

/** Phase 3 of the step. */
int mpmc_g2p(mpmc_sim sim, double dt) {
  const mpmc_grid *g = &sim->grid;
  g2p_ctx c = {.eta = sim->flip, .xout = sim->fbar ? sim->p.xn : sim->p.x};
  for (int a = 0; a < sim->dim; ++a) {
    c.xmin[a] = g->lo[a] - g->h;
    c.xmax[a] = g->hi[a] + g->h;
  }
  int bad = -1;
  MPMC_KERNEL_CALL(g2p_, sim, sim, dt, &c, &bad);
  if (bad >= 0) return report(sim, bad);
  return MPMC_SUCCESS;
}
