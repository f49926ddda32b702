/* mpmc_workflow_run: build the simulation a scene describes and run its stages, writing
 * the outputs (series.csv, snapshots, checkpoints, summary.json, plots) into one directory.
 * Only what the scene needs is switched on: no plastic state without a plastic material,
 * no F-bar pass when off, no gmsh library unless a body is seeded from gmsh. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "wf.h"

/* Errors recorded in the context through the public API, as the core records its own:
 * WF_ERROR formats the message, WF_CHECK returns it from the calling function on failure,
 * WF_CALL propagates a non-zero code. */
__attribute__((format(printf, 5, 6)))
static int wf_error_at(mpmc_context ctx, int code, const char *file, int line, const char *fmt, ...) {
  char body[3840]; /* the core's message buffer less room for the code's text and file:line */
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(body, sizeof body, fmt, ap);
  va_end(ap);
  return ctx ? mpmc_context_set_error(ctx, code, file, line, body) : code;
}
#define WF_ERROR(ctx, code, ...) wf_error_at((ctx), (code), __FILE__, __LINE__, __VA_ARGS__)
#define WF_CHECK(cond, ctx, code, ...)                                          \
  do {                                                                          \
    if (!(cond)) return wf_error_at((ctx), (code), __FILE__, __LINE__, __VA_ARGS__); \
  } while (0)
#define WF_CALL(expr)              \
  do {                             \
    int wf_ierr_ = (expr);         \
    if (wf_ierr_) return wf_ierr_; \
  } while (0)

/* The code of the context's last error. */
static int last_code(mpmc_context ctx) {
  int code = MPMC_ERR_ARG;
  mpmc_context_get_last_code(ctx, &code);
  return code;
}


typedef struct {
  mpmc_context ctx;
  wf_scene sc;
  mpmc_sim sim;
  char out[WF_PATH];
  int quiet, check;
  FILE *series;
  mpmc_output snap;
  wf_stage_record *rec;
  int *wall_ids;           /* per stage and wall, flattened                              */
  int nwall_ids;
  double t_start;
  char status_msg[WF_MSG];
  int noverride;
  const char *const *overrides;
  double strength;         /* the strength reduction factor in force (1: as given)        */
  double ke_below;         /* stage time since which E_k/E_k,max has stayed below the
                              quasi-static ratio (-1: it is above); saved in checkpoints   */
  int saved_threads;       /* OpenMP threads before the run (0: unchanged)                 */
  int ckpt_ok;             /* a checkpoint (the last good state) has been written           */
  double ckpt_time;        /* its simulated time                                          */
  int resumed;             /* outputs are the _resumed files                              */
  int series_rows;         /* data rows series.csv holds from before a resume            */
  wf_fos_result *fos;      /* the factor-of-safety search's trials (a fos stage ran)      */
  int fos_only;            /* stop after the factor-of-safety stage (`mpmc fos`)          */
} wf_run;

/* `threads` applies to every parallel region of the run (the step and the reductions the
 * workflow calls between steps), not only to mpmc_sim_step: on a busy machine a single
 * region with more threads than free cores costs more than the whole step. */
static void set_threads(wf_run *w) {
  if (w->sc.threads == 0) w->sc.threads = wf_par_threads(); /* over MPI: the node shared */
#ifdef _OPENMP
  if (w->sc.threads > 0) {
    w->saved_threads = omp_get_max_threads();
    omp_set_num_threads(w->sc.threads);
  }
#else
  (void)w;
#endif
}

