/* Nearly incompressible Newtonian fluid: sigma = K (J - 1) 1 + 2 mu dev(D), with J the
 * F-bar Jacobian when F-bar is on and D = sym(dF - 1)/dt the rate of deformation. */
#include <math.h>

#include "mpmc_impl.h"

/* in the sim's instruction set, four points at a time (stress_blocks.c) */
static int newtonian_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  return mpmc_kernels_stress_batch(sim, MPMC_BATCH_NEWTONIAN)(sim, mat, id, dt);
}

static double newtonian_wave_speed(const mpmc_material *m) { return sqrt(m->K / m->rho); }

static const mpmc_material_ops ops = {"newtonian", newtonian_update, newtonian_wave_speed, 1, 1};

static const mpmc_param_desc params[] = {
    MPMC_PARAM("K", "Pa", "bulk modulus", 0.0, INFINITY, MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN,
               0.0, -1, -1),
    MPMC_PARAM("mu", "Pa s", "dynamic viscosity", 0.0, INFINITY,
               MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, 0.0, -1, -1),
    MPMC_PARAM("rho", "kg/m^3", "density", 0.0, INFINITY, MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN,
               0.0, -1, -1)};

static int newtonian_setup(mpmc_context ctx, mpmc_material *m) {
  (void)ctx;
  m->K = m->par[0];
  m->mu = m->par[1];
  m->rho = m->par[2];
  return MPMC_SUCCESS;
}

const mpmc_model mpmc_model_newtonian = {
    .name = "newtonian",
    .doc = "Nearly incompressible Newtonian fluid",
    .nparam = 3,
    .nstore = 3,
    .param = params,
    .flags = MPMC_MODEL_FLUID,
    .setup = newtonian_setup,
    .ops = &ops};

/**
 * @brief Add a nearly incompressible Newtonian fluid: sigma = K (J - 1) 1 + 2 mu dev(D).
 * @param K bulk modulus [Pa], > 0
 * @param mu dynamic viscosity [Pa s], >= 0
 * @param rho density [kg/m^3], > 0
 */
int mpmc_sim_add_material_newtonian(mpmc_sim sim, double K, double mu, double rho, int *id) {
  const double par[] = {K, mu, rho};
  return mpmc_material_add(sim, &mpmc_model_newtonian, par, id);
}
