/* Bad input (issue 2): every kind of invalid argument returns its code and a message that
 * names the parameter; nothing is changed by a refused call. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

static mpmc_context ctx;

/* the call must return code and the last error must contain the text */
#define EXPECT(call, code, text)                                                             \
  do {                                                                                       \
    const int got_ = (call);                                                                 \
    const char *m_ = mpmc_context_last_error(ctx);                                           \
    if (got_ != (code) || !strstr(m_, (text)))                                               \
      fail_msg("%s: expected code %d with '%s', got %d: '%s'", #call, (code), (text), got_,  \
               m_);                                                                          \
  } while (0)

static void test_bad_input(void **state) {
  (void)state;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  EXPECT(mpmc_sim_create(ctx, 1, &sim), MPMC_ERR_ARG, "dim = 1");
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {4, 2}, bad_hi[2] = {-1, 2}, x_out[2] = {5, 1};
  const double x_in[4] = {1, 1, 2, 1}, vol[2] = {0.25, 0.25}, vneg[2] = {0.25, -1};
  int id;
  /* order of calls */
  EXPECT(mpmc_sim_add_particles(sim, 2, x_in, vol, 0, NULL), MPMC_ERR_STATE, "set the grid");
  double dt;
  EXPECT(mpmc_sim_stable_dt(sim, 0.3, &dt), MPMC_ERR_STATE, "needs a grid");
  /* grid */
  EXPECT(mpmc_sim_set_grid(sim, lo, hi, 0.0), MPMC_ERR_ARG, "cell size h = 0");
  EXPECT(mpmc_sim_set_grid(sim, lo, hi, -0.5), MPMC_ERR_ARG, "cell size h = -0.5");
  EXPECT(mpmc_sim_set_grid(sim, lo, bad_hi, 0.5), MPMC_ERR_ARG, "axis 0: hi = -1");
  EXPECT(mpmc_sim_set_grid(sim, lo, hi, 1e-9), MPMC_ERR_ARG, "too small");
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.5));
  /* options */
  EXPECT(mpmc_sim_set_basis(sim, 7), MPMC_ERR_ARG, "basis = 7");
  EXPECT(mpmc_sim_set_fbar(sim, 5), MPMC_ERR_ARG, "fbar = 5");
  EXPECT(mpmc_sim_set_fbar(sim, -1), MPMC_ERR_ARG, "fbar = -1");
  EXPECT(mpmc_sim_set_flip_blend(sim, 1.5), MPMC_ERR_ARG, "FLIP/PIC blend = 1.5");
  EXPECT(mpmc_sim_set_pic_diffusivity(sim, -1), MPMC_ERR_ARG, "PIC diffusivity D = -1");
  EXPECT(mpmc_sim_set_pic_diffusivity(sim, INFINITY), MPMC_ERR_ARG, "PIC diffusivity D = inf");
  EXPECT(mpmc_sim_set_damping(sim, 1.0), MPMC_ERR_ARG, "local damping alpha = 1");
  EXPECT(mpmc_sim_set_solver(sim, 5), MPMC_ERR_ARG, "solver = 5");
  EXPECT(mpmc_sim_set_threads(sim, -2), MPMC_ERR_ARG, "threads = -2");
  const double gnan[2] = {0, NAN};
  EXPECT(mpmc_sim_set_gravity(sim, gnan), MPMC_ERR_ARG, "gravity component 1");
  /* materials */
  EXPECT(mpmc_sim_add_material_hencky(sim, -1, 0.3, 1000, &id), MPMC_ERR_ARG, "Young's modulus E = -1");
  EXPECT(mpmc_sim_add_material_hencky(sim, 1e6, 0.5, 1000, &id), MPMC_ERR_ARG, "Poisson's ratio nu = 0.5");
  EXPECT(mpmc_sim_add_material_neo_hookean(sim, 1e6, -0.1, 1000, &id), MPMC_ERR_ARG, "nu = -0.1");
  EXPECT(mpmc_sim_add_material_neo_hookean(sim, 1e6, 0.3, 0, &id), MPMC_ERR_ARG, "density rho = 0");
  EXPECT(mpmc_sim_add_material_newtonian(sim, 0, 1e-3, 1000, &id), MPMC_ERR_ARG, "bulk modulus K = 0");
  EXPECT(mpmc_sim_add_material_newtonian(sim, 2e9, -1, 1000, &id), MPMC_ERR_ARG, "viscosity mu = -1");
  int nmat;
  TCALL(mpmc_sim_get_num_materials(sim, &nmat));
  assert_int_equal(nmat, 0); /* nothing added by refused calls */
  TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.3, 1000, &id));
  /* points */
  EXPECT(mpmc_sim_add_particles(sim, 2, x_in, vol, 3, NULL), MPMC_ERR_ARG, "material id 3");
  EXPECT(mpmc_sim_add_particles(sim, -1, x_in, vol, id, NULL), MPMC_ERR_ARG, "n = -1");
  EXPECT(mpmc_sim_add_particles(sim, 2, x_in, vneg, id, NULL), MPMC_ERR_ARG, "point 1: volume = -1");
  EXPECT(mpmc_sim_add_particles(sim, 1, x_out, vol, id, NULL), MPMC_ERR_OUTSIDE, "coordinate 0 = 5");
  int np;
  TCALL(mpmc_sim_get_num_particles(sim, &np));
  assert_int_equal(np, 0);
  EXPECT(mpmc_sim_step(sim, 1e-3), MPMC_ERR_STATE, "nothing to step");
  TCALL(mpmc_sim_add_particles(sim, 2, x_in, vol, id, NULL));
  /* walls and forces */
  EXPECT(mpmc_sim_add_wall_face(sim, 4, MPMC_WALL_FIXED, NULL), MPMC_ERR_ARG, "face = 4");
  EXPECT(mpmc_sim_add_wall(sim, 0, 0, 1.0, MPMC_WALL_SLIP, NULL), MPMC_ERR_ARG, "wall side = 0");
  EXPECT(mpmc_sim_add_wall(sim, 2, -1, 1.0, MPMC_WALL_SLIP, NULL), MPMC_ERR_ARG, "wall axis = 2");
  EXPECT(mpmc_sim_add_wall(sim, 0, -1, 1.0, 9, NULL), MPMC_ERR_ARG, "wall kind = 9");
  EXPECT(mpmc_sim_remove_wall(sim, 0), MPMC_ERR_ARG, "wall id 0");
  const double finf[2] = {INFINITY, 0};
  EXPECT(mpmc_sim_set_particle_forces(sim, 0, 1, finf), MPMC_ERR_ARG, "force component 0");
  EXPECT(mpmc_sim_set_particle_forces(sim, 1, 2, finf), MPMC_ERR_ARG, "points [1, 3)");
  EXPECT(mpmc_sim_reduce_strength(sim, 0, 1.65), MPMC_ERR_ARG, "not plastic");
  EXPECT(mpmc_sim_reduce_strength(sim, -1, 0.0), MPMC_ERR_ARG, "factor = 0");
  double *f;
  EXPECT(mpmc_sim_get_field(sim, MPMC_FIELD_EPS_P, &f, NULL), MPMC_ERR_STATE, "no 'eps_p' field");
  EXPECT(mpmc_sim_get_field(sim, 42, &f, NULL), MPMC_ERR_ARG, "field = 42");
  /* time step */
  EXPECT(mpmc_sim_stable_dt(sim, 1.5, &dt), MPMC_ERR_ARG, "time-step factor = 1.5");
  EXPECT(mpmc_sim_step(sim, -1.0), MPMC_ERR_ARG, "dt = -1");
  TCALL(mpmc_sim_stable_dt(sim, 1.0, &dt));
  EXPECT(mpmc_sim_step(sim, 2.0 * dt), MPMC_ERR_UNSTABLE, "exceeds the stability limit");
  double t;
  TCALL(mpmc_sim_get_time(sim, &t));
  assert_true(t == 0.0); /* the refused step did not advance */
  TCALL(mpmc_sim_set_force_dt(sim, 1));
  TCALL(mpmc_sim_step(sim, 1.5 * dt)); /* forced: accepted */
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_bad_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
