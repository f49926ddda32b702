/* Workflow runs (issue 5): a two-stage free fall through libmpmc_workflow and the `mpmc`
 * program.  Expected values are independent of the code:
 * - an unconstrained elastic body under uniform gravity translates rigidly; with a fixed
 *   step dt the explicit update (v += g dt, then x += v dt) gives after n steps
 *   u_y = -g dt^2 n (n + 1) / 2, and the centre of mass keeps its x;
 * - a box scene must not load libgmsh (/proc/self/maps);
 * - `mpmc check` writes nothing; a finished run's checkpoint is its end: `mpmc resume`
 *   refuses it (and leaves summary.json alone) until the scene has another stage, then runs
 *   that stage alone, ending where the three stages run uninterrupted end (u_y above,
 *   n = 150);
 * - slope_2d with the standard formulation (F-bar off) locks and does not run out;
 * - a wall on a gmsh boundary group's node set (Cook's "clamp", the nodes x = 0, y = 0..44)
 *   gives the same run as a box wall on those nodes; an unknown set is named in the error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "test_util.h"
#include "mpmc_workflow.h"

#define DIR MPMC_BINARY_DIR "/t651"

static const char *scene_text =
    "scene: fall\n"
    "dim: 2\n"
    "grid: {lo: [0, -1], hi: [2, 2], cell_size: 0.5}\n"
    "fbar: false\n"
    "plots: false\n"
    "materials:\n"
    "  m: {model: hencky, E: 1.0e6, nu: 0.3, rho: 1000}\n"
    "geometry:\n"
    "  - {type: box, lo: [0, 0], hi: [1, 1], ppc: 2}\n"
    "stages:\n"
    "  - {name: first, gravity: [0, -9.81], dt: 0.001, end: {time: 0.05}}\n"
    "  - {name: second, dt: 0.001, end: {time: 0.05}}\n"
    "metrics:\n"
    "  tip_displacement_y: {point: [0.5, 1.0]}\n"
    "  center_of_mass_x:\n";

static void write_text(const char *path, const char *text) { test_write_text(DIR, path, text); }

static void write_scene(const char *path) { write_text(path, scene_text); }

/* The summary in out after n steps of free fall from rest at dt = 0.001 s (every stage of
 * the scene): n steps, and the tip's u_y = -g dt^2 n (n + 1) / 2 (symplectic Euler) */
static void expect_free_fall(const char *summary, int n, const char *what) {
  const double g = 9.81, dt = 0.001;
  const double steps = test_json_number(summary, "steps");
  if (steps != n) fail_msg("%s: expected %d steps in all, got %g", what, n, steps);
  const double expect = -g * dt * dt * n * (n + 1) / 2.0;
  const double uy = test_json_number(summary, "tip_displacement_y");
  if (fabs(uy - expect) > 1e-9 * fabs(expect))
    fail_msg("%s: tip_displacement_y expected %.12g, got %.12g", what, expect, uy);
}

static void test_free_fall(void **state) {
  (void)state;
  const char *scene = DIR "/fall.yaml", *out = DIR "/out-fall";
  write_scene(scene);
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_workflow_run(ctx, scene, out, 0, NULL, MPMC_WORKFLOW_FORCE | MPMC_WORKFLOW_QUIET));
  test_ctx = NULL;
  mpmc_context_destroy(&ctx);
  expect_free_fall(DIR "/out-fall/summary.json", 100, "free fall (2 stages of 0.05 s)");
  const double cx = test_json_number(DIR "/out-fall/summary.json", "center_of_mass_x");
  if (fabs(cx - 0.5) > 1e-12) fail_msg("free fall: center_of_mass_x expected 0.5, got %.15g", cx);
  if (!test_exists(DIR "/out-fall/series.csv")) fail_msg("no series.csv");
  /* a box scene never maps libgmsh */
  FILE *maps = fopen("/proc/self/maps", "r");
  if (maps) {
    char line[1024];
    while (fgets(line, sizeof line, maps))
      if (strstr(line, "libgmsh")) fail_msg("a box scene loaded libgmsh: %s", line);
    fclose(maps);
  }
}

