/* `mpmc resume` as a user meets it (issue 44): a run killed with SIGKILL inside a stage and
 * resumed from its last checkpoint must end exactly where the uninterrupted run ends.
 * - A two-stage scene (a quasi-static settling with damping, then a time-ended collapse at
 *   reduced strength; the step size from the stability limit, recomputed every 10 steps;
 *   F-bar; points sorted every 7 steps) runs once uninterrupted.  The same scene runs again
 *   with a checkpoint after every step and is killed twice, once in each stage, and resumed
 *   each time.  The killed checkpoints are checked to lie inside a stage.
 * - The final states (every particle array of the final checkpoints, the time and the step
 *   count) are the same bits, and so is series.csv: the killed runs' rows after the
 *   checkpoint are trimmed on resume.
 * - Killed in the second stage before a checkpoint inside it, the run resumes from the
 *   checkpoint at that stage's start, again to the same bits and the same series.csv (no
 *   row of zero energy at the stage's start).
 * - `mpmc run --force` into a directory of an earlier run removes that run's files (the
 *   resumed snapshots, snapshot-plot data, a stale temporary checkpoint) and nothing else: a
 *   file of the user's, one with a near name and a subdirectory stay; checkpoint.h5 is
 *   replaced by the run's own. */
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "test_util.h"

#define DIR MPMC_BINARY_DIR "/t660"

static const char *scene_text =
    "scene: block\n"
    "dim: 2\n"
    "grid: {lo: [0, 0], hi: [4, 2], cell_size: 0.1}\n"
    "basis: bspline2\n"
    "fbar: true\n"
    "plots: false\n"
    "sort_interval: 7\n"
    "materials:\n"
    "  clay: {model: hencky_j2, E: 1.0e6, nu: 0.45, rho: 2000, kappa_p: 2.0e4, kappa_r: 1.0e4, eta: 5}\n"
    "geometry:\n"
    "  - {type: box, lo: [0, 0], hi: [1, 1], ppc: 2}\n"
    "stages:\n"
    "  - name: settle\n"
    "    gravity: [0, -9.81]\n"
    "    damping: 0.3\n"
    "    strength_reduction: 0.5\n"
    "    walls: [{face: x_lo, kind: slip, axis: 0}, {face: y_lo, kind: fixed}, "
    "{name: gate, face: x_hi, kind: slip, axis: 0}]\n"
    "    end: {kinetic_energy_ratio: 1.0e-3, max_time: 0.25, min_time: 0.05}\n"
    "  - name: collapse\n"
    "    strength_reduction: 3\n"
    "    remove_walls: [gate]\n"
    "    end: {time: 0.3}\n"
    "metrics:\n"
    "  runout_distance: {axis: x}\n";

static void write_text(const char *path, const char *text) { test_write_text(DIR, path, text); }

/* `mpmc` with arguments (NULL-terminated), output to DIR/cli.log; the child's pid. */
static pid_t spawn_cli(const char *a0, ...) {
  const char *argv[16] = {MPMC_CLI, a0};
  int n = 2;
  va_list ap;
  va_start(ap, a0);
  while (n < 15 && (argv[n] = va_arg(ap, const char *))) ++n;
  va_end(ap);
  argv[n] = NULL;
  const pid_t pid = fork();
  assert_true(pid >= 0);
  if (pid == 0) {
    if (!freopen(DIR "/cli.log", "a", stdout) || !freopen(DIR "/cli.log", "a", stderr)) _exit(126);
    execv(MPMC_CLI, (char *const *)(void *)argv);
    _exit(127);
  }
  return pid;
}

static int wait_cli(pid_t pid) {
  int st = 0;
  while (waitpid(pid, &st, 0) < 0) {
  }
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Rows of series.csv that belong to stage `name`. */
static int rows_of(const char *series, const char *name) {
  if (!test_exists(series)) return 0;
  char *s = test_slurp(series), key[64];
  snprintf(key, sizeof key, "\n%s,", name);
  int n = 0;
  for (const char *p = strstr(s, key); p; p = strstr(p + 1, key)) ++n;
  free(s);
  return n;
}

/* Kill the run `pid` writing into out with SIGKILL once series.csv has `rows` rows of stage
 * `name`; fails when the run ends first. */
static void kill_at(pid_t pid, const char *out, const char *name, int rows) {
  char series[512];
  snprintf(series, sizeof series, "%s/series.csv", out);
  const struct timespec nap = {0, 2000000};
  for (int k = 0; k < 60000; ++k) {
    if (rows_of(series, name) >= rows) {
      kill(pid, SIGKILL);
      wait_cli(pid);
      return;
    }
    int st;
    if (waitpid(pid, &st, WNOHANG) == pid)
      fail_msg("the run into %s ended before stage '%s' had %d series rows: nothing to resume", out, name, rows);
    nanosleep(&nap, NULL);
  }
  kill(pid, SIGKILL);
  wait_cli(pid);
  fail_msg("the run into %s never reached %d series rows of stage '%s'", out, rows, name);
}

/* The workflow's record in checkpoint `path` (malloc'ed); fails the test when it does not read. */
static char *checkpoint_meta(const char *path) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim sim = NULL;
  char *meta = NULL;
  TCALL(mpmc_sim_checkpoint_read(ctx, path, &sim, &meta));
  char *copy = strdup(meta);
  assert_non_null(copy);
  mpmc_free(meta);
  mpmc_sim_destroy(&sim);
  test_ctx = NULL;
  mpmc_context_destroy(&ctx);
  return copy;
}

