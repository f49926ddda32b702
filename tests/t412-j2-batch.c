/* The Hencky-J2 stress update over blocks of four points (stress_j2.c) against the scalar
 * return map of each point (mpmc_j2_return_map): 2D and 3D, a point count that leaves a
 * partial last block, two J2 materials and a Hencky one interleaved (masked lanes), elastic
 * points of strains from 1e-9 to past the series' range (the eigen fallback), plastic
 * points with and without softening history, and a steeply softening material whose
 * returns the auto solver hands to KINSOL; with the newton and the auto solver (whose
 * plastic points the blocks return four at a time, stress_j2.c's plastic4) b_e, eps_p and the
 * stress agree to 1e-12, the counts of plastic corrections and KINSOL fallbacks match, both
 * instruction sets give the same bits, and a point with a non-finite dF fails the update
 * with its own index in the message; the blocks keep the step's guard against non-finite
 * stresses. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "mpmc_impl.h"
#include "return_map.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x2545F4914F6CDD1Dull
#include "test_rand.h"

#define NP 103

typedef struct {
  double be[6 * NP], eps_p[NP], stress[6 * NP];
  int64_t plastic, fallbacks;
} state;

/* 1 if two updates left the same b_e, stress and eps_p, bit for bit */
static int same_bits(const state *a, const state *b) {
  return !memcmp(a->be, b->be, sizeof a->be) && !memcmp(a->stress, b->stress, sizeof a->stress) &&
         !memcmp(a->eps_p, b->eps_p, sizeof a->eps_p);
}

static mpmc_sim make(mpmc_context ctx, int dim, int *mats) {
  mpmc_sim sim = test_unit_box_sim(ctx, dim);
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e7, 0.3, 2000, 3e4, 5e3, 8, &mats[0]));
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 5e7, 0.49, 1800, 2e5, 2e5, 0, &mats[1]));
  TCALL(mpmc_sim_add_material_hencky(sim, 1e7, 0.3, 2000, &mats[2]));
  /* eta (kappa_p - kappa_r) = 3e6 > 3G = 1.15e6: g' > 0 near the bracket's lower end */
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e6, 0.3, 2000, 1.2e4, 2e3, 300, &mats[3]));
  int mat[NP];
  for (int q = 0; q < NP; ++q) /* J2 A mostly, J2 B every third point, Hencky every seventh,
                                  the steep J2 every fifth: blocks mix materials */
    mat[q] = q % 7 == 3 ? mats[2] : q % 5 == 4 ? mats[3] : q % 3 == 1 ? mats[1] : mats[0];
  test_points_on_line(sim, NP, mat);
  TCALL(mpmc_sim_prepare(sim));
  return sim;
}

/* random inputs: b_e^n SPD (some far from I), eps_p, dF of strain magnitudes 1e-9 .. 0.3 */
static void fill(mpmc_sim sim) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  for (int q = 0; q < NP; ++q) {
    /* a few beyond the series (|eps| > 0.18), half of the rest inside the yield surface */
    const double big = q % 11 == 5 ? 0.4 : q % 2 ? 0.001 : 0.02;
    rand_spd(d, big, p->be + q * 6);
    p->eps_p[q] = q % 4 == 0 ? 0.0 : loguni(1e-6, 0.5);
    rand_dF(d, loguni(1e-9, 0.01), p->dF + q * d * d);
    for (int k = 0; k < 6; ++k) p->stress[q * 6 + k] = 0.0;
  }
}

static void save(mpmc_const_sim sim, state *s) {
  memcpy(s->be, sim->p.be, sizeof s->be);
  memcpy(s->eps_p, sim->p.eps_p, sizeof s->eps_p);
  memcpy(s->stress, sim->p.stress, sizeof s->stress);
  s->plastic = sim->stats.return_maps;
  s->fallbacks = sim->stats.kinsol_fallbacks;
}

static const int j2_mats[3] = {0, 1, 3}; /* the indices in mats[] of the J2 materials */

