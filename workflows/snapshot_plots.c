/* Snapshot plots at given times (scene key `snapshot_plots`): during the run the state at
 * each requested time of a stage is kept as snap_<stage>_t<time>_<colour>.csv in the output
 * directory (the step before the time is shortened so that the run lands on it); at the end
 * gnuplot draws one PNG per time and one panel figure per entry, all with the same colour
 * range and the same axes, so that the pictures compare.  2D: the plane; 3D: a side view
 * onto the plane of the horizontal axis (the run-out axis, else x) and the vertical (the
 * gravity direction), near points drawn last, as in the final-state plots (plot.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "wf.h"

const char *const wf_color_names[WF_COLOR_COUNT + 1] = {"pressure", "mean_stress", "eps_p", "displacement", "speed", NULL};
static const char *const color_labels[WF_COLOR_COUNT] = {
    "pressure -tr(sigma)/3 [kPa]", "mean stress tr(sigma)/3 [kPa]", "equivalent plastic strain eps_p",
    "displacement |u| [m]", "speed |v| [m/s]"};

/* Time-window tolerance: a requested time counts as reached within round-off of it. */
static double tol_of(double t) { return 1e-9 * fmax(1.0, fabs(t)); }

/** @brief The next requested plot time of `stage` after t_stage (INFINITY: none). */
double wf_snapplots_next(const wf_scene *sc, int stage, double t_stage) {
  double next = INFINITY;
  for (int k = 0; k < sc->nsnapplot; ++k) {
    const wf_snapplot *p = &sc->snapplots[k];
    if (p->stage != stage) continue;
    for (int j = 0; j < p->ntimes; ++j)
      if (p->times[j] > t_stage + tol_of(p->times[j]) && p->times[j] < next) next = p->times[j];
  }
  return next;
}

static void csv_name(const wf_scene *sc, const wf_snapplot *p, int j, char *buf, size_t len) {
  snprintf(buf, len, "snap_%s_t%g_%s.csv", sc->stages[p->stage].name, p->times[j], wf_color_names[p->color]);
}

static int write_csv_fields(mpmc_sim sim, const wf_scene *sc, const wf_snapplot *p, const char *path, double t) {
  int np, e;
  double *x, *x0, *v, *sig, *eps = NULL;
  wf_all_count(sim, &np);
  if ((e = wf_root_field(sim, MPMC_FIELD_POSITION, &x, NULL)) ||
      (e = wf_root_field(sim, MPMC_FIELD_X0, &x0, NULL)) ||
      (e = wf_root_field(sim, MPMC_FIELD_VELOCITY, &v, NULL)) ||
      (e = wf_root_field(sim, MPMC_FIELD_STRESS, &sig, NULL)))
    return e;
  if (p->color == WF_COLOR_EPS_P && (e = wf_root_field(sim, MPMC_FIELD_EPS_P, &eps, NULL))) return e;
  if (wf_par_rank() != 0) return 0; /* over MPI: rank 0 writes (it gathered the points) */
  const int d = sc->dim;
  int hx, vy;
  wf_view_axes(sc, &hx, &vy);
  const int dz = 3 - hx - vy;
  wf_depth_idx *order = malloc(sizeof *order * (size_t)(np + 1));
  FILE *f = order ? fopen(path, "w") : NULL;
  if (!f) {
    free(order);
    return MPMC_ERR_IO;
  }
  for (int q = 0; q < np; ++q) {
    order[q].q = q;
    order[q].depth = d == 3 ? x[(size_t)q * 3 + dz] : 0.0;
  }
  if (d == 3) qsort(order, (size_t)np, sizeof *order, wf_by_depth);
  fprintf(f, "# %s at t = %.9g s of stage %s\n%c,%c,%s\n", wf_color_names[p->color], t, sc->stages[p->stage].name,
          "xyz"[hx], "xyz"[vy], wf_color_names[p->color]);
  for (int k = 0; k < np; ++k) {
    const size_t q = (size_t)order[k].q;
    double val = 0.0, a2 = 0.0;
    switch (p->color) {
      case WF_COLOR_PRESSURE: val = -(sig[q * 6] + sig[q * 6 + 1] + sig[q * 6 + 2]) / 3000.0; break;
      case WF_COLOR_MEAN_STRESS: val = (sig[q * 6] + sig[q * 6 + 1] + sig[q * 6 + 2]) / 3000.0; break;
      case WF_COLOR_EPS_P: val = eps[q]; break;
      case WF_COLOR_DISPLACEMENT:
        for (int a = 0; a < d; ++a) a2 += pow(x[q * d + a] - x0[q * d + a], 2);
        val = sqrt(a2);
        break;
      default:
        for (int a = 0; a < d; ++a) a2 += v[q * d + a] * v[q * d + a];
        val = sqrt(a2);
        break;
    }
    fprintf(f, "%.7g,%.7g,%.7g\n", x[q * d + hx], x[q * d + vy], val);
  }
  free(order);
  return fclose(f) ? MPMC_ERR_IO : 0;
}

/* write_csv_fields, the velocity and positions given back after (on loan, the velocity makes
 * the stability limit take a pass over the points, the positions cost each F-bar step a
 * copy: mpmc_sim_get_field) */
static int write_csv(mpmc_sim sim, const wf_scene *sc, const wf_snapplot *p, const char *path, double t) {
  const int e = write_csv_fields(sim, sc, p, path, t);
  double *v = NULL, *x = NULL;
  mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v);
  mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &x);
  return e;
}

/**
 * @brief Keep the state for every requested time of `stage` in (t_prev, t_stage].
 * @return 0, or an error code with a message in msg
 */
