/* The closest-point projection for user yield surfaces (return_cpp.h): Newton on the 7x7
 * system (de Souza Neto et al. 2008, box 8.1, in Kirchhoff stress on Hencky elasticity),
 * KINSOL with line search as its globalised fallback, LAPACK opened at run time. */
#include <dlfcn.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "linalg.h"
#include "return_cpp.h"

#define N7 7
#define CPP_NEWTON_ITERS 50
#define CPP_KINSOL_ITERS 200
/* d/d(independent component) of a tensor function: the shear components appear twice */
static const double voigt_w[6] = {1.0, 1.0, 1.0, 2.0, 2.0, 2.0};

/* ---- LAPACK at run time -------------------------------------------------------------- */
/* LAPACKE's prototypes (lapack_int = int in Debian's LP64 build), declared here so that
 * libmpmc needs neither the header nor the library to build. */
#define LAPACK_COL_MAJOR 102
typedef int (*dgesv_fn)(int, int, int, double *, int, int *, double *, int);
typedef int (*dgetrf_fn)(int, int, int, double *, int, int *);
typedef int (*dgetrs_fn)(int, char, int, int, const double *, int, const int *, double *, int);
typedef void (*set_threads_fn)(int);

static struct {
  pthread_once_t once;
  void *handle;
  dgesv_fn dgesv;
  dgetrf_fn dgetrf;
  dgetrs_fn dgetrs;
  char why[256]; /* empty: loaded */
} lapack = {.once = PTHREAD_ONCE_INIT};

/* dlsym's object pointer to a function pointer without the cast ISO C does not define */
static void *sym(void *handle, const char *name, void *fp, size_t size) {
  void *p = dlsym(handle, name);
  if (p) memcpy(fp, &p, size);
  return p;
}

static void lapack_open(void) {
  lapack.handle = dlopen("liblapacke.so.3", RTLD_NOW | RTLD_LOCAL);
  if (!lapack.handle) {
    const char *e = dlerror();
    snprintf(lapack.why, sizeof lapack.why,
             "user yield surfaces need LAPACKE (liblapacke.so.3, Debian package liblapacke): %s",
             e ? e : "not found");
    return;
  }
  if (!sym(lapack.handle, "LAPACKE_dgesv", &lapack.dgesv, sizeof lapack.dgesv) ||
      !sym(lapack.handle, "LAPACKE_dgetrf", &lapack.dgetrf, sizeof lapack.dgetrf) ||
      !sym(lapack.handle, "LAPACKE_dgetrs", &lapack.dgetrs, sizeof lapack.dgetrs)) {
    const char *e = dlerror();
    snprintf(lapack.why, sizeof lapack.why,
             "user yield surfaces need LAPACKE (liblapacke.so.3, Debian package liblapacke): %s",
             e ? e : "a LAPACKE_dget* symbol is missing");
    return;
  }
  /* OpenBLAS (the pthread flavour behind Debian's liblapack.so.3) would start its own
     threads inside our OpenMP regions: one thread */
  set_threads_fn st = NULL;
  if (!sym(lapack.handle, "openblas_set_num_threads", &st, sizeof st))
    sym(RTLD_DEFAULT, "openblas_set_num_threads", &st, sizeof st);
  if (st) st(1);
}

/**
 * @brief Load LAPACKE (once per process, thread-safe); 0 or MPMC_ERR_UNSUPPORTED with the
 * reason in *why.
 */
int mpmc_cpp_lapack_load(const char **why) {
  pthread_once(&lapack.once, lapack_open);
  if (why) *why = lapack.why;
  return lapack.why[0] ? MPMC_ERR_UNSUPPORTED : MPMC_SUCCESS;
}

/**
 * @brief Solve the 7x7 system A x = b (A column-major, overwritten; b becomes x) by
 * Gaussian elimination with partial pivoting.  Returns 0, or 1 for a singular A.
 */
int mpmc_cpp_solve7_gauss(double *A, double *b) {
  for (int k = 0; k < N7; ++k) {
    int p = k;
    double big = fabs(A[k + N7 * k]);
    for (int i = k + 1; i < N7; ++i)
      if (fabs(A[i + N7 * k]) > big) big = fabs(A[i + N7 * k]), p = i;
    if (!(big > 0.0)) return 1; /* also NaN */
    if (p != k) {
      for (int j = k; j < N7; ++j) {
        const double t = A[k + N7 * j];
        A[k + N7 * j] = A[p + N7 * j];
        A[p + N7 * j] = t;
      }
      const double t = b[k];
      b[k] = b[p];
      b[p] = t;
    }
    const double inv = 1.0 / A[k + N7 * k];
    for (int i = k + 1; i < N7; ++i) {
      const double l = A[i + N7 * k] * inv;
      if (l == 0.0) continue;
      for (int j = k + 1; j < N7; ++j) A[i + N7 * j] -= l * A[k + N7 * j];
      b[i] -= l * b[k];
    }
  }
  for (int i = N7 - 1; i >= 0; --i) {
    double s = b[i];
    for (int j = i + 1; j < N7; ++j) s -= A[i + N7 * j] * b[j];
    b[i] = s / A[i + N7 * i];
  }
  return 0;
}

