/* Distributed runs over MPI (issue 47; docs/mpi.md).  Compiled into every build; the
 * functions below do something only in a build with MPMC_HAVE_MPI and for a simulation made
 * by mpmc_sim_create_mpi (sim->dd set): a serial run never calls MPI.
 *
 * Decomposition.  The grid's cells along its longest axis (ties: the outermost) are cut
 * into one slab per rank, cut[r] .. cut[r + 1] - 1, as even as whole cells allow. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

#ifndef MPMC_HAVE_MPI

int mpmc_dd_setup(struct mpmc_sim_s *sim) { return (void)sim, MPMC_SUCCESS; }
void mpmc_dd_free(struct mpmc_sim_s *sim) { (void)sim; }

#else /* MPMC_HAVE_MPI */

#include <mpi.h>

#include "mpmc_mpi.h"

struct mpmc_dd_s {
  MPI_Comm comm;      /* a duplicate of the caller's: our messages never meet theirs */
  int rank, size;
  int axis;           /* the slab axis; -1 until the grid is set                        */
  int *cut;           /* [size + 1] each rank's first cell along axis; cut[size]: cells  */
};

static int create(mpmc_context ctx, MPI_Comm comm, int dim, mpmc_sim *sim) {
  if (!ctx || !sim) return ctx ? MPMC_ERROR(ctx, MPMC_ERR_ARG, "sim pointer is NULL") : MPMC_ERR_ARG;
  int init = 0;
  MPI_Initialized(&init);
  MPMC_CHECK(init, ctx, MPMC_ERR_STATE, "mpmc_sim_create_mpi: call MPI_Init first");
  MPMC_CHECK(comm != MPI_COMM_NULL, ctx, MPMC_ERR_ARG, "mpmc_sim_create_mpi: comm is MPI_COMM_NULL");
  struct mpmc_dd_s *dd = calloc(1, sizeof *dd);
  MPMC_CHECK(dd, ctx, MPMC_ERR_MEMORY, "cannot allocate the decomposition");
  dd->axis = -1;
  MPI_Comm_dup(comm, &dd->comm);
  MPI_Comm_rank(dd->comm, &dd->rank);
  MPI_Comm_size(dd->comm, &dd->size);
  mpmc_sim s = NULL;
  const int err = mpmc_sim_create(ctx, dim, &s);
  if (err) {
    MPI_Comm_free(&dd->comm);
    free(dd);
    return err;
  }
  s->dd = dd;
  *sim = s;
  return MPMC_SUCCESS;
}

/**
 * @brief Create a simulation distributed over the ranks of comm (collective; mpmc_mpi.h).
 *        The communicator is duplicated; the caller may free its own.
 * @param comm an intra-communicator; MPI must be initialised
 */
int mpmc_sim_create_mpi(mpmc_context ctx, MPI_Comm comm, int dim, mpmc_sim *sim) {
  return create(ctx, comm, dim, sim);
}

/** @brief mpmc_sim_create_mpi for Fortran: comm is MPI's Fortran handle (MPI_Comm_f2c). */
int mpmc_sim_create_mpi_f(mpmc_context ctx, MPI_Fint comm, int dim, mpmc_sim *sim) {
  return create(ctx, MPI_Comm_f2c(comm), dim, sim);
}

/** @brief This rank's place in the decomposition (mpmc_mpi.h); NULL arguments are skipped. */
int mpmc_sim_get_mpi_slab(const mpmc_sim sim, int *rank, int *nranks, int *axis, int *cell_lo,
                          int *cell_hi) {
  if (!sim) return MPMC_ERR_ARG;
  const struct mpmc_dd_s *dd = sim->dd;
  MPMC_CHECK(dd, sim->ctx, MPMC_ERR_STATE, "not a simulation of mpmc_sim_create_mpi");
  MPMC_CHECK(dd->axis >= 0, sim->ctx, MPMC_ERR_STATE, "the decomposition needs the grid: set it first");
  if (rank) *rank = dd->rank;
  if (nranks) *nranks = dd->size;
  if (axis) *axis = dd->axis;
  if (cell_lo) *cell_lo = dd->cut[dd->rank];
  if (cell_hi) *cell_hi = dd->cut[dd->rank + 1];
  return MPMC_SUCCESS;
}

void mpmc_dd_free(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd) return;
  int fin = 0;
  MPI_Finalized(&fin);
  if (!fin) MPI_Comm_free(&dd->comm);
  free(dd->cut);
  free(dd);
  sim->dd = NULL;
}

/* The slabs of the grid just set (mpmc_sim_set_grid). */
int mpmc_dd_setup(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd) return MPMC_SUCCESS;
  const mpmc_grid *g = &sim->grid;
  int ax = sim->dim - 1;
  for (int a = sim->dim - 2; a >= 0; --a)
    if (g->n[a] > g->n[ax]) ax = a;
  const int cells = g->n[ax] - 1;
  MPMC_CHECK(cells >= MPMC_DD_MIN_CELLS * dd->size, sim->ctx, MPMC_ERR_ARG,
             "the grid has %d cells (ghost layers included) along its longest axis %d: too few "
             "for %d ranks, whose slabs need %d cells each; use at most %d ranks or a finer grid",
             cells, ax, dd->size, MPMC_DD_MIN_CELLS, cells / MPMC_DD_MIN_CELLS);
  int *cut = realloc(dd->cut, sizeof(int) * (size_t)(dd->size + 1));
  MPMC_CHECK(cut, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the slab cuts");
  for (int r = 0; r <= dd->size; ++r) cut[r] = (int)((long long)cells * r / dd->size);
  dd->cut = cut;
  dd->axis = ax;
  return MPMC_SUCCESS;
}

#endif /* MPMC_HAVE_MPI */
