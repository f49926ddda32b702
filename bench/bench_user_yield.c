/* Nanoseconds per plastic point of the user-yield-surface return (return_cpp.c) with J2 and
 * exponential softening written as a user surface, on the landslide material (paper 4.4:
 * E = 25 MPa, nu = 0.499, kappa_p = 40.82 kPa, kappa_r = 2.45 kPa, eta = 5), auto solver:
 * Newton's 7x7 systems by the hand-written elimination and by LAPACKE_dgesv, against the
 * built-in J2 return (eigen path and fast path); and one 7x7 solve alone each way.
 *   bench_user_yield [npoints]      timing table (markdown), one thread */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "linalg.h"
#include "return_cpp.h"
#include "return_map.h"
#include "bench_util.h"

/* J2 with exponential softening as a user surface (tests/t415's, without its faults) */
static int j2_fn(void *data, const double *tau, double alpha, mpmc_yield_eval *out) {
  const mpmc_j2_param *m = data;
  const double p = (tau[0] + tau[1] + tau[2]) / 3.0, c = sqrt(1.5);
  double s[6], n[6];
  for (int k = 0; k < 6; ++k) s[k] = tau[k] - (k < 3 ? p : 0.0);
  const double ns = sqrt(mpmc_sym3_norm2(s));
  const double e = (m->kappa_p - m->kappa_r) * exp(-m->eta * alpha);
  out->f = c * ns - (m->kappa_r + e);
  out->dfdalpha = m->eta * e;
  for (int k = 0; k < 6; ++k) {
    n[k] = s[k] / ns;
    out->dfdtau[k] = out->r[k] = c * n[k];
    out->drdalpha[k] = 0.0;
  }
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      double v = (i == j) ? (i < 3 ? 1.0 : 0.5) : 0.0;
      if (i < 3 && j < 3) v -= 1.0 / 3.0;
      out->drdtau[6 * i + j] = c * (v - n[i] * n[j]) / ns;
    }
  return 0;
}

typedef struct {
  double be[6], ep, F[3][3];
} state;

/* states on the yield surface at eps_p in [0, 2], then a random increment of 1e-3; only the
 * plastic ones are kept */
static int make_states(const mpmc_j2_param *m, state *st, int n) {
  int k = 0;
  while (k < n) {
    state *s = &st[k];
    s->ep = 2.0 * urand();
    const double kap = mpmc_j2_kappa(m, s->ep), a = kap / (2 * sqrt(3.0) * m->G);
    double lam[3] = {exp(2 * a), exp(-2 * a), 1.0};
    const double th = 2 * M_PI * urand(), c = cos(th), sn = sin(th);
    double R[3][3] = {{c, -sn, 0}, {sn, c, 0}, {0, 0, 1}};
    mpmc_sym3_compose(lam, R, s->be);
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) s->F[p][q] = (p == q) + 1e-3 * (2 * urand() - 1);
    double be[6], tau[6], ep = s->ep, F[3][3];
    memcpy(be, s->be, sizeof be);
    memcpy(F, s->F, sizeof F);
    mpmc_j2_info info = {0};
    if (mpmc_j2_return_map_eig(NULL, MPMC_SOLVER_NEWTON, m, F, be, &ep, tau, NULL, &info))
      return -1;
    k += info.plastic;
  }
  return n;
}

enum { USER_GAUSS, USER_LAPACK, J2_EIG, J2_FAST };

