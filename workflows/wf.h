/* Private declarations of the workflow front end (libmpmc_workflow).  Not installed.
 *
 * yaml.c     YAML -> a small tree with file:line:column on every node, --set overrides
 * scene.c    the scene schema: typed and range-checked reading of that tree into wf_scene
 * run.c      mpmc_workflow_run: builds the simulation and runs the stages (calls report.c)
 * report.c   progress line/bar, series.csv, summary.json, metrics (calls nothing in run.c)
 * plot.c     PNG plots through gnuplot (a child process; its start and end, wf_gnuplot_*,
 *            shared with snapshot_plots.c)
 * gmsh_plugin.c  libmpmc_gmsh loaded with dlopen only when a scene seeds from gmsh
 */
#ifndef MPMC_WF_H
#define MPMC_WF_H

#include <stdint.h>
#include <stdio.h>

#include "mpmc.h"
#include "mpmc_gmsh.h"
#include "mpmc_workflow.h"

#define WF_NAME 64
#define WF_PATH 4096
#define WF_MSG 4096

/* ---- the YAML tree (yaml.c) ------------------------------------------------------ */
typedef enum { WF_SCALAR = 0, WF_SEQ = 1, WF_MAP = 2 } wf_kind;
typedef struct wf_node {
  wf_kind kind;
  char *value;              /* scalar text                                          */
  int quoted;               /* the scalar was quoted: always a string               */
  int line, col;            /* 1-based position; 0 for values given with --set      */
  const char *origin;       /* file name, or the --set argument                     */
  int n, cap;
  char **keys;              /* map keys (NULL for sequences)                         */
  int *key_line, *key_col;  /* positions of the keys                                 */
  struct wf_node **items;
} wf_node;

void wf_node_free(wf_node *n);
/* yaml.c: a YAML (or JSON) file as a tree, NULL with *code and msg; one --set override
 * applied to a tree (origin, named in messages, must outlive it); a map's value by key */
wf_node *wf_yaml_load(const char *path, const char *what, int *code, char *msg, size_t len);
int wf_yaml_override(wf_node *root, const char *arg, const char *origin, char *msg, size_t len);
void wf_key_join(char *out, size_t len, const char *path, const char *key);
const wf_node *wf_map_get(const wf_node *map, const char *key);

/* ---- the scene as read (scene.c) ------------------------------------------------- */
#define WF_MAX_MODELS 32
typedef struct {
  char name[WF_NAME];
  int model;                    /* index in the library's model table (mpmc_model_*)     */
  int npar;                     /* the model's stored parameters                        */
  double par[MPMC_MAX_PARAMS];  /* in the table's order and units, defaults filled      */
  int id; /* in the simulation */
} wf_material;
/* 1 if the model keeps a plastic strain per point */
static inline int wf_model_plastic(int model) {
  mpmc_model_info mi;
  return !mpmc_model_get_info(model, &mi) && mi.plastic;
}

typedef enum { WF_GEOM_BOX, WF_GEOM_POLYGON, WF_GEOM_GMSH } wf_geom_type;
typedef struct {
  int type;
  int material;             /* index into scene materials                           */
  int ppc;
  double lo[3], hi[3];      /* box                                                  */
  int nvert;                /* polygon                                              */
  double *xy;
  char file[WF_PATH];       /* gmsh: absolute or relative to the scene file          */
  int mode;                 /* mpmc_seed_mode                                       */
  char region[WF_NAME];
  double velocity[3];       /* initial velocity                                     */
} wf_body;

/* Rigid bodies (scene key rigid_bodies; rigid.c): a box (2D/3D) or polygon (2D) pushed
 * through the barrier contact of contact_barrier.c, moved per stage (wf_rigid_motion). */
typedef struct {
  char name[WF_NAME];
  int type;                 /* WF_GEOM_BOX or WF_GEOM_POLYGON                       */
  double lo[3], hi[3];      /* box                                                  */
  int nvert;                /* polygon                                              */
  double *xy;
  double friction;          /* Coulomb coefficient mu (large: rough)                */
  int id;                   /* in the simulation                                    */
} wf_rigid;

typedef struct {
  int body;                 /* index into scene rigid bodies                        */
  double velocity[3];       /* from this stage on                                   */
  double ramp;              /* [s] linear ramp from the previous stage's velocity   */
} wf_rigid_motion;

