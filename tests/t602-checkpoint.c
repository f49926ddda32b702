/* Checkpoint and restart (issue 4): N steps equal N/2 steps + checkpoint + restart + N/2
 * steps bit for bit (every particle array compared exactly); a writer killed mid-write
 * leaves the previous checkpoint readable; missing, foreign, truncated and incompatible
 * files are clear errors and a failed write overwrites nothing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>
#include <hdf5.h>

#include "mpmc_impl.h" /* the run monitor's state */
#include "test_util.h"

#define CK MPMC_BINARY_DIR "/t602.ck"
#define CK2 MPMC_BINARY_DIR "/t602-copy.ck"

static mpmc_context ctx;

static mpmc_sim build(int nthreads) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {6, 4}, g[2] = {0.3, -9.81};
  int m1, m2;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.25));
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  TCALL(mpmc_sim_set_flip_blend(sim, 0.9));
  TCALL(mpmc_sim_set_pic_diffusivity(sim, 2.5)); /* eta = 1 - 2.5 dt / h^2, not 0.9: kept by a restart */
  TCALL(mpmc_sim_set_gravity(sim, g));
  TCALL(mpmc_sim_set_damping(sim, 0.05));
  TCALL(mpmc_sim_set_threads(sim, nthreads));
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 2e5, 0.45, 1000, &m1));
  TCALL(mpmc_sim_add_material_newtonian(sim, 2e5, 1e-3, 1000, &m2));
  const double a0[2] = {0.5, 0}, a1[2] = {2.5, 2}, b0[2] = {3.5, 0}, b1[2] = {5, 1.5};
  int n1;
  TCALL(mpmc_sim_seed_box(sim, a0, a1, 2, m1, NULL, &n1));
  TCALL(mpmc_sim_seed_box(sim, b0, b1, 2, m2, NULL, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, NULL));
  int gate;
  TCALL(mpmc_sim_add_wall(sim, 0, 1, 5.5, MPMC_WALL_SEPARABLE, &gate));
  TCALL(mpmc_sim_remove_wall(sim, gate)); /* a removed wall must stay removed */
  const int tip[2] = {n1 - 1, 3};
  TCALL(mpmc_sim_add_particle_set(sim, "tip", 2, tip, NULL));
  return sim;
}

static void compare(mpmc_sim a, mpmc_sim b) {
  int na, nb;
  TCALL(mpmc_sim_get_num_particles(a, &na));
  TCALL(mpmc_sim_get_num_particles(b, &nb));
  assert_int_equal(na, nb);
  static const char *names[MPMC_FIELD_COUNT] = {"position", "velocity", "mass", "volume0", "J", "Jbar",
                                                "stress", "be", "eps_p", "force", "x0"};
  for (int fld = 0; fld < MPMC_FIELD_COUNT; ++fld) {
    double *fa, *fb;
    int ca = 0, cb = 0;
    const int ra = mpmc_sim_get_field(a, fld, &fa, &ca), rb = mpmc_sim_get_field(b, fld, &fb, &cb);
    if (ra != rb) fail_msg("field %s: present in one run only (%d vs %d)", names[fld], ra, rb);
    if (ra) continue;
    for (size_t i = 0; i < (size_t)na * (size_t)ca; ++i)
      if (memcmp(&fa[i], &fb[i], sizeof(double)) != 0)
        fail_msg("field %s entry %zu: uninterrupted %.17g, restarted %.17g", names[fld], i, fa[i], fb[i]);
  }
  const int *ia, *ib;
  TCALL(mpmc_sim_get_material_ids(a, &ia));
  TCALL(mpmc_sim_get_material_ids(b, &ib));
  assert_memory_equal(ia, ib, sizeof(int) * (size_t)na);
  double ta, tb;
  TCALL(mpmc_sim_get_time(a, &ta));
  TCALL(mpmc_sim_get_time(b, &tb));
  if (ta != tb) fail_msg("time: uninterrupted %.17g, restarted %.17g", ta, tb);
  mpmc_stats sa, sb;
  TCALL(mpmc_sim_get_stats(a, &sa));
  TCALL(mpmc_sim_get_stats(b, &sb));
  assert_int_equal(sa.steps, sb.steps);
  assert_int_equal(sa.particle_steps, sb.particle_steps);
  assert_string_equal(mpmc_phase_name(MPMC_PHASE_SLABS), "slabs");
  assert_string_equal(mpmc_phase_name(MPMC_PHASE_CHECKS), "checks");
  assert_string_equal(mpmc_phase_name(MPMC_PHASE_COUNT), "unknown phase");
  /* the step's wall time is the sum of its phases' (the checkpoint carries both) */
  const mpmc_stats *st[2] = {&sa, &sb};
  for (int r = 0; r < 2; ++r) {
    double sum = 0;
    for (int k = 0; k < MPMC_PHASE_COUNT; ++k) {
      if (!(st[r]->phase_seconds[k] >= 0)) fail_msg("phase %d: %g s", k, st[r]->phase_seconds[k]);
      sum += st[r]->phase_seconds[k];
    }
    if (!(st[r]->phase_seconds[MPMC_PHASE_P2G] > 0)) fail_msg("P2G took no time");
    if (!(fabs(sum - st[r]->wall_seconds) <= 1e-9 * st[r]->wall_seconds))
      fail_msg("%s run: phases sum to %.17g s, the steps took %.17g s", r ? "restarted" : "uninterrupted",
               sum, st[r]->wall_seconds);
  }
}

