/* Lattice seeding of boxes and polygons (issue 4).  Expected counts and volumes come from
 * geometry: a grid-aligned region gets exactly its area back; Cook's membrane
 * (corners (0,0), (48,44), (48,60), (0,44)) seeded 2x2 per 1 m cell gives the paper's 5,776
 * points (5,744 strictly inside + 32 on the top edge y = 44 + x/3, counted by hand from
 * 3n - m = 263 for lattice indices m, n) and 23,072 at 0.5 m cells (paper section 4.1). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

static void make(int dim, const double *lo, const double *hi, double h, mpmc_context *ctx,
                 mpmc_sim *sim, int *mat) {
  TCALL(mpmc_context_create(ctx));
  test_ctx = *ctx;
  TCALL(mpmc_sim_create(*ctx, dim, sim));
  TCALL(mpmc_sim_set_grid(*sim, lo, hi, h));
  TCALL(mpmc_sim_add_material_neo_hookean(*sim, 70, 0.3, 1, mat));
}

static void destroy(mpmc_context *ctx, mpmc_sim *sim) {
  mpmc_sim_destroy(sim);
  mpmc_context_destroy(ctx);
  test_ctx = NULL;
}

static double total_volume(mpmc_sim sim, int first, int count) {
  double *v;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VOLUME0, &v, NULL));
  double s = 0;
  for (int q = first; q < first + count; ++q) s += v[q];
  return s;
}

static void test_box(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, first, count;
  const double lo[3] = {0, 0, 0}, hi[3] = {4, 3, 2};
  make(3, lo, hi, 0.5, &ctx, &sim, &mat);
  const double blo[3] = {1, 0.5, 0}, bhi[3] = {3, 2, 1};
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, &first, &count));
  /* 4 x 3 x 2 cells of 0.5 m, 8 points each */
  assert_int_equal(first, 0);
  assert_int_equal(count, 4 * 3 * 2 * 8);
  const double vol = total_volume(sim, first, count);
  if (fabs(vol - 2.0 * 1.5 * 1.0) > 1e-12) fail_msg("expected volume 3, got %.17g", vol);
  double *x;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
  /* the first point sits a quarter cell inside the box's corner */
  if (fabs(x[0] - 1.125) > 1e-14 || fabs(x[1] - 0.625) > 1e-14 || fabs(x[2] - 0.125) > 1e-14)
    fail_msg("expected the first point at (1.125, 0.625, 0.125), got (%g, %g, %g)", x[0], x[1],
             x[2]);
  /* a second box is appended */
  TCALL(mpmc_sim_seed_box(sim, lo, hi, 1, mat, &first, &count));
  assert_int_equal(first, 4 * 3 * 2 * 8);
  assert_int_equal(count, 8 * 6 * 4);
  destroy(&ctx, &sim);
}

static void cook_count(double h, int expected) {
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, count;
  const double lo[2] = {0, 0}, hi[2] = {48, 60};
  make(2, lo, hi, h, &ctx, &sim, &mat);
  const double cook[8] = {0, 0, 48, 44, 48, 60, 0, 44};
  TCALL(mpmc_sim_seed_polygon(sim, 4, cook, 2, mat, NULL, &count));
  if (count != expected) fail_msg("Cook's membrane, h = %g: expected %d points, got %d", h, expected, count);
  /* the area is 1440 m^2; the lattice carries h^2/4 per point */
  const double vol = total_volume(sim, 0, count);
  if (fabs(vol - expected * h * h / 4) > 1e-9) fail_msg("expected volume %g, got %g", expected * h * h / 4, vol);
  destroy(&ctx, &sim);
}

static void test_cook_polygon(void **state) {
  (void)state;
  cook_count(1.0, 5776);
  cook_count(0.5, 23072);
}

