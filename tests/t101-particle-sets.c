/* Named particle sets (issue 4): add, find, replace, borrow; bad input is refused with a
 * message naming the parameter. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

static mpmc_context ctx;
static mpmc_sim sim;

static int setup(void **state) {
  (void)state;
  if (mpmc_context_create(&ctx) || mpmc_sim_create(ctx, 2, &sim)) return -1;
  test_ctx = ctx;
  const double lo[2] = {0, 0}, hi[2] = {4, 4};
  int mat;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 1.0));
  TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.3, 1000, &mat));
  TCALL(mpmc_sim_seed_box(sim, lo, hi, 1, mat, NULL, NULL)); /* 16 points */
  return 0;
}

static int teardown(void **state) {
  (void)state;
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return 0;
}

static void check_message(int code, int expected_code, const char *needle) {
  if (code != expected_code)
    fail_msg("expected error %d, got %d (%s)", expected_code, code, mpmc_context_last_error(ctx));
  if (!strstr(mpmc_context_last_error(ctx), needle))
    fail_msg("expected the message to contain '%s', got '%s'", needle, mpmc_context_last_error(ctx));
}

static void test_add_find_replace(void **state) {
  (void)state;
  int n = -1, id = -1, id2 = -1, m = -1;
  TCALL(mpmc_sim_get_num_particle_sets(sim, &n));
  assert_int_equal(n, 0);
  const int a[3] = {0, 5, 15}, b[2] = {7, 8};
  TCALL(mpmc_sim_add_particle_set(sim, "tip", 3, a, &id));
  TCALL(mpmc_sim_add_particle_set(sim, "clamp", 2, b, &id2));
  assert_int_equal(id, 0);
  assert_int_equal(id2, 1);
  TCALL(mpmc_sim_find_particle_set(sim, "clamp", &m));
  assert_int_equal(m, 1);
  const char *name;
  const int *idx;
  TCALL(mpmc_sim_get_particle_set(sim, 0, &name, &n, &idx));
  assert_string_equal(name, "tip");
  assert_int_equal(n, 3);
  assert_int_equal(idx[2], 15);
  /* the indices were copied: the caller's array may change */
  int c[1] = {3};
  TCALL(mpmc_sim_add_particle_set(sim, "tip", 1, c, &id));
  c[0] = 9;
  assert_int_equal(id, 0); /* replaced in place */
  TCALL(mpmc_sim_get_num_particle_sets(sim, &n));
  assert_int_equal(n, 2);
  TCALL(mpmc_sim_get_particle_set(sim, 0, NULL, &n, &idx));
  assert_int_equal(n, 1);
  assert_int_equal(idx[0], 3);
  /* an empty set is allowed */
  TCALL(mpmc_sim_add_particle_set(sim, "empty", 0, NULL, NULL));
}

static void test_bad_input(void **state) {
  (void)state;
  const int bad[2] = {1, 16};
  int id;
  check_message(mpmc_sim_add_particle_set(sim, "edge", 2, bad, &id), MPMC_ERR_ARG,
                "idx[1] = 16 outside [0, 16)");
  check_message(mpmc_sim_add_particle_set(sim, "", 1, bad, &id), MPMC_ERR_ARG, "name");
  check_message(mpmc_sim_add_particle_set(sim, "edge", 2, NULL, &id), MPMC_ERR_ARG,
                "index array idx is NULL");
  check_message(mpmc_sim_add_particle_set(sim, "edge", -1, bad, &id), MPMC_ERR_ARG, "n = -1");
  check_message(mpmc_sim_find_particle_set(sim, "nothing", &id), MPMC_ERR_ARG,
                "no particle set named 'nothing'");
  int n;
  TCALL(mpmc_sim_get_num_particle_sets(sim, &n));
  check_message(mpmc_sim_get_particle_set(sim, n, NULL, NULL, NULL), MPMC_ERR_ARG,
                "does not exist");
  /* a failed add leaves no set behind */
  int n2;
  TCALL(mpmc_sim_get_num_particle_sets(sim, &n2));
  assert_int_equal(n, n2);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_add_find_replace),
                                     cmocka_unit_test(test_bad_input)};
  return cmocka_run_group_tests(tests, setup, teardown);
}
