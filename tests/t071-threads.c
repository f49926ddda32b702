/* The threaded kernels give the serial answer (issue 11; also the driver of
 * scripts/check-tsan): a 2D and a 3D scene above MPMC_OMP_MIN points (so P2G, G2P, F-bar, the
 * stress update and the monitor run their parallel loops) stepped on 1 and on 2 threads;
 * positions, velocities, stresses and J agree to round-off (the scatter sums in another
 * order), and neither run trips the monitor; also a compact body, whose threads scatter into
 * grids of their own.  Also the slab order P2G builds, the threads' runs of slabs, and G2P's
 * index-order path. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>
#include <limits.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "mpmc_impl.h"

#include "test_util.h"

typedef struct {
  int n;
  double *x, *v, *s, *J;
} snap;

/* compact: a 0.6 m cube at 27 points per cell, six cell planes along every axis: two slabs,
 * so the threads scatter into grids of their own (p2g.c, private_grids) */
static void run(int dim, int nthreads, int fbar, int basis, int compact, snap *out) {
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double h = dim == 2 ? 0.02 : 0.1;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const double blo[3] = {0, 0, 0};
  double bhi[3] = {dim == 2 ? 1.3 : 1.6, 0.7, 0.8}; /* 3D: four even slabs, two colours */
  if (compact) bhi[0] = bhi[1] = bhi[2] = 0.6;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  TCALL(mpmc_sim_set_threads(sim, nthreads));
  int mat, n;
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e6, 0.45, 2000, 8e3, 2e3, 50, &mat));
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, compact ? 3 : 2, mat, NULL, &n));
  if (n <= 4096) fail_msg("expected more than MPMC_OMP_MIN = 4096 points, got %d", n);
  for (int f = 0; f < 2 * dim; ++f)
    if (f != 1) TCALL(mpmc_sim_add_wall_face(sim, f, f == 2 ? MPMC_WALL_FIXED : MPMC_WALL_SLIP, NULL));
  const double g[3] = {0, -9.81, 0};
  TCALL(mpmc_sim_set_gravity(sim, g));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 8; ++s) TCALL(mpmc_sim_step(sim, dt));
  const int expect = compact && nthreads == 2 ? 2 : 0;
  if (sim->grid.nprivate != expect)
    fail_msg("P2G on %d threads: per-thread grids %d, expected %d (%d slabs)", nthreads,
             sim->grid.nprivate, expect, sim->scr.nslab);
  double *f;
  out->n = n;
  const int fields[4] = {MPMC_FIELD_POSITION, MPMC_FIELD_VELOCITY, MPMC_FIELD_STRESS, MPMC_FIELD_J};
  double **dst[4] = {&out->x, &out->v, &out->s, &out->J};
  for (int k = 0; k < 4; ++k) {
    int nc;
    TCALL(mpmc_sim_get_field(sim, fields[k], &f, &nc));
    *dst[k] = malloc(sizeof(double) * (size_t)n * nc);
    memcpy(*dst[k], f, sizeof(double) * (size_t)n * nc);
  }
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

static void compare(const char *what, const double *a, const double *b, size_t len, double scale) {
  for (size_t i = 0; i < len; ++i)
    if (!(fabs(a[i] - b[i]) <= 1e-9 * scale))
      fail_msg("%s[%zu]: 2 threads %.17g, expected the 1-thread value %.17g (tolerance %g)", what, i, b[i], a[i],
               1e-9 * scale);
}

static void check(int dim, int fbar, int basis, int compact) {
  snap one, two;
  run(dim, 1, fbar, basis, compact, &one);
  run(dim, 2, fbar, basis, compact, &two);
  const size_t n = (size_t)one.n;
  compare("x", one.x, two.x, n * dim, 1.0);
  compare("v", one.v, two.v, n * dim, 1.0);
  compare("stress", one.s, two.s, n * 6, 1e4);
  compare("J", one.J, two.J, n, 1.0);
  free(one.x), free(one.v), free(one.s), free(one.J);
  free(two.x), free(two.v), free(two.s), free(two.J);
}

