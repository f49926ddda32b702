/* The Neo-Hookean, Hencky and Newtonian stress updates over blocks of four points
 * (stress_blocks.c) against their formulas point by point (Neo-Hookean: b <- dF b dF^T,
 * tau = mu (b - 1) + lambda ln J 1, sigma = tau / J, with linalg.h's push-forward and
 * determinant and libm's log; Hencky: the same b, eps = 1/2 ln b by linalg.h's series or
 * eigen path, sigma = (K tr eps 1 + 2G dev eps) / J, J = sqrt(det b); Newtonian:
 * sigma = K (J - 1) 1 + 2 mu dev(sym(dF - 1) / dt)): 2D and 3D, a point count that leaves a
 * partial last block, two Neo-Hookean materials, a fluid and a Hencky one in whole blocks and
 * interleaved (blocks that mix materials go point by point), b from near I to stretches of
 * 1.5, beyond the series' reach; the baseline and AVX2 sets give the formulas' bits but for
 * the series (the Neo-Hookean's ln J, within 1e-14 of the moduli; Hencky's ln b at the block's
 * degree, within a few ulp of the strain times the moduli), the FMA and AVX512 sets agree to
 * round-off (and with each other, bit for bit); each update keeps the step's guard: a point
 * whose stress overflows stops it with MPMC_ERR_NUMERIC naming that point, from a block of
 * four and from a mixed block. */
#include <float.h>
#include <limits.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "mpmc_impl.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x9E3779B97F4A7C15ull
#include "test_rand.h"

#define NP 103
#define DT 1e-3 /* the step the updates get (the fluid's rate of deformation) */

static mpmc_sim make(mpmc_context ctx, int dim, int *mats) {
  mpmc_sim sim = test_unit_box_sim(ctx, dim);
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 1e6, 0.45, 2000, &mats[0]));
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 70, 0.499, 1, &mats[1]));
  TCALL(mpmc_sim_add_material_hencky(sim, 1e7, 0.3, 2000, &mats[2]));
  TCALL(mpmc_sim_add_material_newtonian(sim, 2e6, 1e-3, 1000, &mats[3]));
  int mat[NP];
  for (int q = 0; q < NP; ++q) /* the first 40 points of material A, the next 12 fluid and 12
                                  Hencky (whole blocks), then B every third point, Hencky every
                                  seventh and fluid every fifth: mixed blocks */
    mat[q] = q < 40   ? mats[0]
             : q < 52 ? mats[3]
             : q < 64 ? mats[2]
             : q % 7 == 3 ? mats[2]
             : q % 5 == 0 ? mats[3]
             : q % 3 == 1 ? mats[1]
                          : mats[0];
  test_points_on_line(sim, NP, mat);
  TCALL(mpmc_sim_prepare(sim));
  return sim;
}

/* random inputs: b SPD with stretches up to 1.5 (b_zz too in 2D: the formula takes any b;
 * Hencky's block 52 goes point by point for it, 56 and 60 take the series as blocks),
 * dF of strain magnitudes 1e-9 .. 0.05, J within 1 % of 1 */
static void fill(mpmc_sim sim) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  for (int q = 0; q < NP; ++q) {
    const int large = q % 5 == 2 && !(q >= 56 && q < 64); /* Hencky blocks 56, 60: series */
    rand_spd(d, large ? 0.4 : q % 2 ? 1e-6 : 0.02, p->be + q * 6);
    rand_dF(d, loguni(1e-9, 0.05), p->dF + q * d * d);
    p->J[q] = 1.0 + 0.01 * (2.0 * urand() - 1.0); /* the fluid's */
    for (int k = 0; k < 6; ++k) p->stress[q * 6 + k] = 0.0;
  }
}

