/* Mohr-Coulomb on Hencky elasticity: cohesion c, friction angle phi, dilation angle psi
 * (non-associated flow), a tension cut-off sigma_t, exponential softening of c, phi and psi
 * with the accumulated plastic deviatoric strain; the return map in principal stress space
 * with every region (return_mc.h). */
#include "material_frictional.h"
#include "return_mc.h"

static int mc_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  return mpmc_frictional_update(sim, mat, id, MPMC_MC_MOHR_COULOMB);
}

static const mpmc_material_ops ops = {"mohr_coulomb", mc_update, mpmc_frictional_wave_speed, 0,
                                      1};

static const mpmc_param_desc params[] = {MPMC_PARAMS_FRICTIONAL, MPMC_PARAM_RHO_SAT(MPMC_FR_RHO)};

const mpmc_model mpmc_model_mohr_coulomb = {
    .name = "mohr_coulomb",
    .doc = "Hencky elasticity, Mohr-Coulomb plasticity with tension cut-off and softening "
           "(drained frictional soil)",
    .nparam = MPMC_FR_NPARAM + 1,
    .nstore = MPMC_FR_NPARAM + 1,
    .param = params,
    .flags = MPMC_MODEL_SOLID | MPMC_MODEL_PLASTIC | MPMC_MODEL_REGION | MPMC_MODEL_EFFECTIVE | MPMC_MODEL_HENCKY,
    .strength = {MPMC_SRM_FRICTIONAL},
    .setup = mpmc_frictional_setup,
    .ops = &ops};

/**
 * @brief Add Hencky elasticity with Mohr-Coulomb plasticity (docs/materials.md).
 * @param c, phi, psi peak cohesion [Pa] (>= 0), friction angle [deg] in [0, 90) and
 *        dilation angle [deg] in [0, phi]
 * @param c_r, phi_r, psi_r residual values (<= the peak ones); NAN: no softening of that one
 * @param eta softening rate with the accumulated plastic deviatoric strain, >= 0
 * @param sigma_t tension cut-off on the largest principal stress [Pa], >= 0; INFINITY: none
 *        (the apex c cot phi)
 */
int mpmc_sim_add_material_mohr_coulomb(mpmc_sim sim, double E, double nu, double rho, double c,
                                       double phi, double psi, double c_r, double phi_r,
                                       double psi_r, double eta, double sigma_t, int *id) {
  const double par[] = {E, nu, rho, c, phi, psi, c_r, phi_r, psi_r, eta, sigma_t, NAN};
  return mpmc_material_add(sim, &mpmc_model_mohr_coulomb, par, id);
}
