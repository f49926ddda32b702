/* Walls on the grid: half-spaces beyond a plane and axis-aligned boxes.  A wall marks the
 * nodes in its region; the grid update zeroes (FIXED), zeroes the normal component (SLIP) or
 * lets the normal component point away from the wall only (SEPARABLE). */
#include <math.h>
#include <stdlib.h>

#include "sets.h"

static int push_wall(mpmc_sim sim, const mpmc_wall *w, int *id) {
  if (sim->nwall == sim->capwall) {
    const int cap = sim->capwall ? 2 * sim->capwall : 8;
    mpmc_wall *a = realloc(sim->walls, sizeof *a * (size_t)cap);
    MPMC_CHECK(a, sim->ctx, MPMC_ERR_MEMORY, "cannot add a wall");
    sim->walls = a;
    sim->capwall = cap;
  }
  sim->walls[sim->nwall] = *w;
  if (id) *id = sim->nwall;
  sim->nwall++;
  sim->scr.walls_dirty = 1;
  return MPMC_SUCCESS;
}

static int check_kind_axis_side(mpmc_sim sim, int kind, int axis, int side) {
  MPMC_CHECK(kind >= MPMC_WALL_FIXED && kind <= MPMC_WALL_SEPARABLE, sim->ctx, MPMC_ERR_ARG,
             "wall kind = %d is not one of fixed (0), slip (1), separable (2)", kind);
  MPMC_CHECK(axis >= 0 && axis < sim->cfg.dim, sim->ctx, MPMC_ERR_ARG, "wall axis = %d outside [0, %d)",
             axis, sim->cfg.dim);
  MPMC_CHECK(side == -1 || side == 1, sim->ctx, MPMC_ERR_ARG, "wall side = %d must be -1 or +1",
             side);
  return MPMC_SUCCESS;
}

/**
 * @brief Add a wall constraining the nodes on or beyond the plane x[axis] = position.
 * @param side -1: nodes with x[axis] <= position (material above), +1: x[axis] >= position
 * @param kind mpmc_wall_kind
 * @param[out] id the wall's id, for mpmc_sim_remove_wall (may be NULL)
 */
int mpmc_sim_add_wall(mpmc_sim sim, int axis, int side, double position, mpmc_wall_kind kind,
                      int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CALL(check_kind_axis_side(sim, kind, axis, side));
  MPMC_CHECK(isfinite(position), sim->ctx, MPMC_ERR_ARG, "wall position = %g is not finite",
             position);
  mpmc_wall w = {.active = 1, .kind = kind, .axis = axis, .side = side, .nodeset = -1};
  for (int a = 0; a < 3; ++a) {
    w.lo[a] = -INFINITY;
    w.hi[a] = INFINITY;
  }
  if (side < 0)
    w.hi[axis] = position;
  else
    w.lo[axis] = position;
  return push_wall(sim, &w, id);
}

/**
 * @brief Add a wall on a face of the grid box: face = 2*axis + (0: lo, 1: hi).
 */
int mpmc_sim_add_wall_face(mpmc_sim sim, int face, mpmc_wall_kind kind, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(sim->grid.valid, sim->ctx, MPMC_ERR_STATE, "set the grid before adding face walls");
  MPMC_CHECK(face >= 0 && face < 2 * sim->cfg.dim, sim->ctx, MPMC_ERR_ARG,
             "face = %d outside [0, %d)", face, 2 * sim->cfg.dim);
  const int axis = face / 2, hi = face % 2;
  return mpmc_sim_add_wall(sim, axis, hi ? 1 : -1, hi ? sim->grid.hi[axis] : sim->grid.lo[axis],
                           kind, id);
}

/**
 * @brief Constrain the nodes inside the box [lo, hi] (a gate or an obstacle).
 * @param axis the constrained component for SLIP and SEPARABLE
 * @param side for SEPARABLE, -1 if the material lies at larger x[axis] (it may move away
 *        in +axis), +1 if at smaller
 */
int mpmc_sim_add_wall_box(mpmc_sim sim, const double *lo, const double *hi, mpmc_wall_kind kind,
                          int axis, int side, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CALL(check_kind_axis_side(sim, kind, axis, side));
  MPMC_CHECK(lo && hi, sim->ctx, MPMC_ERR_ARG, "wall box lo/hi arrays are NULL");
  mpmc_wall w = {.active = 1, .kind = kind, .axis = axis, .side = side, .nodeset = -1};
  for (int a = 0; a < 3; ++a) {
    w.lo[a] = a < sim->cfg.dim ? lo[a] : -INFINITY;
    w.hi[a] = a < sim->cfg.dim ? hi[a] : INFINITY;
    if (a < sim->cfg.dim)
      MPMC_CHECK(!isnan(lo[a]) && !isnan(hi[a]) && hi[a] >= lo[a], sim->ctx, MPMC_ERR_ARG,
                 "wall box axis %d: hi = %g must be >= lo = %g", a, hi[a], lo[a]);
  }
  return push_wall(sim, &w, id);
}

/**
 * @brief Constrain the nodes of node set `set` (e.g. a gmsh boundary group).
 * @param axis, side as for mpmc_sim_add_wall_box: the constrained component for SLIP and
 *        SEPARABLE, and for SEPARABLE the side the material lies on
 */
