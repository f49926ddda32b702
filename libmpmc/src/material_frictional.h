/* What the frictional models (material_mohr_coulomb.c, material_drucker_prager.c) share:
 * their parameters (the first eleven, in this order) and the stress update over their points,
 * by return_mc.c's return map. */
#ifndef MPMC_MATERIAL_FRICTIONAL_H
#define MPMC_MATERIAL_FRICTIONAL_H

#include "mpmc_impl.h"

enum {
  MPMC_FR_E, MPMC_FR_NU, MPMC_FR_RHO, MPMC_FR_C, MPMC_FR_PHI, MPMC_FR_PSI, MPMC_FR_C_R,
  MPMC_FR_PHI_R, MPMC_FR_PSI_R, MPMC_FR_ETA, MPMC_FR_SIGMA_T, MPMC_FR_NPARAM
};

#define MPMC_PARAMS_FRICTIONAL                                                                \
  MPMC_PARAMS_ELASTIC,                                                                        \
  MPMC_PARAM("c", "Pa", "cohesion", 0.0, INFINITY, MPMC_PARAM_HI_OPEN, 0.0, -1, -1),          \
  MPMC_PARAM("phi", "deg", "friction angle", 0.0, 90.0, MPMC_PARAM_HI_OPEN, 0.0, -1, -1),     \
  MPMC_PARAM("psi", "deg", "dilation angle", 0.0, 90.0,                                       \
             MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, 0.0, -1, MPMC_FR_PHI),                 \
  MPMC_PARAM("c_r", "Pa", "residual cohesion", 0.0, INFINITY,                                 \
             MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, NAN, MPMC_FR_C, MPMC_FR_C),            \
  MPMC_PARAM("phi_r", "deg", "residual friction angle", 0.0, 90.0,                            \
             MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, NAN, MPMC_FR_PHI, MPMC_FR_PHI),        \
  MPMC_PARAM("psi_r", "deg", "residual dilation angle", 0.0, 90.0,                            \
             MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, NAN, MPMC_FR_PSI, MPMC_FR_PSI),        \
  MPMC_PARAM("eta", "1", "softening rate", 0.0, INFINITY,                                     \
             MPMC_PARAM_OPTIONAL | MPMC_PARAM_HI_OPEN, 0.0, -1, -1),                          \
  MPMC_PARAM("sigma_t", "Pa", "tension cut-off", 0.0, INFINITY, MPMC_PARAM_OPTIONAL,          \
             INFINITY, -1, -1)

/* strength reduction of the frictional parameters: c, tan phi, tan psi, sigma_t */
#define MPMC_SRM_FRICTIONAL                                                                   \
  [MPMC_FR_C] = MPMC_SRM_DIVIDE, [MPMC_FR_C_R] = MPMC_SRM_DIVIDE, [MPMC_FR_PHI] = MPMC_SRM_TAN, \
  [MPMC_FR_PHI_R] = MPMC_SRM_TAN, [MPMC_FR_PSI] = MPMC_SRM_TAN, [MPMC_FR_PSI_R] = MPMC_SRM_TAN, \
  [MPMC_FR_SIGMA_T] = MPMC_SRM_DIVIDE

/* elastic constants and the cross checks of the table's parameters */
int mpmc_frictional_setup(mpmc_context ctx, mpmc_material *m);
double mpmc_frictional_wave_speed(const mpmc_material *m);
/* the points of material id, with surface MPMC_MC_MOHR_COULOMB or MPMC_DP_* (return_mc.h) */
int mpmc_frictional_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                           int surface);

#endif
