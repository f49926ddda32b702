/* Grid update (eq 9): nodal velocities from momentum and forces, gravity, local damping,
 * wall constraints.  Leaves the new velocity in mom and the increment v^{n+1} - v^n in
 * force, which is what G2P's FLIP/PIC blend needs. */
#include "mpmc_impl.h"

static inline void update_impl(mpmc_sim sim, const int DIM, double dt) {
  mpmc_grid *g = &sim->grid;
  const double alpha = sim->damping;
  const double *gr = sim->gravity;
  double *restrict gm = g->mass, *restrict gp = g->mom, *restrict gf = g->force;
  const unsigned short *restrict fx = g->fixed;
  const long nn = (long)g->nn;
#pragma omp parallel for schedule(static) if (nn > MPMC_OMP_MIN)
  for (long i = 0; i < nn; ++i) {
    const double m = gm[i];
    if (m <= 0.0) continue;
    const double inv_m = 1.0 / m;
    double v0[3], f[3], v1[3];
    for (int a = 0; a < DIM; ++a) {
      v0[a] = gp[i * DIM + a] * inv_m;
      f[a] = gf[i * DIM + a] + m * gr[a];
    }
    if (alpha > 0.0) mpmc_damping_apply(alpha, f, v0, DIM);
    for (int a = 0; a < DIM; ++a) v1[a] = v0[a] + dt * f[a] * inv_m;
    const unsigned fl = fx[i];
    if (fl) {
      for (int a = 0; a < DIM; ++a) {
        if (fl & (1u << a)) v1[a] = 0.0;
        if ((fl & (8u << a)) && v1[a] < 0.0) v1[a] = 0.0;
        if ((fl & (64u << a)) && v1[a] > 0.0) v1[a] = 0.0;
      }
    }
    for (int a = 0; a < DIM; ++a) {
      gp[i * DIM + a] = v1[a];
      gf[i * DIM + a] = v1[a] - v0[a];
    }
  }
}

/* Walls on node planes with B-spline (or uGIMP) support beyond them: the velocity field is
 * continued across the wall by reflection, odd in the constrained components (zero at the
 * wall) and even in the free ones.  The ghost node's degree of freedom is thereby that of
 * its mirror partner (basis w_m -/+ w_g), so before the update the ghost's mass, momentum
 * and force are folded into the partner (fold = 1), and after it the ghost takes the
 * partner's reflected velocity and increment (fold = 0). */
static void mirror_ghosts(mpmc_sim sim, int fold) {
  mpmc_grid *g = &sim->grid;
  const int d = sim->dim;
  double *gm = g->mass, *gv = g->mom, *gf = g->force;
  const size_t stride[3] = {1, (size_t)g->n[0], (size_t)g->n[0] * (size_t)g->n[1]};
  for (int w = 0; w < sim->nmirror; ++w) {
    const mpmc_mirror *m = &sim->mirrors[w];
    const int a = m->axis, b = (a + 1) % d, c = (a + 2) % d;
    for (int k = 1; k <= MPMC_GHOST; ++k) {
      const int ig = m->plane + m->side * k, im = m->plane - m->side * k;
      if (ig < 0 || ig >= g->n[a] || im < 0 || im >= g->n[a]) continue;
      for (int j = 0; j < g->n[b]; ++j)
        for (int l = 0; l < (d == 3 ? g->n[c] : 1); ++l) {
          const size_t base = stride[b] * (size_t)j + (d == 3 ? stride[c] * (size_t)l : 0);
          const size_t ng = base + stride[a] * (size_t)ig, nm = base + stride[a] * (size_t)im;
          if (gm[ng] <= 0.0) continue;
          if (fold) {
            for (int e = 0; e < d; ++e) {
              const double sg = (m->odd >> e & 1u) ? -1.0 : 1.0;
              gv[nm * d + e] += sg * gv[ng * d + e];
              /* gravity enters the update as (folded mass) * g; the ghost's share of the
               * body force belongs to the partner with the reflection's sign */
              gf[nm * d + e] += sg * gf[ng * d + e] + (sg - 1.0) * gm[ng] * sim->gravity[e];
            }
            gm[nm] += gm[ng];
          } else {
            for (int e = 0; e < d; ++e) {
              const double sg = (m->odd >> e & 1u) ? -1.0 : 1.0;
              gv[ng * d + e] = sg * gv[nm * d + e];
              gf[ng * d + e] = sg * gf[nm * d + e];
            }
          }
        }
    }
  }
}

/** Phase 2 of the step. */
int mpmc_grid_update(mpmc_sim sim, double dt) {
  if (sim->walls_dirty) MPMC_CALL(mpmc_boundary_apply_flags(sim));
  if (sim->nmirror) mirror_ghosts(sim, 1);
  if (sim->dim == 2)
    update_impl(sim, 2, dt);
  else
    update_impl(sim, 3, dt);
  if (sim->nmirror) mirror_ghosts(sim, 0);
  return MPMC_SUCCESS;
}
