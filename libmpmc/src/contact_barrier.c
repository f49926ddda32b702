/* Rigid bodies (axis-aligned boxes in 2D/3D, simple polygons in 2D) moved with a prescribed
 * velocity, in contact with the material points through the IPC barrier (Li et al. 2020;
 * Zhao et al. 2022):
 *
 *   E_p = A_p kappa b(d),  b(d) = -(d - dhat)^2 ln(d/dhat) for 0 < d < dhat, else 0,
 *   f_p = -dE_p/dx_p = A_p kappa (d - dhat) [2 ln(d/dhat) + 1 - dhat/d] n = A_p kappa dhat g(d/dhat) n
 *
 * d the signed distance of point p to the body's surface, n the body's outward normal at the
 * closest point, A_p = V0_p^((dim-1)/dim) the point's tributary contact area (a length per
 * unit thickness in 2D), so kappa is a stiffness per area per length [Pa/m] and
 * kappa dhat g(x) the contact pressure.  Coulomb friction is an elastic stick: a spring
 * and damper on the point's tangential displacement since it stuck, capped at mu times the
 * normal force (then it slides and the anchor follows).  The forces go to p->cforce, which
 * P2G adds to the external force; the body's reaction is minus their sum.  docs/contact.md
 * derives the defaults of dhat and kappa, the time-step limit and the friction law. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "geom.h"
#include "mpmc_impl.h"

/* the gap ratio x = d/dhat at which the default kappa makes the barrier's time-step limit
 * equal to the material's h/c */
#define CONTACT_X_DESIGN 0.5
/* smallest gap ratio used in the stiffness of the time-step limit */
#define CONTACT_X_FLOOR 1e-6
/* below this many points the loops run on one thread (a parallel region costs more) */
#define CONTACT_PAR_MIN 4096

/* ---- the barrier ---------------------------------------------------------------------- */
/* Pressure per kappa*dhat: g(x) = (x - 1)(2 ln x + 1 - 1/x) = -b'(d)/dhat, x = d/dhat. */
static inline double barrier_g(double x) { return (x - 1.0) * (2.0 * log(x) + 1.0 - 1.0 / x); }
/* g'(x) = 2 ln x + 1 - 1/x + (x - 1)(2/x + 1/x^2) = b''(d) with the sign of a stiffness
 * reversed: the barrier's stiffness per area is kappa |g'(x)|. */
static inline double barrier_dg(double x) {
  return 2.0 * log(x) + 1.0 - 1.0 / x + (x - 1.0) * (2.0 / x + 1.0 / (x * x));
}

/* ---- geometry ------------------------------------------------------------------------- */
/* Signed distance from x to the body (negative inside) and the outward unit normal n at the
 * closest surface point. */
