/* Strip footing on Tresca soil at a coarse size (issue 8; the paper's section 4.2 at
 * h = B/10 on a 4B x 4B half model; bench/bench_footing.c runs the paper's sizes).
 * Prandtl: a strip footing on weightless Tresca soil fails at q = (2 + pi) su.
 * Hencky-J2, E = 1000 kPa, nu = 0.49, su = 0.1 kPa (kappa = sqrt(3) su, plane strain),
 * rho = 1000 kg/m^3, no gravity, 2x2 points per cell, dt = 0.4 h/c, local damping 0.002.
 * Half model: slip at x = 0 (symmetry) and x = 4B, fixed at y = 0; the footing is a rough
 * rigid box over x in [-B/2, B/2] on the surface, pushed down at 0.005 B/s after a ramp
 * (1.0 % below the ratio at 0.01 B/s; slower loading is an open problem, docs/contact.md).
 * q = reaction / (B/2);
 * bearing_capacity_ratio = mean q/su over the second half of the settlement (docs/contact.md).
 * Checks, with F-bar and quadratic B-splines: the ratio within 10 % of 2 + pi, and the
 * gap of every point to the footing > 0 on every step. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

static double footing_ratio(int basis, int fbar, double delta_end) {
  const double B = 1.0, E = 1.0e6, nu = 0.49, su = 100.0, rho = 1000.0, size = 4.0;
  const double h = B / 10, W = size * B, D = size * B, rate = 0.005 * B, ramp = 0.001 * B;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double glo[2] = {0.0, 0.0}, ghi[2] = {W, D + 0.3 * B};
  TCALL(mpmc_sim_set_grid(sim, glo, ghi, h));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  TCALL(mpmc_sim_set_damping(sim, 0.002));
  int mat;
  const double kappa = sqrt(3.0) * su;
  TCALL(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, kappa, kappa, 0.0, &mat));
  double *x, *vol;
  const double plo[2] = {0.0, 0.0}, phi[2] = {W, D};
  const int n = test_lattice(2, plo, phi, h, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  free(x);
  free(vol);
  TCALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 1, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  const double flo[2] = {-0.5 * B, D}, fhi[2] = {0.5 * B, D + B};
  int foot;
  TCALL(mpmc_sim_add_rigid_box(sim, flo, fhi, 1000.0, &foot)); /* rough */
  const double c = sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho), dt = 0.4 * h / c;
  double settle = 0.0, qsum = 0.0;
  int nq = 0;
  for (long s = 0; settle < delta_end * B; ++s) {
    /* velocity ramped up linearly in time over the first `ramp` of settlement */
    const double v = settle < ramp ? fmax(rate * sqrt(settle / ramp), 0.02 * rate) : rate;
    const double vb[2] = {0.0, -v};
    TCALL(mpmc_sim_set_rigid_velocity(sim, foot, vb));
    TCALL(mpmc_sim_step(sim, dt));
    settle += v * dt;
    double r[2], gap;
    int pt;
    TCALL(mpmc_sim_get_rigid_reaction(sim, foot, r));
    TCALL(mpmc_sim_get_rigid_gap(sim, foot, &gap, &pt));
    if (!(gap > 0)) fail_msg("step %ld: point %d has gap %g to the footing, expected > 0", s, pt, gap);
    if (settle >= 0.5 * delta_end * B) {
      qsum += r[1] / (0.5 * B) / su;
      nq++;
    }
  }
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return qsum / nq;
}

static void test_fbar_bspline2(void **state) {
  (void)state;
  const double want = 2.0 + M_PI;
  const double got = footing_ratio(MPMC_BASIS_BSPLINE2, 1, 0.006);
  if (fabs(got - want) > 0.10 * want)
    fail_msg("F-bar, B-spline2, h = B/10: bearing_capacity_ratio %.4f, expected 2 + pi = %.4f "
             "within 10 %% (error %+.1f %%; measured +8.2 %%, docs/contact.md)",
             got, want, 100 * (got / want - 1));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_fbar_bspline2),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
