/* Vibrating bar (issue 2, test 4): L = 25, E = 100, nu = 0, rho = 1, fixed at x = 0, free at
 * x = L, v(x, 0) = v0 sin(pi x / 2L).  First mode: omega1 = (pi/2L) sqrt(E/rho), period
 * 10 s, tip amplitude v0/omega1 = 0.15915; the centre-of-mass velocity is
 * (2 v0/pi) cos(omega1 t).  Run as a thin plane-strain strip with slip walls.
 * The linear basis is left out: the free end's points cross into cells whose nodes carry
 * almost no mass (the cell-crossing instability that uGIMP and B-splines remove). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "test_util.h"

static void run_bar(int basis, int fbar, double *period, double *amp) {
  const double L = 25.0, E = 100.0, rho = 1.0, v0 = 0.1, h = 0.25;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0.0, 0.0}, hi[2] = {L + 2.0, 2 * h};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, 0.0, rho, &mat));
  double *x, *vol;
  const double plo[2] = {0.0, 0.0}, phi[2] = {L, 2 * h};
  const int n = test_lattice(2, plo, phi, h, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_FIXED, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 3, MPMC_WALL_SLIP, NULL));
  double *v, *xp;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  for (int q = 0; q < n; ++q) v[2 * q] = v0 * sin(M_PI * x[2 * q] / (2 * L));
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v));
  /* tip: the points in the last column */
  const double xtip0 = L - h / 4;
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  double vprev = 0.0, tprev = 0.0, crossings[4];
  int nc = 0;
  double umax = 0.0;
  const int nsteps = (int)ceil(15.0 / dt);
  for (int s = 0; s < nsteps && nc < 3; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    double t;
    TCALL(mpmc_sim_get_time(sim, &t));
    TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
    TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
    double mv = 0.0, utip = 0.0;
    int ntip = 0;
    for (int q = 0; q < n; ++q) {
      mv += v[2 * q];
      if (x[2 * q] > xtip0 - 1e-9) {
        utip += xp[2 * q] - x[2 * q];
        ntip++;
      }
    }
    mv /= n;
    utip /= ntip;
    if (fabs(utip) > umax) umax = fabs(utip);
    /* centre-of-mass velocity crosses zero at T/4, 3T/4, 5T/4 */
    if (s > 0 && ((vprev > 0) != (mv > 0))) crossings[nc++] = tprev + (t - tprev) * vprev / (vprev - mv);
    vprev = mv;
    tprev = t;
  }
  assert_int_equal(nc, 3);
  *period = crossings[2] - crossings[0];
  *amp = umax;
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void check(int basis, int fbar, double tol) {
  const double omega = M_PI / 50.0 * 10.0, T = 2 * M_PI / omega, A = 0.1 / omega;
  double period, amp;
  run_bar(basis, fbar, &period, &amp);
  const double ep = fabs(period - T) / T, ea = fabs(amp - A) / A;
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("bar basis %d fbar %d: period %.5f (error %.2f%%), tip amplitude %.5f (error %.2f%%)\n",
           basis, fbar, period, 100 * ep, amp, 100 * ea);
  if (ep > tol || ea > tol)
    fail_msg("basis %d fbar %d: period %.5f (expected %.5f, error %.2f%%), tip amplitude %.5f "
             "(expected %.5f, error %.2f%%), tolerance %.1f%%",
             basis, fbar, period, T, 100 * ep, amp, A, 100 * ea, 100 * tol);
}

static void test_bar_bspline2(void **state) {
  (void)state;
  check(MPMC_BASIS_BSPLINE2, 0, 0.02);
}
static void test_bar_bspline2_fbar(void **state) {
  (void)state;
  check(MPMC_BASIS_BSPLINE2, 1, 0.02);
}
static void test_bar_other_bases(void **state) {
  (void)state;
  check(MPMC_BASIS_UGIMP, 1, 0.02);
  check(MPMC_BASIS_BSPLINE3, 1, 0.02);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bar_bspline2),
      cmocka_unit_test(test_bar_bspline2_fbar),
      cmocka_unit_test(test_bar_other_bases),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
