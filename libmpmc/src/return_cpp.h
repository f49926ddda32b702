/* A general closest-point projection for user yield surfaces (mpmc_yield_fn, mpmc.h) on
 * Hencky elasticity (private; the user-yield material, the tests and bench/).
 *
 * With tau = K tr(eps) I + 2G dev(eps) on the logarithmic elastic strains eps = 1/2 ln b_e,
 * the finite-strain return in principal/Kirchhoff space is the small-strain algorithm
 * (Simo 1992; de Souza Neto et al. 2008, box 8.1 and ch. 14).  Unknowns x = (tau, dgamma),
 * alpha = alpha_n + dgamma:
 *   R_tau = tau - tau_trial + dgamma C:r(tau, alpha) = 0   (6, C:r = 2G r + (K - 2G/3) tr r I)
 *   R_f   = f(tau, alpha) / s                      = 0   (s: the stress scale below)
 * The user's derivatives are tensor derivatives in Voigt order; linearising in the six
 * independent components doubles their shear columns (d tau_yz moves tau_yz and tau_zy).
 *
 * Solvers (MPMC_SOLVER_*): NEWTON, a full Newton from (tau_trial, 0) on the 7x7 system;
 * KINSOL, SUNDIALS' line-search Newton with dgamma >= 0 imposed; AUTO, Newton and KINSOL
 * where Newton fails (stalls, diverges, ends with dgamma < 0 or a non-finite iterate).
 * Converged when |R_tau|_max <= tol s + round-off of |tau_trial| and |f| <= tol s +
 * round-off of f, judged on the residual itself: a wrong derivative costs iterations or
 * fails, never gives a wrong stress.
 *
 * LAPACK: libmpmc does not link it (OpenBLAS starts its threads when it is loaded).
 * liblapacke.so.3 is opened at the first plastic point of a user surface (once per process,
 * then openblas_set_num_threads(1): these solves run inside OpenMP regions).  Newton's 7x7
 * systems go to a hand-written Gaussian elimination with partial pivoting unless
 * param.lapack = 1 (bench_user_yield: 151 ns a solve against LAPACKE_dgesv's 401, 1.9 us
 * against 2.5 us a plastic point); KINSOL's go to LAPACK dgetrf/dgetrs through a small
 * SUNLinearSolver of ours (Debian's SUNDIALS has no SUNLinSol_LapackDense).
 *
 * Starts: Newton from (tau_trial, 0) with a perfect-plasticity first step (df/dalpha left
 * out, as the built-in J2 starts from kappa(eps_p)); NEWTON retries once from
 * predictor_start's point, KINSOL (and AUTO's fallback) starts there: the first point past
 * the surface on the predictor's line, from which steep softening converges too. */
#ifndef MPMC_RETURN_CPP_H
#define MPMC_RETURN_CPP_H

#include <stddef.h>

#include "return_map.h"

/* Why a return failed (info.reason) */
enum {
  MPMC_CPP_OK = 0,
  MPMC_CPP_NO_CONVERGENCE = 1, /* Newton and/or KINSOL did not converge                   */
  MPMC_CPP_USER_ERROR = 2,     /* the yield function returned non-zero (info.user_code)   */
  MPMC_CPP_NON_FINITE = 3,     /* NaN/Inf in the trial state or the function's values there */
  MPMC_CPP_NO_LAPACK = 4,      /* liblapacke.so.3 could not be loaded                      */
  MPMC_CPP_NO_WORKSPACE = 5    /* KINSOL needed but ws == NULL, or its memory failed      */
};

#define MPMC_CPP_MSG_LEN 320

/* What one return did (statistics, tests and the material's error message). */
typedef struct {
  int plastic;       /* 1 if f(tau_trial, alpha_n) > tolerance                              */
  int fallback;      /* 1 if the auto solver handed the point to KINSOL                      */
  int newton_iters;  /* Newton iterations (linear solves)                                    */
  int kinsol_iters;  /* KINSOL nonlinear iterations                                          */
  int kinsol_flag;   /* KINSol's return value (0 when KINSOL was not called)                 */
  int reason;        /* MPMC_CPP_*                                                           */
  int user_code;     /* the yield function's non-zero return value (MPMC_CPP_USER_ERROR)     */
  double dgamma;     /* plastic multiplier = increment of alpha                              */
  double residual;   /* max(|R_tau|_max, |f|) / s after the solve                            */
  double scale;      /* s, the stress scale: max(|dev tau_trial|, f(tau_trial, alpha_n))     */
  char message[MPMC_CPP_MSG_LEN]; /* on failure: what happened, for the caller's error       */
} mpmc_cpp_info;

