/* An elastic bar hits a rigid box (issue 8).  1D bar theory (nu = 0, slip walls above and
 * below): a bar of length L moving at v0 onto a rigid wall stays in contact for 2L/c,
 * pushes with rho c v0 H (per unit thickness) meanwhile and leaves at -v0.  No point may
 * ever be inside the box.  Frictionless; the box either stands still (the bar moves) or
 * moves (the bar rests), which must give the same contact force. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

static void run_impact(int moving_body, int basis, int fbar, double tol_v) {
  const double L = 1.0, Hb = 0.1, h = 0.05, E = 1.0e4, rho = 1.0, v0 = 1.0;
  const double c = sqrt(E / rho), x0 = 0.2;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double glo[2] = {0.0, 0.0}, ghi[2] = {1.6, Hb};
  TCALL(mpmc_sim_set_grid(sim, glo, ghi, h));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, 0.0, rho, &mat));
  double *x, *vol;
  const double plo[2] = {x0, 0.0}, phi[2] = {x0 + L, Hb};
  const int n = test_lattice(2, plo, phi, h, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 3, MPMC_WALL_SLIP, NULL));
  /* the box's face at x0: the first column of points sits at gap h/4 = dhat */
  const double blo[2] = {-1.0, -1.0}, bhi[2] = {x0, 1.0};
  int body;
  TCALL(mpmc_sim_add_rigid_box(sim, blo, bhi, 0.0, &body));
  double *v;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  if (moving_body) {
    const double vb[2] = {v0, 0.0};
    TCALL(mpmc_sim_set_rigid_velocity(sim, body, vb));
  } else {
    for (int q = 0; q < n; ++q) v[2 * q] = -v0;
  }
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  const double T = 2 * L / c; /* contact duration */
  const int nsteps = (int)ceil(1.5 * T / dt);
  /* contact time between the half-force crossings (the barrier's cushion delays the rise
   * and the fall alike), impulse, mean force in the middle of the contact */
  const double fexp = rho * c * v0 * Hb;
  double t_up = -1, t_down = -1, impulse = 0, fmid = 0, fprev = 0;
  int nmid = 0;
  for (int s = 0; s < nsteps; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    double r[2], t, gap;
    int pt;
    TCALL(mpmc_sim_get_rigid_reaction(sim, body, r));
    TCALL(mpmc_sim_get_time(sim, &t));
    TCALL(mpmc_sim_get_rigid_gap(sim, body, &gap, &pt));
    if (!(gap > 0)) fail_msg("step %d: point %d has gap %g, expected > 0", s, pt, gap);
    const double f = -r[0]; /* the bar pushes the box towards -x */
    impulse += f * dt;
    if (t_up < 0 && f >= 0.5 * fexp) t_up = t - dt * (f - 0.5 * fexp) / (f - fprev);
    if (t_up > 0 && t_down < 0 && f < 0.5 * fexp) t_down = t - dt * (0.5 * fexp - f) / (fprev - f);
    if (t > 0.25 * T && t < 0.75 * T) {
      fmid += f;
      nmid++;
    }
    fprev = f;
  }
  /* relative velocity after the impact: the bar leaves the box at v0 (less what stays in
   * the bar as vibration: a discrete bar is dispersive, F-bar smooths the wave front) */
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  double vm = 0;
  for (int q = 0; q < n; ++q) vm += v[2 * q];
  vm /= n;
  const double vrel = moving_body ? vm - v0 : vm;
  const double mass = rho * L * Hb, dur = t_down - t_up;
  fmid = nmid ? fmid / nmid : 0.0;
  if (vrel > 1.01 * v0 || vrel < (1 - tol_v) * v0 || fabs(dur - T) > 0.05 * T ||
      fabs(impulse - mass * (v0 + vrel)) > 0.01 * mass * v0 || fabs(fmid - fexp) > 0.05 * fexp)
    fail_msg("moving body %d basis %d fbar %d: rebound velocity %.4f (expected %.4f, at least "
             "%.4f), contact time %.5f (expected 2L/c = %.5f), impulse %.5f (expected m (v0 + "
             "rebound) = %.5f), mean force %.4f (expected rho c v0 H = %.4f)",
             moving_body, basis, fbar, vrel, v0, (1 - tol_v) * v0, dur, T, impulse,
             mass * (v0 + vrel), fmid, fexp);
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void test_bar_hits_box(void **state) {
  (void)state;
  run_impact(0, MPMC_BASIS_BSPLINE2, 0, 0.02);
}
static void test_box_hits_bar(void **state) {
  (void)state;
  run_impact(1, MPMC_BASIS_BSPLINE2, 0, 0.05); /* measured 0.974 v0: the bar crosses cells */
}
static void test_bar_hits_box_ugimp(void **state) {
  (void)state;
  run_impact(0, MPMC_BASIS_UGIMP, 1, 0.1); /* measured 0.93 v0 */
}

/* a body driven far too fast for a forced time step: the step that puts a point inside
 * it fails and says so */
static void test_penetration_guard(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double glo[2] = {0.0, 0.0}, ghi[2] = {1.0, 1.0};
  TCALL(mpmc_sim_set_grid(sim, glo, ghi, 0.1));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, 1e4, 0.3, 1.0, &mat));
  double *x, *vol;
  const double plo[2] = {0.3, 0.3}, phi[2] = {0.7, 0.7};
  const int n = test_lattice(2, plo, phi, 0.1, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  const double blo[2] = {0.2, 0.7}, bhi[2] = {0.8, 2.0};
  int body;
  TCALL(mpmc_sim_add_rigid_box(sim, blo, bhi, 0.0, &body));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.4, &dt));
  const double vb[2] = {0.0, -0.2 / dt}; /* 0.2 m (eight times dhat) a step */
  TCALL(mpmc_sim_set_rigid_velocity(sim, body, vb));
  int err = 0, s;
  for (s = 0; s < 5 && !err; ++s) err = mpmc_sim_step(sim, dt);
  assert_int_equal(err, MPMC_ERR_NUMERIC);
  assert_int_equal(s, 1);
  const char *msg = mpmc_context_last_error(ctx);
  if (!strstr(msg, "crossed into rigid body 0") || !strstr(msg, "gap"))
    fail_msg("message '%s' does not name the body and the gap", msg);
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bar_hits_box),
      cmocka_unit_test(test_box_hits_bar),
      cmocka_unit_test(test_bar_hits_box_ugimp),
      cmocka_unit_test(test_penetration_guard),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
