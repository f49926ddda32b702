/* PNG plots with gnuplot, run as a child process: the final state coloured by mean stress
 * and by equivalent plastic strain (2D: the plane; 3D: a side projection onto the plane of
 * the run-out axis and the vertical), and the time series.  The final state is also kept
 * as final_state.csv.  A missing gnuplot is a warning, never a failure of the run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "wf.h"

/** @brief qsort order of wf_depth_idx: far points (large depth) first, near ones drawn last. */
int wf_by_depth(const void *a, const void *b) {
  const double da = ((const wf_depth_idx *)a)->depth, db = ((const wf_depth_idx *)b)->depth;
  return da < db ? 1 : da > db ? -1 : 0;
}

/**
 * @brief The plots' axes: vy the vertical (2D: y; 3D: the largest gravity component of the
 *        stages that set gravity, z without), hx the horizontal (the run-out axis, else x, or
 *        y when x is vertical).
 */
void wf_view_axes(const wf_scene *sc, int *hx, int *vy) {
  int v = sc->dim == 2 ? 1 : 2;
  for (int i = 0; i < sc->nstage && sc->dim == 3; ++i) {
    if (!sc->stages[i].has_gravity) continue;
    double best = 0;
    for (int a = 0; a < sc->dim; ++a)
      if (fabs(sc->stages[i].gravity[a]) > best) {
        best = fabs(sc->stages[i].gravity[a]);
        v = a;
      }
  }
  *vy = v;
  *hx = sc->metrics.enabled[WF_METRIC_RUNOUT] ? sc->metrics.runout_axis : 0;
  if (*hx == *vy) *hx = *vy == 0 ? 1 : 0;
}

/* The phreatic line over the grid's width as gnuplot's $water table, where the view is along
 * x (a polyline water table); the plot clause that draws it, or "". */
static const char *water_line(FILE *g, const wf_scene *sc, int hx) {
  if (!sc->water.n || hx != 0) return "";
  const wf_water *wt = &sc->water;
  fprintf(g, "$water << EOD\n%.9g,%.9g\n", sc->lo[0], wt->xh[1]);
  for (int k = 0; k < wt->n; ++k) fprintf(g, "%.9g,%.9g\n", wt->xh[2 * k], wt->xh[2 * k + 1]);
  fprintf(g, "%.9g,%.9g\nEOD\n", sc->hi[0], wt->xh[2 * wt->n - 1]);
  return ", $water using 1:2 with lines lw 2 lc rgb '#1f78b4' title 'water table'";
}

/* The points' state in final_state.csv's columns into path, far points first in 3D (looking
 * along the axis other than hx and vy); the displacement from the initial positions
 * (MPMC_FIELD_X0).  *has_eps: an eps_p column with values.  0, or -1.  Over MPI the points
 * are gathered on rank 0, which writes. */
static int write_state(mpmc_sim sim, const wf_scene *sc, const char *path, int hx, int vy, int *has_eps) {
  int np = 0;
  double *x, *x0, *sig, *eps = NULL;
  if (wf_all_count(sim, &np) || wf_root_field(sim, MPMC_FIELD_POSITION, &x, NULL) ||
      wf_root_field(sim, MPMC_FIELD_X0, &x0, NULL) || wf_root_field(sim, MPMC_FIELD_STRESS, &sig, NULL))
    return -1;
  int plastic = 0;
  for (int i = 0; i < sc->nmat; ++i) plastic |= wf_model_plastic(sc->mats[i].model);
  if (plastic && wf_root_field(sim, MPMC_FIELD_EPS_P, &eps, NULL)) eps = NULL;
  *has_eps = eps != NULL;
  /* the return region of the frictional models (docs/materials.md), last column */
  double *region = NULL;
  if (wf_root_field(sim, MPMC_FIELD_REGION, &region, NULL)) region = NULL;
  /* the water table's pore pressure, after it */
  double *pw = NULL;
  if ((!sc->water.n && !sc->water.has_plane) || wf_root_field(sim, MPMC_FIELD_PORE_PRESSURE, &pw, NULL)) pw = NULL;
  if (wf_par_rank() != 0) return 0; /* over MPI: rank 0 writes (it gathered the points) */
  const int d = sc->dim;
  wf_depth_idx *order = malloc(sizeof *order * (size_t)(np + 1));
  FILE *f = fopen(path, "w");
  if (!order || !f) {
    free(order);
    if (f) fclose(f);
    return -1;
  }
  const int dz = 3 - hx - vy; /* 3D: the axis the projection looks along */
  for (int q = 0; q < np; ++q) {
    order[q].q = q;
    order[q].depth = d == 3 ? x[(size_t)q * 3 + dz] : 0.0;
  }
  if (d == 3) qsort(order, (size_t)np, sizeof *order, wf_by_depth);
  fprintf(f, "%s%s%s\n", d == 3 ? "x,y,z,mean_stress,eps_p,ux,uy,uz" : "x,y,mean_stress,eps_p,ux,uy",
          region ? ",region" : "", pw ? ",pore_pressure" : "");
  for (int k = 0; k < np; ++k) {
    const size_t q = (size_t)order[k].q;
    const double p = (sig[q * 6] + sig[q * 6 + 1] + sig[q * 6 + 2]) / 3.0;
    const double *ref = x0 + q * d;
    for (int a = 0; a < d; ++a) fprintf(f, "%.7g,", x[q * d + a]);
    fprintf(f, "%.7g,%.7g", p, eps ? eps[q] : 0.0);
    for (int a = 0; a < d; ++a) fprintf(f, ",%.7g", x[q * d + a] - ref[a]);
    if (region) fprintf(f, ",%d", (int)region[q]);
    if (pw) fprintf(f, ",%.7g", pw[q]);
    fputc('\n', f);
  }
  free(order);
  return fclose(f) ? -1 : 0;
}