/* The material constants and the user surface. */
typedef struct {
  double K, G;        /* bulk and shear moduli                                          */
  mpmc_yield_fn fn;   /* the yield function and its derivatives                         */
  void *data;         /* passed to fn                                                   */
  double tol;         /* relative tolerance on the residuals; <= 0: 1e-12              */
  int max_iters;      /* per solver; <= 0: 50 (Newton), 200 (KINSOL)                   */
  int lapack;         /* 1: Newton's 7x7 solves through LAPACKE_dgesv (else hand-written) */
} mpmc_cpp_param;

/* Stress-space return from tau_trial (Voigt, tensor components) and alpha = alpha_n:
 * tau out (may alias tau_tr), *alpha <- alpha_n + dgamma.  ws may be NULL for
 * MPMC_SOLVER_NEWTON.  Returns 0; MPMC_ERR_SOLVER (no convergence, the yield function
 * returned non-zero, KINSOL failed), MPMC_ERR_NUMERIC (non-finite trial state or function
 * value), MPMC_ERR_UNSUPPORTED (no LAPACKE), MPMC_ERR_MEMORY, MPMC_ERR_ARG; on failure
 * info->reason and info->message say why (info may be NULL) and tau, *alpha are unchanged. */
int mpmc_cpp_return_stress(mpmc_rm_ws *ws, int solver, const mpmc_cpp_param *m,
                           const double tau_tr[6], double *alpha, double tau[6],
                           mpmc_cpp_info *info);

/* The tensor-level return of one point, like mpmc_j2_return_map_eig:
 *   F     relative deformation gradient (3x3); NULL: be is already the trial state;
 *   be    elastic left Cauchy-Green tensor (Voigt), b_e^n in, b_e^{n+1} out;
 *   alpha hardening variable (eps_p), in/out;
 *   tau   Kirchhoff stress out (Voigt); J_out (may be NULL) = sqrt(det be) = exp(tr eps_e).
 * eps = 1/2 ln b (eigen), tau_trial = K tr eps I + 2G dev eps, the stress return, then
 * eps_e = C^-1 tau and b_e = exp(2 eps_e) (eigen again: an anisotropic surface may turn
 * tau away from the trial's axes).  Codes as mpmc_cpp_return_stress, and MPMC_ERR_NUMERIC
 * for a trial b that is not positive definite; on failure be, alpha, tau are unchanged. */
int mpmc_cpp_return_map(mpmc_rm_ws *ws, int solver, const mpmc_cpp_param *m, double F[3][3],
                        double *be, double *alpha, double *tau, double *J_out,
                        mpmc_cpp_info *info);

/* Central differences of f and r at (tau, alpha) against the function's dfdtau, dfdalpha,
 * drdtau, drdalpha: *worst_rel_err = the largest |difference quotient - derivative| over
 * the derivative's size (per array: its max-norm, floored at the f and r scales), and
 * worst_name (may be NULL, name_len bytes) names it, e.g. "drdtau[3][1]".  A material runs
 * it on its first plastic point; a value above ~1e-4 names a wrong derivative (the check is
 * meaningless where f is not smooth, e.g. at the apex of a cone).  Returns 0,
 * MPMC_ERR_SOLVER (the function returned non-zero) or MPMC_ERR_NUMERIC. */
int mpmc_cpp_check_derivatives(const mpmc_cpp_param *m, const double tau[6], double alpha,
                               double *worst_rel_err, char *worst_name, size_t name_len);

/* Load LAPACKE now (the returns do it at their first plastic point): 0, or
 * MPMC_ERR_UNSUPPORTED with *why (may be NULL) the message naming the package. */
int mpmc_cpp_lapack_load(const char **why);

/* The linear solver of Newton's 7x7 systems, A x = b with A column-major (A[i + 7 j]),
 * overwritten; b becomes x.  Returns 0, or 1 for a singular A.  (bench_user_yield.) */
int mpmc_cpp_solve7_gauss(double *A, double *b);
int mpmc_cpp_solve7_lapack(double *A, double *b); /* needs mpmc_cpp_lapack_load() == 0 */

#endif