/* best of 5 passes, ns per point */
static double time_returns(int kind, mpmc_rm_ws *ws, const mpmc_j2_param *m, const state *st,
                           int n, double *iters) {
  mpmc_cpp_param p = {.K = m->K, .G = m->G, .fn = j2_fn, .data = (void *)m};
  p.lapack = kind == USER_LAPACK;
  double best = INFINITY, sum = 0.0;
  long nit = 0;
  for (int pass = 0; pass < 5; ++pass) {
    nit = 0;
    const double t0 = now();
    for (int i = 0; i < n; ++i) {
      double be[6], tau[6], ep = st[i].ep, F[3][3];
      memcpy(be, st[i].be, sizeof be);
      memcpy(F, st[i].F, sizeof F);
      int err;
      if (kind == USER_GAUSS || kind == USER_LAPACK) {
        mpmc_cpp_info info;
        err = mpmc_cpp_return_map(ws, MPMC_SOLVER_AUTO, &p, F, be, &ep, tau, NULL, &info);
        nit += info.newton_iters + info.kinsol_iters;
        if (err) fprintf(stderr, "point %d: %s\n", i, info.message);
      } else if (kind == J2_EIG) {
        err = mpmc_j2_return_map_eig(ws, MPMC_SOLVER_AUTO, m, F, be, &ep, tau, NULL, NULL);
      } else {
        err = mpmc_j2_return_map(ws, MPMC_SOLVER_AUTO, m, F, be, &ep, tau, NULL, NULL);
      }
      if (err) return NAN;
      sum += tau[0];
    }
    const double t = (now() - t0) / n * 1e9;
    if (t < best) best = t;
  }
  if (iters) *iters = (double)nit / n;
  if (sum == 42.0) printf(" "); /* keep the results alive */
  return best;
}

/* ns per 7x7 solve of Newton-like systems (identity plus a rank-one-ish coupling) */
static double time_solve7(int lapack, int n) {
  double A0[49], b0[7], sum = 0.0, best = INFINITY;
  for (int i = 0; i < 7; ++i) {
    b0[i] = urand() - 0.5;
    for (int j = 0; j < 7; ++j) A0[i + 7 * j] = (i == j) + 0.3 * (urand() - 0.5);
  }
  for (int pass = 0; pass < 5; ++pass) {
    const double t0 = now();
    for (int k = 0; k < n; ++k) {
      double A[49], b[7];
      memcpy(A, A0, sizeof A);
      memcpy(b, b0, sizeof b);
      A[0] += 1e-9 * k; /* not loop-invariant */
      if (lapack ? mpmc_cpp_solve7_lapack(A, b) : mpmc_cpp_solve7_gauss(A, b)) return NAN;
      sum += b[3];
    }
    const double t = (now() - t0) / n * 1e9;
    if (t < best) best = t;
  }
  if (sum == 42.0) printf(" ");
  return best;
}

int main(int argc, char **argv) {
  const int n = argc > 1 ? atoi(argv[1]) : 20000;
  if (n < 1) return 1;
  const char *why;
  if (mpmc_cpp_lapack_load(&why)) {
    fprintf(stderr, "%s\n", why);
    return 1;
  }
  const double E = 25e6, nu = 0.499;
  const mpmc_j2_param m = {E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu)), 40.82e3, 2.45e3, 5.0};
  state *st = malloc(sizeof *st * (size_t)n);
  mpmc_rm_ws *ws;
  if (!st || mpmc_rm_ws_create(&ws) || make_states(&m, st, n) != n) return 1;
  double it_g = 0, it_l = 0;
  const double tg = time_returns(USER_GAUSS, ws, &m, st, n, &it_g);
  const double tl = time_returns(USER_LAPACK, ws, &m, st, n, &it_l);
  const double te = time_returns(J2_EIG, ws, &m, st, n, NULL);
  const double tf = time_returns(J2_FAST, ws, &m, st, n, NULL);
  const double sg = time_solve7(0, 200000), sl = time_solve7(1, 200000);
  printf("%d plastic points, landslide material, auto solver, one thread\n\n", n);
  printf("| return (whole point update)               | ns/point | iterations |\n");
  printf("|-------------------------------------------|---------:|-----------:|\n");
  printf("| user J2, hand-written 7x7 elimination     | %8.0f | %10.2f |\n", tg, it_g);
  printf("| user J2, LAPACKE_dgesv (param.lapack = 1) | %8.0f | %10.2f |\n", tl, it_l);
  printf("| built-in J2, eigen path                   | %8.0f |            |\n", te);
  printf("| built-in J2, fast (series) path           | %8.0f |            |\n", tf);
  printf("\n| one 7x7 solve            | ns    |\n|--------------------------|------:|\n");
  printf("| hand-written elimination | %5.0f |\n| LAPACKE_dgesv            | %5.0f |\n", sg, sl);
  mpmc_rm_ws_destroy(&ws);
  free(st);
  return 0;
}