static void run_dim(int dim) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  int mats[4];
  mpmc_sim sim = make(ctx, dim, mats);
  mpmc_particles *p = &sim->p;
  fill(sim);
  static double be0[6 * NP], dF0[9 * NP], want_be[6 * NP], want_s[6 * NP];
  static double got_be[4][6 * NP], got_s[4][6 * NP], want_J[NP], want_lnJ[NP], want_eps[NP];
  memcpy(be0, p->be, sizeof be0);
  memcpy(dF0, p->dF, sizeof(double) * NP * dim * dim);
  /* the expected state, point by point (the materials' formulas) */
  for (int q = 0; q < NP; ++q) {
    double *b = want_be + 6 * q, *s = want_s + 6 * q;
    memcpy(b, be0 + 6 * q, sizeof(double) * 6);
    for (int k = 0; k < 6; ++k) s[k] = 0.0;
    const mpmc_material *m = &sim->mats[p->mat[q]];
    if (p->mat[q] == mats[2]) { /* Hencky */
      double F[3][3], eps[6];
      mpmc_embed(dim, dF0 + q * dim * dim, F);
      mpmc_push_forward(F, b);
      if (mpmc_sym3_log_series(b, eps)) mpmc_sym3_log_eig(b, eps);
      const double tr = eps[0] + eps[1] + eps[2], G2 = 2.0 * m->G, J = sqrt(mpmc_det_sym(b));
      for (int k = 0; k < 6; ++k) s[k] = (G2 * eps[k] + (k < 3 ? (m->K - G2 / 3.0) * tr : 0.0)) / J;
      want_J[q] = J;
      want_eps[q] = sqrt(mpmc_sym3_norm2(eps));
      continue;
    }
    if (p->mat[q] == mats[3]) { /* material_newtonian.c's formula, J (F-bar is off) */
      const double *f = dF0 + q * dim * dim, inv_dt = 1.0 / DT;
      double D[3][3] = {{0}};
      for (int a = 0; a < dim; ++a)
        for (int c = 0; c < dim; ++c) D[a][c] = 0.5 * (f[a * dim + c] + f[c * dim + a]) * inv_dt;
      for (int a = 0; a < dim; ++a) D[a][a] -= inv_dt;
      const double trD = (D[0][0] + D[1][1] + D[2][2]) / 3.0, pr = m->K * (p->J[q] - 1.0);
      const double mu2 = 2.0 * m->mu;
      for (int a = 0; a < 3; ++a) s[a] = pr + mu2 * (D[a][a] - trD);
      s[3] = mu2 * D[1][2], s[4] = mu2 * D[0][2], s[5] = mu2 * D[0][1];
      continue;
    }
    double F[3][3];
    mpmc_embed(dim, dF0 + q * dim * dim, F);
    mpmc_push_forward(F, b);
    const double J = sqrt(mpmc_det_sym(b));
    const double lnJ = log(J), inv_J = 1.0 / J;
    want_J[q] = J;
    want_lnJ[q] = lnJ;
    for (int k = 0; k < 6; ++k) s[k] = (m->G * (b[k] - (k < 3)) + (k < 3 ? m->lambda * lnJ : 0.0)) * inv_J;
  }
  const int sets[4] = {MPMC_KERNELS_BASELINE, MPMC_KERNELS_AVX2, MPMC_KERNELS_FMA,
                       MPMC_KERNELS_AVX512};
  int ran[4] = {0, 0, 0, 0};
  for (int s = 0; s < 4; ++s) {
    if (mpmc_sim_set_kernels(sim, sets[s])) { /* no AVX2 (or AVX-512) here */
      mpmc_context_clear_error(ctx);
      continue;
    }
    ran[s] = 1;
    memcpy(p->be, be0, sizeof be0);
    memcpy(p->dF, dF0, sizeof(double) * NP * dim * dim);
    for (int k = 0; k < 6 * NP; ++k) p->stress[k] = 0.0;
    sim->scr.stress_bad = INT_MAX;
    for (int k = 0; k < 4; ++k) {
      const int m = mats[k];
      TCALL(sim->mats[m].ops->stress_update(sim, &sim->mats[m], m, DT));
    }
    assert_int_equal(sim->scr.stress_bad, INT_MAX);
    memcpy(got_be[s], p->be, sizeof be0);
    memcpy(got_s[s], p->stress, sizeof(double) * 6 * NP);
    const int exact = s < 2; /* no contraction in baseline and AVX2 (but ln J: the series) */
    for (int q = 0; q < NP; ++q) {
      /* in FMA and AVX512 round-off in b and ln J reaches the stress times the moduli (tau ~
       * lambda ln J with ln J ~ 1e-6 here: a relative error of 1e-10 in the stress is one ulp
       * of J) */
      const mpmc_material *mq = &sim->mats[p->mat[q]];
      const int hencky = p->mat[q] == mats[2];
      double tol = 1e-14 * (p->mat[q] == mats[3] ? mq->K + mq->mu / DT
                            : hencky             ? 3.0 * mq->K + 2.0 * mq->G
                                                 : mq->lambda + 2.0 * mq->G);
      if (exact && hencky) /* b exact: the series at the block's degree, within a few ulp of
                              the strain, times the moduli / J */
        tol = 8.0 * DBL_EPSILON * (3.0 * mq->K + 2.0 * mq->G) * want_eps[q] / want_J[q] + 1e-300;
      else if (exact && p->mat[q] != mats[3]) /* b exact: the series' ln J alone, within a few
                                                 ulp of libm's, times lambda / J */
        tol = 8.0 * DBL_EPSILON * mq->lambda * fabs(want_lnJ[q]) / want_J[q] + 1e-300;
      for (int k = 0; k < 6; ++k) {
        const double db = fabs(got_be[s][6 * q + k] - want_be[6 * q + k]);
        double ds = fabs(got_s[s][6 * q + k] - want_s[6 * q + k]);
        const int exact_s = exact && p->mat[q] == mats[3];
        if (exact ? db != 0.0 : !(db <= 1e-14)) ds = INFINITY;
        if (exact_s ? ds != 0.0 : !(ds <= tol))
          fail_msg("dim %d, set %d, point %d (material %d): b[%d] %.17g (want %.17g), stress[%d] "
                   "%.17g (want %.17g)",
                   dim, sets[s], q, p->mat[q], k, got_be[s][6 * q + k], want_be[6 * q + k], k,
                   got_s[s][6 * q + k], want_s[6 * q + k]);
      }
    }
  }
  if (ran[2] && ran[3] &&
      (memcmp(got_be[2], got_be[3], sizeof be0) || memcmp(got_s[2], got_s[3], sizeof be0)))
    fail_msg("dim %d: FMA and AVX512 updates differ", dim);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void test_batch_equals_formula(void **state) {
  (void)state;
  run_dim(3);
  run_dim(2);
}

