/* Rigid-body API (issue 8): bad arguments are refused with a message naming the parameter;
 * a body moves by v dt every step; removed bodies are gone; a point left inside a body
 * stops the next step with the point and the body named. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

#define EXPECT_ERR(expr, code, text)                                                        \
  do {                                                                                      \
    const int e_ = (expr);                                                                  \
    const char *m_ = mpmc_context_last_error(ctx);                                          \
    if (e_ != (code) || !strstr(m_, text))                                                  \
      fail_msg("%s -> %d '%s', expected %d with '%s'", #expr, e_, m_, (int)(code), text);  \
  } while (0)

static mpmc_sim make(mpmc_context *ctx, int dim) {
  mpmc_sim sim;
  TCALL(mpmc_context_create(ctx));
  test_ctx = *ctx;
  TCALL(mpmc_sim_create(*ctx, dim, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.1));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, 1e4, 0.3, 1.0, &mat));
  double *x, *vol;
  const double plo[3] = {0.2, 0.2, 0.2}, phi[3] = {0.4, 0.4, 0.4};
  const int n = test_lattice(dim, plo, phi, 0.1, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  free(x);
  free(vol);
  return sim;
}

static void test_bad_arguments(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim = make(&ctx, 2);
  const double lo[2] = {0.6, 0.6}, hi[2] = {0.8, 0.5}, ok_hi[2] = {0.8, 0.9};
  int id;
  EXPECT_ERR(mpmc_sim_add_rigid_box(sim, lo, hi, 0.0, &id), MPMC_ERR_ARG, "axis 1: hi = 0.5 must exceed lo = 0.6");
  EXPECT_ERR(mpmc_sim_add_rigid_box(sim, NULL, hi, 0.0, &id), MPMC_ERR_ARG, "lo/hi arrays are NULL");
  EXPECT_ERR(mpmc_sim_add_rigid_box(sim, lo, ok_hi, -0.1, &id), MPMC_ERR_ARG, "friction coefficient mu = -0.1");
  EXPECT_ERR(mpmc_sim_add_rigid_box(sim, lo, ok_hi, NAN, &id), MPMC_ERR_ARG, "friction coefficient mu = nan");
  const double two[4] = {0, 0, 1, 1};
  EXPECT_ERR(mpmc_sim_add_rigid_polygon(sim, 2, two, 0.0, &id), MPMC_ERR_ARG, "nvert >= 3 vertices (got 2)");
  const double line[6] = {0, 0, 1, 1, 2, 2};
  EXPECT_ERR(mpmc_sim_add_rigid_polygon(sim, 3, line, 0.0, &id), MPMC_ERR_ARG, "zero area");
  const double bow[8] = {0, 0, 2, 2, 2, 0, 0, 1};
  EXPECT_ERR(mpmc_sim_add_rigid_polygon(sim, 4, bow, 0.0, &id), MPMC_ERR_ARG, "not simple");
  const double dup[8] = {0, 0, 1, 0, 1, 0, 0, 1};
  EXPECT_ERR(mpmc_sim_add_rigid_polygon(sim, 4, dup, 0.0, &id), MPMC_ERR_ARG, "vertices 1 and 2 coincide");
  const double inf[6] = {0, 0, INFINITY, 0, 0, 1};
  EXPECT_ERR(mpmc_sim_add_rigid_polygon(sim, 3, inf, 0.0, &id), MPMC_ERR_ARG, "vertex 1 = (inf, 0) is not finite");
  EXPECT_ERR(mpmc_sim_set_contact_params(sim, -1.0, 0.0), MPMC_ERR_ARG, "barrier range dhat = -1");
  EXPECT_ERR(mpmc_sim_set_contact_params(sim, 0.0, INFINITY), MPMC_ERR_ARG, "barrier stiffness kappa = inf");
  const double v[2] = {0, 1};
  EXPECT_ERR(mpmc_sim_set_rigid_velocity(sim, 0, v), MPMC_ERR_ARG, "rigid body id 0 does not exist");
  TCALL(mpmc_sim_add_rigid_box(sim, lo, ok_hi, 0.0, &id));
  assert_int_equal(id, 0);
  const double vnan[2] = {0, NAN};
  EXPECT_ERR(mpmc_sim_set_rigid_velocity(sim, id, vnan), MPMC_ERR_ARG, "velocity component 1 = nan");
  EXPECT_ERR(mpmc_sim_get_rigid_reaction(sim, 1, NULL), MPMC_ERR_ARG, "rigid body id 1 does not exist");
  EXPECT_ERR(mpmc_sim_get_rigid_reaction(sim, id, NULL), MPMC_ERR_ARG, "reaction array is NULL");
  TCALL(mpmc_sim_remove_rigid(sim, id));
  double off[2];
  EXPECT_ERR(mpmc_sim_get_rigid_offset(sim, id, off), MPMC_ERR_ARG, "was removed");
  EXPECT_ERR(mpmc_sim_remove_rigid(sim, id), MPMC_ERR_ARG, "rigid body id 0 does not exist or was removed");
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);

  sim = make(&ctx, 3);
  const double tri[6] = {0, 0, 1, 0, 0, 1};
  EXPECT_ERR(mpmc_sim_add_rigid_polygon(sim, 3, tri, 0.0, &id), MPMC_ERR_ARG, "polygons are 2D only");
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

/* the body moves by v dt per step (velocity changed between steps), no contact */
static void test_motion(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim = make(&ctx, 3);
  const double lo[3] = {0.7, 0.7, 0.7}, hi[3] = {0.9, 0.9, 0.9};
  int a, b;
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, 0.5, &a));
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, 0.5, &b));
  const double va[3] = {0.01, -0.02, 0.03}, va2[3] = {0.0, 0.0, -0.05};
  TCALL(mpmc_sim_set_rigid_velocity(sim, a, va));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 10; ++s) TCALL(mpmc_sim_step(sim, dt));
  TCALL(mpmc_sim_set_rigid_velocity(sim, a, va2));
  for (int s = 0; s < 5; ++s) TCALL(mpmc_sim_step(sim, dt));
  double off[3], offb[3], r[3];
  TCALL(mpmc_sim_get_rigid_offset(sim, a, off));
  TCALL(mpmc_sim_get_rigid_offset(sim, b, offb));
  for (int k = 0; k < 3; ++k) {
    const double want = 10 * dt * va[k] + 5 * dt * va2[k];
    if (fabs(off[k] - want) > 1e-12 * (fabs(want) + dt) || offb[k] != 0.0)
      fail_msg("offset %d: body a %.12g (expected %.12g), body b %g (expected 0)", k, off[k],
               want, offb[k]);
  }
  TCALL(mpmc_sim_get_rigid_reaction(sim, a, r));
  if (r[0] != 0 || r[1] != 0 || r[2] != 0)
    fail_msg("reaction without contact (%g, %g, %g), expected 0", r[0], r[1], r[2]);
  double gap;
  int pt;
  TCALL(mpmc_sim_get_rigid_gap(sim, b, &gap, &pt));
  /* nearest points: the lattice corner (0.375, 0.375, 0.375) to the corner (0.7, 0.7, 0.7) */
  if (fabs(gap - sqrt(3.0) * 0.325) > 1e-9) fail_msg("gap %.12g, expected %.12g", gap, sqrt(3.0) * 0.325);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

/* a body placed over points: the step refuses to start and names point and body */
static void test_point_inside(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim = make(&ctx, 2);
  const double lo[2] = {0.3, 0.3}, hi[2] = {0.9, 0.9};
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, 0.0, NULL));
  double dt, dt0;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  /* the points inside do not shrink the step: the step names them instead */
  TCALL(mpmc_sim_remove_rigid(sim, 0));
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt0));
  if (dt < 0.5 * dt0) fail_msg("stable dt %g with points inside the body, %g without it", dt, dt0);
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, 0.0, NULL));
  EXPECT_ERR(mpmc_sim_step(sim, dt), MPMC_ERR_NUMERIC, "is inside rigid body 1");
  if (!strstr(mpmc_context_last_error(ctx), "point 10 at (0.325, 0.325, 0)"))
    fail_msg("message '%s' does not name the first point inside, 10 at (0.325, 0.325)",
             mpmc_context_last_error(ctx));
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_arguments),
      cmocka_unit_test(test_motion),
      cmocka_unit_test(test_point_inside),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
