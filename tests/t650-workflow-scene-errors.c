/* Bad scenes (issue 5): syntax error, wrong type, out-of-range value, unknown key, missing
 * mesh, bad --set.  Each must fail with a non-zero code (library) and exit status (the
 * `mpmc` program), a message naming file:line:column and the key, and write nothing over an
 * existing output directory unless --force. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "test_util.h"
#include "mpmc_workflow.h"

#define DIR MPMC_BINARY_DIR "/t650"

/* A valid scene; line numbers matter: the grid block is lines 3-6. */
static const char *scene_fmt =
    "dim: 2\n"                                      /* 1 */
    "basis: bspline2\n"                             /* 2 */
    "grid:\n"                                       /* 3 */
    "  lo: [0, 0]\n"                                /* 4 */
    "  hi: [2, 2]\n"                                /* 5 */
    "  %s\n"                                        /* 6: the cell_size line */
    "materials:\n"                                  /* 7 */
    "  m: %s\n"                                     /* 8: the material */
    "geometry:\n"                                   /* 9 */
    "  - %s\n"                                      /* 10: the body */
    "stages:\n"                                     /* 11 */
    "  - name: fall\n"                              /* 12 */
    "    gravity: [0, -9.81]\n"                     /* 13 */
    "    end: {time: 0.002}\n";                     /* 14 */

static const char *good_body = "{type: box, lo: [0, 0], hi: [1, 1]}";
/* line 8's material (test_material_rules changes it) */
static const char *material = "{model: hencky, E: 1.0e6, nu: 0.3, rho: 1000}";

static void write_scene(const char *path, const char *cell_line, const char *body) {
  mkdir(DIR, 0777);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, scene_fmt, cell_line, material, body);
  fclose(f);
}

/* Run through the library; returns the code and copies the message. */
static int run_lib(const char *scene, const char *out, int nset, const char *const *sets, int flags,
                   char *msg, size_t len) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  const int e = mpmc_workflow_run(ctx, scene, out, nset, sets, flags | MPMC_WORKFLOW_QUIET);
  snprintf(msg, len, "%s", mpmc_context_last_error(ctx));
  mpmc_context_destroy(&ctx);
  return e;
}

/* One bad scene through the library and through the program; out must stay untouched. */
static void check_bad(const char *name, const char *cell_line, const char *body, const char *where,
                      const char *key, const char *what) {
  char scene[512], out[512], msg[2048], marker[600];
  snprintf(scene, sizeof scene, DIR "/%s.yaml", name);
  snprintf(out, sizeof out, DIR "/out-%s", name);
  write_scene(scene, cell_line, body);
  mkdir(out, 0777);
  snprintf(marker, sizeof marker, "%s/keep.txt", out);
  FILE *f = fopen(marker, "w");
  fputs("mine", f);
  fclose(f);
  const int e = run_lib(scene, out, 0, NULL, MPMC_WORKFLOW_FORCE, msg, sizeof msg);
  if (e == 0) fail_msg("%s: expected a non-zero code, got 0", name);
  char loc[600];
  snprintf(loc, sizeof loc, "%s.yaml:%s", name, where);
  test_expect_in(name, msg, loc);
  test_expect_in(name, msg, key);
  test_expect_in(name, msg, what);
  /* even with --force, a scene that does not load writes nothing */
  char sum[600];
  snprintf(sum, sizeof sum, "%s/summary.json", out);
  if (test_exists(sum)) fail_msg("%s: expected no %s after a bad scene, found one", name, sum);
  char args[1400];
  snprintf(args, sizeof args, "run '%s' --out '%s' --force", scene, out);
  const int st = test_run_cli(args, msg, sizeof msg);
  if (st == 0) fail_msg("%s: expected a non-zero exit status from mpmc, got 0", name);
  test_expect_in(name, msg, loc);
  test_expect_in(name, msg, key);
  if (test_exists(sum)) fail_msg("%s: the program wrote %s for a bad scene", name, sum);
  if (!test_exists(marker)) fail_msg("%s: %s was removed", name, marker);
}

