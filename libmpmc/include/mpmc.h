/* libmpmc: explicit material point method with the assumed deformation gradient (F-bar)
 * of Zhao, Jiang & Choo (2023).  The core's public header; the optional libraries declare
 * theirs beside it (mpmc_gmsh.h: libmpmc_gmsh, mpmc_workflow.h: libmpmc_workflow).
 *
 * Conventions: every function returns an int error code, 0 (MPMC_SUCCESS) on success;
 * the context records a human-readable message for the last failure
 * (mpmc_context_last_error).  Handles are opaque.  destroy() takes the handle's address,
 * accepts NULL and sets the handle to NULL.  Units are SI throughout.
 * Stress is stored in Voigt order (xx, yy, zz, yz, xz, xy), tension positive.
 */
#ifndef MPMC_H
#define MPMC_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MPMC_VERSION_MAJOR 0
#define MPMC_VERSION_MINOR 1
#define MPMC_VERSION_PATCH 0

/* Error codes and their messages, defined once (enum and mpmc_error_string). */
#define MPMC_ERROR_LIST(X)                                                        \
  X(MPMC_SUCCESS, "success")                                                      \
  X(MPMC_ERR_ARG, "invalid argument")                                             \
  X(MPMC_ERR_MEMORY, "out of memory")                                             \
  X(MPMC_ERR_STATE, "call out of order")                                          \
  X(MPMC_ERR_OUTSIDE, "material point outside the grid")                          \
  X(MPMC_ERR_NUMERIC, "numerical failure (NaN, Inf or inverted volume)")          \
  X(MPMC_ERR_UNSTABLE, "unstable run (time step above the stability limit, or energy growing without input)") \
  X(MPMC_ERR_SOLVER, "local solver did not converge")                             \
  X(MPMC_ERR_IO, "input/output error")                                            \
  X(MPMC_ERR_FORMAT, "malformed or incompatible file")                            \
  X(MPMC_ERR_UNSUPPORTED, "not supported in this build")

#define MPMC_ERROR_ENUM_(name, msg) name,
typedef enum { MPMC_ERROR_LIST(MPMC_ERROR_ENUM_) MPMC_ERROR_COUNT } mpmc_error;
#undef MPMC_ERROR_ENUM_

typedef struct mpmc_context_s *mpmc_context;
typedef struct mpmc_sim_s *mpmc_sim;
/* a simulation the call only reads (a mpmc_sim converts to it) */
typedef const struct mpmc_sim_s *mpmc_const_sim;

typedef enum {
  MPMC_LOG_SILENT = 0,
  MPMC_LOG_ERROR = 1,
  MPMC_LOG_WARNING = 2,
  MPMC_LOG_INFO = 3,
  MPMC_LOG_DEBUG = 4
} mpmc_log_level;

typedef enum {
  MPMC_BASIS_LINEAR = 0,   /* standard MPM hat functions                         */
  MPMC_BASIS_UGIMP = 1,    /* GIMP with the particle domain fixed at its initial size */
  MPMC_BASIS_BSPLINE2 = 2, /* quadratic B-spline                                  */
  MPMC_BASIS_BSPLINE3 = 3  /* cubic B-spline                                      */
} mpmc_basis;

typedef enum {
  MPMC_WALL_FIXED = 0,    /* every velocity component zero                      */
  MPMC_WALL_SLIP = 1,     /* normal component zero (roller), tangential free     */
  MPMC_WALL_SEPARABLE = 2 /* normal component may only point away from the wall  */
} mpmc_wall_kind;

/* The F-bar projection (mpmc_sim_set_fbar). */
typedef enum {
  MPMC_FBAR_OFF = 0,   /* the standard formulation                                     */
  MPMC_FBAR_PAPER = 1, /* Algorithm 1 as published: projects Jbar^n dJ (eq 26)         */
  MPMC_FBAR_TOTAL = 2, /* projects the Jacobian det F (eqs 18-21 in eq 25): no drift in  */
                       /* long quasi-static runs (docs/theory.md)                       */
  MPMC_FBAR_STABLE = 3, /* the total form projected onto a space one order below the    */
                        /* basis: no checkerboard of the pressure (docs/theory.md)      */
  MPMC_FBAR_ANCHORED = 4 /* projects theta det F, theta = Jbar / J re-anchored as a   */
                         /* point changes volume or moves: Algorithm 1 in flows, no */
                         /* creep at rest (docs/theory.md); the scenes' default     */
} mpmc_fbar_mode;