/* The checkpoint in out lies inside a stage (set up, some time into it). */
static void expect_mid_stage(const char *out, const char *what) {
  char path[512];
  snprintf(path, sizeof path, "%s/checkpoint.h5", out);
  char *meta = checkpoint_meta(path);
  const char *setup = strstr(meta, "\nsetup "), *ts = strstr(meta, "\nstage_time ");
  if (!setup || !ts || atoi(setup + 7) != 1 || !(strtod(ts + 12, NULL) > 0))
    fail_msg("%s: expected a checkpoint inside a stage, its record is:\n%s", what, meta);
  free(meta);
}

/* Every particle array, the time and the step count of two checkpoints: the same bits. */
static void expect_same_state(const char *a, const char *b) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim s[2] = {NULL, NULL};
  TCALL(mpmc_sim_checkpoint_read(ctx, a, &s[0], NULL));
  TCALL(mpmc_sim_checkpoint_read(ctx, b, &s[1], NULL));
  const mpmc_particles *p = &s[0]->p, *q = &s[1]->p;
  if (p->n != q->n) fail_msg("points: %d uninterrupted, %d resumed", p->n, q->n);
  if (memcmp(&s[0]->time, &s[1]->time, sizeof s[0]->time))
    fail_msg("time: %.17g uninterrupted, %.17g resumed", s[0]->time, s[1]->time);
  if (s[0]->stats.steps != s[1]->stats.steps)
    fail_msg("steps: %lld uninterrupted, %lld resumed", (long long)s[0]->stats.steps, (long long)s[1]->stats.steps);
  const struct {
    const char *name;
    const double *x, *y;
    int nc;
  } f[] = {{"x", p->x, q->x, p->dim}, {"v", p->v, q->v, p->dim},         {"stress", p->stress, q->stress, 6},
           {"J", p->J, q->J, 1},      {"eps_p", p->eps_p, q->eps_p, 1}, {"be", p->be, q->be, 6},
           {"Jbar", p->Jbar, q->Jbar, 1}};
  for (size_t k = 0; k < sizeof f / sizeof f[0]; ++k) {
    if (!f[k].x || !f[k].y) fail_msg("field %s missing from a checkpoint", f[k].name);
    for (size_t i = 0; i < (size_t)p->n * (size_t)f[k].nc; ++i)
      if (memcmp(&f[k].x[i], &f[k].y[i], sizeof(double)))
        fail_msg("%s[%zu]: %.17g uninterrupted, %.17g resumed from mid-stage checkpoints", f[k].name, i,
                 f[k].x[i], f[k].y[i]);
  }
  if (memcmp(p->id, q->id, sizeof(int) * (size_t)p->n)) fail_msg("the points' ids (sort order) differ");
  mpmc_sim_destroy(&s[0]);
  mpmc_sim_destroy(&s[1]);
  test_ctx = NULL;
  mpmc_context_destroy(&ctx);
}

/* The two series.csv files are the same bytes; else the first line that differs. */
static void expect_same_series(const char *ref_path, const char *got_path, const char *what) {
  char *ref = test_slurp(ref_path), *got = test_slurp(got_path);
  size_t i = 0, start = 0;
  int line = 1;
  for (; ref[i] && ref[i] == got[i]; ++i)
    if (ref[i] == '\n') ++line, start = i + 1;
  if (ref[i] || got[i])
    fail_msg("series.csv %s differs from the uninterrupted run's at line %d:\nexpected: %.*s\ngot:      %.*s", what,
             line, (int)strcspn(ref + start, "\n"), ref + start, (int)strcspn(got + start, "\n"), got + start);
  free(ref);
  free(got);
}

static void test_resume_mid_stage(void **state) {
  (void)state;
  const char *scene = DIR "/block.yaml";
  write_text(scene, scene_text);
  assert_int_equal(system("rm -rf '" DIR "/ref' '" DIR "/kill'"), 0);
  if (wait_cli(spawn_cli("run", scene, "--out", DIR "/ref", "--quiet", NULL)) != 0)
    fail_msg("the uninterrupted run failed (see %s/cli.log)", DIR);
  /* a checkpoint after every step: the last one is where the kill finds the run */
  kill_at(spawn_cli("run", scene, "--out", DIR "/kill", "--quiet", "--set", "checkpoint_interval=1e-9", NULL),
          DIR "/kill", "settle", 60);
  expect_mid_stage(DIR "/kill", "killed in stage settle");
  kill_at(spawn_cli("resume", DIR "/kill", "--quiet", NULL), DIR "/kill", "collapse", 70);
  expect_mid_stage(DIR "/kill", "killed in stage collapse");
  if (wait_cli(spawn_cli("resume", DIR "/kill", "--quiet", NULL)) != 0)
    fail_msg("the second resume failed (see %s/cli.log)", DIR);
  expect_same_state(DIR "/ref/checkpoint.h5", DIR "/kill/checkpoint.h5");
  expect_same_series(DIR "/ref/series.csv", DIR "/kill/series.csv", "after two kills inside stages");
}

