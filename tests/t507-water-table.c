/* A water table (mpmc_sim_set_water_table; docs/materials.md): a plane-strain soil column,
 * H = 6 m, with the phreatic line at h_w = 4 m, dry density above and saturated below,
 * loaded by gravity to rest.  Analytic: the pore pressure gamma_w (h_w - y); the total
 * vertical stress the weight above; Mohr-Coulomb (an effective-stress model) strains with the
 * effective stress sigma' = sigma + p, so its settlement is the integral of sigma'_v / M;
 * Hencky-J2 (undrained, total stress) strains with the total stress.  Checked: the masses,
 * the pore pressure, the total and effective stresses within 1 % of rho_sat g H and the two
 * settlements within 3 %; the table survives a checkpoint; bad input is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "test_util.h"

static const double H = 6.0, W = 1.0, h = 0.5, HW = 4.0, RHO = 1800.0, RHO_SAT = 2100.0,
                    E = 20e6, NU = 0.3, G = 9.81, GW = 9810.0;

/* the total vertical stress (compression negative) at height y under the analytic column */
static double sigma_v(double y) {
  const double dry = y > HW ? H - y : H - HW, sat = y < HW ? HW - y : 0.0;
  return -G * (RHO * dry + RHO_SAT * sat);
}
static double pore(double y) { return y < HW ? GW * (HW - y) : 0.0; }

typedef struct {
  double mass_err, pw_err, total_err, eff_err, settle_err;
} result;

/* effective: 1 Mohr-Coulomb (strong enough to stay elastic), 0 Hencky-J2 */
static result column(int effective, const char *checkpoint) {
  const double M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU));
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  sim = test_column_sim(ctx, 2, W, H, 2 * h, h);
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_UGIMP));
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  const double gv[2] = {0, -G};
  TCALL(mpmc_sim_set_gravity(sim, gv));
  TCALL(mpmc_sim_set_damping(sim, 0.3));
  TCALL(mpmc_sim_set_kinetic_damping(sim, 1));
  TCALL(mpmc_sim_set_flip_blend(sim, 0.99));
  int mat;
  if (effective) { /* E nu rho c phi psi c_r phi_r psi_r eta sigma_t rho_sat */
    const double par[] = {E, NU, RHO, 1e7, 30, 0, NAN, NAN, NAN, NAN, NAN, RHO_SAT};
    TCALL(mpmc_sim_add_material(sim, "mohr_coulomb", par, 12, &mat));
  } else { /* E nu rho kappa_p kappa_r eta rho_sat */
    const double par[] = {E, NU, RHO, 1e7, NAN, NAN, RHO_SAT};
    TCALL(mpmc_sim_add_material(sim, "hencky_j2", par, 7, &mat));
  }
  const double xh[4] = {-1.0, HW, 2.0, HW};
  TCALL(mpmc_sim_set_water_table(sim, 2, xh, GW));
  double *x;
  const int n = test_column_fill(sim, 2, W, H, h, mat, &x);
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  double kemax = 0.0;
  for (int s = 0, below = 0; s < 100000 && below < 50; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    double ke;
    TCALL(mpmc_sim_get_kinetic_energy(sim, &ke));
    if (ke > kemax) kemax = ke;
    below = ke <= 1e-6 * kemax ? below + 1 : 0;
  }
  if (checkpoint) { /* the table comes back with the state */
    TCALL(mpmc_sim_checkpoint_write(sim, checkpoint, NULL));
    mpmc_sim_destroy(&sim);
    TCALL(mpmc_sim_checkpoint_read(ctx, checkpoint, &sim, NULL));
    TCALL(mpmc_sim_step(sim, dt));
    remove(checkpoint);
  }
  double *xp, *m, *sig, *pw;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_MASS, &m, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &sig, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_PORE_PRESSURE, &pw, NULL));
  result r = {0};
  double utop = 0.0, se = 0.0, ee = 0.0;
  int ntop = 0;
  for (int q = 0; q < n; ++q) {
    const double y0 = x[2 * q + 1], y = xp[2 * q + 1];
    const double vol = h * h / 4; /* 2 x 2 points per cell */
    const double merr = fabs(m[q] - (y0 < HW ? RHO_SAT : RHO) * vol) / (RHO * vol);
    if (merr > r.mass_err) r.mass_err = merr;
    const double perr = fabs(pw[q] - pore(y)) / (GW * HW);
    if (perr > r.pw_err) r.pw_err = perr;
    se += pow(sig[6 * q + 1] - sigma_v(y0), 2);
    ee += pow(sig[6 * q + 1] + pw[q] - (sigma_v(y0) + pore(y0)), 2);
    if (y0 > H - h / 2) utop += y0 - y, ntop++;
  }
  const double scale = RHO_SAT * G * H;
  r.total_err = sqrt(se / n) / scale;
  r.eff_err = sqrt(ee / n) / scale;
  /* settlement: the integral over the column of the strain the model sees, sigma / M */
  double uref = 0.0;
  const int nint = 6000;
  for (int k = 0; k < nint; ++k) {
    const double y = (k + 0.5) * H / nint;
    uref -= (effective ? sigma_v(y) + pore(y) : sigma_v(y)) / M * (H / nint);
  }
  r.settle_err = fabs(utop / ntop - uref) / uref;
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &xp));
  free(x);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return r;
}