typedef enum {
  MPMC_SOLVER_AUTO = 0,   /* scalar Newton, KINSOL where Newton is unsafe        */
  MPMC_SOLVER_NEWTON = 1, /* safeguarded scalar Newton only                      */
  MPMC_SOLVER_KINSOL = 2  /* SUNDIALS KINSOL with line search only               */
} mpmc_solver;

/* Instruction set of the step's transfer kernels (P2G, grid update, G2P, F-bar, the
 * Hencky-J2 update; mpmc_sim_set_kernels).  On x86-64 the library carries them four times:
 * for any x86-64, for x86-64-v3 (AVX2) with the same results to the bit, for x86-64-v3
 * with fused multiply-adds (about 10 % faster on the 3D landslide), whose results differ
 * from the other two by round-off, and the latter for x86-64-v4 (AVX-512), with the fused
 * set's results to the bit (GCC 12, tests/t303) and a few per cent faster where the
 * processor has it. */
typedef enum {
  MPMC_KERNELS_AUTO = 0,     /* AVX512 where the processor has AVX-512, else FMA     */
                             /* where it has AVX2, else BASELINE (the default); the  */
                             /* environment variable MPMC_KERNELS=auto|baseline|     */
                             /* avx2|fma|avx512 read by mpmc_sim_create overrides it */
  MPMC_KERNELS_BASELINE = 1, /* the build's own target (any x86-64 by default)       */
  MPMC_KERNELS_AVX2 = 2,     /* x86-64-v3, BASELINE's bits; refused where the build  */
                             /* or CPU lacks it                                      */
  MPMC_KERNELS_FMA = 3,      /* x86-64-v3 with fused multiply-adds; refused likewise */
  MPMC_KERNELS_AVX512 = 4    /* FMA for x86-64-v4 (AVX-512F/BW/CD/DQ/VL), FMA's bits; */
                             /* refused where the build or CPU lacks it              */
} mpmc_kernels;
/* The kernel set's name as MPMC_KERNELS and summary.json spell it ("auto", "baseline",
 * "avx2", "fma", "avx512"); "unknown kernel set" outside the list. */
const char *mpmc_kernels_name(mpmc_kernels kernels);

/* Particle fields, readable (and writable) in place.  ncomp per particle in brackets. */
typedef enum {
  MPMC_FIELD_POSITION = 0, /* [dim]                                                  */
  MPMC_FIELD_VELOCITY = 1, /* [dim]                                                  */
  MPMC_FIELD_MASS = 2,     /* [1]                                                    */
  MPMC_FIELD_VOLUME0 = 3,  /* [1] initial volume (plane strain: per unit thickness)  */
  MPMC_FIELD_J = 4,        /* [1] det F; current volume = J * volume0 (eq 15)        */
  MPMC_FIELD_JBAR = 5,     /* [1] det F-bar (only with F-bar on)                     */
  MPMC_FIELD_STRESS = 6,   /* [6] Cauchy stress, Voigt xx yy zz yz xz xy             */
  MPMC_FIELD_BE = 7,       /* [6] elastic left Cauchy-Green tensor, Voigt            */
  MPMC_FIELD_EPS_P = 8,    /* [1] equivalent plastic strain (plastic materials only) */
  MPMC_FIELD_FORCE = 9,    /* [dim] external force on the particle (tractions)      */
  MPMC_FIELD_X0 = 10,      /* [dim] initial position                                 */
  MPMC_FIELD_REGION = 11,  /* [1] where the last return mapping went (Mohr-Coulomb and
                              Drucker-Prager only): 0 elastic, 1 plane (cone), 2 edge in
                              triaxial compression, 3 in extension, 4 apex, 5 tension
                              cut-off, 6 and 7 its edges and corners (docs/materials.md) */
  MPMC_FIELD_PORE_PRESSURE = 12, /* [1] the water table's pore pressure (with one only) */
  MPMC_FIELD_COUNT = 13
} mpmc_field;

/* The phases of a step, as mpmc_stats.phase_seconds counts their wall time. */
typedef enum {
  MPMC_PHASE_SORT = 0,    /* sorting the points by cell (mpmc_sim_set_sort_interval)     */
  MPMC_PHASE_SLABS = 1,   /* clearing the grid, the points' slabs (P2G's colouring)       */
  MPMC_PHASE_P2G = 2,     /* mass, momentum and forces onto the grid                     */
  MPMC_PHASE_GRID = 3,    /* grid velocities, walls, damping                             */
  MPMC_PHASE_G2P = 4,     /* velocities, deformation, positions (with F-bar's scatter)   */
  MPMC_PHASE_FBAR = 5,    /* F-bar's nodal average and gather (when every material is
                             Hencky-J2, Hencky, Neo-Hookean or Newtonian the gather runs
                             in the material update, MPMC_PHASE_STRESS)                  */
  MPMC_PHASE_STRESS = 6,  /* the material update                                         */
  MPMC_PHASE_CHECKS = 7,  /* stability limit, rigid bodies' contact, run monitor         */
  MPMC_PHASE_COUNT = 8
} mpmc_phase;
/* The phase's name ("sort", "slabs", "p2g", "grid", "g2p", "fbar", "stress", "checks"), as
 * summary.json keys it; "unknown phase" outside the list. */
