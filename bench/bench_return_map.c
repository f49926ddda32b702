/* Nanoseconds per Hencky-J2 return map on the landslide material (paper 4.4: E = 25 MPa,
 * nu = 0.499, kappa_p = 40.82 kPa, kappa_r = 2.45 kPa, eta = 5) for the newton, kinsol and
 * auto local solvers: the whole point update (push-forward, eigen-decomposition, solve,
 * recomposition) and the scalar solve alone, over 20,000 plastic trial states.
 * The same for elastic trial states, by the fast (series) and the eigen path.
 *   bench_return_map              timing table (markdown)
 *   bench_return_map --elastic    the elastic rows only (for callgrind)
 *   bench_return_map --stability  the stiff/extreme table of docs/stability.md
 *   bench_return_map --mc         Mohr-Coulomb / Drucker-Prager (return_mc.c) against J2
 *   bench_return_map --mc-like    its second table alone (the like-for-like ratios)
 * The Mohr-Coulomb rows: a frictional soil (E = 25 MPa, nu = 0.3, c 20 -> 2 kPa, phi 30 -> 20
 * deg, psi 10 -> 0 deg, eta = 5) on its yield surface at eps_p in [0, 2], mean stress
 * -200..-10 kPa, random Lode angle and rotation, then the same 1e-3 increments as J2's.  The
 * issue's target: the Mohr-Coulomb update at most 2x J2's per point.
 * The second --mc table is like for like: the same b_e^n, eps_p and increment for J2 and the
 * frictional models, with J2's strength matched point by point to Mohr-Coulomb's at the
 * state's mean stress and Lode angle (kappa = sqrt(3/2) |dev tau| at yield, peak and
 * residual, the same eta), on a slope-like mix (80 % never yielded at 20-90 % of the
 * strength, 20 % on the surface with eps_p in [0, 2]; increments 1e-4) and on an all-plastic
 * set (trial states plastic for both models); the rows give ns per point of J2's point update
 * (series path), the frictional update (mpmc_mc_update), the same four points at a time
 * (mpmc_mc_update4 as a sim runs it: its AVX2 build where it can, mpmc_mc_update4_for) and its eigen path alone (mpmc_mc_return_map_eig),
 * and the ratios to J2. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "j2_cases.h" /* tests/: the stiff/extreme table, shared with t403 */
#include "linalg.h"
#include "return_map.h"
#include "return_mc.h"
#include "bench_util.h"

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


/* ---- Mohr-Coulomb / Drucker-Prager ------------------------------------------------- */
static mpmc_mc_param mc_soil(int surface, int soft) {
  const double E = 25e6, nu = 0.3, d = M_PI / 180;
  mpmc_mc_param m = {E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu)), 20e3, 2e3, 30 * d, 20 * d,
                     10 * d, 0.0, 5.0, INFINITY, surface};
  if (!soft) m.c_r = m.c_p, m.phi_r = m.phi_p, m.psi_r = m.psi_p, m.eta = 0;
  return m;
}

static double mc_be0[NS][6], mc_ep0[NS];

/* states on the yield surface of m at eps_p (MC's f along p + q d is linear in q; DP: the
 * same with sqrt(J2) = q |d| / sqrt 2), in a random frame */
static void mc_states(const mpmc_mc_param *m) {
  for (int i = 0; i < NS; ++i) {
    mc_ep0[i] = 2.0 * urand();
    double c, phi, psi;
    mpmc_mc_soften(m, mc_ep0[i], &c, &phi, &psi);
    const double p = -(10e3 + 190e3 * urand());
    double dv[3] = {2 * urand() - 1, 2 * urand() - 1, 0};
    dv[2] = -dv[0] - dv[1];
    const double n = sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
    for (int a = 0; a < 3; ++a) dv[a] /= n;
    double hi = fmax(dv[0], fmax(dv[1], dv[2])), lo = fmin(dv[0], fmin(dv[1], dv[2]));
    double q;
    if (m->surface == MPMC_MC_MOHR_COULOMB)
      q = (2 * c * cos(phi) - 2 * p * sin(phi)) / ((hi - lo) + (hi + lo) * sin(phi));
    else {
      const double sf = sin(phi), g = m->surface == MPMC_DP_COMPRESSION ? 3 - sf : 3 + sf;
      const double eta = 6 * sf / (sqrt(3.0) * g), xi = 6 * cos(phi) / (sqrt(3.0) * g);
      q = (xi * c - eta * p) * sqrt(2.0); /* the plane-strain matching is not timed */
    }
    double lam[3], R[3][3];
    for (int a = 0; a < 3; ++a) {
      const double s = p + 0.999 * q * dv[a]; /* just inside */
      lam[a] = exp(2 * ((s - p) / (2 * m->G) + p / (3 * m->K)));
    }
    const double th = 2 * M_PI * urand(), ph = 2 * M_PI * urand();
    const double Rz[3][3] = {{cos(th), -sin(th), 0}, {sin(th), cos(th), 0}, {0, 0, 1}};
    const double Rx[3][3] = {{1, 0, 0}, {0, cos(ph), -sin(ph)}, {0, sin(ph), cos(ph)}};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) {
        R[r][k] = 0;
        for (int l = 0; l < 3; ++l) R[r][k] += Rz[r][l] * Rx[l][k];
      }
    mpmc_sym3_compose(lam, R, mc_be0[i]);
  }
}

