/* Compressible Neo-Hookean (the paper, section 4.1):
 * psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
 * Kirchhoff stress tau = mu (b - 1) + lambda ln J 1, with b = Fbar Fbar^T carried
 * incrementally as b <- dF b dF^T (plane strain: b_zz stays 1). */
#include <math.h>

#include "mpmc_impl.h"

/* in the sim's instruction set, four points at a time (stress_blocks.c) */
static int nh_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  return mpmc_kernels_stress_batch(sim, MPMC_BATCH_NEO_HOOKEAN)(sim, mat, id, dt);
}

static double nh_wave_speed(const mpmc_material *m) {
  return sqrt((m->lambda + 2.0 * m->G) / m->rho);
}

static const mpmc_material_ops ops = {"neo_hookean", nh_update, nh_wave_speed, 1, 1};

static const mpmc_param_desc params[] = {MPMC_PARAMS_ELASTIC};

static int nh_setup(mpmc_context ctx, mpmc_material *m) {
  (void)ctx;
  mpmc_material_elastic(m);
  return MPMC_SUCCESS;
}

const mpmc_model mpmc_model_neo_hookean = {
    .name = "neo_hookean",
    .doc = "Compressible Neo-Hookean elasticity",
    .nparam = 3,
    .nstore = 3,
    .param = params,
    .flags = MPMC_MODEL_SOLID,
    .setup = nh_setup,
    .ops = &ops};

/**
 * @brief Add a compressible Neo-Hookean material,
 *        psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2.
 * @param E Young's modulus [Pa], > 0
 * @param nu Poisson's ratio, in [0, 0.5)
 * @param rho density [kg/m^3], > 0
 * @param[out] id the material's id (may be NULL)
 */
int mpmc_sim_add_material_neo_hookean(mpmc_sim sim, double E, double nu, double rho, int *id) {
  const double par[] = {E, nu, rho};
  return mpmc_material_add(sim, &mpmc_model_neo_hookean, par, id);
}
