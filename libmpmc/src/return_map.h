/* Return mapping for Hencky elasticity with von Mises (J2) plasticity and exponential
 * softening (private; used by material_hencky_j2.c, the tests and bench/).
 *
 * The scalar problem (de Souza Neto et al. 2008, box 7.4): after a trial state with von
 * Mises stress q_trial > kappa(eps_p), find the plastic multiplier dgamma > 0 with
 *   g(dgamma) = q_trial - 3 G dgamma - kappa(eps_p + dgamma) = 0,
 *   kappa(e)  = kappa_r + (kappa_p - kappa_r) exp(-eta e).
 * g is concave (kappa'' > 0), g(0) > 0 and g -> -inf, so the root is unique and lies in
 *   [(q_trial - kappa(eps_p)) / 3G, (q_trial - kappa_r) / 3G],
 * a bracket of width (kappa(eps_p) - kappa_r) / 3G.  g' = -3G + eta (kappa_p - kappa_r)
 * exp(-eta e) can be positive (strong softening): the residual is then non-monotone near
 * the lower end, the "stiff" case the auto solver hands to KINSOL. */
#ifndef MPMC_RETURN_MAP_H
#define MPMC_RETURN_MAP_H

#include <float.h>
#include <math.h>

#include "mpmc_impl.h"

/* Material constants the return map needs. */
typedef struct {
  double K, G;                  /* bulk and shear moduli                              */
  double kappa_p, kappa_r, eta; /* peak and residual strength (q at yield), softening  */
} mpmc_j2_param;

/* What one return map did (for statistics, tests and error messages). */
typedef struct {
  int plastic;       /* 1 if the trial state was outside the yield surface            */
  int fallback;      /* 1 if the auto solver handed this point to KINSOL               */
  int newton_iters;  /* Newton iterations (including bisection steps)                 */
  int bisections;    /* safeguard (bisection) steps taken by the newton solver          */
  int kinsol_iters;  /* KINSOL nonlinear iterations                                    */
  int kinsol_flag;   /* KINSol's return value (0 when KINSOL was not called)            */
  double q_trial;    /* trial von Mises stress                                          */
  double kappa;      /* strength at the start of the step, kappa(eps_p^n)               */
  double dgamma;     /* plastic multiplier = increment of eps_p                         */
  double residual;   /* |q_new - kappa(eps_p + dgamma)| after the solve                */
} mpmc_j2_info;

/* One workspace per thread: the KINSOL memory, its vectors and its SUNContext, created
 * on first use and reused for every later solve.  Never shared between threads. */
typedef struct mpmc_rm_ws_s mpmc_rm_ws;

int mpmc_rm_ws_create(mpmc_rm_ws **ws);
void mpmc_rm_ws_destroy(mpmc_rm_ws **ws);

typedef double mpmc_rm_v4 __attribute__((vector_size(4 * sizeof(double))));
typedef long long mpmc_rm_v4l __attribute__((vector_size(4 * sizeof(long long))));

/* e = exp(-x) per lane, x >= 0, within 1 ulp of libm's (checked over [0, 708] on 2 x 10^7
 * arguments: at most 1.0 ulp); 0 beyond x = 708 (libm's value there is below 3.3e-308),
 * NaN for NaN.  exp(-x) = 2^n exp(r), n = round(-x / ln 2) by adding 1.5 2^52, r = -x - n ln 2
 * in two parts (n ln2_hi exact), exp(r) by its Taylor polynomial to r^13 (|r| <= 0.35: the
 * tail below 5e-18).  For the softening strengths (mpmc_j2_kappa4).  Vectors through
 * pointers (by value they would change the baseline build's ABI). */