static void run_dim(int dim, int solver) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  int mats[4];
  mpmc_sim sim = make(ctx, dim, mats);
  mpmc_particles *p = &sim->p;
  fill(sim);
  double be0[6 * NP], ep0[NP], dF0[9 * NP];
  memcpy(be0, p->be, sizeof be0);
  memcpy(ep0, p->eps_p, sizeof ep0);
  memcpy(dF0, p->dF, sizeof(double) * NP * dim * dim);
  /* the expected state, point by point by the scalar return map */
  state want = {0};
  int plastic = 0, fallbacks = 0, series_out = 0;
  mpmc_rm_ws *ws;
  TCALL(mpmc_rm_ws_create(&ws));
  for (int q = 0; q < NP; ++q) {
    memcpy(want.be + 6 * q, be0 + 6 * q, sizeof(double) * 6);
    want.eps_p[q] = ep0[q];
    if (p->mat[q] == mats[2]) continue; /* Hencky: not this update's */
    const mpmc_material *m = &sim->mats[p->mat[q]];
    const mpmc_j2_param par = {m->K, m->G, m->kappa_p, m->kappa_r, m->eta};
    double F[3][3], tau[6], J;
    mpmc_embed(dim, dF0 + q * dim * dim, F);
    mpmc_j2_info info = {0};
    TCALL(mpmc_j2_return_map(ws, solver, &par, F, want.be + 6 * q, want.eps_p + q, tau, &J, &info));
    for (int k = 0; k < 6; ++k) want.stress[6 * q + k] = tau[k] / J;
    plastic += info.plastic;
    fallbacks += info.fallback;
    double b[6], eps[6];
    memcpy(b, be0 + 6 * q, sizeof b);
    mpmc_push_forward(F, b);
    series_out += mpmc_sym3_log_series(b, eps);
  }
  mpmc_rm_ws_destroy(&ws);
  if (plastic < 10 || NP - plastic < 30 || series_out < 3 ||
      (solver == MPMC_SOLVER_AUTO && (fallbacks < 2 || plastic - fallbacks < 10)))
    fail_msg("dim %d: weak mix: %d plastic, %d by KINSOL, %d outside the series", dim, plastic,
             fallbacks, series_out);
  TCALL(mpmc_sim_set_solver(sim, solver));
  state got[4];
  /* each set against the scalar update; baseline and AVX2 also against each other, bit for
   * bit (FMA's fused multiply-adds part from them by round-off), and FMA and AVX512 */
  const int sets[4] = {MPMC_KERNELS_BASELINE, MPMC_KERNELS_AVX2, MPMC_KERNELS_FMA,
                       MPMC_KERNELS_AVX512};
  int nsets = 0;
  for (int s = 0; s < 4; ++s) {
    if (mpmc_sim_set_kernels(sim, sets[s])) { /* no AVX2 (or AVX-512) here */
      mpmc_context_clear_error(ctx);
      continue;
    }
    memcpy(p->be, be0, sizeof be0);
    memcpy(p->eps_p, ep0, sizeof ep0);
    memcpy(p->dF, dF0, sizeof(double) * NP * dim * dim);
    for (int k = 0; k < 6 * NP; ++k) p->stress[k] = 0.0;
    const int64_t before = sim->stats.return_maps, fb_before = sim->stats.kinsol_fallbacks;
    for (int k = 0; k < 3; ++k) {
      const int m = mats[j2_mats[k]];
      TCALL(sim->mats[m].ops->stress_update(sim, &sim->mats[m], m, 1e-3));
    }
    save(sim, &got[nsets]);
    got[nsets].plastic -= before;
    got[nsets].fallbacks -= fb_before;
    const state *g = &got[nsets++];
    if (g->plastic != plastic || g->fallbacks != fallbacks)
      fail_msg("dim %d, solver %d, set %d: %lld plastic corrections, %lld by KINSOL, expected %d, %d",
               dim, solver, sets[s], (long long)g->plastic, (long long)g->fallbacks, plastic, fallbacks);
    for (int q = 0; q < NP; ++q) {
      double smax = 0;
      for (int k = 0; k < 6; ++k) smax = fmax(smax, fabs(want.stress[6 * q + k]));
      for (int k = 0; k < 6; ++k) {
        if (!(fabs(g->be[6 * q + k] - want.be[6 * q + k]) <= 1e-12))
          fail_msg("dim %d point %d (material %d): be[%d] %.17g, scalar %.17g", dim, q, p->mat[q], k, g->be[6 * q + k], want.be[6 * q + k]);
        if (!(fabs(g->stress[6 * q + k] - want.stress[6 * q + k]) <= 1e-12 * smax + 1e-300))
          fail_msg("dim %d point %d (material %d): stress[%d] %.17g, scalar %.17g", dim, q, p->mat[q], k, g->stress[6 * q + k], want.stress[6 * q + k]);
      }
      if (!(fabs(g->eps_p[q] - want.eps_p[q]) <= 1e-12 * fmax(1.0, want.eps_p[q])))
        fail_msg("dim %d point %d: eps_p %.17g, scalar %.17g", dim, q, g->eps_p[q], want.eps_p[q]);
    }
  }
  if (nsets >= 3 && !same_bits(&got[0], &got[1]))
    fail_msg("dim %d: baseline and AVX2 stress updates differ", dim);
  if (nsets == 4 && !same_bits(&got[2], &got[3]))
    fail_msg("dim %d: FMA and AVX512 stress updates differ", dim);
  /* a non-finite dF in the middle of a block: the error names the point */
  memcpy(p->be, be0, sizeof be0);
  memcpy(p->eps_p, ep0, sizeof ep0);
  memcpy(p->dF, dF0, sizeof(double) * NP * dim * dim);
  const int bad = 57; /* material J2 A (57 % 3 = 0, 57 % 7 = 1) */
  if (p->mat[bad] != mats[0]) fail_msg("test set-up: point %d is not of material 0", bad);
  p->dF[bad * dim * dim] = NAN;
  const int e = sim->mats[mats[0]].ops->stress_update(sim, &sim->mats[mats[0]], mats[0], 1e-3);
  char want_msg[64];
  snprintf(want_msg, sizeof want_msg, "point %d at", bad);
  if (e == MPMC_SUCCESS || !strstr(mpmc_context_last_error(ctx), want_msg))
    fail_msg("dim %d: non-finite point %d: code %d, '%s'", dim, bad, e, mpmc_context_last_error(ctx));
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