static void check(const char *what, result r) {
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("%s: mass %.1e, pore pressure %.1e, total stress RMS %.3f%%, effective %.3f%%, "
           "settlement %.2f%%\n",
           what, r.mass_err, r.pw_err, 100 * r.total_err, 100 * r.eff_err, 100 * r.settle_err);
  if (!(r.mass_err < 1e-12) || !(r.pw_err < 1e-3) || !(r.total_err < 0.01) ||
      !(r.eff_err < 0.01) || !(r.settle_err < 0.03))
    fail_msg("%s: mass %.1e (< 1e-12), pore pressure %.1e (< 1e-3 of gamma_w h_w), total stress "
             "RMS %.3f%% and effective %.3f%% (< 1%% of rho_sat g H), settlement %.2f%% (< 3%%)",
             what, r.mass_err, r.pw_err, 100 * r.total_err, 100 * r.eff_err, 100 * r.settle_err);
}

static void test_effective_stress_column(void **state) {
  (void)state;
  check("mohr_coulomb", column(1, MPMC_BINARY_DIR "/t507-water-table.h5"));
}

static void test_total_stress_column(void **state) {
  (void)state;
  check("hencky_j2", column(0, NULL));
}

static void test_water_table_bad_input(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double back[4] = {5, 1, 2, 0};
  assert_int_equal(mpmc_sim_set_water_table(sim, 2, back, 9810), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "vertex 1: x = 2 must exceed"));
  const double ok[4] = {0, 1, 2, 0};
  assert_int_equal(mpmc_sim_set_water_table(sim, 2, ok, 0), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "gamma_w = 0"));
  assert_int_equal(mpmc_sim_set_water_table(sim, -1, ok, 9810), MPMC_ERR_ARG);
  assert_int_equal(mpmc_sim_set_water_table_plane(sim, 1, 0, 0, 9810), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "for 3D scenes"));
  assert_int_equal(mpmc_sim_set_water_table(NULL, 2, ok, 9810), MPMC_ERR_ARG);
  TCALL(mpmc_sim_set_water_table(sim, 2, ok, 9810));
  TCALL(mpmc_sim_set_water_table(sim, 0, NULL, 0)); /* removed */
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

/* mpmc_sim_set_geostatic_stress: the same Mohr-Coulomb column, its stresses set at once with
 * K0 = nu / (1 - nu) (the column's elastic state at rest): sigma_v of the overburden,
 * sigma'_h = K0 sigma'_v, sigma = sigma' - p; then it stays at rest (its kinetic energy over
 * 400 steps below 1e-4 of the peak the column loaded by gravity at once reaches). */