/**
 * @brief The same through LAPACKE_dgesv (mpmc_cpp_lapack_load first).  0, or 1 for a
 * singular A or a LAPACK error.
 */
int mpmc_cpp_solve7_lapack(double *A, double *b) {
  int ipiv[N7];
  return lapack.dgesv(LAPACK_COL_MAJOR, N7, 1, A, N7, ipiv, b, N7) != 0;
}

/* ---- the residual and its Jacobian --------------------------------------------------- */
typedef struct {
  const mpmc_cpp_param *m;
  const double *tau_tr;
  double alpha_n;
  double s;              /* the stress scale: max(|tau_trial|, f(tau_trial, alpha_n)) */
  double tol_t, tol_f;   /* the tolerances of R_tau (max-norm) and f, in Pa           */
  double tol_tx;         /* tol_t with the round-off of dgamma C:r at the last x      */
  double rnorm;          /* max(|R_tau|_max, |f|) / s of the last evaluation          */
  int user_code;         /* the function's non-zero return, if any                    */
  int nonfinite;         /* a non-finite value came out of the function              */
  mpmc_yield_eval ev;    /* the last evaluation                                        */
} cpp_problem;

/* C:v for isotropic C in tensor components (Voigt) */
static inline void c_dot(const mpmc_cpp_param *m, const double *v, double *out) {
  const double lam = m->K - 2.0 * m->G / 3.0, tr = v[0] + v[1] + v[2];
  for (int k = 0; k < 6; ++k) out[k] = 2.0 * m->G * v[k];
  for (int k = 0; k < 3; ++k) out[k] += lam * tr;
}

static inline int all_finite(const double *v, int n) {
  double s = 0.0;
  for (int k = 0; k < n; ++k) s += v[k] * 0.0;
  return s == 0.0; /* NaN for any NaN or Inf */
}

/* Evaluate the function at x = (tau, dgamma) into pb->ev and the residual R[7] (Pa: R_tau,
 * f).  Returns 0, or MPMC_ERR_SOLVER / MPMC_ERR_NUMERIC (flags set in pb). */
static int residual(cpp_problem *pb, const double *x, double *R) {
  const mpmc_cpp_param *m = pb->m;
  mpmc_yield_eval *ev = &pb->ev;
  const int rc = m->fn(m->data, x, pb->alpha_n + x[6], ev);
  if (rc) {
    pb->user_code = rc;
    return MPMC_ERR_SOLVER;
  }
  if (!isfinite(ev->f) || !all_finite(ev->r, 6)) {
    pb->nonfinite = 1;
    return MPMC_ERR_NUMERIC;
  }
  double cr[6];
  c_dot(m, ev->r, cr);
  for (int k = 0; k < 6; ++k) R[k] = x[k] - pb->tau_tr[k] + x[6] * cr[k];
  R[6] = ev->f;
  /* R_tau's round-off grows with dgamma C:r: r's own error (eps |dr/dtau| |tau|) times
     dgamma |C|, large after a long return from a pressure-dominated trial state */
  const double lam = fabs(m->K - 2.0 * m->G / 3.0);
  double crmax = 0.0, drsum = 0.0, xmax = 0.0;
  for (int k = 0; k < 6; ++k) {
    crmax = fmax(crmax, fabs(cr[k]));
    xmax = fmax(xmax, fabs(x[k]));
    double rowsum = 0.0;
    for (int j = 0; j < 6; ++j) rowsum += voigt_w[j] * fabs(ev->drdtau[6 * k + j]);
    drsum = fmax(drsum, rowsum);
  }
  pb->tol_tx = pb->tol_t + 16.0 * DBL_EPSILON * fabs(x[6]) *
                               (crmax + (2.0 * m->G + 3.0 * lam) * drsum * xmax);
  double rn = fabs(R[6]);
  for (int k = 0; k < 6; ++k) rn = fmax(rn, fabs(R[k]));
  pb->rnorm = rn / pb->s;
  return MPMC_SUCCESS;
}

/* The Jacobian dR/dx at pb->ev (column-major A[i + 7 j]); the shear columns doubled. */
static int jacobian(cpp_problem *pb, const double *x, double *A) {
  const mpmc_cpp_param *m = pb->m;
  const mpmc_yield_eval *ev = &pb->ev;
  if (!all_finite(ev->dfdtau, 6) || !all_finite(ev->drdtau, 36) ||
      !all_finite(ev->drdalpha, 6) || !isfinite(ev->dfdalpha)) {
    pb->nonfinite = 1;
    return MPMC_ERR_NUMERIC;
  }
  const double dg = x[6], lam = m->K - 2.0 * m->G / 3.0, G2 = 2.0 * m->G;
  for (int j = 0; j < 6; ++j) {
    const double w = voigt_w[j];
    const double trd = ev->drdtau[j] + ev->drdtau[6 + j] + ev->drdtau[12 + j];
    for (int i = 0; i < 6; ++i) {
      double cd = G2 * ev->drdtau[6 * i + j];
      if (i < 3) cd += lam * trd;
      A[i + N7 * j] = (i == j) + dg * w * cd;
    }
    A[6 + N7 * j] = w * ev->dfdtau[j];
  }
  double cr[6], cra[6];
  c_dot(m, ev->r, cr);
  c_dot(m, ev->drdalpha, cra);
  for (int i = 0; i < 6; ++i) A[i + N7 * 6] = cr[i] + dg * cra[i];
  A[6 + N7 * 6] = ev->dfdalpha;
  return MPMC_SUCCESS;
}