const char *mpmc_phase_name(mpmc_phase phase);

/* Run statistics, accumulated since creation. */
typedef struct {
  int64_t steps;
  double time;
  int64_t particle_steps;
  int64_t return_maps;       /* plastic corrections computed                        */
  int64_t kinsol_fallbacks;  /* return maps the auto solver handed to KINSOL        */
  double wall_seconds;       /* inside mpmc_sim_step                                */
  double phase_seconds[MPMC_PHASE_COUNT]; /* wall_seconds by phase (mpmc_phase)      */
} mpmc_stats;

/* ---- errors and context ------------------------------------------------------ */
const char *mpmc_error_string(int code);
int mpmc_context_create(mpmc_context *ctx);
int mpmc_context_destroy(mpmc_context *ctx);
const char *mpmc_context_last_error(const mpmc_context ctx);
int mpmc_context_get_last_error(const mpmc_context ctx, char *buf, int len);
int mpmc_context_clear_error(mpmc_context ctx);
int mpmc_context_get_last_code(const mpmc_context ctx, int *code);
/* Record an error as the library does ("<the code's mpmc_error_string>: message
 * [file:line]"); returns code (MPMC_ERR_ARG if ctx or message is NULL).  For the libraries
 * and callbacks built on libmpmc. */
int mpmc_context_set_error(mpmc_context ctx, int code, const char *file, int line,
                           const char *message);
int mpmc_context_set_log_level(mpmc_context ctx, mpmc_log_level level);
int mpmc_version(int *major, int *minor, int *patch);

/* ---- simulation set-up ----------------------------------------------------- */
int mpmc_sim_create(mpmc_context ctx, int dim, mpmc_sim *sim);
int mpmc_sim_destroy(mpmc_sim *sim);
int mpmc_sim_get_context(mpmc_const_sim sim, mpmc_context *ctx);
int mpmc_sim_get_dim(mpmc_const_sim sim, int *dim);
/* Uniform grid covering the box [lo, hi] with cells of size h; (hi - lo)/h is rounded up
 * to whole cells.  Ghost layers outside the box are added internally so that every basis
 * has full support for material points inside the box. */
int mpmc_sim_set_grid(mpmc_sim sim, const double *lo, const double *hi, double h);
int mpmc_sim_get_grid(mpmc_const_sim sim, double *lo, double *hi, double *h);
int mpmc_sim_set_basis(mpmc_sim sim, mpmc_basis basis);
int mpmc_sim_set_fbar(mpmc_sim sim, mpmc_fbar_mode mode); /* scenes: ANCHORED */
int mpmc_sim_get_fbar(mpmc_const_sim sim, mpmc_fbar_mode *mode);
int mpmc_sim_set_flip_blend(mpmc_sim sim, double eta);
/* PIC's share as a diffusivity D [m^2/s], for quasi-static stages: with D > 0 each step of
 * length dt on cells of size h blends eta = 1 - min(1, D dt / h^2) in place of the fixed
 * blend above.  PIC damps a smooth motion of wavelength L by about D / L^2 a second
 * whatever the time step (the bulk modulus) and the cell size, where a fixed share damps
 * it by the share a step; 0 (the default) returns to the fixed blend. */
int mpmc_sim_set_pic_diffusivity(mpmc_sim sim, double D);
int mpmc_sim_set_gravity(mpmc_sim sim, const double *g);
int mpmc_sim_set_damping(mpmc_sim sim, double alpha);
int mpmc_sim_set_kinetic_damping(mpmc_sim sim, int on); /* 0 off, 1 on */
/* Adaptive viscous damping for quasi-static stages (adaptive dynamic relaxation): nodal
 * velocities damped by c m v with c = 2 zeta omega, omega the lowest mode's frequency
 * estimated each step by a Rayleigh quotient over the grid (over MPI: summed over the
 * ranks); zeta in [0, 2], 1 critical, 0 off.  get: the c [1/s] the next step applies. */
