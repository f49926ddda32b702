/* Hencky elasticity: principal logarithmic strains eps_a = 1/2 ln(lambda_a^2) of b = Fbar
 * Fbar^T, tau_a = K tr(eps) + 2G dev(eps)_a, coaxial with b. */
#include <math.h>

#include "linalg.h"
#include "mpmc_impl.h"

static int hencky_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  mpmc_particles *p = &sim->p;
  const int d = sim->dim;
  const double K = mat->K, G2 = 2.0 * mat->G;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    if (p->mat[q] != id) continue;
    double F[3][3], lam[3], Q[3][3], eps[3], tau[3];
    mpmc_embed(d, p->dF + (size_t)q * d * d, F);
    double *b = p->be + (size_t)q * 6;
    mpmc_push_forward(F, b);
    mpmc_sym3_eig(b, lam, Q);
    for (int a = 0; a < 3; ++a) eps[a] = 0.5 * log(lam[a]);
    const double tr = eps[0] + eps[1] + eps[2];
    const double inv_J = exp(-tr);
    for (int a = 0; a < 3; ++a) tau[a] = (K * tr + G2 * (eps[a] - tr / 3.0)) * inv_J;
    mpmc_sym3_compose(tau, Q, p->stress + (size_t)q * 6);
  }
  return MPMC_SUCCESS;
}

static double hencky_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

const mpmc_material_ops mpmc_ops_hencky = {"hencky", hencky_update, hencky_wave_speed};