int mpmc_sim_add_wall_nodes(mpmc_sim sim, int set, mpmc_wall_kind kind, int axis, int side,
                            int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CALL(check_kind_axis_side(sim, kind, axis, side));
  const int ns = sim->node_sets ? sim->node_sets->n : 0;
  MPMC_CHECK(set >= 0 && set < ns, sim->ctx, MPMC_ERR_ARG, "node set id %d does not exist (%d sets)",
             set, ns);
  mpmc_wall w = {.active = 1, .kind = kind, .axis = axis, .side = side, .nodeset = set};
  for (int a = 0; a < 3; ++a) {
    w.lo[a] = -INFINITY;
    w.hi[a] = INFINITY;
  }
  return push_wall(sim, &w, id);
}

/** @brief Remove a wall (e.g. open a gate between stages). */
int mpmc_sim_remove_wall(mpmc_sim sim, int id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(id >= 0 && id < sim->nwall && sim->walls[id].active, sim->ctx, MPMC_ERR_ARG,
             "wall id %d does not exist or was removed", id);
  sim->walls[id].active = 0;
  sim->scr.walls_dirty = 1;
  return MPMC_SUCCESS;
}

/* Recompute the per-node constraint bits from the active walls. */
int mpmc_boundary_apply_flags(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  if (!g->fixed) return MPMC_SUCCESS;
  const double tol = 1e-9 * g->h;
  for (size_t i = 0; i < g->nn; ++i) g->fixed[i] = 0;
  free(sim->scr.mirrors);
  sim->scr.mirrors = NULL;
  sim->scr.nmirror = 0;
  if (sim->nwall > 0) {
    sim->scr.mirrors = malloc(sizeof *sim->scr.mirrors * (size_t)sim->nwall);
    MPMC_CHECK(sim->scr.mirrors, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate wall mirrors");
  }
  for (int wi = 0; wi < sim->nwall; ++wi) {
    const mpmc_wall *w = &sim->walls[wi];
    if (!w->active) continue;
    unsigned bits;
    if (w->kind == MPMC_WALL_FIXED)
      bits = 7u;
    else if (w->kind == MPMC_WALL_SLIP)
      bits = 1u << w->axis;
    else
      bits = (w->side < 0 ? 8u : 64u) << w->axis;
    if (w->nodeset >= 0) { /* the set's nodes, no mirroring (not a plane) */
      MPMC_CHECK(sim->node_sets && w->nodeset < sim->node_sets->n, sim->ctx, MPMC_ERR_STATE,
                 "wall %d: its node set %d no longer exists", wi, w->nodeset);
      const mpmc_set *ns = &sim->node_sets->s[w->nodeset];
      for (int q = 0; q < ns->n; ++q) {
        const int *c = ns->idx + (size_t)q * sim->cfg.dim;
        size_t node = 0;
        int held = 1; /* over MPI a rank holds only its slab's nodes (grid.off) */
        for (int a = sim->cfg.dim - 1; a >= 0; --a) {
          const int i = c[a] + MPMC_GHOST - g->off[a];
          held &= i >= 0 && i < g->n[a];
          node = node * (size_t)g->n[a] + (size_t)i;
        }
        if (held) g->fixed[node] |= bits;
      }
      continue;
    }
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < sim->cfg.dim; ++a) {
      const double l = (w->lo[a] - g->origin[a]) * g->inv_h, u = (w->hi[a] - g->origin[a]) * g->inv_h;
      lo[a] = isinf(l) ? 0 : (int)ceil(l - tol * g->inv_h) - g->off[a]; /* the held nodes' */
      hi[a] = isinf(u) ? g->n[a] - 1 : (int)floor(u + tol * g->inv_h) - g->off[a];
      if (lo[a] < 0) lo[a] = 0;
      if (hi[a] > g->n[a] - 1) hi[a] = g->n[a] - 1;
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i)
          g->fixed[(size_t)i + (size_t)g->n[0] * ((size_t)j + (size_t)g->n[1] * (size_t)k)] |= bits;
    /* a fixed or slip half-space wall on a node plane mirrors its ghost nodes */
    int unbounded = 1;
    for (int a = 0; a < sim->cfg.dim; ++a)
      if (a != w->axis) unbounded &= isinf(w->lo[a]) && isinf(w->hi[a]);
    const double plane = (w->side < 0 ? w->hi[w->axis] : w->lo[w->axis]);
    const double s = (plane - g->origin[w->axis]) * g->inv_h;
    if (unbounded && w->kind != MPMC_WALL_SEPARABLE && fabs(s - round(s)) < 1e-9) {
      mpmc_mirror *m = &sim->scr.mirrors[sim->scr.nmirror++];
      m->axis = w->axis;
      m->side = w->side;
      m->plane = (int)round(s) - g->off[w->axis]; /* held node index (may lie outside) */
      m->odd = w->kind == MPMC_WALL_FIXED ? 7u : 1u << w->axis;
    }
  }
  sim->scr.walls_dirty = 0;
  return MPMC_SUCCESS;
}
