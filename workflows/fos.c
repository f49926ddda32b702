/* The factor-of-safety search of a `factor_of_safety` stage (docs/workflows.md): the state at
 * the stage's start (after gravity initialisation) is saved once; each trial factor F starts
 * from it, divides every plastic material's strengths by F (mpmc_sim_set_strength_reduction:
 * kappa for J2; c, tan phi, tan psi for the frictional models), and runs the stage's time
 * with its damping.  The verdict, on the largest displacement d(t) of a point since the
 * trial's start (lengths and simulated times only, so that it does not depend on the time
 * step): the trial fails when d exceeds the stage's displacement_limit, or when d still grows
 * at the end, by more than the fraction `growth` of d(T) over the last quarter of the trial
 * (a slope that keeps moving has not found equilibrium; a stable one settles, its d
 * converging).  The first
 * bracket is widened (lo / 1.5, hi x 1.5) until lo stands and hi fails, then bisected until
 * hi - lo <= tolerance.  The factor of safety reported is the bracket's midpoint.
 *
 * Concurrent trials (`jobs: k`): each round runs k trials at once, each in a child process
 * (fork) that opens fos_base.h5 itself, runs its trial exactly as a search with one job does
 * (same factor, same bits), writes its wf_fos_trial into a pipe and leaves with _exit; the
 * parent reports the round's trials in factor order.  A round places its k factors evenly
 * inside the bracket (k = 1: bisection; k = 2: trisection), the first evaluates lo and hi
 * together.  No HDF5 file is open in the parent at a fork (snapshots and checkpoints open and
 * close theirs per write), and the child never returns into the parent's code. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "wf.h"

#define FOS_CHECK_EVERY 20 /* steps between displacement checks (a trial stops when it fails) */

/* largest |x - x0| over the points, x0 their positions at the trial's start (open_trial);
 * over MPI the largest over the ranks (each its own points: nothing is gathered) */
static double max_displacement(mpmc_sim sim, int dim) {
  static const int fields[2] = {MPMC_FIELD_POSITION, MPMC_FIELD_X0};
  double *f[2];
  int n = 0;
  if (wf_own(sim, &n, 2, fields, f, NULL, NULL)) return NAN;
  double *x = f[0];
  const double *x0 = f[1];
  double m = 0.0;
  for (int q = 0; q < n; ++q) {
    double d2 = 0.0;
    for (int a = 0; a < dim; ++a) {
      const double dx = x[(size_t)q * dim + a] - x0[(size_t)q * dim + a];
      d2 += dx * dx;
    }
    if (d2 > m) m = d2;
  }
  mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &x); /* on loan it costs each F-bar step a copy */
  return sqrt(wf_par_max(m));
}

/* The base state with the strengths divided by F, in *sim, each point's initial position
 * (MPMC_FIELD_X0) set to its position in the base state: displacements count from the
 * trial's start, and travel with the points across ranks. */
static int open_trial(mpmc_context ctx, const char *base, const wf_scene *sc, double F, mpmc_sim *sim) {
  char *meta = NULL;
  int e = wf_par_checkpoint_read(ctx, base, sim, &meta);
  mpmc_free(meta);
  if (e) return e;
  if (!e) e = mpmc_sim_set_threads(*sim, sc->threads);
  if (!e) e = mpmc_sim_set_sort_interval(*sim, sc->sort_interval);
  if (!e) e = mpmc_sim_set_strength_reduction(*sim, -1, F);
  static const int fields[2] = {MPMC_FIELD_POSITION, MPMC_FIELD_X0};
  double *f[2] = {NULL, NULL};
  int n = 0;
  if (!e) e = wf_own(*sim, &n, 2, fields, f, NULL, NULL);
  if (!e && n > 0) memcpy(f[1], f[0], sizeof(double) * (size_t)n * (size_t)sc->dim);
  if (f[0]) mpmc_sim_restore_field(*sim, MPMC_FIELD_POSITION, &f[0]);
  if (e) mpmc_sim_destroy(sim);
  return e;
}

/* One trial: the stage's time at factor F from the base state.  A failing trial leaves its
 * final state in the CSV mech (when not NULL; the mechanism, fos_mechanism.csv). */
