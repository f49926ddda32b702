/* Hencky-J2 softening (paper 4.4's sensitive clay: E = 25 MPa, nu = 0.499, kappa_p =
 * 40.82 kPa, kappa_r = 2.45 kPa, eta = 5) along plane-strain pure shear,
 * dF = diag(e^d, e^-d).  The path is coaxial, so logarithmic strains add exactly: with total
 * log strain (t, -t, 0) the return map must give
 *   q = kappa(eps_p) = kappa_r + (kappa_p - kappa_r) exp(-eta eps_p)  and
 *   eps_p = (2/sqrt 3) t - q / 3G   (elastic part q/3G of the equivalent strain),
 * whatever the step size; as eps_p grows q falls to kappa_r. */
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



static void run(int solver) {
  point P;
  point_open(&P, 2);
  const double E = 25e6, nu = 0.499, kp = 40.82e3, kr = 2.45e3, eta = 5.0;
  const double G = E / (2 * (1 + nu));
  TCALL(mpmc_sim_add_material_hencky_j2(P.sim, E, nu, 2150.0, kp, kr, eta, &P.id));
  TCALL(mpmc_sim_set_solver(P.sim, solver));
  point_seed(&P);
  const double d = 0.005;
  const double dF[9] = /* 2x2 used */ {exp(d), 0, 0, exp(-d)};
  double qprev = INFINITY;
  for (int n = 1; n <= 400; ++n) {
    point_apply(&P, dF);
    const double t = n * d, ep = P.sim->p.eps_p[0];
    const double q = vm(P.sim->p.stress) * P.sim->p.J[0];
    const double kap = kr + (kp - kr) * exp(-eta * ep);
    const double ep_expect = 2.0 / sqrt(3.0) * t - q / (3 * G);
    if (fabs(q - kap) > 1e-9 * kap || fabs(ep - ep_expect) > 1e-9 * (1 + ep))
      fail_msg("solver %d step %d (t = %g): q = %.12g, kappa(eps_p) = %.12g; eps_p = %.12g, "
               "expected %.12g",
               solver, n, t, q, kap, ep, ep_expect);
    if (q > qprev * (1 + 1e-12)) fail_msg("step %d: q rose from %.12g to %.12g while softening", n, qprev, q);
    qprev = q;
  }
  const double q = vm(P.sim->p.stress);
  if (!(q - kr <= 1e-3 * kr))
    fail_msg("after eps_p = %.3f: q = %.6g Pa, expected to reach kappa_r = %.6g Pa (within 0.1%%)",
             P.sim->p.eps_p[0], q, kr);
  point_close(&P);
}

static void test_softening_newton(void **state) {
  (void)state;
  run(MPMC_SOLVER_NEWTON);
}
static void test_softening_kinsol(void **state) {
  (void)state;
  run(MPMC_SOLVER_KINSOL);
}
static void test_softening_auto(void **state) {
  (void)state;
  run(MPMC_SOLVER_AUTO);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_softening_newton),
      cmocka_unit_test(test_softening_kinsol),
      cmocka_unit_test(test_softening_auto),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
