/* Named sets: groups of material points (gmsh boundary groups, traction edges, tracked
 * points) and groups of grid nodes (gmsh boundary groups, for walls on them).  Indices are
 * copied; a set with an existing name replaces it so that re-seeding a group does not leave
 * stale members behind.  Both kinds live in the same store, with ncomp ints per member: a
 * point index, or a node's dim integer coordinates. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sets.h"

#define MPMC_SET_NAME_MAX 255

/* Put (add or replace) a set of n members of ncomp ints into *store. */
static int store_put(mpmc_context ctx, struct mpmc_sets_s **store, const char *what,
                     const char *name, int n, int ncomp, const int *idx, int *id) {
  MPMC_CHECK(name && name[0], ctx, MPMC_ERR_ARG, "%s name is NULL or empty", what);
  MPMC_CHECK(strlen(name) <= MPMC_SET_NAME_MAX, ctx, MPMC_ERR_ARG,
             "%s name '%.40s...' is longer than %d characters", what, name, MPMC_SET_NAME_MAX);
  if (!*store) {
    *store = calloc(1, sizeof **store);
    MPMC_CHECK(*store, ctx, MPMC_ERR_MEMORY, "cannot allocate the %ss", what);
  }
  struct mpmc_sets_s *S = *store;
  const size_t len = (size_t)n * (size_t)ncomp;
  int *copy = malloc(sizeof(int) * (len > 0 ? len : 1));
  MPMC_CHECK(copy, ctx, MPMC_ERR_MEMORY, "%s '%s': cannot allocate %d members", what, name, n);
  if (len > 0) memcpy(copy, idx, sizeof(int) * len);
  int k = 0;
  while (k < S->n && strcmp(S->s[k].name, name) != 0) ++k;
  if (k < S->n) { /* replace */
    free(S->s[k].idx);
    S->s[k].idx = copy;
    S->s[k].n = n;
  } else {
    if (S->n == S->cap) {
      const int cap = S->cap ? 2 * S->cap : 8;
      mpmc_set *a = realloc(S->s, sizeof *a * (size_t)cap);
      if (!a) {
        free(copy);
        return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot grow the %ss to %d", what, cap);
      }
      S->s = a;
      S->cap = cap;
    }
    char *nm = malloc(strlen(name) + 1);
    if (!nm) {
      free(copy);
      return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot copy the %s name '%s'", what, name);
    }
    memcpy(nm, name, strlen(name) + 1);
    S->s[k].name = nm;
    S->s[k].idx = copy;
    S->s[k].n = n;
    S->n++;
  }
  if (id) *id = k;
  return MPMC_SUCCESS;
}

static int store_get(mpmc_context ctx, const struct mpmc_sets_s *S, const char *what, int id,
                     const char **name, int *n, const int **idx) {
  const int count = S ? S->n : 0;
  MPMC_CHECK(id >= 0 && id < count, ctx, MPMC_ERR_ARG, "%s id %d does not exist (%d sets)", what,
             id, count);
  const mpmc_set *s = &S->s[id];
  if (name) *name = s->name;
  if (n) *n = s->n;
  if (idx) *idx = s->idx;
  return MPMC_SUCCESS;
}

static int store_find(mpmc_context ctx, const struct mpmc_sets_s *S, const char *what,
                      const char *name, int *id) {
  MPMC_CHECK(name && id, ctx, MPMC_ERR_ARG, "name or id pointer is NULL");
  const int count = S ? S->n : 0;
  for (int k = 0; k < count; ++k)
    if (strcmp(S->s[k].name, name) == 0) {
      *id = k;
      return MPMC_SUCCESS;
    }
  char names[256] = "";
  size_t len = 0;
  for (int k = 0; k < count && len + 1 < sizeof names; ++k)
    len += (size_t)snprintf(names + len, sizeof names - len, "%s%s", k ? ", " : "", S->s[k].name);
  return MPMC_ERROR(ctx, MPMC_ERR_ARG, "no %s named '%s' (there are %d: %s)", what, name, count,
                    count ? names : "none");
}

static void store_free(struct mpmc_sets_s **store) {
  struct mpmc_sets_s *S = *store;
  if (!S) return;
  for (int k = 0; k < S->n; ++k) {
    free(S->s[k].name);
    free(S->s[k].idx);
  }
  free(S->s);
  free(S);
  *store = NULL;
}

/**
 * @brief Add (or replace) the particle set `name` with the n point indices idx[n].
 * @param name non-empty, at most 255 characters
 * @param idx indices in [0, number of points); copied
 * @param[out] id the set's id (may be NULL)
 */