int mpmc_sim_set_adaptive_damping(mpmc_sim sim, double zeta);
int mpmc_sim_get_adaptive_damping(mpmc_const_sim sim, double *c);
/* A water table: hydrostatic pore pressure p = gamma_w max(0, h - z) below the piezometric
 * elevation h (z: the last coordinate, gravity along -z).  h is a polyline of n vertices
 * xh = {x0, h0, x1, h1, ...} over x with x increasing (2D; in 3D the same across y), held
 * constant beyond its ends; n = 0 removes the table.  The models marked effective in the
 * table (Mohr-Coulomb, Drucker-Prager, user yield surfaces) take their stresses as effective
 * and carry the total sigma' - p I; the others (Hencky-J2's undrained total stresses) are
 * unaffected.  The points' masses follow: rho_sat below the table, rho above (points added
 * later too).  Pore pressure: MPMC_FIELD_PORE_PRESSURE. */
int mpmc_sim_set_water_table(mpmc_sim sim, int n, const double *xh, double gamma_w);
/* 3D: the piezometric plane h = a + b x + c y. */
int mpmc_sim_set_water_table_plane(mpmc_sim sim, double a, double b, double c, double gamma_w);
/* The geostatic state at once, under the current gravity (along -z): each soil point's
 * vertical stress from the overburden of its column of points, the horizontal ones K0
 * times it (effective stresses under a water table for the effective models), and the
 * elastic strain that carries them.  Points of models without Hencky elasticity are left
 * as they are. */
int mpmc_sim_set_geostatic_stress(mpmc_sim sim, double k0);
int mpmc_sim_set_solver(mpmc_sim sim, mpmc_solver solver);
int mpmc_sim_set_threads(mpmc_sim sim, int nthreads);
int mpmc_sim_set_kernels(mpmc_sim sim, mpmc_kernels kernels);
/* the set in use: BASELINE, AVX2, FMA or AVX512 */
int mpmc_sim_get_kernels(mpmc_const_sim sim, mpmc_kernels *kernels);

/* ---- materials; each returns its id ----------------------------------------- */
int mpmc_sim_add_material_neo_hookean(mpmc_sim sim, double E, double nu, double rho, int *id);
int mpmc_sim_add_material_hencky(mpmc_sim sim, double E, double nu, double rho, int *id);
/* Hencky elasticity + von Mises (J2) plasticity with exponential softening:
 * q = sqrt(3/2)|dev tau| <= kappa(eps_p) = kappa_r + (kappa_p - kappa_r) exp(-eta eps_p). */
int mpmc_sim_add_material_hencky_j2(mpmc_sim sim, double E, double nu, double rho,
                                    double kappa_p, double kappa_r, double eta, int *id);
/* The same with undrained shear strengths: kappa = sqrt(3) su (von Mises shear strength,
 * as in plane-strain shear; docs/materials.md). */
int mpmc_sim_add_material_hencky_j2_su(mpmc_sim sim, double E, double nu, double rho,
                                       double su_p, double su_r, double eta, int *id);
/* Hencky elasticity + Mohr-Coulomb plasticity (drained frictional soil): cohesion c [Pa],
 * friction and dilation angles phi, psi [deg], residual values c_r, phi_r, psi_r (NAN: the
 * peak value) reached exponentially with the accumulated plastic deviatoric strain at rate
 * eta, tension cut-off sigma_t [Pa] (INFINITY: none).  docs/materials.md. */
int mpmc_sim_add_material_mohr_coulomb(mpmc_sim sim, double E, double nu, double rho, double c,
                                       double phi, double psi, double c_r, double phi_r,
                                       double psi_r, double eta, double sigma_t, int *id);
/* The smooth cone matched to Mohr-Coulomb's c, phi (and psi) at its compression meridian,
 * its extension meridian or its plane-strain strength. */
typedef enum {
  MPMC_DP_MATCH_COMPRESSION = 0,
  MPMC_DP_MATCH_EXTENSION = 1,
  MPMC_DP_MATCH_PLANE_STRAIN = 2
} mpmc_dp_match;
int mpmc_sim_add_material_drucker_prager(mpmc_sim sim, double E, double nu, double rho, double c,
                                         double phi, double psi, double c_r, double phi_r,
                                         double psi_r, double eta, double sigma_t,
                                         mpmc_dp_match match, int *id);
