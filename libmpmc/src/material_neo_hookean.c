/* Compressible Neo-Hookean (the paper, section 4.1):
 * psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
 * Kirchhoff stress tau = mu (b - 1) + lambda ln J 1, with b = Fbar Fbar^T carried
 * incrementally as b <- dF b dF^T (plane strain: b_zz stays 1). */
#include <math.h>

#include "mpmc_impl.h"

/* in the sim's instruction set, four points at a time (stress_blocks.c) */
static int nh_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  return mpmc_kernels_stress_batch(sim, MPMC_MAT_NEO_HOOKEAN)(sim, mat, id, dt);
}

static double nh_wave_speed(const mpmc_material *m) {
  return sqrt((m->lambda + 2.0 * m->G) / m->rho);
}

const mpmc_material_ops mpmc_ops_neo_hookean = {"neo_hookean", nh_update, nh_wave_speed, 1, 1};
