/* The geostatic state at once (mpmc_sim_set_geostatic_stress): each point's vertical stress
 * from the weight of the material above it in its column, sigma_v = -g sum m / A, the
 * horizontal ones K0 times it (in effective stress under a water table for the effective
 * models), and the elastic strain that carries it.  Columns are bins of the points' own
 * spacing over the horizontal axes, so a sloping surface gives each column its own
 * overburden.  Over MPI no rank sees every point: the column width, the median spacing, is
 * found by a bisection over the ranks' counts (mpmc_dd_kth), and each column is summed on one
 * rank (column mod ranks), which the points' masses are sent to and which sends each its
 * vertical stress back (mpmc_dd_exchange): O(own points) a rank, the same sums in the same
 * order as in one process. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

/* a point as its column's rank sees it */
typedef struct {
  long col;      /* column index over the horizontal axes */
  double z;      /* elevation                              */
  long long id;  /* global id: ties in elevation           */
  double m;      /* mass                                   */
} entry;

typedef struct {
  long col;
  double z;
  long long id;
  int k; /* the entry */
} key;

static int by_column_top_down(const void *a, const void *b) {
  const key *x = a, *y = b;
  if (x->col != y->col) return x->col < y->col ? -1 : 1;
  if (x->z != y->z) return x->z > y->z ? -1 : 1;
  return x->id < y->id ? -1 : x->id > y->id;
}

/* The total vertical stress of every entry (sv[k]) from the masses above it in its column,
 * the column summed top down (elevation, then id). */