static int run_trial(mpmc_context ctx, const char *base, const wf_scene *sc, const wf_stage *s, double F,
                     const char *mech, wf_fos_trial *t, char *msg, size_t len) {
  const double w0 = wf_now();
  mpmc_sim sim = NULL;
  int e = open_trial(ctx, base, sc, F, &sim);
  if (e) {
    snprintf(msg, len, "trial F = %g: cannot start from %s: %s", F, base, mpmc_context_last_error(ctx));
    return e;
  }
  *t = (wf_fos_trial){.factor = F};
  const double T = s->end_time, limit = s->fos.displacement_limit;
  double ts = 0.0, dt = s->dt, ke = 0.0, ke_max = 0.0, disp = 0.0, d75 = -1.0;
  long steps = 0;
  while (ts < T * (1 - 1e-9)) {
    if (s->dt <= 0 && (steps % 10 == 0)) e = mpmc_sim_stable_dt(sim, s->dt_factor, &dt);
    double h = dt;
    if (ts + h > T) h = T - ts;
    if (!e) e = mpmc_sim_step(sim, h);
    if (e) break;
    ts += h;
    ++steps;
    if (steps % FOS_CHECK_EVERY == 0 || ts >= T * (1 - 1e-9)) {
      mpmc_sim_get_kinetic_energy(sim, &ke);
      if (ke > ke_max) ke_max = ke;
      disp = max_displacement(sim, sc->dim);
      if (!(disp <= limit)) break; /* failed: no need to go on */
      if (d75 < 0 && ts >= 0.75 * T) d75 = disp;
    }
  }
  if (e) {
    /* a numerical failure of a trial is reported, not taken for a verdict */
    snprintf(msg, len, "trial F = %g at t = %g s of %g: %s", F, ts, T, mpmc_context_last_error(ctx));
  } else {
    t->max_displacement = disp;
    t->growth = d75 >= 0 && disp > 0 ? (disp - d75) / disp : 0.0;
    t->failed = !(disp <= limit) || t->growth > s->fos.growth;
    t->ke_ratio = ke_max > 0 ? ke / ke_max : 0.0;
    t->sim_time = ts;
    t->steps = steps;
  }
  t->wall_seconds = wf_now() - w0;
  if (!e && t->failed && mech) wf_fos_mechanism_write(sim, sc, mech); /* no file: no mechanism plot */
  mpmc_sim_destroy(&sim);
  return e;
}

/* What a child process sends back through its pipe: the trial, or the error that stopped it */
typedef struct {
  wf_fos_trial t;
  int e;
  char msg[1024];
} trial_report;

static void mech_path(char *buf, size_t n, const char *outdir, int trial) {
  snprintf(buf, n, "%s/fos_trial_%d.csv", outdir, trial);
}

