/* Hencky-J2 below yield is Hencky elasticity: the same general deformation applied to a
 * hencky and a hencky_j2 point (strengths far above the stresses) gives the same stress and
 * b_e, no plastic strain and no return map; uniaxial stretch matches the closed form
 * sigma_xx = (K + 4G/3) ln(l) / l, sigma_yy = sigma_zz = (K - 2G/3) ln(l) / l. */
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



static void test_elastic_equals_hencky(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.5));
  const double E = 1e6, nu = 0.3;
  int mh, mj;
  TCALL(mpmc_sim_add_material_hencky(sim, E, nu, 1000.0, &mh));
  TCALL(mpmc_sim_add_material_hencky_j2(sim, E, nu, 1000.0, 1e12, 1e11, 5.0, &mj));
  /* b_e to the bit: the point-by-point forms of the two updates are compiled alike only
   * without contraction (the FMA sets contract scalar and vector code differently) */
  TCALL(mpmc_sim_set_kernels(sim, MPMC_KERNELS_BASELINE));
  const double x[6] = {0.25, 0.5, 0.5, 0.75, 0.5, 0.5}, v = 1.0;
  TCALL(mpmc_sim_add_particles(sim, 1, x, &v, mh, NULL));
  TCALL(mpmc_sim_add_particles(sim, 1, x + 3, &v, mj, NULL));
  TCALL(mpmc_sim_prepare(sim));
  const double F[9] = {1.1, 0.2, 0.0, 0.05, 0.95, 0.1, 0.0, 0.02, 1.03};
  for (int n = 0; n < 3; ++n) {
    memcpy(sim->p.dF, F, sizeof F);
    memcpy(sim->p.dF + 9, F, sizeof F);
    for (int m = 0; m < 2; ++m) TCALL(sim->mats[m].ops->stress_update(sim, &sim->mats[m], m, 1e-3));
    const double *a = sim->p.stress, *b = sim->p.stress + 6;
    const double scale = fabs(a[0]) + fabs(a[1]) + fabs(a[2]);
    for (int c = 0; c < 6; ++c) {
      if (fabs(a[c] - b[c]) > 1e-14 * scale)
        fail_msg("step %d: sigma[%d] hencky %.17g, hencky_j2 %.17g", n, c, a[c], b[c]);
      if (sim->p.be[c] != sim->p.be[6 + c])
        fail_msg("step %d: be[%d] hencky %.17g, hencky_j2 %.17g", n, c, sim->p.be[c], sim->p.be[6 + c]);
    }
  }
  assert_true(sim->p.eps_p[1] == 0.0);
  mpmc_stats st;
  TCALL(mpmc_sim_get_stats(sim, &st));
  assert_int_equal(st.return_maps, 0);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void test_uniaxial_closed_form(void **state) {
  (void)state;
  point P;
  point_open(&P, 3);
  const double E = 1e6, nu = 0.3, K = E / (3 * (1 - 2 * nu)), G = E / (2 * (1 + nu));
  TCALL(mpmc_sim_add_material_hencky_j2(P.sim, E, nu, 1000.0, 1e12, 1e12, 0.0, &P.id));
  point_seed(&P);
  const double l = 1.3;
  const double F[9] = {l, 0, 0, 0, 1, 0, 0, 0, 1};
  point_apply(&P, F);
  const double *s = P.sim->p.stress;
  const double sx = (K + 4 * G / 3) * log(l) / l, sy = (K - 2 * G / 3) * log(l) / l;
  const double expect[6] = {sx, sy, sy, 0, 0, 0};
  for (int c = 0; c < 6; ++c)
    if (fabs(s[c] - expect[c]) > 1e-13 * sx)
      fail_msg("uniaxial stretch %g: sigma[%d] = %.17g, expected %.17g", l, c, s[c], expect[c]);
  point_close(&P);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_elastic_equals_hencky),
      cmocka_unit_test(test_uniaxial_closed_form),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
