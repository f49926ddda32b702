/* One explicit step, as in the paper's Figure 1 and Algorithm 1. */
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <time.h>

#include "mpmc_impl.h"
#include "return_map.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The kernel phases for each instruction set (mpmc_impl.h, mpmc_sim_set_kernels), and the
 * Hencky-J2, Neo-Hookean, Hencky and Newtonian updates' blocks (stress_j2.c,
 * stress_blocks.c), which the materials run in the sim's set. */
typedef struct {
  int (*slabs)(mpmc_sim);
  int (*p2g)(mpmc_sim, double);
  int (*grid_update)(mpmc_sim, double);
  int (*g2p)(mpmc_sim, double);
  int (*fbar)(mpmc_sim, int);
  mpmc_j2_batch_fn j2_batch;
  mpmc_stress_batch_fn nh_batch, hencky_batch, newtonian_batch;
} kernel_set;
static const kernel_set baseline = {mpmc_slabs_build, mpmc_p2g, mpmc_grid_update, mpmc_g2p,
                                    mpmc_fbar, mpmc_j2_batch, mpmc_nh_batch,
                                    mpmc_hencky_batch, mpmc_newtonian_batch};
#ifdef MPMC_HAVE_AVX2_KERNELS
static const kernel_set avx2 = {mpmc_slabs_build_avx2, mpmc_p2g_avx2, mpmc_grid_update_avx2,
                                mpmc_g2p_avx2, mpmc_fbar_avx2, mpmc_j2_batch_avx2,
                                mpmc_nh_batch_avx2, mpmc_hencky_batch_avx2,
                                mpmc_newtonian_batch_avx2};
static const kernel_set fused = {mpmc_slabs_build_fma, mpmc_p2g_fma, mpmc_grid_update_fma,
                                 mpmc_g2p_fma, mpmc_fbar_fma, mpmc_j2_batch_fma,
                                 mpmc_nh_batch_fma, mpmc_hencky_batch_fma,
                                 mpmc_newtonian_batch_fma};
static const kernel_set avx512 = {mpmc_slabs_build_avx512, mpmc_p2g_avx512,
                                  mpmc_grid_update_avx512, mpmc_g2p_avx512, mpmc_fbar_avx512,
                                  mpmc_j2_batch_avx512, mpmc_nh_batch_avx512,
                                  mpmc_hencky_batch_avx512, mpmc_newtonian_batch_avx512};
#define KERNELS(sim)                                  \
  ((sim)->kernels == MPMC_KERNELS_AVX512 ? &avx512   \
   : (sim)->kernels == MPMC_KERNELS_FMA  ? &fused    \
   : (sim)->kernels == MPMC_KERNELS_AVX2 ? &avx2     \
                                         : &baseline)
#else
#define KERNELS(sim) (&baseline)
#endif

mpmc_j2_batch_fn mpmc_kernels_j2_batch(const struct mpmc_sim_s *sim) {
  return KERNELS(sim)->j2_batch;
}

mpmc_stress_batch_fn mpmc_kernels_stress_batch(const struct mpmc_sim_s *sim, int model) {
  return model == MPMC_BATCH_NEWTONIAN ? KERNELS(sim)->newtonian_batch
         : model == MPMC_BATCH_HENCKY  ? KERNELS(sim)->hencky_batch
                                     : KERNELS(sim)->nh_batch;
}

/* The name of a local solver (mpmc_solver) for messages: "auto", "newton" or "kinsol". */
const char *mpmc_solver_name(int solver) {
  return solver == MPMC_SOLVER_NEWTON ? "newton" : solver == MPMC_SOLVER_KINSOL ? "kinsol" : "auto";
}

/**
 * @brief The name of a step phase (mpmc_phase), a static string.
 */
const char *mpmc_phase_name(int phase) {
  static const char *const names[MPMC_PHASE_COUNT] = {"sort", "slabs", "p2g",    "grid",
                                                      "g2p",  "fbar",  "stress", "checks"};
  return phase >= 0 && phase < MPMC_PHASE_COUNT ? names[phase] : "unknown phase";
}

/* The wall time since *t goes to phase ph; *t becomes now. */
static void lap(mpmc_sim sim, int ph, double *t) {
  const double t1 = now();
  sim->stats.phase_seconds[ph] += t1 - *t;
  *t = t1;
}
/* Over MPI every phase ends with the ranks' agreement (mpi.c, mpmc_dd_agree): a failure
 * on one rank fails the step on all with the same message before anyone waits in an
 * exchange; in one process (sim->dd NULL) the call's code as it is. */
#define PHASE(sim, ph, t, call)                                  \
  do {                                                           \
    int phase_err_ = (call);                                     \
    if ((sim)->dd) phase_err_ = mpmc_dd_agree(sim, phase_err_);  \
    if (phase_err_) return phase_err_;                           \
    lap(sim, ph, t);                                             \
  } while (0)