static double body_gap(const mpmc_body *b, int dim, const double *xg, double *n) {
  double x[3] = {0, 0, 0};
  for (int a = 0; a < dim; ++a) x[a] = xg[a] - b->offset[a];
  if (b->kind == BODY_BOX) {
    double q[3] = {0, 0, 0}, out2 = 0.0;
    for (int a = 0; a < dim; ++a) {
      const double c = x[a] < b->lo[a] ? b->lo[a] : x[a] > b->hi[a] ? b->hi[a] : x[a];
      q[a] = x[a] - c;
      out2 += q[a] * q[a];
    }
    if (out2 > 0.0) {
      const double d = sqrt(out2);
      for (int a = 0; a < dim; ++a) n[a] = q[a] / d;
      return d;
    }
    /* inside: the nearest face */
    double best = INFINITY;
    for (int a = 0; a < dim; ++a) {
      const double dl = x[a] - b->lo[a], dh = b->hi[a] - x[a];
      if (dl < best) {
        best = dl;
        for (int c = 0; c < dim; ++c) n[c] = c == a ? -1.0 : 0.0;
      }
      if (dh < best) {
        best = dh;
        for (int c = 0; c < dim; ++c) n[c] = c == a ? 1.0 : 0.0;
      }
    }
    return -best;
  }
  /* polygon: nearest edge point; inside by the crossing number */
  const double *v = b->xy;
  double best2 = INFINITY, cx = 0.0, cy = 0.0, ex = 1.0, ey = 0.0;
  int inside = 0;
  for (int i = 0, j = b->nvert - 1; i < b->nvert; j = i++) {
    const double ax = v[2 * j], ay = v[2 * j + 1], bx = v[2 * i], by = v[2 * i + 1];
    const double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
    double t = ((x[0] - ax) * dx + (x[1] - ay) * dy) / l2;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    const double px = ax + t * dx, py = ay + t * dy;
    const double r2 = (x[0] - px) * (x[0] - px) + (x[1] - py) * (x[1] - py);
    if (r2 < best2) {
      best2 = r2;
      cx = px;
      cy = py;
      ex = dx;
      ey = dy;
    }
    if ((ay > x[1]) != (by > x[1]) && x[0] < ax + (x[1] - ay) * dx / dy) inside = !inside;
  }
  const double r = sqrt(best2);
  if (r > 0.0) {
    const double s = inside ? -1.0 : 1.0;
    n[0] = s * (x[0] - cx) / r;
    n[1] = s * (x[1] - cy) / r;
  } else { /* on the surface: the edge's outward normal (vertices counter-clockwise) */
    const double le = sqrt(ex * ex + ey * ey);
    n[0] = ey / le;
    n[1] = -ex / le;
  }
  return inside ? -r : r;
}

/* Outside the body's bounding box grown by dhat: no contact (gap >= dhat). */
static inline int far_from(const mpmc_body *b, int dim, const double *x, double dhat) {
  for (int a = 0; a < dim; ++a) {
    const double xa = x[a] - b->offset[a];
    if (xa < b->lo[a] - dhat || xa > b->hi[a] + dhat) return 1;
  }
  return 0;
}

/* ---- parameters ----------------------------------------------------------------------- */
/* Point spacing l = (mean V0)^(1/dim) (h/2 before any point exists), dhat = l/2 (the
 * point's half-width, as uGIMP's l_p) and kappa = 4 M l / (h^2 |g'(1/2)|), M = max rho c^2
 * over the materials: the barrier's time-step limit 2 sqrt(m/k) at d = dhat/2 is then
 * h/c for a point of mean size (docs/contact.md). */
static void contact_params(const struct mpmc_sim_s *sim, double *dhat, double *kappa) {
  const struct mpmc_bodies_s *H = sim->bodies;
  if (H && H->step_held) { /* within a step: mpmc_contact_step's */
    *dhat = H->step_dhat;
    *kappa = H->step_kappa;
    return;
  }
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const double h = sim->grid.h;
  double l = 0.5 * h;
  double sn[2] = {0.0, p->n}; /* the volumes' sum and the points, over the ranks over MPI */
  if (p->n > 0) {
    double s = 0.0;
#pragma omp parallel for reduction(+ : s) schedule(static) if (p->n > CONTACT_PAR_MIN)
    for (int q = 0; q < p->n; ++q) s += p->vol0[q];
    sn[0] = s;
  }
  mpmc_dd_sum(sim, sn, 2);
  if (sn[1] > 0) l = pow(sn[0] / sn[1], 1.0 / d);
  double M = 0.0;
  for (int m = 0; m < sim->nmat; ++m) {
    const double c = sim->mats[m].ops->wave_speed(&sim->mats[m]);
    const double Mm = sim->mats[m].rho * c * c;
    if (Mm > M) M = Mm;
  }
  const struct mpmc_bodies_s *B = sim->bodies;
  *dhat = B && B->dhat > 0 ? B->dhat : 0.5 * l;
  *kappa = B && B->kappa > 0 ? B->kappa
                             : 4.0 * M * l / (h * h * fabs(barrier_dg(CONTACT_X_DESIGN)));
}

