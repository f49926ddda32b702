/* A water table: steady hydrostatic pore pressure below a piezometric line (2D, and 3D
 * across y) or plane (3D), p = gamma_w max(0, h(x) - z).  The effective-stress models
 * (MPMC_MODEL_EFFECTIVE) subtract p from the normal stresses they compute from the
 * skeleton's strains, so that the stress carried (and written) is the total one; points below
 * the table weigh their material's saturated density.  No flow: the table stays where it was
 * set as the soil moves through it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

/* the piezometric elevation at horizontal position (x, y) */
static double head(const mpmc_water_table *wt, double x, double y) {
  if (wt->kind == MPMC_WATER_PLANE) return wt->plane[0] + wt->plane[1] * x + wt->plane[2] * y;
  const double *v = wt->xh;
  const int n = wt->n;
  if (x <= v[0]) return v[1];
  if (x >= v[2 * (n - 1)]) return v[2 * (n - 1) + 1];
  int lo = 0, hi = n - 1; /* v[2 lo] <= x < v[2 hi] */
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (v[2 * mid] <= x) lo = mid; else hi = mid;
  }
  const double t = (x - v[2 * lo]) / (v[2 * hi] - v[2 * lo]);
  return v[2 * lo + 1] + t * (v[2 * hi + 1] - v[2 * lo + 1]);
}

double mpmc_water_pressure(const mpmc_water_table *wt, int dim, const double *x) {
  if (wt->kind == MPMC_WATER_NONE) return 0.0;
  const double h = head(wt, x[0], dim == 3 ? x[1] : 0.0), z = x[dim - 1];
  return h > z ? wt->gamma_w * (h - z) : 0.0;
}

void mpmc_water_update(struct mpmc_sim_s *sim) {
  mpmc_particles *p = &sim->p;
  if (!p->pw) return;
  const int d = sim->cfg.dim;
  const mpmc_water_table *wt = &sim->wt;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) p->pw[q] = mpmc_water_pressure(wt, d, p->x + (size_t)q * d);
}

double mpmc_water_density(const struct mpmc_sim_s *sim, const mpmc_material *m, const double *x) {
  if (sim->wt.kind == MPMC_WATER_NONE) return m->rho;
  const double h = head(&sim->wt, x[0], sim->cfg.dim == 3 ? x[1] : 0.0);
  return x[sim->cfg.dim - 1] < h ? m->rho_sat : m->rho;
}

int mpmc_water_set(struct mpmc_sim_s *sim, int kind, int n, const double *xh,
                   const double *plane, double gamma_w, int masses) {
  mpmc_context ctx = sim->ctx;
  mpmc_water_table *wt = &sim->wt;
  double *v = NULL;
  if (kind == MPMC_WATER_POLYLINE) {
    MPMC_CHECK(n >= 1 && xh, ctx, MPMC_ERR_ARG, "water table: %d vertices: give at least one", n);
    for (int i = 0; i < n; ++i) {
      MPMC_CHECK(isfinite(xh[2 * i]) && isfinite(xh[2 * i + 1]), ctx, MPMC_ERR_ARG,
                 "water table: vertex %d = (%g, %g) is not finite", i, xh[2 * i], xh[2 * i + 1]);
      MPMC_CHECK(i == 0 || xh[2 * i] > xh[2 * (i - 1)], ctx, MPMC_ERR_ARG,
                 "water table: vertex %d: x = %g must exceed the previous vertex's x = %g", i,
                 xh[2 * i], xh[2 * (i - 1)]);
    }
    v = malloc(sizeof *v * 2 * (size_t)n);
    MPMC_CHECK(v, ctx, MPMC_ERR_MEMORY, "water table: cannot allocate %d vertices", n);
    memcpy(v, xh, sizeof *v * 2 * (size_t)n);
  } else if (kind == MPMC_WATER_PLANE) {
    MPMC_CHECK(sim->cfg.dim == 3, ctx, MPMC_ERR_ARG,
               "water table: a plane h = a + b x + c y is for 3D scenes (2D: a polyline)");
    MPMC_CHECK(isfinite(plane[0]) && isfinite(plane[1]) && isfinite(plane[2]), ctx, MPMC_ERR_ARG,
               "water table: plane (%g, %g, %g) is not finite", plane[0], plane[1], plane[2]);
  }
  if (kind != MPMC_WATER_NONE)
    MPMC_CHECK(isfinite(gamma_w) && gamma_w > 0, ctx, MPMC_ERR_ARG,
               "water table: unit weight of water gamma_w = %g N/m^3 must be > 0", gamma_w);
  free(wt->xh);
  *wt = (mpmc_water_table){.kind = kind, .n = kind == MPMC_WATER_POLYLINE ? n : 0, .xh = v,
                           .gamma_w = gamma_w};
  if (kind == MPMC_WATER_PLANE) memcpy(wt->plane, plane, sizeof wt->plane);
  mpmc_particles *p = &sim->p;
  if (kind == MPMC_WATER_NONE) {
    free(p->pw);
    p->pw = NULL;
  } else if (p->cap) {
    MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->pw, 1, 0.0));
  }
  const int d = sim->cfg.dim;
  if (masses)
    for (int q = 0; q < p->n; ++q)
      p->m[q] = mpmc_water_density(sim, &sim->mats[p->mat[q]], p->x + (size_t)q * d) * p->vol0[q];
  mpmc_water_update(sim);
  return MPMC_SUCCESS;
}

/**
 * @brief Set a water table from a polyline of piezometric elevations (mpmc.h); n = 0 removes
 *        it.  The points' masses follow: rho_sat below the table, rho above.
 * @param xh n pairs (x, h), x increasing
 * @param gamma_w unit weight of water [N/m^3], > 0 (9810 for fresh water under 9.81 m/s^2)
 */
int mpmc_sim_set_water_table(mpmc_sim sim, int n, const double *xh, double gamma_w) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(n >= 0, sim->ctx, MPMC_ERR_ARG, "water table: n = %d vertices must be >= 0", n);
  return mpmc_water_set(sim, n ? MPMC_WATER_POLYLINE : MPMC_WATER_NONE, n, xh, NULL, gamma_w, 1);
}

/**
 * @brief Set a 3D water table on the piezometric plane h = a + b x + c y (mpmc.h).
 */
int mpmc_sim_set_water_table_plane(mpmc_sim sim, double a, double b, double c, double gamma_w) {
  if (!sim) return MPMC_ERR_ARG;
  const double pl[3] = {a, b, c};
  return mpmc_water_set(sim, MPMC_WATER_PLANE, 0, NULL, pl, gamma_w, 1);
}