static void say(const wf_run *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(const wf_run *w, const char *fmt, ...) {
  if (w->quiet || wf_par_rank() != 0) return; /* over MPI: rank 0's log */
  va_list ap;
  va_start(ap, fmt);
  fputs("mpmc: ", stdout);
  vfprintf(stdout, fmt, ap);
  fputc('\n', stdout);
  va_end(ap);
  fflush(stdout);
}

/* Record msg in the context (the caller reads it with mpmc_context_last_error). */
static int fail(wf_run *w, int code, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail(wf_run *w, int code, const char *fmt, ...) {
  char body[WF_MSG];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(body, sizeof body, fmt, ap);
  va_end(ap);
  snprintf(w->status_msg, sizeof w->status_msg, "%s", body);
  return WF_ERROR(w->ctx, code, "%s", body);
}

/* Wrap a library call: on failure keep the library's message and add what we were doing. */
#define WF_TRY(w, expr, ...)                                                      \
  do {                                                                            \
    int wf_e_ = (expr);                                                           \
    if (wf_e_) {                                                                  \
      char wf_what_[256];                                                         \
      snprintf(wf_what_, sizeof wf_what_, __VA_ARGS__);                           \
      return fail((w), wf_e_, "%s: %s", wf_what_, mpmc_context_last_error((w)->ctx)); \
    }                                                                             \
  } while (0)

static int mkdir_p(const char *path) {
  char tmp[WF_PATH];
  snprintf(tmp, sizeof tmp, "%s", path);
  for (char *p = tmp + 1; *p; ++p) {
    if (*p != '/') continue;
    *p = '\0';
    if (mkdir(tmp, 0777) && errno != EEXIST) return -1;
    *p = '/';
  }
  if (mkdir(tmp, 0777) && errno != EEXIST) return -1;
  return 0;
}

/* 1: exists and holds entries, 0: absent or empty, -1: not a directory */
static int dir_nonempty(const char *path) {
  struct stat s;
  if (stat(path, &s)) return 0;
  if (!S_ISDIR(s.st_mode)) return -1;
  DIR *d = opendir(path);
  if (!d) return -1;
  int any = 0;
  struct dirent *e;
  while ((e = readdir(d)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
      any = 1;
      break;
    }
  closedir(d);
  return any;
}

static void out_path(const wf_run *w, const char *name, char *buf, size_t len) {
  snprintf(buf, len, "%s/%s", w->out, name);
}

/* Does `name` start with pre and end with suf (with something between)? */
static int named(const char *name, const char *pre, const char *suf) {
  const size_t n = strlen(name), p = strlen(pre), s = strlen(suf);
  return n > p + s && !strncmp(name, pre, p) && !strcmp(name + n - s, suf);
}

/* Is `name` a file a run writes into its output directory (docs/workflows.md, "Outputs")? */
static int run_output(const char *name) {
  static const char *const files[] = {"summary.json", "series.csv", "snapshots.h5", "snapshots.xdmf",
                                      "snapshots_resumed.h5", "snapshots_resumed.xdmf", "checkpoint.h5.tmp",
                                      "final_state.csv", "final_mean_stress.png", "final_eps_p.png", "series.png",
                                      "bearing.png", "plots.log", "snapshot_plots.log", "fos_trials.csv", "fos_base.h5",
                                      "fos_mechanism.csv", "fos_mechanism.png", "fos_trials.png", "fos_plots.log",
                                      NULL};
  for (int i = 0; files[i]; ++i) {
    const size_t l = strlen(files[i]);
    /* the file, or the temporary one it is written through (series.csv.tmp, checkpoint.h5.tmp,
     * snapshots.xdmf.tmp) */
    if (!strncmp(name, files[i], l) && (!name[l] || !strcmp(name + l, ".tmp"))) return 1;
  }
  /* snapshot_plots: snap_<stage>_t<time>_<colour>.csv, snapshot_<stage>_t<time>_<colour>.png,
   * snapshots_<stage>_<colour>.png */
  return named(name, "snap_", ".csv") || named(name, "snapshot_", ".png") || named(name, "snapshots_", ".png");
}

/* --force: remove the files an earlier run left in the output directory, so that none of them
 * passes for this run's; only those names (never the directory, nor a file the run does not
 * write).  checkpoint.h5 is not removed but replaced, atomically, by the checkpoint the run
 * writes before its first step: a run that cannot write it stops there and the earlier
 * run's last good state is not lost (t690). */
static int remove_old_outputs(wf_run *w) {
  DIR *d = opendir(w->out);
  if (!d) return fail(w, MPMC_ERR_IO, "cannot read '%s': %s", w->out, strerror(errno));
  struct dirent *e;
  int err = 0;
  while (!err && (e = readdir(d))) {
    char path[WF_PATH];
    struct stat st;
    if (!run_output(e->d_name)) continue;
    out_path(w, e->d_name, path, sizeof path);
    if (lstat(path, &st) == 0 && S_ISREG(st.st_mode) && remove(path) != 0)
      err = fail(w, MPMC_ERR_IO, "--force: cannot remove the old output '%s': %s", path, strerror(errno));
  }
  closedir(d);
  return err;
}

/* ---- set-up ---------------------------------------------------------------------------- */
static int build(wf_run *w) {
  wf_scene *sc = &w->sc;
  WF_TRY(w, wf_par_sim_create(w->ctx, sc->dim, &w->sim), "creating the simulation"); /* par.c */
  mpmc_sim sim = w->sim;
  WF_TRY(w, mpmc_sim_set_grid(sim, sc->lo, sc->hi, sc->h), "grid");
  WF_TRY(w, mpmc_sim_set_basis(sim, sc->basis), "basis");
  WF_TRY(w, mpmc_sim_set_fbar(sim, sc->fbar), "fbar");
  WF_TRY(w, mpmc_sim_set_flip_blend(sim, sc->flip), "flip");
  WF_TRY(w, mpmc_sim_set_solver(sim, sc->solver), "solver");
  WF_TRY(w, mpmc_sim_set_threads(sim, sc->threads), "threads");
  WF_TRY(w, mpmc_sim_set_sort_interval(sim, sc->sort_interval), "sort_interval");
  WF_TRY(w, wf_par_balance(sim, sc->balance_every, sc->balance_threshold), "load_balance");
  for (int i = 0; i < sc->nmat; ++i) {
    wf_material *m = &sc->mats[i];
    const int e = mpmc_sim_add_material(sim, wf_model_name(m->model), m->par, m->npar, &m->id);
    WF_TRY(w, e, "materials.%s", m->name);
  }
  /* before the seeding: points below the table weigh their saturated density */
  if (sc->water.has_plane)
    WF_TRY(w, mpmc_sim_set_water_table_plane(sim, sc->water.plane[0], sc->water.plane[1], sc->water.plane[2],
                                             sc->water.gamma_w),
           "water_table");
  else if (sc->water.n)
    WF_TRY(w, mpmc_sim_set_water_table(sim, sc->water.n, sc->water.xh, sc->water.gamma_w), "water_table");
  for (int i = 0; i < sc->nbody; ++i) {
    const wf_body *b = &sc->bodies[i];
    const int mat = sc->mats[b->material].id;
    int first = 0, count = 0;
    if (b->type == WF_GEOM_BOX) {
      WF_TRY(w, mpmc_sim_seed_box(sim, b->lo, b->hi, b->ppc, mat, &first, &count), "geometry.%d (box)", i);
    } else if (b->type == WF_GEOM_POLYGON) {
      WF_TRY(w, mpmc_sim_seed_polygon(sim, b->nvert, b->xy, b->ppc, mat, &first, &count),
             "geometry.%d (polygon)", i);
    } else {
      char msg[WF_MSG];
      const int e = wf_seed_gmsh(sim, b->file, b->region, b->mode, b->ppc, mat, &first, &count, msg, sizeof msg);
      if (e) return fail(w, e, "geometry.%d (gmsh %s): %s", i, b->file, msg);
    }
    if (count == 0) return fail(w, MPMC_ERR_ARG, "geometry.%d: no material point inside (check the grid and the shape)", i);
    int nonzero = 0;
    for (int a = 0; a < sc->dim; ++a) nonzero |= b->velocity[a] != 0.0;
    if (nonzero) {
      double *v;
      int upto = 0; /* the body's points: [first, upto) (over MPI this rank's of its count) */
      mpmc_sim_get_num_particles(sim, &upto);
      WF_TRY(w, mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL), "velocity");
      for (int q = first; q < upto; ++q)
        for (int a = 0; a < sc->dim; ++a) v[(size_t)q * sc->dim + a] = b->velocity[a];
      mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v);
    }
  }
  {
    char msg[WF_MSG] = "";
    const int e = wf_rigid_build(sim, sc, msg, sizeof msg);
    if (e) return fail(w, e, "%s: %s", msg, mpmc_context_last_error(w->ctx));
  }
  WF_TRY(w, wf_metrics_init(sim, sc), "metrics");
  return 0;
}

/* the kernel set in use and what it is, for the log */
static const char *kernels_detail(int k) {
  if (k == MPMC_KERNELS_AVX512) return "avx512 (x86-64-v4, fused multiply-adds, fma's results)";
  if (k == MPMC_KERNELS_FMA) return "fma (x86-64-v3, fused multiply-adds)";
  if (k == MPMC_KERNELS_AVX2) return "avx2 (x86-64-v3)";
  return mpmc_kernels_name(k);
}

static void log_plan(const wf_run *w) {
  const wf_scene *sc = &w->sc;
  int np = 0, plastic = 0, gmsh = 0, damping = 0, tractions = 0, walls = 0, srf = 0;
  if (w->sim) wf_all_count(w->sim, &np);
  for (int i = 0; i < sc->nmat; ++i) plastic |= wf_model_plastic(sc->mats[i].model);
  for (int i = 0; i < sc->nbody; ++i) gmsh |= sc->bodies[i].type == WF_GEOM_GMSH;
  for (int i = 0; i < sc->nstage; ++i) {
    damping |= sc->stages[i].damping > 0;
    tractions |= sc->stages[i].ntractions > 0;
    walls += sc->stages[i].nwalls;
    srf |= sc->stages[i].strength_reduction > 0 || sc->stages[i].has_fos;
  }
  say(w, "scene %s (%s): %dD%s, grid %g m cells, basis %s, %d material points", sc->name, sc->path,
      sc->dim, sc->dim == 2 ? " plane strain" : "", sc->h, wf_basis_name(sc->basis), np);
  char on[512] = "", off[512] = "";
#define FEATURE(cond, text)                                             \
  do {                                                                  \
    char *buf_ = (cond) ? on : off;                                     \
    const size_t l_ = strlen(buf_);                                     \
    snprintf(buf_ + l_, sizeof on - l_, "%s%s", l_ ? ", " : "", text); \
  } while (0)
  FEATURE(sc->fbar, "F-bar");
  FEATURE(plastic, "plastic state (eps_p)");
  FEATURE(sc->water.n || sc->water.has_plane, "water table (pore pressure)");
  FEATURE(gmsh, "gmsh seeding");
  FEATURE(damping, "local damping");
  FEATURE(walls > 0, "walls");
  FEATURE(tractions, "tractions");
  FEATURE(srf, "strength reduction");
  FEATURE(sc->nrigid > 0, "rigid-body contact");
  FEATURE(sc->sort_interval > 0, "sorting by cell (sort_interval)");
  FEATURE(wf_par_size() > 1, "MPI (points and grid over the ranks)");
#ifdef MPMC_WF_HAVE_CHECKPOINT
  FEATURE(1, "checkpoints");
#else
  FEATURE(0, "checkpoints (not in this build)");
#endif
#undef FEATURE
  say(w, "enabled: %s", on[0] ? on : "nothing optional");
  say(w, "left out: %s", off[0] ? off : "nothing");
  mpmc_kernels kern = MPMC_KERNELS_BASELINE;
  if (w->sim) mpmc_sim_get_kernels(w->sim, &kern);
  say(w, "kernels: %s", kernels_detail(kern));
  char mpi[256] = "";
  if (w->sim) wf_par_plan(w->sim, mpi, sizeof mpi);
  if (mpi[0]) say(w, "%s", mpi);
  for (int i = 0; i < sc->nmat; ++i) {
    const wf_material *m = &sc->mats[i];
    char line[512];
    int l = snprintf(line, sizeof line, "material %s: %s", m->name, wf_model_name(m->model));
    for (int k = 0; k < m->npar && l < (int)sizeof line; ++k) {
      mpmc_param_info pi;
      if (mpmc_model_get_param(m->model, k, &pi)) break;
      if (pi.nwords > 0 && m->par[k] >= 0 && m->par[k] < pi.nwords)
        l += snprintf(line + l, sizeof line - (size_t)l, "%s %s = %s", k ? "," : "", pi.name,
                      pi.words[(int)m->par[k]]);
      else
        l += snprintf(line + l, sizeof line - (size_t)l, "%s %s = %g%s%s", k ? "," : "", pi.name,
                      m->par[k], pi.unit[0] && strcmp(pi.unit, "1") ? " " : "",
                      strcmp(pi.unit, "1") ? pi.unit : "");
    }
    say(w, "%s", line);
  }
  for (int i = 0; i < sc->nstage; ++i) {
    const wf_stage *s = &sc->stages[i];
    char end[128];
    if (s->end_kind == WF_END_TIME)
      snprintf(end, sizeof end, "for %g s", s->end_time);
    else
      snprintf(end, sizeof end, "until E_k/E_k,max < %g (at most %g s)", s->ke_ratio, s->max_time);
    char extra[256] = "";
    if (s->strength_reduction > 0)
      snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", strength = material's / %g",
               s->strength_reduction);
    if (s->damping > 0) snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", damping %g", s->damping);
    if (s->kinetic_damping) snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", kinetic damping");
    if (s->adaptive_damping > 0)
      snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", adaptive damping (zeta %g)", s->adaptive_damping);
    if (s->k0 > 0) snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", geostatic stress K0 = %g", s->k0);
    if (s->nwalls) snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", +%d walls", s->nwalls);
    if (s->nremove) snprintf(extra + strlen(extra), sizeof extra - strlen(extra), ", -%d walls", s->nremove);
    say(w, "stage %d/%d %s: %s%s", i + 1, sc->nstage, s->name, end, extra);
  }
}

