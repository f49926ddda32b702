/* Hencky-J2, plane-strain simple shear (paper 4.3's ground: E = 1000 kPa, nu = 0.49,
 * su = 0.1 kPa given as undrained shear strength, kappa = sqrt(3) su): the shear stress
 * saturates at tau = su.  In steady simple shear the deviator aligns with D, so
 * sigma_xy -> su up to terms of order su/G = 3e-4: tolerance 1e-3 su. */
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "mpmc_impl.h"
#include "return_map.h"
#include "test_util.h"
#include "point_harness.h"



static void test_simple_shear_saturates_at_su(void **state) {
  (void)state;
  point P;
  point_open(&P, 2);
  const double E = 1000e3, nu = 0.49, su = 0.1e3;
  TCALL(mpmc_sim_add_material_hencky_j2_su(P.sim, E, nu, 1800.0, su, su, 0.0, &P.id));
  point_seed(&P);
  const double dg = 2e-4;
  const double dF[9] = /* 2x2 used */ {1, dg, 0, 1};
  double tau_max = 0.0;
  for (int n = 1; n <= 2500; ++n) { /* gamma = 0.5 */
    point_apply(&P, dF);
    const double *s = P.sim->p.stress;
    if (s[5] > tau_max) tau_max = s[5];
    /* on the yield surface once plastic: q = kappa = sqrt(3) su (J = 1) */
    if (P.sim->p.eps_p[0] > 0 && fabs(vm(s) - sqrt(3.0) * su) > 1e-10 * su)
      fail_msg("step %d: q = %.15g, expected kappa = %.15g", n, vm(s), sqrt(3.0) * su);
  }
  const double tau = P.sim->p.stress[5];
  if (fabs(tau - su) > 1e-3 * su || tau_max > su * (1 + 1e-12))
    fail_msg("simple shear: tau_xy = %.6g Pa at gamma = 0.5 (max %.6g), expected su = %.6g Pa",
             tau, tau_max, su);
  /* elastic until tau = su: yield at gamma ~ su / G; the points were plastic afterwards */
  mpmc_stats st;
  TCALL(mpmc_sim_get_stats(P.sim, &st));
  const double G = E / (2 * (1 + nu));
  const int64_t elastic_steps = (int64_t)floor(su / G / dg);
  if (st.return_maps < 2500 - elastic_steps - 2 || st.return_maps > 2500 - elastic_steps + 2)
    fail_msg("return maps counted %lld, expected %lld (2500 steps, %lld elastic)",
             (long long)st.return_maps, (long long)(2500 - elastic_steps), (long long)elastic_steps);
  point_close(&P);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_simple_shear_saturates_at_su)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