/* The file at path still holds before; what names the case. */
static void expect_unchanged(const char *path, const char *before, const char *what) {
  char *now = test_slurp(path);
  if (strcmp(before, now) != 0) fail_msg("%s: expected %s unchanged, it was rewritten:\n%s", what, path, now);
  free(now);
}

static void test_check_and_resume(void **state) {
  (void)state;
  const char *scene = DIR "/fall.yaml";
  write_scene(scene);
  assert_int_equal(system("rm -rf '" DIR "/out-check' '" DIR "/out-resume'"), 0);
  if (test_run_cli("check '" DIR "/fall.yaml' --out '" DIR "/out-check'", NULL, 0) != 0) fail_msg("mpmc check: expected exit 0");
  if (test_exists(DIR "/out-check")) fail_msg("mpmc check created its output directory");
  if (test_run_cli("run '" DIR "/fall.yaml' --out '" DIR "/out-resume' --quiet", NULL, 0) != 0) fail_msg("mpmc run: expected exit 0");
  /* the run ends with a checkpoint after its last stage (workflows/run.c): the rest of this
   * test resumes from it */
  if (!test_exists(DIR "/out-resume/checkpoint.h5"))
    fail_msg("mpmc run: expected " DIR "/out-resume/checkpoint.h5 (the finished run's state), found none");
  /* the checkpoint is the finished run: nothing to resume, and the outputs stay as they are */
  char *before = test_slurp(DIR "/out-resume/summary.json");
  if (test_run_cli("resume '" DIR "/out-resume' --quiet", NULL, 0) == 0) fail_msg("resume of a finished run: expected a failure");
  expect_unchanged(DIR "/out-resume/summary.json", before, "resume of a finished run");
  /* the message says what to do */
  char msg[2048];
  if (test_run_cli("resume '" DIR "/out-resume'", msg, sizeof msg) == 0)
    fail_msg("resume of a finished run: expected a failure");
  if (!strstr(msg, "finished all 2 stages") || !strstr(msg, "add a stage"))
    fail_msg("resume of a finished run: expected 'finished all 2 stages ... add a stage', got: %s", msg);
  /* one more stage in the scene: resuming runs it alone */
  char three[4096];
  snprintf(three, sizeof three, "%s", scene_text);
  char *at = strstr(three, "metrics:");
  assert_non_null(at);
  const char *metrics = strstr(scene_text, "metrics:");
  snprintf(at, sizeof three - (size_t)(at - three), "  - {name: third, dt: 0.001, end: {time: 0.05}}\n%s", metrics);
  write_text(scene, three);
  if (test_run_cli("resume '" DIR "/out-resume' --quiet", NULL, 0) != 0) fail_msg("mpmc resume with a third stage: expected exit 0");
  expect_free_fall(DIR "/out-resume/summary.json", 150, "resume with a third stage");
  char *summary = test_slurp(DIR "/out-resume/summary.json");
  if (!strstr(summary, "\"third\"")) fail_msg("resume: summary.json names no stage 'third'");
  free(summary);
  /* the last stage's end raised from 0.05 to 0.08 s: it goes on from where it ended */
  char *end = strstr(three, "{name: third, dt: 0.001, end: {time: 0.05}}");
  assert_non_null(end);
  memcpy(strstr(end, "0.05"), "0.08", 4);
  write_text(scene, three);
  if (test_run_cli("resume '" DIR "/out-resume' --quiet", NULL, 0) != 0) fail_msg("mpmc resume with a later end: expected exit 0");
  expect_free_fall(DIR "/out-resume/summary.json", 180, "resume to a later end");
  /* a later end from the command line, after the run's own overrides: 20 steps more */
  if (test_run_cli("resume '" DIR "/out-resume' --set stages.third.end.time=0.1 --quiet", NULL, 0) != 0)
    fail_msg("mpmc resume --set stages.third.end.time=0.1: expected exit 0");
  expect_free_fall(DIR "/out-resume/summary.json", 200, "resume --set to a later end");
  /* a bad override is named, and the outputs stay; --out does not apply to resume */
  free(before);
  before = test_slurp(DIR "/out-resume/summary.json");
  if (test_run_cli("resume '" DIR "/out-resume' --set stages.third.end.tme=1", msg, sizeof msg) == 0)
    fail_msg("resume with a misspelt override: expected a failure");
  if (!strstr(msg, "tme")) fail_msg("resume with a misspelt override: the message does not name it: %s", msg);
  expect_unchanged(DIR "/out-resume/summary.json", before, "a refused resume");
  free(before);
  if (test_run_cli("resume '" DIR "/out-resume' --out '" DIR "/elsewhere'", NULL, 0) != 2) fail_msg("resume --out: expected exit 2");
  /* and once more with nothing changed: finished, after three stages */
  if (test_run_cli("resume '" DIR "/out-resume'", msg, sizeof msg) == 0) fail_msg("resume of the finished run: expected a failure");
  if (!strstr(msg, "finished all 3 stages") || !strstr(msg, "raise the last stage's end time"))
    fail_msg("resume of a finished run: expected 'finished all 3 stages ... raise the last stage's end time', got: %s", msg);
}