int mpmc_sim_add_particle_set(mpmc_sim sim, const char *name, int n, const int *idx, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  const char *nm = name ? name : "(null)";
  MPMC_CHECK(n >= 0, ctx, MPMC_ERR_ARG, "particle set '%s': size n = %d must be >= 0", nm, n);
  MPMC_CHECK(n == 0 || idx, ctx, MPMC_ERR_ARG, "particle set '%s': index array idx is NULL", nm);
  for (int i = 0; i < n; ++i)
    MPMC_CHECK(idx[i] >= 0 && idx[i] < sim->p.n, ctx, MPMC_ERR_ARG,
               "particle set '%s': idx[%d] = %d outside [0, %d)", nm, i, idx[i], sim->p.n);
  return store_put(ctx, &sim->sets, "particle set", name, n, 1, idx, id);
}

/** @brief Number of particle sets. */
int mpmc_sim_get_num_particle_sets(mpmc_const_sim sim, int *n) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(n, sim->ctx, MPMC_ERR_ARG, "output pointer n is NULL");
  *n = sim->sets ? sim->sets->n : 0;
  return MPMC_SUCCESS;
}

/**
 * @brief Borrow set `id`: its name, size and indices (valid until the sets change).
 * Any of name, n, idx may be NULL.
 */
int mpmc_sim_get_particle_set(mpmc_const_sim sim, int id, const char **name, int *n,
                              const int **idx) {
  if (!sim) return MPMC_ERR_ARG;
  return store_get(sim->ctx, sim->sets, "particle set", id, name, n, idx);
}

/** @brief The id of the set called `name`; MPMC_ERR_ARG if there is none. */
int mpmc_sim_find_particle_set(mpmc_const_sim sim, const char *name, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  return store_find(sim->ctx, sim->sets, "particle set", name, id);
}

/**
 * @brief Add (or replace) the node set `name`: n grid nodes given by their integer
 *        coordinates ijk[n*dim] (node (i, j, k) at lo + (i, j, k) h; 0 <= i <= cells).
 * Walls on the set (mpmc_sim_add_wall_nodes) see the new members from the next step on.
 */
int mpmc_sim_add_node_set(mpmc_sim sim, const char *name, int n, const int *ijk, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  const mpmc_grid *g = &sim->grid;
  const char *nm = name ? name : "(null)";
  MPMC_CHECK(g->valid, ctx, MPMC_ERR_STATE, "node set '%s': set the grid first", nm);
  MPMC_CHECK(n >= 0, ctx, MPMC_ERR_ARG, "node set '%s': size n = %d must be >= 0", nm, n);
  MPMC_CHECK(n == 0 || ijk, ctx, MPMC_ERR_ARG, "node set '%s': node array ijk is NULL", nm);
  const int d = sim->cfg.dim;
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < d; ++a) {
      const int cells = g->ng[a] - 1 - 2 * MPMC_GHOST, v = ijk[(size_t)i * d + a];
      MPMC_CHECK(v >= 0 && v <= cells, ctx, MPMC_ERR_ARG,
                 "node set '%s': node %d, index %d along axis %d outside [0, %d]", nm, i, v, a,
                 cells);
    }
  MPMC_CALL(store_put(ctx, &sim->node_sets, "node set", name, n, d, ijk, id));
  sim->scr.walls_dirty = 1;
  return MPMC_SUCCESS;
}

/** @brief Number of node sets. */
int mpmc_sim_get_num_node_sets(mpmc_const_sim sim, int *n) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(n, sim->ctx, MPMC_ERR_ARG, "output pointer n is NULL");
  *n = sim->node_sets ? sim->node_sets->n : 0;
  return MPMC_SUCCESS;
}

/** @brief Borrow node set `id`: name, size and node coordinates ijk[n*dim]. */
int mpmc_sim_get_node_set(mpmc_const_sim sim, int id, const char **name, int *n, const int **ijk) {
  if (!sim) return MPMC_ERR_ARG;
  return store_get(sim->ctx, sim->node_sets, "node set", id, name, n, ijk);
}

/** @brief The id of the node set called `name`; MPMC_ERR_ARG if there is none. */
int mpmc_sim_find_node_set(mpmc_const_sim sim, const char *name, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  return store_find(sim->ctx, sim->node_sets, "node set", name, id);
}

void mpmc_sets_free(struct mpmc_sim_s *sim) {
  if (!sim) return;
  store_free(&sim->sets);
  store_free(&sim->node_sets);
}
