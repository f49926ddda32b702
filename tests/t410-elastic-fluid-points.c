/* Single-point stress paths of the other models against closed forms:
 *   neo-Hookean, uniaxial stretch l: sigma = [mu (b - 1) + lambda ln J 1] / J, b = diag(l^2, 1, 1);
 *   Hencky, plane-strain simple shear g: eps = 1/2 ln b (b = F F^T) by the closed-form
 *     2x2 eigen-decomposition, sigma = (K tr eps 1 + 2G dev eps) / J;
 *   Newtonian, a velocity gradient L over dt: sigma = K (J - 1) 1 + 2 mu dev(sym L). */
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



static void test_neo_hookean_uniaxial(void **state) {
  (void)state;
  point P;
  point_open(&P, 3);
  const double E = 70, nu = 0.499, mu = E / (2 * (1 + nu)), lam = E * nu / ((1 + nu) * (1 - 2 * nu));
  TCALL(mpmc_sim_add_material_neo_hookean(P.sim, E, nu, 1.0, &P.id));
  point_seed(&P);
  const double l = 1.2, F[9] = {l, 0, 0, 0, 1, 0, 0, 0, 1};
  point_apply(&P, F);
  const double sx = (mu * (l * l - 1) + lam * log(l)) / l, sy = lam * log(l) / l;
  const double expect[6] = {sx, sy, sy, 0, 0, 0};
  for (int c = 0; c < 6; ++c)
    if (fabs(P.sim->p.stress[c] - expect[c]) > 1e-12 * fabs(sx))
      fail_msg("neo-Hookean stretch %g: sigma[%d] = %.15g, expected %.15g", l, c, P.sim->p.stress[c], expect[c]);
  point_close(&P);
}

static void test_hencky_simple_shear(void **state) {
  (void)state;
  point P;
  point_open(&P, 2);
  const double E = 1e6, nu = 0.3, K = E / (3 * (1 - 2 * nu)), G = E / (2 * (1 + nu)), g = 0.4;
  TCALL(mpmc_sim_add_material_hencky(P.sim, E, nu, 1000.0, &P.id));
  point_seed(&P);
  const double F[9] = {1, g, 0, 1};
  point_apply(&P, F);
  /* b = [[1 + g^2, g], [g, 1]]: eigenvalues m +- r, m = 1 + g^2/2, r = g sqrt(1 + g^2/4) */
  const double m = 1 + g * g / 2, r = g * sqrt(1 + g * g / 4);
  const double l1 = m + r, l2 = m - r, e1 = 0.5 * log(l1), e2 = 0.5 * log(l2);
  /* J = 1, tr eps = 0: sigma = 2G eps; eigenvector of l1: (g, l1 - 1 - g^2) normalised */
  double v[2] = {g, l1 - 1 - g * g};
  const double nv = hypot(v[0], v[1]);
  v[0] /= nv;
  v[1] /= nv;
  const double sxx = 2 * G * (e1 * v[0] * v[0] + e2 * v[1] * v[1]);
  const double syy = 2 * G * (e1 * v[1] * v[1] + e2 * v[0] * v[0]);
  const double sxy = 2 * G * (e1 - e2) * v[0] * v[1];
  const double expect[6] = {sxx, syy, 0, 0, 0, sxy};
  (void)K;
  for (int c = 0; c < 6; ++c)
    if (fabs(P.sim->p.stress[c] - expect[c]) > 1e-12 * G)
      fail_msg("Hencky simple shear %g: sigma[%d] = %.15g, expected %.15g", g, c, P.sim->p.stress[c], expect[c]);
  point_close(&P);
}

static void test_newtonian_rate(void **state) {
  (void)state;
  point P;
  point_open(&P, 2);
  const double K = 2e9, mu = 1e-3, dt = 1e-5;
  TCALL(mpmc_sim_add_material_newtonian(P.sim, K, mu, 997.5, &P.id));
  point_seed(&P);
  const double L[4] = {-3.0, 5.0, 1.0, 2.0}; /* 1/s */
  const double F[9] = {1 + dt * L[0], dt * L[1], dt * L[2], 1 + dt * L[3]};
  struct mpmc_sim_s *s = P.sim;
  for (int k = 0; k < 4; ++k) s->p.dF[k] = F[k];
  const double J = F[0] * F[3] - F[1] * F[2];
  s->p.J[0] = J;
  TCALL(s->mats[P.id].ops->stress_update(s, &s->mats[P.id], P.id, dt));
  const double trD = (L[0] + L[3]) / 3, pr = K * (J - 1);
  const double expect[6] = {pr + 2 * mu * (L[0] - trD), pr + 2 * mu * (L[3] - trD), pr + 2 * mu * (0 - trD),
                            0, 0, mu * (L[1] + L[2])};
  for (int c = 0; c < 6; ++c)
    if (fabs(s->p.stress[c] - expect[c]) > 1e-9 * fabs(pr) + 1e-9 * mu)
      fail_msg("Newtonian: sigma[%d] = %.15g, expected %.15g", c, s->p.stress[c], expect[c]);
  /* the viscous part alone, at J = 1 */
  s->p.J[0] = 1.0;
  TCALL(s->mats[P.id].ops->stress_update(s, &s->mats[P.id], P.id, dt));
  if (fabs(s->p.stress[5] - mu * (L[1] + L[2])) > 1e-12 * mu || fabs(s->p.stress[0] - 2 * mu * (L[0] - trD)) > 1e-9 * mu)
    fail_msg("Newtonian viscous stress: sigma_xy = %.15g (expected %.15g), sigma_xx = %.15g (expected %.15g)",
             s->p.stress[5], mu * (L[1] + L[2]), s->p.stress[0], 2 * mu * (L[0] - trD));
  point_close(&P);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_neo_hookean_uniaxial),
      cmocka_unit_test(test_hencky_simple_shear),
      cmocka_unit_test(test_newtonian_rate),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
