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
/* Over MPI the ranks agree on a failure (mpi.c, mpmc_dd_agree) where every rank must take
 * part (an exchange with the neighbours, a sum over the ranks inside a phase) and at the
 * step's end, not after every phase: a rank whose phase fails skips its phases up to that
 * agreement, so no rank waits in an exchange or a sum that a failed rank does not reach, and
 * every rank fails the step with the same message.  In one process (sim->dd NULL) a failing
 * phase returns at once.  Each agreement's wait counts to phase ph. */
#define PHASE(sim, ph, t, call)            \
  do {                                     \
    if (!err_) {                           \
      err_ = (call);                       \
      lap(sim, ph, t);                     \
    }                                      \
    if (err_ && !(sim)->dd) return err_;   \
  } while (0)
#define AGREE(sim, ph, t)                                 \
  do {                                                    \
    if ((sim)->dd) {                                      \
      err_ = mpmc_dd_agree(sim, err_);                    \
      lap(sim, ph, t);                                    \
    }                                                     \
    if (err_) return err_;                                \
  } while (0)

static int step_phases(mpmc_sim sim, double dt, double *t) {
  const mpmc_kernel_set *k = mpmc_kernels_of(sim);
  int err_ = MPMC_SUCCESS;
  if (sim->bodies) PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_contact_update(sim, dt)); /* barrier forces */
  mpmc_grid_clear_active(&sim->grid); /* the last step's box: the rest is zero already */
  if (sim->cfg.fbar) mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_BOX); /* its F-bar sums too */
  PHASE(sim, MPMC_PHASE_SLABS, t, k->slabs(sim));     /* this step's box, P2G's colouring */
  PHASE(sim, MPMC_PHASE_P2G, t, k->p2g(sim, dt));     /* mass, momentum, forces   (eqs 7, 8, 10) */
  if (sim->dd) { /* MPI: halo sums */
    AGREE(sim, MPMC_PHASE_P2G, t);
    PHASE(sim, MPMC_PHASE_P2G, t, mpmc_dd_halo(sim, MPMC_DD_NODES));
  }
  if (sim->cfg.adr) AGREE(sim, MPMC_PHASE_P2G, t); /* adaptive damping sums over the ranks */
  PHASE(sim, MPMC_PHASE_GRID, t, k->grid_update(sim, dt)); /* velocities, walls, damping (eq 9) */
  PHASE(sim, MPMC_PHASE_G2P, t, k->g2p(sim, dt));     /* v, dF, J, x              (eqs 13-17)    */
  if (sim->cfg.kdamp) { /* v = 0 at a peak of E_k (damping.c; E_k over the ranks) */
    AGREE(sim, MPMC_PHASE_G2P, t);
    mpmc_kinetic_damping(sim);
  }
  if (sim->cfg.fbar && sim->dd) {
    AGREE(sim, MPMC_PHASE_G2P, t);
    PHASE(sim, MPMC_PHASE_FBAR, t, mpmc_dd_halo(sim, MPMC_DD_FBAR));
  }
  if (sim->cfg.fbar) PHASE(sim, MPMC_PHASE_FBAR, t, k->fbar(sim, 1)); /* dF -> dF-bar (Alg. 1, 2-4)   */
  PHASE(sim, MPMC_PHASE_STRESS, t, mpmc_stress_update(sim, dt)); /* material update, dF(-bar);
                                   those with gathers_fbar run F-bar's gather themselves */
  if (sim->bodies) { /* no point inside a body (sums over the ranks) */
    AGREE(sim, MPMC_PHASE_STRESS, t);
    PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_contact_check(sim));
  }
  AGREE(sim, MPMC_PHASE_STRESS, t); /* the monitor's sums over the ranks */
  PHASE(sim, MPMC_PHASE_CHECKS, t, mpmc_monitor_step(sim)); /* NaN velocity, energy growth */
  if (sim->dd) { /* MPI: points to their slabs, in a step where some left theirs (g2p.c) */
    int any = 0;
    err_ = mpmc_dd_agree_leaving(sim, err_, &any);
    lap(sim, MPMC_PHASE_CHECKS, t);
    if (err_) return err_;
    if (any) {
      PHASE(sim, MPMC_PHASE_SORT, t, mpmc_dd_migrate(sim));
      AGREE(sim, MPMC_PHASE_SORT, t);
    }
  }
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
