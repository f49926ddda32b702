/* Helpers shared by the C tests: lattice seeding of boxes, small checks, files and the
 * `mpmc` program.  Include <cmocka.h> first (fail_msg). */
#ifndef MPMC_TEST_UTIL_H
#define MPMC_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "mpmc.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Fail the current cmocka test with the library's message when a call fails. */
/* The context whose last error TCALL prints (tests set it after creating one). */
static mpmc_context test_ctx __attribute__((unused));
#define TCALL(expr)                                                                   \
  do {                                                                                \
    int tcall_ierr_ = (expr);                                                         \
    if (tcall_ierr_)                                                                  \
      fail_msg("%s -> %d: %s", #expr, tcall_ierr_,                                    \
               test_ctx ? mpmc_context_last_error(test_ctx) : mpmc_error_string(tcall_ierr_)); \
  } while (0)

/* |got - want| <= tol, else fail with both values */
#define TCLOSE(got, want, tol)                                                              \
  do {                                                                                      \
    const double tg_ = (got), tw_ = (want), tt_ = (tol);                                    \
    if (!(fabs(tg_ - tw_) <= tt_))                                                          \
      fail_msg("%s = %.17g, expected %.17g (tolerance %g)", #got, tg_, tw_, tt_);           \
  } while (0)

/* A sim of dimension dim on the unit box, cells of 0.1 (the batched stress updates' tests,
 * t412 and t413: points on a line, test_points_on_line). */
static inline mpmc_sim test_unit_box_sim(mpmc_context ctx, int dim) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.1));
  return sim;
}

/* n points on the line x = 0.3 + 0.004 q, y = z = 0.5, point q of material mat[q], v = 1e-4
 * along x */
static inline void test_points_on_line(mpmc_sim sim, int n, const int *mat) {
  for (int q = 0; q < n; ++q) {
    const double x[3] = {0.3 + 0.004 * q, 0.5, 0.5}, v = 1e-4;
    TCALL(mpmc_sim_add_particles(sim, 1, x, &v, mat[q], NULL));
  }
}

/* Seed a box [lo, hi] (whole cells of size h) with ppc points per cell per axis.
 * Returns the number of points; x and vol are malloc'ed. */
static inline int test_lattice(int dim, const double *lo, const double *hi, double h, int ppc,
                               double **x, double **vol) {
  int nc[3] = {1, 1, 1}, np[3] = {1, 1, 1};
  for (int a = 0; a < dim; ++a) {
    nc[a] = (int)lround((hi[a] - lo[a]) / h);
    np[a] = nc[a] * ppc;
  }
  const int n = np[0] * np[1] * np[2];
  *x = malloc(sizeof(double) * (size_t)n * dim);
  *vol = malloc(sizeof(double) * (size_t)n);
  const double dx = h / ppc, v = pow(dx, dim);
  int q = 0;
  for (int k = 0; k < np[2]; ++k)
    for (int j = 0; j < np[1]; ++j)
      for (int i = 0; i < np[0]; ++i, ++q) {
        const int idx[3] = {i, j, k};
        for (int a = 0; a < dim; ++a) (*x)[q * dim + a] = lo[a] + (idx[a] + 0.5) * dx;
        (*vol)[q] = v;
      }
  return n;
}

/* ---- columns (t502, t503, t505, t506, t507) ----------------------------------------- */

/* A column's sim in dim = 2 or 3: the grid over [0, W]^(dim-1) x [0, H + head] (the last
 * axis vertical), cells of h. */
static inline mpmc_sim test_column_sim(mpmc_context ctx, int dim, double W, double H, double head, double h) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {W, dim == 2 ? H + head : W, H + head};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  return sim;
}

/* The column [0, W]^(dim-1) x [0, H] of material mat, 2 points per cell and axis, its sides
 * slip walls and its base fixed.  Returns the number of points; their positions in *x
 * (malloc'ed; x NULL: freed). */
static inline int test_column_fill(mpmc_sim sim, int dim, double W, double H, double h, int mat, double **x) {
  double *xs, *vol;
  const double plo[3] = {0, 0, 0}, phi[3] = {W, dim == 2 ? H : W, H};
  const int n = test_lattice(dim, plo, phi, h, 2, &xs, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, xs, vol, mat, NULL));
  const int up = dim - 1;
  for (int a = 0; a < up; ++a) {
    TCALL(mpmc_sim_add_wall_face(sim, 2 * a, MPMC_WALL_SLIP, NULL));
    TCALL(mpmc_sim_add_wall_face(sim, 2 * a + 1, MPMC_WALL_SLIP, NULL));
  }
  TCALL(mpmc_sim_add_wall_face(sim, 2 * up, MPMC_WALL_FIXED, NULL));
  free(vol);
  if (x)
    *x = xs;
  else
    free(xs);
  return n;
}

/* ---- files ------------------------------------------------------------------------- */

/* Whether path exists (file or directory). */
static inline int test_exists(const char *path) {
  struct stat s;
  return stat(path, &s) == 0;
}

/* The whole of a file, NUL-terminated, malloc'ed (free it); fails the test if unreadable. */
/* Write text to path, creating its folder dir (one level) first. */
static inline void test_write_text(const char *dir, const char *path, const char *text) {
  mkdir(dir, 0777);
  FILE *f = fopen(path, "w");
  if (!f) fail_msg("expected to write %s, cannot open it", path);
  fputs(text, f);
  fclose(f);
}

static inline char *test_slurp(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) fail_msg("expected to read %s, cannot open it", path);
  size_t cap = 1 << 12, n = 0, got;
  char *s = malloc(cap);
  while ((got = fread(s + n, 1, cap - 1 - n, f)) > 0) {
    n += got;
    if (n == cap - 1) s = realloc(s, cap *= 2);
  }
  fclose(f);
  s[n] = '\0';
  return s;
}

/* The number after "key": in a JSON file (summary.json); fails the test without the key. */
static inline double test_json_number(const char *path, const char *key) {
  char *text = test_slurp(path), pat[128];
  snprintf(pat, sizeof pat, "\"%s\": ", key);
  const char *p = strstr(text, pat);
  if (!p) fail_msg("%s: expected a key \"%s\", found none", path, key);
  const double v = strtod(p + strlen(pat), NULL);
  free(text);
  return v;
}

/* Fail unless msg contains part; what names the case. */
static inline void test_expect_in(const char *what, const char *msg, const char *part) {
  if (!strstr(msg, part))
    fail_msg("%s: expected the message to contain \"%s\", got \"%s\"", what, part, msg);
}

#ifdef MPMC_CLI
/* Run the `mpmc` program (MPMC_CLI, set by tests/workflows.cmake and tests/robust.cmake) with
 * the arguments args (a shell command line); returns its exit status (-1 if it did not exit).
 * The start of its stderr is copied into msg (len bytes, NUL-terminated) unless msg is NULL;
 * stdout is dropped, and the rest of stderr is read, so the program never waits on a full
 * pipe. */
static inline int test_run_cli(const char *args, char *msg, size_t len) {
  char cmd[4096], rest[4096];
  snprintf(cmd, sizeof cmd, "'%s' %s 2>&1 >/dev/null", MPMC_CLI, args);
  FILE *p = popen(cmd, "r");
  if (!p) fail_msg("expected to start %s", cmd);
  if (msg && len > 0) {
    const size_t n = fread(msg, 1, len - 1, p);
    msg[n] = '\0';
  }
  while (fread(rest, 1, sizeof rest, p) > 0) {
  }
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
#endif

#endif
