/* TEMPORARY: replaced by the Hencky-J2 implementation (issue 3). */
#include <math.h>

#include "mpmc_impl.h"

static int j2_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  (void)mat; (void)id; (void)dt;
  return MPMC_ERROR(sim->ctx, MPMC_ERR_UNSUPPORTED, "hencky_j2 not implemented yet");
}
static double j2_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}
const mpmc_material_ops mpmc_ops_hencky_j2 = {"hencky_j2", j2_update, j2_wave_speed};
