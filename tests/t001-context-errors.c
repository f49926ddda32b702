/* Context and errors: every code has its message from the X-macro, the last error
 * names the failure, destroy accepts NULL and clears the handle, the log level is checked. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

static void test_error_strings(void **state) {
  (void)state;
  assert_string_equal(mpmc_error_string(MPMC_SUCCESS), "success");
  assert_string_equal(mpmc_error_string(MPMC_ERR_ARG), "invalid argument");
  assert_string_equal(mpmc_error_string(MPMC_ERR_UNSTABLE),
                      "unstable run (time step above the stability limit, or energy growing without input)");
  for (int c = 0; c < MPMC_ERROR_COUNT; ++c) {
    const char *s = mpmc_error_string(c);
    if (!s || !*s || !strcmp(s, "unknown error code")) fail_msg("code %d has no message", c);
  }
  assert_string_equal(mpmc_error_string(-1), "unknown error code");
  assert_string_equal(mpmc_error_string(MPMC_ERROR_COUNT), "unknown error code");
}

static void test_last_error_and_destroy(void **state) {
  (void)state;
  mpmc_context ctx = NULL;
  mpmc_sim sim = NULL;
  assert_int_equal(mpmc_context_create(&ctx), MPMC_SUCCESS);
  assert_string_equal(mpmc_context_last_error(ctx), "");
  assert_int_equal(mpmc_sim_create(ctx, 4, &sim), MPMC_ERR_ARG);
  assert_null(sim);
  const char *msg = mpmc_context_last_error(ctx);
  if (!strstr(msg, "invalid argument") || !strstr(msg, "dim = 4"))
    fail_msg("message '%s' should say 'invalid argument' and name 'dim = 4'", msg);
  char buf[16];
  assert_int_equal(mpmc_context_get_last_error(ctx, buf, sizeof buf), MPMC_SUCCESS);
  assert_int_equal((int)strlen(buf), 15); /* truncated, terminated */
  assert_int_equal(strncmp(buf, msg, 15), 0);
  assert_int_equal(mpmc_context_get_last_error(ctx, buf, 0), MPMC_ERR_ARG);
  assert_int_equal(mpmc_context_clear_error(ctx), MPMC_SUCCESS);
  assert_string_equal(mpmc_context_last_error(ctx), "");
  assert_int_equal(mpmc_context_set_log_level(ctx, 9), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "log level 9"));
  assert_int_equal(mpmc_context_set_log_level(ctx, MPMC_LOG_SILENT), MPMC_SUCCESS);
  /* destroy: NULL accepted, handles cleared */
  assert_int_equal(mpmc_sim_create(ctx, 2, &sim), MPMC_SUCCESS);
  assert_int_equal(mpmc_sim_destroy(&sim), MPMC_SUCCESS);
  assert_null(sim);
  assert_int_equal(mpmc_sim_destroy(&sim), MPMC_SUCCESS);
  assert_int_equal(mpmc_sim_destroy(NULL), MPMC_SUCCESS);
  assert_int_equal(mpmc_context_destroy(&ctx), MPMC_SUCCESS);
  assert_null(ctx);
  assert_int_equal(mpmc_context_destroy(&ctx), MPMC_SUCCESS);
  assert_int_equal(mpmc_context_destroy(NULL), MPMC_SUCCESS);
  assert_string_equal(mpmc_context_last_error(NULL), "no context");
  int major, minor, patch;
  assert_int_equal(mpmc_version(&major, &minor, &patch), MPMC_SUCCESS);
  assert_int_equal(major * 10000 + minor * 100 + patch,
                   MPMC_VERSION_MAJOR * 10000 + MPMC_VERSION_MINOR * 100 + MPMC_VERSION_PATCH);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_error_strings),
      cmocka_unit_test(test_last_error_and_destroy),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
