/* Scene metrics and the progress display.
 *
 * Run-out distance (docs/workflows.md): the slope faces +axis (default x); the initial toe
 * x_toe is `metrics.runout_distance.toe` or, when not given, the largest initial coordinate
 * of any material point along that axis (a slope standing on the grid floor).  The run-out
 * distance is max(0, max_p x_p - x_toe): how far the farthest material has travelled beyond
 * the initial toe. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "wf.h"

const char *const wf_metric_names[WF_METRIC_COUNT] = {"runout_distance", "tip_displacement_y",
                                                      "tip_displacement_x", "center_of_mass_x",
                                                      "settlement_over_B", "q_over_su",
                                                      "bearing_capacity_ratio",
                                                      [WF_METRIC_FRONT_X] = "surge_front_x",
                                                      [WF_METRIC_HYDRO] = "hydrostatic_pressure_error"};

/* The positions given back after reading them: a position array on loan costs each F-bar
 * step a copy (mpmc_sim_get_field). */
static void give_back_x(mpmc_sim sim) {
  double *x = NULL;
  mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &x);
}

/* Hydrostatic pressure error (dam break, paper section 4.3): with p = -tr(sigma)/3 and the
 * reference p_ref = rho g (surface - x_v) (rho = mass / initial volume, x_v the coordinate
 * along gravity), sqrt(sum (p - p_ref)^2 / sum p_ref^2) over the material points. */
static double hydro_error(mpmc_sim sim, const wf_scene *sc) {
  const wf_metrics *m = &sc->metrics;
  double *x, *mass, *vol0, *sig;
  int np;
  mpmc_sim_get_num_particles(sim, &np);
  if (mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL) || mpmc_sim_get_field(sim, MPMC_FIELD_MASS, &mass, NULL) ||
      mpmc_sim_get_field(sim, MPMC_FIELD_VOLUME0, &vol0, NULL) || mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &sig, NULL))
    return NAN;
  double num = 0, den = 0;
  for (int q = 0; q < np; ++q) {
    const double depth = fmax(0.0, m->surface - x[(size_t)q * sc->dim + m->hydro_axis]);
    const double pref = mass[q] / vol0[q] * m->hydro_g * depth;
    const double p = -(sig[(size_t)q * 6] + sig[(size_t)q * 6 + 1] + sig[(size_t)q * 6 + 2]) / 3.0;
    num += (p - pref) * (p - pref);
    den += pref * pref;
  }
  return den > 0 ? sqrt(num / den) : NAN;
}

/** @brief Keep the metrics defined at the end of a stage (hydrostatic_pressure_error). */
int wf_metrics_stage_end(mpmc_sim sim, wf_scene *sc, int stage) {
  wf_metrics *m = &sc->metrics;
  if (m->enabled[WF_METRIC_HYDRO] && m->hydro_stage == stage) {
    m->hydro_value = hydro_error(sim, sc);
    m->hydro_frozen = 1;
    give_back_x(sim);
  }
  return 0;
}

/** @brief Resolve the toe and the tracked point from the initial positions. */
int wf_metrics_init(mpmc_sim sim, wf_scene *sc) {
  const wf_metrics *m = &sc->metrics;
  double *x0;
  int np, e;
  mpmc_sim_get_num_particles(sim, &np);
  if ((e = mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, NULL))) return e;
  const int d = sc->dim;
  if (m->enabled[WF_METRIC_RUNOUT] && !m->has_toe) {
    double toe = -INFINITY;
    for (int q = 0; q < np; ++q) toe = fmax(toe, x0[(size_t)q * d + m->runout_axis]);
    sc->metrics.toe = toe;
  }
  if (m->enabled[WF_METRIC_TIP_X] || m->enabled[WF_METRIC_TIP_Y]) {
    /* by id: the sort by cell (sort_interval) moves the point to other indices */
    const int *ids;
    if ((e = mpmc_sim_get_particle_ids(sim, &ids))) return e;
    double best = INFINITY;
    for (int q = 0; q < np; ++q) {
      double r2 = 0;
      for (int a = 0; a < d; ++a) r2 += pow(x0[(size_t)q * d + a] - m->point[a], 2);
      if (r2 < best) {
        best = r2;
        sc->metrics.tip_id = ids[q];
      }
    }
  }
  return 0;
}

