/* Kinetic damping (mpmc_sim_set_kinetic_damping; docs/workflows.md): the self-weight column of
 * t502 (plane strain, H = 10 m, nu = 0.499, uGIMP, F-bar) loaded by gravity at once reaches
 * E_k / E_k,max < 1e-3, held for 50 steps, in at most a third of the steps local damping
 * alone (alpha = 0.3, as slope_2d's gravity stage) needs, and settles to the analytic
 * settlement u(H) = rho g H^2 / 2M within 3 %.  Adaptive viscous damping
 * (mpmc_sim_set_adaptive_damping) alone reaches the tighter 1e-6 in at most a third of local
 * damping's steps (measured 502 against 2,252) within the same 3 %, its coefficient settles
 * near the column's lowest mode (c = 2 omega_1, omega_1 = pi c_p / 2H), and a restart from a
 * checkpoint goes on bit for bit.  Bad switch values are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <unistd.h>

#include <cmocka.h>

#include "test_util.h"

typedef struct {
  int steps;
  double settle_err;
  double c; /* adaptive damping's coefficient at the end [1/s] */
} result;

/* restart > 0: at that step the column goes through a checkpoint into a new sim, and both
 * go on for 100 steps, which must agree bit for bit */
static result column(double alpha, int kinetic, double adaptive, int restart, double ratio) {
  const double H = 10.0, W = 1.0, h = 0.5, rho = 2000.0, E = 10e6, nu = 0.499, g = 9.81;
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  sim = test_column_sim(ctx, 2, W, H, 2 * h, h);
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_UGIMP));
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  const double gv[2] = {0, -g};
  TCALL(mpmc_sim_set_gravity(sim, gv));
  TCALL(mpmc_sim_set_damping(sim, alpha));
  TCALL(mpmc_sim_set_kinetic_damping(sim, kinetic));
  TCALL(mpmc_sim_set_adaptive_damping(sim, adaptive));
  TCALL(mpmc_sim_set_flip_blend(sim, 0.99));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, nu, rho, &mat));
  double *x;
  const int n = test_column_fill(sim, 2, W, H, h, mat, &x);
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  double kemax = 0.0;
  int s = 0, below = 0;
  for (; s < 200000 && below < 50; ++s) {
    if (s == restart && restart > 0) {
      const char *path = "t506-adaptive.ckpt.h5";
      mpmc_sim b;
      TCALL(mpmc_sim_checkpoint_write(sim, path, NULL));
      TCALL(mpmc_sim_checkpoint_read(ctx, path, &b, NULL));
      unlink(path);
      for (int k = 0; k < 100; ++k) {
        TCALL(mpmc_sim_step(sim, dt));
        TCALL(mpmc_sim_step(b, dt));
      }
      double *xa, *xb, ca, cb;
      TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xa, NULL));
      TCALL(mpmc_sim_get_field(b, MPMC_FIELD_POSITION, &xb, NULL));
      const int same = !memcmp(xa, xb, sizeof(double) * 2 * (size_t)n);
      TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &xa));
      TCALL(mpmc_sim_restore_field(b, MPMC_FIELD_POSITION, &xb));
      TCALL(mpmc_sim_get_adaptive_damping(sim, &ca));
      TCALL(mpmc_sim_get_adaptive_damping(b, &cb));
      mpmc_sim_destroy(&b);
      if (!same || ca != cb || !(ca > 0))
        fail_msg("restart at step %d: expected the same positions and c > 0 after 100 steps, "
                 "got %s positions, c = %.17g and %.17g",
                 restart, same ? "the same" : "different", ca, cb);
      break;
    }
    TCALL(mpmc_sim_step(sim, dt));
    double ke;
    TCALL(mpmc_sim_get_kinetic_energy(sim, &ke));
    if (ke > kemax) kemax = ke;
    below = ke <= ratio * kemax ? below + 1 : 0;
  }
  double *xp;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  double utop = 0.0;
  int ntop = 0;
  for (int q = 0; q < n; ++q)
    if (x[2 * q + 1] > H - h / 2) utop += x[2 * q + 1] - xp[2 * q + 1], ntop++;
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &xp));
  const double uref = rho * g * H * H / (2 * M);
  result r = {s, fabs(utop / ntop - uref) / uref, 0.0};
  TCALL(mpmc_sim_get_adaptive_damping(sim, &r.c));
  free(x);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return r;
}

static void test_kinetic_damping_column(void **state) {
  (void)state;
  const result loc = column(0.3, 0, 0, 0, 1e-3), kin = column(0.3, 1, 0, 0, 1e-3),
               kin0 = column(0.0, 1, 0, 0, 1e-3);
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

static void test_adaptive_damping_column(void **state) {
  (void)state;
  const double H = 10.0, E = 10e6, nu = 0.499, rho = 2000.0;
  const double cp = sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho);
  const double c1 = 2 * M_PI * cp / (2 * H); /* 2 omega_1, the fixed-free column's first mode */
  const result loc = column(0.3, 0, 0, 0, 1e-6), kin = column(0.0, 1, 0, 0, 1e-6),
               adr = column(0.0, 0, 1, 0, 1e-6);
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("to 1e-6: local 0.3: %d steps, kinetic alone: %d, adaptive: %d (settlement error "
           "%.2f%%, c = %g 1/s, 2 omega_1 = %g)\n",
           loc.steps, kin.steps, adr.steps, 100 * adr.settle_err, adr.c, c1);
  if (!(3 * adr.steps <= loc.steps) || !(adr.settle_err < 0.03))
    fail_msg("adaptive damping: expected <= %d steps (a third of local damping's %d) and "
             "settlement within 3%%, got %d steps, %.2f%%",
             loc.steps / 3, loc.steps, adr.steps, 100 * adr.settle_err);
  if (!(adr.c > 0.5 * c1 && adr.c < 2.0 * c1))
    fail_msg("adaptive damping: expected c within a factor 2 of 2 omega_1 = %g 1/s, got %g", c1,
             adr.c);
  column(0.0, 0, 1, 120, 1e-6); /* the restart's check */
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
  assert_int_equal(mpmc_sim_set_adaptive_damping(sim, 2.5), MPMC_ERR_ARG);
  assert_non_null(
      strstr(mpmc_context_last_error(ctx), "adaptive damping ratio zeta = 2.5 must be in [0, 2]"));
  assert_int_equal(mpmc_sim_set_adaptive_damping(NULL, 1), MPMC_ERR_ARG);
  double c = -1.0;
  assert_int_equal(mpmc_sim_get_adaptive_damping(sim, NULL), MPMC_ERR_ARG);
  assert_int_equal(mpmc_sim_get_adaptive_damping(sim, &c), 0);
  assert_true(c == 0.0);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_kinetic_damping_column),
                                     cmocka_unit_test(test_adaptive_damping_column),
                                     cmocka_unit_test(test_kinetic_damping_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
