/* Hencky elasticity: principal logarithmic strains eps_a = 1/2 ln(lambda_a^2) of b = Fbar
 * Fbar^T, tau_a = K tr(eps) + 2G dev(eps)_a, coaxial with b, J = sqrt(det b).  Small strains
 * (|eps| <~ 0.18) take the eigen-free series of linalg.h; both paths agree to round-off
 * (tests/t411).  The update runs in blocks of four points (stress_blocks.c). */
#include <math.h>

#include "mpmc_impl.h"

/* in the sim's instruction set, four points at a time (stress_blocks.c) */
static int hencky_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  return mpmc_kernels_stress_batch(sim, MPMC_BATCH_HENCKY)(sim, mat, id, dt);
}

static double hencky_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

static const mpmc_material_ops ops = {"hencky", hencky_update, hencky_wave_speed, 1, 1};

static const mpmc_param_desc params[] = {MPMC_PARAMS_ELASTIC};

static int hencky_setup(mpmc_context ctx, mpmc_material *m) {
  (void)ctx;
  mpmc_material_elastic(m);
  return MPMC_SUCCESS;
}

const mpmc_model mpmc_model_hencky = {
    .name = "hencky",
    .doc = "Hencky (logarithmic-strain) elasticity",
    .nparam = 3,
    .nstore = 3,
    .param = params,
    .flags = MPMC_MODEL_SOLID | MPMC_MODEL_HENCKY,
    .setup = hencky_setup,
    .ops = &ops};

/**
 * @brief Add a Hencky (logarithmic-strain) elastic material, tau = K tr(eps) 1 + 2G dev(eps).
 */
int mpmc_sim_add_material_hencky(mpmc_sim sim, double E, double nu, double rho, int *id) {
  const double par[] = {E, nu, rho};
  return mpmc_material_add(sim, &mpmc_model_hencky, par, id);
}