static void test_restart_bitwise(void **state) {
  (void)state;
  const int N = 40;
  mpmc_sim a = build(2);
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.3, &dt));
  for (int s = 0; s < N; ++s) TCALL(mpmc_sim_step(a, dt));
  mpmc_sim b = build(2);
  for (int s = 0; s < N / 2; ++s) TCALL(mpmc_sim_step(b, dt));
  TCALL(mpmc_sim_checkpoint_write(b, CK, "stage: gravity"));
  mpmc_sim_destroy(&b);
  char *meta = NULL;
  TCALL(mpmc_sim_checkpoint_read(ctx, CK, &b, &meta));
  assert_string_equal(meta, "stage: gravity");
  mpmc_free(meta);
  for (int s = 0; s < N / 2; ++s) TCALL(mpmc_sim_step(b, dt));
  compare(a, b);
  int id, n;
  const int *idx;
  const char *name;
  TCALL(mpmc_sim_find_particle_set(b, "tip", &id));
  TCALL(mpmc_sim_get_particle_set(b, id, &name, &n, &idx));
  assert_int_equal(n, 2);
  assert_int_equal(idx[1], 3);
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
}

/* The kernel set the steps ran and the run monitor's setting travel with the checkpoint: a
 * run on the baseline kernels (round-off apart from the default fma or avx512 set where the
 * processor has AVX2) restarts on them, bit for bit, and a monitor turned off stays off. */
static void test_restart_settings(void **state) {
  (void)state;
  const char *env = getenv("MPMC_KERNELS");
  if (env && *env) skip(); /* the environment's choice wins over the file's */
  const int N = 20;
  mpmc_sim a = build(1), b = build(1);
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.3, &dt));
  for (int k = 0; k < 2; ++k) {
    TCALL(mpmc_sim_set_kernels(k ? b : a, MPMC_KERNELS_BASELINE));
    TCALL(mpmc_sim_set_energy_monitor(k ? b : a, -1.0));
  }
  for (int s = 0; s < N; ++s) TCALL(mpmc_sim_step(a, dt));
  for (int s = 0; s < N / 2; ++s) TCALL(mpmc_sim_step(b, dt));
  TCALL(mpmc_sim_checkpoint_write(b, CK, NULL));
  mpmc_sim_destroy(&b);
  TCALL(mpmc_sim_checkpoint_read(ctx, CK, &b, NULL));
  mpmc_kernels kb;
  TCALL(mpmc_sim_get_kernels(b, &kb));
  if (kb != MPMC_KERNELS_BASELINE)
    fail_msg("restarted on the %s kernels, the run's were baseline", mpmc_kernels_name(kb));
  if (!(b->monitor.factor < 0.0))
    fail_msg("the energy check, off in the run, is %g after the restart", b->monitor.factor);
  for (int s = 0; s < N / 2; ++s) TCALL(mpmc_sim_step(b, dt));
  compare(a, b);
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
}

static int old_count(const char *path) {
  mpmc_sim s;
  int n;
  TCALL(mpmc_sim_checkpoint_read(ctx, path, &s, NULL));
  TCALL(mpmc_sim_get_num_particles(s, &n));
  mpmc_sim_destroy(&s);
  return n;
}