/* max(|R_tau|_max / tol_t, |f| / tol_f): <= 1 is converged */
static inline double scaled_norm(const cpp_problem *pb, const double *R) {
  double rt = 0.0;
  for (int k = 0; k < 6; ++k) rt = fmax(rt, fabs(R[k]));
  return fmax(rt / pb->tol_tx, fabs(R[6]) / pb->tol_f);
}

/* ---- Newton -------------------------------------------------------------------------- */
/* One Newton step at x, whose residual R (negated in place) was just evaluated: R becomes
 * the step.  pp: the perfect-plasticity predictor (df/dalpha left out), Newton's first step,
 * which gives dgamma = f / (df/dtau : C : r) > 0 where softening would give dgamma < 0
 * (the built-in J2 starts from the same point, return_map.c). */
static int newton_step(cpp_problem *pb, const double *x, double *R, int pp) {
  double A[N7 * N7];
  MPMC_CALL(jacobian(pb, x, A));
  if (pp) A[6 + N7 * 6] = 0.0;
  for (int k = 0; k < N7; ++k) R[k] = -R[k];
  if (pb->m->lapack ? mpmc_cpp_solve7_lapack(A, R) : mpmc_cpp_solve7_gauss(A, R))
    return MPMC_ERR_SOLVER;
  return MPMC_SUCCESS;
}

/* Full Newton from x (in/out).  strict (auto): give up at a stall or a step to dgamma < 0,
 * so that KINSOL takes over early; else such a step is cut to halve dgamma (softening
 * surfaces have a spurious root at dgamma < 0).  Returns 0 when converged with dgamma >= 0,
 * else an MPMC_ERR_* code; *res is the last scaled residual norm. */
static int newton(cpp_problem *pb, int strict, int max_iters, double *x, double *res,
                  mpmc_cpp_info *info) {
  double R[N7], prev = INFINITY;
  for (int it = 0;; ++it) {
    MPMC_CALL(residual(pb, x, R));
    const double nr = scaled_norm(pb, R);
    *res = nr;
    if (nr <= 1.0 && x[6] >= 0.0) return MPMC_SUCCESS;
    if (it >= max_iters || (strict && it >= 4 && nr > 0.5 * prev)) return MPMC_ERR_SOLVER;
    prev = nr;
    MPMC_CALL(newton_step(pb, x, R, it == 0));
    double t = 1.0;
    if (x[6] + R[6] < 0.0) {
      if (strict || !(x[6] > 0.0)) return MPMC_ERR_SOLVER;
      t = 0.5 * x[6] / -R[6];
    }
    for (int k = 0; k < N7; ++k) x[k] += t * R[k];
    info->newton_iters++;
    if (!all_finite(x, N7)) {
      pb->nonfinite = 1;
      return MPMC_ERR_NUMERIC;
    }
  }
}

/* ---- KINSOL with a LAPACK dense linear solver ---------------------------------------- */
/* A SUNLinearSolver over LAPACKE dgetrf/dgetrs on a SUNDenseMatrix (column-major, factored
 * in place like SUNDIALS' own dense solver). */
typedef struct {
  int ipiv[N7];
  sunindextype last_flag;
} lapack_ls;

static SUNLinearSolver_Type ls_gettype(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_DIRECT;
}
static SUNLinearSolver_ID ls_getid(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_CUSTOM;
}
static int ls_initialize(SUNLinearSolver S) {
  ((lapack_ls *)S->content)->last_flag = 0;
  return SUNLS_SUCCESS;
}
static int ls_setup(SUNLinearSolver S, SUNMatrix A) {
  lapack_ls *c = S->content;
  const int n = (int)SM_ROWS_D(A);
  if (n != N7 || SM_COLUMNS_D(A) != N7) return (int)(c->last_flag = SUNLS_ILL_INPUT);
  const int info = lapack.dgetrf(LAPACK_COL_MAJOR, n, n, SM_DATA_D(A), n, c->ipiv);
  c->last_flag = info;
  if (info > 0) return SUNLS_LUFACT_FAIL; /* singular: recoverable, KINSOL retries */
  return info < 0 ? SUNLS_PACKAGE_FAIL_UNREC : SUNLS_SUCCESS;
}
static int ls_solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, sunrealtype tol) {
  (void)tol;
  lapack_ls *c = S->content;
  const int n = (int)SM_ROWS_D(A);
  N_VScale(1.0, b, x);
  const int info = lapack.dgetrs(LAPACK_COL_MAJOR, 'N', n, 1, SM_DATA_D(A), n, c->ipiv,
                                 NV_DATA_S(x), n);
  c->last_flag = info;
  return info ? SUNLS_PACKAGE_FAIL_UNREC : SUNLS_SUCCESS;
}
static sunindextype ls_lastflag(SUNLinearSolver S) {
  return ((lapack_ls *)S->content)->last_flag;
}
static int ls_free(SUNLinearSolver S) {
  if (!S) return SUNLS_SUCCESS;
  free(S->content);
  S->content = NULL;
  SUNLinSolFreeEmpty(S);
  return SUNLS_SUCCESS;
}

