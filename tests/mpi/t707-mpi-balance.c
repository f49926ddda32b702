/* t707: load balance over MPI (mpmc_sim_set_mpi_balance; docs/mpi.md) and the traffic
 * counter (mpmc_sim_get_mpi_traffic).
 * A block 12 m tall (2 x 2 points per 0.5 m cell, Hencky, F-bar anchored) starts in the top
 * half of a 30 m tall grid at 10 m/s down (5 % faster at its top: it rings), under gravity,
 * and falls 11 m in 400 steps: with fixed slabs the mass leaves the upper ranks.  Run once
 * with fixed slabs and once balancing every 10 steps, against the run in one process:
 *  - with balance, positions, velocities and stresses equal one process within 1e-12 of
 *    each field's largest magnitude, by global id, no point lost or doubled;
 *  - the cuts moved (mpmc_sim_get_mpi_slab differs from the grid's even cuts), and the
 *    balances kept the slabs 5 cells wide or more and clear of the base's mirrored wall;
 *  - the imbalance (most points on a rank over the mean) right after each balance is at
 *    most 1.25 (whole cells: a cell row holds 8 of the 192 points), and at the end it is
 *    below the fixed slabs'; balancing beyond an imbalance of 1.3 instead balances, and
 *    no step ends more than 0.1 beyond it (a step's motion); bad arguments are refused;
 *  - the traffic counter: one halo message per neighbour per exchange (two exchanges a step
 *    with F-bar), their bytes, and migration's bytes, more with balance than without.
 * MPMC_TEST_VERBOSE=1 prints the imbalance over the run with and without balance.  Run with
 * 2 and 3 ranks (tests/mpi.cmake). */
#include "mpi_test.h"

#define TOL 1e-12
#define STEPS 400
#define EVERY 10
#define THRESHOLD 1.3

/* A block 12 m tall at y in [14, 26], falling and stretching (test_block). */
static mpmc_sim block(mpmc_context ctx, MPI_Comm comm, int *n) {
  return test_block(ctx, comm, 14.0, 26.0, -10.0, 0.05, n);
}

typedef struct {
  double imb_end, imb_mean, imb_max, imb_after_max; /* after_max: right after the balances */
  double halo_bytes, migrated_bytes;
  long halo_msgs, migrate_msgs, balances;
  int cut_moved, narrowest, total;
} run_info;

/* The block over MPI_COMM_WORLD, balanced every EVERY steps (1), beyond an imbalance of
 * THRESHOLD (2) or not (0); records into out (rank 0). */
