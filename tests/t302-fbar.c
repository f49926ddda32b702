/* F-bar projection (issue 2, test 3; paper Algorithm 1), in each of its forms (paper, total,
 * stable): a homogeneous deformation gives dFbar = dF exactly; a checkerboard of J from point
 * to point is replaced by its volume average.  The stable form (a space one order below the
 * basis) also removes the mode of period 2h, J = 1 + e sum_a cos(pi x_a / h), exactly, which
 * the projection onto the basis itself (total form) passes at a large share of its amplitude:
 * the pressure checkerboard of the strip footing (docs/theory.md).  A caller that borrows the
 * positions once and keeps the pointer across F-bar steps (a legacy Fortran loop) reads the
 * current positions through it, the same bits as a run that borrows them afresh.  In a step
 * the projection's weights are those at x^n, before G2P moves the points. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "transfer.h"
#include "test_util.h"

static mpmc_sim make(mpmc_context ctx, int dim, int basis, int mode, int ncell, double **x, int *n) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double lo[3] = {-1, -1, -1}, hi[3] = {ncell + 1, ncell + 1, ncell + 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 1.0));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, mode));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, 1.0, 0.3, 1.0, &mat));
  double *vol;
  const double plo[3] = {0, 0, 0}, phi[3] = {ncell, ncell, ncell};
  *n = test_lattice(dim, plo, phi, 1.0, 2, x, &vol);
  TCALL(mpmc_sim_add_particles(sim, *n, *x, vol, mat, NULL));
  free(vol);
  TCALL(mpmc_sim_prepare(sim));
  mpmc_grid_clear(&sim->grid);
  mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_ALL);
  TCALL(mpmc_slabs_build(sim)); /* the projection scatters by the slabs P2G builds */
  return sim;
}

static double det(int d, const double *F) {
  return d == 2 ? F[0] * F[3] - F[1] * F[2]
                : F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                      F[2] * (F[3] * F[7] - F[4] * F[6]);
}

static void homogeneous(int dim, int basis, int mode) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  double *x;
  int n;
  mpmc_sim sim = make(ctx, dim, basis, mode, 4, &x, &n);
  const double F2[4] = {1.01, 0.02, -0.015, 0.985};
  const double F3[9] = {1.01, 0.02, 0.003, -0.015, 0.985, 0.01, 0.004, -0.02, 1.03};
  const double *F = dim == 2 ? F2 : F3;
  const double dJ = det(dim, F);
  for (int q = 0; q < n; ++q) {
    for (int k = 0; k < dim * dim; ++k) sim->p.dF[q * dim * dim + k] = F[k];
    sim->p.Jbar[q] = 1.1; /* Jbar^n; the points' J already holds J^n dJ */
    sim->p.J[q] = 1.1 * dJ;
    if (sim->p.Janc) sim->p.Janc[q] = 1.1; /* anchored to Jbar^n / J^n = 1 */
  }
  TCALL(mpmc_fbar(sim, 0));
  for (int q = 0; q < n; ++q) {
    for (int k = 0; k < dim * dim; ++k)
      if (fabs(sim->p.dF[q * dim * dim + k] - F[k]) > 1e-14)
        fail_msg("dim %d basis %d mode %d point %d: dFbar[%d] = %.17g, expected dF = %.17g", dim,
                 basis, mode, q, k, sim->p.dF[q * dim * dim + k], F[k]);
    TCLOSE(sim->p.Jbar[q], 1.1 * dJ, 1e-14);
  }
  free(x);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

#define NCELL 12
/* points inside the box where every node in reach has its full support of points */
static int interior(int dim, const double *x) {
  int in = 1;
  for (int a = 0; a < dim; ++a) in &= x[a] > 4.5 && x[a] < NCELL - 4.5;
  return in;
}

/* A context and a sim whose points carry an isotropic dF of det j(x) (Jbar^n = 1, J = j),
 * projected; finish() frees them. */
static mpmc_sim project(mpmc_context *ctx, int dim, int basis, int mode,
                        double (*jof)(int dim, const double *x), double **x, int *n) {
  TCALL(mpmc_context_create(ctx));
  test_ctx = *ctx;
  mpmc_sim sim = make(*ctx, dim, basis, mode, NCELL, x, n);
  for (int q = 0; q < *n; ++q) {
    const double j = jof(dim, *x + q * dim), s = dim == 2 ? sqrt(j) : cbrt(j);
    for (int k = 0; k < dim * dim; ++k) sim->p.dF[q * dim * dim + k] = (k % (dim + 1) == 0) ? s : 0.0;
    sim->p.Jbar[q] = 1.0;
    sim->p.J[q] = j;
  }
  TCALL(mpmc_fbar(sim, 0));
  return sim;
}

static void finish(mpmc_sim *sim, mpmc_context *ctx, double *x) {
  free(x);
  mpmc_sim_destroy(sim);
  mpmc_context_destroy(ctx);
  test_ctx = NULL;
}