/* read exactly n bytes (fewer: the writer ended first) */
static size_t read_all(int fd, void *buf, size_t n) {
  size_t got = 0;
  while (got < n) {
    const ssize_t r = read(fd, (char *)buf + got, n - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    got += (size_t)r;
  }
  return got;
}

/* The k trials F[0..k) into t[0..k), trial numbers first + j: in this process when k = 1, else
 * at once in k child processes.  0, or the first error (by factor) with msg naming the factor. */
static int run_round(mpmc_context ctx, const char *base, const wf_scene *sc, const wf_stage *s, const char *outdir,
                     const double *F, int k, int first, wf_fos_trial *t, char *msg, size_t len) {
  char mech[WF_PATH + 32];
  if (k == 1) {
    mech_path(mech, sizeof mech, outdir, first);
    return run_trial(ctx, base, sc, s, F[0], mech, &t[0], msg, len);
  }
  pid_t pid[WF_FOS_MAX_JOBS];
  int fd[WF_FOS_MAX_JOBS], started = 0, e = 0;
  fflush(NULL); /* nothing buffered twice (a child leaves by _exit, which does not flush) */
  for (int j = 0; j < k; ++j) {
    int p[2];
    if (pipe(p)) {
      e = MPMC_ERR_IO;
      snprintf(msg, len, "trial F = %g: cannot create a pipe: %s", F[j], strerror(errno));
      break;
    }
    const pid_t c = fork();
    if (c < 0) {
      e = MPMC_ERR_IO;
      snprintf(msg, len, "trial F = %g: cannot start its process: %s", F[j], strerror(errno));
      close(p[0]);
      close(p[1]);
      break;
    }
    if (c == 0) {
      /* the child: its own trial from fos_base.h5, the report, _exit (no atexit handlers:
       * the parent's HDF5 library state and stdio buffers are the parent's to close) */
      close(p[0]);
      for (int i = 0; i < started; ++i) close(fd[i]);
      trial_report r;
      memset(&r, 0, sizeof r);
      mech_path(mech, sizeof mech, outdir, first + j);
      r.e = run_trial(ctx, base, sc, s, F[j], mech, &r.t, r.msg, sizeof r.msg);
      const char *b = (const char *)&r;
      size_t left = sizeof r;
      while (left > 0) {
        const ssize_t w = write(p[1], b, left);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) _exit(2);
        b += w;
        left -= (size_t)w;
      }
      _exit(0);
    }
    close(p[1]);
    pid[started] = c;
    fd[started++] = p[0];
  }
  /* every child started is read and waited for, also after an error */
  for (int j = 0; j < started; ++j) {
    trial_report r;
    const size_t got = read_all(fd[j], &r, sizeof r);
    close(fd[j]);
    int st = 0;
    while (waitpid(pid[j], &st, 0) < 0 && errno == EINTR) {
    }
    if (e) continue;
    if (got != sizeof r || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
      e = MPMC_ERR_IO;
      if (WIFSIGNALED(st))
        snprintf(msg, len, "trial F = %g: its process (pid %ld) died of signal %d (%s)", F[j], (long)pid[j],
                 WTERMSIG(st), strsignal(WTERMSIG(st)));
      else
        snprintf(msg, len, "trial F = %g: its process (pid %ld) ended (exit status %d) without its result", F[j],
                 (long)pid[j], WIFEXITED(st) ? WEXITSTATUS(st) : -1);
    } else if (r.e) {
      e = r.e;
      r.msg[sizeof r.msg - 1] = '\0';
      snprintf(msg, len, "%s", r.msg);
    } else {
      t[j] = r.t;
    }
  }
  return e;
}

