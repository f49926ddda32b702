/* Throughput benchmark: particle-steps per second for
 *   block  - a 3D elastic (Hencky) block, quadratic B-splines, F-bar off / on
 *   column - a 3D column collapse: 2 x 0.5 x 1 m domain, h = 0.025 m, a 0.5 m
 *            cube of J2 soil with 2x2x2 points per cell (64,000 points), gravity
 * on 1 and 2 threads.  Usage: bench_throughput [steps] [scale] [case] [threads] [shuffle] [sort];
 * scale multiplies the number of cells per axis of the column (1 = 64,000 points); case (0-12,
 * the rows of the table; -1 all) and threads (1 or 2; 0 both) narrow the run for profiling,
 * e.g. under callgrind; shuffle = 1 stores the points in random order (what sorting the
 * particle arrays by cell undoes: the cost of lost locality); sort = N sorts the points by cell
 * every N steps (mpmc_sim_set_sort_interval; the first warm-up step sorts).  With MPMC_BENCH_CPU set in
 * the environment the rates are per second of the process's CPU time (all threads) instead
 * of wall-clock time: on a shared, loaded machine that is the steadier measure of the code's
 * cost.  With MPMC_BENCH_PHASES set each row is followed by the share of the step's wall time
 * per phase (mpmc_stats.phase_seconds) of its last run.  With MPMC_BENCH_SHARE=R set, the
 * table (none with a case beyond it, e.g. 99) is followed by F-bar's share of the standard
 * step on the column, one thread: the steps without and with each form (linear, B-spline2,
 * uGIMP and cubic B-splines with the default, anchored form; B-spline2 with Algorithm 1 as
 * published and B-spline2 and uGIMP with the stable form; the linear basis is the reference
 * column's) run alternately for R rounds in this one
 * process, and each round's share is rate(off) / rate(on) - 1 of its adjacent pair (the
 * machine's drift, slow against a round, cancels in a pair).  Printed per form: the median
 * and range of the R shares; the share from the best rate of each (the runs least disturbed
 * by other load, on a busy host the steadier figure); each phase's least ms a step over the
 * rounds, off and on, and their sums' ratio (each phase at its least disturbed round).  With
 * MPMC_BENCH_PAIRED=B set, the same forms are measured with two simulations each, without and
 * with F-bar, stepped in turn [steps] steps at a time for B pairs of blocks; the first step of
 * a block, which brings the simulation's data back into the caches, is not timed, the others
 * are timed one by one, and the least, lower-quartile and median step without and with
 * F-bar are compared: the two alternate within a fraction of a second, so that the host's
 * drift does not separate them, and a step's least time is its least disturbed one. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mpmc.h"
#include "mpmc_bench.h" /* bytes per point (libmpmc/src, the internal archive) */

static double last_bytes;
static int shuffle_points, sort_every, use_cpu_time;
static double last_phase[MPMC_PHASE_COUNT]; /* the last run's share of the step per phase */
static double last_phase_ms[MPMC_PHASE_COUNT + 1]; /* its ms a step per phase, then the step */