static void test_2d_fbar(void **state) {
  (void)state;
  check(2, MPMC_FBAR_PAPER, MPMC_BASIS_BSPLINE2, 0);
}
static void test_2d_ugimp_total(void **state) {
  (void)state;
  check(2, MPMC_FBAR_TOTAL, MPMC_BASIS_UGIMP, 0);
}
static void test_3d_fbar(void **state) {
  (void)state;
  check(3, MPMC_FBAR_PAPER, MPMC_BASIS_BSPLINE2, 0);
}

/* the anchored default, whose G2P kernels are its own (g2p.c: FB 5 and 7) */
static void test_2d_anchored(void **state) {
  (void)state;
  check(2, MPMC_FBAR_ANCHORED, MPMC_BASIS_LINEAR, 0);
}
static void test_3d_anchored(void **state) {
  (void)state;
  check(3, MPMC_FBAR_ANCHORED, MPMC_BASIS_UGIMP, 0);
}

/* the stable form scatters onto the 2h grid: supports one node wider than the basis' */
static void test_3d_ugimp_stable(void **state) {
  (void)state;
  check(3, MPMC_FBAR_STABLE, MPMC_BASIS_UGIMP, 0);
}

/* a body too small for the slabs' colours: per-thread grids in P2G and in G2P's F-bar
 * scatter (Algorithm 1, the anchored and the stable form), without F-bar in P2G alone */
static void test_3d_compact(void **state) {
  (void)state;
  check(3, MPMC_FBAR_PAPER, MPMC_BASIS_BSPLINE2, 1);
  check(3, MPMC_FBAR_ANCHORED, MPMC_BASIS_BSPLINE3, 1);
  check(3, MPMC_FBAR_STABLE, MPMC_BASIS_UGIMP, 1);
  check(3, MPMC_FBAR_OFF, MPMC_BASIS_LINEAR, 1);
}

/* The slab order of P2G (p2g.c, built for two threads' worth of slabs) is a counting sort by
 * plane: a permutation, slabs in plane order, every point in its own slab's planes, and within
 * a slab the points by plane and within a plane in index order (points stored at random).
 * The order does not depend on how the points were split among the threads (one thread gives
 * the same permutation), nor on the axis the build started from (the last step's). */
/* The slab tests' sim: a 2 x 1 x 1 m grid of 0.1 m cells and an elastic material (*mat),
 * no points yet; lo the grid's corner, the origin. */
static const double slab_lo[3] = {0, 0, 0};
static void slab_sim(mpmc_context *ctx, mpmc_sim *sim, int *mat) {
  TCALL(mpmc_context_create(ctx));
  test_ctx = *ctx;
  TCALL(mpmc_sim_create(*ctx, 3, sim));
  const double hi[3] = {2, 1, 1};
  TCALL(mpmc_sim_set_grid(*sim, slab_lo, hi, 0.1));
  TCALL(mpmc_sim_add_material_hencky(*sim, 1e6, 0.3, 1000, mat));
}