static SUNLinearSolver lapack_ls_create(SUNContext sunctx) {
  SUNLinearSolver S = SUNLinSolNewEmpty(sunctx);
  if (!S) return NULL;
  S->ops->gettype = ls_gettype;
  S->ops->getid = ls_getid;
  S->ops->initialize = ls_initialize;
  S->ops->setup = ls_setup;
  S->ops->solve = ls_solve;
  S->ops->lastflag = ls_lastflag;
  S->ops->free = ls_free;
  S->content = calloc(1, sizeof(lapack_ls));
  if (!S->content) {
    SUNLinSolFreeEmpty(S);
    return NULL;
  }
  return S;
}

/* One KINSOL memory per thread, in the workspace's MPMC_RM_SLOT_CPP. */
typedef struct {
  SUNContext sunctx;
  void *kmem;
  N_Vector u, uscale, fscale, constraints;
  SUNMatrix A;
  SUNLinearSolver LS;
  cpp_problem *pb;
} cpp_kinsol;

static void cpp_kinsol_free(void *p) {
  cpp_kinsol *k = p;
  if (!k) return;
  if (k->kmem) KINFree(&k->kmem);
  if (k->LS) SUNLinSolFree(k->LS);
  if (k->A) SUNMatDestroy(k->A);
  N_Vector v[] = {k->u, k->uscale, k->fscale, k->constraints};
  for (int i = 0; i < 4; ++i)
    if (v[i]) N_VDestroy(v[i]);
  if (k->sunctx) SUNContext_Free(&k->sunctx);
  free(k);
}

static int kin_f(N_Vector u, N_Vector f, void *data) {
  cpp_kinsol *k = data;
  const int rc = residual(k->pb, NV_DATA_S(u), NV_DATA_S(f));
  if (rc == MPMC_ERR_SOLVER) return -1; /* the user's error: stop */
  return rc ? 1 : 0;                    /* non-finite: recoverable, shorter step */
}

static int kin_jac(N_Vector u, N_Vector fu, SUNMatrix J, void *data, N_Vector t1, N_Vector t2) {
  (void)t1;
  (void)t2;
  cpp_kinsol *k = data;
  /* KINSOL calls this right after kin_f at the same u, but not always: evaluate again */
  const int rc = residual(k->pb, NV_DATA_S(u), NV_DATA_S(fu));
  if (rc) return rc == MPMC_ERR_SOLVER ? -1 : 1;
  return jacobian(k->pb, NV_DATA_S(u), SM_DATA_D(J)) ? 1 : 0;
}

static void kin_silent_err(int code, const char *module, const char *fn, char *msg, void *d) {
  (void)code, (void)module, (void)fn, (void)msg, (void)d;
}
static void kin_silent_info(const char *module, const char *fn, char *msg, void *d) {
  (void)module, (void)fn, (void)msg, (void)d;
}

static cpp_kinsol *cpp_kinsol_create(void) {
  cpp_kinsol *k = calloc(1, sizeof *k);
  if (!k) return NULL;
  int ok = SUNContext_Create(NULL, &k->sunctx) == 0;
  if (ok) {
    k->u = N_VNew_Serial(N7, k->sunctx);
    k->uscale = N_VNew_Serial(N7, k->sunctx);
    k->fscale = N_VNew_Serial(N7, k->sunctx);
    k->constraints = N_VNew_Serial(N7, k->sunctx);
    ok = k->u && k->uscale && k->fscale && k->constraints;
  }
  if (ok) {
    k->A = SUNDenseMatrix(N7, N7, k->sunctx);
    k->LS = lapack_ls_create(k->sunctx);
    k->kmem = KINCreate(k->sunctx);
    ok = k->A && k->LS && k->kmem;
  }
  if (ok) {
    N_VConst(0.0, k->u);
    N_VConst(0.0, k->constraints);
    NV_Ith_S(k->constraints, 6) = 1.0; /* dgamma >= 0 */
    ok = KINInit(k->kmem, kin_f, k->u) == KIN_SUCCESS &&
         KINSetErrHandlerFn(k->kmem, kin_silent_err, NULL) == KIN_SUCCESS &&
         KINSetInfoHandlerFn(k->kmem, kin_silent_info, NULL) == KIN_SUCCESS &&
         KINSetPrintLevel(k->kmem, 0) == KIN_SUCCESS &&
         KINSetUserData(k->kmem, k) == KIN_SUCCESS &&
         KINSetLinearSolver(k->kmem, k->LS, k->A) == KIN_SUCCESS &&
         KINSetJacFn(k->kmem, kin_jac) == KIN_SUCCESS &&
         KINSetMaxSetupCalls(k->kmem, 1) == KIN_SUCCESS && /* a fresh Jacobian each time */
         KINSetConstraints(k->kmem, k->constraints) == KIN_SUCCESS &&
         /* fscale = 1/tolerance per component below: fnormtol 1 is our criterion */
         KINSetFuncNormTol(k->kmem, 1.0) == KIN_SUCCESS &&
         KINSetScaledStepTol(k->kmem, 4.0 * DBL_EPSILON) == KIN_SUCCESS;
  }
  if (!ok) {
    cpp_kinsol_free(k);
    return NULL;
  }
  return k;
}

