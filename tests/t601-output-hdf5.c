/* HDF5 + XDMF output (issue 4): every dataset the XDMF file names exists in the HDF5 file
 * with the shape the XDMF states; the values are the sim's fields (2D positions padded
 * with z = 0); only the fields the scene has are written. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>
#include <hdf5.h>

#include "test_util.h"

#define H5 MPMC_BINARY_DIR "/t601-out.h5"
#define XDMF MPMC_BINARY_DIR "/t601-out.xdmf"

static void read_doubles(hid_t file, const char *path, double *buf) {
  hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
  if (ds < 0) fail_msg("expected dataset %s", path);
  H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
  H5Dclose(ds);
}

static void test_snapshots(void **state) {
  (void)state;
  mpmc_context ctx;
  mpmc_sim sim;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {4, 4}, g[2] = {0, -9.81};
  int mat, n;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.5));
  TCALL(mpmc_sim_set_fbar(sim, 1));
  TCALL(mpmc_sim_set_gravity(sim, g));
  TCALL(mpmc_sim_add_material_neo_hookean(sim, 1e5, 0.3, 1000, &mat));
  const double blo[2] = {1, 0.5}, bhi[2] = {3, 2.5};
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, &n));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  const int top[3] = {n - 3, n - 2, n - 1};
  TCALL(mpmc_sim_add_particle_set(sim, "top<&>", 3, top, NULL));
  mpmc_output out;
  TCALL(mpmc_output_create(sim, H5, XDMF, &out));
  double dt;
  TCALL(mpmc_sim_stable_dt(sim, 0.3, &dt));
  double times[3];
  for (int k = 0; k < 3; ++k) {
    TCALL(mpmc_sim_get_time(sim, &times[k]));
    TCALL(mpmc_output_write(out));
    for (int s = 0; s < 5; ++s) TCALL(mpmc_sim_step(sim, dt));
  }
  TCALL(mpmc_output_destroy(&out));
  assert_null(out);

  char *x = test_slurp(XDMF);
  /* three snapshots, in time order, with their times */
  int ngrid = 0;
  for (const char *p = x; (p = strstr(p, "<Time Value=\"")); ++ngrid) {
    p += 13;
    const double t = strtod(p, NULL);
    if (ngrid < 3 && t != times[ngrid]) fail_msg("snapshot %d: expected time %.17g, got %.17g", ngrid, times[ngrid], t);
  }
  assert_int_equal(ngrid, 3);
  assert_non_null(strstr(x, "TopologyType=\"Polyvertex\""));
  assert_non_null(strstr(x, "Name=\"set_top&lt;&amp;&gt;\""));
  /* no plastic material: no eps_p; F-bar on: Jbar */
  assert_null(strstr(x, "eps_p"));
  assert_non_null(strstr(x, "/snapshot_000002/Jbar"));
  hid_t f = H5Fopen(H5, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) fail_msg("expected to open %s with HDF5", H5);
  /* every DataItem: Dimensions="a[ b]">file.h5:/group/name</DataItem> */
  int nitems = 0;
  for (const char *p = x; (p = strstr(p, "<DataItem "));) {
    const char *dim = strstr(p, "Dimensions=\"");
    const char *body = strchr(p, '>') + 1;
    const char *end = strstr(body, "</DataItem>");
    assert_true(dim && end && dim < body);
    long d0 = 0, d1 = 0;
    char *e;
    d0 = strtol(dim + 12, &e, 10);
    if (*e == ' ') d1 = strtol(e + 1, &e, 10);
    char ref[512];
    snprintf(ref, sizeof ref, "%.*s", (int)(end - body), body);
    const char *colon = strstr(ref, ".h5:");
    if (!colon || strncmp(ref, "t601-out.h5:", 12) != 0)
      fail_msg("expected a reference to t601-out.h5 relative to the XDMF file, got '%s'", ref);
    char path[512];
    snprintf(path, sizeof path, "%s", colon + 4);
    /* XML escapes in set names */
    char *amp = strstr(path, "&lt;&amp;&gt;");
    if (amp) memmove(amp + 3, amp + 13, strlen(amp + 13) + 1), memcpy(amp, "<&>", 3);
    hid_t ds = H5Dopen2(f, path, H5P_DEFAULT);
    if (ds < 0) fail_msg("expected dataset %s named by the XDMF file", path);
    hid_t sp = H5Dget_space(ds);
    hsize_t dims[2] = {0, 0};
    const int rank = H5Sget_simple_extent_dims(sp, dims, NULL);
    if (rank != (d1 ? 2 : 1) || (long)dims[0] != d0 || (rank == 2 && (long)dims[1] != d1))
      fail_msg("%s: XDMF says [%ld %ld], HDF5 has rank %d [%llu %llu]", path, d0, d1, rank,
               (unsigned long long)dims[0], (unsigned long long)dims[1]);
    H5Sclose(sp);
    H5Dclose(ds);
    ++nitems;
    p = end;
  }
  /* position, velocity, stress, mean_stress, J, Jbar, mass, material, set: 9 per snapshot */
  assert_int_equal(nitems, 27);
  /* values: the last snapshot's positions are the sim's positions before its last 5 steps;
   * check the first snapshot against the seeding instead (x0) */
  double *pos = malloc(sizeof(double) * 3 * (size_t)n), *x0, *stress = malloc(sizeof(double) * 6 * (size_t)n),
         *mean = malloc(sizeof(double) * (size_t)n);
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, NULL));
  read_doubles(f, "/snapshot_000000/position", pos);
  for (int q = 0; q < n; ++q)
    if (pos[3 * q] != x0[2 * q] || pos[3 * q + 1] != x0[2 * q + 1] || pos[3 * q + 2] != 0.0)
      fail_msg("point %d: expected (%g, %g, 0), got (%g, %g, %g)", q, x0[2 * q], x0[2 * q + 1],
               pos[3 * q], pos[3 * q + 1], pos[3 * q + 2]);
  read_doubles(f, "/snapshot_000002/stress", stress);
  read_doubles(f, "/snapshot_000002/mean_stress", mean);
  for (int q = 0; q < n; ++q) {
    const double m = (stress[6 * q] + stress[6 * q + 1] + stress[6 * q + 2]) / 3;
    if (fabs(mean[q] - m) > 1e-12 * (fabs(m) + 1)) fail_msg("point %d: mean stress %g, expected %g", q, mean[q], m);
  }
  unsigned char *mark = malloc((size_t)n);
  hid_t ds = H5Dopen2(f, "/snapshot_000001/set_top<&>", H5P_DEFAULT);
  H5Dread(ds, H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, mark);
  H5Dclose(ds);
  int members = 0;
  for (int q = 0; q < n; ++q) members += mark[q];
  assert_int_equal(members, 3);
  assert_int_equal(mark[n - 1], 1);
  double t;
  hid_t grp = H5Gopen2(f, "/snapshot_000001", H5P_DEFAULT);
  hid_t a = H5Aopen(grp, "time", H5P_DEFAULT);
  H5Aread(a, H5T_NATIVE_DOUBLE, &t);
  H5Aclose(a);
  H5Gclose(grp);
  if (t != times[1]) fail_msg("expected /snapshot_000001 time %.17g, got %.17g", times[1], t);
  H5Fclose(f);
  free(pos);
  free(stress);
  free(mean);
  free(mark);
  free(x);
  /* bad input */
  assert_int_equal(mpmc_output_create(sim, MPMC_BINARY_DIR "/no/such/dir/x.h5", XDMF, &out), MPMC_ERR_IO);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "no/such/dir/x.h5"));
  assert_int_equal(mpmc_output_create(sim, H5, H5, &out), MPMC_ERR_ARG);
  assert_non_null(strstr(mpmc_context_last_error(ctx), "same file"));
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  test_ctx = NULL;
  remove(H5);
  remove(XDMF);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_snapshots)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