typedef struct {
  char name[WF_NAME];       /* "" when unnamed                                      */
  int kind;                 /* mpmc_wall_kind                                       */
  int form;                 /* 0 face, 1 plane, 2 box, 3 node set                   */
  int face, axis, side;
  double position, lo[3], hi[3];
  char set[WF_NAME];        /* form 3: a node set (gmsh boundary group)             */
} wf_wall;

typedef struct {
  char set[WF_NAME];        /* particle set, or "" for the region                   */
  int has_region;
  double lo[3], hi[3];
  double traction[3];       /* [Pa]                                                 */
} wf_traction;

typedef enum { WF_END_TIME = 0, WF_END_QUASI_STATIC = 1 } wf_end_kind;
/* A factor-of-safety search (fos.c): trials from the stage's start, each its end time long */
typedef struct {
  double lo, hi;             /* first bracket: lo expected to stand, hi to fail          */
  double tolerance;          /* bisection until hi - lo <= tolerance                    */
  double displacement_limit; /* [m] a trial fails when a point moves more than this      */
  double growth;             /* ... or when its largest displacement still grows by more
                                than this fraction over the trial's last quarter        */
  int max_trials;
  int jobs;                  /* trials at once, each in a child process (1: in this one) */
} wf_fos;
typedef struct {
  char name[WF_NAME];
  int has_gravity;
  double gravity[3];
  double damping;
  int kinetic_damping; /* velocities to zero at each peak of E_k (mpmc_sim_set_kinetic_damping) */
  double adaptive_damping; /* damping ratio zeta of the estimated lowest mode, 0 off (mpmc_sim_set_adaptive_damping) */
  double k0;           /* initial_stress.k0: the geostatic state at the stage's start; 0: none */
  double flip; /* the stage's FLIP/PIC blend (the scene's where the stage sets none) */
  double pic_diffusivity; /* > 0: PIC's share D dt / h^2 in place of flip [m^2/s] */
  int nwalls;
  wf_wall *walls;
  int nremove;
  char (*remove)[WF_NAME];
  int ntractions;
  wf_traction *tractions;
  double strength_reduction; /* strengths are the material's / this factor from this
                              * stage on (absolute, not cumulative); 0 = unchanged   */
  int reset_velocity;
  int force_dt;               /* accept a dt above the stability limit            */
  int end_kind;
  double end_time;           /* stage duration [s] (WF_END_TIME)                    */
  double ke_ratio, max_time, min_time; /* quasi-static end                          */
  double dt_factor, dt;      /* dt > 0: fixed step                                  */
  int snapshots;             /* HDF5 snapshots during the stage (plus its end)      */
  int series_points;         /* rows of series.csv for the stage                    */
  int nmotion;               /* rigid-body velocities set by the stage (rigid.c)    */
  wf_rigid_motion *motion;
  int has_fos;               /* the stage is a factor-of-safety search (fos)        */
  wf_fos fos;
} wf_stage;

typedef enum { WF_METRIC_RUNOUT, WF_METRIC_TIP_Y, WF_METRIC_TIP_X, WF_METRIC_COM_X,
  WF_METRIC_SETTLEMENT_B, WF_METRIC_Q_SU, WF_METRIC_BEARING, /* bearing_capacity_ratio (rigid.c) */
  WF_METRIC_FRONT_X, WF_METRIC_HYDRO, /* surge_front_x, hydrostatic_pressure_error (report.c) */
  WF_METRIC_COUNT } wf_metric_kind;
typedef struct {
  int enabled[WF_METRIC_COUNT];
  int has_toe;
  double toe;                /* runout: initial toe abscissa                        */
  int runout_material;       /* runout: only this scene material's points; -1: all  */
  int runout_axis;
  double point[3];           /* tip displacement: the point whose motion is tracked */
  int tip_id;                /* id of the nearest material point (set at run time)  */
  /* bearing_capacity_ratio (rigid.c, docs/contact.md): body, footing width B for delta/B,
   * the width the modelled reaction acts on (B/2 in a half model), su, the load axis, and
   * the window: mean q/su over settlements from `from` x the final settlement on */
  int bearing_body, bearing_axis;
  double bearing_B, bearing_width, bearing_su, bearing_from;
  struct wf_bearing *bearing; /* per-step record (run time)                          */
  /* hydrostatic_pressure_error (report.c): RMS of p - rho g (surface - x_v) over the RMS of
   * rho g (surface - x_v), x_v along gravity; live, or kept from the end of hydro_stage */
  double surface, hydro_g;
  int hydro_axis, hydro_stage, hydro_frozen;
  double hydro_value;
} wf_metrics;