/* The paper's strength reduction factor (landslide trigger), for mpmc_sim_reduce_strength. */
#define MPMC_DEFAULT_STRENGTH_REDUCTION 1.65
/* Nearly incompressible Newtonian fluid: p = -K (J - 1), deviatoric 2 mu dev(D). */
int mpmc_sim_add_material_newtonian(mpmc_sim sim, double K, double mu, double rho, int *id);
int mpmc_sim_get_num_materials(mpmc_const_sim sim, int *n);
/* Divide the strengths of a plastic material by factor (J2: kappa_p, kappa_r; Mohr-Coulomb
 * and Drucker-Prager: c, tan phi, tan psi and the tension cut-off); material = -1 for every
 * plastic material.  Factors compose.  Accumulated plastic strain is kept. */
int mpmc_sim_reduce_strength(mpmc_sim sim, int material, double factor);
/* Set the total factor instead: the strengths as given divided by factor (1 restores). */
int mpmc_sim_set_strength_reduction(mpmc_sim sim, int material, double factor);

/* ---- the material model table ---------------------------------------------------- */
/* Every model is described once (docs/materials.md is generated from the same table by
 * `mpmc models --markdown`): its parameters with units, ranges and defaults. */
typedef struct {
  const char *name, *doc;
  int nparam;         /* parameters, aliases included (mpmc_model_get_param)            */
  int nstore;         /* parameters mpmc_sim_add_material takes: the first nstore       */
  int plastic;        /* keeps an accumulated plastic strain per point                  */
  int needs_function; /* added by its own constructor with the caller's function        */
} mpmc_model_info;
typedef struct {
  const char *name, *unit, *doc;
  double lo, hi;          /* valid range; lo_open/hi_open: the end is excluded          */
  int lo_open, hi_open;
  int optional;           /* may be omitted (NAN in mpmc_sim_add_material): then def,   */
  double def;             /*   or parameter default_of's value when default_of >= 0     */
  int default_of;
  int at_most;            /* >= 0: must not exceed parameter at_most                    */
  int alias_of;           /* >= 0: another way to give parameter alias_of, times scale  */
  double scale;
  int strength;           /* strength reduction: 0 kept, 1 divided, 2 tan divided (deg) */
  int nwords;             /* > 0: a choice; the value is the index of one of words       */
  const char *const *words;
} mpmc_param_info;
int mpmc_model_count(int *n);
int mpmc_model_find(const char *name, int *model);
int mpmc_model_get_info(int model, mpmc_model_info *info);
int mpmc_model_get_param(int model, int k, mpmc_param_info *info);
/* Add a material of the named model from its first npar (<= nstore) parameters in the
 * table's order and units (NAN, or left out at the end: the default of an optional one). */
int mpmc_sim_add_material(mpmc_sim sim, const char *model, const double *par, int npar, int *id);
/* A material's model, current (strength-reduced) parameters and reduction factor; par holds
 * MPMC_MAX_PARAMS values (any may be NULL). */
#define MPMC_MAX_PARAMS 16
int mpmc_sim_get_material(mpmc_const_sim sim, int material, int *model, double *par,
                          double *factor);

/* ---- material points ------------------------------------------------------- */
/* Copies n points: x[n*dim] positions, volume[n] volumes (per unit thickness in 2D).
 * Mass = rho * volume.  *first (may be NULL) receives the index of the first new point. */
int mpmc_sim_add_particles(mpmc_sim sim, int n, const double *x, const double *volume,
                           int material, int *first);
int mpmc_sim_get_num_particles(mpmc_const_sim sim, int *n);
/* Borrow a particle field in place (no copy); give it back with restore.  Fields a scene
 * does not have (e.g. EPS_P without a plastic material) are MPMC_ERR_STATE.  The pointer
 * stays the field across steps and sorts until points are added (the arrays may move), and
 * until the field goes with what needs it (JBAR at the first step after F-bar is set off,
 * PORE_PRESSURE when the water table is removed); over MPI a step's migration may move every
 * field, so borrow again after each step.
 * While the velocity is on loan (until its restore) the stability limit of each step takes a
 * pass over the points for max |v| instead of the one G2P found. */
int mpmc_sim_get_field(mpmc_sim sim, mpmc_field field, double **data, int *ncomp);
int mpmc_sim_restore_field(mpmc_sim sim, mpmc_field field, double **data);
int mpmc_sim_get_material_ids(mpmc_sim sim, const int **ids);
/* Sorting the points by grid cell for locality (the transfers' caches): off by default, so
 * a point keeps the index it was added with.  With nsteps > 0 the step sorts every nsteps
 * steps (the first step too), and once a tenth of the interval has passed also when the
 * slabs' axis has changed since the last sort (a flattening body): every per-point array
 * moves, particle sets are renumbered, and ids[i] (get_particle_ids) is the index point i had
 * when it was added, to follow a point.
 * Field pointers stay valid (the arrays are permuted in place).  Results change only by the
 * summation order at the nodes; the sort does not depend on the thread count. */
