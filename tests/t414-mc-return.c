/* The frictional return map (return_mc.c): Mohr-Coulomb and Drucker-Prager with a tension
 * cut-off and softening.  Each region of Mohr-Coulomb against its projection written out
 * here by hand (perfect plasticity), the yield conditions after random returns, the three
 * Drucker-Prager matchings against Mohr-Coulomb's strengths, the apexes, newton vs kinsol vs
 * auto on random softening states and on steep softening, objectivity, strength reduction,
 * the eigen-free elastic check against the eigen path, the update of four points at once
 * against the point update (bit for bit), and three element tests at the
 * tensor level: drained triaxial compression and plane-strain biaxial compression (peak and
 * residual strength) and simple shear (volume change from the dilation angle). */
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "return_mc.h"
#include "test_util.h"

#define TEST_RNG_SEED 0x9B1C3A5D7E2F4061ull
#include "test_rand.h"

#define DEG (M_PI / 180.0)

static mpmc_rm_ws *ws;

static mpmc_mc_param base(void) {
  const double E = 50e6, nu = 0.3;
  mpmc_mc_param m = {.K = E / (3 * (1 - 2 * nu)), .G = E / (2 * (1 + nu)), .c_p = 20e3,
                     .c_r = 20e3, .phi_p = 30 * DEG, .phi_r = 30 * DEG, .psi_p = 10 * DEG,
                     .psi_r = 10 * DEG, .eta = 0, .sigma_t = INFINITY,
                     .surface = MPMC_MC_MOHR_COULOMB};
  return m;
}

/* principal log strains of a principal Kirchhoff stress */
static void strain_of(const mpmc_mc_param *m, const double s[3], double e[3]) {
  const double p = (s[0] + s[1] + s[2]) / 3;
  for (int a = 0; a < 3; ++a) e[a] = (s[a] - p) / (2 * m->G) + p / (3 * m->K);
}

/* return a principal trial stress; fails the test on an error */
static void ret(const mpmc_mc_param *m, int solver, const double str[3], double *ep,
                double tau[3], mpmc_mc_info *info) {
  double etr[3], e[3];
  strain_of(m, str, etr);
  const int err = mpmc_mc_return_principal(ws, solver, m, etr, ep, e, tau, info);
  if (err)
    fail_msg("trial (%.17g, %.17g, %.17g), eps_p %.17g, solver %d: error %d (%s), KINSOL flag "
             "%d; material K %.17g G %.17g c %.17g %.17g phi %.17g %.17g psi %.17g %.17g eta "
             "%.17g sigma_t %.17g surface %d",
             str[0], str[1], str[2], *ep, solver, err, mpmc_error_string(err), info->kinsol_flag,
             m->K, m->G, m->c_p, m->c_r, m->phi_p, m->phi_r, m->psi_p, m->psi_r, m->eta,
             m->sigma_t, m->surface);
  /* eps and tau must belong together */
  const double tr = e[0] + e[1] + e[2];
  for (int a = 0; a < 3; ++a)
    TCLOSE(tau[a], m->K * tr + 2 * m->G * (e[a] - tr / 3), 1e-13 * (fabs(tau[a]) + m->c_p));
}

static void expect3(const char *what, const double got[3], const double want[3], double scale,
                    double rel) {
  for (int a = 0; a < 3; ++a)
    if (!(fabs(got[a] - want[a]) <= rel * scale))
      fail_msg("%s: tau = (%.17g, %.17g, %.17g), expected (%.17g, %.17g, %.17g): component %d "
               "off by %.3g (tolerance %.3g)",
               what, got[0], got[1], got[2], want[0], want[1], want[2], a,
               fabs(got[a] - want[a]), rel * scale);
}

static double absmax3(const double s[3]) { return fmax(fabs(s[0]), fmax(fabs(s[1]), fabs(s[2]))); }

/* the largest yield function of every surface at s (any order), the softened material at ep:
 * <= tol inside; = 0 on the surfaces a return is on */
static double fmax_all(const mpmc_mc_param *m, const double s[3], double ep) {
  double c, phi, psi;
  mpmc_mc_soften(m, ep, &c, &phi, &psi);
  double f = -INFINITY, apex = INFINITY;
  if (m->surface == MPMC_MC_MOHR_COULOMB) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j) f = fmax(f, (s[i] - s[j]) + (s[i] + s[j]) * sin(phi) - 2 * c * cos(phi));
    if (phi > 0) apex = c / tan(phi);
  } else {
    double eta, xi;
    const double sp = sin(phi), t = tan(phi);
    if (m->surface == MPMC_DP_COMPRESSION)
      eta = 6 * sp / (sqrt(3.0) * (3 - sp)), xi = 6 * cos(phi) / (sqrt(3.0) * (3 - sp));
    else if (m->surface == MPMC_DP_EXTENSION)
      eta = 6 * sp / (sqrt(3.0) * (3 + sp)), xi = 6 * cos(phi) / (sqrt(3.0) * (3 + sp));
    else
      eta = 3 * t / sqrt(9 + 12 * t * t), xi = 3 / sqrt(9 + 12 * t * t);
    const double p = (s[0] + s[1] + s[2]) / 3;
    const double j2 = ((s[0] - p) * (s[0] - p) + (s[1] - p) * (s[1] - p) + (s[2] - p) * (s[2] - p)) / 2;
    f = sqrt(j2) + eta * p - xi * c;
    if (eta > 0) apex = xi * c / eta;
  }
  const double st = fmin(m->sigma_t, apex);
  for (int a = 0; a < 3; ++a) f = fmax(f, s[a] - st);
  return f;
}

