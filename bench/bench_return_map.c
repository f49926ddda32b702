/* Nanoseconds per Hencky-J2 return map on the landslide material (paper 4.4: E = 25 MPa,
 * nu = 0.499, kappa_p = 40.82 kPa, kappa_r = 2.45 kPa, eta = 5) for the newton, kinsol and
 * auto local solvers: the whole point update (push-forward, eigen-decomposition, solve,
 * recomposition) and the scalar solve alone, over 20,000 plastic trial states.
 * The same for elastic trial states, by the fast (series) and the eigen path.
 *   bench_return_map              timing table (markdown)
 *   bench_return_map --elastic    the elastic rows only (for callgrind)
 *   bench_return_map --stability  the stiff/extreme table of docs/stability.md */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "j2_cases.h" /* tests/: the stiff/extreme table, shared with t403 */
#include "linalg.h"
#include "return_map.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static unsigned long long rng = 88172645463325252ull;
static double urand(void) {
  rng ^= rng >> 12;
  rng ^= rng << 25;
  rng ^= rng >> 27;
  return (double)((rng * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

#define NS 20000
static double be0[NS][6], ep0[NS], Fs[NS][3][3];

static mpmc_j2_param landslide(void) {
  const double E = 25e6, nu = 0.499;
  const mpmc_j2_param m = {E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu)), 40.82e3, 2.45e3, 5.0};
  return m;
}

/* states on the yield surface at eps_p in [0, 2], then a random increment of 1e-3 */
static void make_states(const mpmc_j2_param *mp) {
  const mpmc_j2_param m = *mp;
  for (int i = 0; i < NS; ++i) {
    ep0[i] = 2.0 * urand();
    const double kap = mpmc_j2_kappa(&m, ep0[i]), a = kap / (2 * sqrt(3.0) * m.G);
    double lam[3] = {exp(2 * a), exp(-2 * a), 1.0}, R[3][3];
    const double th = 2 * M_PI * urand(), c = cos(th), s = sin(th);
    double Rz[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
    memcpy(R, Rz, sizeof R);
    mpmc_sym3_compose(lam, R, be0[i]);
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) Fs[i][p][q] = (p == q) + 1e-3 * (2 * urand() - 1);
  }
}

static int timing(void) {
  const mpmc_j2_param m = landslide();
  make_states(&m);
  mpmc_rm_ws *ws;
  if (mpmc_rm_ws_create(&ws)) return 1;
  const char *names[3] = {"auto", "newton", "kinsol"};
  printf("| solver | ns / point return map | ns / scalar solve | plastic | fallbacks | mean iterations |\n");
  printf("|---|---:|---:|---:|---:|---:|\n");
  for (int s = 0; s < 3; ++s) {
    const int reps = s == MPMC_SOLVER_KINSOL ? 3 : 10;
    long plastic = 0, fb = 0, iters = 0;
    double best = INFINITY, best_scalar = INFINITY;
    for (int r = 0; r < reps; ++r) {
      double sink = 0;
      const double t0 = now();
      for (int i = 0; i < NS; ++i) {
        double be[6], ep = ep0[i], tau[6], J;
        memcpy(be, be0[i], sizeof be);
        mpmc_j2_info info = {0};
        if (mpmc_j2_return_map(ws, s, &m, Fs[i], be, &ep, tau, &J, &info)) return 2;
        sink += tau[0];
        if (r == 0) {
          plastic += info.plastic;
          fb += info.fallback;
          iters += info.newton_iters + info.kinsol_iters;
        }
      }
      const double t = (now() - t0) / NS * 1e9;
      if (t < best) best = t;
      /* the scalar solve alone, on the same trial q */
      const double t1 = now();
      for (int i = 0; i < NS; ++i) {
        const double kap = mpmc_j2_kappa(&m, ep0[i]);
        double dg;
        if (mpmc_rm_solve(ws, s, &m, kap * (1.0 + 0.5 * (i % 7 + 1)), ep0[i], &dg, NULL, NULL)) return 3;
        sink += dg;
      }
      const double ts = (now() - t1) / NS * 1e9;
      if (ts < best_scalar) best_scalar = ts;
      if (sink == 42.0) printf(" ");
    }
    printf("| %s | %.0f | %.0f | %ld / %d | %ld | %.2f |\n", names[s], best, best_scalar, plastic, NS, fb,
           plastic ? (double)iters / plastic : 0.0);
  }
  mpmc_rm_ws_destroy(&ws);
  return 0;
}

/* Elastic points (the bulk of a geotechnical model): the same states at a quarter of the
 * strain and a hundredth of the increment, through the fast (series) path and through the
 * eigen path alone. */
static int timing_elastic(void) {
  const mpmc_j2_param m = landslide();
  make_states(&m);
  mpmc_rm_ws *ws;
  if (mpmc_rm_ws_create(&ws)) return 1;
  static double be_el[NS][6], F_el[NS][3][3];
  for (int i = 0; i < NS; ++i) {
    for (int k = 0; k < 6; ++k) be_el[i][k] = (k < 3) + 0.25 * (be0[i][k] - (k < 3));
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) F_el[i][p][q] = (p == q) + 0.01 * (Fs[i][p][q] - (p == q));
  }
  printf("| elastic trial states | ns / point, fast path | ns / point, eigen path |\n|---|---:|---:|\n");
  double best[2] = {INFINITY, INFINITY};
  for (int r = 0; r < 10; ++r)
    for (int path = 0; path < 2; ++path) {
      double sink = 0;
      const double t0 = now();
      for (int i = 0; i < NS; ++i) {
        double be[6], ep = ep0[i], tau[6], J;
        memcpy(be, be_el[i], sizeof be);
        mpmc_j2_info info = {0};
        const int err = path ? mpmc_j2_return_map_eig(ws, MPMC_SOLVER_AUTO, &m, F_el[i], be, &ep, tau, &J, &info)
                             : mpmc_j2_return_map(ws, MPMC_SOLVER_AUTO, &m, F_el[i], be, &ep, tau, &J, &info);
        if (err || info.plastic) {
          fprintf(stderr, "point %d path %d: err %d plastic %d q %g kappa %g\n", i, path, err, info.plastic, info.q_trial, info.kappa);
          return 4;
        }
        sink += tau[0];
      }
      const double t = (now() - t0) / NS * 1e9;
      if (t < best[path]) best[path] = t;
      if (sink == 42.0) printf(" ");
    }
  printf("| auto | %.0f | %.0f |\n", best[0], best[1]);
  mpmc_rm_ws_destroy(&ws);
  return 0;
}