/* KINSOL from x (in/out).  Returns 0 when converged with dgamma >= 0, else MPMC_ERR_*. */
static int solve_kinsol(mpmc_rm_ws *ws, cpp_problem *pb, int max_iters, double *x, double *res,
                        mpmc_cpp_info *info) {
  void **slot = mpmc_rm_ws_slot(ws, MPMC_RM_SLOT_CPP, cpp_kinsol_free);
  if (!slot) {
    info->reason = MPMC_CPP_NO_WORKSPACE;
    return MPMC_ERR_ARG;
  }
  if (!*slot) *slot = cpp_kinsol_create();
  cpp_kinsol *k = *slot;
  if (!k) {
    info->reason = MPMC_CPP_NO_WORKSPACE;
    return MPMC_ERR_MEMORY;
  }
  k->pb = pb;
  const double s = pb->s; /* scales: tau by the stress scale, dgamma by s / 2G */
  for (int i = 0; i < 6; ++i) {
    NV_Ith_S(k->u, i) = x[i];
    NV_Ith_S(k->uscale, i) = 1.0 / s;
    NV_Ith_S(k->fscale, i) = 1.0 / pb->tol_t;
  }
  NV_Ith_S(k->u, 6) = fmax(x[6], 0.0);
  NV_Ith_S(k->uscale, 6) = 2.0 * pb->m->G / s;
  NV_Ith_S(k->fscale, 6) = 1.0 / pb->tol_f;
  KINSetNumMaxIters(k->kmem, max_iters);
  const int flag = KINSol(k->kmem, k->u, KIN_LINESEARCH, k->uscale, k->fscale);
  long nni = 0;
  KINGetNumNonlinSolvIters(k->kmem, &nni);
  info->kinsol_iters += (int)nni;
  info->kinsol_flag = flag;
  if (pb->user_code) return MPMC_ERR_SOLVER;
  for (int i = 0; i < N7; ++i) x[i] = NV_Ith_S(k->u, i);
  /* judge the result by the residual (a line search stalled at round-off may be there);
     non-finite values on the way were KINSOL's shorter steps, not the answer */
  pb->nonfinite = 0;
  double R[N7];
  if (residual(pb, x, R)) return MPMC_ERR_SOLVER;
  *res = scaled_norm(pb, R);
  if (!(*res <= 1.0 && x[6] >= 0.0)) return MPMC_ERR_SOLVER;
  /* KINSOL stops at the tolerance; one Newton step from there (quadratic convergence) takes
     the result to round-off, as plain Newton's last step does, so that the solvers agree
     beyond the tolerance.  Kept only if it lowers the residual. */
  double y[N7];
  const double rnorm = pb->rnorm;
  memcpy(y, x, sizeof y);
  pb->rnorm = rnorm;
  if (newton_step(pb, x, R, 0) == MPMC_SUCCESS) {
    for (int i = 0; i < N7; ++i) y[i] += R[i];
    double R2[N7];
    if (y[6] >= 0.0 && residual(pb, y, R2) == MPMC_SUCCESS && scaled_norm(pb, R2) <= *res) {
      memcpy(x, y, sizeof y);
      *res = scaled_norm(pb, R2);
      info->newton_iters++;
    } else {
      pb->rnorm = rnorm;
    }
  }
  pb->user_code = 0; /* a failure of the polishing step is not the answer's */
  pb->nonfinite = 0;
  return MPMC_SUCCESS;
}

/* ---- the fallback's start ------------------------------------------------------------ */
/* Along the perfect-plasticity predictor's line
 *   x(c) = (tau_tr - c dg_p C:r_tr, alpha_n + c dg_p),  dg_p = f_tr / (df/dtau : C : r_tr),
 * the first point c = 1, 2, 4, ... on or past the surface (f <= tol) where r still faces
 * r_tr (halving back towards the last point inside when it turned).  On J2 this is the
 * radial return's line, and past the root Newton converges monotonically even where steep
 * softening makes the residual non-monotone near dgamma = 0 (return_map.h): KINSOL from the
 * trial state fails there.  Returns 0 with x set, or 1 (start from the trial state). */