/* ---- every region of Mohr-Coulomb against its projection by hand (perfect plasticity) -- */
static void test_mc_regions(void **state) {
  (void)state;
  mpmc_mc_param m = base();
  const double K = m.K, G = m.G, L = K - 2 * G / 3, c = m.c_p;
  const double sf = sin(m.phi_p), cf = cos(m.phi_p), ss = sin(m.psi_p);
  /* de Souza Neto et al. 2008, box 8.5, rewritten for tension positive */
  const double a = 4 * G * (1 + sf * ss / 3) + 4 * K * sf * ss;
  const double b_comp = 2 * G * (1 - sf - ss - sf * ss / 3) + 4 * K * sf * ss;
  const double b_ext = 2 * G * (1 + sf + ss - sf * ss / 3) + 4 * K * sf * ss;
  double tau[3], ep;
  mpmc_mc_info info;
  for (int solver = 0; solver < 3; ++solver) {
    /* main plane: a general Lode angle */
    {
      const double s[3] = {-20e3, -60e3, -150e3};
      const double f = (s[0] - s[2]) + (s[0] + s[2]) * sf - 2 * c * cf, dg = f / a;
      const double want[3] = {s[0] - dg * (2 * G * (1 + ss) + 2 * L * ss), s[1] - dg * 2 * L * ss,
                              s[2] + dg * (2 * G * (1 - ss) - 2 * L * ss)};
      ep = 0;
      ret(&m, solver, s, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_PLANE);
      expect3("main plane", tau, want, absmax3(s), 1e-12);
      TCLOSE(ep, dg * 2.0 / 3.0 * sqrt(3 + ss * ss), 1e-12 * ep);
    }
    /* triaxial compression edge s1 = s2 (trial on that meridian) */
    {
      const double s[3] = {-50e3, -50e3, -250e3};
      const double fa = (s[0] - s[2]) + (s[0] + s[2]) * sf - 2 * c * cf;
      const double fb = (s[1] - s[2]) + (s[1] + s[2]) * sf - 2 * c * cf;
      const double det = a * a - b_comp * b_comp;
      const double da = (a * fa - b_comp * fb) / det, db = (a * fb - b_comp * fa) / det;
      const double want[3] = {
          s[0] - da * (2 * G * (1 + ss) + 2 * L * ss) - db * 2 * L * ss,
          s[1] - da * 2 * L * ss - db * (2 * G * (1 + ss) + 2 * L * ss),
          s[2] + (da + db) * (2 * G * (1 - ss) - 2 * L * ss)};
      ep = 0;
      ret(&m, solver, s, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_EDGE_COMPRESSION);
      expect3("compression edge", tau, want, absmax3(s), 1e-12);
      TCLOSE(tau[0], tau[1], 1e-12 * absmax3(s));
    }
    /* triaxial extension edge s2 = s3 */
    {
      const double s[3] = {0e3, -200e3, -200e3};
      const double fa = (s[0] - s[2]) + (s[0] + s[2]) * sf - 2 * c * cf;
      const double fc = (s[0] - s[1]) + (s[0] + s[1]) * sf - 2 * c * cf;
      const double det = a * a - b_ext * b_ext;
      const double da = (a * fa - b_ext * fc) / det, dc = (a * fc - b_ext * fa) / det;
      const double want[3] = {s[0] - (da + dc) * (2 * G * (1 + ss) + 2 * L * ss),
                              s[1] - da * 2 * L * ss + dc * (2 * G * (1 - ss) - 2 * L * ss),
                              s[2] + da * (2 * G * (1 - ss) - 2 * L * ss) - dc * 2 * L * ss};
      ep = 0;
      ret(&m, solver, s, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_EDGE_EXTENSION);
      expect3("extension edge", tau, want, absmax3(s), 1e-12);
    }
    /* apex: hydrostatic tension beyond c cot(phi) */
    {
      const double ap = c * cf / sf;
      const double s[3] = {3 * ap + 1e3, 3 * ap, 3 * ap - 2e3};
      const double want[3] = {ap, ap, ap};
      ep = 0;
      ret(&m, solver, s, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_APEX);
      expect3("apex", tau, want, absmax3(s), 1e-12);
      /* eps_p: sqrt(2/3) |dev eps_tr| */
      const double p = (s[0] + s[1] + s[2]) / 3, d0 = s[0] - p, d1 = s[1] - p, d2 = s[2] - p;
      TCLOSE(ep, sqrt(2.0 / 3) * sqrt(d0 * d0 + d1 * d1 + d2 * d2) / (2 * G), 1e-12 * ep);
    }
    /* tension cut-off plane, and its edge with the main plane */
    {
      mpmc_mc_param mt = m;
      mt.sigma_t = 5e3;
      const double s[3] = {-30e3, 20e3, -30e3}; /* any order */
      const double dg = (s[1] - mt.sigma_t) / (L + 2 * G);
      const double want[3] = {s[0] - L * dg, mt.sigma_t, s[2] - L * dg};
      ep = 0;
      ret(&mt, solver, s, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_TENSION);
      expect3("tension plane", tau, want, absmax3(s), 1e-12);
      TCLOSE(ep, dg * 2.0 / 3.0, 1e-12 * ep);
      /* s1 = sigma_t on the main plane: the 2x2 of the cut-off (T) and the main plane (A) */
      const double s2[3] = {50e3, -20e3, -70e3};
      const double fa = (s2[0] - s2[2]) + (s2[0] + s2[2]) * sf - 2 * c * cf, ft = s2[0] - mt.sigma_t;
      /* a_A . De N_T = (1 + sf)(L + 2G) - (1 - sf) L; a_T . De N_A = 2 L ss + 2G (1 + ss) */
      const double aat = (1 + sf) * (L + 2 * G) - (1 - sf) * L, ata = 2 * L * ss + 2 * G * (1 + ss);
      const double dt = ((L + 2 * G) * fa - aat * ft) / (a * (L + 2 * G) - aat * ata);
      const double dA = dt, dT = (ft - ata * dA) / (L + 2 * G);
      const double want2[3] = {s2[0] - dA * (2 * G * (1 + ss) + 2 * L * ss) - dT * (L + 2 * G),
                               s2[1] - dA * 2 * L * ss - dT * L,
                               s2[2] + dA * (2 * G * (1 - ss) - 2 * L * ss) - dT * L};
      ep = 0;
      ret(&mt, solver, s2, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_TENSION_EDGE);
      expect3("tension edge", tau, want2, absmax3(s2), 1e-12);
      /* hydrostatic corner below the apex */
      const double s3[3] = {40e3, 30e3, 35e3}, want3[3] = {5e3, 5e3, 5e3};
      ep = 0;
      ret(&mt, solver, s3, &ep, tau, &info);
      assert_int_equal(info.region, MPMC_MC_TENSION_CORNER);
      expect3("tension corner", tau, want3, absmax3(s3), 1e-12);
    }
  }
  /* elastic: nothing changes */
  const double s[3] = {-10e3, -20e3, -30e3};
  ep = 0.1;
  ret(&m, MPMC_SOLVER_AUTO, s, &ep, tau, &info);
  assert_int_equal(info.plastic, 0);
  expect3("elastic", tau, s, 30e3, 1e-14);
  TCLOSE(ep, 0.1, 0);
  /* bad input */
  double e[3], t[3], etr[3] = {NAN, 0, 0};
  ep = 0;
  assert_int_equal(mpmc_mc_return_principal(ws, 0, &m, etr, &ep, e, t, &info), MPMC_ERR_NUMERIC);
  etr[0] = INFINITY;
  assert_int_equal(mpmc_mc_return_principal(ws, 0, &m, etr, &ep, e, t, &info), MPMC_ERR_NUMERIC);
}

