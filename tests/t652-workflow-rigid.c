/* Rigid bodies in scenes (issue 8): a plate pushed onto an elastic block by a stage's ramped
 * velocity, through libmpmc_workflow.  Expected values are independent of the code:
 * - the plate's settlement: velocity V reached by a linear ramp over t_r, run for T, moves
 *   V (T - t_r / 2) (the discrete sum lags by at most V dt / 2);
 * - the load: the block (slip sides, fixed base) is in uniaxial strain, so the plate's
 *   pressure is M eps with M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) and eps the displacement of
 *   a point in the middle over its height (the barrier's own compression is not in eps, and
 *   the surface layer of B-spline points is left out: it compresses 2 % more);
 * - bad rigid-body keys fail with the key path and what is wrong. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "test_util.h"
#include "mpmc_workflow.h"

#define DIR MPMC_BINARY_DIR "/t652"

/* %s: the stage's rigid_bodies line, %s: the metric's body */
static const char *scene_fmt =
    "scene: plate\n"
    "dim: 2\n"
    "grid: {lo: [0, 0], hi: [1, 1.5], cell_size: 0.25}\n"
    "basis: bspline2\n"
    "fbar: false\n"
    "plots: false\n"
    "materials:\n"
    "  m: {model: hencky, E: 1.0e6, nu: 0.3, rho: 1000}\n"
    "geometry:\n"
    "  - {type: box, lo: [0, 0], hi: [1, 1], ppc: 2}\n"
    "rigid_bodies:\n"
    "  - {name: plate, type: box, lo: [-0.5, 1.0], hi: [1.5, 1.5]}\n"
    "stages:\n"
    "  - name: push\n"
    "    dt: 0.002\n"
    "    damping: 0.05\n"
    "    series_points: 100\n"
    "    walls:\n"
    "      - {face: x_lo, kind: slip}\n"
    "      - {face: x_hi, kind: slip}\n"
    "      - {face: y_lo, kind: fixed}\n"
    "    rigid_bodies: {%s: {velocity: [0, -0.01], ramp: 0.2}}\n"
    "    end: {time: 1.0}\n"
    "metrics:\n"
    "  tip_displacement_y: {point: [0.5, 0.56]}\n"
    "  bearing_capacity_ratio: {body: %s, width: 1.0, su: 1000}\n";

static void write_scene(const char *path, const char *stage_body, const char *metric_body) {
  mkdir(DIR, 0777);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, scene_fmt, stage_body, metric_body);
  fclose(f);
}

static int run(const char *scene, const char *out, char *msg, size_t len) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  const int e = mpmc_workflow_run(ctx, scene, out, 0, NULL, MPMC_WORKFLOW_QUIET | MPMC_WORKFLOW_FORCE);
  snprintf(msg, len, "%s", mpmc_context_last_error(ctx));
  mpmc_context_destroy(&ctx);
  return e;
}

static void test_plate_on_block(void **state) {
  (void)state;
  char msg[1024];
  write_scene(DIR "/plate.yaml", "plate", "plate");
  const int e = run(DIR "/plate.yaml", DIR "/out", msg, sizeof msg);
  if (e) fail_msg("expected the plate scene to run, got %d: %s", e, msg);
  const char *sum = DIR "/out/summary.json";
  const double V = 0.01, T = 1.0, tr = 0.2, dt = 0.002;
  const double delta = test_json_number(sum, "settlement_over_B"); /* B = 1 m */
  const double want = V * (T - 0.5 * tr);
  if (!(fabs(delta - want) <= 0.5 * V * dt + 1e-12))
    fail_msg("plate settlement %.9g m, expected V (T - t_r/2) = %.9g m within V dt / 2", delta, want);
  /* uniaxial strain of the block: a point in the middle (initially at y = 0.5625) */
  const double E = 1.0e6, nu = 0.3, M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)), y0 = 0.5625;
  const double uy = test_json_number(sum, "tip_displacement_y");
  const double q = test_json_number(sum, "q_over_su") * 1000.0; /* su = 1000 Pa, loaded width 1 m */
  const double qwant = M * -uy / y0;
  if (!(uy < 0 && -uy < delta)) fail_msg("top point moved %g m, expected down by less than the plate's %g m", uy, delta);
  if (!(fabs(q - qwant) <= 0.03 * qwant))
    fail_msg("plate pressure %.6g Pa, expected M eps = %.6g Pa within 3 %% (eps = %.4g)", q, qwant, -uy / y0);
  const double ratio = test_json_number(sum, "bearing_capacity_ratio") * 1000.0;
  if (!(ratio > 0.5 * q && ratio < q))
    fail_msg("bearing_capacity_ratio su = %.6g Pa, expected between half and all of the final %.6g Pa "
             "(the load rises with the settlement)", ratio, q);
  /* series.csv: the footing's metrics are undefined on the row before the first step, an
   * empty field there, never "nan" (nor "inf", nor "-0") */
  FILE *f = fopen(DIR "/out/series.csv", "r");
  assert_non_null(f);
  char line[4096];
  int rows = 0;
  while (fgets(line, sizeof line, f)) {
    ++rows;
    if (strstr(line, "nan") || strstr(line, "inf"))
      fail_msg("series.csv row %d holds a non-number: %s", rows, line);
    /* field by field: "-0" (or -0.0, -0e+00) anywhere, the last field too */
    for (char *save = NULL, *tok = strtok_r(line, ",\r\n", &save); tok; tok = strtok_r(NULL, ",\r\n", &save)) {
      char *end = NULL;
      const double x = strtod(tok, &end);
      if (end != tok && *end == '\0' && x == 0.0 && signbit(x))
        fail_msg("series.csv row %d field '%s' is a negative zero", rows, tok);
    }
  }
  fclose(f);
  if (rows < 3) fail_msg("series.csv has %d rows, expected a header and the series", rows);
}

static void expect_bad(const char *stage_body, const char *metric_body, const char *key, const char *what) {
  char msg[1024];
  write_scene(DIR "/bad.yaml", stage_body, metric_body);
  const int e = run(DIR "/bad.yaml", DIR "/out-bad", msg, sizeof msg);
  if (e != MPMC_ERR_ARG) fail_msg("expected MPMC_ERR_ARG (%d), got %d: %s", MPMC_ERR_ARG, e, msg);
  if (!strstr(msg, key) || !strstr(msg, what))
    fail_msg("expected the message to name '%s' and say '%s', got '%s'", key, what, msg);
}

static void test_bad_keys(void **state) {
  (void)state;
  expect_bad("foot", "plate", "stages.0.rigid_bodies.foot", "no rigid body 'foot' (rigid_bodies: plate)");
  expect_bad("plate", "foot", "metrics.bearing_capacity_ratio.body", "no rigid body 'foot'");
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_plate_on_block), cmocka_unit_test(test_bad_keys)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