/* bearing.png: q/su against delta/B from series.csv with Prandtl's 2 + pi (rigid.c) */
static void plot_bearing(FILE *g, const wf_scene *sc) {
  int col = 7;
  for (int k = 0; k < WF_METRIC_SETTLEMENT_B; ++k) col += sc->metrics.enabled[k];
  fprintf(g, "set output 'bearing.png'\nset xlabel 'settlement delta / B'\nset ylabel 'q / su' noenhanced\n"
             "set title '%s: load-settlement curve of the footing' noenhanced\nset key bottom right\n"
             "set yrange [0:*]\n", sc->name);
  fprintf(g, "plot 'series.csv' skip 1 using %d:%d with linespoints lw 2 pt 7 ps 0.4 title 'q/su (mean over each row)', "
             "2 + pi with lines dt 2 lw 2 lc rgb 'black' title 'Prandtl: 2 + pi = 5.14'\n",
          col, col + 1);
  fprintf(g, "set autoscale y\nset key default\n"); /* leave the settings as found */
}

/* ---- gnuplot, for plot.c and snapshot_plots.c ------------------------------------------- */

/**
 * @brief Start gnuplot as a child drawing into outdir (its output to outdir/log), set up with
 *        CSV input and the colour palette.  NULL with a warning in warn when it cannot run:
 *        outdir holds quote characters, gnuplot is missing (nopng: what the run has
 *        instead, for the warning), or it does not start.  what: "plots" or the like.
 */
FILE *wf_gnuplot_open(const char *outdir, const char *log, const char *what, const char *nopng, char *warn,
                      size_t len) {
  if (strpbrk(outdir, "\"'\\`$")) {
    snprintf(warn, len, "output path has quote characters; %s skipped", what);
    return NULL;
  }
  if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
    snprintf(warn, len, "gnuplot not found (Debian package gnuplot-nox): %s", nopng);
    return NULL;
  }
  char cmd[WF_PATH + 64];
  snprintf(cmd, sizeof cmd, "gnuplot >'%s/%s' 2>&1", outdir, log);
  FILE *g = popen(cmd, "w");
  if (!g) {
    snprintf(warn, len, "cannot start gnuplot");
    return NULL;
  }
  fprintf(g, "cd \"%s\"\nset datafile separator ','\n", outdir);
  fprintf(g, "set palette defined (0 '#313695', 1 '#4575b4', 2 '#74add1', 3 '#abd9e9', 4 '#fee090', "
             "5 '#fdae61', 6 '#f46d43', 7 '#d73027', 8 '#a50026')\n");
  return g;
}

/** @brief The PNG terminal at width x height pixels (pngcairo where gnuplot has it). */
void wf_gnuplot_terminal(FILE *g, int width, int height, int font) {
  fprintf(g, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size %d,%d font ',%d' } "
             "else { set terminal png size %d,%d }\n",
          width, height, font, width, height);
}

/** @brief Wait for gnuplot: 0, or 1 with a warning naming outdir/log when it failed. */
int wf_gnuplot_close(FILE *g, const char *outdir, const char *log, char *warn, size_t len) {
  const int st = pclose(g);
  if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
    snprintf(warn, len, "gnuplot failed (see %s/%s)", outdir, log);
    return 1;
  }
  return 0;
}

