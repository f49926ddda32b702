/* The AVX2 kernels give the baseline kernels' results to the bit (mpmc_sim_set_kernels):
 * the same scene stepped once with each set, on the same number of threads, every particle
 * field compared with memcmp; the FMA kernels (fused multiply-adds) agree with them to
 * round-off, and in an optimised build differ from them somewhere (else they would not be
 * fused); where the processor has AVX-512, the AVX512 kernels give the FMA kernels' bits.
 * The scenes cover both dimensions, all four bases, F-bar off, the anchored default on every
 * basis, Algorithm 1, the total and the stable form, elastic, plastic and rigid-body contact forces, damping and walls
 * (mirrored ghosts).  Also the set/get calls and the MPMC_KERNELS variable. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "test_util.h"

typedef struct {
  int dim, basis, fbar, material, rigid;
  double damping;
} scene;

enum { ELASTIC, PLASTIC };

/* Build the scene, step it with the given kernel set, return the context and sim. */
static void run(const scene *sc, int kernels, mpmc_context *pctx, mpmc_sim *psim) {
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, sc->dim, &sim));
  TCALL(mpmc_sim_set_kernels(sim, kernels));
  mpmc_kernels got;
  TCALL(mpmc_sim_get_kernels(sim, &got));
  assert_int_equal(got, kernels);
  const double h = sc->dim == 2 ? 0.05 : 0.1;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1.5, 1};
  const double blo[3] = {0, 0, 0}, bhi[3] = {1.2, 0.8, 0.6};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_set_basis(sim, sc->basis));
  TCALL(mpmc_sim_set_fbar(sim, sc->fbar));
  TCALL(mpmc_sim_set_damping(sim, sc->damping));
  TCALL(mpmc_sim_set_flip_blend(sim, 0.95));
  int mat;
  if (sc->material == PLASTIC)
    TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e6, 0.49, 2000, 6e3, 1e3, 20, &mat));
  else
    TCALL(mpmc_sim_add_material_neo_hookean(sim, 1e6, 0.45, 2000, &mat));
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, NULL));
  for (int f = 0; f < 2 * sc->dim; ++f)
    if (f != 1 && f != 3) TCALL(mpmc_sim_add_wall_face(sim, f, f == 2 ? MPMC_WALL_FIXED : MPMC_WALL_SLIP, NULL));
  const double g[3] = {0, -9.81, 0};
  TCALL(mpmc_sim_set_gravity(sim, g));
  if (sc->rigid) { /* a plate pressed onto the block's top */
    const double plo[3] = {0.2, 0.8, 0.2}, phi[3] = {0.6, 1.0, 0.4}, pv[3] = {0, -0.5, 0};
    int body;
    TCALL(mpmc_sim_add_rigid_box(sim, plo, phi, 0.5, &body));
    TCALL(mpmc_sim_set_rigid_velocity(sim, body, pv));
  }
  /* a shear velocity field, so that every point moves and the plastic points yield */
  double *x, *v;
  int nc;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, &nc));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, &nc));
  int n;
  TCALL(mpmc_sim_get_num_particles(sim, &n));
  for (int q = 0; q < n; ++q) v[(size_t)q * sc->dim] = 0.8 * x[(size_t)q * sc->dim + 1];
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 30; ++s) TCALL(mpmc_sim_step(sim, dt));
  *pctx = ctx;
  *psim = sim;
}

/* Largest difference of the FMA set's fields from the baseline's, relative to each field's
 * largest magnitude, over the scenes so far; the scenes whose fields all agree within 1e-9 of
 * that; and whether any entry differed at all. */
static double fma_rel;
static int fma_close, fma_differs;

