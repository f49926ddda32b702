/* Named particle sets: groups of material points named after gmsh boundary groups,
 * traction edges or tracked points.  Indices are copied; a set with an existing name
 * replaces it so that re-seeding a group does not leave stale members behind. */
#include <stdlib.h>
#include <string.h>

#include "sets.h"

#define MPMC_SET_NAME_MAX 255

/**
 * @brief Add (or replace) the particle set `name` with the n point indices idx[n].
 * @param name non-empty, at most 255 characters
 * @param idx indices in [0, number of points); copied
 * @param[out] id the set's id (may be NULL)
 */
int mpmc_sim_add_particle_set(mpmc_sim sim, const char *name, int n, const int *idx, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(name && name[0], ctx, MPMC_ERR_ARG, "particle set name is NULL or empty");
  MPMC_CHECK(strlen(name) <= MPMC_SET_NAME_MAX, ctx, MPMC_ERR_ARG,
             "particle set name '%.40s...' is longer than %d characters", name, MPMC_SET_NAME_MAX);
  MPMC_CHECK(n >= 0, ctx, MPMC_ERR_ARG, "particle set '%s': size n = %d must be >= 0", name, n);
  MPMC_CHECK(n == 0 || idx, ctx, MPMC_ERR_ARG, "particle set '%s': index array idx is NULL", name);
  for (int i = 0; i < n; ++i)
    MPMC_CHECK(idx[i] >= 0 && idx[i] < sim->p.n, ctx, MPMC_ERR_ARG,
               "particle set '%s': idx[%d] = %d outside [0, %d)", name, i, idx[i], sim->p.n);
  if (!sim->sets) {
    sim->sets = calloc(1, sizeof *sim->sets);
    MPMC_CHECK(sim->sets, ctx, MPMC_ERR_MEMORY, "cannot allocate the particle sets");
  }
  struct mpmc_sets_s *S = sim->sets;
  int *copy = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
  MPMC_CHECK(copy, ctx, MPMC_ERR_MEMORY, "particle set '%s': cannot allocate %d indices", name, n);
  if (n > 0) memcpy(copy, idx, sizeof(int) * (size_t)n);
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
        return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot grow the particle sets to %d", cap);
      }
      S->s = a;
      S->cap = cap;
    }
    const size_t len = strlen(name);
    char *nm = malloc(len + 1);
    if (!nm) {
      free(copy);
      return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot copy the particle set name '%s'", name);
    }
    memcpy(nm, name, len + 1);
    S->s[k].name = nm;
    S->s[k].idx = copy;
    S->s[k].n = n;
    S->n++;
  }
  if (id) *id = k;
  return MPMC_SUCCESS;
}

/** @brief Number of particle sets. */
int mpmc_sim_get_num_particle_sets(const mpmc_sim sim, int *n) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(n, sim->ctx, MPMC_ERR_ARG, "output pointer n is NULL");
  *n = sim->sets ? sim->sets->n : 0;
  return MPMC_SUCCESS;
}

/**
 * @brief Borrow set `id`: its name, size and indices (valid until the sets change).
 * Any of name, n, idx may be NULL.
 */
int mpmc_sim_get_particle_set(const mpmc_sim sim, int id, const char **name, int *n,
                              const int **idx) {
  if (!sim) return MPMC_ERR_ARG;
  const int count = sim->sets ? sim->sets->n : 0;
  MPMC_CHECK(id >= 0 && id < count, sim->ctx, MPMC_ERR_ARG,
             "particle set id %d does not exist (%d sets)", id, count);
  const mpmc_set *s = &sim->sets->s[id];
  if (name) *name = s->name;
  if (n) *n = s->n;
  if (idx) *idx = s->idx;
  return MPMC_SUCCESS;
}

/** @brief The id of the set called `name`; MPMC_ERR_ARG if there is none. */
int mpmc_sim_find_particle_set(const mpmc_sim sim, const char *name, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(name && id, sim->ctx, MPMC_ERR_ARG, "name or id pointer is NULL");
  const int count = sim->sets ? sim->sets->n : 0;
  for (int k = 0; k < count; ++k)
    if (strcmp(sim->sets->s[k].name, name) == 0) {
      *id = k;
      return MPMC_SUCCESS;
    }
  return MPMC_ERROR(sim->ctx, MPMC_ERR_ARG, "no particle set named '%s' (%d sets)", name, count);
}

void mpmc_sets_free(struct mpmc_sim_s *sim) {
  if (!sim || !sim->sets) return;
  for (int k = 0; k < sim->sets->n; ++k) {
    free(sim->sets->s[k].name);
    free(sim->sets->s[k].idx);
  }
  free(sim->sets->s);
  free(sim->sets);
  sim->sets = NULL;
}
