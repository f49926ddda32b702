/* The simulation handle: set-up, material points, field access. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "kernels.h"
#include "sets.h"

/**
 * @brief Create a simulation in dim = 2 (plane strain) or 3 dimensions.
 * Defaults: quadratic B-splines, F-bar off, FLIP/PIC blend 1 (pure FLIP, paper eq 13),
 * no gravity, no damping, solver auto.
 */
int mpmc_sim_create(mpmc_context ctx, int dim, mpmc_sim *sim) {
  if (!ctx || !sim) return ctx ? MPMC_ERROR(ctx, MPMC_ERR_ARG, "sim pointer is NULL") : MPMC_ERR_ARG;
  MPMC_CHECK(dim == 2 || dim == 3, ctx, MPMC_ERR_ARG, "dimension dim = %d must be 2 or 3", dim);
  mpmc_sim s = calloc(1, sizeof *s);
  MPMC_CHECK(s, ctx, MPMC_ERR_MEMORY, "cannot allocate a simulation");
  s->ctx = ctx;
  s->cfg.dim = dim;
  s->cfg.basis = MPMC_BASIS_BSPLINE2;
  s->cfg.flip = 1.0;
  s->cfg.solver = MPMC_SOLVER_AUTO;
  s->sort_last = -1;
  s->sort_axis = -1;
  s->adr_own[0] = -1; /* adaptive damping: every node its own until a step over MPI says */
  s->p.dim = dim;
  const int err = mpmc_kernels_from_env(s);
  if (err) {
    free(s);
    return err;
  }
  *sim = s;
  return MPMC_SUCCESS;
}

/** @brief Destroy a simulation; accepts NULL and sets the handle to NULL. */
int mpmc_sim_destroy(mpmc_sim *sim) {
  if (!sim || !*sim) return MPMC_SUCCESS;
  mpmc_sim s = *sim;
  mpmc_dd_free(s);
  mpmc_return_map_free(s);
  mpmc_contact_free(s);
  mpmc_sets_free(s);
  mpmc_particles_free(&s->p);
  mpmc_grid_free(&s->grid);
  free(s->mats);
  free(s->wt.xh);
  free(s->walls);
  free(s->scr.mirrors);
  free(s->scr.order);
  mpmc_fbar_free(s);
  free(s->scr.slab_start);
  free(s->scr.slab_group);
  free(s->adr_f);
  free(s->scr.adr_rows);
  free(s);
  *sim = NULL;
  return MPMC_SUCCESS;
}

int mpmc_sim_get_context(mpmc_const_sim sim, mpmc_context *ctx) {
  if (!sim || !ctx) return MPMC_ERR_ARG;
  *ctx = sim->ctx;
  return MPMC_SUCCESS;
}

int mpmc_sim_get_dim(mpmc_const_sim sim, int *dim) {
  if (!sim || !dim) return MPMC_ERR_ARG;
  *dim = sim->cfg.dim;
  return MPMC_SUCCESS;
}

/**
 * @brief Set the background grid: the box [lo, hi] (dim values each) with cell size h.
 * Must come before particles are added.
 */
int mpmc_sim_set_grid(mpmc_sim sim, const double *lo, const double *hi, double h) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(lo && hi, sim->ctx, MPMC_ERR_ARG, "grid lo/hi arrays are NULL");
  MPMC_CHECK(sim->p.n == 0, sim->ctx, MPMC_ERR_STATE,
             "the grid must be set before material points are added");
  MPMC_CHECK(!sim->node_sets || sim->node_sets->n == 0, sim->ctx, MPMC_ERR_STATE,
             "the grid must be set before node sets are added");
  MPMC_CALL(mpmc_grid_setup(sim->ctx, &sim->grid, sim->cfg.dim, lo, hi, h));
  MPMC_CALL(mpmc_dd_setup(sim)); /* MPI: the ranks' slabs of this grid */
  sim->adr_nf = 0; /* adaptive damping's node store: refilled for this grid */
  sim->scr.prepared = 0;
  sim->scr.walls_dirty = 1;
  return MPMC_SUCCESS;
}

/** @brief The grid box and cell size (as rounded to whole cells). */
int mpmc_sim_get_grid(mpmc_const_sim sim, double *lo, double *hi, double *h) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(sim->grid.valid, sim->ctx, MPMC_ERR_STATE, "no grid set");
  for (int a = 0; a < sim->cfg.dim; ++a) {
    if (lo) lo[a] = sim->grid.lo[a];
    if (hi) hi[a] = sim->grid.hi[a];
  }
  if (h) *h = sim->grid.h;
  return MPMC_SUCCESS;
}