static void check_scene(const scene *sc) {
  mpmc_context c[4];
  mpmc_sim s[4];
  const int nset = mpmc_kernels_avx512_available() ? 4 : 3; /* avx512 where it runs */
  run(sc, MPMC_KERNELS_BASELINE, &c[0], &s[0]);
  run(sc, MPMC_KERNELS_AVX2, &c[1], &s[1]);
  run(sc, MPMC_KERNELS_FMA, &c[2], &s[2]);
  if (nset == 4) run(sc, MPMC_KERNELS_AVX512, &c[3], &s[3]);
  int n;
  TCALL(mpmc_sim_get_num_particles(s[0], &n));
  int compared = 0;
  double scene_rel = 0.0;
  for (int f = 0; f < MPMC_FIELD_COUNT; ++f) {
    double *a, *b, *m;
    int na, nb, nm;
    if (mpmc_sim_get_field(s[0], f, &a, &na) || !a) continue; /* a field this scene has not */
    TCALL(mpmc_sim_get_field(s[1], f, &b, &nb));
    TCALL(mpmc_sim_get_field(s[2], f, &m, &nm));
    assert_int_equal(na, nb);
    assert_int_equal(na, nm);
    const size_t len = (size_t)n * (size_t)na;
    if (nset == 4) { /* avx512: fma's operations and contractions, so fma's bits */
      double *e;
      int ne;
      TCALL(mpmc_sim_get_field(s[3], f, &e, &ne));
      assert_int_equal(na, ne);
      for (size_t i = 0; i < len; ++i)
        if (memcmp(&m[i], &e[i], sizeof(double)))
          fail_msg("dim %d basis %d fbar %d: field %d, entry %zu: fma %.17g, avx512 %.17g",
                   sc->dim, sc->basis, sc->fbar, f, i, m[i], e[i]);
    }
    if (memcmp(a, b, sizeof(double) * len)) {
      for (size_t i = 0; i < len; ++i)
        if (memcmp(&a[i], &b[i], sizeof(double)))
          fail_msg("dim %d basis %d fbar %d: field %d, entry %zu: baseline %.17g, avx2 %.17g",
                   sc->dim, sc->basis, sc->fbar, f, i, a[i], b[i]);
    }
    double big = 0.0, diff = 0.0;
    for (size_t i = 0; i < len; ++i) {
      big = fmax(big, fabs(a[i]));
      diff = fmax(diff, fabs(m[i] - a[i]));
      fma_differs |= memcmp(&a[i], &m[i], sizeof(double)) != 0;
    }
    /* round-off decides some branches (yield, the Hencky series or the eigen path, contact),
     * so a few points of a plastic or contact scene part by more after 30 steps (up to
     * 1.1e-5 of a field's largest value seen, uGIMP + the stable form, plastic) */
    if (!(diff <= 1e-4 * big)) /* NaN fails too */
      fail_msg("dim %d basis %d fbar %d: field %d: fma differs from baseline by %g (of %g)",
               sc->dim, sc->basis, sc->fbar, f, diff, big);
    scene_rel = fmax(scene_rel, big > 0.0 ? diff / big : 0.0);
    ++compared;
  }
  if (compared < 5) fail_msg("only %d fields compared", compared);
  fma_rel = fmax(fma_rel, scene_rel);
  fma_close += scene_rel <= 1e-9;
  for (int k = 0; k < nset; ++k) {
    mpmc_sim_destroy(&s[k]);
    mpmc_context_destroy(&c[k]);
  }
}

