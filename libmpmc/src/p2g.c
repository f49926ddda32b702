/* Particle to grid: mass (eq 7), momentum (eq 8), internal force (eq 10) and the points'
 * external forces.  Threads scatter without atomics: the points are bucketed by slab
 * (mpmc_slabs_build) and the slabs of one parity run in parallel, then the other parity. */
#include <stdlib.h>

#include "transfer.h"

/* Bucket the points into slabs of MPMC_SLAB_W cells along one axis (a counting sort of
 * indices; the particle arrays themselves are not moved, so indices held
 * by callers and particle sets stay valid). */
int mpmc_slabs_build(mpmc_sim sim) {
  const mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int d = sim->dim;
  /* the outermost axis of the node numbering (z in 3D, y in 2D): a slab's nodes are then one
   * contiguous block, and so are its points when they were seeded in lattice order; another
   * axis only when this one has too few slabs to keep two threads busy */
  int axis = d - 1;
  if (g->n[axis] / MPMC_SLAB_W < 8)
    for (int a = 0; a < d; ++a)
      if (g->n[a] > g->n[axis]) axis = a;
  const int nslab = g->n[axis] / MPMC_SLAB_W + 1;
  if (p->n > sim->cap_order) {
    int *o = realloc(sim->order, sizeof(int) * (size_t)p->n);
    MPMC_CHECK(o, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the slab order of %d points", p->n);
    sim->order = o;
    sim->cap_order = p->n;
  }
  if (nslab + 1 > sim->cap_slab) {
    int *st = realloc(sim->slab_start, sizeof(int) * (size_t)(nslab + 1));
    MPMC_CHECK(st, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate %d slabs", nslab);
    sim->slab_start = st;
    sim->cap_slab = nslab + 1;
  }
  int *start = sim->slab_start, *order = sim->order;
  for (int s = 0; s <= nslab; ++s) start[s] = 0;
  const double o = g->origin[axis], ih = g->inv_h;
  /* points stay within one cell of the box (g2p checks), well inside the ghost layers */
  for (int q = 0; q < p->n; ++q) {
    const int c = (int)((p->x[(size_t)q * d + axis] - o) * ih);
    start[c / MPMC_SLAB_W + 1]++;
  }
  for (int s = 0; s < nslab; ++s) start[s + 1] += start[s];
  for (int q = 0; q < p->n; ++q) {
    const int c = (int)((p->x[(size_t)q * d + axis] - o) * ih);
    order[start[c / MPMC_SLAB_W]++] = q;
  }
  for (int s = nslab; s > 0; --s) start[s] = start[s - 1];
  start[0] = 0;
  sim->nslab = nslab;
  sim->slab_axis = axis;
  return MPMC_SUCCESS;
}

/* Scatter point q: mass, momentum and force w m, w m v, -V sigma grad w + w f_ext. */
MPMC_ALWAYS_INLINE void p2g_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  double *restrict gm = g->mass, *restrict gp = g->mom, *restrict gf = g->force;
  const size_t qd = (size_t)q * DIM;
  mpmc_pw pw;
  mpmc_point_weights(DIM, BASIS, g, p->x + qd, BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
  const double m = p->m[q];
  double mv[3] = {0, 0, 0};
  for (int a = 0; a < DIM; ++a) mv[a] = m * p->v[qd + a];
  const double V = p->vol0[q] * p->J[q];
  const double *s = p->stress + (size_t)q * 6;
  /* -V sigma, rows of the (symmetric) stress in the dim-dimensional subspace */
  double vs[3][3];
  vs[0][0] = -V * s[0];
  vs[1][1] = -V * s[1];
  vs[2][2] = -V * s[2];
  vs[1][2] = vs[2][1] = -V * s[3];
  vs[0][2] = vs[2][0] = -V * s[4];
  vs[0][1] = vs[1][0] = -V * s[5];
  double fe[3] = {0, 0, 0};
  if (p->force)
    for (int a = 0; a < DIM; ++a) fe[a] = p->force[qd + a];
  if (p->cforce)
    for (int a = 0; a < DIM; ++a) fe[a] += p->cforce[qd + a];
  MPMC_STENCIL_LOOP(DIM, BASIS, g, pw, {
    gm[node] += w * m;
    for (int a = 0; a < DIM; ++a) {
      double f = w * fe[a];
      for (int b = 0; b < DIM; ++b) f += vs[a][b] * gw[b];
      gp[node * DIM + a] += w * mv[a];
      gf[node * DIM + a] += f;
    }
  });
}

#define P2G_KERNEL(D, B)                                                                    \
  static void p2g_##D##_##B(mpmc_sim sim) {                                                 \
    const int *restrict order = sim->order, *restrict start = sim->slab_start;              \
    for (int colour = 0; colour < 2; ++colour) {                                            \
      _Pragma("omp parallel for schedule(dynamic, 1) if (sim->p.n > MPMC_OMP_MIN)")         \
      for (int sl = colour; sl < sim->nslab; sl += 2)                                       \
        for (int k = start[sl]; k < start[sl + 1]; ++k) p2g_point(sim, D, B, order[k]);     \
    }                                                                                       \
  }
MPMC_KERNELS(P2G_KERNEL)

/** Phase 1 of the step: reset the grid and scatter the points onto it. */
int mpmc_p2g(mpmc_sim sim, double dt) {
  (void)dt;
  mpmc_grid_clear(&sim->grid, sim->fbar);
  MPMC_CALL(mpmc_slabs_build(sim));
  MPMC_KERNEL_CALL(p2g_, sim, sim);
  return MPMC_SUCCESS;
}
