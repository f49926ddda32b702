/* The geostatic state at once (mpmc_sim_set_geostatic_stress): each point's vertical stress
 * from the weight of the material above it in its column, sigma_v = -g sum m / A, the
 * horizontal ones K0 times it (in effective stress under a water table for the effective
 * models), and the elastic strain that carries it.  Columns are bins of the points' own
 * spacing over the horizontal axes, so a sloping surface gives each column its own
 * overburden. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

typedef struct {
  long col;      /* column index over the horizontal axes */
  double z;      /* elevation                              */
  int q;         /* point                                  */
} entry;

static int by_column_top_down(const void *a, const void *b) {
  const entry *x = a, *y = b;
  if (x->col != y->col) return x->col < y->col ? -1 : 1;
  return x->z > y->z ? -1 : x->z < y->z ? 1 : x->q - y->q;
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
  const int d = sim->dim, v = d - 1;
  MPMC_CHECK(isfinite(k0) && k0 > 0, ctx, MPMC_ERR_ARG,
             "geostatic stress: K0 = %g must be > 0", k0);
  const double g = -sim->gravity[v];
  for (int a = 0; a < v; ++a)
    MPMC_CHECK(sim->gravity[a] == 0.0, ctx, MPMC_ERR_ARG,
               "geostatic stress: gravity must point along -%c (component %d is %g)", "xyz"[v], a,
               sim->gravity[a]);
  MPMC_CHECK(g > 0, ctx, MPMC_ERR_ARG,
             "geostatic stress: gravity along %c is %g: set a downward gravity first", "xyz"[v],
             sim->gravity[v]);
  /* a column's overburden and the median spacing are over points other ranks may hold */
  MPMC_CHECK(mpmc_dd_ranks(sim) == 1, ctx, MPMC_ERR_UNSUPPORTED,
             "geostatic stress (initial_stress.k0) is not available over MPI (%d ranks) yet: "
             "initialise the stresses with a gravity stage instead", mpmc_dd_ranks(sim));
  MPMC_CALL(mpmc_sim_prepare(sim));
  mpmc_particles *p = &sim->p;
  const int n = p->n;
  if (n == 0) return MPMC_SUCCESS;
  MPMC_CHECK(p->be, ctx, MPMC_ERR_STATE, "geostatic stress: no soil material (Hencky elasticity)");
  /* the column width: the median spacing of the points, vol0^(1/d) */
  double *sp = malloc(sizeof *sp * (size_t)n);
  entry *e = malloc(sizeof *e * (size_t)n);
  if (!sp || !e) {
    free(sp);
    free(e);
    return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "geostatic stress: out of memory for %d points", n);
  }
  for (int q = 0; q < n; ++q) sp[q] = pow(p->vol0[q], 1.0 / d);
  qsort(sp, (size_t)n, sizeof *sp, by_double);
  const double w = sp[n / 2], area = d == 3 ? w * w : w;
  free(sp);
  const mpmc_grid *gr = &sim->grid;
  const long nx = (long)ceil((gr->hi[0] - gr->lo[0]) / w) + 1;
  for (int q = 0; q < n; ++q) {
    const double *x = p->x + (size_t)q * d;
    long col = (long)floor((x[0] - gr->lo[0]) / w);
    if (d == 3) col += nx * (long)floor((x[1] - gr->lo[1]) / w);
    e[q] = (entry){col, x[v], q};
  }
  qsort(e, (size_t)n, sizeof *e, by_column_top_down);
  double above = 0.0; /* mass above in the current column */
  for (int k = 0; k < n; ++k) {
    if (k == 0 || e[k].col != e[k - 1].col) above = 0.0;
    const int q = e[k].q;
    const double sv = -g * (above + 0.5 * p->m[q]) / area; /* total, compression < 0 */
    above += p->m[q];
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
  return MPMC_SUCCESS;
}
