/* Seeding from gmsh (issue 4).  Expected numbers come from the geometry: Cook's membrane
 * (area 48 * (44 + 16) / 2 = 1440 m^2) seeded 2x2 per 1 m cell gives the paper's 5,776
 * points; its clamped edge (44 m) holds 44 / 0.5 = 88 points of the first column, its
 * traction edge (16 m) 32, and the tip (48, 60) is nearest to the lattice point
 * (47.75, 59.75).  Quadrature volumes sum to the mesh area to round-off.  The 2D slope's
 * area is 5 * 9.95 + 5 * 5 / 2 = 62.25 m^2.  Seeding leaves the caller's OpenMP thread count
 * as it was (gmsh sets its own on initialising). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>
#include <omp.h>

#include "test_util.h"
#include "mpmc_gmsh.h"

#define MESH(name) MPMC_SOURCE_DIR "/meshes/" name

static mpmc_context ctx;

static mpmc_sim make(int dim, const double *lo, const double *hi, double h, int *mat) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 70, 0.499, 1, mat));
  return sim;
}

static double total_volume(mpmc_sim sim, int first, int count) {
  double *v;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VOLUME0, &v, NULL));
  double s = 0;
  for (int q = first; q < first + count; ++q) s += v[q];
  return s;
}

static int set_size(mpmc_sim sim, const char *name, const int **idx) {
  int id, n;
  TCALL(mpmc_sim_find_particle_set(sim, name, &id));
  TCALL(mpmc_sim_get_particle_set(sim, id, NULL, &n, idx));
  return n;
}

static void test_cook_lattice(void **state) {
  (void)state;
  int mat, first, count;
  const double lo[2] = {0, 0}, hi[2] = {50, 62};
  mpmc_sim sim = make(2, lo, hi, 1.0, &mat);
  TCALL(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "membrane", MPMC_SEED_LATTICE, 2, mat,
                       &first, &count));
  if (count != 5776) fail_msg("Cook's membrane 2x2 per 1 m cell: expected 5776 points, got %d", count);
  const double v = total_volume(sim, first, count);
  if (fabs(v - 5776 * 0.25) > 1e-9) fail_msg("expected volume %g, got %g", 5776 * 0.25, v);
  const int *idx;
  double *x;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
  int n = set_size(sim, "clamp", &idx);
  if (n != 88) fail_msg("expected 88 points along the clamped edge, got %d", n);
  for (int i = 0; i < n; ++i)
    if (fabs(x[2 * idx[i]] - 0.25) > 1e-12) fail_msg("clamp point at x = %g, expected 0.25", x[2 * idx[i]]);
  n = set_size(sim, "traction_edge", &idx);
  if (n != 32) fail_msg("expected 32 points along the traction edge, got %d", n);
  n = set_size(sim, "tip", &idx);
  assert_int_equal(n, 1);
  if (fabs(x[2 * idx[0]] - 47.75) > 1e-12 || fabs(x[2 * idx[0] + 1] - 59.75) > 1e-12)
    fail_msg("expected the tip point at (47.75, 59.75), got (%g, %g)", x[2 * idx[0]], x[2 * idx[0] + 1]);
  mpmc_sim_destroy(&sim);
}

static void test_quadrature(void **state) {
  (void)state;
  int mat, first, count;
  const double lo[2] = {0, 0}, hi[2] = {50, 62};
  mpmc_sim sim = make(2, lo, hi, 1.0, &mat);
  TCALL(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "membrane", MPMC_SEED_QUADRATURE, 2, mat,
                       &first, &count));
  double v = total_volume(sim, first, count);
  if (fabs(v - 1440.0) > 1e-12 * 1440) fail_msg("quadrature: expected volume 1440, got %.17g", v);
  mpmc_sim_destroy(&sim);
  /* the slope: quadrature exact, lattice within its resolution */
  const double slo[2] = {0, 0}, shi[2] = {56, 6};
  sim = make(2, slo, shi, 0.5, &mat);
  TCALL(mpmc_seed_gmsh(sim, MESH("slope_2d.geo"), "soil", MPMC_SEED_QUADRATURE, 3, mat, &first,
                       &count));
  v = total_volume(sim, first, count);
  if (fabs(v - 62.25) > 1e-12 * 62.25) fail_msg("slope quadrature: expected 62.25, got %.17g", v);
  TCALL(mpmc_seed_gmsh(sim, MESH("slope_2d.geo"), "soil", MPMC_SEED_LATTICE, 2, mat, &first,
                       &count));
  v = total_volume(sim, first, count);
  /* only the 45-degree face (7.07 m) is off the lattice: error below its length times the
   * spacing (0.25 m) */
  if (fabs(v - 62.25) > 7.08 * 0.25) fail_msg("slope lattice: expected 62.25 +- 1.77, got %g", v);
  const int *idx;
  int n = set_size(sim, "base", &idx);
  /* the base (14.95 m) under the 0.25 m lattice: the points of the first row, x < 14.95 */
  if (n < 58 || n > 60) fail_msg("expected 58-60 points along the base, got %d", n);
  assert_int_equal(set_size(sim, "toe", &idx), 1);
  mpmc_sim_destroy(&sim);
}

