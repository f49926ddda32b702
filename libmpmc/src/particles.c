/* Structure-of-arrays particle store.  Optional fields are allocated only when a scene
 * needs them (mpmc_particles_ensure). */
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

static int grow_always(mpmc_context ctx, double **a, size_t ncomp, int cap) {
  double *b = realloc(*a, sizeof(double) * ncomp * (size_t)cap);
  MPMC_CHECK(b, ctx, MPMC_ERR_MEMORY, "cannot grow a particle field to %d points", cap);
  *a = b;
  return MPMC_SUCCESS;
}

/* an optional field grows only if the scene has it */
static int grow(mpmc_context ctx, double **a, size_t ncomp, int cap) {
  return *a ? grow_always(ctx, a, ncomp, cap) : MPMC_SUCCESS;
}

int mpmc_particles_reserve(mpmc_context ctx, mpmc_particles *p, int cap) {
  if (cap <= p->cap) return MPMC_SUCCESS;
  const int d = p->dim;
  MPMC_CALL(grow_always(ctx, &p->x, d, cap));
  MPMC_CALL(grow_always(ctx, &p->x0, d, cap));
  MPMC_CALL(grow_always(ctx, &p->v, d, cap));
  MPMC_CALL(grow_always(ctx, &p->m, 1, cap));
  MPMC_CALL(grow_always(ctx, &p->vol0, 1, cap));
  MPMC_CALL(grow_always(ctx, &p->J, 1, cap));
  MPMC_CALL(grow_always(ctx, &p->stress, 6, cap));
  int *mat = realloc(p->mat, sizeof(int) * (size_t)cap);
  MPMC_CHECK(mat, ctx, MPMC_ERR_MEMORY, "cannot grow the material ids to %d points", cap);
  p->mat = mat;
  if (p->id) {
    int *id = realloc(p->id, sizeof(int) * (size_t)cap);
    MPMC_CHECK(id, ctx, MPMC_ERR_MEMORY, "cannot grow the point ids to %d points", cap);
    p->id = id;
  }
  MPMC_CALL(grow(ctx, &p->Jbar, 1, cap));
  MPMC_CALL(grow(ctx, &p->Janc, 1, cap));
  MPMC_CALL(grow(ctx, &p->be, 6, cap));
  MPMC_CALL(grow(ctx, &p->eps_p, 1, cap));
  MPMC_CALL(grow(ctx, &p->region, 1, cap));
  MPMC_CALL(grow(ctx, &p->Jp, 1, cap));
  MPMC_CALL(grow(ctx, &p->pw, 1, cap));
  MPMC_CALL(grow(ctx, &p->lp, 1, cap));
  MPMC_CALL(grow(ctx, &p->force, d, cap));
  MPMC_CALL(grow(ctx, &p->cforce, d, cap));
  if (p->nustate > 0) MPMC_CALL(grow(ctx, &p->ustate, (size_t)p->nustate, cap));
  MPMC_CALL(grow(ctx, &p->dF, (size_t)d * d, cap));
  p->cap = cap;
  return MPMC_SUCCESS;
}

/* Allocate an optional field (if absent) with capacity cap and fill its n*ncomp entries. */
int mpmc_particles_ensure(mpmc_context ctx, mpmc_particles *p, double **field, int ncomp,
                          double fill) {
  if (*field) return MPMC_SUCCESS;
  const size_t cap = p->cap > 0 ? (size_t)p->cap : 1;
  *field = malloc(sizeof(double) * (size_t)ncomp * cap);
  MPMC_CHECK(*field, ctx, MPMC_ERR_MEMORY, "cannot allocate a particle field for %zu points", cap);
  for (size_t i = 0; i < (size_t)ncomp * (size_t)p->n; ++i) (*field)[i] = fill;
  return MPMC_SUCCESS;
}

void mpmc_particles_free(mpmc_particles *p) {
  double **f[] = {&p->x,     &p->x0,    &p->v,  &p->m,      &p->vol0,   &p->J,
                  &p->stress, &p->Jbar, &p->Janc, &p->be, &p->eps_p, &p->region, &p->Jp, &p->pw, &p->lp,
                  &p->force, &p->cforce, &p->ustate, &p->dF};
  for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i) {
    free(*f[i]);
    *f[i] = NULL;
  }
  free(p->mat);
  p->mat = NULL;
  free(p->id);
  p->id = NULL;
  p->n = p->cap = p->nustate = 0;
}
