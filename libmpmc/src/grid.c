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
    g->n[a] = g->ng[a] = n[a];
    g->lo[a] = a < dim ? lo[a] : 0.0;
    g->hi[a] = a < dim ? lo[a] + (n[a] - 1 - 2 * MPMC_GHOST) * h : 0.0;
    g->origin[a] = a < dim ? lo[a] - MPMC_GHOST * h : 0.0;
  }
  g->nn = nn;
  g->valid = 1;
  return MPMC_SUCCESS;
}

int mpmc_grid_span(mpmc_grid *g, int a, int lo, int hi) {
  lo = lo < 0 ? 0 : lo;
  hi = hi > g->ng[a] - 1 ? g->ng[a] - 1 : hi;
  if (lo == g->off[a] && hi - lo + 1 == g->n[a]) return 0;
  mpmc_grid_free(g); /* the arrays' layout changes: mpmc_grid_alloc makes them anew */
  g->off[a] = lo;
  g->n[a] = hi - lo + 1;
  g->nn = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
  g->lin = g->off[0] + (long long)g->n[0] * (g->off[1] + (long long)g->n[1] * g->off[2]);
  for (int b = 0; b < 3; ++b) g->act_lo[b] = g->act_hi[b] = 0; /* nothing scattered yet */
  g->rows_skip = 0;
  return 1;
}

/* Zeroed, 64-byte aligned (a node record is then one cache line); nothing if *a is set. */
int mpmc_grid_array(mpmc_context ctx, double **a, size_t n) {
  if (*a) return MPMC_SUCCESS;
  const size_t bytes = (n * sizeof(double) + 63) / 64 * 64;
  void *m = NULL;
  MPMC_CHECK(posix_memalign(&m, 64, bytes) == 0, ctx, MPMC_ERR_MEMORY,
             "cannot allocate %zu grid values", n);
  memset(m, 0, bytes);
  *a = m;
  return MPMC_SUCCESS;
}

/** Every row of the box [act_lo, act_hi) active over the box's whole x range. */
void mpmc_grid_rows_full(mpmc_grid *g) {
  if (!g->rowx) return;
  for (int k = g->act_lo[2]; k < g->act_hi[2]; ++k)
    for (int j = g->act_lo[1]; j < g->act_hi[1]; ++j) {
      int *rx = g->rowx + 2 * ((size_t)j + (size_t)g->n[1] * (size_t)k);
      rx[0] = g->act_lo[0];
      rx[1] = g->act_hi[0];
    }
}

static void set_active_all(mpmc_grid *g) {
  for (int a = 0; a < 3; ++a) {
    g->act_lo[a] = 0;
    g->act_hi[a] = g->n[a];
  }
  mpmc_grid_rows_full(g);
}

int mpmc_grid_alloc(mpmc_context ctx, mpmc_grid *g) {
  const size_t nn = g->nn;
  MPMC_CALL(mpmc_grid_array(ctx, &g->node, nn * MPMC_NREC));
  if (!g->rowx) {
    g->rowx = malloc(sizeof(int) * 2 * (size_t)g->n[1] * (size_t)g->n[2]);
    MPMC_CHECK(g->rowx, ctx, MPMC_ERR_MEMORY, "cannot allocate the ranges of %d grid rows",
               g->n[1] * g->n[2]);
    mpmc_grid_rows_full(g); /* a box set before (mpmc_grid_clear) gets its rows */
  }
  if (!g->fixed) {
    g->fixed = calloc(nn, sizeof *g->fixed);
    MPMC_CHECK(g->fixed, ctx, MPMC_ERR_MEMORY, "cannot allocate %zu grid flags", nn);
  }
  return MPMC_SUCCESS;
}

void mpmc_grid_clear(mpmc_grid *g) {
  memset(g->node, 0, g->nn * MPMC_NREC * sizeof(double));
  /* conservative: callers that clear by hand may then scatter anywhere */
  set_active_all(g);
}

/* Zero the active box's rows of node on all threads: a serial memset of the landslide's box,
 * ~12 MB, was half of the step's slab phase on two threads. */
void mpmc_grid_clear_active(mpmc_grid *g) {
  const long nrow = mpmc_grid_active_rows(g);
  const long box = (long)(g->act_hi[0] - g->act_lo[0]);
  double *node = g->node;
#pragma omp parallel for schedule(static) if (nrow * box > MPMC_OMP_MIN)
  for (long r = 0; r < nrow; ++r) {
    size_t len;
    const size_t first = mpmc_grid_active_row(g, r, &len);
    memset(node + first * MPMC_NREC, 0, len * MPMC_NREC * sizeof(double));
  }
}

void mpmc_grid_free(mpmc_grid *g) {
  free(g->node);
  free(g->priv);
  free(g->fixed);
  free(g->ccount);
  free(g->rowx);
  free(g->rscratch);
  g->rowx = g->rscratch = NULL;
  g->cap_rscratch = 0;
  g->node = g->priv = NULL;
  g->fixed = NULL;
  g->ccount = NULL;
  g->cap_ccount = g->cap_priv = 0;
  g->nprivate = 0;
}

/* ncopies zeroed copies of a grid array of width doubles per node in *buf (grown as needed;
 * NULL when they would exceed 256 MiB or cannot be had: the caller then uses its colours) */
double *mpmc_grid_copies(const mpmc_grid *g, double **buf, size_t *cap, int width, int ncopies) {
  const size_t len = g->nn * (size_t)width * (size_t)ncopies;
  if (len * sizeof(double) > ((size_t)256 << 20)) return NULL;
  if (len > *cap) {
    free(*buf);
    *buf = calloc(len, sizeof(double));
    *cap = *buf ? len : 0;
  }
  return *buf;
}

/* dst += the copies over the active box, in copy order, and the copies back to zero */
void mpmc_grid_add_copies(const mpmc_grid *g, double *dst, double *copies, int width,
                          int ncopies) {
  const size_t per = g->nn * (size_t)width;
  const long nrow = mpmc_grid_active_rows(g);
  const long box = (long)(g->act_hi[0] - g->act_lo[0]) * width;
#pragma omp parallel for schedule(static) if (nrow * box > MPMC_OMP_MIN)
  for (long r = 0; r < nrow; ++r) {
    size_t nodes;
    const size_t first = mpmc_grid_active_row(g, r, &nodes) * (size_t)width;
    const size_t len = nodes * (size_t)width;
    double *restrict d = dst + first;
    for (int t = 0; t < ncopies; ++t) {
      double *restrict src = copies + per * (size_t)t + first;
      for (size_t i = 0; i < len; ++i) d[i] += src[i];
      memset(src, 0, len * sizeof(double));
    }
  }
}
