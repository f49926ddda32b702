/* Seeding without gmsh: lattice points of the sim's grid inside a box or a polygon.
 * Points sit at cell-centred sub-lattice positions lo + (m + 1/2) h/ppc with volume
 * (h/ppc)^dim, so a grid-aligned region gets exactly its area (volume) back. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom.h"
#include "seed.h"

int mpmc_lattice_init(mpmc_sim sim, const double *bblo, const double *bbhi, int ppc,
                      const char *what, mpmc_lattice *lat) {
  mpmc_context ctx = sim->ctx;
  const mpmc_grid *g = &sim->grid;
  memset(lat, 0, sizeof *lat);
  MPMC_CHECK(g->valid, ctx, MPMC_ERR_STATE, "%s: set the grid before seeding", what);
  MPMC_CHECK(ppc >= 1 && ppc <= 16, ctx, MPMC_ERR_ARG,
             "%s: points per cell per axis ppc = %d must be in [1, 16]", what, ppc);
  const int d = sim->cfg.dim;
  const double tol = 1e-9 * g->h;
  lat->dim = d;
  lat->ppc = ppc;
  lat->dx = g->h / ppc;
  size_t total = 1;
  for (int a = 0; a < 3; ++a) {
    lat->m0[a] = 0;
    lat->nm[a] = 1;
    lat->glo[a] = a < d ? g->lo[a] : 0.0;
  }
  for (int a = 0; a < d; ++a) {
    MPMC_CHECK(isfinite(bblo[a]) && isfinite(bbhi[a]) && bbhi[a] >= bblo[a], ctx, MPMC_ERR_ARG,
               "%s: axis %d: hi = %g must be >= lo = %g", what, a, bbhi[a], bblo[a]);
    MPMC_CHECK(bblo[a] >= g->lo[a] - tol && bbhi[a] <= g->hi[a] + tol, ctx, MPMC_ERR_OUTSIDE,
               "%s: region [%g, %g] on axis %d is outside the grid box [%g, %g]", what, bblo[a],
               bbhi[a], a, g->lo[a], g->hi[a]);
    const long last = lround((g->hi[a] - g->lo[a]) / lat->dx) - 1;
    long m0 = (long)ceil((bblo[a] - g->lo[a]) / lat->dx - 0.5);
    long m1 = (long)floor((bbhi[a] - g->lo[a]) / lat->dx - 0.5);
    if (m0 < 0) m0 = 0;
    if (m1 > last) m1 = last;
    lat->m0[a] = m0;
    lat->nm[a] = m1 >= m0 ? m1 - m0 + 1 : 0;
    total *= (size_t)lat->nm[a];
  }
  MPMC_CHECK(total <= (size_t)INT32_MAX, ctx, MPMC_ERR_ARG,
             "%s: %zu lattice points in the region's bounding box: ppc = %d too large", what,
             total, ppc);
  lat->mark = calloc(total > 0 ? total : 1, 1);
  MPMC_CHECK(lat->mark, ctx, MPMC_ERR_MEMORY, "%s: cannot allocate %zu lattice marks", what, total);
  return MPMC_SUCCESS;
}

int mpmc_lattice_range(const mpmc_lattice *lat, const double *lo, const double *hi, long *m0,
                       long *m1) {
  for (int a = 0; a < 3; ++a) m0[a] = m1[a] = 0;
  for (int a = 0; a < lat->dim; ++a) {
    /* a small margin: the inclusion test decides points on the element's boundary */
    long l = (long)ceil((lo[a] - lat->glo[a]) / lat->dx - 0.5 - 1e-9) - lat->m0[a];
    long u = (long)floor((hi[a] - lat->glo[a]) / lat->dx - 0.5 + 1e-9) - lat->m0[a];
    if (l < 0) l = 0;
    if (u > lat->nm[a] - 1) u = lat->nm[a] - 1;
    if (u < l) return 0;
    m0[a] = l;
    m1[a] = u;
  }
  return 1;
}

