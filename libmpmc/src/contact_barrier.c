/* TEMPORARY: replaced by rigid bodies with barrier contact (issue 8). */
#include <math.h>

#include "mpmc_impl.h"

int mpmc_contact_update(struct mpmc_sim_s *sim, double dt) {
  (void)dt;
  return MPMC_ERROR(sim->ctx, MPMC_ERR_UNSUPPORTED, "contact not implemented yet");
}
double mpmc_contact_stable_dt(const struct mpmc_sim_s *sim) {
  (void)sim;
  return INFINITY;
}
void mpmc_contact_free(struct mpmc_sim_s *sim) { (void)sim; }