/* The model table's rules, as the scene reader applies them: each message names line 8, the
 * key and the rule (the frictional models' ranges and "must not exceed" relations). */
static void test_material_rules(void **state) {
  (void)state;
  static const struct {
    const char *name, *mat, *key, *what;
  } cases[] = {
      {"mc_psi", "{model: mohr_coulomb, E: 1.0e6, nu: 0.3, rho: 1000, c: 1.0e3, phi: 20, psi: 25}",
       "key 'materials.m.psi'", "must not exceed phi = 20 (got 25)"},
      {"mc_phi", "{model: mohr_coulomb, E: 1.0e6, nu: 0.3, rho: 1000, c: 1.0e3, phi: 95}",
       "key 'materials.m.phi'", "must be in [0, 90) (got 95)"},
      {"mc_c", "{model: mohr_coulomb, E: 1.0e6, nu: 0.3, rho: 1000, c: -1, phi: 30}",
       "key 'materials.m.c'", "must be >= 0 (got -1)"},
      {"mc_cr", "{model: mohr_coulomb, E: 1.0e6, nu: 0.3, rho: 1000, c: 1.0e3, phi: 30, c_r: 2.0e3}",
       "key 'materials.m.c_r'", "must not exceed c = 1000 (got 2000)"},
      {"mc_missing", "{model: mohr_coulomb, E: 1.0e6, nu: 0.3, rho: 1000, c: 1.0e3}",
       "key 'materials.m.phi'", "required key is missing: friction angle [deg]"},
      {"dp_match", "{model: drucker_prager, E: 1.0e6, nu: 0.3, rho: 1000, c: 1.0e3, phi: 30, match: cone}",
       "key 'materials.m.match'", "must be one of compression, extension, plane_strain"},
      {"j2_both", "{model: hencky_j2, E: 1.0e6, nu: 0.3, rho: 1000, kappa_p: 1.0e3, su: 600}",
       "key 'materials.m.su'", "give kappa_p or su, not both"},
      {"mc_key", "{model: mohr_coulomb, E: 1.0e6, nu: 0.3, rho: 1000, c: 1.0e3, phi: 30, kappa_p: 1}",
       "key 'materials.m.kappa_p'", "unknown key"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
    material = cases[k].mat;
    check_bad(cases[k].name, "cell_size: 0.5", good_body, "8:", cases[k].key, cases[k].what);
  }
  material = "{model: hencky, E: 1.0e6, nu: 0.3, rho: 1000}";
}

static void test_syntax_error(void **state) {
  (void)state;
  /* a flow list left open on line 6: libyaml reports it where the list cannot go on, at
   * line 7, column 10 (the ':' after "materials"), while parsing grid.cell_size */
  check_bad("syntax", "cell_size: [0.5", good_body, "7:10:", "key 'grid.cell_size", "YAML syntax error");
}

static void test_wrong_type(void **state) {
  (void)state;
  /* "abc" starts at line 6, column 14 */
  check_bad("type", "cell_size: abc", good_body, "6:14:", "key 'grid.cell_size'", "expected a number (got 'abc')");
}

static void test_out_of_range(void **state) {
  (void)state;
  check_bad("range", "cell_size: -1", good_body, "6:14:", "key 'grid.cell_size'", "must be > 0 (got -1)");
}

static void test_unknown_key(void **state) {
  (void)state;
  /* the key itself is at line 6, column 3 */
  check_bad("unknown", "cel_size: 0.5", good_body, "6:3:", "key 'grid.cel_size'", "did you mean 'cell_size'?");
}

static void test_missing_mesh(void **state) {
  (void)state;
  /* the file name is at line 10, column 38 ("  - " then 33 characters before it) */
  check_bad("mesh", "cell_size: 0.5", "{type: gmsh, region: soil, file: no/such.geo}", "10:38:",
            "key 'geometry.0.file'", "no/such.geo' not found");
}

/* --set overrides of the scene at path: these must fail, naming expected in the message
 * (left in msg), and create no output directory; those must run. */
static void set_fails(const char *path, int n, const char **sets, const char *what, const char *expected,
                      char *msg, size_t len) {
  const int e = run_lib(path, DIR "/out-override", n, sets, 0, msg, len);
  if (e == 0) fail_msg("--set %s: expected a failure, got 0", what);
  test_expect_in(what, msg, expected);
  if (test_exists(DIR "/out-override")) fail_msg("--set %s: a failed --set created the output directory", what);
}

static void set_runs(const char *path, const char *out, int n, const char **sets, const char *what) {
  char msg[2048];
  const int e = run_lib(path, out, n, sets, MPMC_WORKFLOW_FORCE, msg, sizeof msg);
  if (e != 0) fail_msg("--set %s: expected success, got %d: %s", what, e, msg);
}

static void test_bad_override(void **state) {
  (void)state;
  char scene[] = DIR "/ok.yaml", msg[2048];
  write_scene(scene, "cell_size: 0.5", good_body);
  const char *sets[] = {"grid.cell_size=-2"};
  set_fails(scene, 1, sets, "grid.cell_size=-2", "key 'grid.cell_size': must be > 0 (got -2)", msg, sizeof msg);
  test_expect_in("--set", msg, "--set grid.cell_size=-2");
  const char *typo[] = {"grid.cell_sise=1"};
  set_fails(scene, 1, typo, "grid.cell_sise=1", "key 'grid.cell_sise': unknown key (did you mean 'cell_size'?)",
            msg, sizeof msg);
  const char *fb[] = {"fbar=stabel"};
  set_fails(scene, 1, fb, "fbar=stabel",
            "key 'fbar': expected true, false, anchored, paper, total or stable (got 'stabel')", msg, sizeof msg);
  const char *ok[] = {"fbar=stable", "stages.0.end.time=0.0005"};
  set_runs(scene, DIR "/out-fbar-stable", 2, ok, "fbar=stable");
  const char *srt[] = {"sort_interval=-1"};
  set_fails(scene, 1, srt, "sort_interval=-1", "key 'sort_interval': must be in [0, 1e+09] (got -1)", msg,
            sizeof msg);
  /* water tables: x must increase; a plane is 3D only; a line runs */
  const char *wback[] = {"water_table={points: [[1, 1], [0, 0]]}"};
  set_fails(scene, 1, wback, "water_table with x decreasing",
            "key 'water_table.points.1': x = 0 must exceed the previous point's x = 1", msg, sizeof msg);
  const char *wplane[] = {"water_table={plane: [1, 0, 0]}"};
  set_fails(scene, 1, wplane, "water_table plane in 2D", "key 'water_table.plane': a plane is for 3D scenes", msg,
            sizeof msg);
  const char *wok[] = {"water_table={points: [[0, 0.5], [2, 0.5]]}", "stages.0.end.time=0.0005"};
  set_runs(scene, DIR "/out-water", 2, wok, "water_table points");
  /* a stage's PIC share: fixed (flip) or a diffusivity (pic_diffusivity), not both */
  const char *pr[] = {"stages.0.flip=0.9", "stages.0.pic_diffusivity=50"};
  set_fails(scene, 2, pr, "stages.0.flip and pic_diffusivity",
            "key 'stages.0.pic_diffusivity': a stage takes either flip (a fixed share a step) or pic_diffusivity, not both",
            msg, sizeof msg);
  const char *prn[] = {"stages.0.pic_diffusivity=-5"};
  set_fails(scene, 1, prn, "stages.0.pic_diffusivity=-5", "key 'stages.0.pic_diffusivity': must be", msg,
            sizeof msg);
  const char *prok[] = {"stages.0.pic_diffusivity=50", "stages.0.end.time=0.0005"};
  set_runs(scene, DIR "/out-pic-diffusivity", 2, prok, "stages.0.pic_diffusivity=50");
  const char *k0[] = {"stages.0.initial_stress={k0: -1}"};
  set_fails(scene, 1, k0, "stages.0.initial_stress k0 = -1", "key 'stages.0.initial_stress.k0': must be > 0 (got -1)",
            msg, sizeof msg);
  const char *k0ok[] = {"stages.0.initial_stress={k0: 0.5}", "stages.0.end.time=0.0005"};
  set_runs(scene, DIR "/out-k0", 2, k0ok, "stages.0.initial_stress={k0: 0.5}");
  const char *ro[] = {"metrics={runout_distance: {material: nope}}"};
  set_fails(scene, 1, ro, "metrics.runout_distance.material=nope",
            "key 'metrics.runout_distance.material': no material named 'nope' in materials", msg, sizeof msg);
  /* an empty list of snapshot plots is none, not an error; sorting every step runs */
  const char *none[] = {"snapshot_plots=[]", "sort_interval=1", "stages.0.end.time=0.0005"};
  set_runs(scene, DIR "/out-noplots", 3, none, "snapshot_plots=[] sort_interval=1");
}

static void test_existing_output(void **state) {
  (void)state;
  char scene[] = DIR "/ok.yaml", msg[2048];
  write_scene(scene, "cell_size: 0.5", good_body);
  const char *out = DIR "/out-existing";
  assert_int_equal(system("rm -rf '" DIR "/out-existing'"), 0);
  mkdir(out, 0777);
  FILE *f = fopen(DIR "/out-existing/keep.txt", "w");
  fputs("mine", f);
  fclose(f);
  int e = run_lib(scene, out, 0, NULL, 0, msg, sizeof msg);
  if (e == 0) fail_msg("a non-empty output directory without --force: expected a failure, got 0");
  test_expect_in("existing output", msg, "exists and is not empty");
  test_expect_in("existing output", msg, "--force");
  if (test_exists(DIR "/out-existing/summary.json")) fail_msg("summary.json written without --force");
  char args[600];
  snprintf(args, sizeof args, "run '%s' --out '%s'", scene, out);
  if (test_run_cli(args, msg, sizeof msg) == 0) fail_msg("mpmc run into a non-empty directory: exit status 0");
  /* with --force the run goes ahead */
  e = run_lib(scene, out, 0, NULL, MPMC_WORKFLOW_FORCE, msg, sizeof msg);
  if (e) fail_msg("with --force: expected success, got %d: %s", e, msg);
  if (!test_exists(DIR "/out-existing/summary.json")) fail_msg("with --force: no summary.json");
}

static void test_usage(void **state) {
  (void)state;
  char msg[4096];
  if (test_run_cli("--help", msg, sizeof msg) != 0) fail_msg("mpmc --help: expected exit status 0");
  if (test_run_cli("frobnicate x.yaml", msg, sizeof msg) == 0) fail_msg("mpmc frobnicate: expected a failure");
  test_expect_in("unknown command", msg, "unknown command 'frobnicate'");
  if (test_run_cli("run " DIR "/does-not-exist.yaml", msg, sizeof msg) == 0)
    fail_msg("mpmc run on a missing file: expected a failure");
  test_expect_in("missing scene", msg, "does-not-exist.yaml: cannot open the scene file");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_syntax_error), cmocka_unit_test(test_wrong_type),
      cmocka_unit_test(test_out_of_range), cmocka_unit_test(test_unknown_key),
      cmocka_unit_test(test_missing_mesh), cmocka_unit_test(test_bad_override),
      cmocka_unit_test(test_existing_output), cmocka_unit_test(test_usage),
      cmocka_unit_test(test_material_rules),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