/* alternating volume change from point to point (2 points per cell per axis) */
static const double ja = 1.02, jb = 0.96;
static double j_checkerboard(int dim, const double *x) {
  int parity = 0;
  for (int a = 0; a < dim; ++a) parity += (int)floor(2.0 * x[a]);
  return parity % 2 ? ja : jb;
}

static void checkerboard(int dim, int basis, int mode) {
  mpmc_context ctx;
  double *x;
  int n;
  mpmc_sim sim = project(&ctx, dim, basis, mode, j_checkerboard, &x, &n);
  const double mean = 0.5 * (ja + jb);
  int checked = 0;
  for (int q = 0; q < n; ++q) {
    if (!interior(dim, x + q * dim)) continue;
    ++checked;
    if (fabs(sim->p.Jbar[q] - mean) > 1e-13)
      fail_msg("dim %d basis %d mode %d point %d: projected J %.17g, expected the average %.17g",
               dim, basis, mode, q, sim->p.Jbar[q], mean);
    TCLOSE(det(dim, sim->p.dF + q * dim * dim), mean, 1e-13);
  }
  assert_true(checked > 0);
  finish(&sim, &ctx, x);
}

/* the mode of period 2h (h = 1) */
static const double e_mode = 1e-3;
static double j_nodal_mode(int dim, const double *x) {
  double j = 1.0;
  for (int a = 0; a < dim; ++a) j += e_mode * cos(M_PI * x[a]);
  return j;
}

/* J = 1 + e sum_a cos(pi x_a): the largest |Jbar - 1| / e over the interior points */
static double nodal_mode(int dim, int basis, int mode) {
  mpmc_context ctx;
  double *x;
  int n;
  mpmc_sim sim = project(&ctx, dim, basis, mode, j_nodal_mode, &x, &n);
  double worst = 0.0;
  for (int q = 0; q < n; ++q) {
    if (!interior(dim, x + q * dim)) continue;
    worst = fmax(worst, fabs(sim->p.Jbar[q] - 1.0) / e_mode);
    TCLOSE(det(dim, sim->p.dF + q * dim * dim), sim->p.Jbar[q], 1e-13);
  }
  finish(&sim, &ctx, x);
  return worst;
}

/* check(dim, basis, form) for both dimensions, every basis and every F-bar form */
static void every_case(void (*check)(int, int, int)) {
  for (int m = MPMC_FBAR_PAPER; m <= MPMC_FBAR_ANCHORED; ++m)
    for (int b = 0; b < 4; ++b)
      for (int d = 2; d <= 3; ++d) check(d, b, m);
}

static void test_homogeneous(void **state) {
  (void)state;
  every_case(homogeneous);
}

static void test_checkerboard(void **state) {
  (void)state;
  every_case(checkerboard);
}

static void test_nodal_mode(void **state) {
  (void)state;
  for (int d = 2; d <= 3; ++d)
    for (int b = 0; b < 4; ++b) {
      const double total = nodal_mode(d, b, MPMC_FBAR_TOTAL), stable = nodal_mode(d, b, MPMC_FBAR_STABLE);
      print_message("dim %d basis %d: |Jbar - 1| / e of the period-2h mode: total %.3g, stable %.3g\n",
                    d, b, total, stable);
      if (stable > 1e-10)
        fail_msg("dim %d basis %d: the stable form left %.3g of the period-2h mode", d, b, stable);
      if (total < 0.05)
        fail_msg("dim %d basis %d: the total form removed the period-2h mode (%.3g): the test "
                 "no longer shows the difference", d, b, total);
    }
}

/* After P2G's reset of the active box (mpmc_grid_clear_active) every F-bar sum in the grid
 * is zero (fb, allocated for the stable form alone, fbj and the records' volume slot): every
 * form's supports, the stable form's spaces too, lie in the active box.  A block translating
 * through the grid, every form, basis and dimension, after each step. */
/* a 2D block falling with F-bar (every form), uGIMP; positions_held: borrowed once and kept */
static mpmc_sim falling(mpmc_context ctx, int form, int *n) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {2, 2}, blo[2] = {0.5, 0.5}, bhi[2] = {1.25, 1.25}, g[2] = {0.3, -10};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.25));
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_UGIMP));
  TCALL(mpmc_sim_set_fbar(sim, form));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.45, 1000, &mat));
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, n));
  TCALL(mpmc_sim_set_gravity(sim, g));
  return sim;
}

