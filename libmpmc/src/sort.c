/* Sorting the material points by grid cell (locality of P2G and G2P; issue 6).
 *
 * The step's transfers visit the points slab by slab (p2g.c) and each point touches the
 * nodes around its cell.  Points that share a cell are then best stored together: their
 * stencils hit the same cache lines of the grid, and the slab order reads the particle
 * arrays in runs instead of at random.  As a run goes on, points flow away from where they
 * were seeded and the store loses that order; mpmc_sim_sort_particles restores it by a
 * stable counting sort on the cell, with the slab axis (mpmc_slab_axis: z, or y in 2D, when
 * the points span enough cell planes along it, else their longest extent; as p2g.c picks it)
 * outermost and the others in the grid's memory order, so that a slab is one contiguous run
 * of points and consecutive points mostly step along x, where node records are contiguous;
 * within a cell the points go by the half of the cell they lie in along each axis, the same
 * order in every cell (the kernels' branches then repeat).
 *
 * Every per-point array moves with the points: the fields, the material ids, the friction
 * anchors of the rigid bodies, the user materials' state, and the particle sets' indices are
 * renumbered.  ids[i] (mpmc_sim_get_particle_ids) is the index point i had when it was
 * added, so callers can follow a point across sorts.  Off by default (the library never
 * renumbers points behind a caller's back); mpmc_sim_set_sort_interval turns it on.  The
 * sort is deterministic and does not depend on the thread count; it changes results only
 * through the summation order at the nodes. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "mpmc_impl.h"
#include "sets.h"

/* ids[i] = i for points that have no id yet (the first call, or points added since) */
static int ensure_ids(mpmc_sim sim) {
  mpmc_particles *p = &sim->p;
  if (p->id) return MPMC_SUCCESS;
  const int cap = p->cap > 0 ? p->cap : 1;
  p->id = malloc(sizeof(int) * (size_t)cap);
  MPMC_CHECK(p->id, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the ids of %d points", cap);
  for (int q = 0; q < p->n; ++q) p->id[q] = q;
  return MPMC_SUCCESS;
}

/* a[perm[i]] -> a[i] for [n][nc] doubles, through tmp (room for n * w doubles), w columns at
 * a time: every column block is read in full before it is written back */
static void permute_doubles(double *a, int nc, const int *perm, int n, double *tmp, int w) {
  for (int c0 = 0; c0 < nc; c0 += w) {
    const int nb = nc - c0 < w ? nc - c0 : w;
    for (size_t i = 0; i < (size_t)n; ++i) {
      const double *src = a + (size_t)perm[i] * nc + c0;
      for (int k = 0; k < nb; ++k) tmp[i * nb + k] = src[k];
    }
    for (size_t i = 0; i < (size_t)n; ++i)
      for (int k = 0; k < nb; ++k) a[i * nc + c0 + k] = tmp[i * nb + k];
  }
}

static void permute_ints(int *a, const int *perm, int n, double *tmp) {
  for (int i = 0; i < n; ++i) tmp[i] = (double)a[perm[i]];
  for (int i = 0; i < n; ++i) a[i] = (int)tmp[i];
}

/* The sort keys of every point: its cell (key[q], exact in a double) and which half of the
 * cell it lies in along each axis (half[q], 0 .. 2^dim - 1), the box [clo, chi] of the cells.
 * The halves order the points of a cell alike in every cell, so the kernels' branches (the
 * B-spline stencil starts at the cell below or at the cell itself, uGIMP's four cases) repeat
 * from cell to cell and predict well. */
static int point_keys(mpmc_const_sim sim, double *key, double *half, int *clo, int *chi) {
  const mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim, n = p->n;
  for (int a = 0; a < 3; ++a) {
    clo[a] = a < d ? g->n[a] : 0;
    chi[a] = a < d ? -1 : 0;
  }
  /* the held cell coordinate (points stay inside the grid, the step checks; clamped for
   * safety); subtracting the held grid's offset is exact */
#define CELL_OF(q, a, s, c)                                                                  \
  const double s = (p->x[(size_t)(q) * d + (a)] - g->origin[a]) * g->inv_h - g->off[a];    \
  const int c = s >= 0.0 ? (s < g->n[a] - 1 ? (int)s : g->n[a] - 2) : 0
  for (int q = 0; q < n; ++q)
    for (int a = 0; a < d; ++a) {
      CELL_OF(q, a, s, c);
      clo[a] = c < clo[a] ? c : clo[a];
      chi[a] = c > chi[a] ? c : chi[a];
    }
  /* axis order, most significant first: the slab axis (P2G's), then the others from the
   * outermost in */
  const int ax = mpmc_slab_axis(d, clo, chi);
  int ord[3], k = 0;
  ord[k++] = ax;
  for (int a = d - 1; a >= 0; --a)
    if (a != ax) ord[k++] = a;
  for (int q = 0; q < n; ++q) {
    double kq = 0.0;
    int hq = 0;
    for (int j = 0; j < d; ++j) {
      const int a = ord[j];
      CELL_OF(q, a, s, c);
      kq = kq * (double)(chi[a] - clo[a] + 1) + (double)(c - clo[a]);
      hq = 2 * hq + (s - c >= 0.5);
    }
    key[q] = kq;
    half[q] = hq;
  }
#undef CELL_OF
  return ax;
}

/**
 * @brief Sort the material points by grid cell now (see the file's comment): every per-point
 *        array is permuted, particle sets renumbered, and the ids (mpmc_sim_get_particle_ids)
 *        follow the points.  Pointers from mpmc_sim_get_field stay valid (in place).
 */
int mpmc_sim_sort_particles(mpmc_sim sim) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  mpmc_particles *p = &sim->p;
  const int n = p->n, d = sim->cfg.dim;
  MPMC_CHECK(sim->grid.valid, ctx, MPMC_ERR_STATE, "sort: set the grid first");
  MPMC_CALL(ensure_ids(sim));
  if (n < 2) {
    sim->sort_last = sim->stats.steps;
    return MPMC_SUCCESS;
  }
  /* scratch: the step's dF array (free between steps) when it is there, else a buffer */
  double *tmp = p->dF;
  int w = d * d;
  double *own = NULL;
  if (!tmp) {
    own = malloc(sizeof(double) * 3 * (size_t)n);
    MPMC_CHECK(own, ctx, MPMC_ERR_MEMORY, "sort: cannot allocate scratch for %d points", n);
    tmp = own;
    w = 3;
  }
  /* the permutation (new index -> old) in the slab order array, which the next step's slab
   * build overwrites anyway */
  if (n > sim->scr.cap_order) {
    int *o = realloc(sim->scr.order, sizeof(int) * (size_t)n);
    if (!o) {
      free(own);
      return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "sort: cannot allocate the order of %d points", n);
    }
    sim->scr.order = o;
    sim->scr.cap_order = n;
  }
  int *perm = sim->scr.order;
  sim->scr.order_ident = 0; /* until the next slab build */
  int clo[3], chi[3];
  double *key = tmp, *half = tmp + n, *first = tmp + 2 * (size_t)n; /* w >= 3 columns */
  sim->sort_axis = point_keys(sim, key, half, clo, chi);
  size_t ncell = 1;
  for (int a = 0; a < d; ++a) ncell *= (size_t)(chi[a] - clo[a] + 1);
  int *cnt = calloc(ncell + 1, sizeof *cnt);
  if (!cnt) {
    free(own);
    return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "sort: cannot allocate %zu cell counts", ncell);
  }
  /* least significant key first: by half, then (stable) by cell */
  int hcnt[9] = {0};
  for (int q = 0; q < n; ++q) hcnt[(int)half[q] + 1]++;
  for (int c = 0; c < 8; ++c) hcnt[c + 1] += hcnt[c];
  for (int q = 0; q < n; ++q) first[hcnt[(int)half[q]]++] = q;
  for (int q = 0; q < n; ++q) cnt[(size_t)key[q] + 1]++;
  for (size_t c = 0; c < ncell; ++c) cnt[c + 1] += cnt[c];
  for (int i = 0; i < n; ++i) {
    const int q = (int)first[i];
    perm[cnt[(size_t)key[q]]++] = q;
  }
  free(cnt);
  int moved = 0;
  for (int i = 0; i < n && !moved; ++i) moved = perm[i] != i;
  if (moved) {
    struct {
      double *a;
      int nc;
    } f[] = {{p->x, d},      {p->x0, d},         {p->v, d},      {p->m, 1},
             {p->vol0, 1},   {p->J, 1},          {p->stress, 6}, {p->Jbar, 1},
             {p->Janc, 1},   {p->be, 6},         {p->eps_p, 1},  {p->lp, 1},     {p->region, 1},  {p->Jp, 1},  {p->pw, 1},
             {p->force, d},  {p->cforce, d},     {p->ustate, p->nustate}};
    for (size_t k = 0; k < sizeof f / sizeof f[0]; ++k)
      if (f[k].a && f[k].nc > 0) permute_doubles(f[k].a, f[k].nc, perm, n, tmp, w);
    permute_ints(p->mat, perm, n, tmp);
    permute_ints(p->id, perm, n, tmp);
    if (sim->bodies)
      for (int b = 0; b < sim->bodies->n; ++b) {
        mpmc_body *B = &sim->bodies->b[b];
        if (!B->anchor) continue;
        const int e = mpmc_contact_grow_anchors(sim, B); /* points added since the last pass */
        if (e) {
          free(own);
          return e;
        }
        permute_doubles(B->anchor, 3, perm, n, tmp, w);
      }
    if (sim->sets && sim->sets->n > 0) { /* old index -> new, then renumber */
      for (int i = 0; i < n; ++i) tmp[perm[i]] = (double)i;
      for (int k = 0; k < sim->sets->n; ++k) {
        mpmc_set *s = &sim->sets->s[k];
        for (int j = 0; j < s->n; ++j) s->idx[j] = (int)tmp[s->idx[j]];
      }
    }
  }
  free(own);
  sim->sort_last = sim->stats.steps;
  return MPMC_SUCCESS;
}