/* ---- snapshot plots at given times (snapshot_plots.c) ------------------------------ */
typedef enum { WF_COLOR_PRESSURE, WF_COLOR_MEAN_STRESS, WF_COLOR_EPS_P, WF_COLOR_DISPLACEMENT, WF_COLOR_SPEED,
               WF_COLOR_COUNT } wf_color;
typedef struct {
  int stage;                 /* times are measured from the start of this stage          */
  int color;                 /* wf_color                                                  */
  int ntimes;
  double *times;             /* [s] after the stage's start                              */
  int has_range;
  double range[2];           /* colour range (default: common min/max of the snapshots)  */
} wf_snapplot;

/* water_table: the piezometric line (x, h) or, in 3D, plane h = a + b x + c y
 * (mpmc_sim_set_water_table) */
typedef struct {
  int n;                     /* polyline vertices; 0: none (or the plane)            */
  double *xh;                /* [n][2]                                               */
  int has_plane;
  double plane[3];
  double gamma_w;            /* unit weight of water [N/m^3]                         */
} wf_water;

typedef struct {
  char path[WF_PATH];        /* the scene file as given                             */
  char dir[WF_PATH];         /* its directory (for relative mesh paths)             */
  char name[WF_NAME];
  int dim;
  int basis, fbar, solver, threads;
  int sort_interval;        /* steps between sorts of the points by cell; 0: never */
  int balance_every;        /* over MPI: balance the slabs every this many steps (0: not by count) */
  double balance_threshold; /* ... or beyond this max/mean points (0: not by threshold)     */
  double flip;
  double lo[3], hi[3], h;
  int nmat;
  wf_material *mats;
  int nbody;
  wf_body *bodies;
  int nstage;
  wf_stage *stages;
  int nrigid;                /* rigid bodies (rigid.c)                               */
  wf_rigid *rigid;
  double contact_dhat, contact_kappa; /* barrier parameters, 0: defaults           */
  wf_metrics metrics;
  int nsnapplot;             /* snapshot_plots: PNGs of the state at given times        */
  wf_snapplot *snapplots;
  int plots;                 /* write PNG plots                                     */
  wf_water water;            /* water_table: hydrostatic pore pressure (water.c)    */
  double checkpoint_interval;/* wall seconds between checkpoints inside a stage     */
  double progress_interval;  /* wall seconds between plain progress lines           */
} wf_scene;

/* Load, override and read a scene.  On failure returns non-zero with a message
 * "file:line:col: key 'a.b': ..." in msg. */
int wf_scene_load(const char *path, int noverride, const char *const *overrides, wf_scene *scene,
                  char *msg, size_t msglen);
void wf_scene_free(wf_scene *scene);
const char *wf_basis_name(int basis);
const char *wf_model_name(int model);

/* ---- reports (report.c) ---------------------------------------------------------- */
/* What a stage did: summary.json's "stages" and the checkpoints' records (run.c). */
typedef struct {
  char name[WF_NAME];
  double sim_time, wall_seconds;
  long steps;
  const char *reason;        /* "time", "quasi_static", "max_time", "fos"; NULL: not done */
  double strength;           /* the strength reduction factor in force at its end (1: none) */
} wf_stage_record;

/* ---- the workflow's record in a checkpoint (record.c) ---------------------------------- */
/* Where a stage stands between two steps: what a checkpoint inside the stage records so that
 * the resumed stage takes the same steps as the uninterrupted one (the step size is computed
 * every 10 steps counted from the stage's start, and kept in between; the next series row and
 * snapshot are running sums). */
typedef struct {
  double t_stage;     /* time into the stage                                            */
  double dt;          /* the step last computed (0: compute it on the next step)        */
  double ke, ke_max, ratio;   /* kinetic energy, its stage maximum, their ratio         */
  double next_series, next_snap; /* stage times of the next row and snapshot (0: derive) */
} wf_clock;
/* Where the run stands: the checkpoint's metadata, as text ("mpmc-workflow 1" and one
 * "key value" line each), which `mpmc resume` reads back. */
