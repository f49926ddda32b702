/* The geostatic state at once (mpmc_sim_set_geostatic_stress): each point's vertical stress
 * from the weight of the material above it in its column, sigma_v = -g sum m / A, the
 * horizontal ones K0 times it (in effective stress under a water table for the effective
 * models), and the elastic strain that carries it.  Columns are bins of the points' own
 * spacing over the horizontal axes, so a sloping surface gives each column its own
 * overburden.  Over MPI every rank sees every point once (mpmc_dd_allgather) and sets its own. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

/* a point as every rank sees it: the columns and the median spacing are over all points */
typedef struct {
  double x[3];   /* position; the last axis is the elevation */
  double m;      /* mass                                      */
  double sp;     /* spacing, vol0^(1/d)                       */
  long long id;  /* global id: ties in elevation              */
} point;

typedef struct {
  long col;      /* column index over the horizontal axes */
  double z;      /* elevation                              */
  long long id;  /* global id                              */
  int k;         /* record                                 */
} entry;

static int by_column_top_down(const void *a, const void *b) {
  const entry *x = a, *y = b;
  if (x->col != y->col) return x->col < y->col ? -1 : 1;
  if (x->z != y->z) return x->z > y->z ? -1 : 1;
  return x->id < y->id ? -1 : x->id > y->id;
}

static int by_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
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
  /* over MPI a column and the median spacing take in points other ranks hold: every rank
   * sees every point (once, at initialisation) and sets its own */
  int err = n > 0 && !p->be ? MPMC_ERROR(ctx, MPMC_ERR_STATE, "geostatic stress: no soil material "
                                         "(Hencky elasticity)")
                            : MPMC_SUCCESS;
  point *mine = malloc(sizeof *mine * (size_t)(n > 0 ? n : 1));
  if (!err && !mine)
    err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", n);
  if ((err = mpmc_dd_agree(sim, err))) {
    free(mine);
    return err;
  }
  for (int q = 0; q < n; ++q) {
    point *r = mine + q;
    for (int a = 0; a < 3; ++a) r->x[a] = a < d ? p->x[(size_t)q * d + a] : 0.0;
    r->m = p->m[q];
    r->sp = pow(p->vol0[q], 1.0 / d);
    r->id = p->id ? p->id[q] : q;
  }
  void *every = NULL;
  int total = 0, off = 0;
  err = mpmc_dd_allgather(sim, mine, n, sizeof *mine, &every, &total, &off);
  free(mine);
  if (err) return err;
  const point *all = every;
  double *sp = malloc(sizeof *sp * (size_t)(total > 0 ? total : 1));
  entry *e = malloc(sizeof *e * (size_t)(total > 0 ? total : 1));
  err = sp && e ? MPMC_SUCCESS
                : MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", total);
  err = mpmc_dd_agree(sim, err);
  if (err || total == 0) {
    free(every);
    free(sp);
    free(e);
    return err;
  }
  /* the column width: the median spacing of the points */
  for (int k = 0; k < total; ++k) sp[k] = all[k].sp;
  qsort(sp, (size_t)total, sizeof *sp, by_double);
  const double w = sp[total / 2], area = d == 3 ? w * w : w;
  free(sp);
  const mpmc_grid *gr = &sim->grid;
  const long nx = (long)ceil((gr->hi[0] - gr->lo[0]) / w) + 1;
  for (int k = 0; k < total; ++k) {
    const double *x = all[k].x;
    long col = (long)floor((x[0] - gr->lo[0]) / w);
    if (d == 3) col += nx * (long)floor((x[1] - gr->lo[1]) / w);
    e[k] = (entry){col, x[v], all[k].id, k};
  }
  qsort(e, (size_t)total, sizeof *e, by_column_top_down);
  double above = 0.0; /* mass above in the current column */
  for (int k = 0; k < total; ++k) {
    if (k == 0 || e[k].col != e[k - 1].col) above = 0.0;
    const double mk = all[e[k].k].m, sv = -g * (above + 0.5 * mk) / area; /* total, compression < 0 */
    above += mk;
    const int q = e[k].k - off; /* this rank's point, or another's */
    if (q < 0 || q >= n) continue;
    const mpmc_material *m = &sim->mats[p->mat[q]];
    if (!(m->model->flags & MPMC_MODEL_HENCKY)) continue;
    const double pw = p->pw && (m->model->flags & MPMC_MODEL_EFFECTIVE) ? p->pw[q] : 0.0;
    /* the skeleton's stress (effective where the model is) and the elastic strain of it */
    const double ev = sv + pw, eh = k0 * ev;
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
  free(e);
  free(every);
  return MPMC_SUCCESS;
}