static void test_batch_equals_scalar(void **state) {
  (void)state;
  const int solvers[2] = {MPMC_SOLVER_NEWTON, MPMC_SOLVER_AUTO};
  for (int k = 0; k < 2; ++k) {
    run_dim(3, solvers[k]);
    run_dim(2, solvers[k]);
  }
}

/* The step's stress guard (stress_update.c) kept by the blocks themselves: points whose
 * elastic stress overflows stop the update with MPMC_ERR_NUMERIC naming the lowest of them,
 * from the J2 blocks' own check with Hencky-J2 alone, from the pass over the stresses with a
 * Hencky material beside it.  3D, K = 1.7e308, dF = 0.9 I (beyond the blocks' series: the
 * scalar return map's lanes; an elastic lane within it cannot overflow with a finite K): the
 * normal components, -7e307 each, add up to -inf (2D's plane strain stays finite). */
static void guard(int dim, int with_hencky) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim sim = test_unit_box_sim(ctx, dim);
  int m, h, mat[NP];
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e304, 0.49999, 2000, 1e307, 1e307, 0, &m));
  if (with_hencky) TCALL(mpmc_sim_add_material_hencky(sim, 1e7, 0.3, 2000, &h));
  for (int q = 0; q < NP; ++q) mat[q] = m;
  test_points_on_line(sim, NP, mat);
  TCALL(mpmc_sim_prepare(sim));
  mpmc_particles *p = &sim->p;
  for (int q = 0; q < NP; ++q)
    for (int k = 0; k < dim * dim; ++k)
      p->dF[q * dim * dim + k] = k % (dim + 1) ? 0.0 : (q == 37 || q == 80 ? 0.9 : 1.0);
  const int e = mpmc_stress_update(sim, 1e-3);
  if (e != MPMC_ERR_NUMERIC || !strstr(mpmc_context_last_error(ctx), "point 37 at") ||
      !strstr(mpmc_context_last_error(ctx), "non-finite stress"))
    fail_msg("dim %d%s: code %d, '%s'", dim, with_hencky ? " with Hencky" : "", e,
             mpmc_context_last_error(ctx));
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void test_stress_guard(void **state) {
  (void)state;
  for (int h = 0; h < 2; ++h) guard(3, h);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_batch_equals_scalar),
                                     cmocka_unit_test(test_stress_guard)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
