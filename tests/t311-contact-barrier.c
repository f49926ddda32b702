/* Barrier contact, single points (issue 8): the force on a point at a known gap from a rigid
 * box or polygon against the IPC barrier written out here, f = A kappa (d - dhat)
 * [2 ln(d/dhat) + 1 - dhat/d] n, checked also as minus the finite-difference gradient of
 * the energy A kappa b(d); the body's reaction; the derived defaults of dhat and kappa
 * (docs/contact.md); smoothed Coulomb friction; the barrier's time-step limit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "test_util.h"

#define CHECK_REL(got, want, rtol, what)                                                      \
  do {                                                                                        \
    const double g_ = (got), w_ = (want);                                                     \
    if (!(fabs(g_ - w_) <= (rtol) * fabs(w_) + 1e-300))                                       \
      fail_msg("%s: got %.12g, expected %.12g (relative tolerance %g)", what, g_, w_, rtol);  \
  } while (0)

static const double E = 1.0e6, NU = 0.3, RHO = 1000.0, H = 0.1, VP = 0.0025; /* l = 0.05 */

/* IPC barrier energy per area per kappa, and its force per area per kappa */
static double b_energy(double d, double dhat) {
  return d < dhat ? -(d - dhat) * (d - dhat) * log(d / dhat) : 0.0;
}
static double b_force(double d, double dhat) {
  return d < dhat ? (d - dhat) * (2.0 * log(d / dhat) + 1.0 - dhat / d) : 0.0;
}

static mpmc_sim make_sim(mpmc_context *ctx, int n, const double *x) {
  mpmc_sim sim;
  TCALL(mpmc_context_create(ctx));
  test_ctx = *ctx;
  TCALL(mpmc_sim_create(*ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {3, 3};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, H));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, NU, RHO, &mat));
  double vol[16];
  for (int i = 0; i < n; ++i) vol[i] = VP;
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  TCALL(mpmc_sim_prepare(sim));
  return sim;
}

static void done(mpmc_sim *sim, mpmc_context *ctx) {
  mpmc_sim_destroy(sim);
  mpmc_context_destroy(ctx);
  test_ctx = NULL;
}

/* derived defaults: dhat = l/2, kappa = 4 M l / (h^2 |g'(1/2)|) with g'(1/2) = 2 ln(1/2) - 5 */
static void test_defaults(void **state) {
  (void)state;
  const double x[2] = {1.0, 1.0};
  mpmc_context ctx;
  mpmc_sim sim = make_sim(&ctx, 1, x);
  const double l = sqrt(VP);
  const double M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU));
  const double kappa = 4 * M * l / (H * H * fabs(2 * log(0.5) - 5));
  double dhat, k;
  TCALL(mpmc_sim_get_contact_params(sim, &dhat, &k));
  CHECK_REL(dhat, 0.5 * l, 1e-12, "default dhat");
  CHECK_REL(k, kappa, 1e-12, "default kappa");
  TCALL(mpmc_sim_set_contact_params(sim, 0.01, 3.0e7));
  TCALL(mpmc_sim_get_contact_params(sim, &dhat, &k));
  CHECK_REL(dhat, 0.01, 1e-15, "caller's dhat");
  CHECK_REL(k, 3.0e7, 1e-15, "caller's kappa");
  done(&sim, &ctx);
}