static void run(int balanced, double *out, int *n, run_info *ri) {
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  mpmc_sim sim = block(ctx, MPI_COMM_WORLD, n);
  int lo0, hi0;
  MCALL(ctx, mpmc_sim_get_mpi_slab(sim, NULL, NULL, NULL, &lo0, &hi0));
  if (balanced) {
    /* bad input: a clear error naming the parameter */
    int e1 = mpmc_sim_set_mpi_balance(sim, -1, 0.0), e2 = mpmc_sim_set_mpi_balance(sim, 0, 0.5);
    if (e1 != MPMC_ERR_ARG || e2 != MPMC_ERR_ARG || !strstr(mpmc_context_last_error(ctx), "threshold")) {
      fprintf(stderr, "rank %d: mpmc_sim_set_mpi_balance(-1, 0) -> %d, (0, 0.5) -> %d (%s), "
              "expected MPMC_ERR_ARG naming the parameter\n", test_rank, e1, e2,
              mpmc_context_last_error(ctx));
      test_failed = 1;
    }
    MCALL(ctx, mpmc_sim_set_mpi_balance(sim, balanced == 1 ? EVERY : 0, balanced == 1 ? 0.0 : THRESHOLD));
  }
  memset(ri, 0, sizeof *ri);
  ri->narrowest = 1 << 30;
  double sum = 0.0;
  for (int s = 0; s < STEPS; ++s) {
    MCALL(ctx, mpmc_sim_step(sim, 2e-3));
    double imb;
    long nb;
    MCALL(ctx, mpmc_sim_get_mpi_imbalance(sim, &imb, &nb));
    sum += imb;
    ri->imb_max = fmax(ri->imb_max, imb);
    int lo, hi;
    MCALL(ctx, mpmc_sim_get_mpi_slab(sim, NULL, NULL, NULL, &lo, &hi));
    ri->cut_moved |= lo != lo0 || hi != hi0;
    ri->narrowest = hi - lo < ri->narrowest ? hi - lo : ri->narrowest;
    /* a balance runs before step k EVERY + 1: measure after the step that follows it */
    if (balanced == 1 && s % EVERY == 0 && s > 0) ri->imb_after_max = fmax(ri->imb_after_max, imb);
  }
  MCALL(ctx, mpmc_sim_get_mpi_imbalance(sim, &ri->imb_end, &ri->balances));
  ri->imb_mean = sum / STEPS;
  MCALL(ctx, mpmc_sim_get_mpi_traffic(sim, &ri->halo_bytes, &ri->halo_msgs, &ri->migrated_bytes,
                                      &ri->migrate_msgs));
  int nl, moved = ri->cut_moved, narrow = ri->narrowest;
  MCALL(ctx, mpmc_sim_get_num_particles(sim, &nl));
  MPI_Allreduce(&nl, &ri->total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&moved, &ri->cut_moved, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
  MPI_Allreduce(&narrow, &ri->narrowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  test_gather(ctx, sim, 2, *n, 1, out);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

int main(int argc, char **argv) {
  test_init(&argc, &argv);
  const int nmax = 2 * 2 * 24 * 2;
  double *bal = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  double *fix = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  int n;
  run_info rb, rf, rt;
  run(1, bal, &n, &rb);
  run(0, fix, &n, &rf);
  run(2, NULL, &n, &rt); /* by threshold: balances, and the imbalance stays near it */
  /* the traffic: this rank's neighbours, one message each per exchange, two a step */
  const int nb = (test_rank > 0) + (test_rank + 1 < test_size);
  test_failed |= rb.halo_msgs != 2L * STEPS * nb || rf.halo_msgs != 2L * STEPS * nb ||
            (nb > 0 && !(rb.halo_bytes > 0)) || rb.migrate_msgs <= rf.migrate_msgs;
  int bad = test_failed;
  double mig[2] = {rb.migrated_bytes, rf.migrated_bytes};
  MPI_Allreduce(MPI_IN_PLACE, mig, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  bad |= !(mig[0] > mig[1]);
  if (bad)
    fprintf(stderr, "rank %d: traffic: halo %ld messages (expected %d), %.0f bytes; migration "
            "%ld messages, %.0f bytes with balance, %ld and %.0f without\n", test_rank,
            rb.halo_msgs, 2 * STEPS * nb, rb.halo_bytes, rb.migrate_msgs, rb.migrated_bytes,
            rf.migrate_msgs, rf.migrated_bytes);
  MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
  if (test_rank == 0) {
    mpmc_context ctx;
    mpmc_context_create(&ctx);
    double *ser = malloc(sizeof(double) * (size_t)n * TEST_REC(2));
    mpmc_sim one = block(ctx, MPI_COMM_NULL, &n);
    for (int s = 0; s < STEPS; ++s) MCALL(ctx, mpmc_sim_step(one, 2e-3));
    test_gather(ctx, one, 2, n, 0, ser);
    mpmc_sim_destroy(&one);
    mpmc_context_destroy(&ctx);
    double rel[3], relf[3];
    test_compare(2, n, bal, ser, rel);
    test_compare(2, n, fix, ser, relf);
    const int bad_fields = !(rel[0] <= TOL && rel[1] <= TOL && rel[2] <= TOL) || rb.total != n;
    const int bad_cuts = !rb.cut_moved || rb.balances < 1 || rb.narrowest < 5 || rf.cut_moved;
    const int bad_imb = !(rb.imb_after_max <= 1.25) || !(rb.imb_end < rf.imb_end) ||
                        rt.balances < 1 || !(rt.imb_max <= THRESHOLD + 0.1);
    bad |= bad_fields || bad_cuts || bad_imb;
    if (bad || test_verbose()) {
      printf("falling block on %d ranks, %d points, %d steps: imbalance (max/mean points) with "
             "fixed slabs: mean %.3f, max %.3f, end %.3f; balanced every %d steps: mean %.3f, "
             "max %.3f, after a balance at most %.3f, end %.3f (%ld balances, narrowest slab %d "
             "cells); beyond %.1f: %ld balances, mean %.3f, max %.3f, end %.3f%s%s\n",
             test_size, n, STEPS, rf.imb_mean, rf.imb_max, rf.imb_end, EVERY, rb.imb_mean,
             rb.imb_max, rb.imb_after_max, rb.imb_end, rb.balances, rb.narrowest, THRESHOLD,
             rt.balances, rt.imb_mean, rt.imb_max, rt.imb_end,
             bad_cuts ? "  <- the cuts did not move, or moved without balance, or a slab < 5" : "",
             bad_imb ? "  <- imbalance after a balance > 1.25, not below fixed slabs', or "
                       "the threshold did not balance" : "");
      printf("  against one process: max |difference| / max |value|: balanced: position %.2g, "
             "velocity %.2g, stress %.2g; fixed slabs: %.2g, %.2g, %.2g; %d points%s\n",
             rel[0], rel[1], rel[2], relf[0], relf[1], relf[2], rb.total,
             bad_fields ? "  <- expected <= 1e-12 and every point once" : "");
      printf("  rank 0's traffic: halo %ld messages, %.0f bytes; migration with balance %ld "
             "messages, %.0f bytes, without %ld, %.0f bytes\n", rb.halo_msgs, rb.halo_bytes,
             rb.migrate_msgs, rb.migrated_bytes, rf.migrate_msgs, rf.migrated_bytes);
    }
  }
  free(bal);
  free(fix);
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Finalize();
  return bad;
}
