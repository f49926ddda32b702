/* Water at rest with the default F-bar (anchored form, docs/theory.md): a column of
 * nearly incompressible Newtonian water (rho = 997.5 kg/m^3, mu = 1e-3 Pa s) H = 0.5 m
 * high, 0.1 m wide (2D, plane strain) or 0.1 x 0.1 m (3D), slip side walls, fixed base,
 * h = 0.05 m with 2 points per cell per axis, gravity switched on at t = 0 with local
 * damping 0.1 and PIC as the diffusivity D = 1 m^2/s (the PIC share D dt / h^2 a step
 * reaches the particle-velocity modes the grid, and so the damping, does not see, and damps
 * the slow modes alike whatever K).  For every basis and K = 2e6, 2e7, 2e8 and
 * 2e9 Pa: 20,000 steps of dt = 0.3 h / c, 150 periods 4H/c of the column's slowest mode
 * whatever K; over the second half the kinetic energy stays below 1e-8 of its peak (a form
 * that gains energy at rest, as Algorithm 1 does, fails), and the pressure -tr(sigma)/3 is
 * rho g depth within 1 % RMS of rho g H.  The full 5 s columns of the dam break run as a
 * benchmark (docs/theory.md). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "test_util.h"

static const char *basis_name[4] = {"linear", "uGIMP", "B-spline2", "B-spline3"};

typedef struct {
  double late_ke; /* the largest kinetic energy over the second half, over its peak */
  double rms;     /* pressure RMS error over rho g H */
} rest;

static rest column(int dim, int basis, double K, int fbar) {
  const double mu = 1e-3, rho = 997.5, g = 9.81, H = 0.5, W = 0.1, h = 0.05;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  sim = test_column_sim(ctx, dim, W, H, 4 * h, h);
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  TCALL(mpmc_sim_set_pic_diffusivity(sim, 1.0)); /* m^2/s, as bench/water_at_rest */
  TCALL(mpmc_sim_set_threads(sim, 1));
  int mat;
  TCALL(mpmc_sim_add_material_newtonian(sim, K, mu, rho, &mat));
  const int n = test_column_fill(sim, dim, W, H, h, mat, NULL);
  const double grav[3] = {0, dim == 2 ? -g : 0, -g};
  TCALL(mpmc_sim_set_gravity(sim, grav));
  TCALL(mpmc_sim_set_damping(sim, 0.1));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  const int nsteps = 20000;
  double peak = 0.0, late = 0.0;
  for (int s = 1; s <= nsteps; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    if (s % 50 == 0) {
      double ke;
      TCALL(mpmc_sim_get_kinetic_energy(sim, &ke));
      peak = ke > peak ? ke : peak;
      if (s > nsteps / 2) late = ke > late ? ke : late;
    }
  }
  double *sg, *xp;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &sg, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  const double top = H * (1 - rho * g * H / (2 * K)); /* the surface after compression */
  double se = 0.0;
  for (int q = 0; q < n; ++q) {
    const double p = -(sg[6 * q] + sg[6 * q + 1] + sg[6 * q + 2]) / 3;
    const double e = p - rho * g * (top - xp[(size_t)q * dim + dim - 1]);
    se += e * e;
  }

  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return (rest){peak > 0 ? late / peak : 1.0, sqrt(se / n) / (rho * g * H)};
}

static void check_dim(int dim) {
  static const double Ks[4] = {2e6, 2e7, 2e8, 2e9};
  int failed = 0;
  for (int b = 0; b < 4; ++b)
    for (int k = 0; k < 4; ++k) {
      const rest r = column(dim, b, Ks[k], MPMC_FBAR_ANCHORED);
      const int bad = !(r.late_ke < 1e-8 && r.rms < 0.01);
      failed |= bad;
      if (bad || getenv("MPMC_TEST_VERBOSE"))
        printf("%dD %-9s K = %.0e Pa: kinetic energy over the second half at most %.2e of its "
               "peak, pressure RMS %.3f%% of rho g H%s\n",
               dim, basis_name[b], Ks[k], r.late_ke, 100 * r.rms,
               bad ? "  <- expected below 1e-8 and 1 %" : "");
    }
  if (failed) fail_msg("%dD water at rest: see the cases above", dim);
}

static void test_at_rest_2d(void **state) {
  (void)state;
  check_dim(2);
}

static void test_at_rest_3d(void **state) {
  (void)state;
  check_dim(3);
}

/* The same column with Algorithm 1 as published does not come to rest: its re-projection of
 * Jbar keeps feeding the motion (docs/theory.md).  Asserted so that the contrast the default
 * form was chosen for stays visible. */
static void test_paper_not_at_rest(void **state) {
  (void)state;
  const rest r = column(2, MPMC_BASIS_UGIMP, 2e9, MPMC_FBAR_PAPER);
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("2D uGIMP K = 2e9 Pa, Algorithm 1: kinetic energy over the second half at most %.2e "
           "of its peak\n", r.late_ke);
  if (!(r.late_ke > 1e-6))
    fail_msg("Algorithm 1's column: kinetic energy over the second half at most %.2e of its "
             "peak, expected above 1e-6 (it does not settle)", r.late_ke);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_at_rest_2d),
      cmocka_unit_test(test_at_rest_3d),
      cmocka_unit_test(test_paper_not_at_rest),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