static inline void mpmc_rm_expneg4(const mpmc_rm_v4 *xp, mpmc_rm_v4 *ep) {
  const mpmc_rm_v4 x = *xp, y = -x;
  const mpmc_rm_v4 shift = {0x1.8p52, 0x1.8p52, 0x1.8p52, 0x1.8p52};
  const mpmc_rm_v4 sh = y * 1.4426950408889634 + shift; /* 1 / ln 2 */
  const mpmc_rm_v4 fn = sh - shift;
  const mpmc_rm_v4l n = (mpmc_rm_v4l)sh - (mpmc_rm_v4l)shift;
  const mpmc_rm_v4 r = (y - fn * 6.93147180369123816490e-01) - fn * 1.90821492927058770002e-10;
  mpmc_rm_v4 p = r * (1.0 / 6227020800.0) + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  const mpmc_rm_v4 e = p * (mpmc_rm_v4)((n + 1023) << 52);
  const mpmc_rm_v4l in = x <= 708.0, beyond = x > 708.0; /* neither: NaN, kept */
  *ep = (mpmc_rm_v4)((in & (mpmc_rm_v4l)e) | (~in & ~beyond & (mpmc_rm_v4l)x));
}

/* kappa(eps_p) of four points, k[l] = kappa_r + (kappa_p - kappa_r) exp(-eta eps[l]): exp(-0)
 * = 1 exactly, and no exp when none of the four has yielded (most of a slope). */
static inline void mpmc_j2_kappa4(const mpmc_j2_param *m, const mpmc_rm_v4 *eps,
                                  mpmc_rm_v4 *k) {
  const mpmc_rm_v4 x = *eps * m->eta, one = {1.0, 1.0, 1.0, 1.0};
  const mpmc_rm_v4l unyielded = x == 0.0;
  mpmc_rm_v4 e = one;
  if (!(unyielded[0] & unyielded[1] & unyielded[2] & unyielded[3])) mpmc_rm_expneg4(&x, &e);
  *k = m->kappa_r +
       (m->kappa_p - m->kappa_r) * (mpmc_rm_v4)((unyielded & (mpmc_rm_v4l)one) |
                                                (~unyielded & (mpmc_rm_v4l)e));
}

/* kappa(e) and the scalar solve.  The unknown is q_new = q_trial - 3G dgamma in
 * [kappa_r, kappa(eps_p)] (return_map.c says why).  solver: MPMC_SOLVER_*.  Returns 0,
 * MPMC_ERR_SOLVER (no convergence or KINSOL failure: info->kinsol_flag says which),
 * MPMC_ERR_NUMERIC (non-finite input), MPMC_ERR_ARG (q_trial <= kappa: elastic) or
 * MPMC_ERR_MEMORY (KINSOL could not be created).  ws may be NULL for MPMC_SOLVER_NEWTON.
 * On success *dgamma >= 0, *q_new (may be NULL) > 0 and
 * |q_new - kappa(eps_p + dgamma)| <= mpmc_rm_tolerance().  kappa of one point: lane 0 of
 * mpmc_j2_kappa4 (the J2 blocks' bits). */
static inline double mpmc_j2_kappa(const mpmc_j2_param *m, double eps_p) {
  const mpmc_rm_v4 ev = {eps_p, eps_p, eps_p, eps_p};
  mpmc_rm_v4 k;
  mpmc_j2_kappa4(m, &ev, &k);
  return k[0];
}
double mpmc_rm_tolerance(const mpmc_j2_param *m, double eps_p);
/* The pieces of the auto solver's Newton iteration (return_map.c, solve_newton) that
 * stress_j2.c runs four points at a time, lane by lane the same operations: the iteration
 * limit, the tolerance |r| <= tol of a solve from kappa0 = kappa(eps_p), and exp(-x) for the
 * small x = eta dgamma of its iterates (|x| <= 1e-2; libm's exp beyond), Horner to x^6 / 6!,
 * the tail below 2e-18 of the value, written for doubles and vectors alike. */
#define MPMC_RM_MAX_ITERS 80
#define MPMC_RM_EXP_SMALL 1e-2
#define MPMC_RM_EXP_NEG_POLY(x)                                                         \
  (1.0 - (x) * (1.0 - (x) * (1.0 / 2.0) *                                               \
                          (1.0 - (x) * (1.0 / 3.0) *                                    \
                                     (1.0 - (x) * (1.0 / 4.0) *                         \
                                                (1.0 - (x) * (1.0 / 5.0) *              \
                                                           (1.0 - (x) * (1.0 / 6.0)))))))
static inline double mpmc_rm_tol_k(const mpmc_j2_param *m, double kappa0) {
  return 1e-12 * m->kappa_r + 16.0 * DBL_EPSILON * kappa0;
}
int mpmc_rm_solve(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double q_trial,
                  double eps_p, double *dgamma, double *q_new, mpmc_j2_info *info);