/** @brief Write final_state.csv and the PNG plots into outdir. */
int wf_plots_write(mpmc_sim sim, const wf_scene *sc, const char *outdir, char *warn, size_t len) {
  int hx, vy;
  wf_view_axes(sc, &hx, &vy);
  char path[WF_PATH + 32];
  int has_eps = 0;
  snprintf(path, sizeof path, "%s/final_state.csv", outdir);
  if (write_state(sim, sc, path, hx, vy, &has_eps)) {
    snprintf(warn, len, "cannot write %s", path);
    return 1;
  }
  if (wf_par_rank() != 0) return 0;
  FILE *g = wf_gnuplot_open(outdir, "plots.log", "plots",
                            "no PNG plots, the data is in final_state.csv and series.csv", warn, len);
  if (!g) return 1;
  const char *ax = "xyz";
  double t = 0;
  mpmc_sim_get_time(sim, &t);
  const int d = sc->dim;
  /* columns of final_state.csv: coordinates, mean stress, eps_p */
  const int cx = hx + 1, cy = vy + 1, cp = d + 1, ce = d + 2;
  wf_gnuplot_terminal(g, 1400, 700, 12);
  const char *water = water_line(g, sc, hx);
  fprintf(g, "set size ratio -1\nset xlabel '%c [m]'\nset ylabel '%c [m]'\nset grid\n", ax[hx], ax[vy]);
  fprintf(g, "set output 'final_mean_stress.png'\n");
  fprintf(g, "set title '%s%s: mean stress p = tr(sigma)/3 [kPa] at t = %.3f s (tension > 0)' noenhanced\n", sc->name,
          d == 3 ? " (side view)" : "", t);
  fprintf(g, "set cblabel 'p [kPa]'\n");
  fprintf(g, "plot 'final_state.csv' skip 1 using %d:%d:($%d/1000) with points pt 7 ps 0.35 lc palette notitle%s\n",
          cx, cy, cp, water);
  if (has_eps) {
    fprintf(g, "set output 'final_eps_p.png'\n");
    fprintf(g, "set title '%s%s: equivalent plastic strain at t = %.3f s' noenhanced\nset cblabel 'eps_p' noenhanced\nset cbrange [0:*]\n",
            sc->name, d == 3 ? " (side view)" : "", t);
    fprintf(g, "plot 'final_state.csv' skip 1 using %d:%d:%d with points pt 7 ps 0.35 lc palette notitle%s\n", cx, cy,
            ce, water);
    fprintf(g, "set cbrange [*:*]\n");
  }
  /* time series: kinetic energy and the scene's metrics */
  fprintf(g, "unset size\nset size noratio\nset output 'series.png'\nset multiplot layout 2,1 title '%s: time series' noenhanced\n",
          sc->name);
  fprintf(g, "set xlabel 'time [s]'\nset ylabel 'kinetic energy [J%s]'\nset logscale y\nset title ''\n",
          d == 2 ? "/m" : "");
  fprintf(g, "plot 'series.csv' skip 1 using 2:($5 > 0 ? $5 : NaN) with lines lw 2 title 'E_k'\n");
  fprintf(g, "unset logscale y\n");
  int col = 7, any = 0;
  for (int k = 0; k < WF_METRIC_COUNT; ++k) {
    if (!sc->metrics.enabled[k]) continue;
    fprintf(g, "%s 'series.csv' skip 1 using 2:%d with lines lw 2 title '%s'", any ? "," : "set ylabel 'metric [m]'\nset key noenhanced\nplot",
            col++, wf_metric_names[k]);
    any = 1;
  }
  if (!any) fprintf(g, "plot 'series.csv' skip 1 using 2:6 with lines lw 2 title 'E_k / E_k,max'");
  fprintf(g, "\nunset multiplot\n");
  if (sc->metrics.enabled[WF_METRIC_BEARING]) plot_bearing(g, sc);
  return wf_gnuplot_close(g, outdir, "plots.log", warn, len);
}

/* ---- the factor-of-safety search's plots (fos.c) ---------------------------------------- */

/**
 * @brief The state at a trial's end in final_state.csv's columns, the displacement measured
 *        from the trial's start (the trial sets the points' initial positions to those of
 *        its base state: fos.c), into path.  0, or -1.
 */
int wf_fos_mechanism_write(mpmc_sim sim, const wf_scene *sc, const char *path) {
  int hx, vy;
  wf_view_axes(sc, &hx, &vy);
  int has_eps;
  return write_state(sim, sc, path, hx, vy, &has_eps);
}

/**
 * @brief fos_trials.png (each trial's largest displacement against F, the limit, the final
 *        bracket) and, when res->mechanism, fos_mechanism.png (|u| since the trial's start and
 *        eps_p at the end of the trial at the smallest failing factor) into outdir; gnuplot's
 *        output in outdir/fos_plots.log.  0, or 1 with a warning.
 */