static void test_positions_held(void **state) {
  (void)state;
  for (int form = MPMC_FBAR_PAPER; form <= MPMC_FBAR_ANCHORED; ++form) {
    mpmc_context ctx;
    TCALL(mpmc_context_create(&ctx));
    test_ctx = ctx;
    int n;
    mpmc_sim a = falling(ctx, form, &n), b = falling(ctx, form, &n);
    double *held, *now, *xb;
    TCALL(mpmc_sim_get_field(a, MPMC_FIELD_POSITION, &held, NULL));
    const double y0 = held[1];
    for (int s = 0; s < 6; ++s) {
      TCALL(mpmc_sim_step(a, 1e-3));
      TCALL(mpmc_sim_step(b, 1e-3));
      TCALL(mpmc_sim_get_field(a, MPMC_FIELD_POSITION, &now, NULL));
      if (now != held) fail_msg("form %d step %d: the positions moved to another array", form, s);
      TCALL(mpmc_sim_get_field(b, MPMC_FIELD_POSITION, &xb, NULL));
      for (int k = 0; k < 2 * n; ++k)
        if (held[k] != xb[k])
          fail_msg("form %d step %d: held position %d is %.17g, the run that borrows afresh has %.17g", form, s, k,
                   held[k], xb[k]);
      TCALL(mpmc_sim_restore_field(b, MPMC_FIELD_POSITION, &xb));
    }
    if (!(held[1] < y0 - 1e-4)) fail_msg("form %d: the block did not fall (y %.9g from %.9g)", form, held[1], y0);
    mpmc_sim_destroy(&a);
    mpmc_sim_destroy(&b);
    mpmc_context_destroy(&ctx);
  }
}

static void test_fb_cleared(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; ++dim)
    for (int m = MPMC_FBAR_PAPER; m <= MPMC_FBAR_ANCHORED; ++m)
      for (int b = 0; b < 4; ++b) {
        mpmc_context ctx;
        TCALL(mpmc_context_create(&ctx));
        test_ctx = ctx;
        mpmc_sim sim;
        TCALL(mpmc_sim_create(ctx, dim, &sim));
        const double lo[3] = {-1, -1, -1}, hi[3] = {12, 6, 6};
        TCALL(mpmc_sim_set_grid(sim, lo, hi, 1.0));
        TCALL(mpmc_sim_set_basis(sim, b));
        TCALL(mpmc_sim_set_fbar(sim, m));
        int mat, n;
        TCALL(mpmc_sim_add_material_hencky(sim, 1.0, 0.3, 1.0, &mat));
        double *x, *vol;
        const double plo[3] = {0, 0, 0}, phi[3] = {4, 4, 4};
        n = test_lattice(dim, plo, phi, 1.0, 2, &x, &vol);
        TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
        free(x);
        free(vol);
        TCALL(mpmc_sim_prepare(sim));
        double *v;
        TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
        for (int q = 0; q < n; ++q) v[q * dim] = 1.0; /* 1 cell/s along x */
        double dt;
        TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
        const int steps = (int)(4.0 / dt); /* four cells on */
        for (int s = 0; s < steps; ++s) {
          TCALL(mpmc_sim_step(sim, dt));
          mpmc_grid_clear_active(&sim->grid);
          mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_BOX);
          const mpmc_grid *g = &sim->grid;
          const mpmc_fbar_state *f = &sim->fb;
          if ((f->fb != NULL) != (m == MPMC_FBAR_STABLE))
            fail_msg("dim %d form %d: fb %s", dim, m, f->fb ? "allocated" : "missing");
          for (size_t i = 0; i < g->nn; ++i) {
            const double fb0 = f->fb ? f->fb[2 * i] : 0.0, fb1 = f->fb ? f->fb[2 * i + 1] : 0.0;
            const double vs = g->node[i * MPMC_NREC + MPMC_VSLOT];
            if (fb0 != 0.0 || fb1 != 0.0 || f->fbj[i] != 0.0 || vs != 0.0)
              fail_msg("dim %d form %d basis %d step %d: node %zu fb (%g, %g), fbj %g, volume "
                       "slot %g after the reset", dim, m, b, s, i, fb0, fb1, f->fbj[i], vs);
          }
        }
        mpmc_sim_destroy(&sim);
        mpmc_context_destroy(&ctx);
        test_ctx = NULL;
      }
}

/* The grid's passes go over each node row's x range alone (grid.rowx, p2g.c's row_ranges, the
 * mirrors' partners added by the grid update): after a step every nonzero grid value (any
 * record slot, fb, fbj) lies in the active box and in its row's range, and the reset of the
 * last step's ranges (mpmc_grid_clear_active) leaves the whole grid zero.  Adds the nodes
 * the ranges held and those of the box to *ranged and *boxed. */