/* Killed in the second stage before any checkpoint inside it: the resume starts from the
 * checkpoint at the stage's start, and series.csv gets no row of zero energy there. */
static void test_resume_stage_start(void **state) {
  (void)state;
  const char *scene = DIR "/block.yaml";
  assert_int_equal(system("rm -rf '" DIR "/kill2'"), 0);
  if (system("test -f '" DIR "/ref/series.csv'") != 0 &&
      wait_cli(spawn_cli("run", scene, "--out", DIR "/ref", "--quiet", NULL)) != 0)
    fail_msg("the uninterrupted run failed (see %s/cli.log)", DIR);
  kill_at(spawn_cli("run", scene, "--out", DIR "/kill2", "--quiet", NULL), DIR "/kill2", "collapse", 20);
  char *meta = checkpoint_meta(DIR "/kill2/checkpoint.h5");
  if (!strstr(meta, "\nstage 1\nsetup 0\n"))
    fail_msg("expected the checkpoint at the start of stage 1 (collapse), its record is:\n%s", meta);
  free(meta);
  if (wait_cli(spawn_cli("resume", DIR "/kill2", "--quiet", NULL)) != 0)
    fail_msg("the resume failed (see %s/cli.log)", DIR);
  expect_same_state(DIR "/ref/checkpoint.h5", DIR "/kill2/checkpoint.h5");
  expect_same_series(DIR "/ref/series.csv", DIR "/kill2/series.csv", "after a kill and a resume from a stage's start");
}

static void test_force(void **state) {
  (void)state;
  const char *scene = DIR "/fall.yaml";
  write_text(scene,
             "scene: fall\ndim: 2\ngrid: {lo: [0, -1], hi: [2, 2], cell_size: 0.5}\nfbar: false\nplots: false\n"
             "materials:\n  m: {model: hencky, E: 1.0e6, nu: 0.3, rho: 1000}\n"
             "geometry:\n  - {type: box, lo: [0, 0], hi: [1, 1], ppc: 2}\n"
             "stages:\n  - {name: only, gravity: [0, -9.81], dt: 0.001, end: {time: 0.005}}\n");
  assert_int_equal(system("rm -rf '" DIR "/force' && mkdir -p '" DIR "/force/mine'"), 0);
  static const char *const old[] = {"summary.json", "snapshots_resumed.h5", "snapshots_resumed.xdmf",
                                    "checkpoint.h5.tmp", "snap_gone_t1_speed.csv", "snapshot_gone_t1_speed.png",
                                    "snapshots_gone_speed.png", "final_eps_p.png", "bearing.png"};
  static const char *const mine[] = {"notes.txt", "series.csv.bak", "snap.csv", "mine/summary.json"};
  char path[512];
  write_text(DIR "/force/checkpoint.h5", "not a checkpoint\n");
  for (size_t i = 0; i < sizeof old / sizeof old[0]; ++i) {
    snprintf(path, sizeof path, "%s/force/%s", DIR, old[i]);
    write_text(path, "from an earlier run\n");
  }
  for (size_t i = 0; i < sizeof mine / sizeof mine[0]; ++i) {
    snprintf(path, sizeof path, "%s/force/%s", DIR, mine[i]);
    write_text(path, "the user's\n");
  }
  if (wait_cli(spawn_cli("run", scene, "--out", DIR "/force", "--force", "--quiet", NULL)) != 0)
    fail_msg("mpmc run --force failed (see %s/cli.log)", DIR);
  for (size_t i = 1; i < sizeof old / sizeof old[0]; ++i) {
    snprintf(path, sizeof path, "%s/force/%s", DIR, old[i]);
    if (test_exists(path)) fail_msg("mpmc run --force left the earlier run's %s", path);
  }
  for (size_t i = 0; i < sizeof mine / sizeof mine[0]; ++i) {
    snprintf(path, sizeof path, "%s/force/%s", DIR, mine[i]);
    if (!test_exists(path)) fail_msg("mpmc run --force removed %s, a file the run does not write", path);
  }
  /* the earlier checkpoint.h5 (here not even a checkpoint) is replaced by the run's own */
  free(checkpoint_meta(DIR "/force/checkpoint.h5"));
  char *sum = test_slurp(DIR "/force/summary.json");
  if (!strstr(sum, "\"completed\"")) fail_msg("summary.json of the forced run: %s", sum);
  free(sum);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_resume_mid_stage),
      cmocka_unit_test(test_resume_stage_start),
      cmocka_unit_test(test_force),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