/** @brief Choose the basis (mpmc_basis). uGIMP needs each point's volume at its addition. */
int mpmc_sim_set_basis(mpmc_sim sim, mpmc_basis basis) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(basis >= MPMC_BASIS_LINEAR && basis <= MPMC_BASIS_BSPLINE3, sim->ctx, MPMC_ERR_ARG,
             "basis = %d is not one of linear (0), ugimp (1), bspline2 (2), bspline3 (3)", basis);
  sim->cfg.basis = basis;
  sim->scr.prepared = 0;
  return MPMC_SUCCESS;
}

/**
 * @brief Choose the F-bar projection: MPMC_FBAR_OFF (0), MPMC_FBAR_PAPER (1, Algorithm 1 as
 * published), MPMC_FBAR_TOTAL (2, the projection of det F), MPMC_FBAR_STABLE (3, the
 * projection of det F onto a space one order below the basis) or MPMC_FBAR_ANCHORED (4, the
 * scenes' default: Algorithm 1 where the points change volume or move, still where they rest;
 * docs/theory.md).
 */
int mpmc_sim_set_fbar(mpmc_sim sim, mpmc_fbar_mode mode) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(mode >= MPMC_FBAR_OFF && mode <= MPMC_FBAR_ANCHORED, sim->ctx, MPMC_ERR_ARG,
             "fbar = %d is not one of off (0), paper (1), total (2), stable (3), anchored (4)",
             mode);
  sim->cfg.fbar = mode;
  sim->scr.prepared = 0;
  return MPMC_SUCCESS;
}

int mpmc_sim_get_fbar(mpmc_const_sim sim, mpmc_fbar_mode *mode) {
  if (!sim || !mode) return MPMC_ERR_ARG;
  *mode = (mpmc_fbar_mode)sim->cfg.fbar;
  return MPMC_SUCCESS;
}

/** @brief FLIP/PIC blend eta in [0, 1] (eq 13): 1 pure FLIP, 0 pure PIC. */
int mpmc_sim_set_flip_blend(mpmc_sim sim, double eta) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(eta) && eta >= 0 && eta <= 1, sim->ctx, MPMC_ERR_ARG,
             "FLIP/PIC blend = %g must be in [0, 1]", eta);
  sim->cfg.flip = eta;
  return MPMC_SUCCESS;
}

/** @brief PIC's diffusivity D [m^2/s] (> 0: eta = 1 - min(1, D dt / h^2) each step; 0: off). */
int mpmc_sim_set_pic_diffusivity(mpmc_sim sim, double D) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(D) && D >= 0, sim->ctx, MPMC_ERR_ARG,
             "PIC diffusivity D = %g [m^2/s] must be finite and >= 0 (0: the fixed FLIP/PIC blend)", D);
  sim->cfg.pic_diff = D;
  return MPMC_SUCCESS;
}

/** @brief Gravitational acceleration g[dim] [m/s^2]. */
int mpmc_sim_set_gravity(mpmc_sim sim, const double *g) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(g, sim->ctx, MPMC_ERR_ARG, "gravity array is NULL");
  for (int a = 0; a < sim->cfg.dim; ++a)
    MPMC_CHECK(isfinite(g[a]), sim->ctx, MPMC_ERR_ARG, "gravity component %d = %g is not finite", a,
               g[a]);
  for (int a = 0; a < 3; ++a) sim->cfg.gravity[a] = a < sim->cfg.dim ? g[a] : 0.0;
  return MPMC_SUCCESS;
}

/** @brief Local (Cundall / Al-Kafaji) damping factor alpha in [0, 1); 0 switches it off. */
int mpmc_sim_set_damping(mpmc_sim sim, double alpha) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(alpha) && alpha >= 0 && alpha < 1, sim->ctx, MPMC_ERR_ARG,
             "local damping alpha = %g must be in [0, 1)", alpha);
  sim->cfg.damping = alpha;
  return MPMC_SUCCESS;
}

/**
 * @brief Kinetic damping (Cundall's dynamic relaxation) for quasi-static stages: the points'
 *        kinetic energy is tracked every step and every point velocity set to zero when it
 *        has passed a peak.  Combines with local damping (mpmc_sim_set_damping).
 * @param on 1: on, 0: off; either call restarts the tracking (from the next step's energy)
 */