int mpmc_sim_set_sort_interval(mpmc_sim sim, int nsteps);
int mpmc_sim_get_sort_interval(mpmc_const_sim sim, int *nsteps);
int mpmc_sim_sort_particles(mpmc_sim sim); /* sort now */
int mpmc_sim_get_particle_ids(mpmc_sim sim, const int **ids);
/* External force on points [first, first+n): f[n*dim] (a traction times its tributary
 * length or area).  Allocates the force field on first use. */
int mpmc_sim_set_particle_forces(mpmc_sim sim, int first, int n, const double *f);

/* ---- boundary conditions on the grid ------------------------------------------ */
/* A wall constrains every grid node on or beyond the plane x[axis] = position:
 * side = -1 constrains nodes with x[axis] <= position (material on the + side),
 * side = +1 nodes with x[axis] >= position. */
int mpmc_sim_add_wall(mpmc_sim sim, int axis, int side, double position, mpmc_wall_kind kind,
                      int *id);
/* A wall on a face of the grid box: face = 2*axis + (0 for lo, 1 for hi). */
int mpmc_sim_add_wall_face(mpmc_sim sim, int face, mpmc_wall_kind kind, int *id);
/* Constrain the nodes inside the axis-aligned box [lo, hi] (gates, obstacles);
 * for SLIP and SEPARABLE the constrained component is `axis`, with material on side
 * -side (side -1: material is at larger x[axis]). */
int mpmc_sim_add_wall_box(mpmc_sim sim, const double *lo, const double *hi, mpmc_wall_kind kind,
                          int axis, int side, int *id);
/* Constrain the nodes of a node set (mpmc_sim_add_node_set, or a gmsh boundary group);
 * axis and side as for a box.  Plain constraint: no ghost mirroring. */
int mpmc_sim_add_wall_nodes(mpmc_sim sim, int set, mpmc_wall_kind kind, int axis, int side,
                            int *id);
int mpmc_sim_remove_wall(mpmc_sim sim, int id);

/* ---- time stepping ---------------------------------------------------------- */
/* dt = factor * h / (max_m c_m + max_p |v_p|), c_m the p-wave speed of material m, at most
 * factor times the viscous limit h^2 rho / (2 mu) and the rigid bodies' contact limit
 * (paper: factor 0.3-0.4). */
int mpmc_sim_stable_dt(mpmc_sim sim, double factor, double *dt);
/* One explicit step (paper Fig. 1 / Algorithm 1).  Refuses a dt above the stability limit
 * (stable_dt with factor 1) with MPMC_ERR_UNSTABLE unless mpmc_sim_set_force_dt(sim, 1). */
int mpmc_sim_step(mpmc_sim sim, double dt);
int mpmc_sim_set_force_dt(mpmc_sim sim, int force);
int mpmc_sim_get_time(mpmc_const_sim sim, double *t);
int mpmc_sim_set_time(mpmc_sim sim, double t);
int mpmc_sim_get_kinetic_energy(mpmc_const_sim sim, double *ke);
int mpmc_sim_get_stats(mpmc_const_sim sim, mpmc_stats *stats);

/* ---- run monitor (monitor.c) ---------------------------------------------------------- */
/* Every step is checked: NaN/Inf or J <= 0 (MPMC_ERR_NUMERIC), a point leaving the grid
 * (MPMC_ERR_OUTSIDE), and kinetic energy growing without input (MPMC_ERR_UNSTABLE): E_k
 * above factor x the energy available since the last change of inputs (E_k + elastic
 * energy then, plus the work of gravity and of the point loads since; rigid bodies and user
 * materials switch this check off).  The message names the step, the point, its position
 * and the cause.
 * factor > 1 (default 10); 0 restores the default; < 0 turns the energy check off.  Every
 * call starts a new baseline: call it after writing velocities or stresses in place. */
#define MPMC_MONITOR_ENERGY_FACTOR 10.0
int mpmc_sim_set_energy_monitor(mpmc_sim sim, double factor);