static void test_slope_locks_without_fbar(void **state) {
  (void)state;
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  const char *sets[] = {"grid.cell_size=0.5", "fbar=false", "plots=false"};
  TCALL(mpmc_workflow_run(ctx, MPMC_SOURCE_DIR "/workflows/slope_2d.yaml", DIR "/out-slope-std", 3, sets,
                          MPMC_WORKFLOW_FORCE | MPMC_WORKFLOW_QUIET));
  test_ctx = NULL;
  mpmc_context_destroy(&ctx);
  /* volumetric locking (paper Fig. 16): the standard formulation barely moves, while with
   * F-bar the same slope runs out by metres (scene-slope_2d) */
  const double r = test_json_number(DIR "/out-slope-std/summary.json", "runout_distance");
  if (!(r < 1.0)) fail_msg("slope_2d without F-bar: expected a locked slope, run-out < 1 m, got %g m", r);
}

static int run_cook(const char *wall, const char *out) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  const char *sets[] = {"grid.cell_size=4", "plots=false", "stages.0.end={time: 2}", wall};
  const int rc = mpmc_workflow_run(ctx, MPMC_SOURCE_DIR "/workflows/cook_membrane.yaml", out, 4, sets,
                                   MPMC_WORKFLOW_FORCE | MPMC_WORKFLOW_QUIET);
  if (rc && !strstr(mpmc_context_last_error(ctx), "nosuch"))
    fail_msg("Cook with %s: %s", wall, mpmc_context_last_error(ctx));
  if (rc && !strstr(mpmc_context_last_error(ctx), "stages.0.walls.0.set"))
    fail_msg("unknown node set: the message '%s' does not name the scene key", mpmc_context_last_error(ctx));
  mpmc_context_destroy(&ctx);
  return rc;
}

static void test_node_set_wall(void **state) {
  (void)state;
  assert_int_equal(run_cook("stages.0.walls.0={set: clamp, kind: fixed}", DIR "/out-cook-set"), 0);
  assert_int_equal(run_cook("stages.0.walls.0={lo: [0, 0], hi: [0, 44], kind: fixed}", DIR "/out-cook-box"), 0);
  const double a = test_json_number(DIR "/out-cook-set/summary.json", "tip_displacement_y");
  const double b = test_json_number(DIR "/out-cook-box/summary.json", "tip_displacement_y");
  if (!(a > 1e-3) || a != b) fail_msg("tip u_y: node-set wall %.17g, box wall %.17g (expected equal, > 1 mm)", a, b);
  if (run_cook("stages.0.walls.0={set: nosuch, kind: fixed}", DIR "/out-cook-bad") == 0)
    fail_msg("a wall on an unknown node set: expected a failure");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_free_fall),
      cmocka_unit_test(test_check_and_resume),
      cmocka_unit_test(test_slope_locks_without_fbar),
      cmocka_unit_test(test_node_set_wall),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
