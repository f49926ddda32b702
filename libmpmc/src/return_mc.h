/* Return mapping for Hencky elasticity with the frictional yield surfaces of soils:
 * Mohr-Coulomb and its three Drucker-Prager matchings, each with a tension cut-off on the
 * largest principal stress, non-associated flow and exponential softening (private; used by
 * the material table, the tests and bench/).
 *
 * Elasticity as in return_map.h: principal elastic log strains eps_a = 1/2 ln lam_a of b_e,
 * Kirchhoff principal stresses tau_a = K tr(eps) + 2G dev(eps)_a.  Tension positive.
 * Principal stresses sorted s1 >= s2 >= s3 (s3 the most compressive); with p = tr(tau)/3:
 *   Mohr-Coulomb  f  = (s1 - s3) + (s1 + s3) sin(phi) - 2 c cos(phi),
 *                 g  = (s1 - s3) + (s1 + s3) sin(psi)            (plastic potential),
 *   Drucker-Prager f = sqrt(J2) + eta_f(phi) p - xi(phi) c,  g = sqrt(J2) + eta_f(psi) p,
 *     the matchings of de Souza Neto, Peric & Owen 2008 (sections 6.4.3 and 8.3):
 *       compression (outer) cone  eta_f = 6 sin / (sqrt3 (3 - sin)), xi = 6 cos / (sqrt3 (3 - sin))
 *       extension (inner) cone    eta_f = 6 sin / (sqrt3 (3 + sin)), xi = 6 cos / (sqrt3 (3 + sin))
 *       plane strain              eta_f = 3 tan / sqrt(9 + 12 tan^2),  xi = 3 / sqrt(9 + 12 tan^2)
 *   tension cut-off  s1 <= sigma_t, associated (Rankine) flow; capped at the apex
 *                    (c cot(phi) for Mohr-Coulomb, xi c / eta_f for Drucker-Prager) whenever
 *                    the apex exists (phi > 0): the cap changes no elastic state and supplies
 *                    the volumetric flow that returns a trial state beyond the apex.
 * Softening: c, phi and psi each x(eps_p) = x_r + (x_p - x_r) exp(-eta eps_p), where eps_p
 * is the accumulated plastic deviatoric strain, eps_p += sqrt(2/3) |dev(d eps^p)| per step
 * (J2's measure for an isochoric flow; the cut-off's flow softens too).  sigma_t does not
 * soften, but its cap at the apex follows c and phi.  Implicit (backward Euler): every
 * quantity at eps_p^{n+1}.
 *
 * The return map tries the sets of active surfaces of the region list below, in order, and
 * takes the first whose multipliers are >= 0 and whose stress violates no surface (the
 * Kuhn-Tucker conditions; for perfect associated plasticity this is the unique closest point
 * in the energy norm).  Perfect plasticity: the surfaces are planes in principal stress
 * space and each region's multipliers are one linear solve (Mohr-Coulomb; Drucker-Prager's
 * cone alone likewise; its corners with the cut-off need a few Newton steps).  Softening:
 * Newton on the multipliers and the increment of eps_p ((n+1) x (n+1), n <= 3 active
 * surfaces: 2 x 2 on a plane, 3 x 3 on an edge), with KINSOL as the fallback exactly as
 * for J2 (MPMC_SOLVER_*, return_map.c). */
#ifndef MPMC_RETURN_MC_H
#define MPMC_RETURN_MC_H

#include "return_map.h"

/* mpmc_mc_param.surface */
enum {
  MPMC_MC_MOHR_COULOMB = 0,
  MPMC_DP_COMPRESSION = 1, /* outer cone: Mohr-Coulomb's strength in triaxial compression */
  MPMC_DP_EXTENSION = 2,   /* inner cone: Mohr-Coulomb's strength in triaxial extension   */
  MPMC_DP_PLANE_STRAIN = 3 /* Mohr-Coulomb's plane-strain strength (associated flow)     */
};