int mpmc_sim_set_kinetic_damping(mpmc_sim sim, int on) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(on == 0 || on == 1, sim->ctx, MPMC_ERR_ARG, "kinetic damping on = %d must be 0 or 1", on);
  sim->cfg.kdamp = on;
  sim->kd_ke = -1.0;
  return MPMC_SUCCESS;
}

/**
 * @brief Adaptive viscous damping (adaptive dynamic relaxation) for quasi-static stages: the
 *        grid update damps the nodal velocities with c m v, c = 2 zeta omega, omega the
 *        lowest mode's frequency estimated every step by a Rayleigh quotient of the nodal
 *        force's change over the nodal velocity (damping.c).  Combines with local and
 *        kinetic damping, but is meant alone.  Over MPI the quotient's sums run over the
 *        ranks.
 * @param zeta damping ratio of the estimated mode in [0, 2]: 1 critical (Underwood's
 *        choice), 0 off; any call restarts the estimate (no damping until the second step
 *        has measured one)
 */
int mpmc_sim_set_adaptive_damping(mpmc_sim sim, double zeta) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(zeta) && zeta >= 0 && zeta <= 2, sim->ctx, MPMC_ERR_ARG,
             "adaptive damping ratio zeta = %g must be in [0, 2] (1: critical, 0: off)", zeta);
  sim->cfg.adr = zeta > 0;
  sim->cfg.adr_zeta = zeta;
  sim->adr_c = 0.0;
  sim->adr_sum[0] = sim->adr_sum[1] = 0.0;
  for (size_t k = 0; k < sim->adr_nf; k += (size_t)(1 + sim->cfg.dim)) sim->adr_f[k] = -2.0;
  return MPMC_SUCCESS;
}

/**
 * @brief The adaptive damping's coefficient c = 2 zeta omega [1/s] the next step applies (0 when
 *        it is off or has no estimate yet).
 */
int mpmc_sim_get_adaptive_damping(mpmc_const_sim sim, double *c) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(c, sim->ctx, MPMC_ERR_ARG, "c is NULL");
  *c = sim->cfg.adr ? sim->adr_c : 0.0;
  return MPMC_SUCCESS;
}

/** @brief Local solver for plastic return mapping (mpmc_solver). */
int mpmc_sim_set_solver(mpmc_sim sim, mpmc_solver solver) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(solver >= MPMC_SOLVER_AUTO && solver <= MPMC_SOLVER_KINSOL, sim->ctx, MPMC_ERR_ARG,
             "solver = %d is not one of auto (0), newton (1), kinsol (2)", solver);
  sim->cfg.solver = solver;
  return MPMC_SUCCESS;
}

/** @brief Threads used by the step (0: OpenMP's default). */
int mpmc_sim_set_threads(mpmc_sim sim, int nthreads) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(nthreads >= 0 && nthreads <= 1024, sim->ctx, MPMC_ERR_ARG,
             "threads = %d must be in [0, 1024]", nthreads);
  sim->cfg.nthreads = nthreads;
  return MPMC_SUCCESS;
}

/** @brief Allow steps above the stability limit (1) or refuse them (0, the default). */
int mpmc_sim_set_force_dt(mpmc_sim sim, int force) {
  if (!sim) return MPMC_ERR_ARG;
  sim->cfg.force_dt = force != 0;
  return MPMC_SUCCESS;
}

/**
 * @brief Add n material points of one material.
 * @param x positions [n*dim], inside the grid box
 * @param volume initial volumes [n] (> 0; per unit thickness in 2D)
 * @param material id from an mpmc_sim_add_material_* call
 * @param[out] first index of the first new point (may be NULL)
 * Over MPI (mpmc_sim_create_mpi) every rank passes the same points and keeps those in its
 * slab; first is then the index of this rank's first new point, and the points' ids are
 * their indices among all points added.
 */
