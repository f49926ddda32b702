/* The stiff/extreme return-map table (issue 3), shared by t403-j2-stiff-cases (which checks
 * every case) and bench/bench_return_map --stability (which prints the table of
 * docs/stability.md): eta x nu x trial states.  Landslide strengths (kappa_p = 40.82 kPa,
 * kappa_r = 2.45 kPa), E = 25 MPa.  Trial states: pure-shear log strains giving
 * q_trial / kappa = 1.001, 10, 100, 1e4 at eps_p = 0 and 0.5, and 50 % increments (simple
 * shear 0.5, stretch 1.5, compression 0.5) from the natural state. */
#ifndef MPMC_J2_CASES_H
#define MPMC_J2_CASES_H

#include <math.h>

#include "return_map.h"

static const double tbl_eta[4] = {5, 50, 500, 5000};
static const double tbl_nu[4] = {0.3, 0.49, 0.499, 0.4999};
#define TBL_NCASE 14

static inline void tbl_material(int ie, int in, mpmc_j2_param *m) {
  const double E = 25e6, nu = tbl_nu[in];
  m->K = E / (3 * (1 - 2 * nu));
  m->G = E / (2 * (1 + nu));
  m->kappa_p = 40.82e3;
  m->kappa_r = 2.45e3;
  m->eta = tbl_eta[ie];
}

/* case c: be (Voigt), eps_p, F (3x3) and a label */
static inline const char *tbl_case(const mpmc_j2_param *m, int c, double *be, double *ep,
                                   double F[3][3]) {
  static const double ratio[4] = {1.001, 10, 100, 1e4};
  static const char *labels[TBL_NCASE] = {
      "q/k=1.001", "q/k=10", "q/k=100", "q/k=1e4", "q/k=1.001 ep=.5", "q/k=10 ep=.5",
      "q/k=100 ep=.5", "q/k=1e4 ep=.5", "shear 0.5", "stretch 1.5", "compress 0.5",
      "shear 0.5 ep=.5", "stretch 1.5 ep=.5", "compress 0.5 ep=.5"};
  for (int k = 0; k < 6; ++k) be[k] = k < 3;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) F[i][j] = i == j;
  *ep = (c >= 4 && c < 8) || c >= 11 ? 0.5 : 0.0;
  if (c < 8) {
    const double kap = m->kappa_r + (m->kappa_p - m->kappa_r) * exp(-m->eta * *ep);
    /* dev log strain (a, -a, 0): q = 2 sqrt(3) G a */
    const double a = ratio[c % 4] * kap / (2 * sqrt(3.0) * m->G);
    be[0] = exp(2 * a);
    be[1] = exp(-2 * a);
  } else {
    const int k = (c - 8) % 3;
    if (k == 0) F[0][1] = 0.5;
    if (k == 1) F[0][0] = 1.5;
    if (k == 2) F[0][0] = 0.5;
  }
  return labels[c];
}

/* von Mises equivalent stress q = sqrt(3/2 s:s) of a Voigt tensor t[6] */
static inline double tbl_vm(const double *t) {
  const double p = (t[0] + t[1] + t[2]) / 3;
  const double a = t[0] - p, b = t[1] - p, c = t[2] - p;
  return sqrt(1.5 * (a * a + b * b + c * c + 2 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])));
}

#endif