/* ---- rigid bodies and contact (contact_barrier.c) ------------------------------------ */
/* Rigid bodies (axis-aligned boxes in 2D/3D, simple polygons in 2D) move with a prescribed
 * velocity and push the material points through the IPC barrier on the gap d between a
 * point and the body's surface:  f = A_p kappa (d - dhat)[2 ln(d/dhat) + 1 - dhat/d] n for
 * 0 < d < dhat (A_p = V0^((dim-1)/dim), n the body's outward normal), with Coulomb friction
 * mu as an elastic stick (a spring on the slip since the point stuck, capped at mu times the
 * normal force; bodies and anchors are saved in checkpoints).  The explicit time step
 * accounts for the barrier stiffness (mpmc_sim_stable_dt); a step after which a point lies
 * inside a body fails with MPMC_ERR_NUMERIC.  Defaults of dhat and kappa: docs/contact.md. */
int mpmc_sim_add_rigid_box(mpmc_sim sim, const double *lo, const double *hi, double mu, int *id);
/* 2D only: nvert vertices xy[2*nvert], either orientation. */
int mpmc_sim_add_rigid_polygon(mpmc_sim sim, int nvert, const double *xy, double mu, int *id);
int mpmc_sim_remove_rigid(mpmc_sim sim, int id);
int mpmc_sim_set_rigid_velocity(mpmc_sim sim, int id, const double *v);
/* Displacement of the body since it was added. */
int mpmc_sim_get_rigid_offset(mpmc_const_sim sim, int id, double *offset);
/* Force of the points on the body in the last step (per unit thickness in 2D). */
int mpmc_sim_get_rigid_reaction(mpmc_const_sim sim, int id, double *f);
/* Smallest signed distance of any point to the body (negative inside) and that point. */
int mpmc_sim_get_rigid_gap(mpmc_const_sim sim, int id, double *gap, int *point);
/* Barrier range dhat [m] and stiffness kappa [Pa/m] for all bodies; 0 = derived default. */
int mpmc_sim_set_contact_params(mpmc_sim sim, double dhat, double kappa);
int mpmc_sim_get_contact_params(mpmc_const_sim sim, double *dhat, double *kappa);

/* ---- named particle sets (sets.c) ---------------------------------------------- */
/* Sets name groups of points (gmsh boundary groups, traction edges, tracked points).
 * Adding a set with an existing name replaces it.  Indices are copied. */
int mpmc_sim_add_particle_set(mpmc_sim sim, const char *name, int n, const int *idx, int *id);
int mpmc_sim_get_num_particle_sets(mpmc_const_sim sim, int *n);
/* Borrow set `id`: its name, size and indices (valid until the sets change). */
int mpmc_sim_get_particle_set(mpmc_const_sim sim, int id, const char **name, int *n,
                              const int **idx);
int mpmc_sim_find_particle_set(mpmc_const_sim sim, const char *name, int *id);

/* ---- named node sets (sets.c) ------------------------------------------------------ */
/* Grid nodes by integer coordinates ijk[n*dim]: node (i, j, k) sits at lo + (i, j, k) h,
 * 0 <= i <= cells along each axis.  gmsh seeding makes one per boundary group (the nodes
 * whose cell of influence, a square/cube of side h centred on the node, touches the group).
 * Adding a set with an existing name replaces it.  Needs the grid; kept in checkpoints. */
int mpmc_sim_add_node_set(mpmc_sim sim, const char *name, int n, const int *ijk, int *id);
int mpmc_sim_get_num_node_sets(mpmc_const_sim sim, int *n);
int mpmc_sim_get_node_set(mpmc_const_sim sim, int id, const char **name, int *n, const int **ijk);
int mpmc_sim_find_node_set(mpmc_const_sim sim, const char *name, int *id);

/* ---- seeding without gmsh (seed.c) --------------------------------------------- */
/* ppc points per cell per axis on the sim's grid lattice, kept where they fall inside
 * the region; volume (h/ppc)^dim each.  *first / *count may be NULL. */
int mpmc_sim_seed_box(mpmc_sim sim, const double *lo, const double *hi, int ppc, int material,
                      int *first, int *count);
/* 2D: a simple polygon given by nvert vertices xy[2*nvert] (either orientation). */
int mpmc_sim_seed_polygon(mpmc_sim sim, int nvert, const double *xy, int ppc, int material,
                          int *first, int *count);

/* ---- output: HDF5 snapshots + XDMF (io_hdf5.c, io_xdmf.c) ------------------------ */
typedef struct mpmc_output_s *mpmc_output;
/* Create (truncate) h5path and write xdmfpath next to it on every snapshot. */
int mpmc_output_create(mpmc_sim sim, const char *h5path, const char *xdmfpath, mpmc_output *out);
/* Append one snapshot of the fields the scene has, at the current time. */
int mpmc_output_write(mpmc_output out);
int mpmc_output_destroy(mpmc_output *out);

