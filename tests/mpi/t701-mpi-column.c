/* t701: the self-weight column (as t502: plane strain, slip side walls, fixed base, gravity,
 * local damping) for 100 steps over MPI against the same run in one process, point by point
 * by global id, for every basis and every F-bar form (the halo sums of mass, momentum, force
 * and F-bar's nodal volumes across the slab boundaries); and once in a grid twice as tall,
 * where the upper ranks' slabs hold no point; and once from the geostatic state
 * (mpmc_sim_set_geostatic_stress, K0 = 0.5), whose columns cross every slab.  Run with 2 and 3 ranks (tests/mpi.cmake).
 * Tolerance: the largest difference of each field (positions, velocities, stresses) at most
 * 1e-12 of its largest magnitude, or, where the run in one process is itself that sensitive
 * to the order of its sums, 3 x what it changes by when only the order of its points is
 * reversed: with F-bar on, reversing the points changes the stresses after 100 steps by up
 * to 1.6e-11 (the halo sums change the same sums' order, by up to 1.3e-11 measured). */
#include "mpi_test.h"

#define STEPS 100
#define TOL 1e-12

static const char *basis_name[4] = {"linear", "uGIMP", "bspline2", "bspline3"};
static const char *fbar_name[5] = {"off", "paper", "total", "stable", "anchored"};

/* The column of height H in a grid of height Hg, on comm or (MPI_COMM_NULL) alone; STEPS
 * steps of dt; the points' records into out (rank 0). */
static void column(MPI_Comm comm, int basis, int fbar, double Hg, double k0, double dt, int reverse,
                   int *ntotal, double *out) {
  const double H = 10.0, W = 1.0, h = 0.5, rho = 2000.0, E = 10e6, nu = 0.3, g = 9.81;
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  mpmc_sim sim = test_sim(ctx, comm, 2);
  const double lo[2] = {0, 0}, hi[2] = {W, Hg};
  MCALL(ctx, mpmc_sim_set_grid(sim, lo, hi, h));
  MCALL(ctx, mpmc_sim_set_basis(sim, basis));
  MCALL(ctx, mpmc_sim_set_fbar(sim, fbar));
  const double gv[2] = {0, -g};
  MCALL(ctx, mpmc_sim_set_gravity(sim, gv));
  MCALL(ctx, mpmc_sim_set_damping(sim, 0.1));
  MCALL(ctx, mpmc_sim_set_flip_blend(sim, 0.95));
  MCALL(ctx, mpmc_sim_set_threads(sim, 1));
  int mat;
  MCALL(ctx, mpmc_sim_add_material_hencky(sim, E, nu, rho, &mat));
  double *x, *vol;
  const double plo[2] = {0, 0}, phi[2] = {W, H};
  const int n = test_lattice2(plo, phi, h, 2, &x, &vol);
  if (reverse) /* the points in reverse order: the same problem, other orders of the sums */
    for (int i = 0; i < n / 2; ++i)
      for (int a = 0; a < 2; ++a) {
        const double t = x[2 * i + a];
        x[2 * i + a] = x[2 * (n - 1 - i) + a];
        x[2 * (n - 1 - i) + a] = t;
      }
  MCALL(ctx, mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  test_walls2(ctx, sim);
  if (k0 > 0) MCALL(ctx, mpmc_sim_set_geostatic_stress(sim, k0));
  for (int s = 0; s < STEPS; ++s) MCALL(ctx, mpmc_sim_step(sim, dt));
  *ntotal = n;
  test_gather(ctx, sim, 2, n, comm != MPI_COMM_NULL, out);
  if (reverse && out) /* back to the ids of the points in order */
    for (int i = 0; i < n / 2; ++i)
      for (int k = 0; k < TEST_REC(2); ++k) {
        const double t = out[i * TEST_REC(2) + k];
        out[i * TEST_REC(2) + k] = out[(n - 1 - i) * TEST_REC(2) + k];
        out[(n - 1 - i) * TEST_REC(2) + k] = t;
      }
  free(x);
  free(vol);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

/* One case on MPI_COMM_WORLD against rank 0's run alone; 1 if it failed. */
static int check(int basis, int fbar, double Hg, double k0, double *worst) {
  const double dt = 1e-4; /* below 0.3 h / c for E = 10 MPa, nu = 0.3 */
  const int nmax = 4 * 2 * 20 * 2;
  double *par = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  double *ser = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  double *rev = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  int n = 0;
  column(MPI_COMM_WORLD, basis, fbar, Hg, k0, dt, 0, &n, par);
  int bad = 0;
  if (test_rank == 0) {
    column(MPI_COMM_NULL, basis, fbar, Hg, k0, dt, 0, &n, ser);
    column(MPI_COMM_NULL, basis, fbar, Hg, k0, dt, 1, &n, rev);
    double rel[3], band[3], tol[3];
    test_compare(2, n, par, ser, rel);
    test_compare(2, n, rev, ser, band);
    for (int f = 0; f < 3; ++f) {
      tol[f] = fmax(TOL, 3 * band[f]);
      bad |= !(rel[f] <= tol[f]);
      worst[f] = fmax(worst[f], rel[f]);
    }
    if (bad || test_verbose())
      printf("column %-8s F-bar %-8s grid height %4.1f K0 %.2f on %d ranks: max |difference| / max "
             "|value| against one process: position %.2g, velocity %.2g, stress %.2g (one "
             "process, points reversed: %.2g, %.2g, %.2g)%s\n",
             basis_name[basis], fbar_name[fbar], Hg, k0, test_size, rel[0], rel[1], rel[2], band[0],
             band[1], band[2], bad ? "  <- expected at most max(1e-12, 3 x the latter)" : "");
  }
  free(rev);
  free(par);
  free(ser);
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return bad;
}

int main(int argc, char **argv) {
  test_init(&argc, &argv);
  double worst[3] = {0, 0, 0};
  for (int b = 0; b < 4; ++b)
    for (int f = 0; f <= 4; ++f) test_failed |= check(b, f, 11.0, 0.0, worst);
  /* twice as tall: the top ranks' slabs are empty at first */
  test_failed |= check(2, 4, 22.0, 0.0, worst);
  /* the geostatic state at once: each column's overburden summed over the ranks' points */
  test_failed |= check(2, 4, 11.0, 0.5, worst);
  if (test_rank == 0 && test_verbose())
    printf("t701 on %d ranks: worst over the cases: position %.3g, velocity %.3g, stress %.3g\n",
           test_size, worst[0], worst[1], worst[2]);
  MPI_Finalize();
  return test_failed;
}