static int step_phases(mpmc_sim sim, double dt, double *t) {
  const kernel_set *k = KERNELS(sim);
  if (sim->bodies) PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_contact_update(sim, dt)); /* barrier forces */
  mpmc_grid_clear_active(&sim->grid); /* the last step's box: the rest is zero already */
  PHASE(sim, MPMC_PHASE_SLABS, t, k->slabs(sim));     /* this step's box, P2G's colouring */
  PHASE(sim, MPMC_PHASE_P2G, t, k->p2g(sim, dt));     /* mass, momentum, forces   (eqs 7, 8, 10) */
  if (sim->dd) PHASE(sim, MPMC_PHASE_P2G, t, mpmc_dd_halo(sim, MPMC_DD_NODES)); /* MPI: halo sums */
  PHASE(sim, MPMC_PHASE_GRID, t, k->grid_update(sim, dt)); /* velocities, walls, damping (eq 9) */
  PHASE(sim, MPMC_PHASE_G2P, t, k->g2p(sim, dt));     /* v, dF, J, x              (eqs 13-17)    */
  if (sim->kdamp) mpmc_kinetic_damping(sim);          /* v = 0 at a peak of E_k (damping.c) */
  if (sim->fbar && sim->dd) PHASE(sim, MPMC_PHASE_FBAR, t, mpmc_dd_halo(sim, MPMC_DD_FBAR));
  if (sim->fbar) PHASE(sim, MPMC_PHASE_FBAR, t, k->fbar(sim, 1)); /* dF -> dF-bar (Alg. 1, 2-4)   */
  PHASE(sim, MPMC_PHASE_STRESS, t, mpmc_stress_update(sim, dt)); /* material update, dF(-bar);
                                   the built-in materials run F-bar's gather themselves */
  if (sim->bodies) MPMC_CALL(mpmc_contact_check(sim)); /* no point inside a rigid body */
  PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_monitor_step(sim)); /* NaN velocity, energy growth */
  if (sim->dd) PHASE(sim, MPMC_PHASE_SORT, t, mpmc_dd_migrate(sim)); /* MPI: points to their slabs */
  return MPMC_SUCCESS;
}

/**
 * @brief Advance the simulation by dt.
 * @param dt time step [s]; refused above the stability limit h/c unless forced
 * @return MPMC_ERR_NUMERIC / MPMC_ERR_OUTSIDE with the step, point and position in the
 *         message when the state became invalid
 */
int mpmc_sim_step(mpmc_sim sim, double dt) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(isfinite(dt) && dt > 0, ctx, MPMC_ERR_ARG, "time step dt = %g must be > 0", dt);
  MPMC_CHECK(sim->nmat > 0 && (sim->dd ? sim->np_global : sim->p.n) > 0, ctx, MPMC_ERR_STATE,
             "nothing to step: add a material and material points first");
  MPMC_CHECK(!sim->dd || !sim->bodies, ctx, MPMC_ERR_UNSUPPORTED,
             "rigid bodies are not supported over MPI yet (issue 47)");
  MPMC_CALL(mpmc_sim_prepare(sim));
#ifdef _OPENMP
  const int saved = omp_get_max_threads();
  if (sim->nthreads > 0) omp_set_num_threads(sim->nthreads);
#endif
  int err = MPMC_SUCCESS;
  const double t0 = now();
  double t = t0;
  if (sim->bodies) mpmc_contact_step(sim, 1); /* the barrier's parameters, once a step */
  if (!sim->force_dt) {
    const double limit = mpmc_stability_limit(sim, 1.0);
    if (!(dt <= limit))
      err = MPMC_ERROR(ctx, MPMC_ERR_UNSTABLE,
                       "dt = %g exceeds the stability limit h/(c + |v|max) = %g (h = %g); use dt "
                       "<= %g (factor 0.3-0.4) or force it",
                       dt, limit, sim->grid.h, limit);
  }
  lap(sim, MPMC_PHASE_CHECKS, &t);
  if (!err) err = mpmc_sort_due(sim); /* locality: points by cell (sort.c), if asked for */
  if (sim->dd) err = mpmc_dd_agree(sim, err);
  lap(sim, MPMC_PHASE_SORT, &t);
  if (!err) err = step_phases(sim, dt, &t);
  if (sim->bodies) mpmc_contact_step(sim, 0);
#ifdef _OPENMP
  if (sim->nthreads > 0) omp_set_num_threads(saved);
#endif
  if (err) return err;
  sim->time += dt;
  sim->stats.steps++;
  sim->stats.particle_steps += sim->p.n;
  sim->stats.wall_seconds += t - t0; /* the sum of the phases */
  return MPMC_SUCCESS;
}