/* tributary contact area of a point: V0^((dim-1)/dim) */
static inline double point_area(int dim, double vol0) {
  return dim == 2 ? sqrt(vol0) : cbrt(vol0 * vol0);
}

/* ---- internal entry points (mpmc_impl.h) ---------------------------------------------- */

int mpmc_contact_grow_anchors(struct mpmc_sim_s *sim, mpmc_body *b) {
  return mpmc_contact_reserve_anchors(sim, b, sim->p.n);
}

int mpmc_contact_reserve_anchors(struct mpmc_sim_s *sim, mpmc_body *b, int n) {
  if (b->nanchor >= n) return MPMC_SUCCESS;
  double *a = realloc(b->anchor, sizeof *a * 3 * (size_t)n);
  MPMC_CHECK(a, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate friction anchors of %d points", n);
  for (size_t i = 3 * (size_t)b->nanchor; i < 3 * (size_t)n; ++i) a[i] = NAN;
  b->anchor = a;
  b->nanchor = n;
  return MPMC_SUCCESS;
}

/* Barrier and friction forces of every active body on the points (p->cforce), the bodies'
 * reactions; then the bodies move by v dt. */
int mpmc_contact_update(struct mpmc_sim_s *sim, double dt) {
  struct mpmc_bodies_s *B = sim->bodies;
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  MPMC_CALL(mpmc_particles_ensure(sim->ctx, p, &p->cforce, d, 0.0));
  double *restrict cf = p->cforce;
  const long nd = (long)p->n * d;
#pragma omp parallel for schedule(static) if (nd > CONTACT_PAR_MIN)
  for (long i = 0; i < nd; ++i) cf[i] = 0.0;
  double dhat, kappa;
  contact_params(sim, &dhat, &kappa);
  int err = MPMC_SUCCESS;
  for (int bi = 0; bi < B->n && !err; ++bi) {
    mpmc_body *b = &B->b[bi];
    if (!b->active) continue;
    const double mu = b->mu;
    if (mu > 0.0 && (err = mpmc_contact_grow_anchors(sim, b))) break;
    double *restrict anc = mu > 0.0 ? b->anchor : NULL;
    const double vb[3] = {b->v[0], b->v[1], b->v[2]};
    double r0 = 0.0, r1 = 0.0, r2 = 0.0;
    int bad = INT_MAX;
#pragma omp parallel for schedule(static) reduction(+ : r0, r1, r2) reduction(min : bad) \
    if (p->n > CONTACT_PAR_MIN)
    for (int q = 0; q < p->n; ++q) {
      const double *x = p->x + (size_t)q * d;
      double *u = anc ? anc + 3 * (size_t)q : NULL; /* out of contact: no anchor (NaN) */
      if (far_from(b, d, x, dhat)) {
        if (u) u[0] = NAN;
        continue;
      }
      double n[3] = {0, 0, 0};
      const double gap = body_gap(b, d, x, n);
      if (!(gap > 0.0)) {
        if (q < bad) bad = q;
        continue;
      }
      if (gap >= dhat) {
        if (u) u[0] = NAN;
        continue;
      }
      /* normal force (the paper's barrier, -b'(d)) */
      const double lam = point_area(d, p->vol0[q]) * kappa * dhat * barrier_g(gap / dhat);
      double f[3] = {0, 0, 0};
      for (int a = 0; a < d; ++a) f[a] = lam * n[a];
      if (u) {
        /* Coulomb friction as an elastic stick (docs/contact.md): the anchor u is where the
         * point stuck, in the body's frame; the trial force -k s - c v_t on the tangential
         * offset s from it (k = m/(4 dt^2), c = m/(2 dt): stable in the explicit step; a
         * steady tangential load T leaves a fixed offset T/k instead of a slip rate) is
         * capped at mu lam, where the point slides and the anchor is dragged along. */
        const double *v = p->v + (size_t)q * d;
        const double k = 0.25 * p->m[q] / (dt * dt), c = 0.5 * p->m[q] / dt;
        double xb[3] = {0, 0, 0}, st[3] = {0, 0, 0}, vt[3] = {0, 0, 0}, ft[3] = {0, 0, 0};
        double vn = 0.0, sn = 0.0, f2 = 0.0;
        for (int a = 0; a < d; ++a) xb[a] = x[a] - b->offset[a];
        if (isnan(u[0]))
          for (int a = 0; a < d; ++a) u[a] = xb[a];
        for (int a = 0; a < d; ++a) {
          vn += (v[a] - vb[a]) * n[a];
          sn += (xb[a] - u[a]) * n[a];
        }
        for (int a = 0; a < d; ++a) {
          vt[a] = v[a] - vb[a] - vn * n[a];
          st[a] = xb[a] - u[a] - sn * n[a];
          ft[a] = -k * st[a] - c * vt[a];
          f2 += ft[a] * ft[a];
        }
        const double fmax = mu * lam;
        if (f2 > fmax * fmax) { /* sliding: the anchor follows so that the spring holds mu lam */
          const double sc = fmax / sqrt(f2);
          for (int a = 0; a < d; ++a) {
            ft[a] *= sc;
            u[a] = xb[a] - sn * n[a] + ft[a] / k;
          }
        }
        for (int a = 0; a < d; ++a) f[a] += ft[a];
      }
      double *c = cf + (size_t)q * d;
      for (int a = 0; a < d; ++a) c[a] += f[a];
      r0 -= f[0];
      r1 -= f[1];
      r2 -= d == 3 ? f[2] : 0.0;
    }
    if (bad != INT_MAX) {
      double n[3];
      const double *x = p->x + (size_t)bad * d;
      char nb[MPMC_POINT_NAME_LEN];
      err = MPMC_ERROR(sim->ctx, MPMC_ERR_NUMERIC,
                       "step %lld, t = %g: point %s at (%g, %g, %g) is inside rigid body %d "
                       "(gap %g <= 0)",
                       (long long)sim->stats.steps, sim->time, mpmc_point_name(p, bad, nb), x[0], x[1],
                       d == 3 ? x[2] : 0.0, bi, body_gap(b, d, x, n));
      break;
    }
    b->reaction[0] = r0;
    b->reaction[1] = r1;
    b->reaction[2] = r2;
    for (int a = 0; a < d; ++a) b->offset[a] += dt * b->v[a];
  }
  if (!sim->dd) return err;
  /* MPI: the reactions over the ranks, summed in rank order (the same bits on every rank),
   * once every rank got through */
  err = mpmc_dd_agree(sim, err);
  for (int bi = 0; bi < B->n && !err; ++bi)
    if (B->b[bi].active) mpmc_dd_sum(sim, B->b[bi].reaction, 3);
  return err;
}

/* The smallest gap of any point to body b, and that point (-1 without points): its index,
 * over MPI its global id (of the points with that gap, the least id; collective). */
static double min_gap(const struct mpmc_sim_s *sim, const mpmc_body *b, int *point) {
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  double gmin = INFINITY;
#pragma omp parallel for schedule(static) reduction(min : gmin) if (p->n > CONTACT_PAR_MIN)
  for (int q = 0; q < p->n; ++q) {
    double n[3];
    const double g = body_gap(b, d, p->x + (size_t)q * d, n);
    if (g < gmin) gmin = g;
  }
  int qmin = -1;
  if (sim->dd) {
    for (int q = 0; q < p->n; ++q) {
      double n[3];
      const int id = p->id ? p->id[q] : q;
      if (body_gap(b, d, p->x + (size_t)q * d, n) == gmin && (qmin < 0 || id < qmin)) qmin = id;
    }
    mpmc_dd_minloc(sim, &gmin, &qmin);
  }
  for (int q = 0; q < p->n && qmin < 0 && !sim->dd; ++q) {
    double n[3];
    if (body_gap(b, d, p->x + (size_t)q * d, n) == gmin) qmin = q;
  }
  if (point) *point = qmin;
  return gmin;
}

void mpmc_contact_step(struct mpmc_sim_s *sim, int begin) {
  struct mpmc_bodies_s *B = sim->bodies;
  B->step_held = 0;
  if (begin) {
    contact_params(sim, &B->step_dhat, &B->step_kappa);
    B->step_held = 1;
  }
}

/* After a step: no point may have crossed into a body (the step that did it fails). */
int mpmc_contact_check(struct mpmc_sim_s *sim) {
  const struct mpmc_bodies_s *B = sim->bodies;
  const int d = sim->cfg.dim;
  double dhat, kappa;
  contact_params(sim, &dhat, &kappa);
  for (int bi = 0; bi < B->n; ++bi) {
    const mpmc_body *b = &B->b[bi];
    if (!b->active) continue;
    int bad = INT_MAX;
#pragma omp parallel for schedule(static) reduction(min : bad) if (sim->p.n > CONTACT_PAR_MIN)
    for (int q = 0; q < sim->p.n; ++q) {
      const double *x = sim->p.x + (size_t)q * d;
      if (far_from(b, d, x, dhat)) continue;
      double n[3];
      if (!(body_gap(b, d, x, n) > 0.0) && q < bad) bad = q;
    }
    if (bad != INT_MAX) {
      double n[3];
      const double *x = sim->p.x + (size_t)bad * d;
      char nb[MPMC_POINT_NAME_LEN];
      return MPMC_ERROR(sim->ctx, MPMC_ERR_NUMERIC,
                        "step %lld, t = %g: point %s crossed into rigid body %d, now at (%g, %g, "
                        "%g) with gap %g <= 0 (barrier dhat = %g, kappa = %g): reduce the time "
                        "step (mpmc_sim_stable_dt) or the body's velocity",
                        (long long)sim->stats.steps, sim->time, mpmc_point_name(&sim->p, bad, nb), bi, x[0], x[1],
                        d == 3 ? x[2] : 0.0, body_gap(b, d, x, n), dhat, kappa);
    }
  }
  return MPMC_SUCCESS;
}

/* Time-step limit of the barrier: min over points of 2 sqrt(m / k), k = A kappa |g'(x)| the
 * barrier's stiffness at the point's gap ratio x, taken no larger than the design ratio 1/2
 * so that points about to touch are covered too.  Points inside a body are left out: the
 * step stops on them with a message that says so. */
double mpmc_contact_stable_dt(const struct mpmc_sim_s *sim) {
  const struct mpmc_bodies_s *B = sim->bodies;
  if (!B || !sim->grid.valid || sim->nmat == 0) return INFINITY;
  int any = 0;
  for (int bi = 0; bi < B->n; ++bi) any |= B->b[bi].active;
  if (!any) return INFINITY;
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  double dhat, kappa;
  contact_params(sim, &dhat, &kappa);
  /* every point but those about to touch has the design ratio's stiffness factor; and
   * 2 sqrt(.) is increasing, so the least m / k gives the least time (the same bits as the
   * least of the points' times; the loop is a pass over every point, twice a step in a
   * workflow: a log and two roots a point made it a tenth of the strip footing's run) */
  const double g_design = fabs(barrier_dg(CONTACT_X_DESIGN));
  double rmin = INFINITY;
#pragma omp parallel for schedule(static) reduction(min : rmin) if (p->n > CONTACT_PAR_MIN)
  for (int q = 0; q < p->n; ++q) {
    const double *x = p->x + (size_t)q * d;
    double xr = CONTACT_X_DESIGN;
    for (int bi = 0; bi < B->n; ++bi) {
      const mpmc_body *b = &B->b[bi];
      if (!b->active || far_from(b, d, x, dhat)) continue;
      double n[3];
      double r = body_gap(b, d, x, n) / dhat;
      if (!(r > 0.0)) continue; /* inside: the step reports it (MPMC_ERR_NUMERIC) */
      if (r < CONTACT_X_FLOOR) r = CONTACT_X_FLOOR;
      if (r < xr) xr = r;
    }
    const double g = xr == CONTACT_X_DESIGN ? g_design : fabs(barrier_dg(xr));
    const double r = p->m[q] / (point_area(d, p->vol0[q]) * kappa * g);
    if (r < rmin) rmin = r;
  }
  double neg = -rmin; /* MPI: the least over the ranks (collective) */
  mpmc_dd_max(sim, &neg, 1);
  return 2.0 * sqrt(-neg);
}

void mpmc_contact_free(struct mpmc_sim_s *sim) {
  struct mpmc_bodies_s *B = sim->bodies;
  if (!B) return;
  for (int i = 0; i < B->n; ++i) {
    free(B->b[i].xy);
    free(B->b[i].anchor);
  }
  free(B->b);
  free(B);
  sim->bodies = NULL;
}

/* ---- public API ------------------------------------------------------------------------ */
static int push_body(mpmc_sim sim, const mpmc_body *body, int *id) {
  if (!sim->bodies) {
    sim->bodies = calloc(1, sizeof *sim->bodies);
    MPMC_CHECK(sim->bodies, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the rigid bodies");
  }
  struct mpmc_bodies_s *B = sim->bodies;
  if (B->n == B->cap) {
    const int cap = B->cap ? 2 * B->cap : 4;
    mpmc_body *a = realloc(B->b, sizeof *a * (size_t)cap);
    MPMC_CHECK(a, sim->ctx, MPMC_ERR_MEMORY, "cannot add a rigid body");
    B->b = a;
    B->cap = cap;
  }
  B->b[B->n] = *body;
  if (id) *id = B->n;
  B->n++;
  return MPMC_SUCCESS;
}

static int check_mu(mpmc_sim sim, double mu) {
  MPMC_CHECK(isfinite(mu) && mu >= 0, sim->ctx, MPMC_ERR_ARG,
             "friction coefficient mu = %g must be finite and >= 0", mu);
  return MPMC_SUCCESS;
}

static int get_body(mpmc_const_sim sim, int id, mpmc_body **b) {
  const struct mpmc_bodies_s *B = sim->bodies;
  MPMC_CHECK(B && id >= 0 && id < B->n && B->b[id].active, sim->ctx, MPMC_ERR_ARG,
             "rigid body id %d does not exist or was removed (%d bodies)", id, B ? B->n : 0);
  *b = &B->b[id];
  return MPMC_SUCCESS;
}

/**
 * @brief Add a rigid axis-aligned box [lo, hi] (dim values each) that pushes material points
 *        through the barrier; it stays still until mpmc_sim_set_rigid_velocity.
 * @param mu Coulomb friction coefficient between the points and the box (>= 0; a large
 *        value makes a rough contact)
 * @param[out] id the body's id (may be NULL)
 */
int mpmc_sim_add_rigid_box(mpmc_sim sim, const double *lo, const double *hi, double mu, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(lo && hi, sim->ctx, MPMC_ERR_ARG, "rigid box lo/hi arrays are NULL");
  MPMC_CALL(check_mu(sim, mu));
  mpmc_body b = {.active = 1, .kind = BODY_BOX, .mu = mu};
  for (int a = 0; a < sim->cfg.dim; ++a) {
    MPMC_CHECK(isfinite(lo[a]) && isfinite(hi[a]) && hi[a] > lo[a], sim->ctx, MPMC_ERR_ARG,
               "rigid box axis %d: hi = %g must exceed lo = %g (both finite)", a, hi[a], lo[a]);
    b.lo[a] = lo[a];
    b.hi[a] = hi[a];
  }
  return push_body(sim, &b, id);
}

/**
 * @brief Add a rigid simple polygon (2D only) of nvert vertices xy[2*nvert], either
 *        orientation; it stays still until mpmc_sim_set_rigid_velocity.
 * @param mu Coulomb friction coefficient (>= 0)
 * @param[out] id the body's id (may be NULL)
 */
int mpmc_sim_add_rigid_polygon(mpmc_sim sim, int nvert, const double *xy, double mu, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(sim->cfg.dim == 2, ctx, MPMC_ERR_ARG,
             "rigid polygons are 2D only (dim = %d): use mpmc_sim_add_rigid_box", sim->cfg.dim);
  MPMC_CHECK(nvert >= 3, ctx, MPMC_ERR_ARG, "polygon needs nvert >= 3 vertices (got %d)", nvert);
  MPMC_CHECK(xy, ctx, MPMC_ERR_ARG, "polygon vertex array xy is NULL");
  MPMC_CALL(check_mu(sim, mu));
  double area2 = 0.0;
  for (int i = 0; i < nvert; ++i) {
    MPMC_CHECK(isfinite(xy[2 * i]) && isfinite(xy[2 * i + 1]), ctx, MPMC_ERR_ARG,
               "polygon vertex %d = (%g, %g) is not finite", i, xy[2 * i], xy[2 * i + 1]);
    const int j = (i + 1) % nvert;
    MPMC_CHECK(xy[2 * i] != xy[2 * j] || xy[2 * i + 1] != xy[2 * j + 1], ctx, MPMC_ERR_ARG,
               "polygon vertices %d and %d coincide", i, j);
    area2 += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
  }
  MPMC_CHECK(area2 != 0.0, ctx, MPMC_ERR_ARG, "polygon has zero area");
  for (int i = 0; i < nvert; ++i)
    for (int j = i + 2; j < nvert; ++j) {
      if (i == 0 && j == nvert - 1) continue; /* adjacent through the closing edge */
      const int i1 = (i + 1) % nvert, j1 = (j + 1) % nvert;
      /* touching counts: a body's boundary must not meet itself */
      MPMC_CHECK(!mpmc_segments_cross(xy + 2 * i, xy + 2 * i1, xy + 2 * j, xy + 2 * j1, 1), ctx,
                 MPMC_ERR_ARG, "polygon is not simple: edges %d-%d and %d-%d intersect", i, i1, j,
                 j1);
    }
  mpmc_body b = {.active = 1, .kind = BODY_POLYGON, .mu = mu, .nvert = nvert};
  b.xy = malloc(sizeof(double) * 2 * (size_t)nvert);
  MPMC_CHECK(b.xy, ctx, MPMC_ERR_MEMORY, "cannot allocate a polygon of %d vertices", nvert);
  b.lo[0] = b.lo[1] = INFINITY;
  b.hi[0] = b.hi[1] = -INFINITY;
  for (int i = 0; i < nvert; ++i) {
    /* store counter-clockwise so that edge normals (ey, -ex) point outwards */
    const int k = area2 > 0 ? i : nvert - 1 - i;
    b.xy[2 * i] = xy[2 * k];
    b.xy[2 * i + 1] = xy[2 * k + 1];
    for (int a = 0; a < 2; ++a) {
      if (xy[2 * k + a] < b.lo[a]) b.lo[a] = xy[2 * k + a];
      if (xy[2 * k + a] > b.hi[a]) b.hi[a] = xy[2 * k + a];
    }
  }
  const int err = push_body(sim, &b, id);
  if (err) free(b.xy);
  return err;
}

/** @brief Set the velocity v[dim] of a rigid body (it moves by v dt every step). */
int mpmc_sim_set_rigid_velocity(mpmc_sim sim, int id, const double *v) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_body *b = NULL;
  MPMC_CALL(get_body(sim, id, &b));
  MPMC_CHECK(v, sim->ctx, MPMC_ERR_ARG, "rigid body velocity array is NULL");
  for (int a = 0; a < sim->cfg.dim; ++a)
    MPMC_CHECK(isfinite(v[a]), sim->ctx, MPMC_ERR_ARG,
               "rigid body velocity component %d = %g is not finite", a, v[a]);
  for (int a = 0; a < sim->cfg.dim; ++a) b->v[a] = v[a];
  return MPMC_SUCCESS;
}

/** @brief The displacement offset[dim] of a rigid body since it was added. */
int mpmc_sim_get_rigid_offset(mpmc_const_sim sim, int id, double *offset) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_body *b = NULL;
  MPMC_CALL(get_body(sim, id, &b));
  MPMC_CHECK(offset, sim->ctx, MPMC_ERR_ARG, "offset array is NULL");
  for (int a = 0; a < sim->cfg.dim; ++a) offset[a] = b->offset[a];
  return MPMC_SUCCESS;
}

