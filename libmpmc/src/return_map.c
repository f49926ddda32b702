/* Local solvers for the J2 return map (return_map.h):
 *   newton  safeguarded scalar Newton on q_new = q_trial - 3G dgamma, kept inside the
 *           bracket of return_map.h by bisection steps -- the fast path, always converges;
 *   kinsol  SUNDIALS KINSOL with line-search globalisation, one memory per thread;
 *   auto    plain Newton while it behaves; at the first sign of trouble (a step leaving the
 *           bracket, a non-negative slope g' >= 0, i.e. a non-monotone residual, or a stall)
 *           the point goes to KINSOL, started from the bracket's lower end y = kappa_r.
 * From there Newton (and so KINSOL's full step) converges monotonically: r(y) is concave and
 * strictly increasing on [kappa_r, root], so each tangent step lands in [y, root]. */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "return_map.h"

/* The scalar problem handed to KINSOL through its user data. */
typedef struct {
  const mpmc_j2_param *m;
  double q_trial, eps_p;
} rm_problem;

struct mpmc_rm_ws_s {
  SUNContext sunctx;
  void *kmem;
  N_Vector u, uscale, fscale, constraints;
  SUNMatrix A;
  SUNLinearSolver LS;
  rm_problem prob;
  int kinsol_ready;
  /* other return maps' per-thread memory (mpmc_rm_ws_slot), freed with the workspace */
  void *slot[MPMC_RM_NSLOT];
  void (*slot_free[MPMC_RM_NSLOT])(void *);
};

/* per-simulation pool: one workspace per thread */
typedef struct {
  int n;
  mpmc_rm_ws **ws;
} rm_pool;

/* The unknown is the returned von Mises stress y = q_trial - 3G dgamma, in [kappa_r,
 * kappa(eps_p)].  The residual r(y) = y - kappa(eps_p + (q_trial - y)/3G) equals
 * g(dgamma) but is formed from numbers of the size of kappa, so it can be driven to
 * 1e-12 kappa even when q_trial = 1e4 kappa (q_trial - 3G dgamma - kappa would cancel
 * to round-off of q_trial).  r is concave and increasing at its root; r' = -g'/3G. */
static inline double rm_r(const mpmc_j2_param *m, double qtr, double ep0, double y, double *dr) {
  const double e = (m->kappa_p - m->kappa_r) * exp(-m->eta * (ep0 + (qtr - y) / (3.0 * m->G)));
  if (dr) *dr = 1.0 - m->eta * e / (3.0 * m->G);
  return y - (m->kappa_r + e);
}

/* Converged when |r| is below 1e-12 of the residual strength (or round-off of kappa):
 * mpmc_rm_tol_k (return_map.h, stress_j2.c's too). */
double mpmc_rm_tolerance(const mpmc_j2_param *m, double eps_p) {
  return mpmc_rm_tol_k(m, mpmc_j2_kappa(m, eps_p));
}

/* ---- KINSOL ------------------------------------------------------------------------- */
static int kin_f(N_Vector u, N_Vector f, void *data) {
  const rm_problem *pb = data;
  const double x = NV_Ith_S(u, 0);
  NV_Ith_S(f, 0) = rm_r(pb->m, pb->q_trial, pb->eps_p, x, NULL);
  return isfinite(NV_Ith_S(f, 0)) ? 0 : 1; /* > 0: recoverable, KINSOL shortens the step */
}

static int kin_jac(N_Vector u, N_Vector fu, SUNMatrix J, void *data, N_Vector t1, N_Vector t2) {
  (void)fu;
  (void)t1;
  (void)t2;
  const rm_problem *pb = data;
  double dg;
  rm_r(pb->m, pb->q_trial, pb->eps_p, NV_Ith_S(u, 0), &dg);
  SM_ELEMENT_D(J, 0, 0) = dg;
  return isfinite(dg) ? 0 : 1;
}

/* KINSOL reports through these; we turn its return flags into our codes instead. */
static void kin_silent_err(int code, const char *module, const char *fn, char *msg, void *d) {
  (void)code;
  (void)module;
  (void)fn;
  (void)msg;
  (void)d;
}
static void kin_silent_info(const char *module, const char *fn, char *msg, void *d) {
  (void)module;
  (void)fn;
  (void)msg;
  (void)d;
}