static void check_rows(mpmc_sim sim, const char *what, int s, long *ranged, long *boxed) {
  const mpmc_grid *g = &sim->grid;
  const mpmc_fbar_state *f = &sim->fb;
  for (int kz = 0; kz < g->n[2]; ++kz)
    for (int j = 0; j < g->n[1]; ++j) {
      const size_t row = (size_t)j + (size_t)g->n[1] * (size_t)kz;
      const int in_box =
          j >= g->act_lo[1] && j < g->act_hi[1] && kz >= g->act_lo[2] && kz < g->act_hi[2];
      const int rlo = g->rowx[2 * row], rhi = g->rowx[2 * row + 1];
      if (in_box) {
        *ranged += rhi > rlo ? rhi - rlo : 0;
        *boxed += g->act_hi[0] - g->act_lo[0];
        if (rhi > rlo && (rlo < g->act_lo[0] || rhi > g->act_hi[0]))
          fail_msg("%s step %d: row (%d, %d) range [%d, %d) outside the box [%d, %d)", what, s,
                   j, kz, rlo, rhi, g->act_lo[0], g->act_hi[0]);
      }
      for (int i = 0; i < g->n[0]; ++i) {
        const size_t nd = (size_t)i + (size_t)g->n[0] * row;
        int nonzero = f->fbj[nd] != 0.0 || (f->fb && (f->fb[2 * nd] != 0.0 || f->fb[2 * nd + 1] != 0.0));
        for (int e = 0; e < MPMC_NREC; ++e) nonzero |= g->node[nd * MPMC_NREC + e] != 0.0;
        if (nonzero && !(in_box && i >= rlo && i < rhi))
          fail_msg("%s step %d: node (%d, %d, %d) holds values outside its row's range [%d, "
                   "%d)%s", what, s, i, j, kz, rlo, rhi, in_box ? "" : " and the box");
      }
    }
  mpmc_grid_clear_active(&sim->grid);
  mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_BOX);
  for (size_t i = 0; i < g->nn; ++i) {
    int nonzero = f->fbj[i] != 0.0 || (f->fb && (f->fb[2 * i] != 0.0 || f->fb[2 * i + 1] != 0.0));
    for (int e = 0; e < MPMC_NREC; ++e) nonzero |= g->node[i * MPMC_NREC + e] != 0.0;
    if (nonzero) fail_msg("%s step %d: node %zu nonzero after the reset", what, s, i);
  }
}

/* check_rows on a wedge (x + y below 4 m in 2D, x + z in 3D, on a 12 m floor) slumping under
 * gravity and sliding along x, with slip walls on x = 0 and (3D) on both y faces and a fixed
 * floor, whose ghost nodes the B-splines and uGIMP mirror; every basis and dimension, the
 * paper's form and the stable one (fb), one and two threads (the latter may scatter into
 * per-thread grids).  The ranges must leave part of the box out (the wedge's upper rows are
 * short), or the test would not show them. */
static void test_row_ranges(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; ++dim)
    for (int b = 0; b < 4; ++b)
      for (int m = MPMC_FBAR_PAPER; m <= MPMC_FBAR_STABLE; m += MPMC_FBAR_STABLE - MPMC_FBAR_PAPER)
        for (int th = 1; th <= 2; ++th) {
          mpmc_context ctx;
          TCALL(mpmc_context_create(&ctx));
          test_ctx = ctx;
          mpmc_sim sim;
          TCALL(mpmc_sim_create(ctx, dim, &sim));
          const double lo[3] = {0, 0, 0}, hi[3] = {12, dim == 3 ? 1.5 : 5, 5};
          TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.25));
          TCALL(mpmc_sim_set_basis(sim, b));
          TCALL(mpmc_sim_set_fbar(sim, m));
          TCALL(mpmc_sim_set_threads(sim, th));
          int mat;
          TCALL(mpmc_sim_add_material_hencky(sim, 2e5, 0.3, 1000, &mat));
          double *x, *vol;
          const double plo[3] = {0, 0, 0}, phi[3] = {4, dim == 3 ? 1.5 : 4, 4};
          int n = test_lattice(dim, plo, phi, 0.25, 2, &x, &vol), k = 0;
          for (int q = 0; q < n; ++q) { /* the wedge: x + height < 4 */
            if (x[q * dim] + x[q * dim + dim - 1] >= 4.0) continue;
            for (int a = 0; a < dim; ++a) x[k * dim + a] = x[q * dim + a];
            vol[k++] = vol[q];
          }
          TCALL(mpmc_sim_add_particles(sim, k, x, vol, mat, NULL));
          free(x);
          free(vol);
          int wid;
          TCALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, &wid));            /* x = 0 */
          TCALL(mpmc_sim_add_wall_face(sim, 2 * (dim - 1), MPMC_WALL_FIXED, &wid)); /* floor */
          if (dim == 3) {
            TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_SLIP, &wid));
            TCALL(mpmc_sim_add_wall_face(sim, 3, MPMC_WALL_SLIP, &wid));
          }
          const double gr[3] = {3.0, dim == 2 ? -9.81 : 0.0, dim == 3 ? -9.81 : 0.0};
          TCALL(mpmc_sim_set_gravity(sim, gr));
          TCALL(mpmc_sim_prepare(sim));
          double dt;
          TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
          char what[96];
          snprintf(what, sizeof what, "wedge, dim %d basis %d form %d threads %d", dim, b, m, th);
          long ranged = 0, boxed = 0;
          for (int s = 0; s < 30; ++s) {
            TCALL(mpmc_sim_step(sim, dt));
            check_rows(sim, what, s, &ranged, &boxed);
          }
          if (!(ranged < 0.85 * boxed))
            fail_msg("%s: the row ranges held %ld of the box's %ld nodes: the wedge does not "
                     "exercise them", what, ranged, boxed);
          double *v;
          TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
          double vmax = 0.0;
          for (int q = 0; q < k; ++q) vmax = v[q * dim] > vmax ? v[q * dim] : vmax;
          if (!(vmax > 0.05)) fail_msg("%s: the wedge does not slide (v_x %g)", what, vmax);
          TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v));
          mpmc_sim_destroy(&sim);
          mpmc_context_destroy(&ctx);
          test_ctx = NULL;
        }
}

