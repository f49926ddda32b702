/* TEMPORARY: replaced by named particle sets (issue 4). */
#include "mpmc_impl.h"
void mpmc_sets_free(struct mpmc_sim_s *sim) { (void)sim; }