void mpmc_lattice_free(mpmc_lattice *lat) {
  free(lat->mark);
  lat->mark = NULL;
}

int mpmc_lattice_add(mpmc_sim sim, mpmc_lattice *lat, int material, const char *what, int *first,
                     int *count) {
  mpmc_context ctx = sim->ctx;
  const int d = lat->dim;
  const size_t total = (size_t)lat->nm[0] * (size_t)lat->nm[1] * (size_t)lat->nm[2];
  size_t n = 0;
  for (size_t i = 0; i < total; ++i) n += lat->mark[i];
  if (n == 0) {
    mpmc_lattice_free(lat);
    return MPMC_ERROR(ctx, MPMC_ERR_ARG,
                      "%s: no lattice point (spacing %g) falls inside the region: refine the grid "
                      "or raise ppc",
                      what, lat->dx);
  }
  double *x = malloc(sizeof(double) * n * (size_t)d);
  double *vol = malloc(sizeof(double) * n);
  if (!x || !vol) {
    free(x);
    free(vol);
    mpmc_lattice_free(lat);
    return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "%s: cannot allocate %zu points", what, n);
  }
  const double v = pow(lat->dx, d);
  size_t q = 0;
  long m[3];
  for (m[2] = 0; m[2] < lat->nm[2]; ++m[2])
    for (m[1] = 0; m[1] < lat->nm[1]; ++m[1])
      for (m[0] = 0; m[0] < lat->nm[0]; ++m[0]) {
        if (!lat->mark[mpmc_lattice_index(lat, m)]) continue;
        mpmc_lattice_point(lat, m, x + q * (size_t)d);
        vol[q++] = v;
      }
  mpmc_lattice_free(lat);
  const int err = mpmc_sim_add_particles(sim, (int)n, x, vol, material, first);
  free(x);
  free(vol);
  if (err) return err;
  if (count) *count = (int)n;
  return MPMC_SUCCESS;
}

/**
 * @brief Seed the box [lo, hi] with ppc x ppc (x ppc) lattice points per grid cell.
 * @param lo,hi the box [dim values each], inside the grid box
 * @param ppc points per cell per axis (1..16)
 * @param material the points' material id
 * @param[out] first index of the first new point (may be NULL)
 * @param[out] count number of points added (may be NULL)
 */
int mpmc_sim_seed_box(mpmc_sim sim, const double *lo, const double *hi, int ppc, int material,
                      int *first, int *count) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(lo && hi, sim->ctx, MPMC_ERR_ARG, "seed box: lo/hi arrays are NULL");
  MPMC_CHECK(material >= 0 && material < sim->nmat, sim->ctx, MPMC_ERR_ARG,
             "seed box: material id %d does not exist (%d materials)", material, sim->nmat);
  mpmc_lattice lat;
  MPMC_CALL(mpmc_lattice_init(sim, lo, hi, ppc, "seed box", &lat));
  /* every lattice point of the box's index range lies in the box */
  const size_t total = (size_t)lat.nm[0] * (size_t)lat.nm[1] * (size_t)lat.nm[2];
  memset(lat.mark, 1, total);
  return mpmc_lattice_add(sim, &lat, material, "seed box", first, count);
}

/* Distance from (px, py) to the segment a-b. */
static double segment_distance(const double *a, const double *b, double px, double py) {
  const double ex = b[0] - a[0], ey = b[1] - a[1], l2 = ex * ex + ey * ey;
  double t = l2 > 0 ? ((px - a[0]) * ex + (py - a[1]) * ey) / l2 : 0.0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return hypot(px - a[0] - t * ex, py - a[1] - t * ey);
}

/* The closed polygon: points on an edge (within tol) count as inside, which is what gives
 * the paper's 5,776 points for Cook's membrane (32 lattice points lie on its top edge);
 * otherwise the crossing-number test (even-odd rule), either orientation. */