/* Walls, gravity, damping, tractions and strength changes at the start of stage i. */
static int stage_setup(wf_run *w, int i) {
  const wf_scene *sc = &w->sc;
  const wf_stage *s = &sc->stages[i];
  mpmc_sim sim = w->sim;
  if (s->has_gravity) WF_TRY(w, mpmc_sim_set_gravity(sim, s->gravity), "stages.%d.gravity", i);
  WF_TRY(w, mpmc_sim_set_damping(sim, s->damping), "stages.%d.damping", i);
  WF_TRY(w, mpmc_sim_set_kinetic_damping(sim, s->kinetic_damping), "stages.%d.kinetic_damping", i);
  WF_TRY(w, mpmc_sim_set_adaptive_damping(sim, s->adaptive_damping), "stages.%d.adaptive_damping", i);
  WF_TRY(w, mpmc_sim_set_flip_blend(sim, s->flip), "stages.%d.flip", i);
  WF_TRY(w, mpmc_sim_set_pic_diffusivity(sim, s->pic_diffusivity), "stages.%d.pic_diffusivity", i);
  WF_TRY(w, mpmc_sim_set_force_dt(sim, s->force_dt), "stages.%d.force_dt", i);
  int base = 0;
  for (int j = 0; j < i; ++j) base += sc->stages[j].nwalls;
  for (int k = 0; k < s->nwalls; ++k) {
    const wf_wall *wl = &s->walls[k];
    int id = -1;
    if (wl->form == 0)
      WF_TRY(w, mpmc_sim_add_wall_face(sim, wl->face, wl->kind, &id), "stages.%d.walls.%d", i, k);
    else if (wl->form == 1)
      WF_TRY(w, mpmc_sim_add_wall(sim, wl->axis, wl->side, wl->position, wl->kind, &id), "stages.%d.walls.%d", i, k);
    else if (wl->form == 2)
      WF_TRY(w, mpmc_sim_add_wall_box(sim, wl->lo, wl->hi, wl->kind, wl->axis, wl->side, &id),
             "stages.%d.walls.%d", i, k);
    else {
      int set = -1;
      WF_TRY(w, mpmc_sim_find_node_set(sim, wl->set, &set), "stages.%d.walls.%d.set", i, k);
      WF_TRY(w, mpmc_sim_add_wall_nodes(sim, set, wl->kind, wl->axis, wl->side, &id), "stages.%d.walls.%d", i, k);
    }
    w->wall_ids[base + k] = id;
  }
  for (int k = 0; k < s->nremove; ++k) {
    int b = 0;
    for (int j = 0; j < i; ++j) {
      for (int m = 0; m < sc->stages[j].nwalls; ++m)
        if (!strcmp(sc->stages[j].walls[m].name, s->remove[k]) && w->wall_ids[b + m] >= 0) {
          WF_TRY(w, mpmc_sim_remove_wall(sim, w->wall_ids[b + m]), "stages.%d.remove_walls.%d", i, k);
          w->wall_ids[b + m] = -1;
        }
      b += sc->stages[j].nwalls;
    }
  }
  if (s->ntractions) {
    int np;
    mpmc_sim_get_num_particles(sim, &np);
    const int d = sc->dim;
    double *f = calloc((size_t)np * d + 1, sizeof *f), *x, *vol0;
    if (!f) return fail(w, MPMC_ERR_MEMORY, "stages.%d.tractions: out of memory", i);
    int e = mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x, NULL);
    if (!e) e = mpmc_sim_get_field(sim, MPMC_FIELD_VOLUME0, &vol0, NULL);
    for (int k = 0; k < s->ntractions && !e; ++k) {
      const wf_traction *t = &s->tractions[k];
      /* force = traction x tributary length (2D: V^(1/2)) or area (3D: V^(2/3)) */
      const double expo = (d - 1.0) / d;
      int hits = 0;
      if (t->set[0]) {
        int id, n;
        const int *idx;
        const char *nm;
        e = mpmc_sim_find_particle_set(sim, t->set, &id);
        if (!e) e = mpmc_sim_get_particle_set(sim, id, &nm, &n, &idx);
        for (int j = 0; !e && j < n; ++j, ++hits)
          for (int a = 0; a < d; ++a) f[(size_t)idx[j] * d + a] += t->traction[a] * pow(vol0[idx[j]], expo);
      } else {
        for (int q = 0; q < np; ++q) {
          int in = 1;
          for (int a = 0; a < d; ++a) in &= x[(size_t)q * d + a] >= t->lo[a] && x[(size_t)q * d + a] <= t->hi[a];
          if (!in) continue;
          ++hits;
          for (int a = 0; a < d; ++a) f[(size_t)q * d + a] += t->traction[a] * pow(vol0[q], expo);
        }
      }
      if (!e && wf_par_total(hits) == 0) { /* over MPI: on any rank */
        free(f);
        return fail(w, MPMC_ERR_ARG, "stages.%d.tractions.%d: no material point in the set or region", i, k);
      }
    }
    if (!e) e = mpmc_sim_set_particle_forces(sim, 0, np, f);
    free(f);
    WF_TRY(w, e, "stages.%d.tractions", i);
  }
  if (s->strength_reduction > 0 && s->strength_reduction != w->strength) {
    /* the factor is absolute: the strengths as given divided by it */
    WF_TRY(w, mpmc_sim_set_strength_reduction(sim, -1, s->strength_reduction),
           "stages.%d.strength_reduction", i);
    w->strength = s->strength_reduction;
  }
  if (s->k0 > 0) /* after the stage's gravity and strengths, before its first step */
    WF_TRY(w, mpmc_sim_set_geostatic_stress(sim, s->k0), "stages.%d.initial_stress", i);
  if (s->reset_velocity) {
    double *v;
    int np;
    mpmc_sim_get_num_particles(sim, &np);
    WF_TRY(w, mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL), "reset_velocity");
    memset(v, 0, sizeof *v * (size_t)np * sc->dim);
    mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v);
  }
  return 0;
}

