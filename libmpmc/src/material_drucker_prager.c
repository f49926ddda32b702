/* Drucker-Prager on Hencky elasticity, matched to Mohr-Coulomb's c and phi (and psi for the
 * flow): the compression (outer) cone, the extension (inner) cone or the plane-strain match;
 * with the tension cut-off and softening of the Mohr-Coulomb model (return_mc.h). */
#include "material_frictional.h"
#include "return_mc.h"

enum { MATCH = MPMC_FR_NPARAM, RHO_SAT, NPARAM };

static int dp_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  /* the matching's word index 0, 1, 2 is MPMC_DP_COMPRESSION - 1, ... */
  return mpmc_frictional_update(sim, mat, id, MPMC_DP_COMPRESSION + (int)mat->par[MATCH]);
}

static const mpmc_material_ops ops = {"drucker_prager", dp_update, mpmc_frictional_wave_speed, 0,
                                      1};

static const char *const match_words[] = {"compression", "extension", "plane_strain", NULL};
static const mpmc_param_desc params[] = {
    MPMC_PARAMS_FRICTIONAL,
    MPMC_CHOICE("match", "the cone's fit to Mohr-Coulomb: its compression or extension "
                         "meridian, or its plane-strain strength",
                match_words, 0.0),
    MPMC_PARAM_RHO_SAT(MPMC_FR_RHO)};

const mpmc_model mpmc_model_drucker_prager = {
    .name = "drucker_prager",
    .doc = "Hencky elasticity, Drucker-Prager plasticity matched to Mohr-Coulomb's c and phi",
    .nparam = NPARAM,
    .nstore = NPARAM,
    .param = params,
    .flags = MPMC_MODEL_SOLID | MPMC_MODEL_PLASTIC | MPMC_MODEL_REGION | MPMC_MODEL_EFFECTIVE | MPMC_MODEL_HENCKY,
    .strength = {MPMC_SRM_FRICTIONAL},
    .setup = mpmc_frictional_setup,
    .ops = &ops};

/**
 * @brief Add Hencky elasticity with Drucker-Prager plasticity matched to Mohr-Coulomb
 *        (the parameters of mpmc_sim_add_material_mohr_coulomb).
 * @param match MPMC_DP_MATCH_COMPRESSION (0), MPMC_DP_MATCH_EXTENSION (1) or
 *        MPMC_DP_MATCH_PLANE_STRAIN (2)
 */
int mpmc_sim_add_material_drucker_prager(mpmc_sim sim, double E, double nu, double rho, double c,
                                         double phi, double psi, double c_r, double phi_r,
                                         double psi_r, double eta, double sigma_t,
                                         mpmc_dp_match match, int *id) {
  const double par[] = {E, nu, rho, c, phi, psi, c_r, phi_r, psi_r, eta, sigma_t, (double)match, NAN};
  return mpmc_material_add(sim, &mpmc_model_drucker_prager, par, id);
}
