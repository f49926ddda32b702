/* Compressible Neo-Hookean (formulas.md): psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
 * Kirchhoff stress tau = mu (b - 1) + lambda ln J 1, with b = Fbar Fbar^T carried
 * incrementally as b <- dF b dF^T (plane strain: b_zz stays 1). */
#include <math.h>

#include "linalg.h"
#include "mpmc_impl.h"

static int nh_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  mpmc_particles *p = &sim->p;
  const int d = sim->dim;
  const double mu = mat->G, lam = mat->lambda;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    if (p->mat[q] != id) continue;
    double F[3][3];
    mpmc_embed(d, p->dF + (size_t)q * d * d, F);
    double *b = p->be + (size_t)q * 6;
    mpmc_push_forward(F, b);
    const double J = sqrt(mpmc_det_sym(b));
    const double lnJ = log(J), inv_J = 1.0 / J;
    double *s = p->stress + (size_t)q * 6;
    for (int k = 0; k < 6; ++k) {
      const double tau = mu * (b[k] - (k < 3)) + (k < 3 ? lam * lnJ : 0.0);
      s[k] = tau * inv_J;
    }
  }
  return MPMC_SUCCESS;
}

static double nh_wave_speed(const mpmc_material *m) {
  return sqrt((m->lambda + 2.0 * m->G) / m->rho);
}

const mpmc_material_ops mpmc_ops_neo_hookean = {"neo_hookean", nh_update, nh_wave_speed, 0, 0};
