/* Hencky elasticity: principal logarithmic strains eps_a = 1/2 ln(lambda_a^2) of b = Fbar
 * Fbar^T, tau_a = K tr(eps) + 2G dev(eps)_a, coaxial with b, J = sqrt(det b).  Small strains
 * (|eps| <~ 0.18) take the eigen-free series of linalg.h; both paths agree to round-off
 * (tests/t411).  The update runs in blocks of four points (stress_blocks.c). */
#include <math.h>

#include "mpmc_impl.h"

/* in the sim's instruction set, four points at a time (stress_blocks.c) */
static int hencky_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  return mpmc_kernels_stress_batch(sim, MPMC_MAT_HENCKY)(sim, mat, id, dt);
}

static double hencky_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

const mpmc_material_ops mpmc_ops_hencky = {"hencky", hencky_update, hencky_wave_speed, 1, 1};