typedef struct {
  char scene[WF_PATH];       /* the scene file, absolute                                */
  int stage;                 /* the stage to run (nstage: the run is finished)          */
  int setup;                 /* 1: inside the stage, which is set up already             */
  wf_clock clock;            /* with setup                                              */
  long steps;                /* steps of the stage so far                               */
  double ke_below;           /* the quasi-static test's hold (-1: above)                */
  double strength;           /* the strength reduction factor in force                  */
  int nset, nwall, ndone;
  char **sets;               /* the run's --set overrides [nset]                        */
  int *walls;                /* the library's ids of the scene's walls added [nwall]    */
  wf_stage_record *done;     /* the finished stages [ndone]; reason a static string     */
} wf_record;
/* r as text into buf; 0, or -1 when it does not fit */
int wf_record_format(const wf_record *r, char *buf, size_t len);
/* text (a checkpoint's metadata; NULL: none) into r, which the caller frees with
 * wf_record_free; 0, MPMC_ERR_FORMAT (not a workflow's record, msg says why) or MPMC_ERR_MEMORY */
int wf_record_parse(const char *text, wf_record *r, char *msg, size_t len);
int wf_record_add_set(wf_record *r, const char *set); /* 0 or MPMC_ERR_MEMORY */
void wf_record_free(wf_record *r);

/* ---- the factor-of-safety search (fos.c) ------------------------------------------ */
#define WF_FOS_MAX_JOBS 16 /* factor_of_safety.jobs at most */
typedef struct {
  double factor, max_displacement, growth, ke_ratio, sim_time, wall_seconds;
  long steps;
  int failed;
} wf_fos_trial;
typedef struct {
  int ntrial;
  wf_fos_trial trial[64];
  double lo, hi;             /* the final bracket: lo stood, hi failed                  */
  int found;                 /* 1: bracketed to the tolerance                           */
  int mechanism;             /* 1: outdir/fos_mechanism.csv holds the trial at hi's end  */
  int jobs;                  /* trials run at once                                      */
} wf_fos_result;
/* The search of stage s from the state sim (set up for the stage), which it leaves as it is:
 * the state is saved to outdir/fos_base.h5 and every trial starts from it.
 * say(data, line) reports each trial.  0, or an mpmc error code with msg. */
int wf_fos_search(mpmc_context ctx, mpmc_sim sim, const wf_scene *sc, int stage, const char *outdir,
                  wf_fos_result *res, void (*say)(void *data, const char *line), void *data, char *msg,
                  size_t len);
/* fos_trials.csv and summary.json's fos fields (report.c) */
int wf_fos_write_csv(const char *path, const wf_fos_result *res);
void wf_fos_json(FILE *f, const wf_fos_result *res);
/* The trials of a finished search read back from its fos_trials.csv (resume); 0, or an error
 * with msg naming the file and row. */
int wf_fos_read_csv(const char *path, wf_fos_result *res, char *msg, size_t len);
/* factor_of_safety.jobs within [1, WF_FOS_MAX_JOBS] */
int wf_fos_jobs(const wf_fos *f);
/* plot.c: the plots' horizontal and vertical axes; points ordered far (large depth) first */
void wf_view_axes(const wf_scene *sc, int *hx, int *vy);
typedef struct {
  double depth;
  int q;
} wf_depth_idx;
int wf_by_depth(const void *a, const void *b);
/* The state at a trial's end as a CSV in final_state.csv's columns, the displacement since
 * the trial's start (the points' initial positions, which the trial sets) (plot.c); 0, or -1. */
int wf_fos_mechanism_write(mpmc_sim sim, const wf_scene *sc, const char *path);
/* fos_mechanism.png (from fos_mechanism.csv, when res->mechanism) and fos_trials.png (from
 * fos_trials.csv) in outdir; 0, or 1 with a warning (gnuplot missing or failed). */
int wf_fos_plots(const wf_scene *sc, int stage, const wf_fos_result *res, const char *outdir, char *warn,
                 size_t len);
FILE *wf_series_open(const char *path, const wf_scene *sc, int append, char *msg, size_t len);
int wf_series_row(FILE *f, mpmc_sim sim, const wf_scene *sc, int stage, long step, double dt, double ke,
                  double ratio);
