/* Particle to grid: mass (eq 7), momentum (eq 8), internal force (eq 10) and the points'
 * external forces. */
#include "transfer.h"

MPMC_ALWAYS_INLINE void p2g_impl(mpmc_sim sim, const int DIM, const int BASIS, int dummy) {
  (void)dummy;
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  double *restrict gm = g->mass, *restrict gp = g->mom, *restrict gf = g->force;
  const double *restrict lp = p->lp;
  const double *restrict pf = p->force;
  const double *restrict pc = p->cforce;
  for (int q = 0; q < p->n; ++q) {
    const size_t qd = (size_t)q * DIM;
    mpmc_pw pw;
    mpmc_point_weights(DIM, BASIS, g, p->x + qd, BASIS == MPMC_BASIS_UGIMP ? lp[q] : 0.0, &pw);
    const double m = p->m[q];
    const double *v = p->v + qd;
    const double V = p->vol0[q] * p->J[q];
    const double *s = p->stress + (size_t)q * 6;
    /* -V sigma, rows of the (symmetric) stress in the dim-dimensional subspace */
    double vs[3][3];
    vs[0][0] = -V * s[0]; vs[1][1] = -V * s[1]; vs[2][2] = -V * s[2];
    vs[1][2] = vs[2][1] = -V * s[3];
    vs[0][2] = vs[2][0] = -V * s[4];
    vs[0][1] = vs[1][0] = -V * s[5];
    double fe[3] = {0, 0, 0};
    if (pf)
      for (int a = 0; a < DIM; ++a) fe[a] = pf[qd + a];
    if (pc)
      for (int a = 0; a < DIM; ++a) fe[a] += pc[qd + a];
    MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, {
      gm[node] += w * m;
      for (int a = 0; a < DIM; ++a) {
        double f = w * fe[a];
        for (int b = 0; b < DIM; ++b) f += vs[a][b] * gw[b];
        gp[node * DIM + a] += w * m * v[a];
        gf[node * DIM + a] += f;
      }
    });
  }
}

/** Phase 1 of the step: reset the grid and scatter the points onto it. */
int mpmc_p2g(mpmc_sim sim, double dt) {
  (void)dt;
  mpmc_grid_clear(&sim->grid, sim->fbar);
  MPMC_DISPATCH(p2g_impl, sim, 0);
  return MPMC_SUCCESS;
}
