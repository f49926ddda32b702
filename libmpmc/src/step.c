/* One explicit step, as in the paper's Figure 1 and Algorithm 1. */
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <time.h>

#include "kernels.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The name of a local solver (mpmc_solver) for messages: "auto", "newton" or "kinsol". */
const char *mpmc_solver_name(int solver) {
  return solver == MPMC_SOLVER_NEWTON ? "newton" : solver == MPMC_SOLVER_KINSOL ? "kinsol" : "auto";
}

/**
 * @brief The name of a step phase (mpmc_phase), a static string.
 */
const char *mpmc_phase_name(mpmc_phase phase) {
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
  const mpmc_kernel_set *k = mpmc_kernels_of(sim);
  if (sim->bodies) PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_contact_update(sim, dt)); /* barrier forces */
  mpmc_grid_clear_active(&sim->grid); /* the last step's box: the rest is zero already */
  if (sim->cfg.fbar) mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_BOX); /* its F-bar sums too */
  PHASE(sim, MPMC_PHASE_SLABS, t, k->slabs(sim));     /* this step's box, P2G's colouring */
  PHASE(sim, MPMC_PHASE_P2G, t, k->p2g(sim, dt));     /* mass, momentum, forces   (eqs 7, 8, 10) */
  if (sim->dd) PHASE(sim, MPMC_PHASE_P2G, t, mpmc_dd_halo(sim, MPMC_DD_NODES)); /* MPI: halo sums */
  PHASE(sim, MPMC_PHASE_GRID, t, k->grid_update(sim, dt)); /* velocities, walls, damping (eq 9) */
  PHASE(sim, MPMC_PHASE_G2P, t, k->g2p(sim, dt));     /* v, dF, J, x              (eqs 13-17)    */
  if (sim->cfg.kdamp) mpmc_kinetic_damping(sim);          /* v = 0 at a peak of E_k (damping.c) */
  if (sim->cfg.fbar && sim->dd) PHASE(sim, MPMC_PHASE_FBAR, t, mpmc_dd_halo(sim, MPMC_DD_FBAR));
  if (sim->cfg.fbar) PHASE(sim, MPMC_PHASE_FBAR, t, k->fbar(sim, 1)); /* dF -> dF-bar (Alg. 1, 2-4)   */
  PHASE(sim, MPMC_PHASE_STRESS, t, mpmc_stress_update(sim, dt)); /* material update, dF(-bar);
                                   the built-in materials run F-bar's gather themselves */
  if (sim->bodies) PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_contact_check(sim)); /* no point inside a body */
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
  MPMC_CALL(mpmc_sim_prepare(sim));
#ifdef _OPENMP
  const int saved = omp_get_max_threads();
  if (sim->cfg.nthreads > 0) omp_set_num_threads(sim->cfg.nthreads);
#endif
  int err = MPMC_SUCCESS;
  const double t0 = now();
  double t = t0;
  if (sim->bodies) mpmc_contact_step(sim, 1); /* the barrier's parameters, once a step */
  if (!sim->cfg.force_dt) {
    const double limit = mpmc_stability_limit(sim, 1.0);
    if (!(dt <= limit))
      err = MPMC_ERROR(ctx, MPMC_ERR_UNSTABLE,
                       "dt = %g exceeds the stability limit h/(c + |v|max) = %g (h = %g); use dt "
                       "<= %g (factor 0.3-0.4) or force it",
                       dt, limit, sim->grid.h, limit);
  }
  lap(sim, MPMC_PHASE_CHECKS, &t);
  if (sim->dd) err = mpmc_dd_agree(sim, err);
  if (!err && sim->dd) err = mpmc_dd_balance_due(sim); /* MPI: cuts moved to even the points */
  if (!err) err = mpmc_sort_due(sim); /* locality: points by cell (sort.c), if asked for */
  if (!err && sim->cfg.fbar) err = mpmc_fbar_reserve(sim); /* room for F-bar's x^n (G2P keeps it) */
  if (sim->dd) err = mpmc_dd_agree(sim, err);
  lap(sim, MPMC_PHASE_SORT, &t);
  if (!err) err = step_phases(sim, dt, &t);
  if (sim->bodies) mpmc_contact_step(sim, 0);
#ifdef _OPENMP
  if (sim->cfg.nthreads > 0) omp_set_num_threads(saved);
#endif
  if (err) return err;
  sim->time += dt;
  sim->stats.steps++;
  sim->stats.particle_steps += sim->p.n;
  sim->stats.wall_seconds += t - t0; /* the sum of the phases */
  return MPMC_SUCCESS;
}