/* Points 37 and 80 overflow, the rest I: model 0, Neo-Hookean with E = 1e304, nu = 0.49999
 * (lambda = 1.7e308) and dF = 0.9 I, whose normal stresses, -7e307 each, add up to -inf
 * (mpmc_stress_finite); model 2, Hencky with the same (K = 1.7e308); model 1, the fluid
 * with K = 1e300 and J = 1e10 there.  mixed: point
 * 38 of a second material of the same model, so that 37's block goes point by point.  One
 * model alone, so that the update's own guard is the step's (no pass over the stresses after
 * it: stress_update.c). */
static void guard(int model, int mixed) {
  const int fluid = model == 1;
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim sim = test_unit_box_sim(ctx, 3);
  int m, h, mat[NP];
  if (fluid) {
    TCALL(mpmc_sim_add_material_newtonian(sim, 1e300, 1e-3, 1000, &m));
    TCALL(mpmc_sim_add_material_newtonian(sim, 2e6, 1e-3, 1000, &h));
  } else if (model == 2) {
    TCALL(mpmc_sim_add_material_hencky(sim, 1e304, 0.49999, 2000, &m));
    TCALL(mpmc_sim_add_material_hencky(sim, 1e7, 0.3, 2000, &h));
  } else {
    TCALL(mpmc_sim_add_material_neo_hookean(sim, 1e304, 0.49999, 2000, &m));
    TCALL(mpmc_sim_add_material_neo_hookean(sim, 1e7, 0.3, 2000, &h));
  }
  for (int q = 0; q < NP; ++q) mat[q] = mixed && q == 38 ? h : m;
  test_points_on_line(sim, NP, mat);
  TCALL(mpmc_sim_prepare(sim));
  mpmc_particles *p = &sim->p;
  for (int q = 0; q < NP; ++q) {
    const int bad = q == 37 || q == 80;
    for (int k = 0; k < 9; ++k) p->dF[q * 9 + k] = k % 4 ? 0.0 : (bad && !fluid ? 0.9 : 1.0);
    p->J[q] = bad && fluid ? 1e10 : 1.0;
  }
  const int e = mpmc_stress_update(sim, DT);
  if (e != MPMC_ERR_NUMERIC || !strstr(mpmc_context_last_error(ctx), "point 37 at") ||
      !strstr(mpmc_context_last_error(ctx), "non-finite stress"))
    fail_msg("%s, %s: code %d, '%s'", fluid ? "fluid" : model == 2 ? "Hencky" : "Neo-Hookean",
             mixed ? "mixed block" : "block of four", e, mpmc_context_last_error(ctx));
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void test_stress_guard(void **state) {
  (void)state;
  for (int model = 0; model < 3; ++model)
    for (int mixed = 0; mixed < 2; ++mixed) guard(model, mixed);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_batch_equals_formula),
                                     cmocka_unit_test(test_stress_guard)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