int wf_fos_plots(const wf_scene *sc, int stage, const wf_fos_result *res, const char *outdir, char *warn,
                 size_t len) {
  const wf_fos *fs = &sc->stages[stage].fos;
  FILE *g = wf_gnuplot_open(outdir, "fos_plots.log", "factor-of-safety plots",
                            "no PNG plots of the search, the data is in fos_trials.csv and fos_mechanism.csv", warn,
                            len);
  if (!g) return 1;
  const double fos = 0.5 * (res->lo + res->hi);
  /* F against the criterion */
  wf_gnuplot_terminal(g, 1200, 800, 12);
  fprintf(g, "set output 'fos_trials.png'\nset title '%s: factor-of-safety search, %d trials (%d at once)%s' "
             "noenhanced\n",
          sc->name, res->ntrial, res->jobs, res->found ? "" : ", no bracket");
  fprintf(g, "set xlabel 'strength reduction factor F'\nset ylabel 'largest displacement in the trial [m]'\n"
             "set logscale y\nset grid\nset key bottom right box opaque noenhanced\n");
  fprintf(g, "set object 1 rectangle from %.9g, graph 0 to %.9g, graph 1 fillcolor rgb '#fdae61' "
             "fillstyle solid 0.6 noborder behind\n",
          res->lo, res->hi);
  fprintf(g, "set arrow 1 from %.9g, graph 0 to %.9g, graph 1 nohead lw 1 lc rgb '#f46d43'\n"
             "set arrow 2 from %.9g, graph 0 to %.9g, graph 1 nohead lw 1 lc rgb '#f46d43'\n",
          res->lo, res->lo, res->hi, res->hi);
  fprintf(g, "plot 'fos_trials.csv' skip 1 using 2:(strcol(3) eq 'stands' && $4 > 0 ? $4 : NaN) with points "
             "pt 7 ps 1.6 lc rgb '#1a9850' title 'stands', "
             "'' skip 1 using 2:(strcol(3) eq 'fails' && $4 > 0 ? $4 : NaN) with points pt 5 ps 1.6 "
             "lc rgb '#d73027' title 'fails', "
             "%.9g with lines dt 2 lw 2 lc rgb 'black' title 'displacement limit %g m', "
             "NaN with boxes fillcolor rgb '#fdae61' fillstyle solid 0.6 noborder title '%s [%.4g, %.4g]: F = %.4g'\n",
          fs->displacement_limit, fs->displacement_limit, res->found ? "final bracket" : "last bracket", res->lo,
          res->hi, fos);
  fprintf(g, "unset object 1\nunset arrow 1\nunset arrow 2\nunset logscale y\nset key default\n");
  if (res->mechanism) {
    double t = 0.0;
    for (int i = 0; i < res->ntrial; ++i)
      if (res->trial[i].factor == res->hi) t = res->trial[i].sim_time;
    int hx, vy;
    wf_view_axes(sc, &hx, &vy);
    const int d = sc->dim, cx = hx + 1, cy = vy + 1, ce = d + 2, cu = d + 3;
    const char *ax = "xyz", *water = water_line(g, sc, hx);
    char umag[96];
    if (d == 3)
      snprintf(umag, sizeof umag, "(sqrt($%d**2 + $%d**2 + $%d**2))", cu, cu + 1, cu + 2);
    else
      snprintf(umag, sizeof umag, "(sqrt($%d**2 + $%d**2))", cu, cu + 1);
    wf_gnuplot_terminal(g, 1400, 1000, 12);
    fprintf(g, "set output 'fos_mechanism.png'\nset size ratio -1\nset grid\nset xlabel '%c [m]'\nset ylabel '%c [m]'\n"
               "set cbrange [0:*]\n",
            ax[hx], ax[vy]);
    fprintf(g, "set multiplot layout 2,1 title '%s%s: the mechanism, at the end (t = %.3g s) of the trial at the "
               "smallest failing factor F = %.4g' noenhanced\n",
            sc->name, d == 3 ? " (side view)" : "", t, res->hi);
    fprintf(g, "set title 'displacement since the trial start |u| [m]'\nset cblabel '|u| [m]'\n"
               "plot 'fos_mechanism.csv' skip 1 using %d:%d:%s with points pt 7 ps 0.35 lc palette notitle%s\n",
            cx, cy, umag, water);
    fprintf(g, "set title 'equivalent plastic strain'\nset cblabel 'eps_p' noenhanced\n"
               "plot 'fos_mechanism.csv' skip 1 using %d:%d:%d with points pt 7 ps 0.35 lc palette notitle%s\n",
            cx, cy, ce, water);
    fprintf(g, "unset multiplot\nset cbrange [*:*]\n");
  }
  return wf_gnuplot_close(g, outdir, "fos_plots.log", warn, len);
}
