/* Conservation (issue 2, test 2): grid mass equals the points' mass; with no gravity and no
 * walls, total linear momentum is conserved to 1e-12 (relative to sum m|v|) over 1000 steps
 * for FLIP, PIC and a blend, every basis, with and without F-bar.  A PIC diffusivity D
 * (mpmc_sim_set_pic_diffusivity) steps exactly as the blend 1 - min(1, D dt / h^2) does. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "test_util.h"

static double urand(unsigned *s) {
  *s = *s * 1664525u + 1013904223u;
  return (*s >> 8) * (1.0 / 16777216.0) - 0.5;
}

/* D > 0: mpmc_sim_set_pic_diffusivity after the blend; *dt_out, *v_out (malloc'd): the
 * step and the final velocities, when not NULL */
static void run_pic(int dim, int basis, double blend, double D, int fbar, int nsteps, double *dt_out,
                    double **v_out) {
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double lo[3] = {-1, -1, -1}, hi[3] = {2, 2, 2}, h = dim == 2 ? 0.1 : 0.2;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  TCALL(mpmc_sim_set_flip_blend(sim, blend));
  if (D > 0) TCALL(mpmc_sim_set_pic_diffusivity(sim, D));
  int mat;
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 1000.0, 0.3, 1.0, &mat));
  double *x, *vol;
  const double plo[3] = {0, 0, 0}, phi[3] = {1, 1, 1};
  const int n = test_lattice(dim, plo, phi, h, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  double *v, *m;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_MASS, &m, NULL));
  unsigned seed = 99u;
  /* a drift plus a smooth shear/expansion field and a little noise: the block deforms, but
   * moves less than a quarter cell over the run, so the linear basis stays clear of the
   * cell-crossing instability */
  for (int q = 0; q < n; ++q)
    for (int a = 0; a < dim; ++a)
      v[q * dim + a] = 0.01 + 0.01 * sin(2 * M_PI * x[q * dim + (a + 1) % dim]) +
                       0.005 * urand(&seed);
  double P0[3] = {0, 0, 0}, scale = 0.0, M = 0.0;
  for (int q = 0; q < n; ++q) {
    M += m[q];
    for (int a = 0; a < dim; ++a) {
      P0[a] += m[q] * v[q * dim + a];
      scale += m[q] * fabs(v[q * dim + a]);
    }
  }
  TCLOSE(M, 1.0, 1e-13); /* rho = 1, unit square/cube */
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < nsteps; ++s) TCALL(mpmc_sim_step(sim, dt));
  /* the grid mass of the last P2G equals the total mass */
  double gm = 0.0;
  for (size_t i = 0; i < sim->grid.nn; ++i) gm += mpmc_grid_mass(&sim->grid, i);
  if (fabs(gm - M) > 1e-13 * M) fail_msg("grid mass %.17g, points' mass %.17g", gm, M);
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  for (int a = 0; a < dim; ++a) {
    double P = 0.0;
    for (int q = 0; q < n; ++q) P += m[q] * v[q * dim + a];
    if (fabs(P - P0[a]) > 1e-12 * scale)
      fail_msg("dim %d basis %d blend %g fbar %d: momentum[%d] %.17g after %d steps, %.17g before "
               "(relative change %.3g > 1e-12)",
               dim, basis, blend, fbar, a, P, nsteps, P0[a], fabs(P - P0[a]) / scale);
  }
  if (dt_out) *dt_out = dt;
  if (v_out) {
    *v_out = malloc(sizeof(double) * (size_t)n * (size_t)dim);
    assert_non_null(*v_out);
    memcpy(*v_out, v, sizeof(double) * (size_t)n * (size_t)dim);
  }
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void run(int dim, int basis, double blend, int fbar, int nsteps) {
  run_pic(dim, basis, blend, 0.0, fbar, nsteps, NULL, NULL);
}

/* the diffusivity replaces the blend (set to 0.3 here, unused): the same bits as the blend
 * 1 - min(1, D dt / h^2) of the same dt and h = 0.1, and pure PIC once D dt / h^2 >= 1 */
static void test_pic_diffusivity(void **state) {
  (void)state;
  const int n = 10 * 10 * 4; /* 2D: 10 x 10 cells of 2 x 2 points */
  const double ih = 1.0 / 0.1;
  double dt, *va, *vb;
  run_pic(2, MPMC_BASIS_UGIMP, 0.3, 0.3, 1, 200, &dt, &va);
  const double eta = 1.0 - fmin(1.0, 0.3 * dt * ih * ih);
  if (!(eta > 0.3 && eta < 1.0)) fail_msg("the case must blend: eta = %g", eta);
  run_pic(2, MPMC_BASIS_UGIMP, eta, 0.0, 1, 200, NULL, &vb);
  assert_memory_equal(va, vb, sizeof(double) * (size_t)n * 2);
  free(va);
  free(vb);
  run_pic(2, MPMC_BASIS_BSPLINE2, 0.3, 2.0 / (dt * ih * ih), 0, 100, NULL, &va);
  run_pic(2, MPMC_BASIS_BSPLINE2, 0.0, 0.0, 0, 100, NULL, &vb);
  assert_memory_equal(va, vb, sizeof(double) * (size_t)n * 2);
  free(va);
  free(vb);
}

static void test_momentum_2d(void **state) {
  (void)state;
  const double blends[3] = {1.0, 0.0, 0.95};
  for (int b = 0; b < 4; ++b)
    for (int k = 0; k < 3; ++k) run(2, b, blends[k], b % 2, 1000);
}

static void test_momentum_3d(void **state) {
  (void)state;
  run(3, MPMC_BASIS_BSPLINE2, 1.0, 1, 1000);
  run(3, MPMC_BASIS_UGIMP, 0.0, 0, 300);
  run(3, MPMC_BASIS_BSPLINE3, 0.9, 1, 300);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_momentum_2d),
      cmocka_unit_test(test_momentum_3d),
      cmocka_unit_test(test_pic_diffusivity),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
