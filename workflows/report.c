/* Reporting: scene metrics, series.csv, summary.json and the progress display.  run.c calls
 * these; nothing here calls back into run.c.
 *
 * Run-out distance (docs/workflows.md): the slope faces +axis (default x); the initial toe
 * x_toe is `metrics.runout_distance.toe` or, when not given, the largest initial coordinate
 * of any material point along that axis (a slope standing on the grid floor).  The run-out
 * distance is max(0, max_p x_p - x_toe): how far the farthest material has travelled beyond
 * the initial toe.  With `material`, only that material's points count for both (the fill
 * of a slope on a foundation layer that reaches beyond the toe). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

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
 * along gravity), sqrt(sum (p - p_ref)^2 / sum p_ref^2) over the material points: each
 * rank's own, in exact sums (the same bits on any number of ranks). */
static double hydro_error(mpmc_sim sim, const wf_scene *sc) {
  const wf_metrics *m = &sc->metrics;
  static const int fields[4] = {MPMC_FIELD_POSITION, MPMC_FIELD_MASS, MPMC_FIELD_VOLUME0, MPMC_FIELD_STRESS};
  double *f[4];
  int np;
  if (wf_own(sim, &np, 4, fields, f, NULL, NULL)) return NAN;
  const double *x = f[0], *mass = f[1], *vol0 = f[2], *sig = f[3];
  wf_xsum s[2]; /* num, den */
  memset(s, 0, sizeof s);
  for (int q = 0; q < np; ++q) {
    const double depth = fmax(0.0, m->surface - x[(size_t)q * sc->dim + m->hydro_axis]);
    const double pref = mass[q] / vol0[q] * m->hydro_g * depth;
    const double p = -(sig[(size_t)q * 6] + sig[(size_t)q * 6 + 1] + sig[(size_t)q * 6 + 2]) / 3.0;
    wf_xsum_add(&s[0], (p - pref) * (p - pref));
    wf_xsum_add(&s[1], pref * pref);
  }
  wf_par_xsum(s, 2);
  const double num = wf_xsum_value(&s[0]), den = wf_xsum_value(&s[1]);
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

/** @brief Resolve the toe and the tracked point from the initial positions: each rank's own
 *         points, then the largest toe and the nearest point over the ranks (collective). */
int wf_metrics_init(mpmc_sim sim, wf_scene *sc) {
  const wf_metrics *m = &sc->metrics;
  double *x0;
  const int *ids = NULL, *mat = NULL, field = MPMC_FIELD_X0;
  int np, e;
  const int d = sc->dim, toe = m->enabled[WF_METRIC_RUNOUT] && !m->has_toe;
  const int tip = m->enabled[WF_METRIC_TIP_X] || m->enabled[WF_METRIC_TIP_Y];
  /* the points of the run-out's material only, when it names one; the tracked point by id
   * (the sort by cell, sort_interval, moves it to other indices) */
  const int by_mat = toe && m->runout_material >= 0;
  if ((e = wf_own(sim, &np, 1, &field, &x0, tip ? &ids : NULL, by_mat ? &mat : NULL))) return e;
  if (toe) {
    const int slide = by_mat ? sc->mats[m->runout_material].id : -1;
    double t = -INFINITY;
    for (int q = 0; q < np; ++q)
      if (!mat || mat[q] == slide) t = fmax(t, x0[(size_t)q * d + m->runout_axis]);
    sc->metrics.toe = wf_par_max(t);
  }
  if (tip) { /* the nearest point, the smallest id of the nearest alike */
    double best = INFINITY;
    int id = -1;
    for (int q = 0; q < np; ++q) {
      double r2 = 0;
      for (int a = 0; a < d; ++a) r2 += pow(x0[(size_t)q * d + a] - m->point[a], 2);
      if (r2 < best || (r2 == best && ids[q] < id)) {
        best = r2;
        id = ids[q];
      }
    }
    sc->metrics.tip_id = wf_par_least(best, id);
  }
  return 0;
}

/* The metrics from each rank's own points, then a reduction exact in any order (a maximum,
 * the value of the rank holding the tracked point, exact sums): no point is gathered for
 * them over MPI, and they have the same bits on any number of ranks. */
static int own_metrics(mpmc_sim sim, const wf_scene *sc, double *v) {
  const wf_metrics *m = &sc->metrics;
  const int d = sc->dim, tip = m->enabled[WF_METRIC_TIP_X] || m->enabled[WF_METRIC_TIP_Y];
  const int *ids = NULL, *mat = NULL;
  const int by_mat = m->enabled[WF_METRIC_RUNOUT] && m->runout_material >= 0;
  const int fields[3] = {MPMC_FIELD_POSITION, tip ? MPMC_FIELD_X0 : -1,
                         m->enabled[WF_METRIC_COM_X] ? MPMC_FIELD_MASS : -1};
  double *f[3];
  int n, e;
  if ((e = wf_own(sim, &n, 3, fields, f, tip ? &ids : NULL, by_mat ? &mat : NULL))) return e;
  const double *x = f[0], *x0 = f[1], *mass = f[2];
  if (m->enabled[WF_METRIC_RUNOUT]) {
    const int slide = by_mat ? sc->mats[m->runout_material].id : -1;
    double front = -INFINITY;
    for (int q = 0; q < n; ++q)
      if (!mat || mat[q] == slide) front = fmax(front, x[(size_t)q * d + m->runout_axis]);
    v[WF_METRIC_RUNOUT] = fmax(0.0, wf_par_max(front) - m->toe);
  }
  if (tip) {
    int q = 0;
    while (q < n && ids[q] != m->tip_id) ++q;
    const int mine = q < n;
    double u[2] = {0.0, 0.0};
    for (int a = 0; a < 2 && mine; ++a) u[a] = x[(size_t)q * d + a] - x0[(size_t)q * d + a];
    wf_par_one(u, 2, mine);
    v[WF_METRIC_TIP_X] = u[0];
    v[WF_METRIC_TIP_Y] = u[1];
  }
  if (m->enabled[WF_METRIC_COM_X]) {
    wf_xsum s[2]; /* sum m x, sum m */
    memset(s, 0, sizeof s);
    for (int q = 0; q < n; ++q) {
      wf_xsum_add(&s[0], mass[q] * x[(size_t)q * d]);
      wf_xsum_add(&s[1], mass[q]);
    }
    wf_par_xsum(s, 2);
    const double mx = wf_xsum_value(&s[0]), mt = wf_xsum_value(&s[1]);
    v[WF_METRIC_COM_X] = mt > 0 ? mx / mt : NAN;
  }
  if (m->enabled[WF_METRIC_FRONT_X]) { /* the surge front: the farthest point along x */
    double front = -INFINITY;
    for (int q = 0; q < n; ++q) front = fmax(front, x[(size_t)q * d]);
    v[WF_METRIC_FRONT_X] = wf_par_max(front);
  }
  return 0;
}

static int metrics_of_fields(mpmc_sim sim, const wf_scene *sc, double *v) {
  const wf_metrics *m = &sc->metrics;
  int e;
  for (int k = 0; k < WF_METRIC_COUNT; ++k) v[k] = NAN;
  if ((e = own_metrics(sim, sc, v))) return e;
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

/* ---- series.csv ----------------------------------------------------------------------------- */

/**
 * @brief Open series.csv at path: a new file (append = 0), or the one a resumed run goes on
 *        with; the header is written to a new or empty file.  NULL with msg on failure.
 */
FILE *wf_series_open(const char *path, const wf_scene *sc, int append, char *msg, size_t len) {
  FILE *f = fopen(path, append ? "a" : "w");
  if (!f) {
    snprintf(msg, len, "cannot write %s: %s", path, strerror(errno));
    return NULL;
  }
  if (!append || fseek(f, 0, SEEK_END) || ftell(f) == 0) { /* new, or none to append to */
    fputs("stage,time,step,dt,kinetic_energy,ke_ratio", f);
    for (int k = 0; k < WF_METRIC_COUNT; ++k)
      if (sc->metrics.enabled[k]) fprintf(f, ",%s", wf_metric_names[k]);
    fputc('\n', f);
  }
  return f;
}

/**
 * @brief One row of series.csv for the current state.
 * @return 0, the metrics' error code, or MPMC_ERR_IO when the row cannot be written (errno)
 */
int wf_series_row(FILE *f, mpmc_sim sim, const wf_scene *sc, int stage, long step, double dt, double ke,
                  double ratio) {
  double t, m[WF_METRIC_COUNT];
  mpmc_sim_get_time(sim, &t);
  const int e = wf_metrics_compute(sim, sc, m); /* over MPI on every rank (collective) */
  if (e || !f) return e;                        /* f: rank 0's */
  fprintf(f, "%s,%.9g,%ld,%.6g,%.9g,%.6g", sc->stages[stage].name, t, step, dt, ke, ratio);
  /* a metric not defined yet (the footing's ratio before its first step) is an empty field,
     never a NaN; + 0.0 turns -0 into 0 */
  for (int k = 0; k < WF_METRIC_COUNT; ++k)
    if (sc->metrics.enabled[k]) isfinite(m[k]) ? fprintf(f, ",%.9g", m[k] + 0.0) : fputc(',', f);
  fputc('\n', f);
  /* a full disk shows here first: stop with the reason instead of a silently short series */
  return fflush(f) || ferror(f) ? MPMC_ERR_IO : 0;
}

/* Resuming: series.csv at path back to the checkpoint, the rows of at most `steps` steps (a
 * killed run wrote rows after its last checkpoint, and maybe half a row), through a temporary
 * file renamed over it.  *kept: the data rows left; an absent file keeps none.  0, or -1
 * with msg.  The step is the third field; stage names may
 * hold commas, so it is found from the end of the row (dt, E_k, ratio and the metrics after
 * it). */
int wf_series_trim(const char *path, const wf_scene *sc, long steps, int *kept, char *msg, size_t len) {
  char tmp[WF_PATH + 8];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  *kept = 0;
  FILE *in = fopen(path, "r");
  if (!in) return errno == ENOENT ? 0 : (snprintf(msg, len, "cannot read %s: %s", path, strerror(errno)), -1);
  FILE *out = fopen(tmp, "w");
  if (!out) {
    snprintf(msg, len, "cannot write %s: %s", tmp, strerror(errno));
    fclose(in);
    return -1;
  }
  int after = 3; /* fields after the step */
  for (int k = 0; k < WF_METRIC_COUNT; ++k) after += sc->metrics.enabled[k];
  char *line = NULL;
  size_t cap = 0;
  ssize_t n;
  for (long row = 0; (n = getline(&line, &cap, in)) > 0; ++row) {
    if (line[n - 1] != '\n') break; /* cut by the kill */
    int keep = row == 0;            /* the header */
    if (!keep) {
      int commas = 0;
      char *p = line + n - 1;
      while (p > line && commas < after) commas += *--p == ',';
      char *end = p; /* the comma after the step */
      while (p > line && p[-1] != ',') --p;
      char *stop = NULL;
      const long st = commas == after && p > line ? strtol(p, &stop, 10) : -1;
      keep = stop == end && st >= 0 && st <= steps;
      *kept += keep;
    }
    if (keep) fputs(line, out);
  }
  free(line);
  fclose(in);
  int bad = fflush(out) != 0;
  bad |= ferror(out) != 0;
  bad |= fclose(out) != 0;
  if (bad || rename(tmp, path)) {
    snprintf(msg, len, "cannot rewrite %s: %s", path, strerror(errno));
    remove(tmp);
    return -1;
  }
  return 0;
}

/* ---- summary.json ------------------------------------------------------------------------- */

static void json_str(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"' || *s == '\\')
      fprintf(f, "\\%c", *s);
    else if ((unsigned char)*s < 0x20)
      fprintf(f, "\\u%04x", *s);
    else
      fputc(*s, f);
  }
  fputc('"', f);
}

static double jnum(double v) { return isfinite(v) ? v : 0.0; }

/**
 * @brief Write summary.json: the scene, the status (error == NULL: completed, else failed
 *        with that message), the run's statistics, the records of the stages done and the
 *        metrics of the current state.  Nothing is written when path cannot be opened.
 */
void wf_summary_write(const char *path, const wf_scene *sc, mpmc_sim sim, const char *error,
                      const wf_stage_record *rec, int nstages_done, double wall, const wf_fos_result *fos) {
  const int ok = error == NULL;
  mpmc_stats st = {0};
  int np = 0;
  double m[WF_METRIC_COUNT] = {0};
  int have_m = 0;
  if (sim) { /* over MPI: collective, every rank's points and counts */
    mpmc_sim_get_stats(sim, &st);
    wf_all_count(sim, &np);
    st.particle_steps = wf_par_total(st.particle_steps);
    st.return_maps = wf_par_total(st.return_maps);
    st.kinsol_fallbacks = wf_par_total(st.kinsol_fallbacks);
    have_m = np > 0 && wf_metrics_compute(sim, sc, m) == 0;
  }
  double imbalance = 1.0; /* over MPI: the most points on a rank over the mean, at the end */
  long balances = 0;
  if (sim) wf_par_imbalance(sim, &imbalance, &balances);
  FILE *f = wf_par_rank() == 0 ? fopen(path, "w") : NULL; /* rank 0 writes */
  if (!f) return;
  fputs("{\n  \"scene\": ", f);
  json_str(f, sc->name);
  fputs(",\n  \"scene_file\": ", f);
  json_str(f, sc->path);
  fprintf(f, ",\n  \"status\": \"%s\",\n", ok ? "completed" : "failed");
  if (!ok) {
    fputs("  \"error\": ", f);
    json_str(f, error);
    fputs(",\n", f);
  }
  fprintf(f, "  \"dim\": %d,\n  \"basis\": \"%s\",\n  \"fbar\": %s,\n  \"cell_size\": %.9g,\n", sc->dim,
          wf_basis_name(sc->basis), sc->fbar == MPMC_FBAR_TOTAL    ? "\"total\""
          : sc->fbar == MPMC_FBAR_STABLE ? "\"stable\""
          : sc->fbar == MPMC_FBAR_PAPER  ? "\"paper\""
          : sc->fbar                     ? "\"anchored\""
                                           : "false", sc->h);
  mpmc_kernels kern = MPMC_KERNELS_BASELINE;
  mpmc_sim_get_kernels(sim, &kern);
  fprintf(f, "  \"kernels\": \"%s\",\n", mpmc_kernels_name(kern));
  int sort_every = 0;
  mpmc_sim_get_sort_interval(sim, &sort_every);
  fprintf(f, "  \"sort_interval\": %d,\n", sort_every);
  int threads = 1;
#ifdef _OPENMP
  threads = sc->threads > 0 ? sc->threads : omp_get_max_threads();
#endif
  fprintf(f, "  \"ranks\": %d,\n  \"threads_per_rank\": %d,\n", wf_par_size(), threads);
  if (wf_par_size() > 1) fprintf(f, "  \"imbalance\": %.4g,\n  \"balances\": %ld,\n", imbalance, balances);
  fprintf(f, "  \"particles\": %d,\n  \"steps\": %lld,\n  \"wall_seconds\": %.6g,\n", np, (long long)st.steps, wall);
  fprintf(f, "  \"step_wall_seconds\": %.6g,\n  \"particle_steps_per_second\": %.6g,\n", st.wall_seconds,
          st.wall_seconds > 0 ? (double)st.particle_steps / st.wall_seconds : 0.0);
  fprintf(f, "  \"return_maps\": %lld,\n  \"kinsol_fallbacks\": %lld,\n", (long long)st.return_maps,
          (long long)st.kinsol_fallbacks);
  fputs("  \"phase_seconds\": {", f);
  for (int k = 0; k < MPMC_PHASE_COUNT; ++k)
    fprintf(f, "%s\"%s\": %.6g", k ? ", " : "", mpmc_phase_name(k), st.phase_seconds[k]);
  fputs("},\n", f);
  fputs("  \"stages\": [", f);
  for (int i = 0; i < nstages_done; ++i) {
    const wf_stage_record *r = &rec[i];
    fprintf(f, "%s\n    {\"name\": ", i ? "," : "");
    json_str(f, r->name);
    fprintf(f, ", \"sim_time\": %.9g, \"steps\": %ld, \"wall_seconds\": %.6g, \"end\": \"%s\", "
               "\"strength_reduction\": %.9g}",
            r->sim_time, r->steps, r->wall_seconds, r->reason ? r->reason : "failed",
            r->strength > 0 ? r->strength : 1.0);
  }
  fputs(nstages_done ? "\n  ]" : "]", f);
  if (fos && fos->ntrial > 0) wf_fos_json(f, fos);
  if (have_m)
    for (int k = 0; k < WF_METRIC_COUNT; ++k)
      /* all 17 digits: the Fortran example is compared with the front end to 1e-9 relative */
      if (sc->metrics.enabled[k]) fprintf(f, ",\n  \"%s\": %.17g", wf_metric_names[k], jnum(m[k]));
  fputs("\n}\n", f);
  fclose(f);
}

/* ---- progress ---------------------------------------------------------------------------- */
double wf_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

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
  if (wf_par_rank() != 0) return; /* over MPI: rank 0's */
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
  if (p->tty && wf_par_rank() == 0) fputc('\n', stderr);
  p->last_print = -1e300;
}