int wf_fos_search(mpmc_context ctx, mpmc_sim sim, const wf_scene *sc, int stage, const char *outdir,
                  wf_fos_result *res, void (*say)(void *data, const char *line), void *data, char *msg,
                  size_t len) {
  const wf_stage *s = &sc->stages[stage];
  const wf_fos *f = &s->fos;
  /* over MPI the trials run one after the other, each over all the ranks */
  const int jobs = wf_par_size() > 1 ? 1 : wf_fos_jobs(f);
  char base[WF_PATH + 32], path[WF_PATH + 32], line[512];
  if (jobs > 1 && sc->threads != 1) {
    /* OpenMP's thread pool does not survive a fork; one thread per trial process anyway */
    snprintf(msg, len, "factor_of_safety.jobs = %d runs trials in processes of one thread each: set threads: 1 "
                       "(got %d)", jobs, sc->threads);
    return MPMC_ERR_ARG;
  }
  /* this search's pictures, not an earlier run's */
  static const char *const old[] = {"fos_mechanism.csv", "fos_mechanism.png", "fos_trials.png", NULL};
  for (int i = 0; old[i] && wf_par_rank() == 0; ++i) {
    snprintf(path, sizeof path, "%s/%s", outdir, old[i]);
    remove(path);
  }
  snprintf(base, sizeof base, "%s/fos_base.h5", outdir);
  int e = mpmc_sim_checkpoint_write(sim, base, "mpmc-workflow fos base");
  if (e) {
    snprintf(msg, len, "cannot save the search's starting state: %s", mpmc_context_last_error(ctx));
    return e;
  }
  memset(res, 0, sizeof *res);
  res->jobs = jobs;
  double lo = f->lo, hi = f->hi;
  int lo_ok = 0, hi_ok = 0; /* lo known to stand, hi known to fail */
  for (;;) {
    double F[WF_FOS_MAX_JOBS];
    int k = 0;
    const int room = f->max_trials - res->ntrial, bracketing = !lo_ok || !hi_ok;
    if (room <= 0) break;
    if (bracketing) {
      if (!lo_ok) F[k++] = lo;
      if (!hi_ok && (k == 0 || (jobs > 1 && room > 1))) F[k++] = hi;
    } else if (hi - lo > f->tolerance) {
      /* k evenly inside the bracket: as many as the jobs, or fewer when they reach the tolerance */
      k = jobs < room ? jobs : room;
      for (int m = 1; m < k; ++m)
        if ((hi - lo) / (m + 1) <= f->tolerance) {
          k = m;
          break;
        }
      for (int j = 0; j < k; ++j) F[j] = k == 1 ? 0.5 * (lo + hi) : lo + (hi - lo) * (j + 1) / (k + 1);
    } else {
      break;
    }
    wf_fos_trial *t = &res->trial[res->ntrial];
    const int first = res->ntrial + 1;
    e = run_round(ctx, base, sc, s, outdir, F, k, first, t, msg, len);
    if (e) {
      for (int j = 0; j < k && wf_par_rank() == 0; ++j) {
        mech_path(path, sizeof path, outdir, first + j);
        remove(path);
      }
      return e;
    }
    for (int j = 0; j < k; ++j) {
      snprintf(line, sizeof line,
               "factor of safety: trial %d, F = %.4f: %s (largest displacement %.4g m, limit %g m; grew %.3g "
               "of it over the last quarter, limit %g; E_k/E_k,max %.3g; %ld steps, %.1f s)",
               first + j, F[j], t[j].failed ? "fails" : "stands", t[j].max_displacement, f->displacement_limit,
               t[j].growth, f->growth, t[j].ke_ratio, t[j].steps, t[j].wall_seconds);
      if (say) say(data, line);
    }
    res->ntrial += k;
    int hi_from = -1; /* the trial of this round that became hi */
    if (bracketing) {
      const wf_fos_trial *tl = !lo_ok ? &t[0] : NULL, *th = !hi_ok && k > (tl != NULL) ? &t[k - 1] : NULL;
      if (tl && tl->failed) {
        hi = lo, hi_ok = 1; /* the lower guess fails: it bounds from above, look lower */
        lo = lo / 1.5;
        hi_from = 0;
      } else {
        if (tl) lo_ok = 1;
        if (th && th->failed) {
          hi_ok = 1;
          hi_from = k - 1;
        } else if (th) {
          lo = hi, lo_ok = 1; /* stands: widen upwards */
          hi = hi * 1.5;
        }
      }
    } else {
      /* the smallest failing factor bounds from above, the largest standing one below it from
       * below (a standing factor above a failing one is left out) */
      int jf = k;
      for (int j = 0; j < k && jf == k; ++j)
        if (t[j].failed) jf = j;
      for (int j = 0; j < jf; ++j) lo = F[j];
      if (jf < k) hi = F[jf], hi_from = jf;
    }
    /* the mechanism: the final state of the trial at the smallest failing factor */
    char mech[WF_PATH + 32];
    snprintf(path, sizeof path, "%s/fos_mechanism.csv", outdir);
    for (int j = 0; j < k && wf_par_rank() == 0; ++j) { /* rank 0 wrote them */
      mech_path(mech, sizeof mech, outdir, first + j);
      if (j == hi_from) {
        res->mechanism = rename(mech, path) == 0;
        if (!res->mechanism) remove(path);
      } else {
        remove(mech);
      }
    }
    res->mechanism = wf_par_total(wf_par_rank() == 0 && res->mechanism) > 0;
  }
  res->lo = lo;
  res->hi = hi;
  res->found = lo_ok && hi_ok && hi - lo <= f->tolerance;
  if (!res->found)
    snprintf(msg, len, "no bracket of width %g after %d trials (lo %g %s, hi %g %s)", f->tolerance, res->ntrial, lo,
             lo_ok ? "stands" : "not shown to stand", hi, hi_ok ? "fails" : "not shown to fail");
  return 0;
}

