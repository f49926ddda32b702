/* Particle to grid: mass (eq 7), momentum (eq 8), internal force (eq 10) and the points'
 * external forces.  Threads scatter without atomics: the points are bucketed by slab
 * (mpmc_slabs_build) and the slabs of one parity run in parallel, then the other parity;
 * a body too small for that scatters into one grid per thread (private_grids). */
#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include "transfer.h"

/* The x range of cells cx .. cx (one point) or of a run into the cell row's entry e[0..1]. */
static inline void widen_row(int *restrict e, int lo, int hi) {
  e[0] = lo < e[0] ? lo : e[0];
  e[1] = hi > e[1] ? hi : e[1];
}

/* mpmc_slabs_build's first pass over points q0 .. q1 - 1 (one chunk): their cells' box into box
 * (lo[3], hi[3]), each point's plane along axis ax into plane, the points per plane added to
 * ct, and (ROWS) the x range of the cells holding points per cell row (cy + n1 cz) widened
 * into rx[2 row ..]; DIM and ROWS constants, so that the axes unroll. */
MPMC_ALWAYS_INLINE void count_chunk(const int DIM, const int ROWS, const mpmc_grid *g,
                                    const double *xs, int q0, int q1, int ax,
                                    int *restrict plane, int *restrict ct, int *restrict box,
                                    int *restrict rx) {
  int lo[3] = {INT_MAX, INT_MAX, INT_MAX}, hi[3] = {-1, -1, -1};
  double o[3] = {0.0, 0.0, 0.0};
  for (int a = 0; a < DIM; ++a) o[a] = g->origin[a];
  const double ih = g->inv_h;
#if defined(__AVX2__) /* the axes in the lanes of one vector: the same operations per lane */
  const __m256i in = _mm256_set_epi64x(0, DIM == 3 ? -1 : 0, -1, -1); /* the point's axes */
  const __m256d ov = _mm256_set_pd(0.0, o[2], o[1], o[0]), ihv = _mm256_set1_pd(ih);
  const __m128i axv = _mm_set1_epi32(ax), offv = _mm_set_epi32(0, g->off[2], g->off[1], g->off[0]);
  __m128i lov = _mm_set1_epi32(INT_MAX), hiv = _mm_set1_epi32(-1);
#endif
  int cur = -1, run = 0; /* runs of one plane (sorted points) counted in a register */
  int crow = -1, rlo = 0, rhi = 0; /* and runs of one cell row, their x range likewise */
  const int n1 = g->n[1];
  for (int q = q0; q < q1; ++q) {
    const double *x = xs + (size_t)q * DIM;
#if defined(__AVX2__)
    const __m128i cv = _mm_sub_epi32(
        _mm256_cvttpd_epi32(_mm256_mul_pd(_mm256_sub_pd(_mm256_maskload_pd(x, in), ov), ihv)),
        offv); /* the held cells' (grid.off) */
    lov = _mm_min_epi32(lov, cv);
    hiv = _mm_max_epi32(hiv, cv);
    const int pl = _mm_cvtsi128_si32(
        _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(cv), axv)));
    const int cx = _mm_cvtsi128_si32(cv), cy = _mm_extract_epi32(cv, 1);
    const int row = DIM == 3 ? cy + n1 * _mm_extract_epi32(cv, 2) : cy;
#else
    int c[3] = {0, 0, 0};
    for (int a = 0; a < DIM; ++a) {
      c[a] = (int)((x[a] - o[a]) * ih) - g->off[a]; /* the held cells' (grid.off) */
      lo[a] = c[a] < lo[a] ? c[a] : lo[a];
      hi[a] = c[a] > hi[a] ? c[a] : hi[a];
    }
    const int pl = ax == 0 ? c[0] : ax == 1 ? c[1] : c[2];
    const int cx = c[0], row = DIM == 3 ? c[1] + n1 * c[2] : c[1];
#endif
    if (ROWS && row != crow) {
      if (crow >= 0) widen_row(rx + 2 * crow, rlo, rhi);
      crow = row;
      rlo = rhi = cx;
    } else if (ROWS) {
      rlo = cx < rlo ? cx : rlo;
      rhi = cx > rhi ? cx : rhi;
    }
    plane[q] = pl;
    if (pl != cur) {
      if (run) ct[cur] += run;
      cur = pl;
      run = 0;
    }
    ++run;
  }
  if (run) ct[cur] += run;
  if (ROWS && crow >= 0) widen_row(rx + 2 * crow, rlo, rhi);