/* mpmc_mc_info.region: where the stress returned to (s1 >= s2 >= s3) */
enum {
  MPMC_MC_ELASTIC = 0,
  MPMC_MC_PLANE = 1,            /* main plane s1-s3 of Mohr-Coulomb; Drucker-Prager: the cone */
  MPMC_MC_EDGE_COMPRESSION = 2, /* s1 = s2 on Mohr-Coulomb (triaxial compression meridian)   */
  MPMC_MC_EDGE_EXTENSION = 3,   /* s2 = s3 on Mohr-Coulomb (triaxial extension meridian)     */
  MPMC_MC_APEX = 4,             /* the hydrostatic apex (the cut-off is at or above it)       */
  MPMC_MC_TENSION = 5,          /* the cut-off plane s1 = sigma_t alone                       */
  MPMC_MC_TENSION_EDGE = 6,     /* two surfaces with the cut-off: s1 = sigma_t on the yield
                                   surface, or s1 = s2 = sigma_t                              */
  MPMC_MC_TENSION_CORNER = 7    /* three or more with the cut-off: s1 = sigma_t on either
                                   edge, s1 = s2 = sigma_t on the yield surface, or the
                                   hydrostatic corner s = sigma_t below the apex              */
};

typedef struct {
  double K, G;         /* bulk, shear modulus [Pa]                                        */
  double c_p, c_r;     /* cohesion peak, residual [Pa], 0 <= c_r <= c_p                    */
  double phi_p, phi_r; /* friction angle peak, residual [rad]                              */
  double psi_p, psi_r; /* dilation angle peak, residual [rad], psi <= phi                  */
  double eta;          /* softening rate of c, phi, psi with eps_p (>= 0; 0: perfect)       */
  double sigma_t;      /* tension cut-off [Pa] on the largest principal stress; INFINITY:
                          none (then the apex, when phi > 0)                                 */
  int surface;         /* MPMC_MC_MOHR_COULOMB, MPMC_DP_*                                    */
} mpmc_mc_param;

/* What one return map did. */
typedef struct {
  int plastic;      /* 1 if the trial state was outside the elastic domain               */
  int region;       /* MPMC_MC_* above                                                   */
  int fallback;     /* 1 if the auto solver handed (some region of) this point to KINSOL  */
  int newton_iters; /* Newton iterations over all regions tried                          */
  int kinsol_iters; /* KINSOL nonlinear iterations                                       */
  int kinsol_flag;  /* the last KINSol return value (0 when KINSOL was not called)        */
  double dgamma;    /* sum of the plastic multipliers of the accepted region             */
  double residual;  /* max |f| of the active surfaces after the return [Pa]              */
} mpmc_mc_info;

/* The material at eps_p (softened c, phi, psi): c, phi, psi in that order, for the tests. */
void mpmc_mc_soften(const mpmc_mc_param *m, double eps_p, double *c, double *phi, double *psi);

/* The convergence tolerance on f [Pa] of a trial state with principal stresses tau_tr. */
double mpmc_mc_tolerance(const mpmc_mc_param *m, const double tau_tr[3]);

int mpmc_mc_return_principal(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m,
                             const double eps_tr[3], double *eps_p, double eps[3],
                             double tau[3], mpmc_mc_info *info);

int mpmc_mc_return_map(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, double F[3][3],
                       double *be, double *eps_p, double *tau, double *J_out,
                       mpmc_mc_info *info);

/* The same return by the eigen-decomposition of every trial b_e (the path of its plastic
 * points): the reference the tests compare mpmc_mc_return_map with. */
int mpmc_mc_return_map_eig(mpmc_rm_ws *ws, int solver, const mpmc_mc_param *m, double F[3][3],
                           double *be, double *eps_p, double *tau, double *J_out,
                           mpmc_mc_info *info);

/* The material at one eps_p, its derivatives in eps_p and what its surfaces need (private
 * to return_mc.c; here for mpmc_mc_pre). */
typedef struct {
  double e;                       /* exp(-eta eps_p), the point of the softening curve     */
  double phi, psi;                /* the angles (the reference of nearby evaluations)     */
  double c, sf, cf, ss, cs;       /* c, sin/cos phi, sin/cos psi                          */
  double dc, dphi, dsf, dcf, dss; /* d/d eps_p                                            */
  double eta, xi, etab;           /* Drucker-Prager: eta_f(phi), xi(phi), eta_f(psi)      */
  double deta, dxi, detab;
  double st, dst;                 /* cut-off, capped at the apex                          */
  int st_apex;                    /* 1 when the cap (the apex) is the cut-off              */
} mpmc_mc_mat;