static void test_killed_writer(void **state) {
  (void)state;
  mpmc_sim small = build(1);
  int n0;
  TCALL(mpmc_sim_get_num_particles(small, &n0));
  TCALL(mpmc_sim_checkpoint_write(small, CK, NULL));
  mpmc_sim_destroy(&small);
  remove(CK ".tmp");
  const pid_t pid = fork();
  assert_true(pid >= 0);
  if (pid == 0) { /* a writer of a large checkpoint (~30 MB) over the small one */
    mpmc_sim big;
    if (mpmc_sim_create(ctx, 2, &big)) _exit(2);
    const double lo[2] = {0, 0}, hi[2] = {100, 100};
    int m;
    mpmc_sim_set_grid(big, lo, hi, 0.5);
    mpmc_sim_add_material_neo_hookean(big, 1e6, 0.3, 1000, &m);
    if (mpmc_sim_seed_box(big, lo, hi, 2, m, NULL, NULL)) _exit(3); /* 160,000 points */
    double *v;
    mpmc_sim_get_field(big, MPMC_FIELD_BE, &v, NULL);
    mpmc_sim_checkpoint_write(big, CK, NULL);
    _exit(0);
  }
  /* kill it as soon as its temporary file holds data, i.e. in the middle of the write */
  struct stat st;
  int seen = 0;
  for (int i = 0; i < 200000 && !seen; ++i) {
    if (stat(CK ".tmp", &st) == 0 && st.st_size > 4096) seen = 1;
    else {
      struct timespec ts = {0, 100000};
      nanosleep(&ts, NULL);
    }
  }
  kill(pid, SIGKILL);
  int status;
  waitpid(pid, &status, 0);
  if (!seen) fail_msg("expected the writer to start writing %s.tmp within 20 s", CK);
  if (!WIFSIGNALED(status)) fail_msg("expected the writer to be killed mid-write, it exited with %d", WEXITSTATUS(status));
  /* the interrupted temporary is left behind; the previous checkpoint is intact */
  const int n = old_count(CK);
  if (n != n0) fail_msg("expected the previous checkpoint (%d points) after the kill, read %d", n0, n);
  /* the next write replaces the stale temporary */
  mpmc_sim s;
  TCALL(mpmc_sim_checkpoint_read(ctx, CK, &s, NULL));
  TCALL(mpmc_sim_checkpoint_write(s, CK, "again"));
  mpmc_sim_destroy(&s);
  assert_int_equal(access(CK ".tmp", F_OK), -1);
}

static void copy_file(const char *from, const char *to, long limit) {
  FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
  assert_true(a && b);
  char buf[4096];
  size_t k;
  long total = 0;
  while ((k = fread(buf, 1, sizeof buf, a)) > 0 && (limit < 0 || total < limit)) {
    if (limit >= 0 && total + (long)k > limit) k = (size_t)(limit - total);
    fwrite(buf, 1, k, b);
    total += (long)k;
  }
  fclose(a);
  fclose(b);
}

static void expect_read_error(const char *path, int code, const char *needle) {
  mpmc_sim s = NULL;
  const int r = mpmc_sim_checkpoint_read(ctx, path, &s, NULL);
  if (r != code) fail_msg("%s: expected error %d, got %d (%s)", path, code, r, mpmc_context_last_error(ctx));
  if (!strstr(mpmc_context_last_error(ctx), needle))
    fail_msg("expected the message to contain '%s', got '%s'", needle, mpmc_context_last_error(ctx));
  assert_null(s);
}

static void test_bad_files(void **state) {
  (void)state;
  mpmc_sim s = build(1);
  TCALL(mpmc_sim_checkpoint_write(s, CK, "x"));
  expect_read_error(MPMC_BINARY_DIR "/t602-none.ck", MPMC_ERR_IO, "t602-none.ck");
  FILE *f = fopen(CK2, "w");
  fputs("this is not HDF5\n", f);
  fclose(f);
  expect_read_error(CK2, MPMC_ERR_FORMAT, "not an HDF5 file");
  struct stat st;
  stat(CK, &st);
  copy_file(CK, CK2, st.st_size / 2);
  expect_read_error(CK2, MPMC_ERR_FORMAT, "t602-copy.ck");
  /* an HDF5 file of another kind */
  hid_t h = H5Fcreate(CK2, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  H5Fclose(h);
  expect_read_error(CK2, MPMC_ERR_FORMAT, "not a libmpmc checkpoint");
  /* a checkpoint from an incompatible (future) version */
  copy_file(CK, CK2, -1);
  h = H5Fopen(CK2, H5F_ACC_RDWR, H5P_DEFAULT);
  hid_t a = H5Aopen(h, "format_version", H5P_DEFAULT);
  const int v = 99;
  H5Awrite(a, H5T_NATIVE_INT, &v);
  H5Aclose(a);
  H5Fclose(h);
  expect_read_error(CK2, MPMC_ERR_FORMAT, "format version 99");
  /* a failed write overwrites nothing: block the temporary name with a directory */
  int n0;
  TCALL(mpmc_sim_get_num_particles(s, &n0));
  mkdir(CK ".tmp", 0700);
  const int r = mpmc_sim_checkpoint_write(s, CK, "y");
  rmdir(CK ".tmp");
  assert_int_equal(r, MPMC_ERR_IO);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "t602.ck.tmp"));
  char *meta;
  mpmc_sim back;
  TCALL(mpmc_sim_checkpoint_read(ctx, CK, &back, &meta));
  assert_string_equal(meta, "x");
  mpmc_free(meta);
  mpmc_sim_destroy(&back);
  mpmc_sim_destroy(&s);
  remove(CK);
  remove(CK2);
}

int main(void) {
  mpmc_context_create(&ctx);
  test_ctx = ctx;
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_killed_writer),
                                     cmocka_unit_test(test_restart_bitwise),
                                     cmocka_unit_test(test_restart_settings),
                                     cmocka_unit_test(test_bad_files)};
  const int r = cmocka_run_group_tests(tests, NULL, NULL);
  mpmc_context_destroy(&ctx);
  return r;
}