#if defined(__AVX2__)
  int lv[4], hv[4];
  _mm_storeu_si128((__m128i *)lv, lov);
  _mm_storeu_si128((__m128i *)hv, hiv);
  for (int a = 0; a < DIM; ++a) {
    lo[a] = lv[a];
    hi[a] = hv[a];
  }
#endif
  for (int a = 0; a < 3; ++a) {
    box[a] = lo[a];
    box[3 + a] = hi[a];
  }
}

/* The active box's row ranges (grid.rowx) from the chunks' cell-row ranges in rscratch, the
 * points' cells spanning [clo, chi]: node row (j, k) holds the stencils (nodes c - 1 .. c + 2
 * along each axis, as the box) of the points in the cell rows j - 2 .. j + 1, k - 2 .. k + 1,
 * so its range is theirs widened by one node below and two above.  Ranges holding more than
 * MPMC_ROWS_DENSE of the box (a compact body: the 3D column's 100 %, the landslide's 86 % at
 * the run-out's start) save less than their bookkeeping costs (10 instructions a point on
 * the column): the next MPMC_ROWS_SKIP steps then take the whole box, as before. */
#define MPMC_ROWS_DENSE 0.8
#define MPMC_ROWS_SKIP 15
static void row_ranges(mpmc_grid *g, int d, int nc, const int *clo, const int *chi) {
  const int n1 = g->n[1];
  const size_t nrows = (size_t)n1 * (size_t)g->n[2];
  int *rx0 = g->rscratch;
  const int zlo = d == 3 ? clo[2] : 0, zhi = d == 3 ? chi[2] : 0;
  for (int t = 1; t < nc; ++t) {
    const int *rx = g->rscratch + 2 * nrows * (size_t)t;
    for (int cz = zlo; cz <= zhi; ++cz)
      for (int cy = clo[1]; cy <= chi[1]; ++cy) {
        const size_t r = (size_t)cy + (size_t)n1 * (size_t)cz;
        widen_row(rx0 + 2 * r, rx[2 * r], rx[2 * r + 1]);
      }
  }
  long held = 0;
  for (int k = g->act_lo[2]; k < g->act_hi[2]; ++k)
    for (int j = g->act_lo[1]; j < g->act_hi[1]; ++j) {
      int lo = INT_MAX, hi = -1;
      const int z0 = d == 3 && k - 2 > zlo ? k - 2 : zlo, z1 = d == 3 && k + 1 < zhi ? k + 1 : zhi;
      const int y0 = j - 2 > clo[1] ? j - 2 : clo[1], y1 = j + 1 < chi[1] ? j + 1 : chi[1];
      for (int cz = z0; cz <= z1; ++cz)
        for (int cy = y0; cy <= y1; ++cy) {
          const int *e = rx0 + 2 * ((size_t)cy + (size_t)n1 * (size_t)cz);
          lo = e[0] < lo ? e[0] : lo;
          hi = e[1] > hi ? e[1] : hi;
        }
      int *out = g->rowx + 2 * ((size_t)j + (size_t)n1 * (size_t)k);
      if (hi < 0) { /* no point's stencil reaches this row */
        out[0] = out[1] = g->act_lo[0];
      } else {
        out[0] = lo - 1 > g->act_lo[0] ? lo - 1 : g->act_lo[0];
        out[1] = hi + 3 < g->act_hi[0] ? hi + 3 : g->act_hi[0];
        held += out[1] - out[0];
      }
    }
  if (held > MPMC_ROWS_DENSE * (double)mpmc_grid_active_rows(g) * (g->act_hi[0] - g->act_lo[0]))
    g->rows_skip = MPMC_ROWS_SKIP;
}

