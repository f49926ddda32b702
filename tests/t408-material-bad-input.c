/* Bad material input: each is refused with MPMC_ERR_ARG and a message naming the parameter
 * (and nothing is added). */
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


static mpmc_context ctx;
static mpmc_sim sim;

static int setup(void **state) {
  (void)state;
  if (mpmc_context_create(&ctx) || mpmc_sim_create(ctx, 2, &sim)) return -1;
  test_ctx = ctx;
  return 0;
}
static int teardown(void **state) {
  (void)state;
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return 0;
}

static void expect(int err, const char *what, const char *name) {
  const char *msg = mpmc_context_last_error(ctx);
  if (err != MPMC_ERR_ARG) fail_msg("%s: code %d, expected MPMC_ERR_ARG (%d)", what, err, MPMC_ERR_ARG);
  if (!strstr(msg, name)) fail_msg("%s: message \"%s\" does not name '%s'", what, msg, name);
  int n;
  TCALL(mpmc_sim_get_num_materials(sim, &n));
  if (n != 0) fail_msg("%s: %d materials after a refused call, expected 0", what, n);
  TCALL(mpmc_context_clear_error(ctx));
}

static void test_j2_strengths(void **state) {
  (void)state;
  const double E = 25e6, nu = 0.3, rho = 2000;
  int id;
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 0.0, 1.0, 5, &id), "kappa_p = 0", "kappa_p");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, -4e4, 1.0, 5, &id), "kappa_p < 0", "kappa_p");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, NAN, 1.0, 5, &id), "kappa_p NaN", "kappa_p");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 4e4, 0.0, 5, &id), "kappa_r = 0", "kappa_r");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 4e4, -1.0, 5, &id), "kappa_r < 0", "kappa_r");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 4e4, 5e4, 5, &id), "kappa_r > kappa_p", "kappa_r");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 4e4, 5e4, 5, &id), "kappa_r > kappa_p", "kappa_p");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 4e4, 2e3, -1, &id), "eta < 0", "eta");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, 4e4, 2e3, INFINITY, &id), "eta inf", "eta");
  expect(mpmc_sim_add_material_hencky_j2(sim, -E, nu, rho, 4e4, 2e3, 5, &id), "E < 0", "E");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, 0.5, rho, 4e4, 2e3, 5, &id), "nu = 0.5", "nu");
  expect(mpmc_sim_add_material_hencky_j2(sim, E, nu, 0.0, 4e4, 2e3, 5, &id), "rho = 0", "rho");
}

static void test_j2_su(void **state) {
  (void)state;
  int id;
  expect(mpmc_sim_add_material_hencky_j2_su(sim, 1e6, 0.49, 1800, 0.0, 0.1, 0, &id), "su_p = 0", "su_p");
  expect(mpmc_sim_add_material_hencky_j2_su(sim, 1e6, 0.49, 1800, 100, -1, 0, &id), "su_r < 0", "su_r");
  expect(mpmc_sim_add_material_hencky_j2_su(sim, 1e6, 0.49, 1800, 100, 200, 0, &id), "su_r > su_p", "su_r");
  expect(mpmc_sim_add_material_hencky_j2_su(sim, 1e6, 0.49, 1800, 100, 50, -2, &id), "eta < 0", "eta");
  /* the convention: kappa = sqrt(3) su */
  TCALL(mpmc_sim_add_material_hencky_j2_su(sim, 1e6, 0.49, 1800, 100.0, 25.0, 3.0, &id));
  const double kp = sim->mats[id].kappa_p, kr = sim->mats[id].kappa_r;
  if (fabs(kp - sqrt(3.0) * 100.0) > 1e-12 * kp || fabs(kr - sqrt(3.0) * 25.0) > 1e-12 * kr)
    fail_msg("su = 100, 25 gave kappa = %.15g, %.15g; expected sqrt(3) su = %.15g, %.15g", kp, kr,
             sqrt(3.0) * 100, sqrt(3.0) * 25);
  /* start the next tests from an empty material table */
  mpmc_sim_destroy(&sim);
  TCALL(mpmc_sim_create(ctx, 2, &sim));
}

static void test_newtonian(void **state) {
  (void)state;
  int id;
  expect(mpmc_sim_add_material_newtonian(sim, 0.0, 1e-3, 997.5, &id), "K = 0", "K");
  expect(mpmc_sim_add_material_newtonian(sim, -2e9, 1e-3, 997.5, &id), "K < 0", "bulk modulus");
  expect(mpmc_sim_add_material_newtonian(sim, 2e9, -1e-3, 997.5, &id), "mu < 0", "mu");
  expect(mpmc_sim_add_material_newtonian(sim, 2e9, 1e-3, -1.0, &id), "rho < 0", "rho");
}

static void test_reduction_and_solver(void **state) {
  (void)state;
  int id;
  TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.3, 1000, &id));
  int err = mpmc_sim_reduce_strength(sim, id, 1.65);
  if (err != MPMC_ERR_ARG || !strstr(mpmc_context_last_error(ctx), "not plastic"))
    fail_msg("reducing an elastic material: code %d, message \"%s\"", err, mpmc_context_last_error(ctx));
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e6, 0.3, 1000, 4e4, 2e3, 5, &id));
  err = mpmc_sim_reduce_strength(sim, id, 0.0);
  if (err != MPMC_ERR_ARG || !strstr(mpmc_context_last_error(ctx), "factor"))
    fail_msg("factor 0: code %d, message \"%s\"", err, mpmc_context_last_error(ctx));
  err = mpmc_sim_reduce_strength(sim, 7, 1.65);
  if (err != MPMC_ERR_ARG || !strstr(mpmc_context_last_error(ctx), "material"))
    fail_msg("material 7: code %d, message \"%s\"", err, mpmc_context_last_error(ctx));
  err = mpmc_sim_set_solver(sim, 3);
  if (err != MPMC_ERR_ARG || !strstr(mpmc_context_last_error(ctx), "solver"))
    fail_msg("solver 3: code %d, message \"%s\"", err, mpmc_context_last_error(ctx));
  if (sim->mats[id].kappa_p != 4e4 || sim->mats[id].kappa_r != 2e3)
    fail_msg("refused reductions changed the strengths to %g, %g", sim->mats[id].kappa_p,
             sim->mats[id].kappa_r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_j2_strengths, setup, teardown),
      cmocka_unit_test_setup_teardown(test_j2_su, setup, teardown),
      cmocka_unit_test_setup_teardown(test_newtonian, setup, teardown),
      cmocka_unit_test_setup_teardown(test_reduction_and_solver, setup, teardown),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