#define MPMC_MC_NREF 5

/* What the elastic check of a point needs, worked out once per material (sines, cosines,
 * the cut-off's cap) for the points that have not yielded (eps_p = 0, most of a slope) and
 * for every point under perfect plasticity: mpmc_mc_prepare, then mpmc_mc_update per point. */
typedef struct {
  mpmc_mc_param m;
  int valid;   /* m passes mpmc_mc_return_principal's checks (else every point takes the
                  eigen path, which reports MPMC_ERR_ARG)                                */
  int perfect; /* no softening: the peak values hold at every eps_p                    */
  double sf;   /* Mohr-Coulomb: sin(phi_p)                                              */
  double k;    /* Mohr-Coulomb: 2 c_p cos(phi_p); Drucker-Prager: xi(phi_p) c_p         */
  double eta;  /* Drucker-Prager: eta_f(phi_p)                                          */
  double gmax; /* Mohr-Coulomb: sqrt(1 + sin^2(phi_p) / 3), the largest (s1 - s3 - s2 sin
                  phi) / (2 sqrt(J2)) over the Lode angle                                */
  double st;   /* the cut-off at the peak, capped at the apex (INFINITY: none)          */
  mpmc_mc_mat q0; /* the material at eps_p = 0 (every eps_p under perfect plasticity)    */
  mpmc_mc_mat ref[MPMC_MC_NREF]; /* at e = exp(-eta eps_p) = i / (MPMC_MC_NREF - 1): the
                                    nearest seeds a point's sines and cosines             */
} mpmc_mc_pre;

void mpmc_mc_prepare(const mpmc_mc_param *m, mpmc_mc_pre *pre);

/* The tensor-form return of one point (as mpmc_mc_return_map, which it is with pre of m):
 * the elastic check from the series Hencky strain of linalg.h and the invariants, without
 * an eigen-decomposition; the eigen path for the plastic points and those within round-off
 * of a surface or beyond the series.  Returns what mpmc_mc_return_map does. */
int mpmc_mc_update(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, double F[3][3],
                   double *be, double *eps_p, double *tau, double *J_out, mpmc_mc_info *info);

/* mpmc_mc_update of n <= 4 points at once, lane l the point F[l], be[l], eps_p[l], tau[l],
 * J_out[l], info[l] (info may be NULL), its return value in err[l]: the trial state, the
 * series Hencky strain, the elastic check, the closed-form eigen-decomposition, Mohr-Coulomb's
 * main-plane return and the recomposition of four points as vectors (batch4.h), each point's
 * results those of mpmc_mc_update (the frictional models' update over blocks of four points,
 * material_frictional.c). */
void mpmc_mc_update4(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, int n,
                     double F[][3][3], double be[][6], double *eps_p, double tau[][6],
                     double *J_out, mpmc_mc_info *info, int *err);
/* The same compiled for x86-64-v3 (AVX2's 256-bit vectors; ISO C's -ffp-contract=off, so
 * the same bits), in builds with the AVX2 kernels (MPMC_KERNEL_DISPATCH, CMakeLists.txt). */
void mpmc_mc_update4_avx2(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, int n,
                          double F[][3][3], double be[][6], double *eps_p, double tau[][6],
                          double *J_out, mpmc_mc_info *info, int *err);
typedef void (*mpmc_mc_update4_fn)(mpmc_rm_ws *ws, int solver, const mpmc_mc_pre *pre, int n,
                                   double F[][3][3], double be[][6], double *eps_p,
                                   double tau[][6], double *J_out, mpmc_mc_info *info, int *err);
/* The block update a sim of kernel set kernels (MPMC_KERNELS_*) runs: the AVX2 one where
 * the build has it, the processor runs it and kernels is not MPMC_KERNELS_BASELINE. */
mpmc_mc_update4_fn mpmc_mc_update4_for(int kernels);

void mpmc_mc_reduce(mpmc_mc_param *m, double factor);

#endif