/* A random material (softening unless perfect) and a random plastic trial stress. */
static void random_case(mpmc_mc_param *m, double s[3], double *ep, int perfect, double eta_max) {
  const double E = loguni(1e6, 1e9), nu = 0.45 * urand();
  m->K = E / (3 * (1 - 2 * nu));
  m->G = E / (2 * (1 + nu));
  m->c_p = E * loguni(1e-5, 1e-3);
  m->c_r = m->c_p * (urand() < 0.2 ? 0.0 : loguni(0.05, 1.0));
  m->phi_p = (urand() < 0.1 ? 0.0 : loguni(10, 45)) * DEG;
  m->phi_r = m->phi_p * loguni(0.5, 1.0);
  m->psi_p = m->phi_p * (urand() < 0.3 ? 0.0 : urand());
  m->psi_r = fmin(m->psi_p, m->phi_r) * urand();
  m->eta = perfect ? 0.0 : loguni(0.5, eta_max);
  m->sigma_t = urand() < 0.5 ? INFINITY : m->c_p * loguni(0.01, 1.0);
  m->surface = (int)(4 * urand());
  if (m->phi_p == 0.0 && m->surface == MPMC_MC_MOHR_COULOMB && !isfinite(m->sigma_t))
    m->sigma_t = m->c_p; /* Tresca has no apex: a trial beyond every surface needs the cut-off */
  *ep = urand() < 0.3 ? 0.0 : loguni(1e-6, 0.5);
  /* a mean stress between -100 c and +2 c, a deviator up to 30 c */
  const double p = m->c_p * (urand() < 0.8 ? -loguni(0.01, 100.0) : 2 * urand());
  const double q = m->c_p * loguni(0.1, 30.0);
  double d[3] = {2 * urand() - 1, 2 * urand() - 1, 0};
  d[2] = -d[0] - d[1];
  const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int a = 0; a < 3; ++a) s[a] = p + q * d[a] / n;
}

/* ---- after a return, no surface is violated and one is active ------------------------ */
static void test_yield_after_return(void **state) {
  (void)state;
  int nplastic = 0, regions[8] = {0};
  for (int k = 0; k < 20000; ++k) {
    mpmc_mc_param m;
    double s[3], ep, tau[3];
    random_case(&m, s, &ep, k % 2, 50.0);
    mpmc_mc_info info;
    const double ep0 = ep;
    ret(&m, MPMC_SOLVER_AUTO, s, &ep, tau, &info);
    const double tol = 16 * mpmc_mc_tolerance(&m, s);
    const double f = fmax_all(&m, tau, ep);
    if (!(f <= tol) || (info.plastic && !(f >= -tol)))
      fail_msg("case %d (surface %d, region %d, plastic %d): max f after return %g, tolerance "
               "%g; trial (%g, %g, %g), returned (%g, %g, %g)",
               k, m.surface, info.region, info.plastic, f, tol, s[0], s[1], s[2], tau[0],
               tau[1], tau[2]);
    assert_true(ep >= ep0);
    nplastic += info.plastic;
    regions[info.region]++;
  }
  /* the random set reaches every region */
  for (int r = 1; r <= 7; ++r)
    if (regions[r] < 10) fail_msg("only %d returns to region %d", regions[r], r);
  assert_true(nplastic > 10000);
}

/* ---- Drucker-Prager: the matchings, the cone and the apex --------------------------- */
static int plastic_at(const mpmc_mc_param *m, const double s[3]) {
  double ep = 0, tau[3];
  mpmc_mc_info info;
  ret(m, MPMC_SOLVER_AUTO, s, &ep, tau, &info);
  return info.plastic;
}

static void test_dp(void **state) {
  (void)state;
  mpmc_mc_param m = base();
  const double c = m.c_p, phi = m.phi_p, sf = sin(phi), cf = cos(phi), p = -80e3;
  const double eps = 1e-7;
  /* compression cone = Mohr-Coulomb in triaxial compression (s1 = s2 > s3) */
  m.surface = MPMC_DP_COMPRESSION;
  const double qc = 6 * (c * cf - p * sf) / (3 - sf);
  for (int side = 0; side < 2; ++side) {
    const double q = qc * (side ? 1 + eps : 1 - eps);
    const double s[3] = {p + q / 3, p + q / 3, p - 2 * q / 3};
    assert_int_equal(plastic_at(&m, s), side);
  }
  /* extension cone = Mohr-Coulomb in triaxial extension (s1 > s2 = s3) */
  m.surface = MPMC_DP_EXTENSION;
  const double qe = 6 * (c * cf - p * sf) / (3 + sf);
  for (int side = 0; side < 2; ++side) {
    const double q = qe * (side ? 1 + eps : 1 - eps);
    const double s[3] = {p + 2 * q / 3, p - q / 3, p - q / 3};
    assert_int_equal(plastic_at(&m, s), side);
  }
  /* plane strain: at Mohr-Coulomb's in-plane failure t = c cos(phi) - s_m sin(phi), with the
   * out-of-plane stress at which associated flow has no out-of-plane plastic strain
   * (s2 - p = -2/3 eta sqrt(J2)), the matched cone is at yield */
  m.surface = MPMC_DP_PLANE_STRAIN;
  {
    const double t = tan(phi), etaf = 3 * t / sqrt(9 + 12 * t * t);
    const double sm = -80e3, tt = c * cf - sm * sf;
    const double rj = tt / sqrt(1 - etaf * etaf / 3), delta = -etaf * rj;
    for (int side = 0; side < 2; ++side) {
      const double k = side ? 1 + eps : 1 - eps; /* scale the in-plane radius */
      const double s[3] = {sm + k * tt, sm + delta, sm - k * tt};
      assert_int_equal(plastic_at(&m, s), side);
    }
  }
  /* the cone's return (perfect): dgamma = f / (G + K eta etab), radial in the deviator */
  for (int surf = MPMC_DP_COMPRESSION; surf <= MPMC_DP_PLANE_STRAIN; ++surf) {
    m.surface = surf;
    double eta, xi, etab;
    const double ss = sin(m.psi_p), tp = tan(m.psi_p), t = tan(phi);
    if (surf == MPMC_DP_COMPRESSION)
      eta = 6 * sf / (sqrt(3.0) * (3 - sf)), xi = 6 * cf / (sqrt(3.0) * (3 - sf)),
      etab = 6 * ss / (sqrt(3.0) * (3 - ss));
    else if (surf == MPMC_DP_EXTENSION)
      eta = 6 * sf / (sqrt(3.0) * (3 + sf)), xi = 6 * cf / (sqrt(3.0) * (3 + sf)),
      etab = 6 * ss / (sqrt(3.0) * (3 + ss));
    else
      eta = 3 * t / sqrt(9 + 12 * t * t), xi = 3 / sqrt(9 + 12 * t * t),
      etab = 3 * tp / sqrt(9 + 12 * tp * tp);
    const double s[3] = {-10e3, -90e3, -300e3}, pt = (s[0] + s[1] + s[2]) / 3;
    double dv[3], rj = 0;
    for (int a = 0; a < 3; ++a) dv[a] = s[a] - pt, rj += dv[a] * dv[a] / 2;
    rj = sqrt(rj);
    const double dg = (rj + eta * pt - xi * c) / (m.G + m.K * eta * etab);
    double want[3];
    for (int a = 0; a < 3; ++a) want[a] = pt - m.K * etab * dg + dv[a] * (1 - m.G * dg / rj);
    double ep = 0, tau[3];
    mpmc_mc_info info;
    ret(&m, MPMC_SOLVER_AUTO, s, &ep, tau, &info);
    assert_int_equal(info.region, MPMC_MC_PLANE);
    expect3("Drucker-Prager cone", tau, want, 300e3, 1e-12);
    TCLOSE(ep, dg / sqrt(3.0), 1e-12 * ep);
    /* the apex xi c / eta */
    const double ap = xi * c / eta, s2[3] = {4 * ap + 3e3, 4 * ap, 4 * ap - 1e3};
    const double want2[3] = {ap, ap, ap};
    ep = 0;
    ret(&m, MPMC_SOLVER_AUTO, s2, &ep, tau, &info);
    assert_int_equal(info.region, MPMC_MC_APEX);
    expect3("Drucker-Prager apex", tau, want2, 4 * ap, 1e-12);
    /* and a cut-off below it */
    mpmc_mc_param mt = m;
    mt.sigma_t = 0.25 * ap;
    const double s3[3] = {0.5 * ap, -0.5 * ap, -0.6 * ap};
    const double dgt = (s3[0] - mt.sigma_t) / (m.K + 4 * m.G / 3), L = m.K - 2 * m.G / 3;
    const double want3[3] = {mt.sigma_t, s3[1] - L * dgt, s3[2] - L * dgt};
    ep = 0;
    ret(&mt, MPMC_SOLVER_AUTO, s3, &ep, tau, &info);
    assert_int_equal(info.region, MPMC_MC_TENSION);
    expect3("Drucker-Prager cut-off", tau, want3, ap, 1e-12);
  }
}