static void same_bits(void **state) {
  (void)state;
  if (!mpmc_kernels_avx2_available()) skip(); /* no AVX2 kernels in this build or CPU */
  const scene scenes[] = {
      {3, MPMC_BASIS_BSPLINE2, MPMC_FBAR_PAPER, PLASTIC, 0, 0.0},
      {3, MPMC_BASIS_LINEAR, MPMC_FBAR_OFF, ELASTIC, 1, 0.05},
      {3, MPMC_BASIS_UGIMP, MPMC_FBAR_TOTAL, PLASTIC, 0, 0.0},
      {3, MPMC_BASIS_BSPLINE3, MPMC_FBAR_PAPER, ELASTIC, 0, 0.1},
      {2, MPMC_BASIS_UGIMP, MPMC_FBAR_TOTAL, PLASTIC, 1, 0.1},
      {2, MPMC_BASIS_BSPLINE2, MPMC_FBAR_OFF, ELASTIC, 0, 0.0},
      {2, MPMC_BASIS_LINEAR, MPMC_FBAR_PAPER, PLASTIC, 0, 0.0},
      {2, MPMC_BASIS_BSPLINE3, MPMC_FBAR_TOTAL, ELASTIC, 1, 0.02},
      {2, MPMC_BASIS_BSPLINE2, MPMC_FBAR_STABLE, PLASTIC, 1, 0.0},
      {3, MPMC_BASIS_UGIMP, MPMC_FBAR_STABLE, PLASTIC, 0, 0.05},
      {3, MPMC_BASIS_BSPLINE3, MPMC_FBAR_STABLE, ELASTIC, 1, 0.0},
      {3, MPMC_BASIS_LINEAR, MPMC_FBAR_ANCHORED, PLASTIC, 0, 0.0},
      {2, MPMC_BASIS_UGIMP, MPMC_FBAR_ANCHORED, ELASTIC, 1, 0.05},
      {3, MPMC_BASIS_BSPLINE2, MPMC_FBAR_ANCHORED, PLASTIC, 1, 0.1},
      {2, MPMC_BASIS_BSPLINE3, MPMC_FBAR_ANCHORED, PLASTIC, 0, 0.0},
  };
  for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; ++k) check_scene(&scenes[k]);
  const int nsc = (int)(sizeof scenes / sizeof scenes[0]);
#ifdef __OPTIMIZE__ /* GCC forms fused multiply-adds only when it optimises (not in -O0) */
  if (!fma_differs) fail_msg("the fma kernels gave the baseline's bits: no fused multiply-adds?");
#endif
  if (2 * fma_close < nsc) /* most scenes part by round-off only (11 of 15 seen) */
    fail_msg("fma against baseline: only %d of %d scenes within 1e-9", fma_close, nsc);
  if (getenv("MPMC_TEST_VERBOSE"))
    printf("fma against baseline: %d of %d scenes within 1e-9 of each field's largest value, "
           "the largest difference %.3g of it\n", fma_close, nsc, fma_rel);
}

/* what AUTO resolves to on this processor */
static int auto_set(void) {
  return mpmc_kernels_avx512_available() ? MPMC_KERNELS_AVX512
         : mpmc_kernels_avx2_available() ? MPMC_KERNELS_FMA
                                         : MPMC_KERNELS_BASELINE;
}

