/* Hencky elasticity: principal logarithmic strains eps_a = 1/2 ln(lambda_a^2) of b = Fbar
 * Fbar^T, tau_a = K tr(eps) + 2G dev(eps)_a, coaxial with b.  Small strains (|eps| <~ 0.18)
 * take the eigen-free series of linalg.h; both paths agree to round-off (tests/t411). */
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
    double F3[3][3];
    /* 3D: dF is already a row-major 3x3 */
    double(*F)[3] = d == 3 ? (double(*)[3])(p->dF + (size_t)q * 9) : F3;
    if (d != 3) mpmc_embed(d, p->dF + (size_t)q * d * d, F3);
    double *b = p->be + (size_t)q * 6, *sg = p->stress + (size_t)q * 6;
    mpmc_push_forward(F, b);
    double eps[6];
    /* eps = 1/2 ln b: series for small strains, eigen path beyond (linalg.h) */
    if (mpmc_sym3_log_series(b, eps)) mpmc_sym3_log_eig(b, eps);
    const double tr = eps[0] + eps[1] + eps[2];
    const double inv_J = exp(-tr), p0 = (K - G2 / 3.0) * tr;
    /* sigma = (K tr eps I + 2G dev eps) / J */
    for (int k = 0; k < 6; ++k) sg[k] = G2 * eps[k] * inv_J;
    for (int k = 0; k < 3; ++k) sg[k] += p0 * inv_J;
  }
  return MPMC_SUCCESS;
}

static double hencky_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

const mpmc_material_ops mpmc_ops_hencky = {"hencky", hencky_update, hencky_wave_speed, 0, 0};