/* ---- checkpoint and restart (checkpoint.c) ------------------------------------------ */
/* Everything needed to continue the run, written atomically (temporary file, fsync,
 * rename).  meta: caller's text stored alongside (e.g. the workflow's stage), may be NULL. */
int mpmc_sim_checkpoint_write(mpmc_const_sim sim, const char *path, const char *meta);
/* Create a simulation from a checkpoint; *meta (may be NULL) receives a copy of the
 * caller's text, to be released with mpmc_free. */
int mpmc_sim_checkpoint_read(mpmc_context ctx, const char *path, mpmc_sim *sim, char **meta);
void mpmc_free(void *ptr);
/* A checkpoint cannot hold a function pointer: after mpmc_sim_checkpoint_read, re-attach the
 * stress function of each user material (its steps fail with MPMC_ERR_STATE until then). */
int mpmc_sim_set_material_user_fn(mpmc_sim sim, int material,
                                  int (*fn)(void *data, const double *dF, double dt, double *state,
                                            double *stress),
                                  void *data);

/* ---- user materials (material_user.c) ---------------------------------------------- */
/* Called for each point of the material, from several threads at once: from the relative
 * deformation gradient dF (3x3 row-major, F-bar scaled when on), update state[nstate]
 * (initialised to zero) and the Cauchy stress[6] (Voigt, holds the previous stress on
 * entry).  Returns 0, or non-zero to stop the step with MPMC_ERR_SOLVER. */
typedef int (*mpmc_user_stress_fn)(void *data, const double *dF, double dt, double *state,
                                   double *stress);
/* nstate in [0, 4096]; wave_speed: the material's p-wave speed [m/s] for the stable step.
 * In plane strain dF is the 3x3 embedding (dF[8] = 1).  From Fortran: a bind(C) function
 * registered with c_funloc (module mpmc, fortran/mpmc.f90). */
int mpmc_sim_add_material_user(mpmc_sim sim, mpmc_user_stress_fn fn, void *data, int nstate,
                               double rho, double wave_speed, int *id);
/* Borrow the user state of every point, [n][*nstate]: *nstate is the row length (that of the
 * user material with the most state); the points of `material` use the first entries of
 * their rows.  Valid until points are added or a user material with more state is. */
int mpmc_sim_get_user_state(mpmc_sim sim, int material, double **state, int *nstate);

/* ---- user yield surfaces (return_cpp.c) ------------------------------------------- */
/* A yield surface the library returns to (closest-point projection on Hencky elasticity):
 * at the Kirchhoff stress tau (Voigt xx yy zz yz xz xy, tensor components) and the hardening
 * variable alpha (the accumulated plastic multiplier, alpha = alpha_n + dgamma; kept per
 * point as eps_p), the function fills every field.  Derivatives are tensor derivatives in
 * Voigt order: for f = tau:tau / 2, dfdtau = tau (shear entries tau_yz, not 2 tau_yz);
 * drdtau[6 i + j] = d r_i / d tau_j as fourth-order tensor components, minor-symmetric. */
typedef struct {
  double f;            /* yield function [Pa]; <= 0 inside                            */
  double dfdtau[6];    /* df/dtau                                                     */
  double dfdalpha;     /* df/dalpha [Pa]                                              */
  double r[6];         /* flow direction dg/dtau (associated: r = dfdtau)             */
  double drdtau[36];   /* dr/dtau [1/Pa]                                              */
  double drdalpha[6];  /* dr/dalpha                                                   */
} mpmc_yield_eval;
/* Returns 0, or non-zero to stop the step with MPMC_ERR_SOLVER.  Called from several
 * threads at once. */
typedef int (*mpmc_yield_fn)(void *data, const double *tau, double alpha, mpmc_yield_eval *out);
/* Hencky elasticity (E [Pa], nu, rho [kg/m^3]) with the yield surface fn: the library returns
 * to it (Newton on (tau, dgamma), KINSOL as the fallback, LAPACK loaded at the first plastic
 * point).  A failed return names the point and, when the check finds one, the function's
 * wrong derivative.  After mpmc_sim_checkpoint_read: mpmc_sim_set_material_yield_fn. */
int mpmc_sim_add_material_user_yield(mpmc_sim sim, mpmc_yield_fn fn, void *data, double E,
                                     double nu, double rho, int *id);
int mpmc_sim_set_material_yield_fn(mpmc_sim sim, int material, mpmc_yield_fn fn, void *data);

#ifdef __cplusplus
}
#endif
#endif /* MPMC_H */