/* series.csv cut back to the rows of at most `steps` steps (resume); 0, or -1 with msg. */
int wf_series_trim(const char *path, const wf_scene *sc, long steps, int *kept, char *msg, size_t len);
void wf_summary_write(const char *path, const wf_scene *sc, mpmc_sim sim, const char *error,
                      const wf_stage_record *rec, int nstages_done, double wall, const wf_fos_result *fos);
extern const char *const wf_metric_names[WF_METRIC_COUNT];
/* Compute the enabled metrics of the current state into values[WF_METRIC_COUNT]. */
int wf_metrics_compute(mpmc_sim sim, const wf_scene *sc, double *values);
/* Resolve per-run metric data (toe, tracked point) from the initial state. */
int wf_metrics_init(mpmc_sim sim, wf_scene *sc);

typedef struct {
  int tty;
  double last_print, start, stage_start;
  int width, stage;
} wf_progress;
void wf_progress_init(wf_progress *p);
/* frac < 0: unknown (quasi-static stages before their maximum time is near) */
void wf_progress_update(wf_progress *p, const wf_scene *sc, int stage, double t_stage,
                        double t_end, long steps, double steps_per_s, double interval, int force);
void wf_progress_done(wf_progress *p);

/* ---- rigid bodies (rigid.c) ------------------------------------------------------ */
/* Add the scene's rigid bodies and barrier parameters to the simulation. */
int wf_rigid_build(mpmc_sim sim, wf_scene *sc, char *msg, size_t len);
/* Before each step of stage i, t_stage into it: set the bodies' (ramped) velocities. */
int wf_rigid_before_step(mpmc_sim sim, const wf_scene *sc, int stage, double t_stage, char *msg,
                         size_t len);
/* After each step: record the footing's settlement and load (bearing_capacity_ratio). */
int wf_rigid_after_step(mpmc_sim sim, const wf_scene *sc, char *msg, size_t len);
/* The bearing metrics of the record: delta/B and q/su (mean since the last call with
 * mark = 1), and the ratio over the window; NAN without a record. */
void wf_bearing_values(const wf_scene *sc, int mark, double *delta_b, double *q_su, double *ratio);
void wf_rigid_free(wf_scene *sc);

/* ---- plots (plot.c) -------------------------------------------------------------- */
/* Final state (coloured by mean stress and equivalent plastic strain) and time series.
 * Returns 0, or 1 when gnuplot is missing or failed (a warning, not an error). */
int wf_plots_write(mpmc_sim sim, const wf_scene *sc, const char *outdir, char *warn, size_t len);

/* gnuplot as a child process, set up for CSV data and the palette (NULL with a warning when
 * it cannot run), a PNG terminal, and its end (0, or 1 with a warning). */
FILE *wf_gnuplot_open(const char *outdir, const char *log, const char *what, const char *nopng, char *warn,
                      size_t len);
void wf_gnuplot_terminal(FILE *g, int width, int height, int font);
int wf_gnuplot_close(FILE *g, const char *outdir, const char *log, char *warn, size_t len);

/* Keep metrics defined at the end of a stage (hydrostatic_pressure_error); report.c. */
int wf_metrics_stage_end(mpmc_sim sim, wf_scene *sc, int stage);

/* ---- snapshot plots (snapshot_plots.c) ------------------------------------------- */
extern const char *const wf_color_names[WF_COLOR_COUNT + 1]; /* NULL-terminated (get_enum) */
/* The next requested time of `stage` after t_stage (INFINITY: none): the run lands on it. */
double wf_snapplots_next(const wf_scene *sc, int stage, double t_stage);
/* Keep the state (snap_*.csv in outdir) for the requested times in (t_prev, t_stage]. */
int wf_snapplots_step(mpmc_sim sim, const wf_scene *sc, const char *outdir, int stage, double t_prev,
                      double t_stage, char *msg, size_t len);
/* Draw the PNGs of the kept snapshots; 0, or 1 with a warning (like wf_plots_write). */
int wf_snapplots_plot(const wf_scene *sc, const char *outdir, char *warn, size_t len);