/* A row of series.csv (report.c); a failure stops the run with the reason. */
static int series_row(wf_run *w, int stage, long step, double dt, double ke, double ratio) {
  /* over MPI every rank computes the metrics, rank 0 writes the row */
  const int e = wf_par_agree(wf_series_row(w->series, w->sim, &w->sc, stage, step, dt, ke, ratio));
  if (e == MPMC_ERR_IO) return fail(w, e, "cannot write %s/series.csv: %s", w->out, strerror(errno));
  WF_TRY(w, e, "metrics");
  return 0;
}

static int snapshot(wf_run *w) {
  if (!w->snap) return 0;
  WF_TRY(w, mpmc_output_write(w->snap), "snapshot");
  return 0;
}

#ifdef MPMC_WF_HAVE_CHECKPOINT
/* At the start of `stage` (c == NULL: before its setup) or inside it (c: where it stands). */
static int checkpoint(wf_run *w, int stage, const wf_clock *c, long steps) {
  char path[WF_PATH], meta[16384];
  const wf_clock c0 = {0};
  const int setup_done = c != NULL;
  if (!c) c = &c0;
  out_path(w, "checkpoint.h5", path, sizeof path);
  wf_record r = {.stage = stage, .setup = setup_done, .clock = *c, .steps = steps,
                 .ke_below = setup_done ? w->ke_below : -1.0, .strength = w->strength,
                 .nset = w->noverride, .sets = (char **)w->overrides, .nwall = w->nwall_ids,
                 .walls = w->wall_ids, .ndone = stage, .done = w->rec};
  /* the absolute path, so that `mpmc resume` works from any directory */
  if (!realpath(w->sc.path, r.scene)) snprintf(r.scene, sizeof r.scene, "%s", w->sc.path);
  if (wf_record_format(&r, meta, sizeof meta)) return fail(w, MPMC_ERR_MEMORY, "checkpoint: too many overrides to record");
  wf_par_share(meta, (int)sizeof meta); /* over MPI: rank 0's record (its wall seconds) on every rank */
  WF_TRY(w, mpmc_sim_checkpoint_write(w->sim, path, meta), "checkpoint %s", path);
  w->ckpt_ok = 1;
  mpmc_sim_get_time(w->sim, &w->ckpt_time);
  return 0;
}
#endif

/* A step failed (the monitor's energy check, NaN, J <= 0, a point leaving the grid, a dt
 * above the limit): the state in memory is the failing one.  The last good state is the
 * newest checkpoint.h5 (written at the start, at the end of every stage but the last, and every
 * checkpoint_interval), left untouched; copying the state before every step instead would
 * cost a full copy of the particles per step.  The failing state is appended to the
 * snapshots for inspection. */
static int step_failed(wf_run *w, int e, const wf_stage *s, double t, long steps) {
  char lib[4096] /* the core's message buffer */, note[2 * WF_PATH + 256] = "";
  snprintf(lib, sizeof lib, "%s", mpmc_context_last_error(w->ctx));
  if (w->ckpt_ok)
    snprintf(note, sizeof note,
             "; last good state: %s/checkpoint.h5 (t = %.6g s): change the scene (e.g. dt_factor) and "
             "run `mpmc resume %s`",
             w->out, w->ckpt_time, w->out);
  const size_t l = strlen(note);
  if (w->snap && mpmc_output_write(w->snap) == 0)
    snprintf(note + l, sizeof note - l, "; the failing state is the last snapshot in %s/snapshots%s.h5", w->out,
             w->resumed ? "_resumed" : "");
  return fail(w, e, "stage '%s' at t = %.6g s (step %ld): %s%s", s->name, t, steps, lib, note);
}

/* The quasi-static end test, checked every 10 steps: E_k/E_k,max <= tol must hold at every
 * check for a while, not just once.  A slow oscillation (Cook's membrane under its dead load
 * swings with a period of ~60 s) passes through E_k = 0 at each turning point: a single
 * check there ended the stage at the peak of the swing, 1.6 % beyond the equilibrium.  The
 * ratio stays below tol near a turning point for about 2 sqrt(tol) / omega, a fraction
 * sqrt(tol) / pi of the period, so holding it for 5 % of the stage time so far (at least 50
 * steps) rejects the turning points of any swing whose energy is still above ~5 tol.
 * *below: stage time since the ratio has stayed below tol, -1 when above. */
static int wf_quasi_static(double ratio, double tol, double t_stage, double min_time, double dt,
                           double *below) {
  if (!(ratio <= tol) || t_stage < min_time) {
    *below = -1.0;
    return 0;
  }
  if (*below < 0) *below = t_stage;
  return t_stage - *below >= fmax(0.05 * t_stage, 50.0 * dt);
}