/* the same with kappa0 = mpmc_j2_kappa(m, eps_p) already known (saves its exp) */
int mpmc_rm_solve_k(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double q_trial,
                    double eps_p, double kappa0, double *dgamma, double *q_new,
                    mpmc_j2_info *info);

/* The whole return map of one point (material_hencky_j2.c):
 *   F    relative deformation gradient (3x3, F-bar scaled when on); NULL: be is already
 *        the trial state;
 *   be   elastic left Cauchy-Green tensor (Voigt), b_e^n in, b_e^{n+1} out;
 *   eps_p equivalent plastic strain, in/out;
 *   tau  Kirchhoff stress out (Voigt); the Cauchy stress is tau / J with
 *        J = sqrt(det be) = *J_out (may be NULL).
 * Returns 0, MPMC_ERR_NUMERIC (trial be not positive definite or not finite) or the
 * solver's code; on failure be, eps_p and tau are left unchanged. */
int mpmc_j2_return_map(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double F[3][3],
                       double *be, double *eps_p, double *tau, double *J_out,
                       mpmc_j2_info *info);

/* The plastic part of mpmc_j2_return_map's series path, for callers that formed the trial
 * state themselves (stress_j2.c): b the trial b_e, e its deviatoric Hencky strain (returned
 * scaled to the new one), tr its trace, qtr > k0 = kappa(eps_p) the trial von Mises stress;
 * writes be, eps_p, tau, J_out (may be NULL) and info->plastic, the solver's fields. */
int mpmc_j2_plastic(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, const double *b,
                    double *e, double tr, double qtr, double k0, double *be, double *eps_p,
                    double *tau, double *J_out, mpmc_j2_info *info);

/* The same by the eigen-decomposition of the trial b_e for every point (mpmc_j2_return_map
 * takes the eigen-free series of linalg.h when |ln b_e| <~ 0.36): the reference of tests/t411. */
int mpmc_j2_return_map_eig(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double F[3][3],
                           double *be, double *eps_p, double *tau, double *J_out,
                           mpmc_j2_info *info);

/* The per-thread workspaces of a simulation (sim->scr.solver_ws): makes sure there are
 * at least nthreads and returns them; freed by mpmc_return_map_free. */
/* Slots of a workspace for the other return maps' per-thread memory (their KINSOL): the
 * frictional models (return_mc.c) and the user yield surfaces (return_cpp.c). */
enum { MPMC_RM_SLOT_MC = 0, MPMC_RM_SLOT_CPP = 1, MPMC_RM_NSLOT = 2 };
void **mpmc_rm_ws_slot(mpmc_rm_ws *ws, int k, void (*free_fn)(void *));
int mpmc_rm_sim_workspaces(struct mpmc_sim_s *sim, int nthreads, mpmc_rm_ws ***ws);

/* stress_j2.c, one of the kernel files (mpmc_impl.h): the stress update of material id's
 * points, elastic ones four at a time, the others by mpmc_j2_return_map; counts of plastic
 * corrections and KINSOL fallbacks, and the lowest failed point (INT_MAX: none). */
#define MPMC_J2_BATCH_PROTOTYPE(S)                                                            \
  int mpmc_j2_batch##S(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,               \
                       mpmc_rm_ws **ws, int64_t *nret, int64_t *nfb, int *first_bad);
MPMC_J2_BATCH_PROTOTYPE()
#if defined(MPMC_HAVE_AVX2_KERNELS) || defined(MPMC_ISA_AVX2) || defined(MPMC_ISA_FMA)
MPMC_J2_BATCH_PROTOTYPE(_avx2)
MPMC_J2_BATCH_PROTOTYPE(_fma)
MPMC_J2_BATCH_PROTOTYPE(_avx512)
#endif
/* The sim's set of it (kernels.c's table, sim->cfg.kernels), which material_hencky_j2.c runs. */
typedef int (*mpmc_j2_batch_fn)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                                mpmc_rm_ws **ws, int64_t *nret, int64_t *nfb, int *first_bad);
mpmc_j2_batch_fn mpmc_kernels_j2_batch(const struct mpmc_sim_s *sim);

#endif
