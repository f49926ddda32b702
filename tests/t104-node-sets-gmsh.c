/* Node sets (issue 4): gmsh boundary groups become sets of grid nodes, walls act on them, and
 * they survive checkpoints.  Expected sets come from the geometry: Cook's membrane on 1 m
 * cells has its clamped edge x = 0, y = 0..44 on 45 nodes and its traction edge x = 48,
 * y = 44..60 on 17; the tip (48, 60) is a node.  A slanted edge's set is checked against
 * the definition (node within h/2 |n|_1 of the edge) by brute force over every node. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "test_util.h"
#include "mpmc_gmsh.h"

#define MESH(name) MPMC_SOURCE_DIR "/meshes/" name

static mpmc_context ctx;

static mpmc_sim cook(int *count) {
  mpmc_sim sim;
  int mat;
  const double lo[2] = {0, 0}, hi[2] = {50, 62};
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 1.0));
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_UGIMP));
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 70, 0.3, 1, &mat));
  TCALL(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "membrane", MPMC_SEED_LATTICE, 2, mat,
                       NULL, count));
  return sim;
}

static int node_set(mpmc_sim sim, const char *name, const int **ijk) {
  int id, n;
  TCALL(mpmc_sim_find_node_set(sim, name, &id));
  TCALL(mpmc_sim_get_node_set(sim, id, NULL, &n, ijk));
  return n;
}

static void test_cook_node_sets(void **state) {
  (void)state;
  int count;
  mpmc_sim sim = cook(&count);
  const int *ijk;
  int n = node_set(sim, "clamp", &ijk);
  if (n != 45) fail_msg("clamp: expected the 45 nodes x = 0, y = 0..44, got %d", n);
  for (int k = 0; k < n; ++k)
    if (ijk[2 * k] != 0 || ijk[2 * k + 1] < 0 || ijk[2 * k + 1] > 44)
      fail_msg("clamp node (%d, %d) is not on x = 0, y = 0..44", ijk[2 * k], ijk[2 * k + 1]);
  n = node_set(sim, "traction_edge", &ijk);
  if (n != 17) fail_msg("traction_edge: expected the 17 nodes x = 48, y = 44..60, got %d", n);
  for (int k = 0; k < n; ++k)
    if (ijk[2 * k] != 48 || ijk[2 * k + 1] < 44 || ijk[2 * k + 1] > 60)
      fail_msg("traction_edge node (%d, %d) off x = 48, y = 44..60", ijk[2 * k], ijk[2 * k + 1]);
  n = node_set(sim, "tip", &ijk);
  assert_int_equal(n, 1);
  assert_int_equal(ijk[0], 48);
  assert_int_equal(ijk[1], 60);
  mpmc_sim_destroy(&sim);
}

/* A triangle with a 45-degree hypotenuse (a physical curve): every node within
 * h/2 * (|nx| + |ny|) = h / sqrt(2) of the segment, and no other, is in the set. */
