/* Single-point harness shared by the material tests: one material point in a one-cell grid;
 * the material's stress update is called directly with a prescribed relative deformation
 * gradient. */
#ifndef MPMC_POINT_HARNESS_H
#define MPMC_POINT_HARNESS_H

#include "linalg.h"
#include "mpmc_impl.h"
#include "test_util.h"

typedef struct {
  mpmc_context ctx;
  mpmc_sim sim;
  int id;
} point;

static inline void point_open(point *P, int dim) {
  TCALL(mpmc_context_create(&P->ctx));
  test_ctx = P->ctx;
  TCALL(mpmc_sim_create(P->ctx, dim, &P->sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  TCALL(mpmc_sim_set_grid(P->sim, lo, hi, 0.5));
}

/* after the material is added: one point of it */
static inline void point_seed(point *P) {
  const double x[3] = {0.5, 0.5, 0.5}, v = 1.0;
  TCALL(mpmc_sim_add_particles(P->sim, 1, x, &v, P->id, NULL));
  TCALL(mpmc_sim_prepare(P->sim));
}

/* dF: dim x dim row-major */
static inline void point_apply(point *P, const double *dF) {
  struct mpmc_sim_s *s = P->sim;
  const int d = s->cfg.dim;
  for (int k = 0; k < d * d; ++k) s->p.dF[k] = dF[k];
  double F3[3][3];
  mpmc_embed(d, dF, F3);
  s->p.J[0] *= mpmc_det3(F3);
  TCALL(s->mats[P->id].ops->stress_update(s, &s->mats[P->id], P->id, 1e-3));
}

static inline void point_close(point *P) {
  mpmc_sim_destroy(&P->sim);
  mpmc_context_destroy(&P->ctx);
  test_ctx = NULL;
}

/* von Mises stress of a Voigt tensor */
static inline double vm(const double *t) {
  const double p = (t[0] + t[1] + t[2]) / 3;
  const double a = t[0] - p, b = t[1] - p, c = t[2] - p;
  return sqrt(1.5 * (a * a + b * b + c * c + 2 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])));
}

#endif
