/* t702: points migrating across several ranks, ranks without points, and failures on a
 * rank other than 0.
 *  - A block falls from the top rank's slab through every other (initial velocity 20 m/s
 *    down, 5 % faster at its top than at its bottom: it rings; gravity) for 400 steps: the ranks below start without points, the top one ends
 *    without; positions, velocities and stresses equal the run in one process to 1e-12 of
 *    each field's magnitude, by global id, and no point is lost or doubled.
 *  - The block thrown up out of the grid: the top rank finds the point that left, and every
 *    rank returns MPMC_ERR_OUTSIDE with the same message, naming the rank and the point's
 *    global id.
 *  - On 3 ranks or more, the block moving 25 m in one (forced) step, from the top rank's
 *    slab past the middle one's: MPMC_ERR_UNSTABLE, "more than one subdomain", on every rank.
 * Run with 2 and 3 ranks (tests/mpi.cmake). */
#include "mpi_test.h"

#define TOL 1e-12

/* The ringing block of 2 x 4 cells at y in [26, 28] (test_block). */
static mpmc_sim block(mpmc_context ctx, MPI_Comm comm, double vy, double stretch, int *n) {
  return test_block(ctx, comm, 26.0, 28.0, vy, stretch, n);
}

/* The falling block; 1 if it failed. */
static int fall(void) {
  const int steps = 400;
  const double dt = 2e-3;
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  int n, nl, bad = 0;
  mpmc_sim sim = block(ctx, MPI_COMM_WORLD, -20.0, 0.05, &n);
  /* which ranks held points at some step: every one of them must have */
  int held = 0, first_empty = 0;
  MCALL(ctx, mpmc_sim_get_num_particles(sim, &nl));
  first_empty = nl == 0;
  for (int s = 0; s < steps; ++s) {
    MCALL(ctx, mpmc_sim_step(sim, dt));
    MCALL(ctx, mpmc_sim_get_num_particles(sim, &nl));
    held |= nl > 0;
  }
  int total = nl, empties = first_empty, all_held = held;
  MPI_Allreduce(&nl, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&first_empty, &empties, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&held, &all_held, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  double *par = test_rank == 0 ? malloc(sizeof(double) * (size_t)n * TEST_REC(2)) : NULL;
  test_gather(ctx, sim, 2, n, 1, par);
  mpmc_sim_destroy(&sim);
  if (test_rank == 0) {
    double *ser = malloc(sizeof(double) * (size_t)n * TEST_REC(2));
    mpmc_sim one = block(ctx, MPI_COMM_NULL, -20.0, 0.05, &n);
    for (int s = 0; s < steps; ++s) MCALL(ctx, mpmc_sim_step(one, dt));
    test_gather(ctx, one, 2, n, 0, ser);
    double *x;
    MCALL(ctx, mpmc_sim_get_field(one, MPMC_FIELD_POSITION, &x, NULL));
    const double yend = x[1];
    mpmc_sim_destroy(&one);
    double rel[3];
    test_compare(2, n, par, ser, rel);
    bad = !(rel[0] <= TOL && rel[1] <= TOL && rel[2] <= TOL) || total != n ||
          empties != test_size - 1 || !all_held;
    if (bad || test_verbose())
      printf("falling block on %d ranks: %d points (expected %d), %d ranks empty at the start "
             "(expected %d), every rank held points at some step: %s; the first point from "
             "y = 26.25 to %.2f; max |difference| / max |value| against one process: "
             "position %.2g, velocity %.2g, stress %.2g (expected <= 1e-12)\n",
             test_size, total, n, empties, test_size - 1, all_held ? "yes" : "no", yend, rel[0],
             rel[1], rel[2]);
    free(ser);
  }
  free(par);
  mpmc_context_destroy(&ctx);
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return bad;
}

/* A step that fails: every rank must return code with the same message, which names the
 * rank that found it and contains want; 1 if not. */
static int failure(const char *what, double vy, double dt, int code, const char *want) {
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  int n;
  mpmc_sim sim = block(ctx, MPI_COMM_WORLD, vy, 0.0, &n);
  MCALL(ctx, mpmc_sim_set_force_dt(sim, 1));
  MCALL(ctx, mpmc_sim_set_energy_monitor(sim, -1.0));
  int err = 0, steps = 0;
  while (!err && steps < 100) err = mpmc_sim_step(sim, dt), ++steps;
  char msg[4096], root[4096];
  snprintf(msg, sizeof msg, "%s", mpmc_context_last_error(ctx));
  memcpy(root, msg, sizeof root);
  MPI_Bcast(root, sizeof root, MPI_CHAR, 0, MPI_COMM_WORLD);
  char rank_tag[32];
  snprintf(rank_tag, sizeof rank_tag, "rank %d of %d", test_size - 1, test_size);
  int bad = err != code || strcmp(msg, root) != 0 || !strstr(msg, want) ||
            !strstr(msg, rank_tag) || !strstr(msg, "(id ");
  int any = 0;
  MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
  if (bad || (test_rank == 0 && test_verbose()))
    printf("%s on %d ranks, rank %d: step %d returned %d (expected %d): %s%s\n", what, test_size,
           test_rank, steps, err, code, msg,
           bad ? "  <- expected the same message on every rank, from the top rank, with the "
                 "point's id" : "");
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  return any;
}

int main(int argc, char **argv) {
  test_init(&argc, &argv);
  test_failed |= fall();
  test_failed |= failure("block thrown out of the grid", 200.0, 2e-3, MPMC_ERR_OUTSIDE,
                         "left the grid box");
  if (test_size >= 3)
    test_failed |= failure("block across two slabs in a step", -2500.0, 1e-2, MPMC_ERR_UNSTABLE,
                           "more than one subdomain");
  MPI_Allreduce(MPI_IN_PLACE, &test_failed, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
  MPI_Finalize();
  return test_failed;
}
