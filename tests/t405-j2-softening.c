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

/* Single-point harness: one material point in a one-cell grid; the material's stress
 * update is called directly with a prescribed relative deformation gradient. */
typedef struct {
  mpmc_context ctx;
  mpmc_sim sim;
  int id;
} point;

static void point_open(point *P, int dim) {
  TCALL(mpmc_context_create(&P->ctx));
  test_ctx = P->ctx;
  TCALL(mpmc_sim_create(P->ctx, dim, &P->sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  TCALL(mpmc_sim_set_grid(P->sim, lo, hi, 0.5));
}

/* after the material is added: one point of it */
static void point_seed(point *P) {
  const double x[3] = {0.5, 0.5, 0.5}, v = 1.0;
  TCALL(mpmc_sim_add_particles(P->sim, 1, x, &v, P->id, NULL));
  TCALL(mpmc_sim_prepare(P->sim));
}

/* dF: dim x dim row-major */
static void point_apply(point *P, const double *dF) {
  struct mpmc_sim_s *s = P->sim;
  const int d = s->dim;
  for (int k = 0; k < d * d; ++k) s->p.dF[k] = dF[k];
  double F3[3][3];
  mpmc_embed(d, dF, F3);
  s->p.J[0] *= mpmc_det3(F3);
  TCALL(s->mats[P->id].ops->stress_update(s, &s->mats[P->id], P->id, 1e-3));
}

static void point_close(point *P) {
  mpmc_sim_destroy(&P->sim);
  mpmc_context_destroy(&P->ctx);
  test_ctx = NULL;
}

/* von Mises stress of a Voigt tensor */
static double vm(const double *t) {
  const double p = (t[0] + t[1] + t[2]) / 3;
  const double a = t[0] - p, b = t[1] - p, c = t[2] - p;
  return sqrt(1.5 * (a * a + b * b + c * c + 2 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])));
}

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