/* The mirrors' partners outside the points' row ranges: interior slip walls on the node
 * planes x = 2.5 and y = 5.5 (material on their + sides), and on their constrained sides a
 * block of points 0.5 to 1 m from each (x in [1.5, 2], y in [0.5, 1]; x in [5, 6], y in [4,
 * 4.5]), sharing no node row: the ghost nodes of the B-splines and uGIMP within their reach
 * carry mass, and the partners across the wall, which no point's stencil reaches, must join
 * the rows' ranges (grid_update.c, grow_box_for_mirrors: the x wall's within a row, the y
 * wall's as whole rows beyond the box). */
static void test_row_ranges_mirrors(void **state) {
  (void)state;
  for (int b = 1; b < 4; ++b) {
    mpmc_context ctx;
    TCALL(mpmc_context_create(&ctx));
    test_ctx = ctx;
    mpmc_sim sim;
    TCALL(mpmc_sim_create(ctx, 2, &sim));
    const double lo[2] = {0, 0}, hi[2] = {8, 8};
    TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.25));
    TCALL(mpmc_sim_set_basis(sim, b));
    TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_PAPER));
    int mat, wid;
    TCALL(mpmc_sim_add_material_hencky(sim, 2e5, 0.3, 1000, &mat));
    const double alo[2] = {1.5, 0.5}, ahi[2] = {2.0, 1.0}, blo[2] = {5.0, 4.0}, bhi[2] = {6.0, 4.5};
    TCALL(mpmc_sim_seed_box(sim, alo, ahi, 2, mat, NULL, NULL));
    TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, NULL));
    TCALL(mpmc_sim_add_wall(sim, 0, -1, 2.5, MPMC_WALL_SLIP, &wid));
    TCALL(mpmc_sim_add_wall(sim, 1, -1, 5.5, MPMC_WALL_SLIP, &wid));
    TCALL(mpmc_sim_prepare(sim));
    char what[64];
    snprintf(what, sizeof what, "interior walls, basis %d", b);
    long ranged = 0, boxed = 0;
    for (int s = 0; s < 3; ++s) {
      TCALL(mpmc_sim_step(sim, 1e-4));
      check_rows(sim, what, s, &ranged, &boxed);
    }
    mpmc_sim_destroy(&sim);
    mpmc_context_destroy(&ctx);
    test_ctx = NULL;
  }
}

/* The step leaves the gather to the material update when every material runs it (fbar.c,
 * sim->fb.deferred: Hencky-J2, Hencky, Neo-Hookean, Newtonian): the same bits as the gather as a
 * phase of its own, which an unused user material beside it brings back.  A 3D and a 2D
 * block slumping under gravity, 40 steps, every basis and form: softening J2 soil (plastic
 * points, the return maps' chunks), and each of the other three models; the deferred path
 * leaves dF unscaled (it scales as it loads), so dF differs where F-bar acted. */
/* extra: an unused user material too (no material update then gathers: the gather phase
 * runs); two: the body as two materials of the same parameters, split at x = 0.625 between
 * the two points of a cell and sorted by cell, so that the deferred gather meets blocks of
 * four points of both (the updates' point-by-point paths) */
