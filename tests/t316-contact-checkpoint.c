/* Rigid bodies in checkpoints (issue 8): N steps of a footing-like set-up (an elastic-plastic
 * block pressed by a moving rough box, touched by a still polygon, with a third body removed
 * before the checkpoint and a non-default barrier range) equal N/2 steps + checkpoint +
 * restart + N/2 steps bit for bit: every particle array, the bodies' offsets, reactions and
 * gaps.  The restarted bodies keep their velocity, friction, shape, removal and the barrier
 * parameters; a damaged /bodies block is a clear error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>
#include <hdf5.h>

#include "test_util.h"

#define CK MPMC_BINARY_DIR "/t316.ck"
#define CK2 MPMC_BINARY_DIR "/t316-bad.ck"

static mpmc_context ctx;
static double dhat_set; /* the non-default barrier range */

/* bodies: 0 = the pushing box, 1 = a still triangle on the block's side, 2 = removed */
static mpmc_sim build(void) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {2, 1.25};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.125));
  TCALL(mpmc_sim_set_basis(sim, MPMC_BASIS_BSPLINE2));
  TCALL(mpmc_sim_set_fbar(sim, MPMC_FBAR_TOTAL));
  TCALL(mpmc_sim_set_damping(sim, 0.01));
  TCALL(mpmc_sim_set_threads(sim, 1));
  int mat;
  TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e5, 0.45, 1000, 200, 200, 0.0, &mat));
  double *x, *vol;
  const double plo[2] = {0, 0}, phi[2] = {1.5, 1.0};
  const int n = test_lattice(2, plo, phi, 0.125, 2, &x, &vol);
  TCALL(mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  free(x);
  free(vol);
  TCALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  dhat_set = 0.8 * 0.25 * 0.125; /* 0.8 x the default (half the point spacing) */
  TCALL(mpmc_sim_set_contact_params(sim, dhat_set, 0.0));
  /* the box's base at gap dhat from the top row of points (y = 1 - h/4) */
  const double blo[2] = {-0.5, 1.0 - 0.25 * 0.125 + dhat_set}, bhi[2] = {0.5, 1.5};
  int box, tri, gone;
  TCALL(mpmc_sim_add_rigid_box(sim, blo, bhi, 1000.0, &box));
  const double xy[6] = {1.5 - 0.25 * 0.125 + dhat_set, 0.2, 1.9, 0.2, 1.9, 0.8};
  TCALL(mpmc_sim_add_rigid_polygon(sim, 3, xy, 0.3, &tri));
  const double glo[2] = {1.6, 1.0}, ghi[2] = {1.9, 1.2};
  TCALL(mpmc_sim_add_rigid_box(sim, glo, ghi, 0.0, &gone));
  TCALL(mpmc_sim_remove_rigid(sim, gone));
  const double vb[2] = {0.0, -0.05};
  TCALL(mpmc_sim_set_rigid_velocity(sim, box, vb));
  return sim;
}

static void compare(mpmc_sim a, mpmc_sim b) {
  int na, nb;
  TCALL(mpmc_sim_get_num_particles(a, &na));
  TCALL(mpmc_sim_get_num_particles(b, &nb));
  assert_int_equal(na, nb);
  for (int fld = 0; fld < MPMC_FIELD_COUNT; ++fld) {
    double *fa, *fb;
    int ca = 0, cb = 0;
    const int ra = mpmc_sim_get_field(a, fld, &fa, &ca), rb = mpmc_sim_get_field(b, fld, &fb, &cb);
    if (ra != rb) fail_msg("field %d: present in one run only (%d vs %d)", fld, ra, rb);
    if (ra) continue;
    for (size_t i = 0; i < (size_t)na * (size_t)ca; ++i)
      if (memcmp(&fa[i], &fb[i], sizeof(double)) != 0)
        fail_msg("field %d entry %zu: uninterrupted %.17g, restarted %.17g", fld, i, fa[i], fb[i]);
  }
  for (int id = 0; id < 2; ++id) {
    double oa[2], ob[2], fa[2], fb[2], ga, gb;
    int pa, pb;
    TCALL(mpmc_sim_get_rigid_offset(a, id, oa));
    TCALL(mpmc_sim_get_rigid_offset(b, id, ob));
    TCALL(mpmc_sim_get_rigid_reaction(a, id, fa));
    TCALL(mpmc_sim_get_rigid_reaction(b, id, fb));
    TCALL(mpmc_sim_get_rigid_gap(a, id, &ga, &pa));
    TCALL(mpmc_sim_get_rigid_gap(b, id, &gb, &pb));
    for (int c = 0; c < 2; ++c) {
      if (memcmp(&oa[c], &ob[c], sizeof(double)))
        fail_msg("body %d offset[%d]: uninterrupted %.17g, restarted %.17g", id, c, oa[c], ob[c]);
      if (memcmp(&fa[c], &fb[c], sizeof(double)))
        fail_msg("body %d reaction[%d]: uninterrupted %.17g, restarted %.17g", id, c, fa[c], fb[c]);
    }
    if (memcmp(&ga, &gb, sizeof(double)) || pa != pb)
      fail_msg("body %d gap: uninterrupted %.17g (point %d), restarted %.17g (point %d)", id, ga,
               pa, gb, pb);
  }
}