int mpmc_sim_add_particles(mpmc_sim sim, int n, const double *x, const double *volume, int material,
                           int *first) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  mpmc_particles *p = &sim->p;
  const mpmc_grid *g = &sim->grid;
  const int d = sim->cfg.dim;
  MPMC_CHECK(g->valid, ctx, MPMC_ERR_STATE, "set the grid before adding material points");
  MPMC_CHECK(n >= 0, ctx, MPMC_ERR_ARG, "number of points n = %d must be >= 0", n);
  MPMC_CHECK(n == 0 || (x && volume), ctx, MPMC_ERR_ARG, "position or volume array is NULL");
  MPMC_CHECK(material >= 0 && material < sim->nmat, ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  MPMC_CHECK(n <= INT32_MAX - p->n, ctx, MPMC_ERR_ARG, "too many material points");
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < d; ++a) {
      const double xa = x[(size_t)i * d + a];
      MPMC_CHECK(isfinite(xa) && xa >= g->lo[a] && xa <= g->hi[a], ctx, MPMC_ERR_OUTSIDE,
                 "point %d: coordinate %d = %g outside the grid box [%g, %g]", i, a, xa, g->lo[a],
                 g->hi[a]);
    }
    MPMC_CHECK(isfinite(volume[i]) && volume[i] > 0, ctx, MPMC_ERR_ARG,
               "point %d: volume = %g must be > 0", i, volume[i]);
    if (sim->cfg.basis == MPMC_BASIS_UGIMP) {
      const double lp = 0.5 * pow(volume[i], 1.0 / d);
      MPMC_CHECK(lp <= 0.5 * g->h * (1 + 1e-9), ctx, MPMC_ERR_ARG,
                 "point %d: uGIMP half-length %g exceeds half a cell (%g): use at least one point per cell",
                 i, lp, 0.5 * g->h);
    }
  }
  MPMC_CHECK(sim->np_global + n <= INT32_MAX, ctx, MPMC_ERR_ARG, "too many material points");
  int cap = p->cap ? p->cap : 64;
  while (cap < p->n + n) cap = cap > INT32_MAX / 2 ? INT32_MAX : 2 * cap;
  MPMC_CALL(mpmc_particles_reserve(ctx, p, cap));
  p->global_ids = sim->dd != NULL;
  if (sim->dd && !p->id) { /* over MPI a point's id is its global index */
    p->id = malloc(sizeof(int) * (size_t)p->cap);
    MPMC_CHECK(p->id, ctx, MPMC_ERR_MEMORY, "cannot allocate the ids of %d points", p->cap);
    for (int q = 0; q < p->n; ++q) p->id[q] = q;
  }
  const mpmc_material *m = &sim->mats[material];
  const int n0 = p->n;
  size_t q = (size_t)n0 - 1;
  for (int i = 0; i < n; ++i) {
    if (sim->dd && !mpmc_dd_keep(sim, x + (size_t)i * d)) continue; /* another rank's */
    ++q;
    for (int a = 0; a < d; ++a) {
      p->x[q * d + a] = x[(size_t)i * d + a];
      p->x0[q * d + a] = x[(size_t)i * d + a];
      p->v[q * d + a] = 0.0;
    }
    p->vol0[q] = volume[i];
    p->m[q] = mpmc_water_density(sim, m, x + (size_t)i * d) * volume[i];
    p->J[q] = 1.0;
    for (int k = 0; k < 6; ++k) p->stress[q * 6 + k] = 0.0;
    p->mat[q] = material;
    if (p->id) /* a point's id is its index when added (over all ranks) */
      p->id[q] = sim->dd ? (int)(sim->np_global + i) : (int)q;
    if (p->Jbar) p->Jbar[q] = 1.0;
    if (p->be)
      for (int k = 0; k < 6; ++k) p->be[q * 6 + k] = k < 3 ? 1.0 : 0.0;
    if (p->eps_p) p->eps_p[q] = 0.0;
    if (p->region) p->region[q] = 0.0;
    if (p->Jp) p->Jp[q] = 1.0;
    if (p->pw) p->pw[q] = mpmc_water_pressure(&sim->wt, d, x + (size_t)i * d);
    if (p->lp) p->lp[q] = 0.5 * pow(volume[i], 1.0 / d);
    if (p->force)
      for (int a = 0; a < d; ++a) p->force[q * d + a] = 0.0;
    if (p->cforce)
      for (int a = 0; a < d; ++a) p->cforce[q * d + a] = 0.0;
    for (int k = 0; k < p->nustate; ++k) p->ustate[q * (size_t)p->nustate + k] = 0.0;
  }
  p->n = (int)(q + 1);
  sim->np_global += n;
  if (first) *first = n0;
  sim->scr.prepared = 0;
  return MPMC_SUCCESS;
}

int mpmc_sim_get_num_particles(mpmc_const_sim sim, int *n) {
  if (!sim || !n) return MPMC_ERR_ARG;
  *n = sim->p.n;
  return MPMC_SUCCESS;
}