static int predictor_start(cpp_problem *pb, double *x) {
  double R[N7];
  for (int k = 0; k < 6; ++k) x[k] = pb->tau_tr[k];
  x[6] = 0.0;
  if (residual(pb, x, R)) return 1;
  const mpmc_yield_eval e0 = pb->ev;
  double cr[6], den = 0.0;
  c_dot(pb->m, e0.r, cr);
  for (int k = 0; k < 6; ++k) den += voigt_w[k] * e0.dfdtau[k] * cr[k];
  if (!(den > 0.0) || !(e0.f > 0.0)) return 1;
  const double dgp = e0.f / den;
  double lo = 0.0, c = 1.0;
  for (int it = 0; it < 64 && c > lo; ++it) {
    for (int k = 0; k < 6; ++k) x[k] = pb->tau_tr[k] - c * dgp * cr[k];
    x[6] = c * dgp;
    double rr = 0.0;
    const int bad = residual(pb, x, R);
    if (!bad)
      for (int k = 0; k < 6; ++k) rr += voigt_w[k] * pb->ev.r[k] * e0.r[k];
    if (bad || !(rr > 0.0)) { /* the function refused the point, or r turned: back off */
      pb->user_code = pb->nonfinite = 0;
      c = 0.5 * (lo + c);
      continue;
    }
    if (R[6] <= pb->tol_f) return 0;
    lo = c;
    c *= 2.0;
  }
  return 1;
}

/* ---- the return ---------------------------------------------------------------------- */
static void fail_message(const cpp_problem *pb, const double *tau_tr, double alpha_n,
                         double res, mpmc_cpp_info *info) {
  char *msg = info->message;
  const size_t len = sizeof info->message;
  switch (info->reason) {
  case MPMC_CPP_USER_ERROR:
    snprintf(msg, len, "the user yield function returned %d (alpha = %g) after %d Newton and %d "
             "KINSOL iterations", info->user_code, alpha_n + info->dgamma, info->newton_iters,
             info->kinsol_iters);
    return;
  case MPMC_CPP_NO_WORKSPACE:
    snprintf(msg, len, "the user yield surface's KINSOL needs a workspace (ws NULL or out "
                       "of memory)");
    return;
  default:
    break;
  }
  int n = snprintf(msg, len,
                   "the user yield surface's return did not converge after %d Newton and %d "
                   "KINSOL iterations (KINSOL flag %d), residual %.3g x the tolerance%s%s: "
                   "check the yield function's derivatives",
                   info->newton_iters, info->kinsol_iters, info->kinsol_flag, res,
                   info->dgamma < 0 ? ", dgamma < 0" : "",
                   pb->nonfinite ? ", a non-finite value on the way" : "");
  /* name the worst derivative at the trial state when central differences disagree */
  double worst = 0.0;
  char name[32];
  if (n > 0 && (size_t)n < len &&
      mpmc_cpp_check_derivatives(pb->m, tau_tr, alpha_n, &worst, name, sizeof name) == 0 &&
      worst > 1e-4)
    snprintf(msg + n, len - (size_t)n, "; %s differs from central differences by %.2g", name,
             worst);
}

/**
 * @brief Closest-point projection in Kirchhoff stress space from tau_trial and alpha_n
 * (return_cpp.h).
 */