/* best-of-reps ns per point of J2 (fast path or eigen path) on its landslide states */
static double j2_ns(mpmc_rm_ws *ws, int eig) {
  const mpmc_j2_param m = landslide();
  make_states(&m);
  double best = INFINITY, sink = 0;
  for (int r = 0; r < 10; ++r) {
    const double t0 = now();
    for (int i = 0; i < NS; ++i) {
      double be[6], ep = ep0[i], tau[6], J;
      memcpy(be, be0[i], sizeof be);
      mpmc_j2_info info = {0};
      const int err = eig ? mpmc_j2_return_map_eig(ws, MPMC_SOLVER_AUTO, &m, Fs[i], be, &ep, tau, &J, &info)
                          : mpmc_j2_return_map(ws, MPMC_SOLVER_AUTO, &m, Fs[i], be, &ep, tau, &J, &info);
      if (err) return NAN;
      sink += tau[0];
    }
    best = fmin(best, (now() - t0) / NS * 1e9);
  }
  if (sink == 42.0) printf(" ");
  return best;
}

static int timing_mc(void) {
  mpmc_rm_ws *ws;
  if (mpmc_rm_ws_create(&ws)) return 1;
  const double j2f = j2_ns(ws, 0), j2e = j2_ns(ws, 1);
  printf("| model | solver | ns / point | plastic | fallbacks | mean iterations (newton + kinsol) | regions plane/edges/apex | / J2 fast | / J2 eigen |\n");
  printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  printf("| J2 (landslide) | auto | %.0f | | | | | 1.00 | %.2f |\n", j2f, j2f / j2e);
  printf("| J2 (landslide), eigen path | auto | %.0f | | | | | %.2f | 1.00 |\n", j2e, j2e / j2f);
  const char *names[3] = {"auto", "newton", "kinsol"};
  const struct {
    const char *label;
    int surface, soft;
  } models[] = {{"Mohr-Coulomb, softening", MPMC_MC_MOHR_COULOMB, 1},
                {"Mohr-Coulomb, perfect", MPMC_MC_MOHR_COULOMB, 0},
                {"Drucker-Prager (compression), softening", MPMC_DP_COMPRESSION, 1}};
  for (int k = 0; k < 3; ++k) {
    const mpmc_mc_param m = mc_soil(models[k].surface, models[k].soft);
    rng_state = TEST_RNG_SEED;
    const mpmc_j2_param lm = landslide();
    make_states(&lm); /* the same increments Fs as J2's */
    mc_states(&m);
    for (int s = 0; s < 3; ++s) {
      if (!models[k].soft && s) continue; /* one closed form for every solver */
      const int reps = s == MPMC_SOLVER_KINSOL ? 3 : 10;
      long plastic = 0, fb = 0, iters = 0, reg[8] = {0};
      double best = INFINITY, sink = 0;
      for (int r = 0; r < reps; ++r) {
        const double t0 = now();
        for (int i = 0; i < NS; ++i) {
          double be[6], ep = mc_ep0[i], tau[6], J;
          memcpy(be, mc_be0[i], sizeof be);
          mpmc_mc_info info;
          const int err = mpmc_mc_return_map(ws, s, &m, Fs[i], be, &ep, tau, &J, &info);
          if (err) {
            fprintf(stderr, "%s %s point %d: error %d\n", models[k].label, names[s], i, err);
            return 2;
          }
          sink += tau[0];
          if (r == 0) {
            plastic += info.plastic;
            fb += info.fallback;
            iters += info.newton_iters + info.kinsol_iters;
            reg[info.region]++;
          }
        }
        best = fmin(best, (now() - t0) / NS * 1e9);
      }
      if (sink == 42.0) printf(" ");
      printf("| %s | %s | %.0f | %ld / %d | %ld | %.2f | %ld/%ld/%ld | %.2f | %.2f |\n", models[k].label,
             models[k].soft ? names[s] : "closed form", best, plastic, NS, fb,
             plastic ? (double)iters / plastic : 0.0, reg[1], reg[2] + reg[3], reg[4], best / j2f,
             best / j2e);
    }
  }
  mpmc_rm_ws_destroy(&ws);
  return 0;
}