static void test_slanted_edge(void **state) {
  (void)state;
  char dir[] = "/tmp/mpmc-t104-XXXXXX";
  assert_non_null(mkdtemp(dir));
  char geo[300];
  snprintf(geo, sizeof geo, "%s/tri.geo", dir);
  FILE *f = fopen(geo, "w");
  assert_non_null(f);
  fputs("Point(1) = {0.3, 0.2, 0, 1};\nPoint(2) = {6.4, 0.2, 0, 1};\nPoint(3) = {0.3, 6.3, 0, 1};\n"
        "Line(1) = {1, 2};\nLine(2) = {2, 3};\nLine(3) = {3, 1};\nCurve Loop(1) = {1, 2, 3};\n"
        "Plane Surface(1) = {1};\nPhysical Surface(\"tri\") = {1};\nPhysical Curve(\"hyp\") = {2};\n",
        f);
  fclose(f);
  mpmc_sim sim;
  int mat;
  const double lo[2] = {0, 0}, hi[2] = {8, 8}, h = 0.5;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 70, 0.3, 1, &mat));
  TCALL(mpmc_seed_gmsh(sim, geo, "tri", MPMC_SEED_LATTICE, 2, mat, NULL, NULL));
  const int *ijk;
  const int n = node_set(sim, "hyp", &ijk);
  const double a[2] = {6.4, 0.2}, b[2] = {0.3, 6.3}, tol = h / sqrt(2.0);
  int expect = 0;
  for (int j = 0; j <= 16; ++j)
    for (int i = 0; i <= 16; ++i) {
      const double px = i * h, py = j * h, ex = b[0] - a[0], ey = b[1] - a[1];
      double t = ((px - a[0]) * ex + (py - a[1]) * ey) / (ex * ex + ey * ey);
      t = t < 0 ? 0 : (t > 1 ? 1 : t);
      const double dist = hypot(px - a[0] - t * ex, py - a[1] - t * ey);
      int in = 0;
      for (int k = 0; k < n; ++k) in |= ijk[2 * k] == i && ijk[2 * k + 1] == j;
      if (fabs(dist - tol) < 1e-9 * h) continue; /* on the band's edge: either way */
      if ((dist < tol) != in)
        fail_msg("node (%d, %d) at distance %g (band %g) is %s the set", i, j, dist, tol,
                 in ? "wrongly in" : "missing from");
      expect += dist < tol;
    }
  if (n < expect || expect < 20) fail_msg("hyp: %d nodes for %d expected", n, expect);
  mpmc_sim_destroy(&sim);
  remove(geo);
  rmdir(dir);
}

/* A fixed wall on the node set "clamp" acts exactly like a fixed box on the same nodes. */
static void test_wall_on_node_set(void **state) {
  (void)state;
  int count;
  mpmc_sim a = cook(&count), b = cook(&count);
  int set, wa, wb;
  TCALL(mpmc_sim_find_node_set(a, "clamp", &set));
  TCALL(mpmc_sim_add_wall_nodes(a, set, MPMC_WALL_FIXED, 0, -1, &wa));
  const double blo[2] = {0, 0}, bhi[2] = {0, 44};
  TCALL(mpmc_sim_add_wall_box(b, blo, bhi, MPMC_WALL_FIXED, 0, -1, &wb));
  const double g[2] = {0, -1};
  TCALL(mpmc_sim_set_gravity(a, g));
  TCALL(mpmc_sim_set_gravity(b, g));
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.3, &dt));
  for (int s = 0; s < 40; ++s) {
    TCALL(mpmc_sim_step(a, dt));
    TCALL(mpmc_sim_step(b, dt));
  }
  double *xa, *xb;
  TCALL(mpmc_sim_get_field(a, MPMC_FIELD_POSITION, &xa, NULL));
  TCALL(mpmc_sim_get_field(b, MPMC_FIELD_POSITION, &xb, NULL));
  double moved = 0;
  for (int q = 0; q < 2 * count; ++q) {
    if (xa[q] != xb[q]) fail_msg("x[%d]: node-set wall %.17g, box wall %.17g", q, xa[q], xb[q]);
  }
  double *x0;
  TCALL(mpmc_sim_get_field(a, MPMC_FIELD_X0, &x0, NULL));
  for (int q = 0; q < 2 * count; ++q) moved = fmax(moved, fabs(xa[q] - x0[q]));
  if (!(moved > 1e-3)) fail_msg("the membrane did not move under gravity (%g m)", moved);
  (void)wa;
  (void)wb;
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
}