/* Run stage i, from its start (from == NULL) or from where a checkpoint left it. */
static int run_stage(wf_run *w, int i, const wf_clock *from, long *nsteps, wf_progress *pr) {
  long steps = *nsteps;
  const wf_scene *sc = &w->sc;
  const wf_stage *s = &sc->stages[i];
  mpmc_sim sim = w->sim;
  wf_stage_record *rec = &w->rec[i];
  snprintf(rec->name, sizeof rec->name, "%s", s->name);
  const double T = s->end_time; /* quasi-static: the maximum time */
  const double w0 = wf_now();
  wf_clock c = {.dt = s->dt, .ratio = 1.0};
  if (from && from->t_stage > 0) c = *from;
  double t_stage = c.t_stage, dt = s->dt > 0 ? s->dt : c.dt, ke = c.ke, ke_max = c.ke_max, ratio = c.ratio;
  double last_ckpt = w0, t0;
  mpmc_sim_get_time(sim, &t0);
  t0 -= t_stage;
  const double every_series = T / s->series_points;
  const double every_snap = s->snapshots > 0 ? T / (s->snapshots + 1) : INFINITY;
  /* a checkpoint of before these were recorded: the next ones from the stage time */
  double next_series = c.next_series > 0 ? c.next_series : every_series * floor(t_stage / every_series + 1e-9);
  double next_snap = c.next_snap > 0 ? c.next_snap : every_snap * (floor(t_stage / every_snap + 1e-9) + 1);
  const char *reason = NULL;
  /* the steps are counted from the stage's start, also when resumed inside it: the step size
   * is recomputed on the same steps as in the uninterrupted run */
  long s0 = 0, s_run = steps;
  for (int j = 0; j < i; ++j) s0 += w->rec[j].steps;
  (void)last_ckpt;
  char spmsg[WF_MSG] = ""; /* snapshot plots at given times (snapshot_plots.c) */
  if (t_stage == 0 && wf_snapplots_step(sim, sc, w->out, i, -1.0, 0.0, spmsg, sizeof spmsg))
    return fail(w, MPMC_ERR_IO, "%s", spmsg);
  while (!reason) {
    if (s->dt <= 0 && ((steps - s0) % 10 == 0 || dt <= 0))
      WF_TRY(w, mpmc_sim_stable_dt(sim, s->dt_factor, &dt), "stages.%d: time step", i);
    double h = dt;
    if (t_stage + h > T) h = T - t_stage; /* land on the stage's end */
    const double t_plot = wf_snapplots_next(sc, i, t_stage);
    if (t_stage + h > t_plot) h = t_plot - t_stage; /* and on the times of snapshot_plots */
    char rmsg[WF_MSG] = "";
    int e = wf_rigid_before_step(sim, sc, i, t_stage, rmsg, sizeof rmsg); /* rigid.c */
    if (!e) e = mpmc_sim_step(sim, h);
    if (!e) e = wf_rigid_after_step(sim, sc, rmsg, sizeof rmsg);
    if (e && rmsg[0]) return fail(w, e, "stage '%s': %s: %s", s->name, rmsg, mpmc_context_last_error(w->ctx));
    if (e) {
      const double tt = t0 + t_stage;
      return step_failed(w, e, s, tt, steps);
    }
    t_stage += h;
    ++steps;
    if (sc->nsnapplot && wf_snapplots_step(sim, sc, w->out, i, t_stage - h, t_stage, spmsg, sizeof spmsg))
      return fail(w, MPMC_ERR_IO, "%s", spmsg);
    const int at_end = t_stage >= T * (1 - 1e-9); /* not a sliver of a step for round-off */
    if (s->end_kind == WF_END_QUASI_STATIC) {
      /* quasi-static when the kinetic energy has fallen to ke_ratio of its stage maximum and
       * stayed there (wf_quasi_static) */
      if ((steps - s0) % 10 == 1 || at_end) { /* an O(n) reduction: not every step */
        mpmc_sim_get_kinetic_energy(sim, &ke);
        if (ke > ke_max) ke_max = ke;
        ratio = ke_max > 0 ? ke / ke_max : 0.0;
        if (wf_quasi_static(ratio, s->ke_ratio, t_stage, s->min_time, h, &w->ke_below)) reason = "quasi_static";
      }
    }
    if (!reason && at_end) reason = s->end_kind == WF_END_TIME ? "time" : "max_time";
    if (t_stage >= next_series || reason) {
      if (s->end_kind == WF_END_TIME) mpmc_sim_get_kinetic_energy(sim, &ke);
      if (s->end_kind == WF_END_TIME) {
        if (ke > ke_max) ke_max = ke;
        ratio = ke_max > 0 ? ke / ke_max : 0.0;
      }
      if (series_row(w, i, steps, h, ke, ratio)) return -1;
      while (next_series <= t_stage) next_series += every_series;
    }
    if (t_stage >= next_snap && !reason) {
      if (snapshot(w)) return -1;
      while (next_snap <= t_stage) next_snap += every_snap;
    }
    const double now = wf_now();
    const double rate = (double)(steps - s_run) / fmax(now - w0, 1e-9);
    if (!w->quiet) wf_progress_update(pr, sc, i, t_stage, T, steps, rate, sc->progress_interval, reason != NULL);
#ifdef MPMC_WF_HAVE_CHECKPOINT
    if (!reason && now - last_ckpt > sc->checkpoint_interval) {
      const wf_clock here = {t_stage, dt, ke, ke_max, ratio, next_series, next_snap};
      if (checkpoint(w, i, &here, steps)) return -1;
      last_ckpt = now;
    }
#endif
  }
  if (!w->quiet) wf_progress_done(pr);
  rec->sim_time = t_stage;
  rec->steps = steps;
  for (int j = 0; j < i; ++j) rec->steps -= w->rec[j].steps; /* this stage's own steps */
  *nsteps = steps;
  rec->wall_seconds += wf_now() - w0;
  rec->reason = reason;
  rec->strength = w->strength;
  wf_metrics_stage_end(sim, &w->sc, i); /* metrics kept from the end of this stage */
  if (snapshot(w)) return -1;
  if (!strcmp(reason, "max_time"))
    say(w, "warning: stage %s reached max_time %g s before E_k/E_k,max fell below %g (last %.3g)", s->name,
        s->max_time, s->ke_ratio, ratio);
  say(w, "stage %d/%d %s done: %.4g s simulated in %ld steps, %.1f s wall (%s)", i + 1, sc->nstage, s->name,
      t_stage, rec->steps, rec->wall_seconds, reason);
  return 0;
}

static void say_line(void *data, const char *line) { say((const wf_run *)data, "%s", line); }

/* Stage i is a factor-of-safety search (fos.c): trials from the state at hand, which itself
 * does not move; the stages after it go on from this state at the first failing factor. */