static void kinsol_free(mpmc_rm_ws *ws) {
  if (ws->kmem) KINFree(&ws->kmem);
  if (ws->LS) SUNLinSolFree(ws->LS);
  if (ws->A) SUNMatDestroy(ws->A);
  N_Vector *v[] = {&ws->u, &ws->uscale, &ws->fscale, &ws->constraints};
  for (int i = 0; i < 4; ++i)
    if (*v[i]) {
      N_VDestroy(*v[i]);
      *v[i] = NULL;
    }
  if (ws->sunctx) SUNContext_Free(&ws->sunctx);
  ws->kmem = NULL;
  ws->LS = NULL;
  ws->A = NULL;
  ws->sunctx = NULL;
  ws->kinsol_ready = 0;
}

/* Create the KINSOL memory once per workspace (per thread). */
static int kinsol_init(mpmc_rm_ws *ws) {
  if (ws->kinsol_ready) return MPMC_SUCCESS;
  int ok = SUNContext_Create(NULL, &ws->sunctx) == 0;
  if (ok) {
    ws->u = N_VNew_Serial(1, ws->sunctx);
    ws->uscale = N_VNew_Serial(1, ws->sunctx);
    ws->fscale = N_VNew_Serial(1, ws->sunctx);
    ws->constraints = N_VNew_Serial(1, ws->sunctx);
    ok = ws->u && ws->uscale && ws->fscale && ws->constraints;
  }
  if (ok) {
    ws->A = SUNDenseMatrix(1, 1, ws->sunctx);
    ws->LS = ws->A ? SUNLinSol_Dense(ws->u, ws->A, ws->sunctx) : NULL;
    ws->kmem = KINCreate(ws->sunctx);
    ok = ws->A && ws->LS && ws->kmem;
  }
  if (ok) {
    NV_Ith_S(ws->u, 0) = 0.0;
    NV_Ith_S(ws->constraints, 0) = 2.0; /* y = q_new > 0 */
    ok = KINInit(ws->kmem, kin_f, ws->u) == KIN_SUCCESS &&
         KINSetErrHandlerFn(ws->kmem, kin_silent_err, NULL) == KIN_SUCCESS &&
         KINSetInfoHandlerFn(ws->kmem, kin_silent_info, NULL) == KIN_SUCCESS &&
         KINSetPrintLevel(ws->kmem, 0) == KIN_SUCCESS &&
         KINSetUserData(ws->kmem, &ws->prob) == KIN_SUCCESS &&
         KINSetLinearSolver(ws->kmem, ws->LS, ws->A) == KIN_SUCCESS &&
         KINSetJacFn(ws->kmem, kin_jac) == KIN_SUCCESS &&
         /* a fresh Jacobian every iteration (KINSOL's default reuse of 10 makes a scalar
            Newton fail) */
         KINSetMaxSetupCalls(ws->kmem, 1) == KIN_SUCCESS &&
         KINSetNumMaxIters(ws->kmem, MPMC_RM_MAX_ITERS) == KIN_SUCCESS &&
         KINSetConstraints(ws->kmem, ws->constraints) == KIN_SUCCESS &&
         /* fscale = 1/tol below, so fnormtol = 1 means |g| <= tol */
         KINSetFuncNormTol(ws->kmem, 1.0) == KIN_SUCCESS &&
         KINSetScaledStepTol(ws->kmem, 4.0 * DBL_EPSILON) == KIN_SUCCESS;
  }
  if (!ok) {
    kinsol_free(ws);
    return MPMC_ERR_MEMORY;
  }
  ws->kinsol_ready = 1;
  return MPMC_SUCCESS;
}

static int solve_kinsol(mpmc_rm_ws *ws, const mpmc_j2_param *m, double qtr, double ep0, double y0,
                        double tol, double *y, mpmc_j2_info *info) {
  if (!ws) return MPMC_ERR_ARG;
  /* KINSOL accepts a guess only at 0.01 fnormtol; the lower bracket end is often the root
     already (eta eps_p >> 1) */
  if (fabs(rm_r(m, qtr, ep0, y0, NULL)) <= tol) {
    *y = y0;
    return MPMC_SUCCESS;
  }
  MPMC_CALL(kinsol_init(ws));
  ws->prob.m = m;
  ws->prob.q_trial = qtr;
  ws->prob.eps_p = ep0;
  NV_Ith_S(ws->u, 0) = y0;
  NV_Ith_S(ws->uscale, 0) = 1.0 / mpmc_j2_kappa(m, ep0);
  NV_Ith_S(ws->fscale, 0) = 1.0 / tol;
  const int flag = KINSol(ws->kmem, ws->u, KIN_LINESEARCH, ws->uscale, ws->fscale);
  long nni = 0;
  KINGetNumNonlinSolvIters(ws->kmem, &nni);
  info->kinsol_iters += (int)nni;
  info->kinsol_flag = flag;
  *y = NV_Ith_S(ws->u, 0);
  /* a line search that stalls at round-off after reaching the tolerance is a success */
  if (flag < 0 && !(fabs(rm_r(m, qtr, ep0, *y, NULL)) <= tol)) return MPMC_ERR_SOLVER;
  return MPMC_SUCCESS;
}