enum { SLUMP_J2, SLUMP_NH, SLUMP_HENCKY, SLUMP_FLUID, SLUMP_MODELS };
static int unused_stress(void *data, const double *dF, double dt, double *state, double *stress) {
  (void)data, (void)dF, (void)dt, (void)state, (void)stress;
  return 1; /* never called: the material has no points */
}
static void add_slump_material(mpmc_sim sim, int model, int *id) {
  if (model == SLUMP_J2)
    TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e6, 0.45, 2000, 8e3, 2e3, 20, id));
  else if (model == SLUMP_NH)
    TCALL(mpmc_sim_add_material_neo_hookean(sim, 1e6, 0.45, 2000, id));
  else if (model == SLUMP_HENCKY)
    TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.45, 2000, id));
  else
    TCALL(mpmc_sim_add_material_newtonian(sim, 1e6, 1e-3, 1000, id));
}
static mpmc_sim slump(mpmc_context ctx, int dim, int basis, int form, int extra, int two,
                      int model) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {4, 2, 2};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.25));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, form));
  int mat, mat2 = -1, unused;
  add_slump_material(sim, model, &mat);
  if (two) add_slump_material(sim, model, &mat2);
  if (extra) TCALL(mpmc_sim_add_material_user(sim, unused_stress, NULL, 0, 1000, 1.0, &unused));
  const double blo[3] = {0, 0, 0}, bhi[3] = {two ? 0.625 : 1.5, 1.0, 1.5};
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, NULL));
  if (two) {
    const double rlo[3] = {0.625, 0, 0}, rhi[3] = {1.5, 1.0, 1.5};
    TCALL(mpmc_sim_seed_box(sim, rlo, rhi, 2, mat2, NULL, NULL));
    TCALL(mpmc_sim_sort_particles(sim));
  }
  const double g[3] = {0, dim == 2 ? -9.81 : 0, dim == 3 ? -9.81 : 0};
  TCALL(mpmc_sim_set_gravity(sim, g));
  for (int f = 0; f < 2 * dim; ++f) TCALL(mpmc_sim_add_wall_face(sim, f, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_set_threads(sim, 2));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 40; ++s) TCALL(mpmc_sim_step(sim, dt));
  return sim;
}

static void test_deferred_gather(void **state) {
  (void)state;
  static const int fields[] = {MPMC_FIELD_POSITION, MPMC_FIELD_VELOCITY, MPMC_FIELD_J,
                               MPMC_FIELD_JBAR,     MPMC_FIELD_STRESS,   MPMC_FIELD_BE,
                               MPMC_FIELD_EPS_P};
  static const char *const names[] = {"hencky_j2", "neo_hookean", "hencky", "newtonian"};
  for (int model = 0; model < SLUMP_MODELS; ++model)
  for (int two = 0; two <= 1; ++two)
  for (int dim = 2; dim <= 3; ++dim)
    for (int form = MPMC_FBAR_PAPER; form <= MPMC_FBAR_ANCHORED; ++form)
      for (int b = 0; b < 4; ++b) {
        mpmc_context ctx;
        TCALL(mpmc_context_create(&ctx));
        test_ctx = ctx;
        mpmc_sim fused = slump(ctx, dim, b, form, 0, two, model),
                 apart = slump(ctx, dim, b, form, 1, two, model);
        const int n = fused->p.n;
        /* the fields the model has: b_e but for the fluid, eps_p for J2 alone */
        const int nf = model == SLUMP_J2 ? 7 : model == SLUMP_FLUID ? 5 : 6;
        for (int f = 0; f < nf; ++f) {
          double *a, *c;
          int na, nc;
          TCALL(mpmc_sim_get_field(fused, fields[f], &a, &na));
          TCALL(mpmc_sim_get_field(apart, fields[f], &c, &nc));
          assert_int_equal(na, nc);
          if (memcmp(a, c, sizeof(double) * (size_t)na * (size_t)n) != 0)
            fail_msg("%s, dim %d form %d basis %d (two materials: %d): field %d differs between "
                     "the deferred gather and the gather phase",
                     names[model], dim, form, b, two, fields[f]);
        }
        double plastic = 0.0, dfdiff = 0.0;
        for (int q = 0; q < n && model == SLUMP_J2; ++q) plastic += fused->p.eps_p[q] > 0.0;
        for (int k = 0; k < n * dim * dim; ++k) dfdiff += fused->p.dF[k] != apart->p.dF[k];
        if ((model == SLUMP_J2 && plastic < 0.05 * n) || dfdiff == 0.0)
          fail_msg("%s, dim %d form %d basis %d: %g of %d points plastic, %g dF entries differ: "
                   "the test no longer shows the deferred gather",
                   names[model], dim, form, b, plastic, n, dfdiff);
        mpmc_sim_destroy(&fused);
        mpmc_sim_destroy(&apart);
        mpmc_context_destroy(&ctx);
        test_ctx = NULL;
      }
}

/* Point q's sum_i w_i(x) Jbar_i over the grid's nodal averages fbj at the positions xs: with
 * the weights of the stable form's space (transfer.h), or of the basis itself (the paper and
 * total forms), axis by axis as the 1D weights. */