static int metrics_of_fields(mpmc_sim sim, const wf_scene *sc, double *v) {
  const wf_metrics *m = &sc->metrics;
  double *x, *x0, *mass;
  int np, e;
  mpmc_sim_get_num_particles(sim, &np);
  if ((e = mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL))) return e;
  if ((e = mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, NULL))) return e;
  if ((e = mpmc_sim_get_field(sim, MPMC_FIELD_MASS, &mass, NULL))) return e;
  const int d = sc->dim;
  for (int k = 0; k < WF_METRIC_COUNT; ++k) v[k] = NAN;
  if (m->enabled[WF_METRIC_RUNOUT]) {
    double front = -INFINITY;
    for (int q = 0; q < np; ++q) front = fmax(front, x[(size_t)q * d + m->runout_axis]);
    v[WF_METRIC_RUNOUT] = fmax(0.0, front - m->toe);
  }
  if (m->enabled[WF_METRIC_TIP_X] || m->enabled[WF_METRIC_TIP_Y]) {
    const int *ids;
    if ((e = mpmc_sim_get_particle_ids(sim, &ids))) return e;
    size_t q = 0;
    while ((int)q < np - 1 && ids[q] != m->tip_id) ++q;
    v[WF_METRIC_TIP_X] = x[q * d] - x0[q * d];
    v[WF_METRIC_TIP_Y] = x[q * d + 1] - x0[q * d + 1];
  }
  if (m->enabled[WF_METRIC_COM_X]) {
    double mx = 0, mt = 0;
    for (int q = 0; q < np; ++q) {
      mx += mass[q] * x[(size_t)q * d];
      mt += mass[q];
    }
    v[WF_METRIC_COM_X] = mt > 0 ? mx / mt : NAN;
  }
  if (m->enabled[WF_METRIC_FRONT_X]) { /* the surge front: the farthest point along x */
    double front = -INFINITY;
    for (int q = 0; q < np; ++q) front = fmax(front, x[(size_t)q * d]);
    v[WF_METRIC_FRONT_X] = front;
  }
  if (m->enabled[WF_METRIC_HYDRO]) v[WF_METRIC_HYDRO] = m->hydro_frozen ? m->hydro_value : hydro_error(sim, sc);
  if (m->enabled[WF_METRIC_BEARING]) /* rigid.c: q/su averaged since the last series row */
    wf_bearing_values(sc, 1, &v[WF_METRIC_SETTLEMENT_B], &v[WF_METRIC_Q_SU], &v[WF_METRIC_BEARING]);
  return 0;
}

/** @brief The enabled metrics of the current state. */
int wf_metrics_compute(mpmc_sim sim, const wf_scene *sc, double *v) {
  const int e = metrics_of_fields(sim, sc, v);
  give_back_x(sim);
  return e;
}

/* ---- progress ---------------------------------------------------------------------------- */
void wf_progress_init(wf_progress *p) {
  memset(p, 0, sizeof *p);
  p->tty = isatty(fileno(stderr));
  p->start = wf_now();
  p->last_print = -1e300;
  p->width = 24;
}

static void fmt_eta(double s, char *buf, size_t len) {
  if (!isfinite(s) || s < 0)
    snprintf(buf, len, "--:--");
  else if (s >= 3600)
    snprintf(buf, len, "%d:%02d:%02d", (int)(s / 3600), (int)fmod(s / 60, 60), (int)fmod(s, 60));
  else
    snprintf(buf, len, "%d:%02d", (int)(s / 60), (int)fmod(s, 60));
}

/**
 * On a terminal: a bar redrawn in place about 5 times a second.  Elsewhere (logs, CI): one
 * plain line every `interval` wall seconds, and one when the stage ends.
 */
void wf_progress_update(wf_progress *p, const wf_scene *sc, int stage, double t_stage, double t_end,
                        long steps, double rate, double interval, int force) {
  const double now = wf_now();
  const double every = p->tty ? 0.2 : interval;
  if (!force && now - p->last_print < every) return;
  p->last_print = now;
  const wf_stage *s = &sc->stages[stage];
  const double frac = t_end > 0 ? fmin(1.0, t_stage / t_end) : 1.0;
  /* ETA from this stage's simulated time per wall second; an upper bound for
   * quasi-static stages, which may stop before their maximum time */
  if (stage != p->stage || p->stage_start == 0) {
    p->stage = stage;
    p->stage_start = now;
  }
  char eta[32];
  const double sw = now - p->stage_start;
  (void)steps;
  fmt_eta(frac > 0 ? sw * (1 - frac) / frac : NAN, eta, sizeof eta);
  const char *qs = s->end_kind == WF_END_QUASI_STATIC ? "<=" : "";
  if (p->tty) {
    char bar[64];
    const int fill = (int)(frac * p->width + 0.5);
    for (int i = 0; i < p->width; ++i) bar[i] = i < fill ? '#' : '.';
    bar[p->width] = '\0';
    fprintf(stderr, "\r[%d/%d %-12.12s] t = %8.4f / %g s [%s] %3.0f%%  %8.0f steps/s  ETA %s%s   ", stage + 1,
            sc->nstage, s->name, t_stage, t_end, bar, 100 * frac, rate, qs, eta);
  } else {
    fprintf(stderr, "mpmc: stage %d/%d %s: t = %.4f / %g s (%.0f%%), %ld steps, %.0f steps/s, ETA %s%s\n",
            stage + 1, sc->nstage, s->name, t_stage, t_end, 100 * frac, steps, rate, qs, eta);
  }
  fflush(stderr);
}

void wf_progress_done(wf_progress *p) {
  if (p->tty) fputc('\n', stderr);
  p->last_print = -1e300;
}
