/* Uniform background grid in 2D/3D with ghost layers around the user's box. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

int mpmc_grid_setup(mpmc_context ctx, mpmc_grid *g, int dim, const double *lo, const double *hi,
                    double h) {
  MPMC_CHECK(h > 0 && isfinite(h), ctx, MPMC_ERR_ARG, "cell size h = %g must be > 0", h);
  size_t nn = 1;
  int n[3] = {1, 1, 1};
  for (int a = 0; a < dim; ++a) {
    MPMC_CHECK(isfinite(lo[a]) && isfinite(hi[a]) && hi[a] > lo[a], ctx, MPMC_ERR_ARG,
               "grid box axis %d: hi = %g must exceed lo = %g", a, hi[a], lo[a]);
    const double cells = ceil((hi[a] - lo[a]) / h - 1e-9);
    MPMC_CHECK(cells <= 1e6, ctx, MPMC_ERR_ARG, "grid axis %d would have %g cells (h = %g too small)",
               a, cells, h);
    n[a] = (int)cells + 1 + 2 * MPMC_GHOST;
    nn *= (size_t)n[a];
  }
  MPMC_CHECK(nn <= (size_t)1 << 31, ctx, MPMC_ERR_ARG, "grid would have %zu nodes (h = %g too small)",
             nn, h);
  mpmc_grid_free(g);
  memset(g, 0, sizeof *g);
  g->dim = dim;
  g->h = h;
  g->inv_h = 1.0 / h;
  for (int a = 0; a < 3; ++a) {
    g->n[a] = n[a];
    g->lo[a] = a < dim ? lo[a] : 0.0;
    g->hi[a] = a < dim ? lo[a] + (n[a] - 1 - 2 * MPMC_GHOST) * h : 0.0;
    g->origin[a] = a < dim ? lo[a] - MPMC_GHOST * h : 0.0;
  }
  g->nn = nn;
  g->valid = 1;
  return MPMC_SUCCESS;
}

static int alloc_d(mpmc_context ctx, double **a, size_t n) {
  if (*a) return MPMC_SUCCESS;
  *a = calloc(n, sizeof(double));
  MPMC_CHECK(*a, ctx, MPMC_ERR_MEMORY, "cannot allocate %zu grid values", n);
  return MPMC_SUCCESS;
}

int mpmc_grid_alloc(mpmc_context ctx, mpmc_grid *g, int with_fbar) {
  const size_t nn = g->nn, d = (size_t)g->dim;
  MPMC_CALL(alloc_d(ctx, &g->mass, nn));
  MPMC_CALL(alloc_d(ctx, &g->mom, nn * d));
  MPMC_CALL(alloc_d(ctx, &g->force, nn * d));
  if (with_fbar) {
    MPMC_CALL(alloc_d(ctx, &g->vol, nn));
    MPMC_CALL(alloc_d(ctx, &g->jv, nn));
  }
  if (!g->fixed) {
    g->fixed = calloc(nn, sizeof *g->fixed);
    MPMC_CHECK(g->fixed, ctx, MPMC_ERR_MEMORY, "cannot allocate %zu grid flags", nn);
  }
  return MPMC_SUCCESS;
}

void mpmc_grid_clear(mpmc_grid *g, int with_fbar) {
  const size_t nn = g->nn, d = (size_t)g->dim;
  memset(g->mass, 0, nn * sizeof(double));
  memset(g->mom, 0, nn * d * sizeof(double));
  memset(g->force, 0, nn * d * sizeof(double));
  if (with_fbar) {
    memset(g->vol, 0, nn * sizeof(double));
    memset(g->jv, 0, nn * sizeof(double));
  }
}

void mpmc_grid_free(mpmc_grid *g) {
  free(g->mass);
  free(g->mom);
  free(g->force);
  free(g->vol);
  free(g->jv);
  free(g->fixed);
  g->mass = g->mom = g->force = g->vol = g->jv = NULL;
  g->fixed = NULL;
}