static int run_fos(wf_run *w, int i) {
  const double w0 = wf_now();
  const wf_stage *s = &w->sc.stages[i];
  wf_stage_record *rec = &w->rec[i];
  snprintf(rec->name, sizeof rec->name, "%s", s->name);
  if (!w->fos && !(w->fos = calloc(1, sizeof *w->fos))) return fail(w, MPMC_ERR_MEMORY, "factor of safety");
  char msg[WF_MSG] = "";
  say(w, "stage %d/%d %s: factor of safety between %g and %g to %g, trials of %g s, failure beyond %g m, "
      "%d trial%s at once", i + 1, w->sc.nstage, s->name, s->fos.lo, s->fos.hi, s->fos.tolerance, s->end_time,
      s->fos.displacement_limit, wf_par_size() > 1 ? 1 : s->fos.jobs,
      wf_par_size() > 1 ? (s->fos.jobs > 1 ? " (over MPI: one at a time over the ranks)" : "")
      : s->fos.jobs > 1 ? "s (child processes)" : "");
  const int e = wf_fos_search(w->ctx, w->sim, &w->sc, i, w->out, w->fos, w->quiet ? NULL : say_line, w, msg,
                              sizeof msg);
  if (e) return fail(w, e, "stage '%s': %s", s->name, msg);
  char path[WF_PATH];
  out_path(w, "fos_trials.csv", path, sizeof path);
  if (wf_par_agree(wf_par_rank() == 0 && wf_fos_write_csv(path, w->fos) ? MPMC_ERR_IO : 0))
    return fail(w, MPMC_ERR_IO, "cannot write %s: %s", path, strerror(errno));
  if (w->sc.plots && wf_par_rank() == 0) {
    char warn[WF_MSG] = "";
    if (wf_fos_plots(&w->sc, i, w->fos, w->out, warn, sizeof warn)) say(w, "warning: plots: %s", warn);
  }
  if (!w->fos->found) return fail(w, MPMC_ERR_NUMERIC, "stage '%s': %s", s->name, msg);
  const double F = w->fos->hi;
  WF_TRY(w, mpmc_sim_set_strength_reduction(w->sim, -1, F), "stages.%d: the first failing factor", i);
  w->strength = F;
  rec->sim_time = 0.0;
  rec->steps = 0;
  rec->wall_seconds += wf_now() - w0;
  rec->reason = "fos";
  rec->strength = F;
  say(w, "stage %d/%d %s done: factor of safety %.4g (%g stands, %g fails), %d trials, %.1f s wall", i + 1,
      w->sc.nstage, s->name, 0.5 * (w->fos->lo + w->fos->hi), w->fos->lo, w->fos->hi, w->fos->ntrial,
      rec->wall_seconds);
  return 0;
}

static int open_outputs(wf_run *w, int append) {
  char path[WF_PATH], xpath[WF_PATH], msg[WF_MSG];
  out_path(w, "series.csv", path, sizeof path);
  msg[0] = '\0';
  if (wf_par_rank() == 0) w->series = wf_series_open(path, &w->sc, append, msg, sizeof msg); /* rank 0's */
  if (wf_par_agree(wf_par_rank() == 0 && !w->series ? MPMC_ERR_IO : 0)) return fail(w, MPMC_ERR_IO, "%s", msg);
  w->resumed = append;
  out_path(w, append ? "snapshots_resumed.h5" : "snapshots.h5", path, sizeof path);
  out_path(w, append ? "snapshots_resumed.xdmf" : "snapshots.xdmf", xpath, sizeof xpath);
  WF_TRY(w, mpmc_output_create(w->sim, path, xpath, &w->snap), "snapshots %s", path);
  return 0;
}

/* From the start of first_stage (from == NULL), or inside it: from->t_stage > 0, or at its
 * start once set up (setup_done: a checkpoint inside the stage, or the last stage of a
 * finished run going on to a later end) */
static int run_all(wf_run *w, int first_stage, const wf_clock *from, long steps, int setup_done) {
  const double t_stage = from ? from->t_stage : 0.0;
  wf_progress pr;
  wf_progress_init(&pr);
  if (first_stage == 0 && t_stage == 0 && snapshot(w)) return -1;
#ifdef MPMC_WF_HAVE_CHECKPOINT
  /* the last good state exists from the start: a failure in the first stage keeps it */
  if (first_stage == 0 && t_stage == 0 && !setup_done && checkpoint(w, 0, NULL, steps)) return -1;
#endif
  for (int i = first_stage; i < w->sc.nstage; ++i) {
    if (!(i == first_stage && setup_done) && stage_setup(w, i)) return -1;
    /* the state the run starts from; a resumed run has it unless killed before writing it */
    if (i == 0 && t_stage == 0 && !setup_done && w->series_rows == 0 && series_row(w, i, steps, 0, 0, 1)) return -1;
    if (!(i == first_stage && t_stage > 0)) w->ke_below = -1.0; /* else restored from the checkpoint */
    if (w->sc.stages[i].has_fos) {
      if (run_fos(w, i)) return -1;
    } else if (run_stage(w, i, i == first_stage ? from : NULL, &steps, &pr)) {
      return -1;
    }
#ifdef MPMC_WF_HAVE_CHECKPOINT
    /* at the start of the next stage; after the last one, the finished run (stage = nstage),
     * which `mpmc resume` continues once the scene has another stage: that one only warns
     * when it cannot be written, the run itself is done and its outputs follow */
    const int last = i + 1 == w->sc.nstage || (w->fos_only && w->sc.stages[i].has_fos);
    if (checkpoint(w, i + 1, NULL, steps)) {
      if (!last) return -1;
      say(w, "warning: the final checkpoint: %s (the run is complete; it cannot be extended by `mpmc resume`)",
          mpmc_context_last_error(w->ctx));
    }
#endif
    /* `mpmc fos`: the answer, without the stages after (`mpmc resume` runs them) */
    if (w->fos_only && w->sc.stages[i].has_fos) break;
  }
  return 0;
}

static int finish(wf_run *w, int err) {
  int done = 0;
  while (done < w->sc.nstage && w->rec && w->rec[done].reason) ++done;
  if (!w->check && w->out[0]) {
    char path[WF_PATH];
    out_path(w, "summary.json", path, sizeof path);
    wf_summary_write(path, &w->sc, w->sim, err == 0 ? NULL : w->status_msg, w->rec, done, wf_now() - w->t_start,
                     w->fos);
    if (err == 0 && w->sc.plots && w->sim) {
      char warn[WF_MSG] = "";
      if (wf_plots_write(w->sim, &w->sc, w->out, warn, sizeof warn)) say(w, "warning: plots: %s", warn);
      if (wf_par_rank() == 0 && wf_snapplots_plot(&w->sc, w->out, warn, sizeof warn))
        say(w, "warning: snapshot plots: %s", warn);
    }
    if (err == 0) say(w, "done in %.1f s: %s", wf_now() - w->t_start, path);
  }
  if (w->series) fclose(w->series);
#ifdef _OPENMP
  if (w->saved_threads > 0) omp_set_num_threads(w->saved_threads);
#endif
  mpmc_output_destroy(&w->snap);
  mpmc_sim_destroy(&w->sim);
  wf_root_release();
  free(w->rec);
  free(w->fos);
  free(w->wall_ids);
  wf_scene_free(&w->sc);
  return err;
}

