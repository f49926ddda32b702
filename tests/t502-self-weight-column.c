/* Self-weight column (issue 2, test 5): plane strain, H = 10 m, rho = 2000, E = 10 MPa,
 * nu = 0.499, slip side walls, fixed base, gravity applied with local damping until the
 * kinetic energy has decayed.  Analytic: sigma_v = -rho g (H - y),
 * settlement u(y) = rho g (H y - y^2/2) / M, M = E (1-nu) / ((1+nu)(1-2nu)).
 * With F-bar (MPMC_FBAR_TOTAL, MPMC_FBAR_STABLE and MPMC_FBAR_ANCHORED), for every basis:
 * RMS error of sigma_v below 3 % of rho g H and the top's settlement within 3 %.  The standard formulation's errors are printed
 * beside it (volumetric locking: expected to be worse), and so is Algorithm 1 as published
 * (MPMC_FBAR_PAPER), whose re-projection of Jbar makes the column creep (docs/theory.md):
 * the test asserts that creep, so a change that removes or worsens it is noticed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include "test_util.h"

typedef struct {
  double rms, settle_err;
  int steps;
} result;

static const char *basis_name[4] = {"linear", "uGIMP", "B-spline2", "B-spline3"};

/* fixed_steps > 0: run exactly that many steps instead of until the energy has decayed;
 * h the cell size */
static result column_h(int basis, int fbar, int fixed_steps, double h) {
  const double H = 10.0, W = 1.0, rho = 2000.0, E = 10e6, nu = 0.499, g = 9.81;
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  sim = test_column_sim(ctx, 2, W, H, 2 * h, h);
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  const double gv[2] = {0, -g};
  TCALL(mpmc_sim_set_gravity(sim, gv));
  TCALL(mpmc_sim_set_damping(sim, 0.1));
  /* a little PIC removes the velocity noise pure FLIP keeps in its null space */
  TCALL(mpmc_sim_set_flip_blend(sim, 0.95));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, nu, rho, &mat));
  double *x;
  const int n = test_column_fill(sim, 2, W, H, h, mat, &x);
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  /* quasi-static: run until the kinetic energy is below 1e-10 of its peak (checked every
   * 100 steps, at least 20 first-mode periods 4H/c) */
  const double c = sqrt(M / rho), period = 4 * H / c;
  const int min_steps = fixed_steps ? fixed_steps : (int)(20 * period / dt);
  const int max_steps = fixed_steps ? fixed_steps : 40 * min_steps;
  double kemax = 0.0;
  int s = 0;
  for (; s < max_steps; ++s) {
    TCALL(mpmc_sim_step(sim, dt));
    if (s % 100 == 0) {
      double ke;
      TCALL(mpmc_sim_get_kinetic_energy(sim, &ke));
      if (ke > kemax) kemax = ke;
      if (!fixed_steps && s > min_steps && ke < 1e-10 * kemax) break;
    }
  }
  double *sig, *xp;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &sig, NULL));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  double se = 0.0, utop = 0.0, uref = 0.0;
  int ntop = 0;
  for (int q = 0; q < n; ++q) {
    const double y = x[2 * q + 1];
    const double e = sig[6 * q + 1] - (-rho * g * (H - y));
    se += e * e;
    if (y > H - h / 2) {
      utop += x[2 * q + 1] - xp[2 * q + 1];
      uref += rho * g * (H * y - 0.5 * y * y) / M;
      ntop++;
    }
  }
  result r = {sqrt(se / n) / (rho * g * H), fabs(utop - uref) / uref, s};
  free(x);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  return r;
}

static result column(int basis, int fbar, int fixed_steps) {
  return column_h(basis, fbar, fixed_steps, 0.5);
}

static void test_column_fbar_all_bases(void **state) {
  (void)state;
  int failed = 0;
  for (int b = 0; b < 4; ++b) {
    const result s = column(b, MPMC_FBAR_OFF, 0);
    for (int form = MPMC_FBAR_TOTAL; form <= MPMC_FBAR_ANCHORED; ++form) {
      const result f = column(b, form, 0);
      const int bad = f.rms > 0.03 || f.settle_err > 0.03;
      failed |= bad;
      if (bad || getenv("MPMC_TEST_VERBOSE"))
        printf("column %-9s  F-bar %-6s: stress RMS %.2f%% of rho g H, settlement error %.2f%% (%d "
               "steps)  | standard: %.2f%%, %.2f%%%s\n",
               basis_name[b],
               form == MPMC_FBAR_TOTAL ? "total" : form == MPMC_FBAR_STABLE ? "stable" : "anchored",
               100 * f.rms,
               100 * f.settle_err, f.steps, 100 * s.rms, 100 * s.settle_err,
               bad ? "  <- F-bar above the 3% tolerance" : "");
    }
  }
  if (failed) fail_msg("F-bar column: expected stress RMS and settlement errors below 3%%");
}

/* Algorithm 1 as published re-projects Jbar every step; for the column at rest the smoothing
 * near the base and the top never stops and the true volume creeps.  After the same number
 * of steps as a settled total-form run, its settlement is off by far more than 3 %. */
static void test_column_paper_creeps(void **state) {
  (void)state;
  const result p = column(MPMC_BASIS_UGIMP, MPMC_FBAR_PAPER, 10000);
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("column uGIMP  F-bar as published: stress RMS %.2f%%, settlement error %.2f%% after %d "
           "steps\n", 100 * p.rms, 100 * p.settle_err, p.steps);
  if (!(p.settle_err > 0.2))
    fail_msg("Algorithm 1 column after %d steps: settlement error %.2f%%, expected the creep "
             "(> 20%%) measured when the total form was introduced",
             p.steps, 100 * p.settle_err);
}

/* The default form (anchored) does not creep: run on for 50,000 steps, several times what the
 * column needs to settle, for every basis at h = 0.25 m, its stress and settlement stay within
 * 1 % of the analytic ones and its settlement where it was when it came to rest (Algorithm 1
 * drifts by 110 % in 10,000 steps, test_column_paper_creeps). */
static void test_column_default_no_creep(void **state) {
  (void)state;
  for (int b = 0; b < 4; ++b) {
    const result rest = column_h(b, MPMC_FBAR_ANCHORED, 0, 0.25);
    const result on = column_h(b, MPMC_FBAR_ANCHORED, 50000, 0.25);
    if (getenv("MPMC_TEST_VERBOSE"))
      printf("column %-9s anchored, h = 0.25: at rest after %d steps stress RMS %.3f%%, "
             "settlement error %.3f%%; after 50,000 steps %.3f%%, %.3f%%\n",
             basis_name[b], rest.steps, 100 * rest.rms, 100 * rest.settle_err, 100 * on.rms,
             100 * on.settle_err);
    if (!(on.rms < 0.01 && on.settle_err < 0.01 && fabs(on.settle_err - rest.settle_err) < 1e-3))
      fail_msg("column %s, anchored F-bar: after 50,000 steps stress RMS %.3f%%, settlement "
               "error %.3f%% (at rest after %d steps: %.3f%%); expected both below 1%% and the "
               "settlement within 0.1%% of where it came to rest",
               basis_name[b], 100 * on.rms, 100 * on.settle_err, rest.steps,
               100 * rest.settle_err);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_column_default_no_creep),
      cmocka_unit_test(test_column_fbar_all_bases),
      cmocka_unit_test(test_column_paper_creeps),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