static double column_peak_ke(int geostatic, double *err) {
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  sim = test_column_sim(ctx, 2, W, H, 2 * h, h);
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_UGIMP));
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  const double gv[2] = {0, -G};
  TCALL(mpmc_sim_set_gravity(sim, gv));
  const double par[] = {E, NU, RHO, 1e7, 30, 0, NAN, NAN, NAN, NAN, NAN, RHO_SAT};
  int mat;
  TCALL(mpmc_sim_add_material(sim, "mohr_coulomb", par, 12, &mat));
  const double xh[2] = {0.0, HW};
  TCALL(mpmc_sim_set_water_table(sim, 1, xh, GW));
  double *x;
  const int n = test_column_fill(sim, 2, W, H, h, mat, &x);
  const double k0 = NU / (1 - NU);
  *err = 0.0;
  if (geostatic) {
    TCALL(mpmc_sim_set_geostatic_stress(sim, k0));
    double *sig, *pw;
    TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &sig, NULL));
    TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_PORE_PRESSURE, &pw, NULL));
    for (int q = 0; q < n; ++q) {
      const double y = x[2 * q + 1], sv = sigma_v(y), p = pore(y), sh = k0 * (sv + p) - p;
      const double e = fmax(fabs(sig[6 * q + 1] - sv), fabs(sig[6 * q] - sh)) / (RHO_SAT * G * H);
      if (e > *err) *err = e;
    }
  }
  double dt, kemax = 0.0;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 400; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    double ke;
    TCALL(mpmc_sim_get_kinetic_energy(sim, &ke));
    if (ke > kemax) kemax = ke;
  }
  free(x);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return kemax;
}

static void test_geostatic_column(void **state) {
  (void)state;
  double err0, err;
  const double ke_gravity = column_peak_ke(0, &err0), ke_k0 = column_peak_ke(1, &err);
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("geostatic: stress error %.2e of rho_sat g H; peak E_k %.3e J (gravity at once %.3e J)\n",
           err, ke_k0, ke_gravity);
  /* the columns' half-point overburden is exact on the lattice: the error is round-off */
  if (!(err < 1e-12) || !(ke_k0 < 1e-4 * ke_gravity))
    fail_msg("geostatic column: stress error %.2e (< 1e-12), peak E_k %.3e J (< 1e-4 of %.3e J)",
             err, ke_k0, ke_gravity);
}

/* 3D: the plane h = a + b x + c y gives each point its pressure and density */
static void test_plane_3d(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {4, 4, 4};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.5));
  const double par[] = {E, NU, RHO, 1e4, 30, 0, NAN, NAN, NAN, NAN, NAN};
  int mat;
  TCALL(mpmc_sim_add_material(sim, "drucker_prager", par, 11, &mat)); /* rho_sat: rho */
  TCALL(mpmc_sim_set_water_table_plane(sim, 2.0, 0.1, -0.2, GW));
  const double x[9] = {1, 1, 1, 3, 0.5, 2.5, 2, 3, 0.25}, vol[3] = {0.1, 0.1, 0.1};
  TCALL(mpmc_sim_add_particles(sim, 3, x, vol, mat, NULL));
  double *pw, *m;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_PORE_PRESSURE, &pw, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_MASS, &m, NULL));
  for (int q = 0; q < 3; ++q) {
    const double hq = 2.0 + 0.1 * x[3 * q] - 0.2 * x[3 * q + 1], z = x[3 * q + 2];
    assert_true(fabs(pw[q] - (hq > z ? GW * (hq - z) : 0.0)) < 1e-9);
    assert_true(fabs(m[q] - RHO * vol[q]) < 1e-12); /* drucker_prager given no rho_sat */
  }
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_effective_stress_column),
                                     cmocka_unit_test(test_total_stress_column),
                                     cmocka_unit_test(test_geostatic_column),
                                     cmocka_unit_test(test_plane_3d),
                                     cmocka_unit_test(test_water_table_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
