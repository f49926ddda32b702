/* Strength reduction between stages (paper 4.4: kappa / 1.65): the strengths are divided,
 * the accumulated plastic strain is kept, and the next return map brings the stress to the
 * reduced yield surface: q = kappa_reduced(eps_p') with eps_p' - eps_p = (q_before - q)/3G
 * (no deformation in the step, so the whole stress drop is plastic). */
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



static void test_reduce_keeps_plastic_strain(void **state) {
  (void)state;
  point P;
  point_open(&P, 2);
  const double E = 25e6, nu = 0.499, kp = 40.82e3, kr = 2.45e3, eta = 5.0, f = MPMC_DEFAULT_STRENGTH_REDUCTION;
  const double G = E / (2 * (1 + nu));
  TCALL(mpmc_sim_add_material_hencky_j2(P.sim, E, nu, 2150.0, kp, kr, eta, &P.id));
  point_seed(&P);
  const double d = 0.002;
  const double dF[9] = {exp(d), 0, 0, exp(-d)};
  for (int n = 0; n < 20; ++n) point_apply(&P, dF);
  const double ep = P.sim->p.eps_p[0], q0 = vm(P.sim->p.stress);
  assert_true(ep > 0.01);
  assert_true(f == 1.65);
  TCALL(mpmc_sim_reduce_strength(P.sim, -1, f));
  if (fabs(P.sim->mats[P.id].kappa_p - kp / f) > 1e-12 * kp || fabs(P.sim->mats[P.id].kappa_r - kr / f) > 1e-12 * kr)
    fail_msg("reduced strengths %.12g, %.12g; expected %.12g, %.12g", P.sim->mats[P.id].kappa_p,
             P.sim->mats[P.id].kappa_r, kp / f, kr / f);
  if (P.sim->p.eps_p[0] != ep) fail_msg("eps_p changed by the reduction: %.17g -> %.17g", ep, P.sim->p.eps_p[0]);
  const double I[9] = {1, 0, 0, 1};
  point_apply(&P, I);
  const double ep1 = P.sim->p.eps_p[0], q1 = vm(P.sim->p.stress);
  const double kap = (kr + (kp - kr) * exp(-eta * ep1)) / f;
  if (fabs(q1 - kap) > 1e-9 * kap)
    fail_msg("after reduction: q = %.12g, expected kappa/1.65 = %.12g", q1, kap);
  if (fabs((ep1 - ep) - (q0 - q1) / (3 * G)) > 1e-9 * (ep1 - ep))
    fail_msg("plastic strain increment %.12g, expected (q0 - q)/3G = %.12g", ep1 - ep, (q0 - q1) / (3 * G));
  point_close(&P);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_reduce_keeps_plastic_strain)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