static int overburden(mpmc_context ctx, const entry *e, int n, double g, double area, double *sv) {
  key *k = malloc(sizeof *k * (size_t)(n > 0 ? n : 1));
  MPMC_CHECK(k, ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", n);
  for (int i = 0; i < n; ++i) k[i] = (key){e[i].col, e[i].z, e[i].id, i};
  qsort(k, (size_t)n, sizeof *k, by_column_top_down);
  double above = 0.0; /* mass above in the current column */
  for (int i = 0; i < n; ++i) {
    if (i == 0 || k[i].col != k[i - 1].col) above = 0.0;
    const double mk = e[k[i].k].m;
    sv[k[i].k] = -g * (above + 0.5 * mk) / area; /* total, compression < 0 */
    above += mk;
  }
  free(k);
  return MPMC_SUCCESS;
}

/* Each point's total vertical stress sv[q] from its column's overburden: the entries go to
 * their column's rank (column mod ranks), which sums its columns and sends each entry's
 * stress back the way it came (collective; in one process all columns here). */
static int column_stress(mpmc_sim sim, const entry *mine, int n, double g, double area, double *sv) {
  mpmc_context ctx = sim->ctx;
  const int P = mpmc_dd_ranks(sim);
  const size_t nn = (size_t)(n > 0 ? n : 1);
  int *count = calloc(3 * (size_t)P, sizeof *count), *pos = malloc(sizeof *pos * nn);
  entry *out = malloc(sizeof *out * nn);
  int err = mpmc_dd_agree(sim, count && pos && out ? MPMC_SUCCESS
                                                   : MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", n));
  void *got = NULL;
  double *col_sv = NULL, *back = NULL;
  int nr = 0, nb = 0;
  if (!err) { /* rank after rank; pos[q]: the entry's place */
    int *first = count + P, *rcount = count + 2 * P;
    for (int q = 0; q < n; ++q) count[pos[q] = (int)(((mine[q].col % P) + P) % P)]++;
    for (int r = 1; r < P; ++r) first[r] = first[r - 1] + count[r - 1];
    for (int q = 0; q < n; ++q) out[pos[q] = first[pos[q]]++] = mine[q];
    err = mpmc_dd_exchange(sim, out, count, sizeof *out, &got, rcount, &nr);
    if (!err) {
      col_sv = malloc(sizeof *col_sv * (size_t)(nr > 0 ? nr : 1));
      err = col_sv ? overburden(ctx, got, nr, g, area, col_sv)
                   : MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", nr);
      err = mpmc_dd_agree(sim, err);
    }
    if (!err) err = mpmc_dd_exchange(sim, col_sv, rcount, sizeof *col_sv, (void **)&back, count, &nb);
    for (int q = 0; !err && q < n; ++q) sv[q] = back[pos[q]];
  }
  free(count);
  free(pos);
  free(out);
  free(got);
  free(col_sv);
  free(back);
  return err;
}

/**
 * @brief Set every soil point's stress to the geostatic state under the current gravity
 *        (along the last axis): sigma_v from the overburden of its column, sigma_h = K0
 *        sigma_v, in effective stress (sigma' = sigma + p) for the effective models under a
 *        water table; plane strain: sigma_zz from zero elastic out-of-plane strain.  The
 *        elastic strain b_e follows (Hencky).  Points of models without Hencky elasticity
 *        (Neo-Hookean, fluids, user stress functions) are left as they are.
 * @param k0 the coefficient of earth pressure at rest, > 0
 */
int mpmc_sim_set_geostatic_stress(mpmc_sim sim, double k0) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  const int d = sim->cfg.dim, v = d - 1;
  MPMC_CHECK(isfinite(k0) && k0 > 0, ctx, MPMC_ERR_ARG,
             "geostatic stress: K0 = %g must be > 0", k0);
  const double g = -sim->cfg.gravity[v];
  for (int a = 0; a < v; ++a)
    MPMC_CHECK(sim->cfg.gravity[a] == 0.0, ctx, MPMC_ERR_ARG,
               "geostatic stress: gravity must point along -%c (component %d is %g)", "xyz"[v], a,
               sim->cfg.gravity[a]);
  MPMC_CHECK(g > 0, ctx, MPMC_ERR_ARG,
             "geostatic stress: gravity along %c is %g: set a downward gravity first", "xyz"[v],
             sim->cfg.gravity[v]);
  MPMC_CALL(mpmc_sim_prepare(sim));
  mpmc_particles *p = &sim->p;
  const int n = p->n;
  int err = n > 0 && !p->be ? MPMC_ERROR(ctx, MPMC_ERR_STATE, "geostatic stress: no soil material "
                                         "(Hencky elasticity)")
                            : MPMC_SUCCESS;
  const size_t nn = (size_t)(n > 0 ? n : 1);
  double *sv = malloc(sizeof *sv * nn);
  entry *mine = malloc(sizeof *mine * nn);
  if (!err && !(sv && mine))
    err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", n);
  double total = n; /* points over the ranks (exact in a double) */
  if (!(err = mpmc_dd_agree(sim, err))) mpmc_dd_sum(sim, &total, 1);
  if (!err && total > 0) {
    /* the column width: the median spacing of the points */
    for (int q = 0; q < n; ++q) sv[q] = pow(p->vol0[q], 1.0 / d);
    const double w = mpmc_dd_kth(sim, sv, n, (long long)total / 2), area = d == 3 ? w * w : w;
    const mpmc_grid *gr = &sim->grid;
    const long nx = (long)ceil((gr->hi[0] - gr->lo[0]) / w) + 1;
    for (int q = 0; q < n; ++q) {
      const double *x = p->x + (size_t)q * d;
      long col = (long)floor((x[0] - gr->lo[0]) / w);
      if (d == 3) col += nx * (long)floor((x[1] - gr->lo[1]) / w);
      mine[q] = (entry){col, x[v], p->id ? p->id[q] : q, p->m[q]};
    }
    err = column_stress(sim, mine, n, g, area, sv);
  }
  for (int q = 0; !err && total > 0 && q < n; ++q) {
    const mpmc_material *m = &sim->mats[p->mat[q]];
    if (!(m->model->flags & MPMC_MODEL_HENCKY)) continue;
    const double pw = p->pw && (m->model->flags & MPMC_MODEL_EFFECTIVE) ? p->pw[q] : 0.0;
    /* the skeleton's stress (effective where the model is) and the elastic strain of it */
    const double ev = sv[q] + pw, eh = k0 * ev;
    const double ez = d == 3 ? eh : m->nu * (eh + ev);
    const double s[3] = {eh, d == 3 ? eh : ev, d == 3 ? ev : ez};
    const double tr = s[0] + s[1] + s[2];
    double *be = p->be + (size_t)q * 6, *st = p->stress + (size_t)q * 6;
    for (int a = 0; a < 3; ++a) {
      const double eps = (s[a] - tr / 3.0) / (2.0 * m->G) + tr / (9.0 * m->K);
      be[a] = exp(2.0 * eps);
      be[a + 3] = 0.0;
      st[a] = s[a] - pw;
      st[a + 3] = 0.0;
    }
    if (d == 2) be[2] = 1.0; /* no elastic out-of-plane strain: sigma_zz = nu (sigma_xx + sigma_yy) */
  }
  free(sv);
  free(mine);
  return err;
}