/**
 * @brief Sort the points by cell every nsteps steps (0: never, the default).  The step sorts
 *        before its first phase when nsteps steps have passed since the last sort (or none
 *        was done), so a run's first step sorts.
 */
int mpmc_sim_set_sort_interval(mpmc_sim sim, int nsteps) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(nsteps >= 0, sim->ctx, MPMC_ERR_ARG, "sort interval = %d steps must be >= 0 (0: never)",
             nsteps);
  sim->cfg.sort_every = nsteps;
  return MPMC_SUCCESS;
}

int mpmc_sim_get_sort_interval(mpmc_const_sim sim, int *nsteps) {
  if (!sim || !nsteps) return MPMC_ERR_ARG;
  *nsteps = sim->cfg.sort_every;
  return MPMC_SUCCESS;
}

/** @brief ids[i]: the index point i had when it was added (i itself until a sort moved it). */
int mpmc_sim_get_particle_ids(mpmc_sim sim, const int **ids) {
  if (!sim || !ids) return MPMC_ERR_ARG;
  MPMC_CALL(ensure_ids(sim));
  *ids = sim->p.id;
  return MPMC_SUCCESS;
}

/* step.c: sort before the step when the interval has passed */
int mpmc_sort_due(mpmc_sim sim) {
  if (sim->cfg.sort_every <= 0) return MPMC_SUCCESS;
  const int64_t since = sim->stats.steps - sim->sort_last;
  /* also soon after the slab axis changed (the last step's slab build chose another than the
   * sort's, as a collapsing body gets flatter): the storage order then no longer follows the
   * slabs; at most one such sort per tenth of the interval, should the axis go back and forth */
  const int flip = sim->sort_axis >= 0 && sim->scr.slab_axis != sim->sort_axis &&
                   since >= (sim->cfg.sort_every + 9) / 10;
  if (sim->sort_last >= 0 && since < sim->cfg.sort_every && !flip) return MPMC_SUCCESS;
  return mpmc_sim_sort_particles(sim);
}