int mpmc_cpp_return_stress(mpmc_rm_ws *ws, int solver, const mpmc_cpp_param *m,
                           const double tau_tr_in[6], double *alpha, double tau[6],
                           mpmc_cpp_info *info) {
  mpmc_cpp_info local;
  if (!info) info = &local;
  memset(info, 0, offsetof(mpmc_cpp_info, message));
  info->message[0] = '\0';
  if (!m || !m->fn || !alpha || !tau || !tau_tr_in || !(m->G > 0) || !(m->K > 0) ||
      solver < MPMC_SOLVER_AUTO || solver > MPMC_SOLVER_KINSOL)
    return MPMC_ERR_ARG;
  double tau_tr[6];
  memcpy(tau_tr, tau_tr_in, sizeof tau_tr); /* tau may alias tau_tr */
  const double alpha_n = *alpha;
  cpp_problem pb = {.m = m, .tau_tr = tau_tr, .alpha_n = alpha_n, .s = 1.0};
  double x[N7], R[N7];
  for (int k = 0; k < 6; ++k) x[k] = tau_tr[k];
  x[6] = 0.0;
  /* the trial state: a non-finite one, or a function that fails there, ends it here */
  int err = all_finite(tau_tr, 6) && isfinite(alpha_n) ? residual(&pb, x, R) : MPMC_ERR_NUMERIC;
  if (!err && !all_finite(pb.ev.dfdtau, 6)) err = MPMC_ERR_NUMERIC;
  if (err) {
    info->reason = err == MPMC_ERR_NUMERIC ? MPMC_CPP_NON_FINITE : MPMC_CPP_USER_ERROR;
    info->user_code = pb.user_code;
    if (pb.user_code)
      snprintf(info->message, sizeof info->message,
               "the user yield function returned %d at the trial state (alpha = %g)",
               pb.user_code, alpha_n);
    else
      snprintf(info->message, sizeof info->message,
               "non-finite trial stress or alpha, or the user yield function gave a non-finite "
               "f, r or df/dtau at the trial state (alpha = %g)", alpha_n);
    return err;
  }
  /* the tolerances, fixed at the trial state: tol relative to the stress size s, plus
     round-off of tau_trial in R_tau and of f's own evaluation (through |df/dtau| |tau|) */
  const double tol = m->tol > 0 ? m->tol : 1e-12;
  double tmax = 0.0, tn2 = 0.0, dfsum = 0.0;
  for (int k = 0; k < 6; ++k) {
    tmax = fmax(tmax, fabs(tau_tr[k]));
    tn2 += voigt_w[k] * tau_tr[k] * tau_tr[k];
    dfsum += voigt_w[k] * fabs(pb.ev.dfdtau[k]);
  }
  const double s = fmax(fmax(sqrt(tn2), fabs(R[6])), DBL_MIN);
  pb.s = s;
  pb.tol_t = tol * s + 16.0 * DBL_EPSILON * tmax;
  pb.tol_f = tol * s + 16.0 * DBL_EPSILON * (tmax * dfsum + s);
  info->scale = s;
  if (R[6] <= pb.tol_f) { /* elastic */
    for (int k = 0; k < 6; ++k) tau[k] = tau_tr[k];
    return MPMC_SUCCESS;
  }
  info->plastic = 1;
  const char *why;
  if (mpmc_cpp_lapack_load(&why)) {
    info->reason = MPMC_CPP_NO_LAPACK;
    snprintf(info->message, sizeof info->message, "%s", why);
    return MPMC_ERR_UNSUPPORTED;
  }
  const int maxn = m->max_iters > 0 ? m->max_iters : CPP_NEWTON_ITERS;
  const int maxk = m->max_iters > 0 ? m->max_iters : CPP_KINSOL_ITERS;
  double res = NAN;
  if (solver == MPMC_SOLVER_AUTO || solver == MPMC_SOLVER_NEWTON)
    err = newton(&pb, solver == MPMC_SOLVER_AUTO, maxn, x, &res, info);
  if (err && solver == MPMC_SOLVER_NEWTON && !pb.user_code && !predictor_start(&pb, x)) {
    pb.nonfinite = 0; /* once more, from past the surface (softening, predictor_start) */
    err = newton(&pb, 0, maxn, x, &res, info);
  }
  if (solver == MPMC_SOLVER_KINSOL || (err && solver == MPMC_SOLVER_AUTO && !pb.user_code)) {
    info->fallback = solver == MPMC_SOLVER_AUTO;
    pb.nonfinite = 0;
    if (predictor_start(&pb, x)) {
      for (int k = 0; k < 6; ++k) x[k] = tau_tr[k];
      x[6] = 0.0;
    }
    err = solve_kinsol(ws, &pb, maxk, x, &res, info);
  }
  info->dgamma = x[6];
  info->residual = pb.rnorm;
  if (err) {
    if (pb.user_code) {
      info->reason = MPMC_CPP_USER_ERROR;
      info->user_code = pb.user_code;
      err = MPMC_ERR_SOLVER;
    } else if (!info->reason) {
      /* a non-finite iterate of a Newton that diverged is non-convergence too */
      info->reason = MPMC_CPP_NO_CONVERGENCE;
      err = MPMC_ERR_SOLVER;
    }
    fail_message(&pb, tau_tr, alpha_n, res, info);
    return err;
  }
  for (int k = 0; k < 6; ++k) tau[k] = x[k];
  *alpha = alpha_n + x[6];
  return MPMC_SUCCESS;
}

/**
 * @brief The tensor-level return of one point on Hencky elasticity (return_cpp.h).
 */
int mpmc_cpp_return_map(mpmc_rm_ws *ws, int solver, const mpmc_cpp_param *m, double F[3][3],
                        double *be, double *alpha, double *tau, double *J_out,
                        mpmc_cpp_info *info) {
  mpmc_cpp_info local;
  if (!info) info = &local;
  info->message[0] = '\0';
  if (!m || !be || !alpha || !tau) return MPMC_ERR_ARG;
  double b[6], lam[3], Q[3][3], t[3], tau_tr[6], tn[6];
  for (int k = 0; k < 6; ++k) b[k] = be[k];
  if (F) mpmc_push_forward(F, b);
  mpmc_sym3_eig(b, lam, Q);
  for (int a = 0; a < 3; ++a)
    if (!(lam[a] > 0.0) || !isfinite(lam[a])) {
      memset(info, 0, offsetof(mpmc_cpp_info, message));
      info->reason = MPMC_CPP_NON_FINITE;
      snprintf(info->message, sizeof info->message,
               "trial b_e not positive definite or not finite (eigenvalue %g)", lam[a]);
      return MPMC_ERR_NUMERIC;
    }
  double eps[3];
  for (int a = 0; a < 3; ++a) eps[a] = 0.5 * log(lam[a]);
  const double tr = eps[0] + eps[1] + eps[2];
  for (int a = 0; a < 3; ++a) t[a] = m->K * tr + 2.0 * m->G * (eps[a] - tr / 3.0);
  mpmc_sym3_compose(t, Q, tau_tr);
  double al = *alpha;
  MPMC_CALL(mpmc_cpp_return_stress(ws, solver, m, tau_tr, &al, tn, info));
  if (!info->plastic) {
    for (int k = 0; k < 6; ++k) be[k] = b[k], tau[k] = tau_tr[k];
    if (J_out) *J_out = exp(tr);
    return MPMC_SUCCESS;
  }
  /* eps_e = C^-1 tau = dev tau / 2G + tr tau / 9K I, b_e = exp(2 eps_e) */
  double ee[6], mu[3];
  const double p3 = (tn[0] + tn[1] + tn[2]) / 3.0;
  for (int k = 0; k < 6; ++k) ee[k] = tn[k] / (2.0 * m->G);
  for (int k = 0; k < 3; ++k) ee[k] += p3 / (3.0 * m->K) - p3 / (2.0 * m->G);
  mpmc_sym3_eig(ee, mu, Q);
  const double tre = mu[0] + mu[1] + mu[2];
  for (int a = 0; a < 3; ++a) mu[a] = exp(2.0 * mu[a]);
  mpmc_sym3_compose(mu, Q, be);
  for (int k = 0; k < 6; ++k) tau[k] = tn[k];
  *alpha = al;
  if (J_out) *J_out = exp(tre);
  return MPMC_SUCCESS;
}