static void write_file(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static void check_message(int code, int expected, const char *needle) {
  if (code != expected)
    fail_msg("expected error %d, got %d (%s)", expected, code, mpmc_context_last_error(ctx));
  if (!strstr(mpmc_context_last_error(ctx), needle))
    fail_msg("expected the message to contain '%s', got '%s'", needle, mpmc_context_last_error(ctx));
}

static void test_bad_input(void **state) {
  (void)state;
  int mat, n;
  const double lo[2] = {0, 0}, hi[2] = {50, 62};
  mpmc_sim sim = make(2, lo, hi, 1.0, &mat);
  check_message(mpmc_seed_gmsh(sim, MPMC_BINARY_DIR "/no-such-file.geo", "membrane", 0, 2, mat,
                               NULL, NULL),
                MPMC_ERR_IO, "no-such-file.geo");
  const char *bad = MPMC_BINARY_DIR "/t103-syntax.geo";
  write_file(bad, "Point(1) = {0, 0, 0, 1};\nPoint(2) = {1, 0, 0, 1}\nLine(1) = {1, 2;\n");
  check_message(mpmc_seed_gmsh(sim, bad, "x", 0, 2, mat, NULL, NULL), MPMC_ERR_FORMAT, "line 3");
  const char *empty = MPMC_BINARY_DIR "/t103-empty.geo";
  const char *tri = "Point(1) = {0, 0, 0, 1}; Point(2) = {1, 0, 0, 1}; Point(3) = {1, 1, 0, 1};\n"
                    "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 1};\n"
                    "Curve Loop(1) = {1, 2, 3}; Plane Surface(1) = {1};\n"
                    "Physical Surface(\"tri\") = {1};\n";
  char text[1024];
  snprintf(text, sizeof text, "%sPhysical Surface(\"hollow\") = {};\n", tri);
  write_file(empty, text);
  check_message(mpmc_seed_gmsh(sim, empty, "hollow", 0, 2, mat, NULL, NULL), MPMC_ERR_FORMAT,
                "'hollow' (dimension 2)");
  snprintf(text, sizeof text, "%sPhysical Curve(\"nocurve\") = {42};\n", tri);
  write_file(empty, text);
  check_message(mpmc_seed_gmsh(sim, empty, "tri", 0, 2, mat, NULL, NULL), MPMC_ERR_FORMAT,
                "'nocurve' (dimension 1) in");
  check_message(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "soil", 0, 2, mat, NULL, NULL),
                MPMC_ERR_ARG, "group named 'soil' (it has: membrane)");
  TCALL(mpmc_sim_get_num_particles(sim, &n));
  assert_int_equal(n, 0);
  mpmc_sim_destroy(&sim);
  /* a grid that does not cover the membrane */
  const double shi[2] = {40, 62};
  sim = make(2, lo, shi, 1.0, &mat);
  check_message(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "membrane", 0, 2, mat, NULL, NULL),
                MPMC_ERR_OUTSIDE, "outside the grid box");
  check_message(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "membrane", 1, 2, mat, NULL, NULL),
                MPMC_ERR_OUTSIDE, "outside the grid box");
  TCALL(mpmc_sim_get_num_particles(sim, &n));
  assert_int_equal(n, 0);
  mpmc_sim_destroy(&sim);
  remove(bad);
  remove(empty);
}

/* gmshInitialize and gmshFinalize set OpenMP's threads to gmsh's General.NumThreads (1): a
 * scene seeded from gmsh then stepped on one thread whatever the cores or OMP_NUM_THREADS. */
static void test_threads_kept(void **state) {
  (void)state;
  int mat, first, count;
  const double lo[2] = {0, 0}, hi[2] = {50, 62};
  const int before = omp_get_max_threads();
  omp_set_num_threads(3);
  mpmc_sim sim = make(2, lo, hi, 1.0, &mat);
  TCALL(mpmc_seed_gmsh(sim, MESH("cook_membrane.geo"), "membrane", MPMC_SEED_LATTICE, 1, mat,
                       &first, &count));
  const int after = omp_get_max_threads();
  omp_set_num_threads(before);
  mpmc_sim_destroy(&sim);
  if (after != 3) fail_msg("OpenMP threads 3 before seeding from gmsh, %d after", after);
}

int main(void) {
  mpmc_context_create(&ctx);
  test_ctx = ctx;
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_cook_lattice),
                                     cmocka_unit_test(test_quadrature),
                                     cmocka_unit_test(test_bad_input),
                                     cmocka_unit_test(test_threads_kept)};
  const int r = cmocka_run_group_tests(tests, NULL, NULL);
  mpmc_context_destroy(&ctx);
  return r;
}