/**
 * @brief The force f[dim] the material points exerted on a rigid body in the last step
 *        (minus the sum of the contact forces on the points; per unit thickness in 2D).
 */
int mpmc_sim_get_rigid_reaction(mpmc_const_sim sim, int id, double *f) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_body *b = NULL;
  MPMC_CALL(get_body(sim, id, &b));
  MPMC_CHECK(f, sim->ctx, MPMC_ERR_ARG, "reaction array is NULL");
  for (int a = 0; a < sim->cfg.dim; ++a) f[a] = b->reaction[a];
  return MPMC_SUCCESS;
}

/**
 * @brief The smallest signed distance from any material point to a rigid body's surface
 *        (negative inside) and that point (-1 and +inf without points); over MPI the
 *        smallest over every rank's points and the point's global id (collective).
 */
int mpmc_sim_get_rigid_gap(mpmc_const_sim sim, int id, double *gap, int *point) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_body *b = NULL;
  MPMC_CALL(get_body(sim, id, &b));
  MPMC_CHECK(gap, sim->ctx, MPMC_ERR_ARG, "gap pointer is NULL");
  *gap = min_gap(sim, b, point);
  return MPMC_SUCCESS;
}

/** @brief Remove a rigid body (its id is not reused). */
int mpmc_sim_remove_rigid(mpmc_sim sim, int id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_body *b = NULL;
  MPMC_CALL(get_body(sim, id, &b));
  b->active = 0;
  return MPMC_SUCCESS;
}

