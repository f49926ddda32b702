/* The kernels: which instruction sets this processor runs (CPU detection), the choice of a
 * sim's set (mpmc_sim_set_kernels, MPMC_KERNELS), and the table of each set's phases and
 * stress blocks, indexed by the set.  A kernel is compiled once per set from one source
 * (MPMC_KERNELS in mpmc_impl.h) and dispatched by (dim, basis) inside (MPMC_KERNEL_CALL). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernels.h"

int mpmc_kernels_avx2_available(void) {
#if defined(MPMC_HAVE_AVX2_KERNELS)
  /* x86-64-v3 is AVX2, BMI1/2, FMA, F16C, LZCNT, MOVBE: every processor with AVX2 and BMI2
   * has the others too (clang 14's builtin knows no "x86-64-v3").  The "avx" check includes
   * that the OS saves the AVX state. */
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx") && __builtin_cpu_supports("avx2") &&
         __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
         __builtin_cpu_supports("bmi2");
#else
  return 0;
#endif
}

int mpmc_kernels_avx512_available(void) {
#if defined(MPMC_HAVE_AVX2_KERNELS)
  /* x86-64-v4 adds AVX-512 F, BW, CD, DQ and VL to x86-64-v3; the "avx512f" check includes
   * that the OS saves the AVX-512 state */
  return mpmc_kernels_avx2_available() && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512cd") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
  return 0;
#endif
}

/* Why the kernels of the request cannot run here (for the messages). */
static const char *kernels_missing(int request) {
#if defined(MPMC_HAVE_AVX2_KERNELS)
  if (request == MPMC_KERNELS_AVX512 && mpmc_kernels_avx2_available())
    return "this processor has no AVX-512 (x86-64-v4: AVX-512 F, BW, CD, DQ and VL)";
  return "this processor has no AVX2 (x86-64-v3)";
#else
  (void)request;
  return "this build has no AVX2 or AVX-512 kernels (not x86-64, or MPMC_ARCH set)";
#endif
}

/* Whether a valid request (mpmc_kernels) can run in this build on this processor. */
static int runs_here(int request) {
  return request == MPMC_KERNELS_AUTO || request == MPMC_KERNELS_BASELINE ||
         (request == MPMC_KERNELS_AVX512 ? mpmc_kernels_avx512_available()
                                         : mpmc_kernels_avx2_available());
}

/* Take a valid request (mpmc_kernels): AVX2, FMA and AVX512 are refused where they cannot
 * run, the message naming the request as `what` says; AUTO becomes AVX512 where AVX-512 is
 * available, else FMA where AVX2 is, else BASELINE. */
static int use_kernels(mpmc_sim s, int request, const char *what) {
  const int avx2 = mpmc_kernels_avx2_available(), avx512 = mpmc_kernels_avx512_available();
  MPMC_CHECK(runs_here(request), s->ctx, MPMC_ERR_ARG, "%s: %s", what, kernels_missing(request));
  s->cfg.kernels = request != MPMC_KERNELS_AUTO ? request
               : avx512                     ? MPMC_KERNELS_AVX512
               : avx2                       ? MPMC_KERNELS_FMA
                                            : MPMC_KERNELS_BASELINE;
  return MPMC_SUCCESS;
}

/**
 * @brief The name of a kernel set (mpmc_kernels) as MPMC_KERNELS and summary.json spell it,
 *        a static string.
 */
const char *mpmc_kernels_name(mpmc_kernels kernels) {
  static const char *const names[] = {"auto", "baseline", "avx2", "fma", "avx512"};
  return kernels >= MPMC_KERNELS_AUTO && kernels <= MPMC_KERNELS_AVX512 ? names[kernels]
                                                                        : "unknown kernel set";
}

/* The default set, or the one MPMC_KERNELS names (auto, baseline, avx2, fma, avx512). */
int mpmc_kernels_from_env(mpmc_sim s) {
  const char *e = getenv("MPMC_KERNELS");
  int req = MPMC_KERNELS_AUTO;
  if (e && *e) {
    req = -1;
    for (int k = MPMC_KERNELS_AUTO; k <= MPMC_KERNELS_AVX512; ++k)
      if (!strcmp(e, mpmc_kernels_name(k))) req = k;
    MPMC_CHECK(req >= 0, s->ctx, MPMC_ERR_ARG,
               "environment variable MPMC_KERNELS = '%.40s' is not one of auto, baseline, avx2, "
               "fma, avx512", e);
  }
  char what[64];
  snprintf(what, sizeof what, "environment variable MPMC_KERNELS = %s", mpmc_kernels_name(req));
  return use_kernels(s, req, what);
}

/* A checkpoint's set (checkpoint.c): taken where it runs here, unless MPMC_KERNELS names a
 * set (mpmc_sim_create applied it); otherwise, or for a value no set has, the sim's own. */
