/* The run monitor, called once at the end of every step (step.c).  NaN/Inf positions and
 * stresses, J <= 0 and points leaving the grid are caught where they arise (g2p.c,
 * stress_update.c); this file adds what no single phase can see: a non-finite velocity
 * (g2p moves points with the grid velocity, so a bad point velocity would only show a step
 * later on the grid) and kinetic energy growing without input.
 *
 * Energy balance.  Gravity g and the point loads f are constant between baselines, so their
 * work since the baseline is exact and cheap: W = sum m g.(x - x0) + sum f.(x - x0), from the
 * sums sum m g.x and sum f.x.  Fixed, slip and separable walls do no work; damping,
 * plasticity, viscosity and PIC only dissipate; so
 *     E_k <= E_k0 + Psi_0 + W    (Psi >= 0 the elastic energy)
 * with Psi_0 = sum V0 (p_tau^2 / 2K + s_tau:s_tau / 4G), tau = J sigma, at the baseline
 * (Hencky's energy in Kirchhoff stress: exact for Hencky and Hencky-J2, a small-strain
 * estimate for neo-Hookean; fluids: p^2 / 2K).  The run stops when
 *     E_k > factor (max(E_k0 + Psi_0 + W, 0) + 0.01 S),   S = E_k0 + Psi_0 + |W|:
 * the factor (10) absorbs the estimate of Psi and the scheme's own energy error, the 1 % of
 * the energy scale the round-off of a balance near zero (a body at the top of its flight).
 * A blow-up grows geometrically, so the stop comes a step or two after the limit is crossed
 * and before NaN.  Any change of inputs (gravity, walls, strengths, number of points, loads)
 * starts a new baseline.  Rigid bodies (prescribed motion: their work is not summed here)
 * and user materials (no energy known) switch the energy check off; the other checks stay.
 *
 * Cost: the input signature (O(materials + walls)) every step; one pass over x and v (a few
 * flops a point, against hundreds in P2G and G2P) every MPMC_MONITOR_EVERY steps, and every
 * step while E_k is above a tenth of the limit or has doubled since the last pass; one pass
 * with the stresses at each new baseline. */
#include <limits.h>
#include <math.h>
#include <stdio.h>

#include "mpmc_impl.h"

#define MPMC_MONITOR_EVERY 8

/* The inputs that may add energy.  Loads also enter through sum |f| (check passes only). */
static void signature(mpmc_const_sim sim, double *sig) {
  for (int a = 0; a < 3; ++a) sig[a] = sim->cfg.gravity[a];
  double k = sim->nmat;
  for (int m = 0; m < sim->nmat; ++m) k += sim->mats[m].srm; /* strength reductions */
  sig[3] = k;
  sig[4] = sim->dd ? (double)sim->np_global : sim->p.n; /* MPI: every rank's points */
  double w = 0.0;
  for (int i = 0; i < sim->nwall; ++i) w += sim->walls[i].active ? (double)(i + 1) : 0.0;
  sig[5] = w + 1e6 * sim->nwall;
  sig[6] = sim->p.force != NULL && !sim->dd; /* MPI: a rank's own; sum |f| (sig[7]) counts */
}

/* Elastic energy density per reference volume of stress s (Voigt), J, material m. */
static double energy_density(const mpmc_material *m, const double *s, double J) {
  const double p = J * (s[0] + s[1] + s[2]) / 3.0;
  double e = p * p / (2.0 * m->K);
  if (m->model->flags & MPMC_MODEL_FLUID) return e; /* the viscous deviator stores nothing */
  double ss = 0.0;
  for (int a = 0; a < 3; ++a) ss += (J * s[a] - p) * (J * s[a] - p);
  for (int a = 3; a < 6; ++a) ss += 2.0 * J * J * s[a] * s[a];
  return e + ss / (4.0 * m->G);
}

/* One pass: kinetic energy, largest |v|^2, sum m g.x, sum f.x, sum |f|, first non-finite
 * velocity (INT_MAX if none) and, with psi != NULL, the elastic energy. */
typedef struct {
  double ke, v2max, gx, fx, fabs, psi;
  int bad;
  double v2mine; /* over MPI: this rank's largest |v|^2 (v2max: all ranks')             */
  int bad_here;  /* over MPI: 1 on the rank of the failing point the message names        */
} sums;

