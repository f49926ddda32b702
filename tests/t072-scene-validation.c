/* Scene validation, one case per class of key (issue 11): every value is checked for type
 * and range before anything runs, and the error names file:line:column and the key path.
 * Each case changes one line of a valid scene; the scene is checked through the library
 * (mpmc_workflow_run with MPMC_WORKFLOW_CHECK: nothing is written) and must fail with
 * MPMC_ERR_ARG and the message "<file>:<line>:<column>: key '<path>': <what>". */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "test_util.h"
#include "mpmc_workflow.h"

#define DIR MPMC_BINARY_DIR "/t072"

/* The valid scene, one entry per line (line numbers are 1 + index). */
static const char *const base[] = {
    "dim: 2",                                                                        /* 1 */
    "grid: {lo: [0, 0], hi: [4, 2], cell_size: 0.5}",                                /* 2 */
    "flip: 0.95",                                                                    /* 3 */
    "threads: 1",                                                                    /* 4 */
    "materials:",                                                                    /* 5 */
    "  clay: {model: hencky_j2, E: 1.0e6, nu: 0.3, rho: 2000, kappa_p: 4e4, eta: 5}", /* 6 */
    "  water: {model: newtonian, K: 2.0e9, mu: 1.0e-3, rho: 1000}",                  /* 7 */
    "geometry:",                                                                     /* 8 */
    "  - {type: box, material: clay, lo: [0, 0], hi: [2, 1], ppc: 2}",               /* 9 */
    "stages:",                                                                       /* 10 */
    "  - name: gravity",                                                             /* 11 */
    "    gravity: [0, -9.81]",                                                       /* 12 */
    "    damping: 0.3",                                                              /* 13 */
    "    strength_reduction: 1.65",                                                  /* 14 */
    "    dt_factor: 0.3",                                                            /* 15 */
    "    end: {kinetic_energy_ratio: 1.0e-3, max_time: 1, min_time: 0.1}",           /* 16 */
    "  - name: run",                                                                 /* 17 */
    "    end: {time: 1}",                                                            /* 18 */
};
#define NLINE (int)(sizeof base / sizeof base[0])

typedef struct {
  const char *name;
  int line;            /* 1-based line replaced                                    */
  const char *text;    /* the new line                                             */
  const char *value;   /* the text the error points at (its column is checked)      */
  const char *key;     /* the key path in the message                              */
  const char *what;    /* the rest of the message                                  */
} bad_case;