/* ---- newton, kinsol and auto agree with softening ------------------------------------ */
static void compare_solvers(int ncase, double eta_max, int *nfb_out, int *nstates) {
  int nfb = 0, n = 0;
  for (int k = 0; k < ncase; ++k) {
    mpmc_mc_param m;
    double s[3], ep0;
    random_case(&m, s, &ep0, 0, eta_max);
    double tau[3][3], ep[3];
    mpmc_mc_info info[3];
    for (int sv = 0; sv < 3; ++sv) {
      ep[sv] = ep0;
      ret(&m, sv, s, &ep[sv], tau[sv], &info[sv]);
    }
    const int N = MPMC_SOLVER_NEWTON, A = MPMC_SOLVER_AUTO;
    if (!info[N].plastic) continue;
    ++n;
    const double scale = absmax3(s) + m.c_p;
    for (int sv = 0; sv < 3; ++sv) {
      const double dt = fmax(fabs(tau[sv][0] - tau[N][0]),
                             fmax(fabs(tau[sv][1] - tau[N][1]), fabs(tau[sv][2] - tau[N][2])));
      const double dep = fabs(ep[sv] - ep[N]);
      if (!(dt <= 1e-10 * scale) || !(dep <= 1e-10 * (ep[N] - ep0 + scale / m.G)) ||
          info[sv].region != info[N].region)
        fail_msg("case %d (surface %d, eta %g): newton region %d tau (%.17g, %.17g, %.17g) "
                 "eps_p %.17g; solver %d region %d tau (%.17g, %.17g, %.17g) eps_p %.17g",
                 k, m.surface, m.eta, info[N].region, tau[N][0], tau[N][1], tau[N][2], ep[N], sv,
                 info[sv].region, tau[sv][0], tau[sv][1], tau[sv][2], ep[sv]);
    }
    assert_int_equal(info[N].fallback, 0);
    nfb += info[A].fallback;
  }
  *nfb_out = nfb;
  *nstates = n;
}

static void test_solvers_agree(void **state) {
  (void)state;
  int nfb, n;
  compare_solvers(10000, 50.0, &nfb, &n);
  if (n < 5000) fail_msg("only %d plastic states of 10^4", n);
}

/* Steep softening: eta (c_p - c_r) far beyond the elastic stiffness of the return (~G), so
 * that the local residual is not monotone: auto hands points to KINSOL and still agrees. */
static void test_steep_softening(void **state) {
  (void)state;
  mpmc_mc_param m = base();
  m.c_r = 1e3;
  m.phi_r = 20 * DEG;
  m.psi_r = 0;
  m.eta = 5000; /* eta (c_p - c_r) = 9.5e7 > sqrt(3) G = 3.3e7 */
  int nfb = 0;
  for (int k = 0; k < 300; ++k) {
    const double p = -loguni(1e3, 3e5), q = m.c_p * loguni(2.0, 40.0);
    double d[3] = {2 * urand() - 1, 2 * urand() - 1, 0};
    d[2] = -d[0] - d[1];
    const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double s[3], tau[3][3], ep[3];
    for (int a = 0; a < 3; ++a) s[a] = p + q * d[a] / n;
    const double ep0 = urand() < 0.5 ? 0 : loguni(1e-7, 1e-4);
    mpmc_mc_info info[3];
    for (int sv = 0; sv < 3; ++sv) {
      ep[sv] = ep0;
      ret(&m, sv, s, &ep[sv], tau[sv], &info[sv]);
      const double f = fmax_all(&m, tau[sv], ep[sv]);
      if (info[sv].plastic && !(fabs(f) <= 16 * mpmc_mc_tolerance(&m, s)))
        fail_msg("steep case %d solver %d: max f after return %g", k, sv, f);
    }
    for (int sv = 0; sv < 3; ++sv)
      for (int a = 0; a < 3; ++a)
        if (!(fabs(tau[sv][a] - tau[MPMC_SOLVER_KINSOL][a]) <= 1e-10 * (absmax3(s) + m.c_p)))
          fail_msg("steep case %d: solver %d tau[%d] %.17g, kinsol %.17g", k, sv, a, tau[sv][a],
                   tau[MPMC_SOLVER_KINSOL][a]);
    nfb += info[MPMC_SOLVER_AUTO].fallback;
  }
  if (nfb == 0) fail_msg("steep softening: auto never fell back to KINSOL");
}