static int prepare(wf_run *w, const char *scene, int noverride, const char *const *overrides) {
  char msg[WF_MSG];
  const int e = wf_scene_load(scene, noverride, overrides, &w->sc, msg, sizeof msg);
  if (e) return fail(w, e, "%s", msg);
  w->rec = calloc((size_t)w->sc.nstage, sizeof *w->rec);
  for (int i = 0; i < w->sc.nstage; ++i) w->nwall_ids += w->sc.stages[i].nwalls;
  w->wall_ids = malloc(sizeof(int) * (size_t)(w->nwall_ids + 1));
  if (!w->rec || !w->wall_ids) return fail(w, MPMC_ERR_MEMORY, "out of memory");
  for (int i = 0; i < w->nwall_ids; ++i) w->wall_ids[i] = -1;
  return 0;
}

/**
 * @brief Run a YAML scene (the `mpmc run` command).
 * @param scene the scene file
 * @param outdir output directory (NULL: out/<scene name>); refused when it exists and is
 *        not empty unless flags has MPMC_WORKFLOW_FORCE
 * @param noverride,overrides "key.path=value" strings applied over the scene
 * @param flags MPMC_WORKFLOW_FORCE | MPMC_WORKFLOW_QUIET | MPMC_WORKFLOW_CHECK
 * @return 0 when every stage completed; the message is in mpmc_context_last_error
 */
int mpmc_workflow_run(mpmc_context ctx, const char *scene, const char *outdir, int noverride,
                      const char *const *overrides, int flags) {
  if (!ctx) return MPMC_ERR_ARG;
  WF_CHECK(scene && scene[0], ctx, MPMC_ERR_ARG, "scene file name is NULL or empty");
  WF_CHECK(noverride >= 0 && (noverride == 0 || overrides), ctx, MPMC_ERR_ARG,
             "noverride = %d with overrides = NULL", noverride);
  WF_CHECK(flags >= 0 && flags < 16, ctx, MPMC_ERR_ARG, "flags = %d: unknown bits", flags);
  wf_run w = {0};
  w.ctx = ctx;
  w.quiet = (flags & MPMC_WORKFLOW_QUIET) != 0;
  w.check = (flags & MPMC_WORKFLOW_CHECK) != 0;
  w.fos_only = (flags & MPMC_WORKFLOW_FOS) != 0;
  w.t_start = wf_now();
  w.strength = 1.0;
  w.noverride = noverride;
  w.overrides = overrides;
  if (prepare(&w, scene, noverride, overrides)) return finish(&w, mpmc_context_last_error(ctx)[0] ? last_code(ctx) : MPMC_ERR_ARG);
  if (outdir && outdir[0])
    snprintf(w.out, sizeof w.out, "%s", outdir);
  else
    snprintf(w.out, sizeof w.out, "out/%s", w.sc.name);
  if (!w.check) {
    const int ne = (int)wf_par_total(wf_par_rank() == 0 ? dir_nonempty(w.out) : 0); /* rank 0's */
    if (ne < 0) return finish(&w, fail(&w, MPMC_ERR_IO, "output '%s' is not a directory", w.out));
    if (ne > 0 && !(flags & MPMC_WORKFLOW_FORCE)) {
      w.out[0] = '\0';
      return finish(&w, fail(&w, MPMC_ERR_IO, "output directory '%s' exists and is not empty: "
                                              "nothing written (use --force to write over it)",
                             outdir && outdir[0] ? outdir : "out/<scene>"));
    }
  }
  /* build the simulation before touching the output directory: a scene that cannot be
   * built writes nothing */
  char out_saved[WF_PATH];
  snprintf(out_saved, sizeof out_saved, "%s", w.out);
  w.out[0] = '\0';
  set_threads(&w);
  if (build(&w)) return finish(&w, last_code(ctx));
  snprintf(w.out, sizeof w.out, "%s", out_saved);
  log_plan(&w);
  if (w.check) {
    say(&w, "check: %s is valid", scene);
    return finish(&w, 0);
  }
  /* over MPI rank 0 makes the directory and clears it, and every rank knows how it went */
  if (wf_par_agree(wf_par_rank() == 0 && mkdir_p(w.out) ? MPMC_ERR_IO : 0))
    return finish(&w, fail(&w, MPMC_ERR_IO, "cannot create '%s': %s", w.out, strerror(errno)));
  if ((flags & MPMC_WORKFLOW_FORCE) && wf_par_agree(wf_par_rank() == 0 ? remove_old_outputs(&w) : 0))
    return finish(&w, wf_par_rank() == 0 ? last_code(ctx)
                                         : fail(&w, MPMC_ERR_IO, "--force: rank 0 cannot remove the old outputs"));
  say(&w, "output: %s", w.out);
  if (open_outputs(&w, 0)) return finish(&w, last_code(ctx));
  const int err = run_all(&w, 0, NULL, 0, 0);
  return finish(&w, err ? last_code(ctx) : 0);
}

/**
 * @brief Continue a workflow from the checkpoint in outdir (the `mpmc resume` command).
 * @param flags MPMC_WORKFLOW_QUIET
 */
int mpmc_workflow_resume(mpmc_context ctx, const char *outdir, int flags) {
  return mpmc_workflow_resume_set(ctx, outdir, 0, NULL, flags);
}

/**
 * @brief mpmc_workflow_resume with noverride "key.path=value" overrides applied after the
 *        run's own (`mpmc resume DIR --set ...`): e.g. a later end for the last stage of a
 *        finished run.  Later checkpoints record them with the run's.
 */