/* ---- like for like: the same trial states for J2 and the frictional models ------------ */
static double ll_be[NS][6], ll_ep[NS], ll_F[NS][3][3];
static mpmc_j2_param ll_j2[NS];

/* the multiplier of the unit deviatoric direction dv (|dv| = 1) that puts p + q dv on
 * Mohr-Coulomb's surface with c, phi */
static double mc_qm(double c, double phi, double p, const double dv[3]) {
  const double hi = fmax(dv[0], fmax(dv[1], dv[2])), lo = fmin(dv[0], fmin(dv[1], dv[2]));
  return (2 * c * cos(phi) - 2 * p * sin(phi)) / ((hi - lo) + (hi + lo) * sin(phi));
}

/* one state: mean stress p, a random Lode angle at ratio r of the strength at eps_p, a
 * random frame, an increment of size h; J2's kappa matched at (p, Lode angle) */
static void ll_state(const mpmc_mc_param *m, int i, double r, double ep, double h) {
  double c, phi, psi;
  mpmc_mc_soften(m, ep, &c, &phi, &psi);
  const double p = -(10e3 + 190e3 * urand());
  double dv[3] = {2 * urand() - 1, 2 * urand() - 1, 0};
  dv[2] = -dv[0] - dv[1];
  const double n = sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
  for (int a = 0; a < 3; ++a) dv[a] /= n;
  const double q = r * mc_qm(c, phi, p, dv);
  double lam[3], R[3][3];
  for (int a = 0; a < 3; ++a) {
    const double s = p + q * dv[a];
    lam[a] = exp(2 * ((s - p) / (2 * m->G) + p / (3 * m->K)));
  }
  const double th = 2 * M_PI * urand(), ph = 2 * M_PI * urand();
  const double Rz[3][3] = {{cos(th), -sin(th), 0}, {sin(th), cos(th), 0}, {0, 0, 1}};
  const double Rx[3][3] = {{1, 0, 0}, {0, cos(ph), -sin(ph)}, {0, sin(ph), cos(ph)}};
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 3; ++k) {
      R[a][k] = 0;
      for (int l = 0; l < 3; ++l) R[a][k] += Rz[a][l] * Rx[l][k];
    }
  mpmc_sym3_compose(lam, R, ll_be[i]);
  ll_ep[i] = ep;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) ll_F[i][a][b] = (a == b) + h * (2 * urand() - 1);
  const double s3 = sqrt(1.5);
  ll_j2[i] = (mpmc_j2_param){m->K, m->G, s3 * mc_qm(m->c_p, m->phi_p, p, dv),
                             s3 * mc_qm(m->c_r, m->phi_r, p, dv), m->eta};
}

/* the slope-like mix (set 0) or the all-plastic set (1) of Mohr-Coulomb material m */
static int ll_states(const mpmc_mc_param *m, int set, mpmc_rm_ws *ws) {
  for (int i = 0; i < NS; ++i) {
    if (set == 0) {
      if (urand() < 0.8)
        ll_state(m, i, 0.2 + 0.7 * urand(), 0.0, 1e-4);
      else
        ll_state(m, i, 0.999, 2.0 * urand(), 1e-4);
      continue;
    }
    for (int tries = 0;; ++tries) { /* plastic for both */
      if (tries > 1000) return 1;
      ll_state(m, i, 0.999, 2.0 * urand(), 1e-3);
      double be[6], ep = ll_ep[i], tau[6], J;
      mpmc_j2_info ji = {0};
      mpmc_mc_info mi;
      memcpy(be, ll_be[i], sizeof be);
      if (mpmc_j2_return_map(ws, MPMC_SOLVER_AUTO, &ll_j2[i], ll_F[i], be, &ep, tau, &J, &ji)) return 2;
      ep = ll_ep[i];
      memcpy(be, ll_be[i], sizeof be);
      if (mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, m, ll_F[i], be, &ep, tau, &J, &mi)) return 3;
      if (ji.plastic && mi.plastic) break;
    }
  }
  return 0;
}

/* best of 10 runs, ns per point: path 0 J2, 1 the frictional update, 2 its eigen path,
 * 3 the frictional update four points at a time (the material's blocks, the sim's default
 * build of mpmc_mc_update4) */