/* ---- tensor level: principal directions kept, objectivity ---------------------------- */
static void test_objectivity(void **state) {
  (void)state;
  for (int k = 0; k < 2000; ++k) {
    mpmc_mc_param m;
    double s[3], ep0;
    random_case(&m, s, &ep0, k % 2, 50.0);
    double e[3], lam[3], R[3][3], Q[3][3], be[6], beR[6], tau[6], tauR[6], J, JR;
    strain_of(&m, s, e);
    for (int a = 0; a < 3; ++a) lam[a] = exp(2 * e[a]);
    rand_rotation(Q);
    mpmc_sym3_compose(lam, Q, be);
    rand_rotation(R);
    double B[3][3], T[3][3] = {{0}}, BR[3][3] = {{0}};
    mpmc_voigt_to_mat(be, B);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int l = 0; l < 3; ++l)
          for (int n = 0; n < 3; ++n) BR[i][j] += R[i][l] * B[l][n] * R[j][n];
    mpmc_mat_to_voigt(BR, beR);
    double ep = ep0, epR = ep0;
    mpmc_mc_info info;
    assert_int_equal(mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, &m, NULL, be, &ep, tau, &J, &info), 0);
    assert_int_equal(mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, &m, NULL, beR, &epR, tauR, &JR, &info), 0);
    const double sc = absmax3(s) + m.c_p;
    /* round-off of the eigen path: ~eps in b_e's eigenvalues, K eps in the stress */
    const double rt = 64 * DBL_EPSILON * (m.K + m.G);
    /* tau and b_e commute (same principal directions) */
    double tb[6], bt[6], Tm[3][3], Bm[3][3];
    mpmc_voigt_to_mat(tau, Tm);
    mpmc_voigt_to_mat(be, Bm);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double x = 0, y = 0;
        for (int l = 0; l < 3; ++l) x += Tm[i][l] * Bm[l][j], y += Bm[i][l] * Tm[l][j];
        if (!(fabs(x - y) <= 20 * (1e-11 * sc + rt))) /* |b_e| <~ 20 */
          fail_msg("case %d: tau b_e - b_e tau [%d][%d] = %g", k, i, j, x - y);
      }
    (void)tb;
    (void)bt;
    /* tau(R b R^T) = R tau(b) R^T */
    mpmc_voigt_to_mat(tau, T);
    double RT[3][3] = {{0}}, want[6];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int l = 0; l < 3; ++l)
          for (int n = 0; n < 3; ++n) RT[i][j] += R[i][l] * T[l][n] * R[j][n];
    mpmc_mat_to_voigt(RT, want);
    for (int c = 0; c < 6; ++c)
      if (!(fabs(tauR[c] - want[c]) <= 1e-10 * sc + rt))
        fail_msg("case %d: tau(R b R^T)[%d] = %.17g, R tau R^T = %.17g (scale %g, region %d, "
                 "surface %d, eta %g)", k, c, tauR[c], want[c], sc, info.region, m.surface, m.eta);
    TCLOSE(epR, ep, 1e-10 * (ep + sc / m.G) + rt / m.G);
    TCLOSE(JR, J, 1e-12 * J);
  }
}

/* ---- the elastic check without eigenvectors (mpmc_mc_update) against the eigen path ---- */
static void test_fast_vs_eig(void **state) {
  (void)state;
  int nel = 0, npl = 0;
  for (int k = 0; k < 6000; ++k) {
    mpmc_mc_param m;
    double s[3], ep0;
    random_case(&m, s, &ep0, k % 3 == 0, 50.0);
    if (k % 2) /* towards the hydrostatic axis below the apex: mostly elastic */
      for (int a = 0; a < 3; ++a) s[a] = -m.c_p + 0.1 * (s[a] + m.c_p);
    double e[3], lam[3], Q[3][3], be[6], be2[6], tau[6], tau2[6], J, J2, F[3][3];
    strain_of(&m, s, e);
    for (int a = 0; a < 3; ++a) lam[a] = exp(2 * e[a]);
    rand_rotation(Q);
    mpmc_sym3_compose(lam, Q, be);
    memcpy(be2, be, sizeof be);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F[i][j] = (i == j) + 1e-4 * (2 * urand() - 1);
    double ep = ep0, ep2 = ep0;
    mpmc_mc_info info, info2;
    const int err = mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, &m, F, be, &ep, tau, &J, &info);
    const int err2 = mpmc_mc_return_map_eig(ws, MPMC_SOLVER_AUTO, &m, F, be2, &ep2, tau2, &J2, &info2);
    if (err != err2) fail_msg("case %d: error %d, eigen path %d", k, err, err2);
    if (err) continue;
    if (info.plastic != info2.plastic || info.region != info2.region)
      fail_msg("case %d: plastic %d region %d, eigen path plastic %d region %d", k, info.plastic,
               info.region, info2.plastic, info2.region);
    const double sc = absmax3(s) + m.c_p, rt = 64 * DBL_EPSILON * (m.K + m.G);
    for (int c = 0; c < 6; ++c) {
      if (!(fabs(tau[c] - tau2[c]) <= 1e-12 * sc + rt))
        fail_msg("case %d (plastic %d): tau[%d] = %.17g, eigen path %.17g", k, info.plastic, c,
                 tau[c], tau2[c]);
      if (!(fabs(be[c] - be2[c]) <= 64 * DBL_EPSILON * (1 + fabs(be2[c]))))
        fail_msg("case %d (plastic %d): b_e[%d] = %.17g, eigen path %.17g", k, info.plastic, c,
                 be[c], be2[c]);
    }
    TCLOSE(ep, ep2, 1e-12 * (ep2 + sc / m.G) + rt / m.G);
    TCLOSE(J, J2, 1e-14 * J2);
    nel += !info.plastic;
    npl += info.plastic;
  }
  if (nel < 1500 || npl < 1500) fail_msg("only %d elastic and %d plastic cases", nel, npl);
}

/* ---- four points at once (mpmc_mc_update4) against mpmc_mc_update per point ------------ */
/* the same results (== : the sign of a zero may differ), errors, regions and statistics, on
 * blocks of mixed points: elastic and plastic, softening and perfect, every surface, strains
 * beyond the series, diagonal and plane-strain b_e (the closed form's special cases and
 * zero shear components), a negative eps_p (an error) and partial blocks */