static sums pass(mpmc_const_sim sim, int with_psi) {
  const mpmc_particles *p = &sim->p;
  const mpmc_material *mats = sim->mats;
  const double *g = sim->cfg.gravity, *f = p->force;
  const int d = sim->cfg.dim;
  double ke = 0.0, v2max = 0.0, gx = 0.0, fx = 0.0, fa = 0.0, psi = 0.0;
  int bad = INT_MAX;
#pragma omp parallel for reduction(+ : ke, gx, fx, fa, psi) reduction(max : v2max) \
    reduction(min : bad) schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    const double *x = p->x + (size_t)q * d, *v = p->v + (size_t)q * d;
    double v2 = 0.0, gxq = 0.0;
    for (int a = 0; a < d; ++a) {
      v2 += v[a] * v[a];
      gxq += g[a] * x[a];
    }
    if (!isfinite(v2) && q < bad) bad = q;
    ke += 0.5 * p->m[q] * v2;
    gx += p->m[q] * gxq;
    if (v2 > v2max) v2max = v2;
    if (f) {
      double f2 = 0.0;
      for (int a = 0; a < d; ++a) {
        fx += f[(size_t)q * d + a] * x[a];
        f2 += f[(size_t)q * d + a] * f[(size_t)q * d + a];
      }
      fa += sqrt(f2);
    }
    if (with_psi)
      psi += p->vol0[q] * energy_density(&mats[p->mat[q]], p->stress + (size_t)q * 6, p->J[q]);
  }
  sums s = {ke, v2max, gx, fx, fa, psi, bad, v2max, bad != INT_MAX};
  if (sim->dd) { /* MPI: sums over the ranks in rank order, the lowest failing global id */
    double t[5] = {ke, gx, fx, fa, psi}, mx[2] = {v2max, bad != INT_MAX ? -(double)p->id[bad] : -INFINITY};
    mpmc_dd_sum(sim, t, 5);
    mpmc_dd_max(sim, mx, 2);
    s.ke = t[0], s.gx = t[1], s.fx = t[2], s.fabs = t[3], s.psi = t[4], s.v2max = mx[0];
    s.bad_here = bad != INT_MAX && -(double)p->id[bad] == mx[1];
    if (mx[1] > -INFINITY && !s.bad_here) s.bad = 0; /* fails on every rank, named by one */
  }
  return s;
}

static void baseline(mpmc_monitor *mo, const sums *s, int64_t step, const double *sig) {
  mo->e0[0] = s->ke;
  mo->e0[1] = s->psi;
  mo->gx0 = s->gx;
  mo->fx0 = s->fx;
  mo->base_step = step;
  mo->ke_last = s->ke;
  for (int i = 0; i < 7; ++i) mo->sig[i] = sig[i];
  mo->sig[7] = s->fabs;
}