static double ll_time(mpmc_rm_ws *ws, const mpmc_mc_param *m, int path, long *plastic) {
  mpmc_mc_pre pre;
  mpmc_mc_prepare(m, &pre);
  const mpmc_mc_update4_fn update4 = mpmc_mc_update4_for(MPMC_KERNELS_AUTO); /* a sim's */
  double best = INFINITY, sink = 0;
  *plastic = 0;
  for (int r = 0; r < 10; ++r) {
    long np = 0;
    const double t0 = now();
    if (path == 3)
      for (int i = 0; i < NS; i += 4) { /* NS is a multiple of 4 */
        double be[4][6], ep[4], tau[4][6], J[4];
        mpmc_mc_info info[4];
        int err[4];
        memcpy(be, ll_be[i], sizeof be);
        memcpy(ep, ll_ep + i, sizeof ep);
        update4(ws, MPMC_SOLVER_AUTO, &pre, 4, ll_F + i, be, ep, tau, J, info, err);
        for (int l = 0; l < 4; ++l) {
          if (err[l]) {
            fprintf(stderr, "like for like, blocks, point %d: error %d\n", i + l, err[l]);
            return NAN;
          }
          np += info[l].plastic;
          sink += tau[l][0];
        }
      }
    for (int i = 0; i < NS && path != 3; ++i) {
      double be[6], ep = ll_ep[i], tau[6], J;
      memcpy(be, ll_be[i], sizeof be);
      int err, pl;
      if (path == 0) {
        mpmc_j2_info info = {0};
        err = mpmc_j2_return_map(ws, MPMC_SOLVER_AUTO, &ll_j2[i], ll_F[i], be, &ep, tau, &J, &info);
        pl = info.plastic;
      } else {
        mpmc_mc_info info;
        err = path == 1 ? mpmc_mc_update(ws, MPMC_SOLVER_AUTO, &pre, ll_F[i], be, &ep, tau, &J, &info)
                        : mpmc_mc_return_map_eig(ws, MPMC_SOLVER_AUTO, m, ll_F[i], be, &ep, tau, &J, &info);
        pl = info.plastic;
      }
      if (err) {
        fprintf(stderr, "like for like, path %d, point %d: error %d\n", path, i, err);
        return NAN;
      }
      np += pl;
      sink += tau[0];
    }
    best = fmin(best, (now() - t0) / NS * 1e9);
    *plastic = np;
  }
  if (sink == 42.0) printf(" ");
  return best;
}

static int timing_like(void) {
  mpmc_rm_ws *ws;
  if (mpmc_rm_ws_create(&ws)) return 1;
  printf("| states | model | ns / point J2 | ns / point model | ratio | blocks of 4 | ratio | eigen path alone | plastic J2 / model |\n");
  printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  const char *sets[2] = {"slope mix", "all plastic"};
  const struct {
    const char *label;
    int surface, soft;
  } models[] = {{"Mohr-Coulomb, softening", MPMC_MC_MOHR_COULOMB, 1},
                {"Mohr-Coulomb, perfect", MPMC_MC_MOHR_COULOMB, 0},
                {"Drucker-Prager (compression), softening", MPMC_DP_COMPRESSION, 1}};
  for (int set = 0; set < 2; ++set)
    for (int k = 0; k < 3; ++k) {
      const mpmc_mc_param m = mc_soil(models[k].surface, models[k].soft);
      rng_state = TEST_RNG_SEED;
      /* the states come from Mohr-Coulomb's strength: the same b_e, eps_p, F for every row */
      const mpmc_mc_param mmc = mc_soil(MPMC_MC_MOHR_COULOMB, models[k].soft);
      if (ll_states(&mmc, set, ws)) {
        fprintf(stderr, "like for like: no plastic states\n");
        return 2;
      }
      long pj, pm, pe, pb;
      const double tj = ll_time(ws, &m, 0, &pj), tm = ll_time(ws, &m, 1, &pm), te = ll_time(ws, &m, 2, &pe);
      const double tb = ll_time(ws, &m, 3, &pb);
      if (!(isfinite(tj) && isfinite(tm) && isfinite(te) && isfinite(tb)) || pb != pm) return 3;
      printf("| %s | %s | %.0f | %.0f | %.2f | %.0f | %.2f | %.0f | %ld / %ld of %d |\n", sets[set],
             models[k].label, tj, tm, tm / tj, tb, tb / tj, te, pj, pm, NS);
    }
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
  if (argc > 1 && !strcmp(argv[1], "--mc-like")) return timing_like();
  if (argc > 1 && !strcmp(argv[1], "--mc")) {
    const int err = timing_mc();
    printf("\n");
    return err ? err : timing_like();
  }
  int err = timing();
  printf("\n");
  if (!err) err = timing_elastic();
  printf("\n");
  if (!err) err = timing_mc();
  printf("\n");
  return err ? err : timing_like();
}