static void test_blocks(void **state) {
  (void)state;
  int nel = 0, npl = 0, nbig = 0;
  for (int k = 0; k < 3000; ++k) {
    mpmc_mc_param m;
    double s0[3], ep0;
    random_case(&m, s0, &ep0, k % 3 == 0, 50.0);
    mpmc_mc_pre pre;
    mpmc_mc_prepare(&m, &pre);
    const int n = k % 7 == 6 ? 1 + k % 3 : 4;
    double F[4][3][3], be[4][6], be1[4][6], ep[4], ep1[4], tau[4][6], tau1[4][6], J[4], J1[4];
    mpmc_mc_info info[4], info1[4];
    int err[4];
    for (int l = 0; l < n; ++l) {
      double s[3], e[3], lam[3], Q[3][3];
      const double p = m.c_p * (urand() < 0.8 ? -loguni(0.01, 100.0) : 2 * urand());
      const double q = m.c_p * loguni(0.1, 30.0);
      double d[3] = {2 * urand() - 1, 2 * urand() - 1, 0};
      d[2] = -d[0] - d[1];
      const double nd = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int a = 0; a < 3; ++a) s[a] = l == 0 ? s0[a] : p + q * d[a] / nd;
      if ((k + l) % 2) /* towards the hydrostatic axis below the apex: mostly elastic */
        for (int a = 0; a < 3; ++a) s[a] = -m.c_p + 0.1 * (s[a] + m.c_p);
      strain_of(&m, s, e);
      const int kind = (int)(10 * urand());
      if (kind == 0) /* beyond the series: the Jacobi path */
        for (int a = 0; a < 3; ++a) e[a] += 0.2 * (a - 1.0);
      for (int a = 0; a < 3; ++a) lam[a] = exp(2 * e[a]);
      rand_rotation(Q);
      if (kind == 1 || kind == 2) /* diagonal, or a rotation in the x-y plane */
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (kind == 1 || i == 2 || j == 2) Q[i][j] = (i == j);
      mpmc_sym3_compose(lam, Q, be[l]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          F[l][i][j] = (i == j) + (kind == 1 || (kind == 2 && (i == 2 || j == 2))
                                        ? 0.0 : 1e-4 * (2 * urand() - 1));
      ep[l] = l == 0 ? ep0 : urand() < 0.3 ? 0.0 : loguni(1e-6, 0.5);
      if (kind == 3 && urand() < 0.1) ep[l] = -1.0;
      nbig += kind == 0;
    }
    memcpy(be1, be, sizeof be);
    memcpy(ep1, ep, sizeof ep);
    /* the baseline build, or its AVX2 build where there is one (odd blocks) */
    const mpmc_mc_update4_fn update4 =
        k % 2 ? mpmc_mc_update4_for(MPMC_KERNELS_AVX2) : mpmc_mc_update4;
    update4(ws, MPMC_SOLVER_AUTO, &pre, n, F, be, ep, tau, J, info, err);
    for (int l = 0; l < n; ++l) {
      const int err1 = mpmc_mc_update(ws, MPMC_SOLVER_AUTO, &pre, F[l], be1[l], &ep1[l], tau1[l],
                                      &J1[l], &info1[l]);
      if (err[l] != err1) fail_msg("block %d lane %d: error %d, point update %d", k, l, err[l], err1);
      if (err1) continue;
      if (info[l].plastic != info1[l].plastic || info[l].region != info1[l].region ||
          info[l].fallback != info1[l].fallback || info[l].newton_iters != info1[l].newton_iters)
        fail_msg("block %d lane %d: plastic %d region %d, point update plastic %d region %d", k,
                 l, info[l].plastic, info[l].region, info1[l].plastic, info1[l].region);
      for (int c = 0; c < 6; ++c)
        if (!(tau[l][c] == tau1[l][c] && be[l][c] == be1[l][c]))
          fail_msg("block %d lane %d (plastic %d): tau[%d] = %.17g, b_e = %.17g; point update "
                   "%.17g, %.17g", k, l, info1[l].plastic, c, tau[l][c], be[l][c], tau1[l][c],
                   be1[l][c]);
      if (!(ep[l] == ep1[l] && J[l] == J1[l]))
        fail_msg("block %d lane %d: eps_p %.17g J %.17g, point update %.17g %.17g", k, l, ep[l],
                 J[l], ep1[l], J1[l]);
      nel += !info1[l].plastic;
      npl += info1[l].plastic;
    }
  }
  if (nel < 2000 || npl < 2000 || nbig < 500)
    fail_msg("only %d elastic, %d plastic, %d large-strain points", nel, npl, nbig);
}

/* ---- strength reduction ------------------------------------------------------------- */
static void test_reduce(void **state) {
  (void)state;
  mpmc_mc_param m = base();
  m.c_r = 5e3;
  m.phi_r = 25 * DEG;
  m.psi_r = 0;
  m.sigma_t = 8e3;
  mpmc_mc_param r = m;
  mpmc_mc_reduce(&r, 1.5);
  TCLOSE(r.c_p, 20e3 / 1.5, 1e-12 * 20e3);
  TCLOSE(r.c_r, 5e3 / 1.5, 1e-12 * 5e3);
  TCLOSE(tan(r.phi_p), tan(30 * DEG) / 1.5, 1e-14);
  TCLOSE(tan(r.phi_r), tan(25 * DEG) / 1.5, 1e-14);
  TCLOSE(tan(r.psi_p), tan(10 * DEG) / 1.5, 1e-14);
  TCLOSE(r.psi_r, 0.0, 0.0);
  TCLOSE(r.sigma_t, 8e3 / 1.5, 1e-12 * 8e3);
  assert_true(r.K == m.K && r.G == m.G && r.eta == m.eta && r.surface == m.surface);
  mpmc_mc_param inf = base();
  mpmc_mc_reduce(&inf, 2.0);
  assert_true(isinf(inf.sigma_t));
  /* factor 1 changes nothing */
  r = m;
  mpmc_mc_reduce(&r, 1.0);
  TCLOSE(r.phi_p, m.phi_p, 1e-15);
}

/* ---- element tests at the tensor level ----------------------------------------------- */
typedef struct {
  double be[6], ep;
} pstate;

/* one step of the diagonal stretch (1 + da, 1 + x, 1 + x) from st; lateral Kirchhoff stress */
static double tri_step(const mpmc_mc_param *m, const pstate *st, double da, double x, pstate *out,
                       double tau[6], mpmc_mc_info *info) {
  double F[3][3] = {{1 + da, 0, 0}, {0, 1 + x, 0}, {0, 0, 1 + x}}, J;
  *out = *st;
  const int err = mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, m, F, out->be, &out->ep, tau, &J, info);
  if (err) fail_msg("triaxial step: error %d", err);
  return tau[1];
}