/* Node sets and walls on them are in the checkpoint; a restart continues bit for bit. */
static void test_checkpoint(void **state) {
  (void)state;
  int count, set;
  mpmc_sim a = cook(&count);
  TCALL(mpmc_sim_find_node_set(a, "clamp", &set));
  TCALL(mpmc_sim_add_wall_nodes(a, set, MPMC_WALL_FIXED, 0, -1, NULL));
  const double g[2] = {0, -1};
  TCALL(mpmc_sim_set_gravity(a, g));
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.3, &dt));
  for (int s = 0; s < 10; ++s) TCALL(mpmc_sim_step(a, dt));
  char path[] = "/tmp/mpmc-t104-ckpt-XXXXXX";
  const int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  TCALL(mpmc_sim_checkpoint_write(a, path, NULL));
  mpmc_sim b;
  TCALL(mpmc_sim_checkpoint_read(ctx, path, &b, NULL));
  remove(path);
  int na, nb;
  TCALL(mpmc_sim_get_num_node_sets(a, &na));
  TCALL(mpmc_sim_get_num_node_sets(b, &nb));
  assert_int_equal(na, nb);
  for (int k = 0; k < na; ++k) {
    const char *sa, *sb;
    const int *ia, *ib;
    int ma, mb;
    TCALL(mpmc_sim_get_node_set(a, k, &sa, &ma, &ia));
    TCALL(mpmc_sim_get_node_set(b, k, &sb, &mb, &ib));
    assert_string_equal(sa, sb);
    assert_int_equal(ma, mb);
    assert_memory_equal(ia, ib, sizeof(int) * 2 * (size_t)ma);
  }
  for (int s = 0; s < 10; ++s) {
    TCALL(mpmc_sim_step(a, dt));
    TCALL(mpmc_sim_step(b, dt));
  }
  double *xa, *xb;
  TCALL(mpmc_sim_get_field(a, MPMC_FIELD_POSITION, &xa, NULL));
  TCALL(mpmc_sim_get_field(b, MPMC_FIELD_POSITION, &xb, NULL));
  assert_memory_equal(xa, xb, sizeof(double) * 2 * (size_t)count);
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
}

static void expect(int code, int want, const char *needle) {
  if (code != want) fail_msg("expected error %d, got %d (%s)", want, code, mpmc_context_last_error(ctx));
  if (!strstr(mpmc_context_last_error(ctx), needle))
    fail_msg("message '%s' does not name '%s'", mpmc_context_last_error(ctx), needle);
}

static void test_api_errors(void **state) {
  (void)state;
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  const int one[3] = {0, 0, 0};
  expect(mpmc_sim_add_node_set(sim, "base", 1, one, NULL), MPMC_ERR_STATE, "set the grid");
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.5));
  const int bad[6] = {0, 0, 0, 4, 0, 3};
  expect(mpmc_sim_add_node_set(sim, "base", 2, bad, NULL), MPMC_ERR_ARG, "axis 2 outside [0, 2]");
  expect(mpmc_sim_add_node_set(sim, "", 1, one, NULL), MPMC_ERR_ARG, "name");
  expect(mpmc_sim_add_node_set(sim, "base", 1, NULL, NULL), MPMC_ERR_ARG, "ijk is NULL");
  int id, n;
  const int two[6] = {0, 0, 0, 4, 2, 2};
  TCALL(mpmc_sim_add_node_set(sim, "base", 2, two, &id));
  TCALL(mpmc_sim_add_node_set(sim, "base", 1, one, &n)); /* replaces */
  assert_int_equal(n, id);
  TCALL(mpmc_sim_get_num_node_sets(sim, &n));
  assert_int_equal(n, 1);
  expect(mpmc_sim_find_node_set(sim, "top", &id), MPMC_ERR_ARG, "no node set named 'top'");
  expect(mpmc_sim_get_node_set(sim, 3, NULL, NULL, NULL), MPMC_ERR_ARG, "node set id 3");
  expect(mpmc_sim_add_wall_nodes(sim, 1, MPMC_WALL_FIXED, 0, -1, NULL), MPMC_ERR_ARG, "node set id 1");
  expect(mpmc_sim_add_wall_nodes(sim, 0, 7, 0, -1, NULL), MPMC_ERR_ARG, "wall kind");
  expect(mpmc_sim_set_grid(sim, lo, hi, 0.25), MPMC_ERR_STATE, "before node sets");
  mpmc_sim_destroy(&sim);
}

int main(void) {
  mpmc_context_create(&ctx);
  test_ctx = ctx;
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_cook_node_sets),
                                     cmocka_unit_test(test_slanted_edge),
                                     cmocka_unit_test(test_wall_on_node_set),
                                     cmocka_unit_test(test_checkpoint),
                                     cmocka_unit_test(test_api_errors)};
  const int r = cmocka_run_group_tests(tests, NULL, NULL);
  mpmc_context_destroy(&ctx);
  return r;
}