/** @brief The end-of-step checks (module comment); 0 or the error with its message. */
int mpmc_monitor_step(mpmc_sim sim) {
  mpmc_monitor *mo = &sim->monitor;
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const int64_t step = sim->stats.steps + 1; /* this step, counted from 1 */
  int energy = mo->factor >= 0.0 && !sim->bodies;
  for (int m = 0; m < sim->nmat && energy; ++m) energy = !(sim->mats[m].model->flags & MPMC_MODEL_CALLBACK);
  double sig[7];
  signature(sim, sig);
  int changed = mo->base_step <= 0 || step < mo->base_step;
  for (int i = 0; i < 7 && !changed; ++i) changed = sig[i] != mo->sig[i];
  if (!changed && step < mo->next_check) return MPMC_SUCCESS;

  const sums s = pass(sim, changed && energy);
  if (s.bad != INT_MAX) {
    if (!s.bad_here) return MPMC_DD_FOLLOW; /* MPI: the point's rank reports it */
    const double *x = p->x + (size_t)s.bad * d, *v = p->v + (size_t)s.bad * d;
    char nb[MPMC_POINT_NAME_LEN];
    return MPMC_ERROR(sim->ctx, MPMC_ERR_NUMERIC,
                      "step %lld, t = %g: point %s at (%g, %g, %g) has a non-finite velocity "
                      "(%g, %g, %g): reduce the time step",
                      (long long)sim->stats.steps, sim->time, mpmc_point_name(p, s.bad, nb), x[0], x[1],
                      d == 3 ? x[2] : 0.0, v[0], v[1], d == 3 ? v[2] : 0.0);
  }
  /* a new baseline when the inputs changed, or sum |f| without a new force array */
  if (changed || (energy && (p->force || sim->dd) && s.fabs != mo->sig[7])) {
    const sums sb = changed ? s : pass(sim, 1);
    baseline(mo, &sb, step, sig);
    mo->next_check = step + MPMC_MONITOR_EVERY;
    return MPMC_SUCCESS;
  }
  if (!energy) {
    mo->next_check = step + MPMC_MONITOR_EVERY;
    return MPMC_SUCCESS;
  }
  const double factor = mo->factor > 0.0 ? mo->factor : MPMC_MONITOR_ENERGY_FACTOR;
  const double wg = s.gx - mo->gx0, wf = s.fx - mo->fx0;
  const double avail = mo->e0[0] + mo->e0[1] + wg + wf;
  const double scale = mo->e0[0] + mo->e0[1] + fabs(wg) + fabs(wf);
  const double lim = factor * (fmax(avail, 0.0) + 0.01 * scale);
  const int watch = s.ke > 0.1 * lim || s.ke > 2.0 * mo->ke_last;
  mo->next_check = step + (watch ? 1 : MPMC_MONITOR_EVERY);
  mo->ke_last = s.ke;
  if (!(s.ke > lim)) return MPMC_SUCCESS;
  double jr[2] = {-INFINITY, -INFINITY}; /* -min J, max J for the hint below */
  if (sim->cfg.fbar == MPMC_FBAR_TOTAL || sim->cfg.fbar == MPMC_FBAR_STABLE) {
    for (int i = 0; i < p->n; ++i) jr[0] = fmax(jr[0], -p->J[i]), jr[1] = fmax(jr[1], p->J[i]);
    mpmc_dd_max(sim, jr, 2); /* MPI: over the ranks */
  }
  if (sim->dd && !mpmc_dd_owner(sim, s.v2mine)) return MPMC_DD_FOLLOW; /* the fastest's rank */
  int q = 0; /* the fastest point, for the message */
  for (int i = 0; i < p->n; ++i) {
    double v2 = 0.0;
    for (int a = 0; a < d; ++a) v2 += p->v[(size_t)i * d + a] * p->v[(size_t)i * d + a];
    if (v2 >= s.v2mine) {
      q = i;
      break;
    }
  }
  const double *x = p->x + (size_t)q * d;
  char nb[MPMC_POINT_NAME_LEN];
  /* The forms that project det F itself follow the points' own J, which drifts in a large
   * flow (splashing, run-up; docs/theory.md): say so, with the range of J. */
  char hint[256] = "";
  if (sim->cfg.fbar == MPMC_FBAR_TOTAL || sim->cfg.fbar == MPMC_FBAR_STABLE) {
    const double jmin = -jr[0], jmax = jr[1];
    snprintf(hint, sizeof hint,
             "; or, in a large flow, use the default F-bar form (MPMC_FBAR_ANCHORED, scene "
             "'fbar: true'), which follows Algorithm 1 where the points move: the %s form "
             "projects the points' own J, which drift in a flow (here %.3g to %.3g)",
             sim->cfg.fbar == MPMC_FBAR_TOTAL ? "total" : "stable", jmin, jmax);
  }
  return MPMC_ERROR(sim->ctx, MPMC_ERR_UNSTABLE,
                    "step %lld, t = %g: kinetic energy grows without input: E_k = %.4g J exceeds "
                    "%g x the %.4g J available since step %lld (kinetic %.3g + elastic %.3g + "
                    "work of gravity %.3g + of loads %.3g); fastest point %s at (%g, %g, %g), "
                    "|v| = %.4g m/s: the run is unstable, reduce the time step%s",
                    (long long)sim->stats.steps, sim->time, s.ke, factor, avail,
                    (long long)mo->base_step, mo->e0[0], mo->e0[1], wg, wf, mpmc_point_name(p, q, nb), x[0], x[1],
                    d == 3 ? x[2] : 0.0, sqrt(s.v2max), hint);
}

/**
 * @brief Set the energy check of the run monitor and start a new baseline.
 * @param factor stop when the kinetic energy exceeds factor times the energy available since
 *        the baseline: > 1, 0 for the default MPMC_MONITOR_ENERGY_FACTOR, < 0 to turn it off
 */
int mpmc_sim_set_energy_monitor(mpmc_sim sim, double factor) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(isfinite(factor) && (factor > 1.0 || factor <= 0.0), sim->ctx, MPMC_ERR_ARG,
             "energy monitor factor = %g must be > 1 (0: default %g, < 0: off)", factor,
             MPMC_MONITOR_ENERGY_FACTOR);
  sim->monitor.factor = factor;
  sim->monitor.base_step = 0;
  return MPMC_SUCCESS;
}