/* exp(-x) for the small x of Newton's iterates (x = eta dgamma: a step's plastic increment
 * times the softening rate, mostly < 1e-2): return_map.h's polynomial, libm's exp beyond. */
static inline double exp_neg_small(double x) {
  if (!(fabs(x) <= MPMC_RM_EXP_SMALL)) return exp(-x);
  return MPMC_RM_EXP_NEG_POLY(x);
}

/* rm_r with kappa(eps_p) - kappa_r = a = (kappa_p - kappa_r) exp(-eta eps_p) known (the
 * caller's kappa0 - kappa_r) and c = eta / 3G: kappa(eps_p + dgamma) - kappa_r =
 * a exp(-eta dgamma), so an iterate costs a short polynomial instead of an exp. */
static inline double rm_r_k(const mpmc_j2_param *m, double a, double c, double qtr, double y,
                            double *dr) {
  const double e = a * exp_neg_small(c * (qtr - y));
  *dr = 1.0 - c * e;
  return y - (m->kappa_r + e);
}

/* Newton on the bracket [lo, hi] of y, from hi (the perfect-plasticity predictor
 * y = kappa(eps_p) = k0).  strict = 1 (auto): return 1 ("stiff") instead of safeguarding;
 * strict = 0 (newton): bisect whenever the Newton step leaves the bracket. */
static int solve_newton(const mpmc_j2_param *m, double qtr, double k0, double tol, int strict,
                        double *lo, double *hi, double *y, double *res, mpmc_j2_info *info) {
  double yi = *hi, rprev = INFINITY;
  const double a = k0 - m->kappa_r, c = m->eta / (3.0 * m->G);
  *res = NAN; /* |r(y)| when the returned y is an evaluated iterate, else NaN */
  for (int it = 0; it < MPMC_RM_MAX_ITERS; ++it) {
    double dr;
    const double r = rm_r_k(m, a, c, qtr, yi, &dr);
    if (fabs(r) <= tol) {
      *y = yi;
      *res = fabs(r);
      return 0;
    }
    if (r < 0)
      *lo = yi;
    else
      *hi = yi;
    if (strict && (dr <= 0.0 || (it >= 3 && fabs(r) > 0.5 * fabs(rprev)))) return 1;
    rprev = r;
    double yn = yi - r / dr;
    /* a step landing a few ulps outside the bracket is clamped, not treated as leaving it */
    const double slack = 8.0 * DBL_EPSILON * *hi;
    if (yn > *hi && yn <= *hi + slack) yn = *hi;
    if (yn < *lo && yn >= *lo - slack) yn = *lo;
    if (!(yn >= *lo && yn <= *hi)) { /* also catches dr = 0 and NaN */
      if (strict) return 1;
      yn = 0.5 * (*lo + *hi);
      info->bisections++;
    }
    info->newton_iters++;
    if (fabs(yn - yi) <= 2.0 * DBL_EPSILON * fabs(yn)) { /* round-off level: stop */
      *y = yn;
      return 0;
    }
    yi = yn;
  }
  *y = yi;
  return strict ? 1 : 0; /* the caller checks the residual */
}

/**
 * @brief Solve the J2 consistency condition (return_map.h): dgamma and q_new = q_trial - 3G dgamma.
 */
int mpmc_rm_solve(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double qtr, double ep0,
                  double *dgamma, double *q_new, mpmc_j2_info *info) {
  return mpmc_rm_solve_k(ws, solver, m, qtr, ep0, mpmc_j2_kappa(m, ep0), dgamma, q_new, info);
}

/**
 * @brief mpmc_rm_solve with kappa(eps_p) given (the return map has it already).
 */