int mpmc_workflow_resume_set(mpmc_context ctx, const char *outdir, int noverride, const char *const *overrides,
                             int flags) {
  if (!ctx) return MPMC_ERR_ARG;
  WF_CHECK(outdir && outdir[0], ctx, MPMC_ERR_ARG, "output directory outdir is NULL or empty");
  WF_CHECK(noverride >= 0 && (noverride == 0 || overrides), ctx, MPMC_ERR_ARG,
             "resume: noverride = %d with overrides %s", noverride, overrides ? "given" : "NULL");
  for (int i = 0; i < noverride; ++i)
    WF_CHECK(overrides[i], ctx, MPMC_ERR_ARG, "resume: override %d is NULL", i);
#ifndef MPMC_WF_HAVE_CHECKPOINT
  (void)flags;
  return WF_ERROR(ctx, MPMC_ERR_UNSUPPORTED, "resume: this build has no checkpoints (checkpoint.c)");
#else
  char path[WF_PATH];
  snprintf(path, sizeof path, "%s/checkpoint.h5", outdir);
  mpmc_sim sim = NULL;
  char *meta = NULL;
  WF_CALL(wf_par_checkpoint_read(ctx, path, &sim, &meta));
  /* the workflow's record */
  wf_record rec;
  char why[WF_MSG] = "";
  int bad = wf_record_parse(meta, &rec, why, sizeof why) != 0;
  mpmc_free(meta);
  for (int i = 0; i < noverride && !bad; ++i) /* the caller's, after the run's own */
    if (wf_record_add_set(&rec, overrides[i])) {
      snprintf(why, sizeof why, "out of memory for the overrides");
      bad = 1;
    }
  int err = 0;
  wf_run w = {0};
  w.ctx = ctx;
  w.quiet = (flags & MPMC_WORKFLOW_QUIET) != 0;
  w.t_start = wf_now();
  w.noverride = rec.nset;
  w.overrides = (const char *const *)rec.sets;
  /* the walls the checkpoint records: those of its stages, or of more (not yet added) */
  int walls_before = 0; /* of the stages up to the one resumed */
  if (bad) { /* wf_record_parse: a scene and a stage, or why not */
    err = WF_ERROR(ctx, MPMC_ERR_FORMAT, "resume: %s was not written by the workflow (%s)", path, why);
  } else if (prepare(&w, rec.scene, rec.nset, w.overrides)) {
    err = last_code(ctx);
  } else {
    /* a stage's walls are added by its setup */
    for (int i = 0; i < rec.stage + (rec.setup != 0) && i < w.sc.nstage; ++i) walls_before += w.sc.stages[i].nwalls;
  }
  /* errors before this point leave the outputs as they are (w.out empty: finish writes no
   * summary); a finished run is not a failed one */
  double t_ckpt = 0.0;
  if (sim) mpmc_sim_get_time(sim, &t_ckpt);
  /* A finished run (the checkpoint after its last stage) continues with the stages added to
   * the scene since, or its last stage from where it ended when that stage's end time was
   * raised (an end by time; not one that came to rest) */
  if (!err && rec.stage == w.sc.nstage && rec.ndone == rec.stage && rec.stage > 0) {
    const wf_stage *last = &w.sc.stages[rec.stage - 1];
    const wf_stage_record *r = &rec.done[rec.stage - 1];
    if (strcmp(r->reason, "quasi_static") != 0 && last->end_time > r->sim_time * (1 + 1e-9)) {
      /* the last stage again, at its old end, set up; ke_max is used by quasi-static ends
       * only, the step size is computed on the first step */
      rec.clock = (wf_clock){.t_stage = r->sim_time, .ratio = 1.0};
      --rec.stage;
      --rec.ndone;
      rec.setup = 1;
      rec.ke_below = -1.0;
    } else {
      char how[WF_PATH + 160] = "";
      if (strcmp(r->reason, "quasi_static"))
        snprintf(how, sizeof how,
                 " or raise the last stage's end time (e.g. `mpmc resume %s --set stages.%s.end.%s=T`, T > %.6g)",
                 outdir, last->name, last->end_kind == WF_END_QUASI_STATIC ? "max_time" : "time", r->sim_time);
      err = fail(&w, MPMC_ERR_STATE,
                 "resume: the run in %s finished all %d stages of %s (checkpoint at t = %.6g s, stage '%s' "
                 "ended by %s at %.6g s); to continue it, add a stage to the scene%s",
                 outdir, rec.stage, rec.scene, t_ckpt, last->name, r->reason, r->sim_time, how);
    }
  }
  if (!err && (rec.nwall < walls_before || rec.nwall > w.nwall_ids || rec.ndone != rec.stage || rec.stage > w.sc.nstage)) {
    err = fail(&w, MPMC_ERR_FORMAT,
               "resume: the scene %s no longer matches the checkpoint (stages or walls changed: %d stages "
               "done, %d walls recorded; the scene has %d stages, %d walls)",
               rec.scene, rec.ndone, rec.nwall, w.sc.nstage, w.nwall_ids);
  } else if (!err) {
    snprintf(w.out, sizeof w.out, "%s", outdir);
    if (rec.nwall) memcpy(w.wall_ids, rec.walls, sizeof *rec.walls * (size_t)rec.nwall);
    for (int i = 0; i < rec.ndone; ++i) {
      w.rec[i] = rec.done[i];
      snprintf(w.rec[i].name, sizeof w.rec[i].name, "%s", w.sc.stages[i].name);
    }
    /* a finished search is not run again: its answer comes back from fos_trials.csv */
    for (int i = 0; i < rec.ndone && !err; ++i) {
      if (strcmp(rec.done[i].reason, "fos") || !w.sc.stages[i].has_fos) continue;
      char trials[WF_PATH], msg[WF_MSG];
      out_path(&w, "fos_trials.csv", trials, sizeof trials);
      if (!w.fos && !(w.fos = calloc(1, sizeof *w.fos))) {
        err = fail(&w, MPMC_ERR_MEMORY, "resume: factor of safety");
      } else if (wf_fos_read_csv(trials, w.fos, msg, sizeof msg)) {
        err = fail(&w, MPMC_ERR_FORMAT, "resume: stage '%s' (a finished factor-of-safety search): %s",
                   w.sc.stages[i].name, msg);
      } else {
        w.fos->jobs = wf_fos_jobs(&w.sc.stages[i].fos);
        out_path(&w, "fos_mechanism.csv", trials, sizeof trials);
        w.fos->mechanism = access(trials, R_OK) == 0;
      }
    }
    w.sim = sim;
    w.ckpt_ok = 1; /* the checkpoint resumed from is the last good state until the next one */
    w.ckpt_time = t_ckpt;
    w.strength = rec.strength;
    w.ke_below = rec.ke_below;
    set_threads(&w);
    mpmc_sim_set_threads(w.sim, w.sc.threads);
    if (wf_par_balance(w.sim, w.sc.balance_every, w.sc.balance_threshold)) err = last_code(ctx);
    sim = NULL;
    if (wf_metrics_init(w.sim, &w.sc)) err = last_code(ctx);
    say(&w, "resuming %s at stage %d/%d (%s), %.4g s into it", rec.scene, rec.stage + 1, w.sc.nstage,
        w.sc.stages[rec.stage].name, rec.clock.t_stage);
    if (!err) {
      char series[WF_PATH], msg[WF_MSG];
      out_path(&w, "series.csv", series, sizeof series);
      msg[0] = '\0';
      const int bad_trim = wf_par_rank() == 0 && wf_series_trim(series, &w.sc, rec.steps, &w.series_rows, msg, sizeof msg);
      w.series_rows = (int)wf_par_total(w.series_rows); /* rank 0's count (the others' are 0) */
      if (wf_par_agree(bad_trim ? MPMC_ERR_IO : 0)) err = fail(&w, MPMC_ERR_IO, "resume: %s", msg);
    }
    if (!err) err = open_outputs(&w, 1) ? last_code(ctx) : 0;
    if (!err) {
      if (rec.setup && w.sc.stages[rec.stage].has_gravity) mpmc_sim_set_gravity(w.sim, w.sc.stages[rec.stage].gravity);
      if (rec.setup) {
        const wf_stage *s = &w.sc.stages[rec.stage];
        mpmc_sim_set_damping(w.sim, s->damping);
        mpmc_sim_set_kinetic_damping(w.sim, s->kinetic_damping);
        mpmc_sim_set_adaptive_damping(w.sim, s->adaptive_damping);
        mpmc_sim_set_flip_blend(w.sim, s->flip);
        mpmc_sim_set_pic_diffusivity(w.sim, s->pic_diffusivity);
      }
      err = run_all(&w, rec.stage, &rec.clock, rec.steps, rec.setup) ? last_code(ctx) : 0;
    }
  }
  mpmc_sim_destroy(&sim);
  err = finish(&w, err);
  wf_record_free(&rec);
  return err;
#endif
}