int mpmc_kernels_restore(mpmc_sim s, int saved) {
  const char *e = getenv("MPMC_KERNELS");
  if ((e && *e) || saved < MPMC_KERNELS_AUTO || saved > MPMC_KERNELS_AVX512 || !runs_here(saved))
    return MPMC_SUCCESS;
  return use_kernels(s, saved, "the checkpoint's kernel set");
}

/**
 * @brief Instruction set of the step's transfer kernels (mpmc_kernels).  BASELINE and AVX2
 * give the same results to the bit, FMA (fused multiply-adds) differs from them by round-off,
 * AVX512 (FMA for AVX-512, the fastest) gives FMA's bits; AUTO (the default) takes AVX512
 * where the processor has AVX-512, else FMA where it has AVX2.
 * @param kernels MPMC_KERNELS_AUTO, _BASELINE, _AVX2, _FMA or _AVX512 (MPMC_ERR_ARG for AVX2
 *        and FMA where this build or processor has no AVX2 kernels, for AVX512 where it has
 *        no AVX-512 ones)
 */
int mpmc_sim_set_kernels(mpmc_sim sim, mpmc_kernels kernels) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(kernels >= MPMC_KERNELS_AUTO && kernels <= MPMC_KERNELS_AVX512, sim->ctx,
             MPMC_ERR_ARG,
             "kernels = %d is not one of auto (0), baseline (1), avx2 (2), fma (3), avx512 (4)",
             kernels);
  char what[32];
  snprintf(what, sizeof what, "kernels = %s (%d)", mpmc_kernels_name(kernels), kernels);
  return use_kernels(sim, kernels, what);
}

/** @brief The kernel set the step runs: MPMC_KERNELS_BASELINE, _AVX2, _FMA or _AVX512. */
int mpmc_sim_get_kernels(mpmc_const_sim sim, mpmc_kernels *kernels) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(kernels, sim->ctx, MPMC_ERR_ARG, "kernels pointer is NULL");
  *kernels = sim->cfg.kernels;
  return MPMC_SUCCESS;
}

/* The kernel phases for each instruction set, and the Hencky-J2, Neo-Hookean, Hencky and
 * Newtonian updates' blocks (stress_j2.c, stress_blocks.c), which the materials run in the
 * sim's set. */
static const mpmc_kernel_set baseline = {mpmc_slabs_build, mpmc_p2g, mpmc_grid_update, mpmc_g2p, mpmc_fbar,
                                         mpmc_j2_batch, mpmc_nh_batch, mpmc_hencky_batch,
                                         mpmc_newtonian_batch};
#ifdef MPMC_HAVE_AVX2_KERNELS
static const mpmc_kernel_set avx2 = {mpmc_slabs_build_avx2, mpmc_p2g_avx2, mpmc_grid_update_avx2, mpmc_g2p_avx2,
                                     mpmc_fbar_avx2, mpmc_j2_batch_avx2, mpmc_nh_batch_avx2,
                                     mpmc_hencky_batch_avx2, mpmc_newtonian_batch_avx2};
static const mpmc_kernel_set fused = {mpmc_slabs_build_fma, mpmc_p2g_fma, mpmc_grid_update_fma, mpmc_g2p_fma,
                                      mpmc_fbar_fma, mpmc_j2_batch_fma, mpmc_nh_batch_fma,
                                      mpmc_hencky_batch_fma, mpmc_newtonian_batch_fma};
static const mpmc_kernel_set avx512 = {mpmc_slabs_build_avx512, mpmc_p2g_avx512, mpmc_grid_update_avx512,
                                       mpmc_g2p_avx512, mpmc_fbar_avx512, mpmc_j2_batch_avx512,
                                       mpmc_nh_batch_avx512, mpmc_hencky_batch_avx512,
                                       mpmc_newtonian_batch_avx512};
#endif

/** The kernel set the sim's step runs (mpmc_sim_set_kernels). */
const mpmc_kernel_set *mpmc_kernels_of(const struct mpmc_sim_s *sim) {
#ifdef MPMC_HAVE_AVX2_KERNELS
  return sim->cfg.kernels == MPMC_KERNELS_AVX512 ? &avx512
         : sim->cfg.kernels == MPMC_KERNELS_FMA  ? &fused
         : sim->cfg.kernels == MPMC_KERNELS_AVX2 ? &avx2
                                             : &baseline;
#else
  (void)sim;
  return &baseline;
#endif
}

mpmc_j2_batch_fn mpmc_kernels_j2_batch(const struct mpmc_sim_s *sim) {
  return mpmc_kernels_of(sim)->j2_batch;
}

mpmc_stress_batch_fn mpmc_kernels_stress_batch(const struct mpmc_sim_s *sim, int model) {
  const mpmc_kernel_set *k = mpmc_kernels_of(sim);
  return model == MPMC_BATCH_NEWTONIAN ? k->newtonian_batch
         : model == MPMC_BATCH_HENCKY  ? k->hencky_batch
                                       : k->nh_batch;
}

