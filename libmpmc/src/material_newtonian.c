/* Nearly incompressible Newtonian fluid: sigma = K (J - 1) 1 + 2 mu dev(D), with J the
 * F-bar Jacobian when F-bar is on and D = sym(dF - 1)/dt the rate of deformation. */
#include <math.h>

#include "mpmc_impl.h"

/* in the sim's instruction set, four points at a time (stress_blocks.c) */
static int newtonian_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  return mpmc_kernels_stress_batch(sim, MPMC_MAT_NEWTONIAN)(sim, mat, id, dt);
}

static double newtonian_wave_speed(const mpmc_material *m) { return sqrt(m->K / m->rho); }

const mpmc_material_ops mpmc_ops_newtonian = {"newtonian", newtonian_update, newtonian_wave_speed, 1, 1};
