/* Hencky-J2 objectivity: after plastic loading by a general deformation, a rigid rotation R
 * as the increment gives sigma_new = R sigma R^T: the invariants (I1, J2, det) are
 * unchanged and no plastic strain accrues.  Both one large rotation and many small ones. */
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "linalg.h"
#include "mpmc_impl.h"
#include "return_map.h"
#include "test_util.h"
#include "point_harness.h"



static void rotation(double angle, double R[3][3]) {
  /* Rodrigues, axis (1, 2, 3)/sqrt(14) */
  const double n[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)};
  const double c = cos(angle), s = sin(angle);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = c * (i == j) + (1 - c) * n[i] * n[j];
  R[0][1] -= s * n[2]; R[1][0] += s * n[2];
  R[0][2] += s * n[1]; R[2][0] -= s * n[1];
  R[1][2] -= s * n[0]; R[2][1] += s * n[0];
}

static void invariants(const double *t, double inv[3]) {
  double A[3][3];
  mpmc_voigt_to_mat(t, A);
  inv[0] = A[0][0] + A[1][1] + A[2][2];
  inv[1] = vm(t);
  inv[2] = mpmc_det3(A);
}

static void run(int nrot) {
  point P;
  point_open(&P, 3);
  const double E = 25e6, nu = 0.3, kp = 40.82e3, kr = 2.45e3, eta = 5.0;
  TCALL(mpmc_sim_add_material_hencky_j2(P.sim, E, nu, 2150.0, kp, kr, eta, &P.id));
  point_seed(&P);
  const double F1[9] = {1.004, 0.003, -0.001, 0.002, 0.998, 0.0025, 0.0, -0.0015, 1.001};
  for (int n = 0; n < 5; ++n) point_apply(&P, F1);
  const double ep0 = P.sim->p.eps_p[0];
  if (!(ep0 > 1e-3)) fail_msg("set-up: eps_p = %g, expected plastic loading (> 1e-3)", ep0);
  double s0[6], inv0[3];
  memcpy(s0, P.sim->p.stress, sizeof s0);
  invariants(s0, inv0);
  const double total = 0.5 * M_PI;
  double R[3][3], Rtot[3][3], dF[9];
  rotation(total / nrot, R);
  rotation(total, Rtot);
  for (int i = 0; i < 9; ++i) dF[i] = R[i / 3][i % 3];
  for (int n = 0; n < nrot; ++n) point_apply(&P, dF);
  const double *s = P.sim->p.stress;
  double inv[3], expect[6];
  invariants(s, inv);
  const double scale = fabs(inv0[0]) + inv0[1];
  /* each step re-derives b_e from its logarithm: round-off of ~eps per step in the log
     strains, i.e. ~eps / 0.015 in the stress here; 90 steps: allow 1e-10 */
  const double tol = nrot == 1 ? 1e-12 : 1e-10;
  if (fabs(inv[0] - inv0[0]) > tol * scale || fabs(inv[1] - inv0[1]) > tol * scale ||
      fabs(inv[2] - inv0[2]) > 10 * tol * scale * scale * scale)
    fail_msg("%d rotations: invariants (I1, q, det) = (%.15g, %.15g, %.15g), expected (%.15g, "
             "%.15g, %.15g)",
             nrot, inv[0], inv[1], inv[2], inv0[0], inv0[1], inv0[2]);
  double S0[3][3], T[3][3] = {{0}}, Rs[3][3];
  mpmc_voigt_to_mat(s0, S0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Rs[i][j] = 0;
      for (int k = 0; k < 3; ++k) Rs[i][j] += Rtot[i][k] * S0[k][j];
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) T[i][j] += Rs[i][k] * Rtot[j][k];
  mpmc_mat_to_voigt(T, expect);
  for (int c = 0; c < 6; ++c)
    if (fabs(s[c] - expect[c]) > 10 * tol * scale)
      fail_msg("%d rotations: sigma[%d] = %.15g, expected R sigma R^T = %.15g", nrot, c, s[c],
               expect[c]);
  if (fabs(P.sim->p.eps_p[0] - ep0) > tol * ep0)
    fail_msg("%d rotations: eps_p changed from %.17g to %.17g", nrot, ep0, P.sim->p.eps_p[0]);
  point_close(&P);
}

static void test_one_rotation(void **state) {
  (void)state;
  run(1);
}
static void test_many_rotations(void **state) {
  (void)state;
  run(90);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_one_rotation),
      cmocka_unit_test(test_many_rotations),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