/* Each colour's slabs split among the nt threads in runs of consecutive slabs, balanced by
 * points: a slab goes to the thread whose share of the colour's points (its t-th nt-th)
 * holds the slab's middle point.  The runs, not a dynamic schedule, hand out the slabs, so that a thread
 * takes the same slabs every step while the points stay where they are, and (the points
 * sorted with the slab axis outermost, sort.c) about the points that it updates in G2P's
 * and the stress update's index ranges: its points and nodes are in its own core's caches
 * from the phase before.  With the slabs handed out as threads came free, two threads on
 * the 3D column (64,000 points) took longer in G2P than one: each phase fetched most of its
 * data from the other core.  The results do not depend on the runs (slabs of a colour share
 * no node). */
static int slab_groups(mpmc_sim sim, int nt) {
  const int ns = sim->scr.nslab, *start = sim->scr.slab_start;
  const size_t need = 2 * ((size_t)nt + 1);
  if (need > (size_t)sim->scr.cap_group) {
    int *gr = realloc(sim->scr.slab_group, sizeof(int) * need);
    MPMC_CHECK(gr, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the slab runs of %d threads", nt);
    sim->scr.slab_group = gr;
    sim->scr.cap_group = (int)need;
  }
  sim->scr.slab_nt = nt;
  for (int c = 0; c < 2; ++c) {
    int *gr = sim->scr.slab_group + c * (nt + 1);
    long total = 0, sum = 0;
    for (int sl = c; sl < ns; sl += 2) total += start[sl + 1] - start[sl];
    int t = 0, sl = c;
    gr[t++] = c;
    for (; sl < ns; sl += 2) {
      const long k = start[sl + 1] - start[sl];
      /* thread t's run starts here if its share begins in this slab's first half or before */
      while (t < nt && 2 * nt * sum + nt * k >= 2 * total * t) gr[t++] = sl;
      sum += k;
    }
    while (t <= nt) gr[t++] = sl; /* the colour's end */
  }
  return MPMC_SUCCESS;
}

/* Bucket the points into slabs of whole cell planes along one axis (a counting sort of
 * indices, by plane and within a plane by index; the particle arrays themselves are not
 * moved here: sort.c does that, every sort_interval steps when the caller asks for it), and
 * set the grid's active box to the nodes the points' stencils reach.  Visiting a plane's
 * points in index order (particle arrays in order, grid at random when the points are
 * shuffled) was faster than by cell (grid in order, particle arrays at random) on the 3D
 * column; sorted points are in both orders at once.
 * Slabs of one parity run in parallel: a point in cell c touches nodes c-1 .. c+2 at most
 * (cubic), so two slabs with one slab of at least MPMC_SLAB_W = 3 cells between them share no
 * node.  The slab boundaries balance the points: about 2 x threads slabs or a multiple, so
 * each thread gets the same share of each colour (fixed-width slabs left one of two threads
 * idle for a third of P2G in the 3D column).  Results depend on the thread count only
 * through the summation order at the nodes that two slabs share (at every node when the
 * threads scatter into grids of their own, private_grids).
 * Both passes over the points run on all threads, each over a fixed chunk of them: the
 * first finds the box and counts the points per plane of the slab axis (the last step's
 * axis; counted again in the rare step where mpmc_slab_axis picks another for the box), the
 * second places them.  Each point's plane is kept in between in dF, which is free from the
 * end of one step's material update until its G2P (sort.c uses it likewise).  The order
 * does not depend on the chunks, so neither on the thread count. */
int MPMC_ISA(mpmc_slabs_build)(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim, n = p->n;
  if (n == 0) {
    for (int a = 0; a < 3; ++a) g->act_lo[a] = g->act_hi[a] = 0;
    sim->scr.nslab = 0;
    return slab_groups(sim, mpmc_max_threads()); /* empty runs, for one thread or more */
  }
  MPMC_CHECK(p->dF, sim->ctx, MPMC_ERR_STATE, "slabs: the points' fields are not allocated");
  if (n > sim->scr.cap_order) {
    int *o = realloc(sim->scr.order, sizeof(int) * (size_t)n);
    MPMC_CHECK(o, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the slab order of %d points", n);
    sim->scr.order = o;
    sim->scr.cap_order = n;
  }
  const int nt = mpmc_max_threads();
  const int nc = n > MPMC_OMP_MIN ? nt : 1; /* chunks */
  int nmax = 1;
  for (int a = 0; a < d; ++a) nmax = g->n[a] > nmax ? g->n[a] : nmax;
  /* counts per chunk and plane, [nc][nmax], then the chunks' fill positions; the chunks'
   * boxes [nc][6] */
  const size_t need = (size_t)nc * (size_t)nmax + 6 * (size_t)nc;
  if (need > g->cap_ccount) {
    int *c = realloc(g->ccount, sizeof(int) * need);
    MPMC_CHECK(c, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate %zu plane counts", need);
    g->ccount = c;
    g->cap_ccount = need;
  }
  int *cnt = g->ccount, *box = cnt + (size_t)nc * nmax;
  /* per chunk the x range of the cells of each cell row, [nc][n1 n2][2] */
  const size_t nrows = (size_t)g->n[1] * (size_t)g->n[2], rneed = 2 * nrows * (size_t)nc;
  if (rneed > g->cap_rscratch) {
    int *r = realloc(g->rscratch, sizeof(int) * rneed);
    MPMC_CHECK(r, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the ranges of %zu cell rows", nrows);
    g->rscratch = r;
    g->cap_rscratch = rneed;
  }
  int *plane = (int *)(void *)p->dF;
  /* the row ranges pay where the box is sparse; where they held most of it they are taken
   * as the whole box for the next MPMC_ROWS_SKIP steps (safe: a superset) */
  const int rows = g->rows_skip <= 0;
  int clo[3] = {0, 0, 0}, chi[3] = {0, 0, 0};
  int ax = sim->scr.slab_axis >= 0 && sim->scr.slab_axis < d ? sim->scr.slab_axis : d - 1;
  for (int pass = 0; pass < 2; ++pass) {
    /* the cells holding points (the points stay within one cell of the box, g2p checks, well
     * inside the ghost layers, so the cell coordinates are positive) and the plane counts */
#pragma omp parallel for schedule(static, 1) num_threads(nc) if (nc > 1)
    for (int t = 0; t < nc; ++t) {
      int *ct = cnt + (size_t)t * nmax, *rx = g->rscratch + 2 * nrows * (size_t)t;
      for (int k = 0; k < nmax; ++k) ct[k] = 0;
      for (size_t r = 0; r < (rows ? nrows : 0); ++r) {
        rx[2 * r] = INT_MAX;
        rx[2 * r + 1] = -1;
      }
      const int q0 = mpmc_chunk_start(n, t, nc), q1 = mpmc_chunk_start(n, t + 1, nc);
      int *bt = box + 6 * t;
      if (d == 3 && rows)
        count_chunk(3, 1, g, p->x, q0, q1, ax, plane, ct, bt, rx);
      else if (d == 3)
        count_chunk(3, 0, g, p->x, q0, q1, ax, plane, ct, bt, rx);
      else if (rows)
        count_chunk(2, 1, g, p->x, q0, q1, ax, plane, ct, bt, rx);
      else
        count_chunk(2, 0, g, p->x, q0, q1, ax, plane, ct, bt, rx);
    }
    for (int a = 0; a < d; ++a) {
      clo[a] = INT_MAX;
      chi[a] = -1;
      for (int t = 0; t < nc; ++t) {
        clo[a] = box[6 * t + a] < clo[a] ? box[6 * t + a] : clo[a];
        chi[a] = box[6 * t + 3 + a] > chi[a] ? box[6 * t + 3 + a] : chi[a];
      }
    }
    const int best = mpmc_slab_axis(d, clo, chi);
    if (best == ax) break;
    ax = best; /* the box calls for another axis: count along that one */
  }
  for (int a = 0; a < 3; ++a) {
    const int lo = a < d ? clo[a] - 1 : 0, hi = a < d ? chi[a] + 3 : 1;
    g->act_lo[a] = lo < 0 ? 0 : lo;
    g->act_hi[a] = hi > g->n[a] ? g->n[a] : hi;
  }
  if (rows) {
    row_ranges(g, d, nc, clo, chi);
  } else {
    mpmc_grid_rows_full(g);
    --g->rows_skip;
  }
  const int np = chi[ax] - clo[ax] + 1; /* planes */
  const int per = np / (MPMC_SLAB_W * 2 * nt);
  const double share = (double)n / (2 * nt * (per < 1 ? 1 : per));
  const int cap = np / MPMC_SLAB_W + 2;
  if (cap > sim->scr.cap_slab) {
    int *st = realloc(sim->scr.slab_start, sizeof(int) * (size_t)cap);
    MPMC_CHECK(st, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate %d slabs", cap);
    sim->scr.slab_start = st;
    sim->scr.cap_slab = cap;
  }
  /* close a slab once it holds its share of the points and is at least MPMC_SLAB_W planes
   * wide (the last one may be narrower: no slab of its colour lies beyond it); the chunks'
   * counts become their fill positions: the points of plane pl go after those of the planes
   * before it, a chunk's after those of the chunks before it */
  int *start = sim->scr.slab_start, ns = 0, width = 0, sum = 0;
  start[0] = 0;
  for (int pl = clo[ax]; pl <= chi[ax]; ++pl) {
    for (int t = 0; t < nc; ++t) {
      int *c = cnt + (size_t)t * nmax + pl;
      const int k = *c;
      *c = sum;
      sum += k;
    }
    ++width;
    if (pl == chi[ax] || (width >= MPMC_SLAB_W && sum >= share * (ns + 1))) {
      start[++ns] = sum;
      width = 0;
    }
  }
  /* order[k] = k throughout (order_ident) when every run of points in one plane starts at
   * its own index: positions within a run follow the points' */
  int *order = sim->scr.order, ident = 1;
#pragma omp parallel for schedule(static, 1) num_threads(nc) if (nc > 1) reduction(& : ident)
  for (int t = 0; t < nc; ++t) {
    int *fill = cnt + (size_t)t * nmax;
    const int q0 = mpmc_chunk_start(n, t, nc), q1 = mpmc_chunk_start(n, t + 1, nc);
    if (q0 >= q1) continue; /* more threads than points to share */
    int cur = plane[q0], pos = fill[cur], same = pos == q0;
    for (int q = q0; q < q1; ++q) {
      const int pl = plane[q];
      if (pl != cur) {
        fill[cur] = pos;
        cur = pl;
        pos = fill[pl];
        same &= pos == q;
      }
      order[pos++] = q;
    }
    ident &= same;
  }
  sim->scr.order_ident = ident;
  sim->scr.nslab = ns;
  sim->scr.slab_axis = ax;
  return slab_groups(sim, nt);
}

/* Value of record slot s for mass m, momentum mv, force f (vectors of DIM) and F-bar's volume
 * vol; with DIM and s constants this folds to one of them. */
MPMC_ALWAYS_INLINE double rec_slot(const int DIM, int s, double m, const double *mv,
                                   const double *f, double vol) {
  return s == 0                               ? m
         : s <= DIM                           ? mv[s - 1]
         : s >= MPMC_FOFF && s < MPMC_FOFF + DIM ? f[s - MPMC_FOFF]
         : s == MPMC_VSLOT                    ? vol
                                              : 0.0;
}

/* Scatter point q: mass, momentum and force w m, w m v, -V sigma grad w + w f_ext, all
 * into the node records, and with F-bar's paper, total and anchored forms the volume w V^n
 * into MPMC_VSLOT (Algorithm 1 step 3's nodal volume, as the products w_x (w_y (w_z V)) that
 * fbar.c's scatter_point repeats; the other terms add exact zeros to the slot).
 * Per row of the stencil the record's increment splits as
 *   rec += w_x c + w_x' e,  c = w_y (w_z (m, m v, f_ext, V) + w_z' (-V sigma_.2))
 *                               + w_y' w_z (-V sigma_.1),
 *                           e = w_y w_z (-V sigma_.0)
 * (grad w = (w_x' w_y w_z, w_x w_y' w_z, w_x w_y w_z')), the w_z factors formed once per
 * plane of rows, c and e once per row: per node a few whole-vector multiply-adds on one
 * record. */
MPMC_ALWAYS_INLINE void p2g_point(mpmc_sim sim, const int DIM, const int BASIS,
                                   double *restrict rec, int q, const mpmc_pw4 *t, int l) {
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int R = MPMC_NREC, S = mpmc_stencil(BASIS), NV = MPMC_NV, NC = MPMC_NC, AX = MPMC_PW4_AXIS;
  const size_t qd = (size_t)q * DIM;
  const double *W = &t->w[0][0][l], *DW = &t->dw[0][0][l]; /* node k, axis a: [AX a + 4 k] */
  const double m = p->m[q];
  const double V = p->vol0[q] * p->J[q];
  const double vf = sim->cfg.fbar != MPMC_FBAR_STABLE ? V : 0.0;
  const double *s = p->stress + (size_t)q * 6;
  /* -V sigma, rows of the (symmetric) stress in the dim-dimensional subspace; being
   * symmetric, row b is also column b */
  double vs[3][3];
  vs[0][0] = -V * s[0];
  vs[1][1] = -V * s[1];
  vs[2][2] = -V * s[2];
  vs[1][2] = vs[2][1] = -V * s[3];
  vs[0][2] = vs[2][0] = -V * s[4];
  vs[0][1] = vs[1][0] = -V * s[5];
  double mv[3] = {0, 0, 0}, fe[3] = {0, 0, 0};
  for (int a = 0; a < DIM; ++a) {
    mv[a] = m * p->v[qd + a];
    if (p->force) fe[a] = p->force[qd + a];
    if (p->cforce) fe[a] += p->cforce[qd + a];
  }
  /* record-shaped factors (m, m v | f_ext) and (0, 0 | -V sigma_.b), built in registers (a
   * round trip through memory would stall on store forwarding) */
  static const double zero3[3] = {0, 0, 0};
#define MF_(sl) rec_slot(DIM, sl, m, mv, fe, vf)
#define S0_(sl) rec_slot(DIM, sl, 0.0, zero3, vs[0], 0.0)
#define S1_(sl) rec_slot(DIM, sl, 0.0, zero3, vs[1], 0.0)
#define S2_(sl) rec_slot(DIM, sl, 0.0, zero3, vs[2], 0.0)
  mpmc_vd MF[MPMC_NV], S0[MPMC_NV], S1[MPMC_NV], S2[MPMC_NV];
  for (int k = 0; k < NV; ++k) {
    MF[k] = MPMC_VSET(MF_, k);
    S0[k] = MPMC_VSET(S0_, k);
    S1[k] = MPMC_VSET(S1_, k);
    S2[k] = MPMC_VSET(S2_, k);
  }
#undef MF_
#undef S0_
#undef S1_
#undef S2_
  const size_t sy = (size_t)g->n[0], sz = (size_t)g->n[0] * (size_t)g->n[1];
  for (int kz = 0; kz < (DIM == 3 ? S : 1); ++kz) {
    /* the plane's factors: MF w_z + S2 w_z' (the latter in the force half), S1 w_z, S0 w_z
     * (in 2D the factors themselves, and the rows' sums those of the row-by-row form) */
    mpmc_vd MFz[MPMC_NV], S1z[MPMC_NV], S0z[MPMC_NV];
    if (DIM == 3) {
      const double wz = W[2 * AX + 4 * kz], dz = DW[2 * AX + 4 * kz];
      for (int k = 0; k < NC; ++k) MFz[k] = wz * MF[k];
      for (int k = NC; k < NV; ++k) {
        MFz[k] = wz * MF[k] + dz * S2[k];
        S1z[k] = wz * S1[k];
        S0z[k] = wz * S0[k];
      }
    } else {
      for (int k = 0; k < NV; ++k) MFz[k] = MF[k], S1z[k] = S1[k], S0z[k] = S0[k];
    }
    for (int j = 0; j < S; ++j) {
      const double wy = W[AX + 4 * j], dy = DW[AX + 4 * j];
      mpmc_vd c[MPMC_NV], e[MPMC_NV];
      for (int k = 0; k < NC; ++k) c[k] = wy * MFz[k];
      for (int k = NC; k < NV; ++k) {
        c[k] = wy * MFz[k] + dy * S1z[k];
        e[k] = wy * S0z[k];
      }
      double *restrict r = rec + ((size_t)t->node0[l] + sy * (size_t)j + sz * (size_t)kz) * R;
      for (int i = 0; i < S; ++i) {
        const double wx = W[4 * i], dx = DW[4 * i];
        double *ri = r + i * R;
        for (int k = 0; k < NC; ++k) MPMC_V(ri + MPMC_VW * k) += wx * c[k];
        for (int k = NC; k < NV; ++k) MPMC_V(ri + MPMC_VW * k) += wx * c[k] + dx * e[k];
      }
    }
  }
}

/* Slabs of two colours keep nt threads busy when each colour splits evenly among them.  A
 * small body spans too few cell planes for that (the 8,000-point block of bench/: ten planes,
 * slabs of 3, 3, 3 and 1 planes, so in the second colour one thread scatters 2,400 points
 * while the other has 800); then the threads scatter nc = nt consecutive chunks of the slab
 * order each into a grid of their own, chunk 0 into the grid itself, and the copies are added
 * to it (a race-free scatter by per-thread accumulation).  Taken when the colours would keep
 * the threads less than 90 % busy (a colour lasts as long as its largest slab or its share per
 * thread, whichever is longer).  The copies are whole grids, zero outside the active box (they
 * are cleared over it after each use); not taken when they would exceed 256 MiB. */
static double *private_grids(mpmc_sim sim, int nt) {
  mpmc_grid *g = &sim->grid;
  if (nt < 2 || sim->p.n <= MPMC_OMP_MIN) return NULL;
  double span = 0.0; /* the colours' duration in points */
  for (int c = 0; c < 2; ++c) {
    int total = 0, largest = 0;
    for (int sl = c; sl < sim->scr.nslab; sl += 2) {
      const int k = sim->scr.slab_start[sl + 1] - sim->scr.slab_start[sl];
      total += k;
      largest = k > largest ? k : largest;
    }
    span += fmax((double)largest, (double)total / nt);
  }
  if (sim->p.n >= 0.9 * nt * span) return NULL;
  return mpmc_grid_copies(g, &g->priv, &g->cap_priv, MPMC_NREC, nt - 1);
}

#define P2G_KERNEL(D, B)                                                                    \
  static void p2g_##D##_##B(mpmc_sim sim, double *priv, int nc) {                           \
    const int *restrict order = sim->scr.order, *restrict start = sim->scr.slab_start;      \
    double *node = sim->grid.node;                                                          \
    if (priv) {                                                                             \
      const size_t per = sim->grid.nn * MPMC_NREC;                                          \
      _Pragma("omp parallel for schedule(static, 1) num_threads(nc)")                       \
      for (int t = 0; t < nc; ++t) {                                                        \
        const int k1 = mpmc_chunk_start(sim->p.n, t + 1, nc);                               \
        double *rec = t ? priv + per * (size_t)(t - 1) : node;                              \
        MPMC_BATCHES4(0, D, B, 1, 0, NULL, &sim->grid, sim->p.x, sim->p.lp, order,          \
                      mpmc_chunk_start(sim->p.n, t, nc), k1, q, l, w4,                      \
                      p2g_point(sim, D, B, rec, q, &w4, l));                                \
      }                                                                                     \
      return;                                                                               \
    }                                                                                       \
    for (int colour = 0; colour < 2; ++colour) {                                            \
      _Pragma("omp parallel for schedule(static, 1) num_threads(sim->scr.slab_nt) if (sim->p.n > MPMC_OMP_MIN)") \
      MPMC_SLABS_OF(sim, colour, sl)                                                        \
        MPMC_BATCHES4(0, D, B, 1, 0, NULL, &sim->grid, sim->p.x, sim->p.lp, order,          \
                      start[sl], start[sl + 1], q, l, w4,                                   \
                      p2g_point(sim, D, B, node, q, &w4, l));                               \
    }                                                                                       \
  }
MPMC_KERNELS(P2G_KERNEL)

/** Phase 1 of the step: scatter the points onto the grid, after the step has cleared the
 * last step's box and built this step's slabs (mpmc_slabs_build). */
int MPMC_ISA(mpmc_p2g)(mpmc_sim sim, double dt) {
  (void)dt;
  const int nt = mpmc_max_threads();
  double *priv = private_grids(sim, nt);
  sim->grid.nprivate = priv ? nt : 0;
  MPMC_KERNEL_CALL(p2g_, sim, sim, priv, nt);
  if (priv) mpmc_grid_add_copies(&sim->grid, sim->grid.node, priv, MPMC_NREC, nt - 1);
  return MPMC_SUCCESS;
}