/* ---- gmsh (gmsh_plugin.c) -------------------------------------------------------- */
int wf_seed_gmsh(mpmc_sim sim, const char *file, const char *region, int mode, int ppc,
                 int material, int *first, int *count, char *msg, size_t len);

/* ---- over MPI (par.c) ---------------------------------------------------------------- */
/* The run's ranks: over MPI (an MPI build, MPI initialised with several ranks) those of
 * MPI_COMM_WORLD; otherwise rank 0 of 1.  Rank 0 writes the front end's files and the log. */
int wf_par_size(void);
int wf_par_rank(void);
/* The same code on every rank: the lowest failing rank's (collective; err as it is alone). */
int wf_par_agree(int err);
/* Rank 0's buf on every rank; the sum and the largest of v over the ranks (collective). */
void wf_par_share(char *buf, int len);
long wf_par_total(long v);
double wf_par_max(double v);
/* v[0 .. n-1] of the one rank whose mine is set, on every rank, in place (collective; in
 * one process v as it is) */
void wf_par_one(double *v, int n, int mine);
/* The id of the least (d, id) over the ranks, d first, the smaller id on a tie; each rank
 * gives its own least (d = INFINITY when it has none) (collective; in one process id). */
int wf_par_least(double d, int id);
/* An exact sum of doubles: its value does not depend on the order of the additions, so
 * each rank sums its own points and wf_par_xsum gives the same bits on any number of ranks
 * as in one process.  A fixed-point number with its lowest bit at 2^-1074 (the least
 * subnormal), 32 bits a digit, the digits' carries taken every 2^29 additions (adds). */
#define WF_XSUM_DIGITS 68
typedef struct { /* zeroed: 0 */
  int64_t d[WF_XSUM_DIGITS];
  double special; /* the infinities and NaNs added, summed as doubles (+-inf or NaN) */
  long adds;      /* additions since the digits were last normalised */
} wf_xsum;
void wf_xsum_add(wf_xsum *s, double x);
double wf_xsum_value(wf_xsum *s); /* the exact sum rounded to a double (one rounding) */
/* s[0 .. n-1] summed over the ranks, in place, n <= WF_XSUM_MAX (collective; in one
 * process nothing) */
#define WF_XSUM_MAX 4
void wf_par_xsum(wf_xsum *s, int n);
/* A simulation over the run's ranks; one read back from a checkpoint over them. */
int wf_par_sim_create(mpmc_context ctx, int dim, mpmc_sim *sim);
int wf_par_checkpoint_read(mpmc_context ctx, const char *path, mpmc_sim *sim, char **meta);
/* The threads a rank takes where the scene leaves them open (threads: 0): over MPI without
 * OMP_NUM_THREADS, the node's cores shared among the ranks on it, at most the cores this
 * rank may run on, at least 1; else 0, OpenMP's default (collective). */
int wf_par_threads(void);
/* The log's line on the decomposition ("" in one process). */
void wf_par_plan(mpmc_sim sim, char *line, size_t len);
/* The scene's load_balance over MPI (mpmc_sim_set_mpi_balance); nothing in one process.
 * After a run, *imbalance: the most points on a rank over the mean, *balances: done. */
int wf_par_balance(mpmc_sim sim, int every, double threshold);
void wf_par_imbalance(mpmc_sim sim, double *imbalance, long *balances);
/* The points over the ranks (collective; in one process this one's). */
int wf_all_count(mpmc_sim sim, int *n);
/* Every point, read only, on rank 0 (collective): like mpmc_sim_get_field /
 * _get_particle_ids, but over MPI every rank's points gathered on rank 0 in the order of
 * their global ids (valid until the next call for the same field); the other ranks get
 * NULL and hold nothing.  For what rank 0 alone writes point by point. */
int wf_root_field(mpmc_sim sim, int field, double **data, int *ncomp);
int wf_root_ids(mpmc_sim sim, const int **ids);
void wf_root_release(void);
/* This rank's own points (collective over MPI, a rank without points agreeing, once for
 * all asked): their number, the fields asked (data[k] of fields[k]; NULL where fields[k] < 0),
 * their ids and material ids (either NULL: not asked). */
int wf_own(mpmc_sim sim, int *n, int nf, const int *fields, double **data, const int **ids, const int **mat);

/* Monotonic wall-clock seconds (report.c). */
double wf_now(void);

#endif