/**
 * @brief Set the barrier's range dhat [m] and stiffness kappa [Pa/m] for all bodies;
 *        0 derives the default (docs/contact.md).
 */
int mpmc_sim_set_contact_params(mpmc_sim sim, double dhat, double kappa) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(dhat) && dhat >= 0, sim->ctx, MPMC_ERR_ARG,
             "barrier range dhat = %g must be finite and >= 0 (0: default)", dhat);
  MPMC_CHECK(isfinite(kappa) && kappa >= 0, sim->ctx, MPMC_ERR_ARG,
             "barrier stiffness kappa = %g must be finite and >= 0 (0: default)", kappa);
  if (!sim->bodies) {
    sim->bodies = calloc(1, sizeof *sim->bodies);
    MPMC_CHECK(sim->bodies, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the rigid bodies");
  }
  sim->bodies->dhat = dhat;
  sim->bodies->kappa = kappa;
  return MPMC_SUCCESS;
}

/** @brief The barrier's range dhat and stiffness kappa in effect (defaults resolved). */
int mpmc_sim_get_contact_params(mpmc_const_sim sim, double *dhat, double *kappa) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(sim->grid.valid, sim->ctx, MPMC_ERR_STATE,
             "the contact defaults need a grid (set it first)");
  MPMC_CHECK(sim->nmat > 0 || (sim->bodies && sim->bodies->kappa > 0), sim->ctx, MPMC_ERR_STATE,
             "the default barrier stiffness needs a material (add one first)");
  double dh, ka;
  contact_params(sim, &dh, &ka);
  if (dhat) *dhat = dh;
  if (kappa) *kappa = ka;
  return MPMC_SUCCESS;
}