static void set_get(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  mpmc_kernels k = MPMC_KERNELS_AUTO;
  TCALL(mpmc_sim_get_kernels(sim, &k));
  assert_int_equal(k, auto_set());
  TCALL(mpmc_sim_set_kernels(sim, MPMC_KERNELS_BASELINE));
  TCALL(mpmc_sim_get_kernels(sim, &k));
  assert_int_equal(k, MPMC_KERNELS_BASELINE);
  TCALL(mpmc_sim_set_kernels(sim, MPMC_KERNELS_AUTO)); /* AUTO resolves to a set */
  TCALL(mpmc_sim_get_kernels(sim, &k));
  assert_int_equal(k, auto_set());
  assert_int_equal(mpmc_sim_set_kernels(sim, 5), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "kernels = 5"));
  /* the names MPMC_KERNELS and summary.json use */
  assert_string_equal(mpmc_kernels_name(MPMC_KERNELS_AUTO), "auto");
  assert_string_equal(mpmc_kernels_name(MPMC_KERNELS_BASELINE), "baseline");
  assert_string_equal(mpmc_kernels_name(MPMC_KERNELS_AVX2), "avx2");
  assert_string_equal(mpmc_kernels_name(MPMC_KERNELS_FMA), "fma");
  assert_string_equal(mpmc_kernels_name(MPMC_KERNELS_AVX512), "avx512");
  assert_string_equal(mpmc_kernels_name(5), "unknown kernel set");
  assert_string_equal(mpmc_kernels_name(-1), "unknown kernel set");
  assert_int_equal(mpmc_sim_get_kernels(sim, NULL), MPMC_ERR_ARG);
  if (!mpmc_kernels_avx2_available()) {
    assert_int_equal(mpmc_sim_set_kernels(sim, MPMC_KERNELS_AVX2), MPMC_ERR_ARG);
    assert_non_null(strstr(mpmc_context_last_error(ctx), "no AVX2"));
    assert_int_equal(mpmc_sim_set_kernels(sim, MPMC_KERNELS_FMA), MPMC_ERR_ARG);
    assert_non_null(strstr(mpmc_context_last_error(ctx), "kernels = fma (3)"));
  } else {
    TCALL(mpmc_sim_set_kernels(sim, MPMC_KERNELS_AVX2));
    TCALL(mpmc_sim_get_kernels(sim, &k));
    assert_int_equal(k, MPMC_KERNELS_AVX2);
  }
  if (!mpmc_kernels_avx512_available()) { /* refused, saying what is missing */
    assert_int_equal(mpmc_sim_set_kernels(sim, MPMC_KERNELS_AVX512), MPMC_ERR_ARG);
    assert_non_null(strstr(mpmc_context_last_error(ctx), "kernels = avx512 (4)"));
    assert_non_null(strstr(mpmc_context_last_error(ctx),
                           mpmc_kernels_avx2_available() ? "no AVX-512" : "no AVX2"));
  } else {
    TCALL(mpmc_sim_set_kernels(sim, MPMC_KERNELS_AVX512));
    TCALL(mpmc_sim_get_kernels(sim, &k));
    assert_int_equal(k, MPMC_KERNELS_AVX512);
  }
  mpmc_sim_destroy(&sim);
  /* the environment variable: a valid name sets the default, anything else is an error
   * naming the variable, and no sim is made */
  setenv("MPMC_KERNELS", "baseline", 1);
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  TCALL(mpmc_sim_get_kernels(sim, &k));
  assert_int_equal(k, MPMC_KERNELS_BASELINE);
  mpmc_sim_destroy(&sim);
  if (mpmc_kernels_avx2_available()) {
    setenv("MPMC_KERNELS", "avx2", 1);
    TCALL(mpmc_sim_create(ctx, 3, &sim));
    TCALL(mpmc_sim_get_kernels(sim, &k));
    assert_int_equal(k, MPMC_KERNELS_AVX2);
    mpmc_sim_destroy(&sim);
  }
  setenv("MPMC_KERNELS", "avx512", 1); /* made where it runs, else refused by name */
  sim = NULL;
  if (mpmc_kernels_avx512_available()) {
    TCALL(mpmc_sim_create(ctx, 3, &sim));
    TCALL(mpmc_sim_get_kernels(sim, &k));
    assert_int_equal(k, MPMC_KERNELS_AVX512);
    mpmc_sim_destroy(&sim);
  } else {
    assert_int_equal(mpmc_sim_create(ctx, 3, &sim), MPMC_ERR_ARG);
    assert_null(sim);
    assert_non_null(strstr(mpmc_context_last_error(ctx), "MPMC_KERNELS = avx512"));
  }
  setenv("MPMC_KERNELS", "sse9", 1);
  sim = NULL;
  assert_int_equal(mpmc_sim_create(ctx, 3, &sim), MPMC_ERR_ARG);
  assert_null(sim);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "MPMC_KERNELS = 'sse9'"));
  unsetenv("MPMC_KERNELS");
  mpmc_context_destroy(&ctx);
}

int main(void) {
  unsetenv("MPMC_KERNELS");
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(same_bits),
      cmocka_unit_test(set_get),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
