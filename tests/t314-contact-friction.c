/* Coulomb friction against a moving rigid plate (issue 8).  An elastic block rests under
 * gravity g on a rigid box that slides sideways at speed V.  While the block slips it
 * accelerates at mu g towards the plate's velocity (Coulomb); with a large mu it sticks and
 * moves with the plate.  The plate carries the block's weight.  2D and 3D (plate moving diagonally), and no point ever inside
 * the plate. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

/* mean displacement of the block's bottom layer relative to the plate, along dir */
static double base_slip(mpmc_sim sim, int n, const double *x0, int dim, int up, double ybot,
                        int plate, const double *dir) {
  double *xp, off[3] = {0, 0, 0}, s = 0;
  int nb = 0;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  TCALL(mpmc_sim_get_rigid_offset(sim, plate, off));
  for (int q = 0; q < n; ++q) {
    if (x0[(size_t)q * dim + up] > ybot) continue;
    for (int a = 0; a < dim; ++a) s += (xp[(size_t)q * dim + a] - x0[(size_t)q * dim + a] - off[a]) * dir[a];
    nb++;
  }
  return s / nb;
}

/* returns the block's mean velocity along the plate's direction at t_end */
static void run(int dim, double mu, double V, double t_end, double *v_along, double *v_bottom,
                double *normal_impulse, double *slip) {
  const double h = 0.05, E = 1.0e5, nu = 0.3, rho = 1000.0, g = 10.0;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double glo[3] = {0.0, 0.0, 0.0}, ghi[3] = {1.5, dim == 2 ? 0.5 : 1.5, 0.5};
  const int up = dim - 1; /* the vertical axis */
  double lo3[3], hi3[3];
  for (int a = 0; a < dim; ++a) {
    lo3[a] = glo[a];
    hi3[a] = ghi[a];
  }
  TCALL(mpmc_sim_set_grid(sim, lo3, hi3, h));
  int mat;
  TCALL(mpmc_sim_add_material_hencky(sim, E, nu, rho, &mat));
  /* block 0.3 (x 0.3) x 0.15, its base on the plate's top face z = 0.1 */
  double plo[3] = {0.3, 0.3, 0.1}, phi[3] = {0.6, 0.6, 0.25};
  if (dim == 2) {
    plo[1] = 0.1;
    phi[1] = 0.25;
  }
  double *x, *vol;
  const int n = test_lattice(dim, plo, phi, h, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  double gr[3] = {0, 0, 0};
  gr[up] = -g;
  TCALL(mpmc_sim_set_gravity(sim, gr));
  double blo[3] = {-10, -10, -10}, bhi[3] = {10, 10, 10};
  bhi[up] = 0.1;
  int plate;
  TCALL(mpmc_sim_add_rigid_box(sim, blo, bhi, mu, &plate));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  /* settle onto the barrier with local damping, the plate at rest */
  TCALL(mpmc_sim_set_damping(sim, 0.5));
  for (int s = 0; s < (int)ceil(0.1 / dt); ++s) TCALL(mpmc_sim_step(sim, dt));
  TCALL(mpmc_sim_set_damping(sim, 0.0));
  /* the plate slides along x (2D) or along (3, 4)/5 in the horizontal plane (3D) */
  double dir[3] = {1, 0, 0};
  if (dim == 3) {
    dir[0] = 0.6;
    dir[1] = 0.8;
  }
  double vb[3] = {V * dir[0], V * dir[1], 0};
  TCALL(mpmc_sim_set_rigid_velocity(sim, plate, vb));
  const int nsteps = (int)ceil(t_end / dt);
  dt = t_end / nsteps;
  double ry = 0, slip_half = 0;
  for (int s = 0; s < nsteps; ++s) {
    if (s == nsteps / 2) slip_half = base_slip(sim, n, x, dim, up, plo[up] + 0.5 * h, plate, dir);
    TCALL(mpmc_sim_step(sim, dt));
    double r[3], gap;
    int pt;
    TCALL(mpmc_sim_get_rigid_reaction(sim, plate, r));
    ry += r[up] * dt;
    TCALL(mpmc_sim_get_rigid_gap(sim, plate, &gap, &pt));
    if (!(gap > 0)) fail_msg("step %d: point %d has gap %g, expected > 0", s, pt, gap);
  }
  /* velocity along the plate's direction: of the whole block, and of its bottom layer */
  double *v;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  double va = 0, vbot = 0, mass = 0;
  int nbot = 0;
  for (int q = 0; q < n; ++q) {
    double vq = 0;
    for (int a = 0; a < dim; ++a) vq += v[(size_t)q * dim + a] * dir[a];
    va += vq;
    if (x[(size_t)q * dim + up] < plo[up] + 0.5 * h) {
      vbot += vq;
      nbot++;
    }
    mass += rho * vol[q];
  }
  *v_along = va / n;
  *v_bottom = vbot / nbot;
  *normal_impulse = -ry / mass; /* per unit mass: m g t at rest */
  *slip = base_slip(sim, n, x, dim, up, plo[up] + 0.5 * h, plate, dir) - slip_half;
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

static void check_sliding(int dim) {
  const double mu = 0.3, g = 10.0, V = 5.0, t = 0.2;
  double va, vbot, imp, slip;
  run(dim, mu, V, t, &va, &vbot, &imp, &slip);
  /* Coulomb while slipping (the plate is faster throughout): tangential impulse = mu times
   * the normal one, which for a block at rest is its weight m g t */
  if (fabs(va - mu * imp) > 0.02 * mu * imp || fabs(imp - g * t) > 0.03 * g * t)
    fail_msg("dim %d sliding: block velocity %.4f (expected mu N t / m = %.4f, mu g t = %.4f), "
             "normal impulse per mass %.4f (expected g t = %.4f)",
             dim, va, mu * imp, mu * g * t, imp, g * t);
}

static void test_sliding_2d(void **state) {
  (void)state;
  check_sliding(2);
}
static void test_sliding_3d(void **state) {
  (void)state;
  check_sliding(3);
}

/* a rough contact: the block catches up with the plate (after V/(mu g) = 0.025 s) and rides
 * along with it */
static void test_sticking_2d(void **state) {
  (void)state;
  const double V = 0.5, t = 0.2;
  double va, vbot, imp, slip;
  run(2, 2.0, V, t, &va, &vbot, &imp, &slip);
  /* over the second half the base does not slip on the plate (the plate travels V t/2; the
   * elastic stick holds each point within T/k of where it stuck: measured 0.2 % of the
   * plate's travel); the block as a whole moves with it, give or take the elastic
   * vibration set off when the base caught up */
  if (fabs(slip) > 0.02 * V * t / 2 || fabs(va - V) > 0.25 * V)
    fail_msg("sticking: slip of the base over the second half %.3g m (expected 0, plate "
             "travel %.3g m), block velocity %.4f (expected the plate's %.4f)",
             slip, V * t / 2, va, V);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sliding_2d),
      cmocka_unit_test(test_sliding_3d),
      cmocka_unit_test(test_sticking_2d),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
