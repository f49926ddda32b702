/* Lattice seeding of the 3D slope (issue 4/10): meshes/slope_3d.geo with 0.2 m cells and
 * 2x2x2 points per cell.  The soil is 62.25 m^2 x 5 m = 311.25 m^3, i.e. 311,250 points of
 * 0.001 m^3 up to the lattice's resolution on the 45-degree face (35.4 m^2 at most half a
 * spacing, 0.05 m, off: +-1.77 m^3), and it must seed in seconds (cell-bucketed search). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "test_util.h"
#include "mpmc_gmsh.h"

static void test_slope_3d(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {56, 5, 6};
  int mat, first, count;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.2));
  TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.49, 1800, &mat));
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  TCALL(mpmc_seed_gmsh(sim, MPMC_SOURCE_DIR "/meshes/slope_3d.geo", "soil", MPMC_SEED_LATTICE, 2,
                       mat, &first, &count));
  clock_gettime(CLOCK_MONOTONIC, &t1);
  const double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  if (secs > 30) fail_msg("expected seeding in seconds, took %.1f s", secs);
  const double v = count * 1e-3;
  if (fabs(v - 311.25) > 1.77) fail_msg("expected 311.25 +- 1.77 m^3 (311,250 points), got %d points", count);
  /* boundary sets: the base holds the first layer of points under the soil's footprint */
  int id, nb;
  TCALL(mpmc_sim_find_particle_set(sim, "base", &id));
  TCALL(mpmc_sim_get_particle_set(sim, id, NULL, &nb, NULL));
  /* footprint 14.95 m x 5 m, 0.1 m spacing: ~149.5 x 50 points */
  if (abs(nb - 7475) > 50) fail_msg("expected ~7475 points on the base, got %d", nb);
  TCALL(mpmc_sim_find_particle_set(sim, "toe", &id));
  TCALL(mpmc_sim_get_particle_set(sim, id, NULL, &nb, NULL));
  assert_int_equal(nb, 1);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_slope_3d)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