/* Drained triaxial compression: confining Kirchhoff stress s_c held on y, z; axial
 * compression along x by 1e-4 steps.  Peak q = s_lat - s_ax from Mohr-Coulomb in triaxial
 * compression, q = 2 (c cos phi - s_c sin phi) / (1 - sin phi), then softening to c_r, phi_r. */
static void test_triaxial(void **state) {
  (void)state;
  mpmc_mc_param m = base();
  m.c_r = 2e3;
  m.phi_r = 22 * DEG;
  m.psi_p = 5 * DEG;
  m.psi_r = 0;
  m.eta = 60;
  const double sc = -100e3;
  pstate st = {{0}, 0};
  for (int a = 0; a < 3; ++a) st.be[a] = exp(2 * sc / (3 * m.K));
  const double qpk = 2 * (m.c_p * cos(m.phi_p) - sc * sin(m.phi_p)) / (1 - sin(m.phi_p));
  const double qres = 2 * (m.c_r * cos(m.phi_r) - sc * sin(m.phi_r)) / (1 - sin(m.phi_r));
  double qmax = 0, q = 0, x = 0;
  for (int step = 0; step < 1500; ++step) {
    pstate nx;
    double tau[6];
    mpmc_mc_info info;
    /* secant on the lateral strain for tau_yy = s_c */
    double x0 = x, g0 = tri_step(&m, &st, -1e-4, x0, &nx, tau, &info) - sc;
    double x1 = x0 + 1e-5, g1 = tri_step(&m, &st, -1e-4, x1, &nx, tau, &info) - sc;
    for (int it = 0; it < 40 && fabs(g1) > 1e-9 * fabs(sc); ++it) {
      const double x2 = x1 - g1 * (x1 - x0) / (g1 - g0);
      x0 = x1, g0 = g1, x1 = x2;
      g1 = tri_step(&m, &st, -1e-4, x1, &nx, tau, &info) - sc;
    }
    if (!(fabs(g1) <= 1e-9 * fabs(sc))) fail_msg("step %d: lateral stress not held (%g)", step, g1);
    TCLOSE(tau[2], sc, 1e-8 * fabs(sc));
    x = x1;
    st = nx;
    q = tau[1] - tau[0];
    qmax = fmax(qmax, q);
  }
  if (!(fabs(qmax - qpk) <= 5e-3 * qpk))
    fail_msg("triaxial peak q = %.6g, Mohr-Coulomb %.6g", qmax, qpk);
  if (!(fabs(q - qres) <= 5e-3 * qres))
    fail_msg("triaxial residual q = %.6g (eps_p %.3g), Mohr-Coulomb %.6g", q, st.ep, qres);
}

/* one plane-strain step (1 + da, 1 + x, 1) from st; lateral Kirchhoff stress tau_yy */
static double bx_step(const mpmc_mc_param *m, const pstate *st, double da, double x, pstate *out,
                      double tau[6], mpmc_mc_info *info) {
  double F[3][3] = {{1 + da, 0, 0}, {0, 1 + x, 0}, {0, 0, 1}}, J;
  *out = *st;
  const int err = mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, m, F, out->be, &out->ep, tau, &J, info);
  if (err) fail_msg("biaxial step: error %d", err);
  return tau[1];
}

/* Plane-strain biaxial compression: stretch (1 + da, 1 + x, 1) per step, eps_zz = 0 held,
 * confining Kirchhoff stress s_c < 0 held on y by the lateral stretch x, axial compression
 * along x by 1e-4 steps.
 * Peak (tension positive, s1 >= s2 >= s3): x is the most compressive, s3 = tau_xx, and the
 * confinement the least, s1 = tau_yy = s_c; the out-of-plane tau_zz is the intermediate one
 * (elastically it moves by lambda d(eps_xx + eps_yy), between the two; plastically the flow
 * N = (1 + sin psi, 0, -(1 - sin psi)) of the main plane has no zz part, associated or not,
 * so eps_zz = 0 needs no change of it), checked below.  Mohr-Coulomb's main plane then
 * holds alone: (s1 - s3) + (s1 + s3) sin phi = 2 c cos phi with s1 = s_c, q = s1 - s3:
 *   q + (2 s_c - q) sin phi = 2 c cos phi  =>  q = 2 (c cos phi - s_c sin phi) / (1 - sin phi),
 * i.e. with the compression-positive confinement s3' = -s_c:
 *   q = 2 c cos phi / (1 - sin phi) + 2 s3' sin phi / (1 - sin phi);
 * the same with c_r, phi_r for the residual.  The intermediate stress plays no part, so the
 * peak equals triaxial compression's at the same confinement. */
static void test_biaxial(void **state) {
  (void)state;
  mpmc_mc_param m = base();
  m.c_r = 2e3;
  m.phi_r = 22 * DEG;
  m.psi_p = 5 * DEG;
  m.psi_r = 0;
  m.eta = 60;
  const double sc = -100e3;
  pstate st = {{0}, 0};
  for (int a = 0; a < 3; ++a) st.be[a] = exp(2 * sc / (3 * m.K));
  const double sp = sin(m.phi_p), sr = sin(m.phi_r);
  const double qpk = 2 * m.c_p * cos(m.phi_p) / (1 - sp) + 2 * -sc * sp / (1 - sp);
  const double qres = 2 * m.c_r * cos(m.phi_r) / (1 - sr) + 2 * -sc * sr / (1 - sr);
  double qmax = 0, q = 0, x = 0, tau[6];
  int nplane = 0;
  for (int step = 0; step < 1500; ++step) {
    pstate nx;
    mpmc_mc_info info;
    /* secant on the lateral stretch for tau_yy = s_c; F_zz = 1 keeps eps_zz = 0 */
    double x0 = x, g0 = bx_step(&m, &st, -1e-4, x0, &nx, tau, &info) - sc;
    double x1 = x0 + 1e-5, g1 = bx_step(&m, &st, -1e-4, x1, &nx, tau, &info) - sc;
    for (int it = 0; it < 40 && fabs(g1) > 1e-9 * fabs(sc); ++it) {
      const double x2 = x1 - g1 * (x1 - x0) / (g1 - g0);
      x0 = x1, g0 = g1, x1 = x2;
      g1 = bx_step(&m, &st, -1e-4, x1, &nx, tau, &info) - sc;
    }
    if (!(fabs(g1) <= 1e-9 * fabs(sc))) fail_msg("step %d: lateral stress not held (%g)", step, g1);
    /* tau_zz between tau_xx and tau_yy: the out-of-plane stress is the intermediate one */
    if (!(tau[2] <= tau[1] + 1e-9 * fabs(sc) && tau[2] >= tau[0] - 1e-9 * fabs(sc)))
      fail_msg("step %d: tau_zz = %.6g not between tau_xx = %.6g and tau_yy = %.6g", step, tau[2],
               tau[0], tau[1]);
    nplane += info.plastic && info.region == MPMC_MC_PLANE;
    x = x1;
    st = nx;
    q = tau[1] - tau[0];
    qmax = fmax(qmax, q);
  }
  if (nplane < 1000) fail_msg("biaxial: only %d plastic steps on the main plane", nplane);
  if (!(fabs(qmax - qpk) <= 5e-3 * qpk))
    fail_msg("biaxial peak q = %.6g, Mohr-Coulomb %.6g", qmax, qpk);
  if (!(fabs(q - qres) <= 5e-3 * qres))
    fail_msg("biaxial residual q = %.6g (eps_p %.3g), Mohr-Coulomb %.6g", q, st.ep, qres);
}