int mpmc_rm_solve_k(mpmc_rm_ws *ws, int solver, const mpmc_j2_param *m, double qtr, double ep0,
                    double k0, double *dgamma, double *q_new, mpmc_j2_info *info) {
  mpmc_j2_info local = {0};
  if (!info) info = &local;
  info->q_trial = qtr;
  info->kappa = k0;
  if (!(isfinite(qtr) && isfinite(k0) && isfinite(m->G) && m->G > 0)) return MPMC_ERR_NUMERIC;
  if (!(qtr > k0)) return MPMC_ERR_ARG; /* elastic: nothing to solve */
  const double tol = mpmc_rm_tol_k(m, k0);
  /* bracket of y (return_map.h): r(kappa_r) <= 0 <= r(kappa(eps_p)) */
  double lo = m->kappa_r, hi = k0;
  if (hi < lo) hi = lo;
  double y = hi, res = NAN;
  int err = MPMC_SUCCESS;
  if (solver == MPMC_SOLVER_KINSOL) {
    err = solve_kinsol(ws, m, qtr, ep0, lo, tol, &y, info);
  } else {
    const int stiff =
        solve_newton(m, qtr, k0, tol, solver == MPMC_SOLVER_AUTO, &lo, &hi, &y, &res, info);
    if (stiff) {
      info->fallback = 1;
      res = NAN;
      /* from the bracket's lower end KINSOL's Newton steps increase monotonically to the root */
      err = solve_kinsol(ws, m, qtr, ep0, lo, tol, &y, info);
    }
  }
  if (err) return err;
  const double dg = (qtr - y) / (3.0 * m->G);
  info->dgamma = dg;
  info->residual = isnan(res) ? fabs(rm_r(m, qtr, ep0, y, NULL)) : res;
  if (!(dg >= 0.0) || !isfinite(dg) || !(y > 0.0) || !(info->residual <= tol))
    return MPMC_ERR_SOLVER;
  *dgamma = dg;
  if (q_new) *q_new = y;
  return MPMC_SUCCESS;
}

int mpmc_rm_ws_create(mpmc_rm_ws **ws) {
  if (!ws) return MPMC_ERR_ARG;
  *ws = calloc(1, sizeof **ws);
  return *ws ? MPMC_SUCCESS : MPMC_ERR_MEMORY;
}

void mpmc_rm_ws_destroy(mpmc_rm_ws **ws) {
  if (!ws || !*ws) return;
  for (int k = 0; k < MPMC_RM_NSLOT; ++k)
    if ((*ws)->slot[k] && (*ws)->slot_free[k]) (*ws)->slot_free[k]((*ws)->slot[k]);
  kinsol_free(*ws);
  free(*ws);
  *ws = NULL;
}

/**
 * @brief The workspace's slot k (MPMC_RM_SLOT_*): a return map's own per-thread memory,
 * created by the caller on first use and released by free_fn with the workspace.
 */
void **mpmc_rm_ws_slot(mpmc_rm_ws *ws, int k, void (*free_fn)(void *)) {
  if (!ws || k < 0 || k >= MPMC_RM_NSLOT) return NULL;
  ws->slot_free[k] = free_fn;
  return &ws->slot[k];
}

int mpmc_rm_sim_workspaces(struct mpmc_sim_s *sim, int nthreads, mpmc_rm_ws ***ws) {
  rm_pool *pool = sim->scr.solver_ws;
  if (!pool) {
    pool = calloc(1, sizeof *pool);
    MPMC_CHECK(pool, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the return-map workspaces");
    sim->scr.solver_ws = pool;
  }
  if (nthreads < 1) nthreads = 1;
  if (pool->n < nthreads) {
    mpmc_rm_ws **a = realloc(pool->ws, sizeof *a * (size_t)nthreads);
    MPMC_CHECK(a, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate %d return-map workspaces", nthreads);
    pool->ws = a;
    for (int t = pool->n; t < nthreads; ++t) a[t] = NULL;
    for (int t = pool->n; t < nthreads; ++t) {
      MPMC_CHECK(mpmc_rm_ws_create(&a[t]) == MPMC_SUCCESS, sim->ctx, MPMC_ERR_MEMORY,
                 "cannot allocate return-map workspace %d", t);
      pool->n = t + 1;
    }
  }
  *ws = pool->ws;
  return MPMC_SUCCESS;
}

/** Free the per-thread workspaces (called by mpmc_sim_destroy). */
void mpmc_return_map_free(struct mpmc_sim_s *sim) {
  if (!sim || !sim->scr.solver_ws) return;
  rm_pool *pool = sim->scr.solver_ws;
  for (int t = 0; t < pool->n; ++t) mpmc_rm_ws_destroy(&pool->ws[t]);
  free(pool->ws);
  free(pool);
  sim->scr.solver_ws = NULL;
}
