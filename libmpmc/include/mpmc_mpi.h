/* libmpmc over MPI: a simulation bound to a communicator (docs/mpi.md).
 *
 * Only in a build with -DMPMC_WITH_MPI=ON (libmpmc then links MPI).  The grid is cut into
 * slabs of whole cells along its longest axis, one per rank; each rank keeps the material
 * points that lie in its slab and the nodes their stencils reach.  Every other function of
 * mpmc.h takes such a simulation unchanged and is collective over the communicator: set-up,
 * adding or seeding points (every rank passes the same points and keeps those of its slab;
 * their ids, mpmc_sim_get_particle_ids, are their global indices), stepping.  The fields
 * (mpmc_sim_get_field) are the rank's own points. */
#ifndef MPMC_MPI_H
#define MPMC_MPI_H

#include <mpi.h>

#include "mpmc.h"

#ifdef __cplusplus
extern "C" {
#endif

int mpmc_sim_create_mpi(mpmc_context ctx, MPI_Comm comm, int dim, mpmc_sim *sim);
/* The same for Fortran: comm is MPI's Fortran handle (mpi_f08's comm%MPI_VAL, or the
 * integer of the mpi module). */
int mpmc_sim_create_mpi_f(mpmc_context ctx, MPI_Fint comm, int dim, mpmc_sim *sim);
/* A simulation over comm from a checkpoint (mpmc_sim_checkpoint_write) written by any number
 * of ranks or by one process: each rank keeps the points of its slab, with their global ids
 * and every field (collective; checkpoint.c).  _f: MPI's Fortran handle. */
int mpmc_sim_checkpoint_read_mpi(mpmc_context ctx, MPI_Comm comm, const char *path, mpmc_sim *sim,
                                 char **meta);
int mpmc_sim_checkpoint_read_mpi_f(mpmc_context ctx, MPI_Fint comm, const char *path,
                                   mpmc_sim *sim, char **meta);
/* This rank's place in the decomposition: its rank and the number of ranks, the slab axis
 * and the slab's cells [cell_lo, cell_hi) along it (grid cell 0 is the first ghost cell
 * below the box; a load balance moves them); the simulation's grid must be set.  Any
 * argument may be NULL. */
int mpmc_sim_get_mpi_slab(mpmc_const_sim sim, int *rank, int *nranks, int *axis, int *cell_lo,
                          int *cell_hi);
/* What this rank sent since the simulation was created: the bytes (payload) and messages of
 * the halo sums (after P2G, and F-bar's after G2P), and of migration (points moving to
 * another rank's slab, their counts included).  A message to a neighbour counts even when
 * empty; ranks at the ends send to one neighbour.  Any argument may be NULL. */
int mpmc_sim_get_mpi_traffic(mpmc_const_sim sim, double *halo_bytes, long *halo_msgs,
                             double *migrated_bytes, long *migrate_msgs);
/* Load balance: before a step, when every_n_steps steps passed since the last balance
 * (0: never by count) or when the most points on a rank exceed threshold times the mean
 * (0: never by threshold; else >= 1), the cuts move to split the points evenly (whole cells,
 * slabs of 5 cells or more, clear of walls mirrored along the slab axis) and every point
 * goes to its new rank.  Off by default (0, 0): the slabs stay where the grid put them, but
 * for a cut that walls mirrored along the slab axis come within reach of, which moves clear
 * of them whenever the walls change.
 * The results change only by the order of the halo sums (docs/mpi.md).  Collective. */
int mpmc_sim_set_mpi_balance(mpmc_sim sim, int every_n_steps, double threshold);
/* The most points on a rank over the mean over the ranks (1: even), and the balances done
 * so far (cuts moved).  Collective; either argument may be NULL. */
int mpmc_sim_get_mpi_imbalance(mpmc_const_sim sim, double *imbalance, long *balances);

#ifdef __cplusplus
}
#endif
#endif /* MPMC_MPI_H */