static const bad_case cases[] = {
    {"E > 0", 6, "  clay: {model: hencky_j2, E: 0, nu: 0.3, rho: 2000, kappa_p: 4e4, eta: 5}", "0, nu",
     "materials.clay.E", "must be > 0 (got 0)"},
    {"nu < 0.5", 6, "  clay: {model: hencky_j2, E: 1.0e6, nu: 0.5, rho: 2000, kappa_p: 4e4, eta: 5}", "0.5,",
     "materials.clay.nu", "must be in [0, 0.5) (got 0.5)"},
    {"nu >= 0", 6, "  clay: {model: hencky_j2, E: 1.0e6, nu: -0.1, rho: 2000, kappa_p: 4e4, eta: 5}", "-0.1",
     "materials.clay.nu", "must be in [0, 0.5) (got -0.1)"},
    {"rho > 0", 7, "  water: {model: newtonian, K: 2.0e9, mu: 1.0e-3, rho: -1000}", "-1000",
     "materials.water.rho", "must be > 0 (got -1000)"},
    {"K > 0", 7, "  water: {model: newtonian, K: 0, mu: 1.0e-3, rho: 1000}", "0, mu", "materials.water.K",
     "must be > 0 (got 0)"},
    {"mu >= 0", 7, "  water: {model: newtonian, K: 2.0e9, mu: -1, rho: 1000}", "-1", "materials.water.mu",
     "must be >= 0 (got -1)"},
    {"kappa_p > 0", 6, "  clay: {model: hencky_j2, E: 1.0e6, nu: 0.3, rho: 2000, kappa_p: -4e4, eta: 5}", "-4e4",
     "materials.clay.kappa_p", "must be > 0 (got -40000)"},
    {"eta >= 0", 6, "  clay: {model: hencky_j2, E: 1.0e6, nu: 0.3, rho: 2000, kappa_p: 4e4, eta: -5}", "-5",
     "materials.clay.eta", "must be >= 0 (got -5)"},
    {"E is a number", 6, "  clay: {model: hencky_j2, E: stiff, nu: 0.3, rho: 2000, kappa_p: 4e4, eta: 5}", "stiff",
     "materials.clay.E", "expected a number (got 'stiff')"},
    {"E finite", 6, "  clay: {model: hencky_j2, E: .inf, nu: 0.3, rho: 2000, kappa_p: 4e4, eta: 5}", ".inf",
     "materials.clay.E", "must be > 0 (got inf)"},
    {"cell_size > 0", 2, "grid: {lo: [0, 0], hi: [4, 2], cell_size: 0}", "0}", "grid.cell_size",
     "must be > 0 (got 0)"},
    {"ppc >= 1", 9, "  - {type: box, material: clay, lo: [0, 0], hi: [2, 1], ppc: 0}", "0}", "geometry.0.ppc",
     "must be in [1, 8] (got 0)"},
    {"ppc whole", 9, "  - {type: box, material: clay, lo: [0, 0], hi: [2, 1], ppc: 1.5}", "1.5",
     "geometry.0.ppc", "expected a whole number (got 1.5)"},
    {"flip in [0, 1]", 3, "flip: 1.2", "1.2", "flip", "must be in [0, 1] (got 1.2)"},
    {"threads >= 0", 4, "threads: -2", "-2", "threads", "must be in [0, 1024] (got -2)"},
    {"damping in [0, 1)", 13, "    damping: 1", "1", "stages.0.damping", "must be in [0, 1) (got 1)"},
    {"strength_reduction > 0", 14, "    strength_reduction: 0", "0", "stages.0.strength_reduction",
     "must be > 0 (got 0)"},
    {"dt_factor in (0, 1]", 15, "    dt_factor: 1.5", "1.5", "stages.0.dt_factor", "must be in (0, 1] (got 1.5)"},
    {"end time > 0", 18, "    end: {time: 0}", "0}", "stages.1.end.time", "must be > 0 (got 0)"},
    {"max_time > 0", 16, "    end: {kinetic_energy_ratio: 1.0e-3, max_time: -1, min_time: 0.1}", "-1",
     "stages.0.end.max_time", "must be > 0 (got -1)"},
    {"min_time <= max_time", 16, "    end: {kinetic_energy_ratio: 1.0e-3, max_time: 1, min_time: 2}", "2}",
     "stages.0.end.min_time", "must not exceed max_time = 1 (got 2)"},
    {"ke ratio in (0, 1)", 16, "    end: {kinetic_energy_ratio: 1, max_time: 1, min_time: 0.1}", "1, max",
     "stages.0.end.kinetic_energy_ratio", "must be in (0, 1) (got 1)"},
    {"force_dt is a bool", 15, "    force_dt: maybe", "maybe", "stages.0.force_dt",
     "expected true or false (got 'maybe')"},
    {"gravity has dim numbers", 12, "    gravity: [0, -9.81, 0]", "[0", "stages.0.gravity",
     "expected a list of 2 numbers"},
};
#define NCASE (int)(sizeof cases / sizeof cases[0])

static void write_scene(const char *path, int line, const char *text) {
  mkdir(DIR, 0777);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  for (int i = 0; i < NLINE; ++i) fprintf(f, "%s\n", i + 1 == line ? text : base[i]);
  fclose(f);
}

static int check(const char *scene, char *msg, size_t len) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  const int e = mpmc_workflow_run(ctx, scene, DIR "/never", 0, NULL, MPMC_WORKFLOW_CHECK | MPMC_WORKFLOW_QUIET);
  snprintf(msg, len, "%s", mpmc_context_last_error(ctx));
  mpmc_context_destroy(&ctx);
  return e;
}

static void test_valid(void **state) {
  (void)state;
  char msg[2048];
  write_scene(DIR "/valid.yaml", 0, NULL);
  const int e = check(DIR "/valid.yaml", msg, sizeof msg);
  if (e) fail_msg("the base scene: expected it to be valid, got %d: %s", e, msg);
}

static void test_bad_values(void **state) {
  (void)state;
  for (int i = 0; i < NCASE; ++i) {
    const bad_case *c = &cases[i];
    char path[256], msg[2048], want[512];
    snprintf(path, sizeof path, DIR "/case%02d.yaml", i);
    write_scene(path, c->line, c->text);
    const int e = check(path, msg, sizeof msg);
    if (e != MPMC_ERR_ARG) fail_msg("%s: expected MPMC_ERR_ARG (%d), got %d: %s", c->name, MPMC_ERR_ARG, e, msg);
    const char *at = strstr(c->text, c->value);
    if (!at) fail_msg("%s: bad case (value not in the line)", c->name);
    snprintf(want, sizeof want, "case%02d.yaml:%d:%d: key '%s': %s", i, c->line, (int)(at - c->text) + 1, c->key,
             c->what);
    if (!strstr(msg, want)) fail_msg("%s: expected the message to contain \"%s\", got \"%s\"", c->name, want, msg);
  }
  struct stat st;
  if (stat(DIR "/never", &st) == 0) fail_msg("a check wrote the output directory %s", DIR "/never");
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_valid), cmocka_unit_test(test_bad_values)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