static int in_polygon(int nv, const double *xy, double px, double py, double tol) {
  for (int i = 0, j = nv - 1; i < nv; j = i++)
    if (segment_distance(xy + 2 * j, xy + 2 * i, px, py) <= tol) return 1;
  int in = 0;
  for (int i = 0, j = nv - 1; i < nv; j = i++) {
    const double xi = xy[2 * i], yi = xy[2 * i + 1], xj = xy[2 * j], yj = xy[2 * j + 1];
    if ((yi > py) != (yj > py) && px < xj + (py - yj) * (xi - xj) / (yi - yj)) in = !in;
  }
  return in;
}

/**
 * @brief 2D: seed the simple polygon xy[2*nvert] (either orientation) with ppc x ppc
 *        lattice points per grid cell, kept where they fall inside (even-odd rule).
 * Volumes are (h/ppc)^2 per unit thickness; a grid-aligned polygon gets its area exactly.
 */
int mpmc_sim_seed_polygon(mpmc_sim sim, int nvert, const double *xy, int ppc, int material,
                          int *first, int *count) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(sim->cfg.dim == 2, ctx, MPMC_ERR_ARG, "seed polygon: needs a 2D simulation (dim = %d)",
             sim->cfg.dim);
  MPMC_CHECK(nvert >= 3, ctx, MPMC_ERR_ARG, "seed polygon: nvert = %d must be >= 3", nvert);
  MPMC_CHECK(xy, ctx, MPMC_ERR_ARG, "seed polygon: vertex array xy is NULL");
  MPMC_CHECK(material >= 0 && material < sim->nmat, ctx, MPMC_ERR_ARG,
             "seed polygon: material id %d does not exist (%d materials)", material, sim->nmat);
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, area2 = 0.0;
  for (int i = 0; i < nvert; ++i) {
    for (int a = 0; a < 2; ++a) {
      const double c = xy[2 * i + a];
      MPMC_CHECK(isfinite(c), ctx, MPMC_ERR_ARG, "seed polygon: vertex %d coordinate %d = %g", i,
                 a, c);
      if (c < lo[a]) lo[a] = c;
      if (c > hi[a]) hi[a] = c;
    }
    const int j = (i + 1) % nvert;
    area2 += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
  }
  if (nvert <= 4096) /* O(n^2): simple polygons only (the even-odd rule would seed holes) */
    for (int i = 0; i < nvert; ++i)
      for (int j = i + 2; j < nvert; ++j) {
        if (i == 0 && j == nvert - 1) continue; /* adjacent through the closing edge */
        /* proper crossings only */
        MPMC_CHECK(!mpmc_segments_cross(xy + 2 * i, xy + 2 * ((i + 1) % nvert), xy + 2 * j,
                                        xy + 2 * ((j + 1) % nvert), 0),
                   ctx, MPMC_ERR_ARG, "seed polygon: edges %d and %d cross (not a simple polygon)",
                   i, j);
      }
  MPMC_CHECK(fabs(area2) > 1e-14 * (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1), ctx, MPMC_ERR_ARG,
             "seed polygon: the %d vertices enclose no area", nvert);
  mpmc_lattice lat;
  MPMC_CALL(mpmc_lattice_init(sim, lo, hi, ppc, "seed polygon", &lat));
  long m[3] = {0, 0, 0};
  for (m[1] = 0; m[1] < lat.nm[1]; ++m[1])
    for (m[0] = 0; m[0] < lat.nm[0]; ++m[0]) {
      double x[2];
      mpmc_lattice_point(&lat, m, x);
      lat.mark[mpmc_lattice_index(&lat, m)] = (unsigned char)in_polygon(nvert, xy, x[0], x[1], 1e-9 * lat.dx);
    }
  return mpmc_lattice_add(sim, &lat, material, "seed polygon", first, count);
}