/* Allocate the optional fields and grid arrays the configuration needs. */
int mpmc_sim_prepare(mpmc_sim sim) {
  if (sim->scr.prepared) return MPMC_SUCCESS;
  mpmc_context ctx = sim->ctx;
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  MPMC_CHECK(sim->grid.valid, ctx, MPMC_ERR_STATE, "no grid set");
  int solid = 0, plastic = 0, region = 0;
  for (int i = 0; i < sim->nmat; ++i) {
    solid |= sim->mats[i].solid;
    plastic |= sim->mats[i].plastic;
    region |= (sim->mats[i].model->flags & MPMC_MODEL_REGION) != 0;
  }
  if (p->cap == 0) MPMC_CALL(mpmc_particles_reserve(ctx, p, 64));
  if (solid) {
    if (!p->be) {
      MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->be, 6, 0.0));
      for (int q = 0; q < p->n; ++q)
        for (int k = 0; k < 3; ++k) p->be[(size_t)q * 6 + k] = 1.0;
    }
  }
  if (plastic) MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->eps_p, 1, 0.0));
  if (region) MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->region, 1, 0.0));
  /* the plastic volume ratio: with F-bar and a frictional (dilatant) model only */
  if (region && sim->cfg.fbar) MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->Jp, 1, 1.0));
  if (sim->wt.kind != MPMC_WATER_NONE && !p->pw) {
    MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->pw, 1, 0.0));
    mpmc_water_update(sim);
  }
  if (sim->cfg.basis == MPMC_BASIS_UGIMP && !p->lp) {
    MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->lp, 1, 0.0));
    for (int q = 0; q < p->n; ++q) {
      p->lp[q] = 0.5 * pow(p->vol0[q], 1.0 / d);
      MPMC_CHECK(p->lp[q] <= 0.5 * sim->grid.h * (1 + 1e-9), ctx, MPMC_ERR_ARG,
                 "point %d: uGIMP half-length %g exceeds half a cell (%g)", q, p->lp[q],
                 0.5 * sim->grid.h);
    }
  }
  MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->dF, d * d, 0.0));
  MPMC_CALL(mpmc_grid_alloc(ctx, &sim->grid));
  MPMC_CALL(mpmc_fbar_prepare(sim)); /* Jbar, Janc and the projection's arrays, per form */
  sim->scr.walls_dirty = 1;
  sim->scr.prepared = 1;
  return MPMC_SUCCESS;
}

static double **field_ptr(mpmc_sim sim, int field, int *ncomp) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  switch (field) {
    case MPMC_FIELD_POSITION: *ncomp = d; return &p->x;
    case MPMC_FIELD_VELOCITY: *ncomp = d; return &p->v;
    case MPMC_FIELD_MASS: *ncomp = 1; return &p->m;
    case MPMC_FIELD_VOLUME0: *ncomp = 1; return &p->vol0;
    case MPMC_FIELD_J: *ncomp = 1; return &p->J;
    case MPMC_FIELD_JBAR: *ncomp = 1; return &p->Jbar;
    case MPMC_FIELD_STRESS: *ncomp = 6; return &p->stress;
    case MPMC_FIELD_BE: *ncomp = 6; return &p->be;
    case MPMC_FIELD_EPS_P: *ncomp = 1; return &p->eps_p;
    case MPMC_FIELD_FORCE: *ncomp = d; return &p->force;
    case MPMC_FIELD_X0: *ncomp = d; return &p->x0;
    case MPMC_FIELD_REGION: *ncomp = 1; return &p->region;
    case MPMC_FIELD_PORE_PRESSURE: *ncomp = 1; return &p->pw;
    default: return NULL;
  }
}

static const char *field_names[MPMC_FIELD_COUNT] = {
    "position", "velocity", "mass", "volume0", "J", "Jbar", "stress", "be", "eps_p", "force", "x0",
    "region", "pore_pressure"};

/**
 * @brief Borrow a particle field in place (no copy).  Layout [n][ncomp].
 * Optional fields are created by the first step (or mpmc_sim_get_field after it):
 * a field the scene does not have is MPMC_ERR_STATE.  A borrowed velocity may be written:
 * until it is given back (mpmc_sim_restore_field) the stability limit recomputes max |v|.
 */