static double projected_at(mpmc_const_sim sim, const double *xs, int q) {
  const mpmc_grid *g = &sim->grid;
  const int d = sim->cfg.dim, basis = sim->cfg.basis, S = mpmc_stencil(basis);
  if (sim->cfg.fbar == MPMC_FBAR_STABLE) {
    mpmc_spw sp;
    mpmc_stable_weights(d, basis, g, xs + (size_t)q * d, &sp);
    double pi = 0.0;
    MPMC_STABLE_LOOP(d, basis, sp, { pi += w * sim->fb.fbj[node]; });
    return pi;
  }
  double w[3][MPMC_MAX_STENCIL] = {{0}}, dw[MPMC_MAX_STENCIL];
  int base[3] = {0, 0, 0};
  for (int a = 0; a < d; ++a)
    mpmc_basis_1d(basis, (xs[(size_t)q * d + a] - g->origin[a]) * g->inv_h,
                  basis == MPMC_BASIS_UGIMP ? sim->p.lp[q] * g->inv_h : 0.0, g->inv_h, &base[a],
                  w[a], dw);
  const size_t sy = (size_t)g->n[0], sz = sy * (size_t)g->n[1];
  const size_t node0 = (size_t)base[0] + sy * (size_t)base[1] + (d == 3 ? sz * (size_t)base[2] : 0);
  double pi = 0.0;
  for (int k = 0; k < (d == 3 ? S : 1); ++k)
    for (int j = 0; j < S; ++j)
      for (int i = 0; i < S; ++i)
        pi += w[0][i] * w[1][j] * (d == 3 ? w[2][k] : 1.0) *
              sim->fb.fbj[node0 + (size_t)i + sy * (size_t)j + sz * (size_t)k];
  return pi;
}

/* Algorithm 1 projects with the weights at x^n (G2P moves the points, and keeps x^n for the
 * gather): after a step of the slump, every point's projected Jacobian (Jbar) is the sum of
 * the nodal averages with its weights at the positions before the step, not after it; every
 * form, every basis, 2D and 3D, one and two threads. */
static void test_gather_at_xn(void **state) {
  (void)state;
  for (int dim = 2; dim <= 3; ++dim)
    for (int form = MPMC_FBAR_PAPER; form <= MPMC_FBAR_ANCHORED; ++form)
      for (int b = 0; b < 4; ++b)
        for (int threads = 1; threads <= 2; ++threads) {
          mpmc_context ctx;
          TCALL(mpmc_context_create(&ctx));
          test_ctx = ctx;
          mpmc_sim sim = slump(ctx, dim, b, form, 0, 0, SLUMP_HENCKY);
          TCALL(mpmc_sim_set_threads(sim, threads));
          const int n = sim->p.n;
          double *xn = malloc(sizeof(double) * (size_t)n * (size_t)dim), dt;
          assert_non_null(xn);
          memcpy(xn, sim->p.x, sizeof(double) * (size_t)n * (size_t)dim);
          TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
          TCALL(mpmc_sim_step(sim, dt));
          double worst = 0.0, moved = 0.0;
          for (int q = 0; q < n; ++q) {
            const double e = fabs(projected_at(sim, xn, q) - sim->p.Jbar[q]);
            worst = e > worst ? e : worst;
            const double m = fabs(projected_at(sim, sim->p.x, q) - sim->p.Jbar[q]);
            moved = m > moved ? m : moved;
          }
          if (!(worst <= 1e-13))
            fail_msg("dim %d form %d basis %d, %d threads: Jbar differs from the projection at "
                     "x^n by %.3g", dim, form, b, threads, worst);
          if (!(moved > 1e-9))
            fail_msg("dim %d form %d basis %d: the projection at x^{n+1} is within %.3g of the "
                     "one at x^n: the test no longer tells them apart", dim, form, b, moved);
          free(xn);
          mpmc_sim_destroy(&sim);
          mpmc_context_destroy(&ctx);
          test_ctx = NULL;
        }
}

/* What G2P keeps of x^n for the gather is allocated for the form that needs it and freed
 * when the form changes (nothing a scene does not use): the weights' offsets and first nodes
 * for the paper and total forms, the positions for the stable form, neither without F-bar;
 * each change of form between steps still projects at x^n (test_gather_at_xn's check). */
