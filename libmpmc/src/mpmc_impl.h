/* Private structures of libmpmc.  Not installed. */
#ifndef MPMC_IMPL_H
#define MPMC_IMPL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "mpmc.h"
#ifdef _OPENMP
#include <omp.h>
#endif

/* Parallel loops run on one thread below this many items: forking and joining the team
 * costs more than it saves for small scenes, and far more on a loaded machine. */
#define MPMC_OMP_MIN 4096
/* The threads the next parallel region gets: 1 in a build without OpenMP. */
static inline int mpmc_max_threads(void) {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/* ---- context and errors (context.c, error.c) ---------------------------------- */
#define MPMC_MSG_LEN 4096 /* room for a monitor report plus two output paths (workflows) */
struct mpmc_context_s {
  int last_code;
  char last_msg[MPMC_MSG_LEN];
  int log_level;
};

/* Record an error (file, line, formatted message) in ctx and return code. */
int mpmc_error_set(mpmc_context ctx, int code, const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
void mpmc_log(mpmc_context ctx, int level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#define MPMC_ERROR(ctx, code, ...) mpmc_error_set((ctx), (code), __FILE__, __LINE__, __VA_ARGS__)
/* Check cond; on failure record a message and return code from the calling function. */
#define MPMC_CHECK(cond, ctx, code, ...)                                                \
  do {                                                                                  \
    if (!(cond)) return mpmc_error_set((ctx), (code), __FILE__, __LINE__, __VA_ARGS__); \
  } while (0)
/* Propagate a non-zero code. */
#define MPMC_CALL(expr)          \
  do {                           \
    int mpmc_ierr_ = (expr);     \
    if (mpmc_ierr_) return mpmc_ierr_; \
  } while (0)

/* ---- particles (particles.c): structure of arrays ------------------------------- */
typedef struct {
  int n, cap, dim;
  double *x;     /* [n][dim] position                                             */
  double *x0;    /* [n][dim] initial position                                     */
  double *v;     /* [n][dim] velocity                                             */
  double *m;     /* [n] mass                                                      */
  double *vol0;  /* [n] initial volume                                            */
  double *J;     /* [n] det F                                                     */
  double *stress;/* [n][6] Cauchy stress, Voigt                                   */
  int *mat;      /* [n] material id                                               */
  /* allocated on demand (NULL when the scene does not need them) */
  double *Jbar;  /* [n] det F-bar                (F-bar on)                          */
  double *Janc;  /* [n] F-bar's anchored form: the anchored Jacobian, J times the point's
                    last Jbar / J (transfer.h, mpmc_anchor)                          */
  double *be;    /* [n][6] elastic left Cauchy-Green (solid materials)            */
  double *eps_p; /* [n] equivalent plastic strain (plastic materials)             */
  double *region;/* [n] where the last return went (frictional models, MPMC_MC_*)  */
  double *Jp;    /* [n] plastic volume ratio J / J_e of dilatant flow (frictional
                    models with F-bar on): F-bar projects J / Jp, the volume change
                    that is not plastic, and hands the material Jp x the projection,
                    so that plastic dilation stays at its point (fbar.c)           */
  double *pw;    /* [n] pore pressure of the water table (water.c; with one only)  */
  double *lp;    /* [n] uGIMP half-length, fixed at its initial value (uGIMP)      */
  double *force; /* [n][dim] external force (tractions)                           */
  double *cforce;/* [n][dim] contact force from rigid bodies (contact_barrier.c)   */
  double *ustate;/* [n][nustate] state of user materials (material_user.c)        */
  int nustate;
  int *id;       /* [n] the index each point had when added (allocated by the first sort or
                    mpmc_sim_get_particle_ids; NULL: ids are the indices) (sort.c)      */
  int global_ids; /* over MPI: ids are indices among every rank's points (always named)  */
  /* step scratch */
  double *dF;    /* [n][dim*dim] relative deformation gradient, row-major         */
} mpmc_particles;

/* A point's name in error messages: its index, and its id (the index it was added with)
 * when a sort by cell has moved it, e.g. "57 (id 1203)". */
#define MPMC_POINT_NAME_LEN 40
static inline const char *mpmc_point_name(const mpmc_particles *p, int q, char *buf) {
  if (p->id && (p->id[q] != q || p->global_ids))
    snprintf(buf, MPMC_POINT_NAME_LEN, "%d (id %d)", q, p->id[q]);
  else
    snprintf(buf, MPMC_POINT_NAME_LEN, "%d", q);
  return buf;
}

int mpmc_particles_reserve(mpmc_context ctx, mpmc_particles *p, int cap);
int mpmc_particles_ensure(mpmc_context ctx, mpmc_particles *p, double **field, int ncomp,
                          double fill);
void mpmc_particles_free(mpmc_particles *p);

/* ---- grid (grid.c) ------------------------------------------------------------------ */
#define MPMC_GHOST 3 /* ghost cells outside the user box on each side (cubic needs 2) */
/* Doubles per node record, one cache line: slot 0 mass, 1 .. dim momentum, MPMC_FOFF ..
 * MPMC_FOFF + dim - 1 force, the rest zero (P2G adds to and G2P reads from one line per node,
 * in whole vectors of 2 or 4 doubles: the halves are mass-momentum and force). */
#define MPMC_NREC 8
#define MPMC_FOFF 4
/* Slot of F-bar's nodal volume sum w V^n (Algorithm 1 step 3) in the paper, total and
 * anchored forms: P2G scatters it with the mass (the points are at x^n there as in the
 * projection, and the slot rides in a vector P2G writes anyway), so G2P's fused scatter adds
 * one value per node, V^n j, instead of two; the grid update leaves the slot alone. */
#define MPMC_VSLOT 7
_Static_assert(MPMC_VSLOT >= MPMC_FOFF + 3 && MPMC_VSLOT < MPMC_NREC, "a free record slot");
typedef struct {
  int dim;
  double lo[3], hi[3]; /* user box                                                */
  double h, inv_h;
  double origin[3];    /* position of global node 0 (lo - GHOST*h)                 */
  int ng[3];           /* the whole grid's nodes per axis (1 in unused axes)        */
  /* The nodes held: n[a] per axis from global node off[a] (over MPI a rank holds only its
   * slab and halo along the slab axis: mpmc_grid_span; else off = 0, n = ng).  Node
   * indices are the held ones' everywhere: positions give global indices (origin), from
   * which off is subtracted exactly, so a held node has the same weights as in one process;
   * a linear index is the global formula with the held dims minus lin. */
  int n[3];            /* nodes held per axis                                       */
  int off[3];          /* global index of the first node held per axis              */
  size_t nn;           /* nodes held                                                */
  long long lin;       /* off[0] + n[0] (off[1] + n[1] off[2])                       */
  double *node;        /* [nn][MPMC_NREC] mass, momentum, f_int + f_ext (slots above), with
                          F-bar's paper, total and anchored forms sum w V^n in MPMC_VSLOT; after the
                          grid update mass, new velocity, velocity increment            */
  unsigned short *fixed; /* [nn] bit a: component a fixed; bit 3+a: v_a >= 0 only; bit 6+a: v_a <= 0 only */
  /* node index box [act_lo, act_hi) per axis outside which node and fb are zero: the points'
   * stencils of the last P2G (and the mirror partners the grid update folded into); the
   * step clears only this box and the grid update visits only it, each row over its rowx
   * range */
  int act_lo[3], act_hi[3];
  /* [n1 n2][2]: for each node row (j, k) of the active box, the x range [lo, hi) of its
   * nodes outside which node, fb and fbj are zero, as the box (mpmc_slabs_build: the
   * stencils of the points in the cell rows around it); a spreading flow leaves most of its
   * box empty (the landslide's at 4 s of run-out: 44 % of it reached), so the grid's passes
   * (clearing, the per-thread copies' sum, the grid update, F-bar's average) go row by row
   * over these ranges alone */
  int *rowx;
  int *rscratch; /* p2g.c scratch: per chunk, the x range of the cells of each cell row */
  size_t cap_rscratch;
  int rows_skip; /* slab builds left that take the whole box's rows (p2g.c, row_ranges) */
  int *ccount;         /* p2g.c scratch: points per plane of cells, slab fill positions   */
  size_t cap_ccount;
  /* per-thread accumulation (p2g.c, private_grids) when slabs cannot keep the threads busy:
   * the other threads' copies of node, zero outside the active box; nprivate: this step's
   * P2G ran that way on nprivate threads (G2P's F-bar scatter follows it) */
  double *priv;
  size_t cap_priv;
  int nprivate;
  int valid;
} mpmc_grid;

int mpmc_grid_setup(mpmc_context ctx, mpmc_grid *g, int dim, const double *lo, const double *hi,
                    double h);
int mpmc_grid_alloc(mpmc_context ctx, mpmc_grid *g);
/* Hold only the global nodes [lo, hi] along axis a (clipped to the grid; the other axes
 * whole): frees the node arrays when the span changes (mpmc_grid_alloc makes them anew) and
 * returns 1, else 0.  Over MPI (mpi.c) a rank's slab and halo. */
int mpmc_grid_span(mpmc_grid *g, int a, int lo, int hi);
/* the whole grid's nodes */
static inline size_t mpmc_grid_global_nodes(const mpmc_grid *g) {
  return (size_t)g->ng[0] * (size_t)g->ng[1] * (size_t)g->ng[2];
}
/* *a: n zeroed doubles, 64-byte aligned (unless *a is set already) */
int mpmc_grid_array(mpmc_context ctx, double **a, size_t n);
/* zero the whole grid (every node active) */
void mpmc_grid_clear(mpmc_grid *g);
/* zero the active box only (the hot path: everything outside it is zero already) */
void mpmc_grid_clear_active(mpmc_grid *g);
double *mpmc_grid_copies(const mpmc_grid *g, double **buf, size_t *cap, int width, int ncopies);
void mpmc_grid_add_copies(const mpmc_grid *g, double *dst, double *copies, int width,
                          int ncopies);
void mpmc_grid_free(mpmc_grid *g);
/* every row of the active box over the box's whole x range (grid.rowx) */
void mpmc_grid_rows_full(mpmc_grid *g);
/* The active box as rows of nodes along x: their number, and row r's first active node and
 * the number of active nodes that follow it consecutively (its rowx range, at most the box's
 * act_hi[0] - act_lo[0]). */
static inline long mpmc_grid_active_rows(const mpmc_grid *g) {
  const long ny = g->act_hi[1] - g->act_lo[1], nz = g->act_hi[2] - g->act_lo[2];
  return g->act_hi[0] > g->act_lo[0] && ny > 0 && nz > 0 ? ny * nz : 0;
}
/* node i's plane along axis a (its index j, k or l) */
static inline long mpmc_grid_plane(const mpmc_grid *g, int a, size_t i) {
  const long n0 = g->n[0], n1 = g->n[1], l = (long)i;
  return a == 0 ? l % n0 : a == 1 ? l / n0 % n1 : l / (n0 * n1);
}
/* the grid row (j, k) index j + n1 k of the active box's row r */
static inline size_t mpmc_grid_row_index(const mpmc_grid *g, long r) {
  const long ny = g->act_hi[1] - g->act_lo[1];
  return (size_t)(g->act_lo[1] + r % ny) + (size_t)g->n[1] * (size_t)(g->act_lo[2] + r / ny);
}
static inline size_t mpmc_grid_active_row(const mpmc_grid *g, long r, size_t *len) {
  const size_t row = mpmc_grid_row_index(g, r);
  const int lo = g->rowx[2 * row], hi = g->rowx[2 * row + 1];
  *len = hi > lo ? (size_t)(hi - lo) : 0;
  return (size_t)lo + (size_t)g->n[0] * row;
}
/* nodal mass of node i (after P2G) */
static inline double mpmc_grid_mass(const mpmc_grid *g, size_t i) {
  return g->node[i * MPMC_NREC];
}

/* ---- F-bar's step state (fbar.c owns it; the life of a step is told at the top of fbar.c) */
/* What the projection keeps between the phases of one step, none of it from one step to the
 * next: the nodal sums and what G2P keeps of x^n for the gather.  The points' own F-bar
 * state travels with them in the particle arrays (Jbar, Janc, Jp: sorted, migrated and
 * checkpointed with the rest) and the nodal volume sum of the paper, total and anchored
 * forms rides in the node records (MPMC_VSLOT).  Allocated by mpmc_fbar_prepare for the form
 * in use; what a form does not use stays NULL. */
typedef struct {
  size_t nn;      /* grid nodes the sums hold (0: none allocated)                        */
  double *fb;     /* [nn][2] the stable form only: sum w V, sum w V J in its own space   */
  double *fbj;    /* [nn + 4] the nodal Jbar in the active box; in the paper, total and
                     anchored forms G2P scatters sum w V^n j here first, which the
                     average divides by MPMC_VSLOT's sum in place; the gather loads rows
                     of four from a row's first node, the lanes beyond the stencil unused */
  double *priv;   /* G2P's other threads' copies of fb or fbj, when P2G ran on private
                     grids (g2p.c; grid.nprivate)                                       */
  size_t cap_priv;
  int cap;        /* points the kept arrays below hold (at least the particles' n)      */
  double *xn;     /* [cap][dim] the stable form: x^n, from G2P (which moves x) to the gather */
  double *xoff;   /* [dim][cap] the paper, total and anchored forms: the points' offsets at
                     x^n from their first stencil nodes (axis a's at xoff + a cap), from
                     which the basis gives their weights (transfer.h, mpmc_kept_weights4) */
  int *xnode;     /* [cap] those first stencil nodes                                     */
  double *scale;  /* [cap_scale] the deferred gather's factors of dF (stress_j2.c,
                     stress_blocks.c), allocated by the first deferred gather            */
  int cap_scale;
  int scattered;  /* G2P scattered this step's volumes (fused, race-free)                */
  int deferred;   /* the step's gather is left to the material update (every material's
                     ops->gathers_fbar): it takes x^n as G2P kept it                     */
} mpmc_fbar_state;

/* ---- materials: the model table (material_table.c) and one file per model ------------- */
struct mpmc_sim_s;
typedef struct mpmc_material_s mpmc_material;

/* How a model updates its points. */
typedef struct {
  const char *name;
  /* Update the stress of every point p with mat[p] == id from the relative deformation
   * gradient dF (F-bar scaled when F-bar is on).  Batched over the particle arrays. */
  int (*stress_update)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt);
  /* p-wave speed for the stable time step */
  double (*wave_speed)(const mpmc_material *mat);
  /* 1: stress_update runs F-bar's gather for its points itself when the step defers it
   * (sim->fb.deferred; fbar.c mpmc_fbar_gather_range), scaling dF as it loads it */
  int gathers_fbar;
  /* 1: stress_update guards its stresses itself: the lowest index of a point it left with a
   * non-finite stress into sim->scr.stress_bad (stress_update.c) */
  int checks_stress;
} mpmc_material_ops;

/* A model's description (material_table.c lists them): its name, parameters with units and
 * ranges, per-point state and strength-reduction rule.  The library's validation, the
 * checkpoint, the scene reader, `mpmc check` and the docs' parameter table read it. */
#define MPMC_MAX_PARAM 16
_Static_assert(MPMC_MAX_PARAM == MPMC_MAX_PARAMS, "the public and the table's parameter limit");
#define MPMC_RAD 0.017453292519943295 /* pi / 180: parameters in degrees to radians */
typedef struct {
  const char *name;      /* key in scenes and checkpoints                               */
  const char *unit;      /* "Pa", "deg", "kg/m^3", "1", "Pa s"                          */
  const char *doc;       /* one line                                                    */
  double lo, hi;         /* valid range                                                 */
  unsigned flags;        /* MPMC_PARAM_*                                                */
  double def;            /* default when MPMC_PARAM_OPTIONAL (NAN: default_of's value)  */
  int default_of;        /* default: the value of this parameter (-1: def)              */
  int at_most;           /* must not exceed this parameter's value (-1: no such rule)   */
  int alias_of;          /* an alternative way to give parameter alias_of, times scale  */
  double scale;          /*   (not stored; -1: a parameter of its own)                  */
  const char *const *words; /* a choice: the value is the index of the word             */
} mpmc_param_desc;

typedef struct mpmc_model_s {
  const char *name;      /* model key in scenes and checkpoints ("hencky_j2")           */
  const char *doc;       /* one line                                                    */
  int nparam;            /* entries in param (stored ones first, then aliases)          */
  int nstore;            /* stored parameters: par[0 .. nstore)                         */
  const mpmc_param_desc *param;
  unsigned flags;        /* MPMC_MODEL_*                                                */
  int strength[MPMC_MAX_PARAM]; /* strength reduction: per stored parameter,
                            MPMC_SRM_KEEP (0), MPMC_SRM_DIVIDE (a strength) or
                            MPMC_SRM_TAN (an angle in degrees whose tangent is divided)   */
  /* derive the material's constants from m->par (after validation; may add checks) */
  int (*setup)(mpmc_context ctx, mpmc_material *m);
  const mpmc_material_ops *ops;
} mpmc_model;

enum { MPMC_PARAM_OPTIONAL = 1, MPMC_PARAM_LO_OPEN = 2, MPMC_PARAM_HI_OPEN = 4 };
/* Table entries: a parameter in [lo, hi] (flags: open ends, optional with default def or,
 * def_of >= 0, the value of parameter def_of; at_most >= 0: not above that parameter), an
 * alias (another way to give parameter of, times scale), a choice among words (default the
 * word numbered def). */
#define MPMC_PARAM(nm, un, dc, lo_, hi_, fl, def_, def_of, at_most_)                          \
  {.name = nm, .unit = un, .doc = dc, .lo = lo_, .hi = hi_, .flags = fl, .def = def_,         \
   .default_of = def_of, .at_most = at_most_, .alias_of = -1, .scale = 1.0, .words = NULL}
#define MPMC_ALIAS(nm, un, dc, lo_, hi_, fl, of, sc)                                          \
  {.name = nm, .unit = un, .doc = dc, .lo = lo_, .hi = hi_, .flags = fl, .def = 0.0,          \
   .default_of = -1, .at_most = -1, .alias_of = of, .scale = sc, .words = NULL}
#define MPMC_CHOICE(nm, dc, w, def_)                                                          \
  {.name = nm, .unit = "", .doc = dc, .lo = 0.0, .hi = 0.0, .flags = MPMC_PARAM_OPTIONAL,     \
   .def = def_, .default_of = -1, .at_most = -1, .alias_of = -1, .scale = 1.0, .words = w}
/* the solid models' first three parameters: E, nu, rho */
#define MPMC_PARAMS_ELASTIC                                                                   \
  MPMC_PARAM("E", "Pa", "Young's modulus", 0.0, INFINITY, MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, \
             0.0, -1, -1),                                                                    \
  MPMC_PARAM("nu", "1", "Poisson's ratio", 0.0, 0.5, MPMC_PARAM_HI_OPEN, 0.0, -1, -1),       \
  MPMC_PARAM("rho", "kg/m^3", "density", 0.0, INFINITY,                                       \
             MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, 0.0, -1, -1)
/* E, nu, rho of m->par[0..2] to the elastic constants (material_table.c) */
void mpmc_material_elastic(mpmc_material *m);
enum {
  MPMC_MODEL_SOLID = 1,     /* keeps b_e per point                                       */
  MPMC_MODEL_PLASTIC = 2,   /* keeps eps_p per point                                     */
  MPMC_MODEL_REGION = 4,    /* keeps the return region per point                         */
  MPMC_MODEL_CALLBACK = 8,  /* needs the caller's function: added by its own constructor */
  MPMC_MODEL_FLUID = 16,    /* no elastic deviator (the energy check's density)          */
  MPMC_MODEL_EFFECTIVE = 32, /* stresses from the skeleton's strains are effective: a water
                               table's pore pressure is subtracted (water.c)              */
  MPMC_MODEL_HENCKY = 64    /* Hencky elasticity on b_e (geostatic.c sets its state)       */
};
/* The saturated density below a water table, after the model's other stored parameters;
 * rho's by default (water.c). */
#define MPMC_PARAM_RHO_SAT(rho_index)                                                         \
  MPMC_PARAM("rho_sat", "kg/m^3", "saturated density (below a water table)", 0.0, INFINITY,   \
             MPMC_PARAM_OPTIONAL | MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, NAN, rho_index, -1)
enum { MPMC_SRM_KEEP = 0, MPMC_SRM_DIVIDE = 1, MPMC_SRM_TAN = 2 };

/* the table (material_table.c) */
int mpmc_model_table_size(void);
const mpmc_model *mpmc_model_at(int k);
const mpmc_model *mpmc_model_named(const char *name);
/* add a material of model from its stored parameters (validated against the table) */
int mpmc_material_add(struct mpmc_sim_s *sim, const mpmc_model *model, const double *par,
                      int *id);
/* re-derive m's constants after par changed (strength reduction) */
int mpmc_material_setup(mpmc_context ctx, mpmc_material *m);
/* a material read back from a checkpoint: m->par0 validated, then reduced by m->srm */
int mpmc_material_restore(mpmc_context ctx, mpmc_material *m);

struct mpmc_material_s {
  const mpmc_model *model;
  const mpmc_material_ops *ops;             /* the model's (restored user materials:
                                               unattached until re-attached)            */
  double par[MPMC_MAX_PARAM];               /* stored parameters, strength reduced      */
  double par0[MPMC_MAX_PARAM];              /* as given                                  */
  double srm;                               /* strength reduction factor applied (1)    */
  /* derived by the model's setup */
  double rho;
  double rho_sat;                           /* below a water table (rho without one)    */
  double E, nu, K, G, lambda;               /* elastic constants                     */
  double kappa_p, kappa_r, eta;             /* J2 softening                          */
  double mu;                                /* fluid viscosity                       */
  int solid;                                /* needs be                              */
  int plastic;                              /* needs eps_p                           */
  /* user materials (material_user.c, material_user_yield.c) */
  mpmc_user_stress_fn user_fn;              /* the caller's stress update            */
  mpmc_yield_fn yield_fn;                   /* the caller's yield surface            */
  void *user_data;                          /* handed back to user_fn                */
  int user_nstate;                          /* state variables it uses per point     */
  double user_wave_speed;                   /* p-wave speed for the stable time step */
};

/* ---- walls (boundary.c) ------------------------------------------------------------ */
typedef struct {
  int active;
  int kind, axis, side;
  double lo[3], hi[3]; /* the constrained region (infinite in unbounded directions) */
  int nodeset;         /* >= 0: the wall constrains this node set instead of a region */
} mpmc_wall;

/* A wall on a node plane, unbounded along the other axes: the ghost nodes beyond it take the
 * mirror image of the velocities inside (odd for constrained components, even for free
 * ones), so that B-splines see a wall at the plane instead of a clamped layer of ghosts. */
typedef struct {
  int axis, side, plane; /* plane: held node index of the wall along axis (grid.off) */
  unsigned odd;          /* bit a: component a is reflected with a sign change */
} mpmc_mirror;

/* ---- run monitor (monitor.c) --------------------------------------------------------- */
/* State of the energy check: the energy at a baseline and the work the external forces have
 * done since, and a signature of the inputs (gravity, walls, strengths, points, loads) that
 * starts a new baseline when it changes.  Zero-initialised with the sim (factor 0: default). */
typedef struct {
  double factor;       /* stop when E_k > factor * available; < 0: energy check off      */
  int64_t base_step;   /* step of the baseline; 0: none yet                              */
  double e0[2];        /* kinetic and elastic energy at the baseline [J]                 */
  double gx0, fx0;     /* sum m g.x and sum f.x at the baseline (work = their change)    */
  double sig[8];       /* input signature at the baseline                                */
  double ke_last;      /* kinetic energy at the last check                               */
  int64_t next_check;  /* step of the next velocity pass                                 */
} mpmc_monitor;
/* After each step: NaN/Inf velocity and kinetic energy above the energy available
 * (MPMC_ERR_UNSTABLE). */
int mpmc_monitor_step(struct mpmc_sim_s *sim);

/* ---- water table (water.c) ------------------------------------------------------------ */
/* The piezometric elevation h over the horizontal position: a polyline h(x) (2D, and 3D
 * extruded along y), or in 3D a plane h = a + b x + c y; the pore pressure of a point at
 * elevation z (the last coordinate) is gamma_w max(0, h - z). */
enum { MPMC_WATER_NONE = 0, MPMC_WATER_POLYLINE = 1, MPMC_WATER_PLANE = 2 };
typedef struct {
  int kind;           /* MPMC_WATER_NONE, MPMC_WATER_POLYLINE, MPMC_WATER_PLANE        */
  int n;              /* polyline vertices                                             */
  double *xh;         /* [n][2] (x, h), x increasing                                   */
  double plane[3];    /* a, b, c                                                       */
  double gamma_w;     /* unit weight of water [N/m^3]                                  */
} mpmc_water_table;
/* the pore pressure at position x (dim coordinates) */
double mpmc_water_pressure(const mpmc_water_table *wt, int dim, const double *x);
/* the name of a local solver for messages (step.c): "auto", "newton", "kinsol" */
const char *mpmc_solver_name(int solver);
/* p->pw of every point from its position (each step before the stresses) */
void mpmc_water_update(struct mpmc_sim_s *sim);
/* the density of a new point of material m at x: rho_sat below the water table */
double mpmc_water_density(const struct mpmc_sim_s *sim, const mpmc_material *m, const double *x);
/* set (kind MPMC_WATER_NONE: remove) the water table; masses: the points' masses follow
 * (rho_sat below, rho above), as mpmc_sim_set_water_table does, or stay (a checkpoint) */
int mpmc_water_set(struct mpmc_sim_s *sim, int kind, int n, const double *xh,
                   const double *plane, double gamma_w, int masses);

/* ---- the simulation ---------------------------------------------------------------- */
/* What the caller chose of the method (mpmc_sim_set_*): read by the steps, changed only
 * between them; checkpointed with the data. */
typedef struct {
  int dim;
  int basis;
  int fbar;           /* F-bar's form (mpmc_fbar_mode; 0: off)                          */
  double flip;        /* FLIP/PIC blend eta (eq 13)                                    */
  double pic_diff;    /* > 0: PIC's diffusivity D, eta = 1 - min(1, D dt / h^2)         */
  double gravity[3];
  double damping;     /* local damping alpha                                           */
  int kdamp;          /* kinetic damping on (damping.c, mpmc_kinetic_damping)           */
  int adr;            /* adaptive viscous damping on (damping.c)                        */
  double adr_zeta;    /* its damping ratio of the estimated mode: c = 2 zeta omega      */
  int solver;         /* local return mapping's solver (mpmc_solver)                    */
  int nthreads;       /* OpenMP threads of a step; 0: the caller's                      */
  int force_dt;       /* steps above the stability limit allowed                        */
  int kernels;        /* kernel set in use: MPMC_KERNELS_BASELINE or _AVX2              */
  int sort_every;     /* sort the points by cell every this many steps; 0: never        */
} mpmc_settings;

/* What a step rebuilds from the settings and the data, never checkpointed: the slabs of the
 * race-free scatter, the return maps' workspaces, the grid update's per-row sums, the
 * stress guard, the speed the stability limit reads, and what is to be rebuilt. */
typedef struct {
  int prepared;       /* fields and grid arrays match the configuration (mpmc_sim_prepare) */
  int walls_dirty;    /* recompute the node constraint flags                           */
  mpmc_mirror *mirrors; /* derived from the walls by mpmc_boundary_apply_flags          */
  int nmirror;
  int stress_bad; /* the step's stress guard: lowest point with a non-finite stress (INT_MAX) */
  void *solver_ws;    /* return-mapping workspaces (return_map.c), per thread          */
  double *adr_rows;   /* [rows][2] adaptive damping: the grid update's per-row sums, added in
                         row order                                                      */
  size_t adr_nrows;
  /* race-free scatter (p2g.c): points bucketed into slabs of at least MPMC_SLAB_W cells
   * along one axis; slabs of one colour (parity) never touch the same node, so they run in
   * parallel */
  int *order;         /* [n] point indices grouped by slab                             */
  int *slab_start;    /* [nslab + 1] offsets into order                                */
  int nslab, slab_axis, cap_order, cap_slab;
  int order_ident;    /* order[k] = k for all k (mpmc_slabs_build): the points are stored
                         slab by slab (as the sort leaves them, and the lattice seeding
                         where the slab axis is z), and G2P takes the same sequence
                         without the indirection (g2p.c) */
  /* the slabs of colour c that thread t scatters: c's slabs sl = group[c][t], + 2, ..., below
   * group[c][t + 1], for t < slab_nt (mpmc_slab_group, MPMC_SLABS_OF) */
  int *slab_group;    /* [2][slab_nt + 1] */
  int slab_nt, cap_group;
  /* max_p |v_p|^2 as G2P left v (stability.c reads it instead of a pass over v): valid
   * (v2max_ok) from a G2P while the velocity field is not borrowed (mpmc_sim_get_field,
   * until mpmc_sim_restore_field: both clear it) */
  double v2max;
  int v2max_ok;
} mpmc_scratch;

/* A simulation: its settings (cfg), its data (the points, the grid, the materials, walls,
 * bodies and sets, the water table, the time and the run's counters: what a checkpoint
 * holds) and the step's scratch (scr, and F-bar's, fb). */
struct mpmc_sim_s {
  mpmc_context ctx;
  mpmc_settings cfg;
  /* data */
  mpmc_particles p;
  mpmc_grid grid;
  mpmc_material *mats;
  int nmat, capmat;
  mpmc_wall *walls;
  int nwall, capwall;
  mpmc_water_table wt; /* hydrostatic pore pressure below a phreatic line (water.c)    */
  struct mpmc_bodies_s *bodies; /* rigid bodies and barrier contact (contact_barrier.c) */
  struct mpmc_sets_s *sets;     /* named particle sets (sets.c)                       */
  struct mpmc_sets_s *node_sets; /* named grid node sets (sets.c)                     */
  double time;
  mpmc_stats stats;
  mpmc_monitor monitor;         /* energy check after each step (monitor.c)           */
  double kd_ke;       /* kinetic damping: E_k of the points after the last step; -1: none */
  /* adaptive viscous damping (damping.c): c = 2 zeta omega, omega^2 a Rayleigh quotient of the
   * grid's force change over the velocity, smoothed as num / den of running sums */
  double adr_c;       /* the damping coefficient c [1/s] the next grid update applies   */
  double adr_sum[2];  /* running sums of v.(f^{n-1} - f^n) and dt m v.v (the quotient)  */
  double *adr_f;      /* [grid nn][1 + dim] (the held nodes): the step a node last held mass, its force then */
  size_t adr_nf;      /* doubles in adr_f (0: none)                                     */
  int adr_own[3];     /* over MPI: the slab axis and the held node planes [lo, hi) whose
                       * nodes this rank adds to the sums (each halo node once); axis -1: all */
  int64_t sort_last;  /* step count at the last sort; -1: none yet (sort.c)             */
  int sort_axis;      /* the slab axis the last sort put outermost; -1: none            */
  int v_borrowed;     /* the velocity field is on loan to the caller (mpmc_sim_get_field) */
  struct mpmc_dd_s *dd; /* the MPI decomposition (mpi.c); NULL: one process            */
  int64_t np_global;    /* points added so far over all ranks (their ids: 0 ..)        */
  /* scratch */
  mpmc_scratch scr;
  mpmc_fbar_state fb; /* F-bar's step state (fbar.c)                                  */
};

/* Minimum slab width in cells: a point in cell c touches nodes c-1 .. c+2 at most (cubic),
 * so two slabs of the same parity, one slab apart, share no node when the slab between them
 * is wider than 2 cells (slabs are widened beyond this to balance the points per thread). */
#define MPMC_SLAB_W 3
/* Chunk t of nc consecutive chunks of [0, n): the first index; chunk t ends where t + 1
 * begins (the slab build, and P2G's and G2P's per-thread grids, split the points so) */
static inline int mpmc_chunk_start(int n, int t, int nc) { return (int)((long long)n * t / nc); }
/* Thread t's slabs of colour c run from mpmc_slab_group(sim, c, t) (in steps of two) to
 * mpmc_slab_group(sim, c, t + 1) (p2g.c, slab_groups). */
#define mpmc_slab_group(sim, c, t) ((sim)->scr.slab_group[(c) * ((sim)->scr.slab_nt + 1) + (t)])
/* Loop header: the slabs sl of colour c, each thread its own run of them (slab_groups), in
 * an OpenMP loop whose pragma (with clauses for the body's reductions) precedes it. */
#define MPMC_SLABS_OF(sim, c, sl)                  \
  for (int t_ = 0; t_ < (sim)->scr.slab_nt; ++t_) \
    for (int sl = mpmc_slab_group(sim, c, t_); sl < mpmc_slab_group(sim, c, t_ + 1); sl += 2)
/* The slab axis for points whose cells span [clo, chi] per axis: the outermost axis of the
 * grid's memory (z in 3D, y in 2D) when the points span MPMC_SLAB_PLANES cell planes along
 * it, else the longest extent, ties to the outermost.  p2g.c slabs along it and sort.c puts it
 * outermost in its key, so the innermost sort axis, along which consecutive points follow
 * one another, is x, the axis along which node records are contiguous whenever x is not the
 * slab axis: with x as slab axis (the landslide's, 55 m long) consecutive points stepped
 * along y, a row of records (18 kB) apart, and G2P took a quarter longer.  24 planes make
 * eight slabs of three planes or more for two threads, four per colour (p2g.c balances the
 * points among them). */
#define MPMC_SLAB_PLANES 24
static inline int mpmc_slab_axis(int dim, const int *clo, const int *chi) {
  if (chi[dim - 1] - clo[dim - 1] + 1 >= MPMC_SLAB_PLANES) return dim - 1;
  int ax = dim - 1;
  for (int a = dim - 2; a >= 0; --a)
    if (chi[a] - clo[a] > chi[ax] - clo[ax]) ax = a;
  return ax;
}

/* The step's kernel phases (p2g.c, grid_update.c, g2p.c, fbar.c; stress_j2.c and
 * stress_blocks.c, the Hencky-J2, Neo-Hookean and Newtonian updates) exist once per
 * instruction set: CMakeLists.txt compiles these files three times more, for x86-64-v3 (AVX2)
 * with MPMC_ISA_AVX2 defined, which appends _avx2 to their external names, with MPMC_ISA_FMA
 * (_fma) and fused multiply-adds allowed, and as fma for x86-64-v4 (AVX-512) with
 * MPMC_ISA_AVX512 (_avx512; MPMC_ISA_FMA defined as well, the source's fma paths being its
 * own).  A sim runs one set (sim->cfg.kernels, mpmc_sim_set_kernels); baseline and avx2 give the
 * same bits, as ISO C mode allows no floating-point contraction (tests/t303); fma differs
 * from them by round-off; avx512 gives fma's bits with this compiler (t303 checks it): the
 * same operations, contracted alike, in the 32 vector registers of AVX-512's encoding. */
#if defined(MPMC_ISA_AVX512)
#define MPMC_ISA(fn) fn##_avx512
#elif defined(MPMC_ISA_FMA)
#define MPMC_ISA(fn) fn##_fma
#elif defined(MPMC_ISA_AVX2)
#define MPMC_ISA(fn) fn##_avx2
#else
#define MPMC_ISA(fn) fn
#define MPMC_ISA_BASELINE /* the baseline compile: a kernel file's functions that exist once */
#endif
#define MPMC_KERNEL_PROTOTYPES(S)                              \
  int mpmc_slabs_build##S(struct mpmc_sim_s *sim);             \
  int mpmc_p2g##S(struct mpmc_sim_s *sim, double dt);          \
  int mpmc_grid_update##S(struct mpmc_sim_s *sim, double dt);  \
  int mpmc_g2p##S(struct mpmc_sim_s *sim, double dt);          \
  int mpmc_fbar##S(struct mpmc_sim_s *sim, int defer);         \
  void mpmc_fbar_gather_range##S(struct mpmc_sim_s *sim, int id, int q0, int q1, double *scale); \
  int mpmc_nh_batch##S(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt); \
  int mpmc_hencky_batch##S(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt); \
  int mpmc_newtonian_batch##S(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt);
/* phases of one step (step.c calls them in this order, mpmc_stress_update last) */
MPMC_KERNEL_PROTOTYPES()
#if defined(MPMC_HAVE_AVX2_KERNELS) || defined(MPMC_ISA_AVX2) || defined(MPMC_ISA_FMA)
MPMC_KERNEL_PROTOTYPES(_avx2)
MPMC_KERNEL_PROTOTYPES(_fma)
MPMC_KERNEL_PROTOTYPES(_avx512)
#endif
int mpmc_stress_update(struct mpmc_sim_s *sim, double dt);
/* the sim's set of a material's update over blocks of four (stress_blocks.c), which the
 * material's ops->stress_update runs: MPMC_BATCH_NEO_HOOKEAN (mpmc_nh_batch),
 * MPMC_BATCH_HENCKY (mpmc_hencky_batch) or MPMC_BATCH_NEWTONIAN (mpmc_newtonian_batch) */
enum { MPMC_BATCH_NEO_HOOKEAN = 0, MPMC_BATCH_HENCKY = 1, MPMC_BATCH_NEWTONIAN = 2 };
typedef int (*mpmc_stress_batch_fn)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                                    double dt);
mpmc_stress_batch_fn mpmc_kernels_stress_batch(const struct mpmc_sim_s *sim, int model);
/* the step's stress guard (stress_update.c): 0 if a component of s (Voigt) is NaN or Inf */
static inline int mpmc_stress_finite(const double *s) {
  return isfinite(s[0] + s[1] + s[2] + s[3] + s[4] + s[5]);
}
/* 1 if this build carries the AVX2 kernels (avx2 and fma) and the processor (and OS) runs
 * them (kernels.c) */
int mpmc_kernels_avx2_available(void);
/* 1 if the AVX-512 kernels (avx512) can run here likewise (kernels.c) */
int mpmc_kernels_avx512_available(void);

/* sort.c: before a step, sort the points by cell if the sort interval has passed */
int mpmc_sort_due(struct mpmc_sim_s *sim);

/* helpers shared between files */
int mpmc_sim_prepare(struct mpmc_sim_s *sim);
int mpmc_boundary_apply_flags(struct mpmc_sim_s *sim);
void mpmc_damping_apply(double alpha, double *restrict f, const double *restrict v, int dim);
/* 1/2 sum m |v|^2 of the points over all ranks (sim.c; collective) */
double mpmc_points_kinetic_energy(const struct mpmc_sim_s *sim);
/* Kinetic damping after G2P: at a peak of the points' E_k, every point velocity to zero. */
void mpmc_kinetic_damping(struct mpmc_sim_s *sim);
/* Adaptive damping: the node store for the step's grid update (0, or MPMC_ERR_MEMORY), and
 * after it the new coefficient from the rows' sums (damping.c). */
int mpmc_adaptive_damping_prepare(struct mpmc_sim_s *sim, long nrow);
void mpmc_adaptive_damping_finish(struct mpmc_sim_s *sim, long nrow);
/* Over MPI the slab axis and the held node planes [own[1], own[2]) whose sums this rank
 * counts (the ranks' planes cover the grid's, each once); own[0] = -1 in one process. */
void mpmc_adaptive_damping_own(const struct mpmc_sim_s *sim, int own[3]);
double mpmc_stability_limit(const struct mpmc_sim_s *sim, double factor);
void mpmc_return_map_free(struct mpmc_sim_s *sim);
/* contact_barrier.c: fill p->cforce before P2G (only called when sim->bodies is set), the
 * time-step limit of the barrier stiffness (INFINITY without bodies), and clean-up */
int mpmc_contact_update(struct mpmc_sim_s *sim, double dt);
double mpmc_contact_stable_dt(const struct mpmc_sim_s *sim);
void mpmc_contact_free(struct mpmc_sim_s *sim);
/* after the step: a point that crossed into a body fails the step (MPMC_ERR_NUMERIC) */
int mpmc_contact_check(struct mpmc_sim_s *sim);
/* begin = 1: derive the barrier's parameters once and hold them until the call with 0, at
 * the end of mpmc_sim_step (only called when sim->bodies is set) */
void mpmc_contact_step(struct mpmc_sim_s *sim, int begin);
/* fbar.c, F-bar's state (compiled once, not per instruction set): prepare allocates the
 * points' Jbar (and Janc for the anchored form) and the state's arrays for the sim's form,
 * zeroed, freeing what the form does not use (off: all of it); reserve grows the kept arrays
 * to the particles' capacity before G2P writes them; clear zeroes the sums (what: below) and
 * forgets a scatter. */
enum {
  MPMC_FBAR_CLEAR_BOX = 0,    /* over the grid's active box (the step's, before P2G)       */
  MPMC_FBAR_CLEAR_ALL = 1,    /* over the whole grid                                       */
  MPMC_FBAR_CLEAR_VOLUMES = 2 /* over the active box, and the records' MPMC_VSLOT there   */
};
int mpmc_fbar_prepare(struct mpmc_sim_s *sim);
int mpmc_fbar_reserve(struct mpmc_sim_s *sim);
void mpmc_fbar_clear(struct mpmc_sim_s *sim, int what);
void mpmc_fbar_free(struct mpmc_sim_s *sim);
/* sets.c */
void mpmc_sets_free(struct mpmc_sim_s *sim);

/* mpi.c: the MPI decomposition; every function is a no-op (one process) when sim->dd is
 * NULL, as always in a build without MPI. */
#define MPMC_DD_MIN_CELLS 5 /* a slab's least width: only two ranks reach a halo node    */
enum { MPMC_DD_NODES = 0, MPMC_DD_FBAR = 1 }; /* what mpmc_dd_halo exchanges              */
/* An error a rank returns when it knows the step fails but another rank holds the point the
 * message names (mpmc_dd_agree takes that rank's message). */
#define MPMC_DD_FOLLOW (-1)
int mpmc_dd_setup(struct mpmc_sim_s *sim);
int mpmc_dd_keep(const struct mpmc_sim_s *sim, const double *x);
/* collective: the same error code and message on every rank (MPMC_DD_FOLLOW: see above) */
int mpmc_dd_agree(const struct mpmc_sim_s *sim, int err);
int mpmc_dd_halo(struct mpmc_sim_s *sim, int what);
int mpmc_dd_migrate(struct mpmc_sim_s *sim);
/* G2P's box narrowed to this rank's slab along its axis: beyond it a point may have left */
void mpmc_dd_slab_box(const struct mpmc_sim_s *sim, double *xmin, double *xmax);
/* G2P's finding: some point of this rank went beyond that box this step (any = 1) or none */
void mpmc_dd_leaving(struct mpmc_sim_s *sim, int any);
/* collective: mpmc_dd_agree, and *any = whether G2P found such a point on some rank */
int mpmc_dd_agree_leaving(struct mpmc_sim_s *sim, int err, int *any);
/* before a step: move the cuts and the points if a balance is due (collective) */
int mpmc_dd_balance_due(struct mpmc_sim_s *sim);
/* v[0 .. n) summed over the ranks in rank order (the same bits on every rank) / maximum */
void mpmc_dd_sum(const struct mpmc_sim_s *sim, double *v, int n);
void mpmc_dd_max(const struct mpmc_sim_s *sim, double *v, int n);
/* 1 on the (lowest) rank whose v is the largest */
int mpmc_dd_owner(const struct mpmc_sim_s *sim, double v);
/* the least v over the ranks and, of the ranks that have it, the least id (collective);
 * without any: v = +inf and id = -1 */
void mpmc_dd_minloc(const struct mpmc_sim_s *sim, double *v, int *id);
/* Records to other ranks: send holds scount[r] records of size bytes for each rank r, rank
 * after rank; *recv (malloc'ed, the caller frees it) gets rcount[r] from each rank r, rank
 * after rank, *rtotal in all (collective; one process: a copy).  scount, rcount: [ranks]. */
int mpmc_dd_exchange(struct mpmc_sim_s *sim, const void *send, const int *scount, size_t size, void **recv,
                     int *rcount, int *rtotal);
/* The k-th smallest (from 0) of every rank's v[0 .. n), non-negative and not NaN, exactly,
 * without gathering them: a bisection over the values with one count over the ranks a bit
 * (collective; in one process the same bisection) */
double mpmc_dd_kth(const struct mpmc_sim_s *sim, const double *v, int n, long long k);
/* the number of ranks (1 in one process) */
int mpmc_dd_ranks(const struct mpmc_sim_s *sim);
/* the decomposition's communicator (an MPI_Comm; NULL in one process) */
const void *mpmc_dd_comm(const struct mpmc_sim_s *sim);
void mpmc_dd_free(struct mpmc_sim_s *sim);

#endif