static void test_restart_bitwise(void **state) {
  (void)state;
  const int N = 60;
  mpmc_sim a = build(), b = build();
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.4, &dt));
  double fy_half = 0.0;
  for (int s = 0; s < N; ++s) {
    TCALL(mpmc_sim_step(a, dt));
    if (s == N / 2 - 1) {
      double r[2];
      TCALL(mpmc_sim_get_rigid_reaction(a, 0, r));
      fy_half = r[1];
    }
  }
  for (int s = 0; s < N / 2; ++s) TCALL(mpmc_sim_step(b, dt));
  TCALL(mpmc_sim_checkpoint_write(b, CK, "footing"));
  mpmc_sim_destroy(&b);
  TCALL(mpmc_sim_checkpoint_read(ctx, CK, &b, NULL));
  /* the box is in contact at the checkpoint (else the test would prove little) */
  double r[2], off[2];
  TCALL(mpmc_sim_get_rigid_reaction(b, 0, r));
  if (!(r[1] > 0.0) || r[1] != fy_half)
    fail_msg("restored reaction of the box %.17g, expected the uninterrupted %.17g (> 0)", r[1],
             fy_half);
  TCALL(mpmc_sim_get_rigid_offset(b, 0, off));
  TCLOSE(off[1], -0.05 * dt * (N / 2), 1e-12);
  /* removal and the barrier range survive */
  const int rr = mpmc_sim_get_rigid_offset(b, 2, off);
  assert_int_equal(rr, MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "removed"));
  double dh, ka, ka0;
  TCALL(mpmc_sim_get_contact_params(b, &dh, &ka));
  TCALL(mpmc_sim_get_contact_params(a, NULL, &ka0));
  if (dh != dhat_set || ka != ka0)
    fail_msg("restored barrier dhat %.17g kappa %.17g, expected %.17g and %.17g", dh, ka, dhat_set,
             ka0);
  for (int s = 0; s < N / 2; ++s) TCALL(mpmc_sim_step(b, dt));
  compare(a, b);
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
}

static void test_bad_block(void **state) {
  (void)state;
  mpmc_sim s = build();
  TCALL(mpmc_sim_checkpoint_write(s, CK, NULL));
  mpmc_sim_destroy(&s);
  /* a body of an unknown kind */
  hid_t f = H5Fopen(CK, H5F_ACC_RDWR, H5P_DEFAULT);
  hid_t ds = H5Dopen2(f, "bodies/bodies", H5P_DEFAULT);
  double rows[3][19];
  H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows);
  rows[1][1] = 7.0;
  H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows);
  H5Dclose(ds);
  H5Fclose(f);
  mpmc_sim back = NULL;
  const int r = mpmc_sim_checkpoint_read(ctx, CK, &back, NULL);
  if (r != MPMC_ERR_FORMAT || !strstr(mpmc_context_last_error(ctx), "rigid body 1: kind 7"))
    fail_msg("expected MPMC_ERR_FORMAT (%d) naming 'rigid body 1: kind 7', got %d: %s",
             MPMC_ERR_FORMAT, r, mpmc_context_last_error(ctx));
  assert_null(back);
  /* a missing dataset */
  f = H5Fopen(CK, H5F_ACC_RDWR, H5P_DEFAULT);
  H5Ldelete(f, "bodies/vertices", H5P_DEFAULT);
  H5Fclose(f);
  const int r2 = mpmc_sim_checkpoint_read(ctx, CK, &back, NULL);
  if (r2 != MPMC_ERR_FORMAT || !strstr(mpmc_context_last_error(ctx), "/bodies"))
    fail_msg("expected MPMC_ERR_FORMAT (%d) naming /bodies, got %d: %s", MPMC_ERR_FORMAT, r2,
             mpmc_context_last_error(ctx));
  assert_null(back);
  remove(CK);
  remove(CK2);
}

int main(void) {
  mpmc_context_create(&ctx);
  test_ctx = ctx;
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_restart_bitwise),
                                     cmocka_unit_test(test_bad_block)};
  const int r = cmocka_run_group_tests(tests, NULL, NULL);
  mpmc_context_destroy(&ctx);
  return r;
}