static void test_slab_order(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, n;
  slab_sim(&ctx, &sim, &mat);
  const double *lo = slab_lo, bhi[3] = {1.6, 0.7, 0.8};
  TCALL(mpmc_sim_seed_box(sim, lo, bhi, 2, mat, NULL, &n));
  if (n <= 4096) fail_msg("expected more than MPMC_OMP_MIN points, got %d", n);
  double *x;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
  srand(3);
  for (int q = n - 1; q > 0; --q) {
    const int r = rand() % (q + 1);
    for (int a = 0; a < 3; ++a) {
      const double t = x[3 * q + a];
      x[3 * q + a] = x[3 * r + a], x[3 * r + a] = t;
    }
  }
  TCALL(mpmc_sim_prepare(sim));
  TCALL(mpmc_slabs_build(sim)); /* slabs for OMP_NUM_THREADS = 2 (CTest's environment) */
  const int ax = sim->scr.slab_axis, ns = sim->scr.nslab;
  if (ns < 4) fail_msg("%d slabs: expected at least 4 for two threads (OMP_NUM_THREADS=2)", ns);
  const mpmc_grid *g = &sim->grid;
  unsigned char *seen = calloc((size_t)n, 1);
  int last_plane = -1;
  for (int sl = 0; sl < ns; ++sl) {
    int pmin = INT_MAX, pmax = -1;
    for (int k = sim->scr.slab_start[sl]; k < sim->scr.slab_start[sl + 1]; ++k) {
      const int q = sim->scr.order[k];
      if (q < 0 || q >= n || seen[q]) fail_msg("order[%d] = %d: not a permutation", k, q);
      seen[q] = 1;
      const int pl = (int)((x[3 * q + ax] - g->origin[ax]) * g->inv_h);
      if (k > sim->scr.slab_start[sl]) {
        const int qp = sim->scr.order[k - 1];
        const int plp = (int)((x[3 * qp + ax] - g->origin[ax]) * g->inv_h);
        if (pl < plp || (pl == plp && q < qp))
          fail_msg("slab %d: point %d (plane %d) after point %d (plane %d)", sl, q, pl, qp, plp);
      }
      pmin = pl < pmin ? pl : pmin;
      pmax = pl > pmax ? pl : pmax;
    }
    if (pmin <= last_plane) fail_msg("slab %d starts at plane %d, the slab before ends at %d", sl, pmin, last_plane);
    last_plane = pmax;
  }
  if (sim->scr.slab_start[ns] != n) fail_msg("slabs hold %d of %d points", sim->scr.slab_start[ns], n);
  int *first = malloc(sizeof(int) * (size_t)n);
  memcpy(first, sim->scr.order, sizeof(int) * (size_t)n);
  sim->scr.slab_axis = 2; /* a wrong start: the build must count again along x */
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  TCALL(mpmc_slabs_build(sim));
  omp_set_num_threads(saved);
  if (sim->scr.slab_axis != ax) fail_msg("slab axis %d from a wrong start, %d before", sim->scr.slab_axis, ax);
  for (int k = 0; k < n; ++k)
    if (sim->scr.order[k] != first[k])
      fail_msg("order[%d] = %d on one thread, %d on %d", k, sim->scr.order[k], first[k], saved);
  free(first);
  free(seen);
  /* the axis rule: z once the points span MPMC_SLAB_PLANES planes along it (the landslide:
   * 275 cells long, 30 high), else the longest extent (y and x in 2D likewise) */
  const int clo[3] = {0, 0, 0}, tall[3] = {274, 24, MPMC_SLAB_PLANES - 1}, flat[3] = {274, 24, MPMC_SLAB_PLANES - 2};
  if (mpmc_slab_axis(3, clo, tall) != 2) fail_msg("slab axis %d for %d z planes, expected 2", mpmc_slab_axis(3, clo, tall), MPMC_SLAB_PLANES);
  if (mpmc_slab_axis(3, clo, flat) != 0) fail_msg("slab axis %d for %d z planes, expected 0", mpmc_slab_axis(3, clo, flat), MPMC_SLAB_PLANES - 1);
  if (mpmc_slab_axis(2, clo, tall) != 1) fail_msg("2D: slab axis %d for 25 y planes, expected 1", mpmc_slab_axis(2, clo, tall));
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

/* Each colour's slabs go to the threads in runs (p2g.c, slab_groups): for two and three
 * threads, on a body whose slabs hold unequal numbers of points (a floor with a tower at one
 * end), the runs of a colour cover its slabs in order, each slab once, each slab in the run
 * of the thread whose share of the colour's points (the t-th nt-th) holds the slab's middle
 * point, and so each thread's points differ from its share by at most the largest slab. */
static void test_slab_groups(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, n1, n2;
  slab_sim(&ctx, &sim, &mat);
  const double floor_hi[3] = {1.6, 0.7, 0.3}, tlo[3] = {0, 0, 0.3}, thi[3] = {0.4, 0.7, 0.9};
  TCALL(mpmc_sim_seed_box(sim, slab_lo, floor_hi, 2, mat, NULL, &n1));
  TCALL(mpmc_sim_seed_box(sim, tlo, thi, 2, mat, NULL, &n2));
  TCALL(mpmc_sim_prepare(sim));
  const int saved = omp_get_max_threads();
  for (int nt = 2; nt <= 3; ++nt) {
    omp_set_num_threads(nt);
    TCALL(mpmc_slabs_build(sim));
    const int ns = sim->scr.nslab;
    if (sim->scr.slab_nt != nt) fail_msg("slab runs for %d threads, expected %d", sim->scr.slab_nt, nt);
    for (int c = 0; c < 2; ++c) {
      long total = 0, kmax = 0;
      for (int sl = c; sl < ns; sl += 2) {
        const long k = sim->scr.slab_start[sl + 1] - sim->scr.slab_start[sl];
        total += k;
        kmax = k > kmax ? k : kmax;
      }
      const int end = c + 2 * ((ns - c + 1) / 2); /* the first slab index of colour c >= ns */
      if (mpmc_slab_group(sim, c, 0) != c || mpmc_slab_group(sim, c, nt) != end)
        fail_msg("%d threads, colour %d: runs from slab %d to %d, expected %d to %d", nt, c,
                 mpmc_slab_group(sim, c, 0), mpmc_slab_group(sim, c, nt), c, end);
      for (int t = 0; t < nt; ++t) {
        const int s0 = mpmc_slab_group(sim, c, t), s1 = mpmc_slab_group(sim, c, t + 1);
        if (s1 < s0 || (s0 - c) % 2 || (s1 - c) % 2)
          fail_msg("%d threads, colour %d: thread %d's run %d .. %d", nt, c, t, s0, s1);
        long pts = 0;
        for (int sl = s0; sl < s1; sl += 2) {
          long before = 0; /* the colour's points in the slabs before sl */
          for (int o = c; o < sl; o += 2) before += sim->scr.slab_start[o + 1] - sim->scr.slab_start[o];
          const long k = sim->scr.slab_start[sl + 1] - sim->scr.slab_start[sl];
          const int owner = (int)floor((before + 0.5 * k) * nt / (double)total);
          if ((owner < nt ? owner : nt - 1) != t)
            fail_msg("%d threads, colour %d: slab %d (points %ld .. %ld of %ld) in thread %d's "
                     "run, expected thread %d's", nt, c, sl, before, before + k, total, t,
                     owner < nt ? owner : nt - 1);
          pts += k;
        }
        if (labs(nt * pts - total) > nt * kmax)
          fail_msg("%d threads, colour %d: thread %d has %ld of %ld points (largest slab %ld)",
                   nt, c, t, pts, total, kmax);
      }
    }
  }
  omp_set_num_threads(saved);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

/* G2P's index-order path (sim->scr.order_ident, g2p.c): the slab build flags an order that is
 * the identity, and only then.  Seeded x fastest, the box's points are not
 * in the order of its slab axis, x; sorted (the slab axis outermost), they are, on one thread
 * and on two; a point moved to a plane of its own breaks it.  With the flag on, G2P (F-bar's
 * scatter too) takes the same sequence as through the order: fbj and the points' x, v, dF and
 * J to the bit (and P2G's records), the flag cleared by hand for the comparison. */
static void test_index_order(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, n;
  slab_sim(&ctx, &sim, &mat);
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_PAPER));
  const double bhi[3] = {1.6, 0.7, 0.8}, g[3] = {0.3, -9.81, 0.1};
  TCALL(mpmc_sim_seed_box(sim, slab_lo, bhi, 2, mat, NULL, &n));
  TCALL(mpmc_sim_set_gravity(sim, g));
  TCALL(mpmc_sim_prepare(sim));
  TCALL(mpmc_slabs_build(sim));
  if (sim->scr.slab_axis != 0 || sim->scr.order_ident)
    fail_msg("seeded x fastest: slab axis %d, identity flag %d; expected axis 0 and no identity",
             sim->scr.slab_axis, sim->scr.order_ident);
  TCALL(mpmc_sim_sort_particles(sim));
  const int saved = omp_get_max_threads();
  for (int nt = 1; nt <= 2; ++nt) {
    omp_set_num_threads(nt);
    TCALL(mpmc_slabs_build(sim));
    if (!sim->scr.order_ident) fail_msg("sorted, %d thread(s): no identity flag", nt);
    for (int k = 0; k < n; ++k)
      if (sim->scr.order[k] != k) fail_msg("sorted, %d thread(s): order[%d] = %d", nt, k, sim->scr.order[k]);
  }
  omp_set_num_threads(saved);
  double *v;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  for (int k = 0; k < 3 * n; ++k) v[k] = 0.05 * sin(0.37 * k);
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v));
  mpmc_particles *p = &sim->p;
  const size_t n3 = 3 * (size_t)n, n9 = 9 * (size_t)n;
  double *x0 = malloc(sizeof(double) * n3), *v0 = malloc(sizeof(double) * n3);
  double *J0 = malloc(sizeof(double) * (size_t)n), *Jb0 = malloc(sizeof(double) * (size_t)n);
  memcpy(x0, p->x, sizeof(double) * n3), memcpy(v0, p->v, sizeof(double) * n3);
  memcpy(J0, p->J, sizeof(double) * (size_t)n), memcpy(Jb0, p->Jbar, sizeof(double) * (size_t)n);
  const size_t nrec = sim->grid.nn * MPMC_NREC;
  double *out[2][6];
  const size_t len[6] = {nrec, sim->grid.nn, n3, n3, n9, (size_t)n};
  for (int run = 0; run < 2; ++run) {
    memcpy(p->x, x0, sizeof(double) * n3), memcpy(p->v, v0, sizeof(double) * n3);
    memcpy(p->J, J0, sizeof(double) * (size_t)n), memcpy(p->Jbar, Jb0, sizeof(double) * (size_t)n);
    mpmc_grid_clear(&sim->grid);
    mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_ALL);
    TCALL(mpmc_slabs_build(sim));
    if (!sim->scr.order_ident) fail_msg("run %d: no identity flag", run);
    if (run) sim->scr.order_ident = 0; /* the same sequence through the order */
    TCALL(mpmc_p2g(sim, 1e-4));
    TCALL(mpmc_grid_update(sim, 1e-4));
    TCALL(mpmc_g2p(sim, 1e-4));
    const double *src[6] = {sim->grid.node, sim->fb.fbj, p->x, p->v, p->dF, p->J};
    for (int f = 0; f < 6; ++f) {
      out[run][f] = malloc(sizeof(double) * len[f]);
      memcpy(out[run][f], src[f], sizeof(double) * len[f]);
    }
  }
  const char *names[6] = {"grid records", "fbj", "x", "v", "dF", "J"};
  double sum = 0.0;
  for (int f = 0; f < 6; ++f) {
    for (size_t i = 0; i < len[f]; ++i) {
      if (memcmp(&out[0][f][i], &out[1][f][i], sizeof(double)))
        fail_msg("%s[%zu]: %.17g in index order, %.17g through the order", names[f], i,
                 out[0][f][i], out[1][f][i]);
      sum += fabs(out[0][f][i]);
    }
    free(out[0][f]), free(out[1][f]);
  }
  if (!(sum > 0.0)) fail_msg("the transfers left everything zero");
  /* one point to a plane beyond the others' (the sorted order no longer the identity) */
  p->x[0] = 1.75;
  TCALL(mpmc_slabs_build(sim));
  if (sim->scr.order_ident) fail_msg("point 0 moved to x = 1.75: still flagged as identity");
  if (sim->scr.order[n - 1] != 0) fail_msg("point 0 moved to the last plane: order[%d] = %d", n - 1, sim->scr.order[n - 1]);
  free(x0), free(v0), free(J0), free(Jb0);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_2d_fbar), cmocka_unit_test(test_2d_ugimp_total),
                                     cmocka_unit_test(test_3d_fbar), cmocka_unit_test(test_2d_anchored),
                                     cmocka_unit_test(test_3d_anchored), cmocka_unit_test(test_3d_ugimp_stable), cmocka_unit_test(test_3d_compact),
                                     cmocka_unit_test(test_slab_order), cmocka_unit_test(test_slab_groups),
                                     cmocka_unit_test(test_index_order)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