int wf_fos_write_csv(const char *path, const wf_fos_result *res) {
  FILE *f = fopen(path, "w");
  if (!f) return MPMC_ERR_IO;
  fputs("trial,factor,verdict,max_displacement,growth,ke_ratio,sim_time,steps,wall_seconds\n", f);
  for (int i = 0; i < res->ntrial; ++i) {
    const wf_fos_trial *t = &res->trial[i];
    fprintf(f, "%d,%.9g,%s,%.9g,%.6g,%.6g,%.9g,%ld,%.6g\n", i + 1, t->factor, t->failed ? "fails" : "stands",
            t->max_displacement, t->growth, t->ke_ratio, t->sim_time, t->steps, t->wall_seconds);
  }
  return fclose(f) ? MPMC_ERR_IO : 0;
}

/** @brief The trials a search runs at once: factor_of_safety.jobs within [1, WF_FOS_MAX_JOBS]. */
int wf_fos_jobs(const wf_fos *f) {
  return f->jobs < 1 ? 1 : f->jobs > WF_FOS_MAX_JOBS ? WF_FOS_MAX_JOBS : f->jobs;
}

/**
 * @brief The trials of a finished search back from its fos_trials.csv (`mpmc resume` after the
 *        search): the bracket from the largest standing and the smallest failing factor.
 *        0, MPMC_ERR_IO (no file) or MPMC_ERR_FORMAT (a row that does not parse; msg names it).
 */
int wf_fos_read_csv(const char *path, wf_fos_result *res, char *msg, size_t len) {
  FILE *f = fopen(path, "r");
  if (!f) {
    snprintf(msg, len, "cannot read %s: %s", path, strerror(errno));
    return MPMC_ERR_IO;
  }
  char line[512], verdict[16];
  int row = 0, e = 0;
  res->ntrial = 0;
  res->lo = -HUGE_VAL;
  res->hi = HUGE_VAL;
  while (!e && fgets(line, sizeof line, f)) {
    if (++row == 1) continue; /* the header */
    wf_fos_trial t = {0};
    int k = 0;
    if (sscanf(line, "%d,%lf,%15[a-z],%lf,%lf,%lf,%lf,%ld,%lf", &k, &t.factor, verdict, &t.max_displacement,
               &t.growth, &t.ke_ratio, &t.sim_time, &t.steps, &t.wall_seconds) != 9 ||
        (strcmp(verdict, "fails") && strcmp(verdict, "stands")) ||
        res->ntrial == (int)(sizeof res->trial / sizeof res->trial[0])) {
      snprintf(msg, len, "%s:%d: not a trial row (trial,factor,verdict,...)", path, row);
      e = MPMC_ERR_FORMAT;
      break;
    }
    t.failed = !strcmp(verdict, "fails");
    if (t.failed && t.factor < res->hi) res->hi = t.factor;
    if (!t.failed && t.factor > res->lo) res->lo = t.factor;
    res->trial[res->ntrial++] = t;
  }
  fclose(f);
  if (!e && (res->ntrial == 0 || !isfinite(res->lo) || !isfinite(res->hi))) {
    snprintf(msg, len, "%s: no bracket (a standing and a failing trial)", path);
    e = MPMC_ERR_FORMAT;
  }
  res->found = !e;
  return e;
}

void wf_fos_json(FILE *f, const wf_fos_result *res) {
  if (res->found)
    fprintf(f, ",\n  \"factor_of_safety\": %.6g", 0.5 * (res->lo + res->hi));
  else
    fputs(",\n  \"factor_of_safety\": null", f);
  fprintf(f, ",\n  \"fos_bracket\": [%.6g, %.6g],\n  \"fos_jobs\": %d,\n  \"fos_trials\": [", res->lo, res->hi,
          res->jobs);
  for (int i = 0; i < res->ntrial; ++i) {
    const wf_fos_trial *t = &res->trial[i];
    fprintf(f, "%s\n    {\"factor\": %.9g, \"verdict\": \"%s\", \"max_displacement\": %.9g, \"growth\": %.6g, "
               "\"ke_ratio\": %.6g, \"steps\": %ld, \"wall_seconds\": %.6g}",
            i ? "," : "", t->factor, t->failed ? "fails" : "stands", t->max_displacement, t->growth, t->ke_ratio,
            t->steps, t->wall_seconds);
  }
  fputs(res->ntrial ? "\n  ]" : "]", f);
}