/* box [0.5, 1.5] x [1, 1.5]: points below its face, beside its corner, out of range */
static void test_box_force(void **state) {
  (void)state;
  const double l = sqrt(VP), dhat = 0.5 * l;
  const double xs[8] = {1.0, 1.0 - 0.3 * dhat,             /* below the face, x = 0.3   */
                        0.7, 1.0 - 0.9 * dhat,             /* below the face, x = 0.9   */
                        1.5 + 0.4 * dhat, 1.0 - 0.5 * dhat, /* beside the corner (1.5, 1) */
                        1.2, 1.0 - 1.2 * dhat};            /* out of range              */
  mpmc_context ctx;
  mpmc_sim sim = make_sim(&ctx, 4, xs);
  const double lo[2] = {0.5, 1.0}, hi[2] = {1.5, 1.5};
  int id;
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, 0.0, &id));
  double dh, kappa;
  TCALL(mpmc_sim_get_contact_params(sim, &dh, &kappa));
  CHECK_REL(dh, dhat, 1e-12, "dhat");
  TCALL(mpmc_contact_update(sim, 1e-4));
  const double *f = sim->p.cforce, A = l;
  /* closest points and gaps written out */
  const double cp[8] = {1.0, 1.0, 0.7, 1.0, 1.5, 1.0, 1.2, 1.0};
  double sum[2] = {0, 0};
  for (int q = 0; q < 4; ++q) {
    const double rx = xs[2 * q] - cp[2 * q], ry = xs[2 * q + 1] - cp[2 * q + 1];
    const double d = sqrt(rx * rx + ry * ry);
    const double mag = A * kappa * b_force(d, dhat);
    char what[64];
    snprintf(what, sizeof what, "point %d force x", q);
    if (mag == 0.0) {
      if (f[2 * q] != 0.0 || f[2 * q + 1] != 0.0)
        fail_msg("point %d out of range: force (%g, %g), expected 0", q, f[2 * q], f[2 * q + 1]);
      continue;
    }
    CHECK_REL(f[2 * q], mag * rx / d, 1e-10, what);
    snprintf(what, sizeof what, "point %d force y", q);
    CHECK_REL(f[2 * q + 1], mag * ry / d, 1e-10, what);
    /* minus the gradient of the energy, by central differences of the geometry */
    const double e = 1e-7 * dhat;
    for (int a = 0; a < 2; ++a) {
      double xp[2] = {xs[2 * q], xs[2 * q + 1]}, xm[2] = {xs[2 * q], xs[2 * q + 1]};
      xp[a] += e;
      xm[a] -= e;
      const double dp = hypot(xp[0] - fmin(fmax(xp[0], lo[0]), hi[0]), xp[1] - fmin(fmax(xp[1], lo[1]), hi[1]));
      const double dm = hypot(xm[0] - fmin(fmax(xm[0], lo[0]), hi[0]), xm[1] - fmin(fmax(xm[1], lo[1]), hi[1]));
      const double fd = -A * kappa * (b_energy(dp, dhat) - b_energy(dm, dhat)) / (2 * e);
      snprintf(what, sizeof what, "point %d force %d = -dE/dx", q, a);
      if (fabs(fd) > 1e-9 * mag) CHECK_REL(f[2 * q + a], fd, 1e-5, what);
    }
    sum[0] += f[2 * q];
    sum[1] += f[2 * q + 1];
  }
  double r[2];
  TCALL(mpmc_sim_get_rigid_reaction(sim, id, r));
  CHECK_REL(r[0], -sum[0], 1e-12, "reaction x");
  CHECK_REL(r[1], -sum[1], 1e-12, "reaction y");
  double gap;
  int pt;
  TCALL(mpmc_sim_get_rigid_gap(sim, id, &gap, &pt));
  CHECK_REL(gap, 0.3 * dhat, 1e-10, "smallest gap");
  assert_int_equal(pt, 0);
  done(&sim, &ctx);
}

/* a triangle, given clockwise and counter-clockwise: a point near its sloped edge */
static void test_polygon_force(void **state) {
  (void)state;
  const double l = sqrt(VP), dhat = 0.5 * l;
  /* triangle (1,1) (2,1) (1,2); the hypotenuse x + y = 3 has outward normal (1,1)/sqrt 2 */
  const double ccw[6] = {1, 1, 2, 1, 1, 2}, cw[6] = {1, 1, 1, 2, 2, 1};
  const double d = 0.6 * dhat, s = d / sqrt(2.0);
  const double xs[2] = {1.5 + s, 1.5 + s};
  for (int orient = 0; orient < 2; ++orient) {
    mpmc_context ctx;
    mpmc_sim sim = make_sim(&ctx, 1, xs);
    int id;
    TCALL(mpmc_sim_add_rigid_polygon(sim, 3, orient ? cw : ccw, 0.0, &id));
    double dh, kappa;
    TCALL(mpmc_sim_get_contact_params(sim, &dh, &kappa));
    TCALL(mpmc_contact_update(sim, 1e-4));
    const double mag = l * kappa * b_force(d, dhat);
    CHECK_REL(sim->p.cforce[0], mag / sqrt(2.0), 1e-9, "polygon force x");
    CHECK_REL(sim->p.cforce[1], mag / sqrt(2.0), 1e-9, "polygon force y");
    double gap;
    TCALL(mpmc_sim_get_rigid_gap(sim, id, &gap, NULL));
    CHECK_REL(gap, d, 1e-10, "polygon gap");
    done(&sim, &ctx);
  }
}

/* friction, an elastic stick (docs/contact.md): the anchor is where the point stuck, in the
 * body's frame; f_t = -k s - c v_t with s the tangential offset from it, k = m/(4 dt^2),
 * c = m/(2 dt), capped at mu lam (sliding: the anchor is dragged so that the spring holds
 * mu lam); out of contact the anchor is dropped.  The body slides along x at 0.3 m/s and
 * the point moves with it plus a slip speed vt (positions set by hand: no grid step). */