static int stability(void) {
  mpmc_rm_ws *ws;
  if (mpmc_rm_ws_create(&ws)) return 1;
  printf("| eta | nu | 3G / eta(kp-kr) | newton max it (bisections) | kinsol max it | auto: fallbacks / cases | max abs(q - kappa)/kappa | failures |\n");
  printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int ie = 0; ie < 4; ++ie)
    for (int in = 0; in < 4; ++in) {
      mpmc_j2_param m;
      tbl_material(ie, in, &m);
      int nmax = 0, nbis = 0, kmax = 0, fb = 0, fails = 0, plastic = 0;
      double worst = 0;
      for (int c = 0; c < TBL_NCASE; ++c)
        for (int s = 0; s < 3; ++s) {
          double be[6], ep, F[3][3], tau[6], J;
          tbl_case(&m, c, be, &ep, F);
          mpmc_j2_info info = {0};
          const int err = mpmc_j2_return_map(ws, s, &m, F, be, &ep, tau, &J, &info);
          if (err) {
            ++fails;
            continue;
          }
          if (!info.plastic) continue;
          if (s == MPMC_SOLVER_NEWTON) {
            if (info.newton_iters > nmax) nmax = info.newton_iters;
            nbis += info.bisections;
          }
          if (s == MPMC_SOLVER_KINSOL && info.kinsol_iters > kmax) kmax = info.kinsol_iters;
          if (s == MPMC_SOLVER_AUTO) {
            fb += info.fallback;
            ++plastic;
          }
          const double kap = mpmc_j2_kappa(&m, ep), e = fabs(tbl_vm(tau) - kap) / kap;
          if (e > worst) worst = e;
        }
      printf("| %g | %g | %.3g | %d (%d) | %d | %d / %d | %.1e | %d |\n", m.eta, tbl_nu[in],
             3 * m.G / (m.eta * (m.kappa_p - m.kappa_r)), nmax, nbis, kmax, fb, plastic, worst, fails);
    }
  mpmc_rm_ws_destroy(&ws);
  return 0;
}

int main(int argc, char **argv) {
  if (argc > 1 && !strcmp(argv[1], "--stability")) return stability();
  if (argc > 1 && !strcmp(argv[1], "--elastic")) return timing_elastic();
  const int err = timing();
  printf("\n");
  return err ? err : timing_elastic();
}