/* Simple shear (det F = 1) from a confining state: the plastic volumetric log strain
 * ln J_p = ln det F - tr(eps_e) = tr(eps_e0) - tr(eps_e) stays 0 with psi = 0, and with
 * psi > 0 grows at d(ln J_p) / d eps_p = 3 sin(psi) / sqrt(3 + sin^2 psi) on the main plane
 * (tr N / (sqrt(2/3) |dev N|), N = (1 + sin psi, 0, -(1 - sin psi))). */
static void test_simple_shear(void **state) {
  (void)state;
  for (int dil = 0; dil < 2; ++dil) {
    mpmc_mc_param m = base();
    m.psi_p = m.psi_r = dil ? 15 * DEG : 0.0;
    const double sc = -100e3;
    pstate st = {{0}, 0};
    for (int a = 0; a < 3; ++a) st.be[a] = exp(2 * sc / (3 * m.K));
    const double tr0 = sc / m.K; /* tr(eps_e0) */
    double dv = 0, dep = 0;
    int nplane = 0;
    for (int step = 0; step < 400; ++step) {
      double F[3][3] = {{1, 2e-4, 0}, {0, 1, 0}, {0, 0, 1}}, tau[6], J;
      mpmc_mc_info info;
      const double ep0 = st.ep, lnJ0 = log(sqrt(mpmc_det_sym(st.be)));
      assert_int_equal(mpmc_mc_return_map(ws, MPMC_SOLVER_AUTO, &m, F, st.be, &st.ep, tau, &J, &info), 0);
      if (info.plastic && info.region == MPMC_MC_PLANE) {
        dv += lnJ0 - log(J); /* this step's plastic volumetric strain (det F = 1) */
        dep += st.ep - ep0;
        ++nplane;
      }
      if (!dil) TCLOSE(log(J), tr0, 1e-10);
    }
    if (nplane < 100) fail_msg("psi %d: only %d plastic steps on the main plane", dil, nplane);
    const double s = sin(m.psi_p), want = 3 * s / sqrt(3 + s * s) * dep;
    if (!(fabs(dv - want) <= 1e-8 * (fabs(want) + dep)))
      fail_msg("psi = %g deg: plastic volumetric strain %.12g over eps_p %.6g, expected %.12g",
               m.psi_p / DEG, dv, dep, want);
    if (dil) assert_true(dv > 1e-3);
  }
}

static int setup(void **state) {
  (void)state;
  return mpmc_rm_ws_create(&ws);
}
static int teardown(void **state) {
  (void)state;
  mpmc_rm_ws_destroy(&ws);
  return 0;
}

/* ---- without sigma_t the regions with the cut-off are not tried (return_mc.c,
 * tension_regions): the same returns as with a cut-off far above the apex, which caps it
 * there and tries them all -- Mohr-Coulomb, and Drucker-Prager where 2 eta_f / sqrt3 < 1 */
static void test_apex_cap(void **state) {
  (void)state;
  int napex = 0;
  for (int k = 0; k < 4000; ++k) {
    mpmc_mc_param m;
    double s[3], ep0;
    random_case(&m, s, &ep0, k % 3 == 0, 50.0);
    m.sigma_t = INFINITY;
    if (m.phi_p == 0.0 || m.phi_r == 0.0) continue; /* no apex */
    if (m.surface != MPMC_MC_MOHR_COULOMB) {
      m.surface = MPMC_DP_COMPRESSION + k % 3;
      const double sf = sin(fmax(m.phi_p, m.phi_r));
      const double eta = m.surface == MPMC_DP_PLANE_STRAIN
                             ? 3 * tan(asin(sf)) / sqrt(9 + 12 * tan(asin(sf)) * tan(asin(sf)))
                             : 6 * sf / (sqrt(3.0) * (m.surface == MPMC_DP_COMPRESSION ? 3 - sf : 3 + sf));
      if (!(2 * eta < sqrt(3.0) * 0.99)) continue;
    }
    if (k % 2) /* towards the apex and beyond */
      for (int a = 0; a < 3; ++a) s[a] = m.c_p * (1 + 4 * urand()) + 0.2 * (s[a] - s[0]);
    mpmc_mc_param mc = m; /* above every apex c cot(phi) of the softened material */
    mc.sigma_t = 2 * m.c_p / tan(fmin(m.phi_p, m.phi_r));
    double ep = ep0, ep2 = ep0, t[3], t2[3];
    mpmc_mc_info info, info2;
    ret(&m, MPMC_SOLVER_AUTO, s, &ep, t, &info);
    ret(&mc, MPMC_SOLVER_AUTO, s, &ep2, t2, &info2);
    if (info.region != info2.region)
      fail_msg("case %d (surface %d): region %d, with the cut-off %d", k, m.surface, info.region,
               info2.region);
    const double sc = absmax3(s) + mc.sigma_t; /* the tolerances' scale (mpmc_mc_tolerance) */
    expect3("stress", t, t2, sc, 1e-11);
    TCLOSE(ep, ep2, 1e-11 * (ep2 + sc / m.G));
    napex += info.region == MPMC_MC_APEX;
  }
  if (napex < 100) fail_msg("only %d apex returns", napex);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_mc_regions),       cmocka_unit_test(test_yield_after_return),
      cmocka_unit_test(test_dp),               cmocka_unit_test(test_solvers_agree),
      cmocka_unit_test(test_steep_softening),  cmocka_unit_test(test_objectivity),
      cmocka_unit_test(test_reduce),           cmocka_unit_test(test_triaxial),
      cmocka_unit_test(test_simple_shear),     cmocka_unit_test(test_fast_vs_eig),
      cmocka_unit_test(test_biaxial),          cmocka_unit_test(test_apex_cap),
      cmocka_unit_test(test_blocks),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
