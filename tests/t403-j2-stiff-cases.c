/* Stiff and extreme return maps (issue 3): eta in {5, 50, 500, 5000}, nu in {0.3, 0.49,
 * 0.499, 0.4999}, trial stresses up to 1e4 kappa, 50 % strain increments.  Every solver
 * either converges -- finite state, q = kappa(eps_p) to 1e-10 kappa (plus round-off of the
 * pressure), all solvers agreeing on dgamma to 1e-10 -- or returns a clear error code with the
 * state untouched.  Never NaN, never a silent wrong state.  (Table: docs/stability.md.) */
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "j2_cases.h"
#include "linalg.h"
#include "mpmc_impl.h"
#include "return_map.h"
#include "test_util.h"

static void test_table(void **state) {
  (void)state;
  mpmc_rm_ws *ws;
  assert_int_equal(mpmc_rm_ws_create(&ws), 0);
  int nfail = 0, nfb = 0;
  for (int ie = 0; ie < 4; ++ie)
    for (int in = 0; in < 4; ++in) {
      mpmc_j2_param m;
      tbl_material(ie, in, &m);
      for (int c = 0; c < TBL_NCASE; ++c) {
        double dgam[3] = {0, 0, 0};
        int ok[3] = {0, 0, 0};
        for (int s = 0; s < 3; ++s) {
          double be[6], be0[6], ep, ep0, F[3][3], tau[6] = {0}, J = 0;
          const char *label = tbl_case(&m, c, be, &ep, F);
          memcpy(be0, be, sizeof be);
          ep0 = ep;
          mpmc_j2_info info = {0};
          const int err = mpmc_j2_return_map(ws, s, &m, F, be, &ep, tau, &J, &info);
          if (err) {
            ++nfail;
            if (err != MPMC_ERR_SOLVER && err != MPMC_ERR_NUMERIC)
              fail_msg("eta %g nu %g %s solver %d: unexpected code %d", m.eta, tbl_nu[in], label, s, err);
            if (memcmp(be, be0, sizeof be) || ep != ep0)
              fail_msg("eta %g nu %g %s solver %d: failed (%d) but changed the state", m.eta,
                       tbl_nu[in], label, s, err);
            continue;
          }
          for (int k = 0; k < 6; ++k)
            if (!isfinite(tau[k]) || !isfinite(be[k]))
              fail_msg("eta %g nu %g %s solver %d: non-finite result", m.eta, tbl_nu[in], label, s);
          if (!(ep >= ep0) || !isfinite(J) || !(J > 0))
            fail_msg("eta %g nu %g %s solver %d: eps_p %g -> %g, J %g", m.eta, tbl_nu[in], label, s, ep0, ep, J);
          if (info.plastic) {
            const double kap = mpmc_j2_kappa(&m, ep), pr = fabs(tau[0] + tau[1] + tau[2]) / 3;
            const double err_q = fabs(tbl_vm(tau) - kap);
            if (err_q > 1e-10 * kap + 32 * DBL_EPSILON * pr)
              fail_msg("eta %g nu %g %s solver %d: q %.15g, kappa %.15g (|p| %g)", m.eta, tbl_nu[in],
                       label, s, tbl_vm(tau), kap, pr);
          }
          ok[s] = 1;
          dgam[s] = ep - ep0;
          nfb += info.fallback;
        }
        for (int s = 1; s < 3; ++s)
          if (ok[0] && ok[s] && fabs(dgam[s] - dgam[0]) > 1e-10 * dgam[0])
            fail_msg("eta %g nu %g case %d: dgamma newton %.17g, solver %d %.17g", m.eta, tbl_nu[in], c,
                     dgam[0], s, dgam[s]);
      }
    }
  /* with these strengths all cases converge; the table also needs stiff ones */
  if (nfail) fail_msg("%d return maps failed (expected none in this table)", nfail);
  if (nfb == 0) fail_msg("no KINSOL fallback in the table: the stiff cases are not exercised");
  mpmc_rm_ws_destroy(&ws);
}

/* A trial state that is not positive definite (an inverted increment) is a clear error. */
static void test_inverted(void **state) {
  (void)state;
  mpmc_j2_param m;
  tbl_material(0, 0, &m);
  double be[6] = {1, 1, 1, 0, 0, 0}, ep = 0.1, tau[6], J;
  double F[3][3] = {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  /* b = F F^T is still positive definite for det F < 0: use a NaN increment instead */
  F[0][1] = NAN;
  const int err = mpmc_j2_return_map(NULL, MPMC_SOLVER_NEWTON, &m, F, be, &ep, tau, &J, NULL);
  if (err != MPMC_ERR_NUMERIC) fail_msg("NaN increment: code %d, expected MPMC_ERR_NUMERIC", err);
  if (be[0] != 1 || ep != 0.1) fail_msg("NaN increment changed the state");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_table),
      cmocka_unit_test(test_inverted),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
