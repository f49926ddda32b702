/* t703: a 3D column (1 x 1 x 4 m, h = 0.125 m, 2 x 2 x 2 points per cell: 16,384 points,
 * several thousand per rank, enough for the threads' own grids in P2G), quadratic B-splines
 * and F-bar's default (anchored) form, the points sorted by cell every 10 steps, two OpenMP
 * threads per rank, released from rest under gravity: 60 steps over MPI against the same run
 * in one process (two threads), by global id.  Bound: 1e-12 of each field's magnitude, or 3 x
 * what reversing the order of the points changes in one process (mpi_test.h, t701).  Run
 * with 2 and 3 ranks (tests/mpi.cmake). */
#include "mpi_test.h"

#define STEPS 60

static void column3(MPI_Comm comm, int reverse, int *ntotal, double *out) {
  const double h = 0.125;
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  mpmc_sim sim = test_sim(ctx, comm, 3);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 4.5};
  MCALL(ctx, mpmc_sim_set_grid(sim, lo, hi, h));
  MCALL(ctx, mpmc_sim_set_basis(sim, MPMC_BASIS_BSPLINE2));
  MCALL(ctx, mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  const double gv[3] = {0, 0, -9.81};
  MCALL(ctx, mpmc_sim_set_gravity(sim, gv));
  MCALL(ctx, mpmc_sim_set_threads(sim, 2));
  MCALL(ctx, mpmc_sim_set_sort_interval(sim, 10));
  int mat;
  MCALL(ctx, mpmc_sim_add_material_hencky(sim, 1e6, 0.3, 2000.0, &mat));
  const int m = 16, mz = 64, n = m * m * mz; /* 2 points per cell and axis */
  double *x = malloc(sizeof(double) * 3 * n), *vol = malloc(sizeof(double) * n);
  const double dx = h / 2;
  for (int k = 0, q = 0; k < mz; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i, ++q) {
        const int qq = reverse ? n - 1 - q : q;
        x[3 * qq] = (i + 0.5) * dx;
        x[3 * qq + 1] = (j + 0.5) * dx;
        x[3 * qq + 2] = (k + 0.5) * dx;
        vol[qq] = dx * dx * dx;
      }
  MCALL(ctx, mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  for (int f = 0; f < 4; ++f) MCALL(ctx, mpmc_sim_add_wall_face(sim, f, MPMC_WALL_SLIP, NULL));
  MCALL(ctx, mpmc_sim_add_wall_face(sim, 4, MPMC_WALL_FIXED, NULL));
  double dt;
  MCALL(ctx, mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < STEPS; ++s) MCALL(ctx, mpmc_sim_step(sim, dt));
  *ntotal = n;
  test_gather(ctx, sim, 3, n, comm != MPI_COMM_NULL, out);
  if (reverse && out)
    for (int i = 0; i < n / 2; ++i)
      for (int k = 0; k < TEST_REC(3); ++k) {
        const double t = out[(size_t)i * TEST_REC(3) + k];
        out[(size_t)i * TEST_REC(3) + k] = out[(size_t)(n - 1 - i) * TEST_REC(3) + k];
        out[(size_t)(n - 1 - i) * TEST_REC(3) + k] = t;
      }
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

int main(int argc, char **argv) {
  test_init(&argc, &argv);
  const size_t len = (size_t)16 * 16 * 64 * TEST_REC(3);
  double *par = test_rank == 0 ? malloc(sizeof(double) * len) : NULL;
  int n;
  column3(MPI_COMM_WORLD, 0, &n, par);
  if (test_rank == 0) {
    double *ser = malloc(sizeof(double) * len), *rev = malloc(sizeof(double) * len);
    column3(MPI_COMM_NULL, 0, &n, ser);
    column3(MPI_COMM_NULL, 1, &n, rev);
    double rel[3], band[3];
    test_compare(3, n, par, ser, rel);
    test_compare(3, n, rev, ser, band);
    for (int f = 0; f < 3; ++f) test_failed |= !(rel[f] <= fmax(1e-12, 3 * band[f]));
    if (test_failed || test_verbose())
      printf("3D column, %d points, %d ranks x 2 threads, sorted every 10 steps, %d steps: max "
             "|difference| / max |value| against one process: position %.2g, velocity %.2g, "
             "stress %.2g (one process, points reversed: %.2g, %.2g, %.2g)%s\n",
             n, test_size, STEPS, rel[0], rel[1], rel[2], band[0], band[1], band[2],
             test_failed ? "  <- expected at most max(1e-12, 3 x the latter)" : "");
    free(ser);
    free(rev);
  }
  free(par);
  MPI_Bcast(&test_failed, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Finalize();
  return test_failed;
}