int mpmc_sim_get_field(mpmc_sim sim, mpmc_field field, double **data, int *ncomp) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(data, sim->ctx, MPMC_ERR_ARG, "data pointer is NULL");
  int nc = 0;
  double **f = field_ptr(sim, field, &nc);
  MPMC_CHECK(f, sim->ctx, MPMC_ERR_ARG, "field = %d is not a particle field", field);
  if (!*f && sim->grid.valid) MPMC_CALL(mpmc_sim_prepare(sim));
  MPMC_CHECK(*f, sim->ctx, MPMC_ERR_STATE, "this simulation has no '%s' field", field_names[field]);
  if (field == MPMC_FIELD_VELOCITY) sim->v_borrowed = 1, sim->scr.v2max_ok = 0; /* G2P's max |v| no longer holds */
  *data = *f;
  if (ncomp) *ncomp = nc;
  return MPMC_SUCCESS;
}

/** @brief Give back a field borrowed with mpmc_sim_get_field; sets *data to NULL. */
int mpmc_sim_restore_field(mpmc_sim sim, mpmc_field field, double **data) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(field >= 0 && field < MPMC_FIELD_COUNT, sim->ctx, MPMC_ERR_ARG,
             "field = %d is not a particle field", field);
  if (data) *data = NULL;
  if (field == MPMC_FIELD_VELOCITY) { /* the caller may have written v: a pass until G2P's next */
    sim->v_borrowed = 0;
    sim->scr.v2max_ok = 0;
  }
  return MPMC_SUCCESS;
}

/** @brief Borrow the material id of each point (read-only). */
int mpmc_sim_get_material_ids(mpmc_sim sim, const int **ids) {
  if (!sim || !ids) return MPMC_ERR_ARG;
  *ids = sim->p.mat;
  return MPMC_SUCCESS;
}

/** @brief Set the external force f[n*dim] on points [first, first+n). */
int mpmc_sim_set_particle_forces(mpmc_sim sim, int first, int n, const double *f) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  MPMC_CHECK(first >= 0 && n >= 0 && first <= p->n - n, sim->ctx, MPMC_ERR_ARG,
             "points [%d, %d) outside [0, %d)", first, first + n, p->n);
  MPMC_CHECK(n == 0 || f, sim->ctx, MPMC_ERR_ARG, "force array is NULL");
  for (int i = 0; i < n * d; ++i)
    MPMC_CHECK(isfinite(f[i]), sim->ctx, MPMC_ERR_ARG, "force component %d = %g is not finite", i,
               f[i]);
  MPMC_CALL(mpmc_particles_ensure(sim->ctx, p, &p->force, d, 0.0));
  memcpy(p->force + (size_t)first * d, f, sizeof(double) * (size_t)n * d);
  return MPMC_SUCCESS;
}

int mpmc_sim_get_time(mpmc_const_sim sim, double *t) {
  if (!sim || !t) return MPMC_ERR_ARG;
  *t = sim->time;
  return MPMC_SUCCESS;
}

int mpmc_sim_set_time(mpmc_sim sim, double t) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(t), sim->ctx, MPMC_ERR_ARG, "time = %g is not finite", t);
  sim->time = t;
  return MPMC_SUCCESS;
}

/* 1/2 sum m |v|^2 of the points over all ranks (collective), the same bits on each: the sum
 * of m |v|^2 halved (exact) */
double mpmc_points_kinetic_energy(const struct mpmc_sim_s *sim) {
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  double e = 0.0;
#pragma omp parallel for reduction(+ : e) schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    double v2 = 0.0;
    for (int a = 0; a < d; ++a) v2 += p->v[(size_t)q * d + a] * p->v[(size_t)q * d + a];
    e += p->m[q] * v2;
  }
  mpmc_dd_sum(sim, &e, 1); /* MPI: over the ranks (collective) */
  return 0.5 * e;
}

/** @brief Total kinetic energy 1/2 sum m |v|^2 of the material points. */
int mpmc_sim_get_kinetic_energy(mpmc_const_sim sim, double *ke) {
  if (!sim || !ke) return MPMC_ERR_ARG;
  *ke = mpmc_points_kinetic_energy(sim);
  return MPMC_SUCCESS;
}

int mpmc_sim_get_stats(mpmc_const_sim sim, mpmc_stats *stats) {
  if (!sim || !stats) return MPMC_ERR_ARG;
  *stats = sim->stats;
  stats->time = sim->time;
  return MPMC_SUCCESS;
}