static void test_friction(void **state) {
  (void)state;
  const double l = sqrt(VP), dhat = 0.5 * l, mu = 0.4, dt = 1e-4;
  const double xs[2] = {1.0, 1.0 - 0.5 * dhat};
  mpmc_context ctx;
  mpmc_sim sim = make_sim(&ctx, 1, xs);
  const double lo[2] = {0.5, 1.0}, hi[2] = {1.5, 1.5};
  int id;
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, mu, &id));
  const double vb[2] = {0.3, 0.0};
  TCALL(mpmc_sim_set_rigid_velocity(sim, id, vb));
  double dh, kappa;
  TCALL(mpmc_sim_get_contact_params(sim, &dh, &kappa));
  const double lam = l * kappa * b_force(0.5 * dhat, dhat), m = RHO * VP;
  const double k = 0.25 * m / (dt * dt), c = 0.5 * m / dt;
  /* sticking: a slip speed whose force stays below mu lam for three updates */
  const double vt = 0.5 * mu * lam * dt / m;
  sim->p.v[0] = vb[0] + vt;
  sim->p.v[1] = 7.0; /* normal motion must not matter */
  for (int n = 1; n <= 3; ++n) {
    TCALL(mpmc_contact_update(sim, dt));
    char what[64];
    snprintf(what, sizeof what, "friction, stuck, update %d", n);
    CHECK_REL(sim->p.cforce[1], -lam, 1e-10, "normal force");
    CHECK_REL(sim->p.cforce[0], -k * (n - 1) * vt * dt - c * vt, 1e-9, what);
    sim->p.x[0] += (vb[0] + vt) * dt;
  }
  /* sliding: capped at mu lam; then at rest relative to the body the spring still holds it */
  sim->p.v[0] = vb[0] + 10.0 * vt;
  TCALL(mpmc_contact_update(sim, dt));
  CHECK_REL(sim->p.cforce[0], -mu * lam, 1e-10, "friction, sliding");
  sim->p.x[0] += (vb[0] + 10.0 * vt) * dt;
  sim->p.v[0] = vb[0];
  TCALL(mpmc_contact_update(sim, dt));
  CHECK_REL(sim->p.cforce[0], -mu * lam, 1e-9, "friction, stopped after sliding");
  sim->p.x[0] += vb[0] * dt;
  /* out of contact and back: a fresh anchor, no spring force */
  sim->p.x[1] = 1.0 - 2.0 * dhat;
  TCALL(mpmc_contact_update(sim, dt));
  CHECK_REL(sim->p.cforce[0] + 1.0, 1.0, 1e-14, "friction out of contact");
  sim->p.x[0] += vb[0] * dt;
  sim->p.x[1] = 1.0 - 0.5 * dhat;
  sim->p.v[0] = vb[0] + vt;
  TCALL(mpmc_contact_update(sim, dt));
  CHECK_REL(sim->p.cforce[0], -c * vt, 1e-9, "friction, stuck again");
  double off[2];
  TCALL(mpmc_sim_get_rigid_offset(sim, id, off));
  CHECK_REL(off[0], 7 * vb[0] * dt, 1e-12, "body offset x after seven updates");
  done(&sim, &ctx);
}

/* the time-step limit: 2 sqrt(m / (A kappa |g'(x)|)) at the point's gap ratio x (1/2 at
 * most), g'(x) by central differences of g(x) = (x - 1)(2 ln x + 1 - 1/x) */
static double gprime(double x) {
  const double e = 1e-6;
  const double gp = (x + e - 1) * (2 * log(x + e) + 1 - 1 / (x + e));
  const double gm = (x - e - 1) * (2 * log(x - e) + 1 - 1 / (x - e));
  return (gp - gm) / (2 * e);
}

static void test_stable_dt(void **state) {
  (void)state;
  const double l = sqrt(VP), dhat = 0.5 * l, m = RHO * VP;
  const double M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU)), c = sqrt(M / RHO);
  const double xs[4] = {1.0, 1.0 - 0.8 * dhat, 2.5, 2.5};
  mpmc_context ctx;
  mpmc_sim sim = make_sim(&ctx, 2, xs);
  double dt0;
  TCALL(mpmc_sim_stable_dt(sim, 1.0, &dt0));
  CHECK_REL(dt0, H / c, 1e-12, "stable dt without bodies");
  const double lo[2] = {0.5, 1.0}, hi[2] = {1.5, 1.5};
  int id;
  TCALL(mpmc_sim_add_rigid_box(sim, lo, hi, 0.0, &id));
  double kappa;
  TCALL(mpmc_sim_get_contact_params(sim, NULL, &kappa));
  /* the default kappa puts the design limit at x = 1/2 on h/c */
  double dt1;
  TCALL(mpmc_sim_stable_dt(sim, 1.0, &dt1));
  const double t_half = 2 * sqrt(m / (l * kappa * fabs(gprime(0.5))));
  CHECK_REL(t_half, H / c, 1e-6, "design limit at x = 1/2 equals h/c");
  CHECK_REL(dt1, fmin(H / c, t_half), 1e-6, "stable dt with a body, point at x = 0.8");
  /* move the point to x = 0.1: its stiffness sets the limit */
  sim->p.x[1] = 1.0 - 0.1 * dhat;
  TCALL(mpmc_sim_stable_dt(sim, 0.5, &dt1));
  const double t_01 = 2 * sqrt(m / (l * kappa * fabs(gprime(0.1))));
  CHECK_REL(dt1, 0.5 * t_01, 1e-6, "stable dt, point at x = 0.1");
  /* a step above it is refused */
  const int err = mpmc_sim_step(sim, 1.5 * t_01);
  assert_int_equal(err, MPMC_ERR_UNSTABLE);
  if (!strstr(mpmc_context_last_error(ctx), "stability limit"))
    fail_msg("message '%s' does not name the stability limit", mpmc_context_last_error(ctx));
  done(&sim, &ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_defaults),      cmocka_unit_test(test_box_force),
      cmocka_unit_test(test_polygon_force), cmocka_unit_test(test_friction),
      cmocka_unit_test(test_stable_dt),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
