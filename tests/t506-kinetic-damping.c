/* Kinetic damping (mpmc_sim_set_kinetic_damping; docs/workflows.md): the self-weight column of
 * t502 (plane strain, H = 10 m, nu = 0.499, uGIMP, F-bar) loaded by gravity at once reaches
 * E_k / E_k,max < 1e-3, held for 50 steps, in at most a third of the steps local damping
 * alone (alpha = 0.3, as slope_2d's gravity stage) needs, and settles to the analytic
 * settlement u(H) = rho g H^2 / 2M within 3 %.  A bad switch value is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "test_util.h"

typedef struct {
  int steps;
  double settle_err;
} result;

static result column(double alpha, int kinetic) {
  const double H = 10.0, W = 1.0, h = 0.5, rho = 2000.0, E = 10e6, nu = 0.499, g = 9.81;
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {W, H + 2 * h};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_UGIMP));
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  const double gv[2] = {0, -g};
  TCALL(mpmc_sim_set_gravity(sim, gv));
  TCALL(mpmc_sim_set_damping(sim, alpha));
  TCALL(mpmc_sim_set_kinetic_damping(sim, kinetic));
  TCALL(mpmc_sim_set_flip_blend(sim, 0.99));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, nu, rho, &mat));
  double *x, *vol;
  const double plo[2] = {0, 0}, phi[2] = {W, H};
  const int n = test_lattice(2, plo, phi, h, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 1, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  double kemax = 0.0;
  int s = 0, below = 0;
  for (; s < 200000 && below < 50; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    double ke;
    TCALL(mpmc_sim_get_kinetic_energy(sim, &ke));
    if (ke > kemax) kemax = ke;
    below = ke <= 1e-3 * kemax ? below + 1 : 0;
  }
  double *xp;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  double utop = 0.0;
  int ntop = 0;
  for (int q = 0; q < n; ++q)
    if (x[2 * q + 1] > H - h / 2) utop += x[2 * q + 1] - xp[2 * q + 1], ntop++;
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &xp));
  const double uref = rho * g * H * H / (2 * M);
  result r = {s, fabs(utop / ntop - uref) / uref};
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return r;
}

static void test_kinetic_damping_column(void **state) {
  (void)state;
  const result loc = column(0.3, 0), kin = column(0.3, 1), kin0 = column(0.0, 1);
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("local 0.3: %d steps (settlement error %.2f%%), kinetic + local 0.3: %d (%.2f%%), "
           "kinetic alone: %d (%.2f%%)\n",
           loc.steps, 100 * loc.settle_err, kin.steps, 100 * kin.settle_err, kin0.steps,
           100 * kin0.settle_err);
  if (!(3 * kin.steps <= loc.steps) || !(kin.settle_err < 0.03))
    fail_msg("kinetic + local damping: expected <= %d steps (a third of local damping's %d) and "
             "settlement within 3%%, got %d steps, %.2f%%",
             loc.steps / 3, loc.steps, kin.steps, 100 * kin.settle_err);
}

static void test_kinetic_damping_bad_input(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  assert_int_equal(mpmc_sim_set_kinetic_damping(sim, 2), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "kinetic damping on = 2 must be 0 or 1"));
  assert_int_equal(mpmc_sim_set_kinetic_damping(NULL, 1), MPMC_ERR_ARG);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_kinetic_damping_column),
                                     cmocka_unit_test(test_kinetic_damping_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