static void test_kept_fields(void **state) {
  (void)state;
  static const int forms[] = {MPMC_FBAR_PAPER, MPMC_FBAR_STABLE,   MPMC_FBAR_TOTAL,
                              MPMC_FBAR_OFF,   MPMC_FBAR_ANCHORED, MPMC_FBAR_PAPER};
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim sim = slump(ctx, 3, MPMC_BASIS_UGIMP, MPMC_FBAR_OFF, 0, 0, SLUMP_HENCKY);
  const int n = sim->p.n;
  double *xn = malloc(sizeof(double) * 3 * (size_t)n), dt;
  assert_non_null(xn);
  for (size_t f = 0; f < sizeof forms / sizeof forms[0]; ++f) {
    const int form = forms[f];
    TCALL(mpmc_sim_set_fbar(sim, form));
    memcpy(xn, sim->p.x, sizeof(double) * 3 * (size_t)n);
    TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
    TCALL(mpmc_sim_step(sim, dt));
    const int kept = form != MPMC_FBAR_OFF && form != MPMC_FBAR_STABLE;
    if ((sim->p.Jbar != NULL) != (form != MPMC_FBAR_OFF))
      fail_msg("form %d: the points' Jbar %s", form, sim->p.Jbar ? "kept" : "absent");
    if ((sim->fb.xn != NULL) != (form == MPMC_FBAR_STABLE) || (sim->fb.xoff != NULL) != kept ||
        (sim->fb.xnode != NULL) != kept || (sim->p.Janc != NULL) != (form == MPMC_FBAR_ANCHORED))
      fail_msg("form %d: x^n %s, offsets %s, first nodes %s, anchored J %s", form,
               sim->fb.xn ? "kept" : "absent", sim->fb.xoff ? "kept" : "absent",
               sim->fb.xnode ? "kept" : "absent", sim->p.Janc ? "kept" : "absent");
    double worst = 0.0;
    for (int q = 0; q < n && form != MPMC_FBAR_OFF; ++q) {
      const double e = fabs(projected_at(sim, xn, q) - sim->p.Jbar[q]);
      worst = e > worst ? e : worst;
    }
    if (!(worst <= 1e-13))
      fail_msg("form %d after form %d: Jbar differs from the projection at x^n by %.3g", form,
               f ? forms[f - 1] : MPMC_FBAR_OFF, worst);
  }
  free(xn);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

/* F-bar switched off and on again starts from the points' J, the Jacobian the material state
 * has after the steps without F-bar: the first step of Algorithm 1 then scatters
 * Jbar^n dJ = J^n dJ, the total form's J^{n+1} to the bit, and both forms give the same step.
 * (A Jbar kept from before the switch off, behind by the slump's volume change since, gave the
 * two forms different steps.) */
static void test_switch_on_again(void **state) {
  (void)state;
  double *jb[2] = {NULL, NULL}, *xs[2] = {NULL, NULL}, *ss[2] = {NULL, NULL}, dt = 0.0;
  int n = 0;
  for (int k = 0; k < 2; ++k) {
    mpmc_context ctx;
    TCALL(mpmc_context_create(&ctx));
    test_ctx = ctx;
    mpmc_sim sim = slump(ctx, 2, MPMC_BASIS_BSPLINE2, MPMC_FBAR_PAPER, 0, 0, SLUMP_HENCKY);
    if (k == 0) TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
    for (int s = 0; s < 3; ++s) TCALL(mpmc_sim_step(sim, dt));
    TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_OFF));
    for (int s = 0; s < 30; ++s) TCALL(mpmc_sim_step(sim, dt));
    TCALL(mpmc_sim_set_fbar(sim, k ? MPMC_FBAR_TOTAL : MPMC_FBAR_PAPER));
    TCALL(mpmc_sim_step(sim, dt));
    n = sim->p.n;
    jb[k] = malloc(sizeof(double) * (size_t)n);
    xs[k] = malloc(sizeof(double) * 2 * (size_t)n);
    ss[k] = malloc(sizeof(double) * 6 * (size_t)n);
    assert_true(jb[k] && xs[k] && ss[k]);
    memcpy(jb[k], sim->p.Jbar, sizeof(double) * (size_t)n);
    memcpy(xs[k], sim->p.x, sizeof(double) * 2 * (size_t)n);
    memcpy(ss[k], sim->p.stress, sizeof(double) * 6 * (size_t)n);
    mpmc_sim_destroy(&sim);
    mpmc_context_destroy(&ctx);
    test_ctx = NULL;
  }
  double dj = 0.0, ds = 0.0, smax = 0.0;
  for (int q = 0; q < n; ++q) dj = fmax(dj, fabs(jb[0][q] - jb[1][q]));
  for (int i = 0; i < 6 * n; ++i) {
    ds = fmax(ds, fabs(ss[0][i] - ss[1][i]));
    smax = fmax(smax, fabs(ss[1][i]));
  }
  if (!(dj == 0.0) || !(ds == 0.0) || memcmp(xs[0], xs[1], sizeof(double) * 2 * (size_t)n))
    fail_msg("F-bar switched on again: Algorithm 1's step differs from the total form's (Jbar "
             "by up to %.3g, stress by %.3g of %.3g): it did not start from J", dj, ds, smax);
  for (int k = 0; k < 2; ++k) free(jb[k]), free(xs[k]), free(ss[k]);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_switch_on_again),
      cmocka_unit_test(test_homogeneous),
      cmocka_unit_test(test_checkerboard),
      cmocka_unit_test(test_nodal_mode),
      cmocka_unit_test(test_fb_cleared),
      cmocka_unit_test(test_row_ranges),
      cmocka_unit_test(test_row_ranges_mirrors),
      cmocka_unit_test(test_deferred_gather),
      cmocka_unit_test(test_positions_held),
      cmocka_unit_test(test_gather_at_xn),
      cmocka_unit_test(test_kept_fields),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