static double now(void) {
  struct timespec ts;
  clock_gettime(use_cpu_time ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#define CHECK(expr)                                                                        \
  do {                                                                                     \
    int e_ = (expr);                                                                       \
    if (e_) {                                                                              \
      fprintf(stderr, "%s failed: %s\n", #expr, mpmc_context_last_error(ctx));             \
      exit(1);                                                                             \
    }                                                                                      \
  } while (0)

/* The scene (0 block, 1 column) in ctx, stepped 3 times (the warm-up: allocations);
 * *np the number of points, *dtp the step */
static mpmc_sim scene_sim(mpmc_context ctx, int scene, int basis, int fbar, int j2, int threads,
                          double scale, int *np, double *dtp) {
  mpmc_sim sim;
  CHECK(mpmc_sim_create(ctx, 3, &sim));
  double h, lo[3] = {0, 0, 0}, hi[3], blo[3] = {0, 0, 0}, bhi[3];
  if (scene == 0) { /* block */
    h = 0.05 / scale;
    hi[0] = hi[1] = hi[2] = 1.0;
    bhi[0] = bhi[1] = bhi[2] = 0.5;
  } else { /* column collapse */
    h = 0.025 / scale;
    hi[0] = 2.0, hi[1] = 0.5, hi[2] = 1.0;
    bhi[0] = bhi[1] = bhi[2] = 0.5;
  }
  CHECK(mpmc_sim_set_grid(sim, lo, hi, h));
  CHECK(mpmc_sim_set_basis(sim, basis));
  CHECK(mpmc_sim_set_fbar(sim, fbar));
  CHECK(mpmc_sim_set_threads(sim, threads));
  int mat;
  if (j2)
    CHECK(mpmc_sim_add_material_hencky_j2(sim, 10e6, 0.3, 2000, 20e3, 5e3, 5, &mat));
  else
    CHECK(mpmc_sim_add_material_hencky(sim, 10e6, 0.3, 2000, &mat));
  CHECK(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, np));
  if (shuffle_points) { /* every other field is still uniform: permuting x and x0 suffices */
    double *x, *x0;
    CHECK(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
    CHECK(mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, NULL));
    srand(12345);
    for (int q = *np - 1; q > 0; --q) {
      const int r = (int)(((double)rand() / ((double)RAND_MAX + 1.0)) * (q + 1));
      for (int a = 0; a < 3; ++a) {
        double t = x[3 * q + a];
        x[3 * q + a] = x[3 * r + a], x[3 * r + a] = t;
        t = x0[3 * q + a];
        x0[3 * q + a] = x0[3 * r + a], x0[3 * r + a] = t;
      }
    }
    CHECK(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &x));
    CHECK(mpmc_sim_restore_field(sim, MPMC_FIELD_X0, &x0));
  }
  CHECK(mpmc_sim_set_sort_interval(sim, sort_every));
  if (scene == 1) {
    const double g[3] = {0, 0, -9.81};
    CHECK(mpmc_sim_set_gravity(sim, g));
    for (int f = 0; f < 6; ++f) CHECK(mpmc_sim_add_wall_face(sim, f, f == 4 ? MPMC_WALL_FIXED : MPMC_WALL_SLIP, NULL));
  } else {
    double *v;
    CHECK(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
    for (int q = 0; q < *np; ++q) v[3 * q] = 0.1 * (q % 7) / 7.0; /* some deformation */
  }
  double dt;
  CHECK(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 3; ++s) CHECK(mpmc_sim_step(sim, dt)); /* warm-up: allocations */
  *dtp = dt;
  return sim;
}

/* returns particle-steps per second; *np the number of points */
static double run(int scene, int basis, int fbar, int j2, int threads, int steps, double scale,
                  int *np) {
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  double dt;
  mpmc_sim sim = scene_sim(ctx, scene, basis, fbar, j2, threads, scale, np, &dt);
  mpmc_stats st0, st1;
  CHECK(mpmc_sim_get_stats(sim, &st0));
  const double t0 = now();
  for (int s = 0; s < steps; ++s) CHECK(mpmc_sim_step(sim, dt));
  const double t = now() - t0;
  CHECK(mpmc_sim_get_stats(sim, &st1));
  for (int k = 0; k < MPMC_PHASE_COUNT; ++k) {
    last_phase[k] = (st1.phase_seconds[k] - st0.phase_seconds[k]) / (st1.wall_seconds - st0.wall_seconds);
    last_phase_ms[k] = 1e3 * (st1.phase_seconds[k] - st0.phase_seconds[k]) / steps;
  }
  last_phase_ms[MPMC_PHASE_COUNT] = 1e3 * (st1.wall_seconds - st0.wall_seconds) / steps;
  last_bytes = mpmc_bench_bytes_per_point(sim);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  return (double)(*np) * steps / t;
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The forms whose share MPMC_BENCH_SHARE and MPMC_BENCH_PAIRED measure */
static const struct {
  int basis, fbar;
  const char *name;
} forms[] = {{MPMC_BASIS_LINEAR, MPMC_FBAR_ANCHORED, "linear anchored"},
             {MPMC_BASIS_BSPLINE2, MPMC_FBAR_ANCHORED, "bspline2 anchored"},
             {MPMC_BASIS_UGIMP, MPMC_FBAR_ANCHORED, "ugimp anchored"},
             {MPMC_BASIS_BSPLINE3, MPMC_FBAR_ANCHORED, "bspline3 anchored"},
             {MPMC_BASIS_BSPLINE2, MPMC_FBAR_PAPER, "bspline2 paper"},
             {MPMC_BASIS_BSPLINE2, MPMC_FBAR_STABLE, "bspline2 stable"},
             {MPMC_BASIS_UGIMP, MPMC_FBAR_STABLE, "ugimp stable"}};
enum { NF = sizeof forms / sizeof forms[0] };

/* MPMC_BENCH_SHARE: F-bar's share, off and on alternated in rounds (see the file's comment) */
static void fbar_shares(int rounds, int steps, double scale) {
  double *sh = malloc(sizeof(double) * (size_t)rounds * NF), best[NF][2] = {{0}};
  double least[NF][2][MPMC_PHASE_COUNT + 1];
  if (!sh) return;
  for (int f = 0; f < NF; ++f)
    for (int o = 0; o < 2; ++o)
      for (int k = 0; k <= MPMC_PHASE_COUNT; ++k) least[f][o][k] = INFINITY;
  for (int r = 0; r < rounds; ++r)
    for (int f = 0; f < NF; ++f) {
      int np;
      /* off first in even rounds, on first in odd ones */
      const int first = r % 2 ? forms[f].fbar : 0, second = r % 2 ? 0 : forms[f].fbar;
      const double a = run(1, forms[f].basis, first, 1, 1, steps, scale, &np);
      for (int k = 0; k <= MPMC_PHASE_COUNT; ++k)
        least[f][first != 0][k] = fmin(least[f][first != 0][k], last_phase_ms[k]);
      const double b = run(1, forms[f].basis, second, 1, 1, steps, scale, &np);
      for (int k = 0; k <= MPMC_PHASE_COUNT; ++k)
        least[f][second != 0][k] = fmin(least[f][second != 0][k], last_phase_ms[k]);
      const double off = first ? b : a, on = first ? a : b;
      sh[f * rounds + r] = off / on - 1.0;
      best[f][0] = off > best[f][0] ? off : best[f][0];
      best[f][1] = on > best[f][1] ? on : best[f][1];
    }
  printf("F-bar's share of the step on the column, one thread, %d rounds of %d steps alternated "
         "(rate off / rate on - 1):\n", rounds, steps);
  for (int f = 0; f < NF; ++f) {
    double *v = sh + f * rounds;
    qsort(v, (size_t)rounds, sizeof *v, cmp_double);
    const double med = rounds % 2 ? v[rounds / 2] : 0.5 * (v[rounds / 2 - 1] + v[rounds / 2]);
    printf("  %-16s median %+6.1f %%  range %+6.1f .. %+6.1f %%  best rates %.3f / %.3f M/s: "
           "%+6.1f %%\n", forms[f].name, 100 * med, 100 * v[0], 100 * v[rounds - 1],
           best[f][0] / 1e6, best[f][1] / 1e6, 100 * (best[f][0] / best[f][1] - 1.0));
    printf("    least ms a step, off -> on:");
    for (int k = 0; k <= MPMC_PHASE_COUNT; ++k)
      if (least[f][1][k] > 0.0005)
        printf(" %s %.3f -> %.3f", k < MPMC_PHASE_COUNT ? mpmc_phase_name(k) : "step",
               least[f][0][k], least[f][1][k]);
    /* the sums of the phases' least times: each phase at its least disturbed round, off and
     * on alike (both sums below any one round's step) */
    double sum[2] = {0.0, 0.0};
    for (int o = 0; o < 2; ++o)
      for (int k = 0; k < MPMC_PHASE_COUNT; ++k) sum[o] += least[f][o][k];
    printf("\n    the phases' least times summed: %.3f -> %.3f ms, %+6.1f %%\n", sum[0], sum[1],
           100 * (sum[1] / sum[0] - 1.0));
  }
  free(sh);
}

/* q-quantile of v[0 .. n - 1], sorted in place (the lower of the two middle values) */
static double quantile(double *v, int n, double q) {
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return v[(int)(q * (n - 1))];
}

/* MPMC_BENCH_PAIRED: F-bar's share from two simulations per form, without and with F-bar,
 * stepped in turn `steps` steps at a time for `blocks` pairs of blocks (see the file's
 * comment) */
static void fbar_paired(int blocks, int steps, double scale) {
  printf("F-bar's share of the step on the column, one thread, the simulations without and "
         "with F-bar stepped in turn %d steps at a time, %d pairs (least, lower quartile and "
         "median step, off -> on):\n", steps, blocks);
  const int per = steps - 1; /* timed steps a block: the first brings its data back */
  double *t[2];
  t[0] = malloc(sizeof(double) * (size_t)blocks * (size_t)(per > 0 ? per : 1));
  t[1] = malloc(sizeof(double) * (size_t)blocks * (size_t)(per > 0 ? per : 1));
  if (!t[0] || !t[1] || per < 1) {
    free(t[0]), free(t[1]);
    return;
  }
  for (int f = 0; f < NF; ++f) {
    mpmc_context ctx;
    mpmc_context_create(&ctx);
    int np, nt[2] = {0, 0};
    double dt[2];
    mpmc_sim sim[2] = {scene_sim(ctx, 1, forms[f].basis, 0, 1, 1, scale, &np, &dt[0]),
                       scene_sim(ctx, 1, forms[f].basis, forms[f].fbar, 1, 1, scale, &np, &dt[1])};
    for (int b = 0; b < blocks; ++b)
      for (int k = 0; k < 2; ++k) {
        const int on = (b + k) % 2; /* off first in even pairs, on first in odd ones */
        CHECK(mpmc_sim_step(sim[on], dt[on]));
        for (int s = 0; s < per; ++s) {
          const double t0 = now();
          CHECK(mpmc_sim_step(sim[on], dt[on]));
          t[on][nt[on]++] = now() - t0;
        }
      }
    for (int k = 0; k < 2; ++k) mpmc_sim_destroy(&sim[k]);
    mpmc_context_destroy(&ctx);
    const double qs[3] = {0.0, 0.25, 0.5};
    printf("  %-16s", forms[f].name);
    for (int i = 0; i < 3; ++i) {
      const double a = quantile(t[0], nt[0], qs[i]), c = quantile(t[1], nt[1], qs[i]);
      printf(" %s %.3f -> %.3f ms %+6.1f %%", i == 0 ? "least" : i == 1 ? "quartile" : "median",
             1e3 * a, 1e3 * c, 100 * (c / a - 1.0));
    }
    printf("\n");
    fflush(stdout);
  }
  free(t[0]), free(t[1]);
}

int main(int argc, char **argv) {
  const int steps = argc > 1 ? atoi(argv[1]) : 20;
  const double scale = argc > 2 ? atof(argv[2]) : 1.0;
  const int only = argc > 3 ? atoi(argv[3]) : -1;
  const int nthr = argc > 4 ? atoi(argv[4]) : 0;
  shuffle_points = argc > 5 ? atoi(argv[5]) : 0;
  sort_every = argc > 6 ? atoi(argv[6]) : 0;
  use_cpu_time = getenv("MPMC_BENCH_CPU") != NULL;
  const int phases = getenv("MPMC_BENCH_PHASES") != NULL;
  const char *bn[4] = {"linear", "ugimp", "bspline2", "bspline3"};
  const char *fb[5] = {"off", "paper", "total", "stable", "anch"};
  const int on = MPMC_FBAR_ANCHORED; /* the default form */
  struct {
    int scene, basis, fbar, j2;
  } cases[] = {
      {0, MPMC_BASIS_BSPLINE2, 0, 0}, {0, MPMC_BASIS_BSPLINE2, on, 0},
      {1, MPMC_BASIS_LINEAR, 0, 1},   {1, MPMC_BASIS_BSPLINE2, 0, 1},
      {1, MPMC_BASIS_BSPLINE2, on, 1},
      /* the landslide's basis (slope_3d.yaml) */
      {1, MPMC_BASIS_UGIMP, 0, 1},    {1, MPMC_BASIS_UGIMP, on, 1},
      /* the stable form of F-bar (J-bar one order below the basis) */
      {1, MPMC_BASIS_BSPLINE2, MPMC_FBAR_STABLE, 1}, {1, MPMC_BASIS_UGIMP, MPMC_FBAR_STABLE, 1},
      /* the reference column's basis with F-bar */
      {1, MPMC_BASIS_LINEAR, on, 1},
      /* Algorithm 1 as published */
      {1, MPMC_BASIS_BSPLINE2, MPMC_FBAR_PAPER, 1},
      /* cubic B-splines, without and with F-bar (callgrind's counts per case) */
      {1, MPMC_BASIS_BSPLINE3, 0, 1}, {1, MPMC_BASIS_BSPLINE3, on, 1},
  };
  printf("%-7s %-9s %-5s %-10s %9s %14s %14s %8s %7s\n", "scene", "basis", "fbar", "material",
         "points", "1 thread [M/s]", "2 threads [M/s]", "speedup", "B/point");
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
    if (only >= 0 && (size_t)only != c) continue;
    int np = 0;
    double r1 = NAN, r2 = NAN;
    for (int t = 1; t <= 2; ++t) {
      if (nthr && nthr != t) continue;
      const double r = run(cases[c].scene, cases[c].basis, cases[c].fbar, cases[c].j2, t, steps,
                           scale, &np);
      *(t == 1 ? &r1 : &r2) = r;
    }
    printf("%-7s %-9s %-5s %-10s %9d %14.3f %14.3f %8.2f %7.0f\n", cases[c].scene ? "column" : "block",
           bn[cases[c].basis], fb[cases[c].fbar], cases[c].j2 ? "hencky_j2" : "hencky", np, r1 / 1e6,
           r2 / 1e6, r2 / r1, last_bytes);
    if (phases) { /* the last run's (the 2-thread one when both ran) */
      printf("  phases (%% of the step):");
      for (int k = 0; k < MPMC_PHASE_COUNT; ++k)
        printf(" %s %.1f", mpmc_phase_name(k), 100 * last_phase[k]);
      printf("\n");
    }
    fflush(stdout);
  }
  const char *share = getenv("MPMC_BENCH_SHARE");
  if (share && atoi(share) > 0) fbar_shares(atoi(share), steps, scale);
  const char *paired = getenv("MPMC_BENCH_PAIRED");
  if (paired && atoi(paired) > 0) fbar_paired(atoi(paired), steps, scale);
  return 0;
}