/**
 * @brief Central-difference check of the user function's derivatives at (tau, alpha)
 * (return_cpp.h).
 */
int mpmc_cpp_check_derivatives(const mpmc_cpp_param *m, const double tau[6], double alpha,
                               double *worst_rel_err, char *worst_name, size_t name_len) {
  if (!m || !m->fn || !tau || !worst_rel_err) return MPMC_ERR_ARG;
  mpmc_yield_eval e0, ep, em;
  int rc = m->fn(m->data, tau, alpha, &e0);
  if (rc) return MPMC_ERR_SOLVER;
  if (!isfinite(e0.f) || !all_finite(e0.dfdtau, 6) || !all_finite(e0.r, 6) ||
      !all_finite(e0.drdtau, 36) || !all_finite(e0.drdalpha, 6) || !isfinite(e0.dfdalpha))
    return MPMC_ERR_NUMERIC;
  double tmax = 0.0, rmax = 0.0, dfmax = 0.0, drmax = 0.0, dramax = 0.0;
  for (int k = 0; k < 6; ++k) {
    tmax = fmax(tmax, fabs(tau[k]));
    rmax = fmax(rmax, fabs(e0.r[k]));
    dfmax = fmax(dfmax, fabs(e0.dfdtau[k]));
    dramax = fmax(dramax, fabs(e0.drdalpha[k]));
  }
  for (int k = 0; k < 36; ++k) drmax = fmax(drmax, fabs(e0.drdtau[k]));
  const double S = fmax(tmax, fabs(e0.f)) + DBL_MIN; /* stress scale */
  const double den_df = fmax(dfmax, fabs(e0.f) / S) + DBL_MIN, den_dfa = fmax(fabs(e0.dfdalpha), S);
  const double den_dr = fmax(drmax, rmax / S) + DBL_MIN, den_dra = fmax(dramax, rmax) + DBL_MIN;
  double worst = 0.0;
  char buf[32] = "none";
  /* tau directions: move the independent component j (both tensor entries), so that the
     difference quotient is w_j times the tensor derivative */
  const double ht = 1e-6 * S;
  for (int j = 0; j < 6; ++j) {
    double tp[6], tm[6];
    memcpy(tp, tau, sizeof tp);
    memcpy(tm, tau, sizeof tm);
    tp[j] += ht;
    tm[j] -= ht;
    if (m->fn(m->data, tp, alpha, &ep) || m->fn(m->data, tm, alpha, &em)) return MPMC_ERR_SOLVER;
    const double c = 1.0 / (2.0 * ht * voigt_w[j]);
    double err = fabs((ep.f - em.f) * c - e0.dfdtau[j]) / den_df;
    if (!(err <= worst)) worst = err, snprintf(buf, sizeof buf, "dfdtau[%d]", j);
    for (int i = 0; i < 6; ++i) {
      err = fabs((ep.r[i] - em.r[i]) * c - e0.drdtau[6 * i + j]) / den_dr;
      if (!(err <= worst)) worst = err, snprintf(buf, sizeof buf, "drdtau[%d][%d]", i, j);
    }
  }
  const double ha = 1e-6 * fmax(fabs(alpha), 1e-2);
  if (m->fn(m->data, tau, alpha + ha, &ep) || m->fn(m->data, tau, alpha - ha, &em))
    return MPMC_ERR_SOLVER;
  double err = fabs((ep.f - em.f) / (2.0 * ha) - e0.dfdalpha) / den_dfa;
  if (!(err <= worst)) worst = err, snprintf(buf, sizeof buf, "dfdalpha");
  for (int i = 0; i < 6; ++i) {
    err = fabs((ep.r[i] - em.r[i]) / (2.0 * ha) - e0.drdalpha[i]) / den_dra;
    if (!(err <= worst)) worst = err, snprintf(buf, sizeof buf, "drdalpha[%d]", i);
  }
  *worst_rel_err = worst;
  if (worst_name && name_len) snprintf(worst_name, name_len, "%s", buf);
  return isfinite(worst) ? MPMC_SUCCESS : MPMC_ERR_NUMERIC;
}