int wf_snapplots_step(mpmc_sim sim, const wf_scene *sc, const char *outdir, int stage, double t_prev,
                      double t_stage, char *msg, size_t len) {
  for (int k = 0; k < sc->nsnapplot; ++k) {
    const wf_snapplot *p = &sc->snapplots[k];
    if (p->stage != stage) continue;
    for (int j = 0; j < p->ntimes; ++j) {
      const double tj = p->times[j], tol = tol_of(tj);
      if (!(t_prev < tj - tol && t_stage >= tj - tol)) continue;
      char name[WF_NAME * 2 + 64], path[WF_PATH + WF_NAME * 2 + 64];
      csv_name(sc, p, j, name, sizeof name);
      snprintf(path, sizeof path, "%s/%s", outdir, name);
      const int e = wf_par_agree(write_csv(sim, sc, p, path, t_stage)); /* rank 0 writes */
      if (e) {
        snprintf(msg, len, "snapshot_plots.%d: cannot write %s", k, path);
        return e;
      }
    }
  }
  return 0;
}

static int exists(const char *path) {
  struct stat s;
  return stat(path, &s) == 0;
}

/**
 * @brief Draw the PNGs of every snapshot kept in outdir: snapshot_<stage>_t<time>_<colour>.png
 *        and, per entry, snapshots_<stage>_<colour>.png with all its times as panels.
 * @return 0, or 1 with a warning in warn (gnuplot missing or failed, times never reached)
 */
int wf_snapplots_plot(const wf_scene *sc, const char *outdir, char *warn, size_t len) {
  if (sc->nsnapplot == 0) return 0;
  FILE *g = wf_gnuplot_open(outdir, "snapshot_plots.log", "snapshot plots",
                            "no snapshot PNGs, the data is in snap_*.csv", warn, len);
  if (!g) return 1;
  int missing = 0;
  fprintf(g, "set grid\n");
  int hx, vy;
  wf_view_axes(sc, &hx, &vy);
  for (int k = 0; k < sc->nsnapplot; ++k) {
    const wf_snapplot *p = &sc->snapplots[k];
    const char *stage = sc->stages[p->stage].name, *col = wf_color_names[p->color];
    char files[64][WF_NAME * 2 + 64];
    double when[64];
    int n = 0;
    for (int j = 0; j < p->ntimes && n < 64; ++j) {
      char path[WF_PATH + WF_NAME * 2 + 64];
      csv_name(sc, p, j, files[n], sizeof files[n]);
      snprintf(path, sizeof path, "%s/%s", outdir, files[n]);
      if (!exists(path)) {
        ++missing;
        continue;
      }
      when[n++] = p->times[j];
    }
    if (n == 0) continue;
    /* one colour range and one frame for all the times of this entry */
    fprintf(g, "vlo = 1e300; vhi = -1e300; xlo = 1e300; xhi = -1e300; ylo = 1e300; yhi = -1e300\n");
    for (int j = 0; j < n; ++j)
      fprintf(g, "stats '%s' skip 2 using 1:2 nooutput\nxlo = (STATS_min_x < xlo) ? STATS_min_x : xlo; "
                 "xhi = (STATS_max_x > xhi) ? STATS_max_x : xhi; ylo = (STATS_min_y < ylo) ? STATS_min_y : ylo; "
                 "yhi = (STATS_max_y > yhi) ? STATS_max_y : yhi\n"
                 "stats '%s' skip 2 using 3 nooutput\nvlo = (STATS_min < vlo) ? STATS_min : vlo; "
                 "vhi = (STATS_max > vhi) ? STATS_max : vhi\n",
              files[j], files[j]);
    if (p->has_range)
      fprintf(g, "vlo = %.9g; vhi = %.9g\n", p->range[0], p->range[1]);
    fprintf(g, "if (vhi <= vlo) { vhi = vlo + 1 }\npad = 0.03 * ((xhi - xlo) > (yhi - ylo) ? (xhi - xlo) : (yhi - ylo))\n"
               "set xrange [xlo - pad : xhi + pad]\nset yrange [ylo - pad : yhi + pad]\nset cbrange [vlo : vhi]\n");
    fprintf(g, "set size ratio -1\nset xlabel '%c [m]'\nset ylabel '%c [m]'\nset cblabel '%s' noenhanced\n", "xyz"[hx],
            "xyz"[vy], color_labels[p->color]);
    for (int j = 0; j < n; ++j) {
      wf_gnuplot_terminal(g, 1200, 800, 12);
      fprintf(g, "set output 'snapshot_%s_t%g_%s.png'\n", stage, when[j], col);
      fprintf(g, "set title '%s%s: %s at t = %g s of stage %s' noenhanced\n", sc->name, sc->dim == 3 ? " (side view)" : "",
              col, when[j], stage);
      fprintf(g, "plot '%s' skip 2 using 1:2:3 with points pt 7 ps 0.4 lc palette notitle\n", files[j]);
    }
    const int cols = n < 2 ? 1 : 2, rows = (n + cols - 1) / cols;
    wf_gnuplot_terminal(g, 900 * cols, 600 * rows, 11);
    fprintf(g, "set output 'snapshots_%s_%s.png'\nset multiplot layout %d,%d title '%s: %s, stage %s' noenhanced\n", stage, col,
            rows, cols, sc->name, col, stage);
    for (int j = 0; j < n; ++j)
      fprintf(g, "set title 't = %g s'\nplot '%s' skip 2 using 1:2:3 with points pt 7 ps 0.3 lc palette notitle\n", when[j],
              files[j]);
    fprintf(g, "unset multiplot\nset output\n");
  }
  if (wf_gnuplot_close(g, outdir, "snapshot_plots.log", warn, len)) return 1;
  if (missing) {
    snprintf(warn, len, "%d requested snapshot time(s) were never reached (after the stage's end?)", missing);
    return 1;
  }
  return 0;
}