static void test_polygon_orientation_and_area(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, c1, c2;
  const double lo[2] = {0, 0}, hi[2] = {10, 10};
  make(2, lo, hi, 0.5, &ctx, &sim, &mat);
  /* a grid-aligned L shape, area 3*1 + 1*2 = 5, clockwise and counter-clockwise */
  const double ccw[12] = {1, 1, 4, 1, 4, 2, 2, 2, 2, 4, 1, 4};
  double cw[12];
  for (int i = 0; i < 6; ++i) cw[2 * i] = ccw[2 * (5 - i)], cw[2 * i + 1] = ccw[2 * (5 - i) + 1];
  TCALL(mpmc_sim_seed_polygon(sim, 6, ccw, 3, mat, NULL, &c1));
  TCALL(mpmc_sim_seed_polygon(sim, 6, cw, 3, mat, NULL, &c2));
  assert_int_equal(c1, c2);
  /* points: 5 m^2 / (0.5/3)^2 = 180 */
  assert_int_equal(c1, 180);
  const double v = total_volume(sim, 0, c1);
  if (fabs(v - 5.0) > 1e-12) fail_msg("expected the L shape's area 5, got %.17g", v);
  /* a triangle not aligned with the grid: the area converges with the lattice spacing */
  const double tri[6] = {0.3, 0.2, 9.7, 0.9, 4.1, 8.8}; /* area 40.1 */
  int first, c3;
  TCALL(mpmc_sim_seed_polygon(sim, 3, tri, 4, mat, &first, &c3));
  const double a = total_volume(sim, first, c3), exact = 0.5 * fabs((9.7 - 0.3) * (8.8 - 0.2) - (4.1 - 0.3) * (0.9 - 0.2));
  /* error bounded by the perimeter (~27 m) times half the spacing (1/16 m) */
  if (fabs(a - exact) > 27 * 0.0625) fail_msg("expected area %g within 1.7, got %g", exact, a);
  destroy(&ctx, &sim);
}

static void check_message(mpmc_context ctx, int code, int expected, const char *needle) {
  if (code != expected)
    fail_msg("expected error %d, got %d (%s)", expected, code, mpmc_context_last_error(ctx));
  if (!strstr(mpmc_context_last_error(ctx), needle))
    fail_msg("expected the message to contain '%s', got '%s'", needle, mpmc_context_last_error(ctx));
}

static void test_bad_input(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, n;
  const double lo[2] = {0, 0}, hi[2] = {4, 4};
  make(2, lo, hi, 1.0, &ctx, &sim, &mat);
  const double out_lo[2] = {1, 1}, out_hi[2] = {5, 2};
  check_message(ctx, mpmc_sim_seed_box(sim, out_lo, out_hi, 2, mat, NULL, NULL), MPMC_ERR_OUTSIDE,
                "outside the grid box");
  check_message(ctx, mpmc_sim_seed_box(sim, lo, hi, 0, mat, NULL, NULL), MPMC_ERR_ARG, "ppc = 0");
  check_message(ctx, mpmc_sim_seed_box(sim, lo, hi, 2, 7, NULL, NULL), MPMC_ERR_ARG,
                "material id 7");
  const double bow[8] = {0, 0, 2, 2, 2, 0, 0, 2}; /* self-intersecting */
  check_message(ctx, mpmc_sim_seed_polygon(sim, 4, bow, 2, mat, NULL, NULL), MPMC_ERR_ARG,
                "not a simple polygon");
  const double line[6] = {0, 0, 1, 1, 2, 2};
  check_message(ctx, mpmc_sim_seed_polygon(sim, 3, line, 2, mat, NULL, NULL), MPMC_ERR_ARG,
                "enclose no area");
  const double sliver[6] = {1.01, 1.01, 1.2, 1.01, 1.01, 1.2}; /* between lattice points */
  check_message(ctx, mpmc_sim_seed_polygon(sim, 3, sliver, 1, mat, NULL, NULL), MPMC_ERR_ARG,
                "no lattice point");
  TCALL(mpmc_sim_get_num_particles(sim, &n));
  assert_int_equal(n, 0); /* nothing was added by the failures */
  destroy(&ctx, &sim);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_box), cmocka_unit_test(test_cook_polygon),
      cmocka_unit_test(test_polygon_orientation_and_area), cmocka_unit_test(test_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
