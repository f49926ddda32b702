/* Snapshots and checkpoints of a simulation over MPI ranks (io_mpi.c; docs/mpi.md, "I/O").
 *
 * One file whatever the number of ranks, written collectively with the parallel HDF5 (MPI-IO
 * driver): every rank calls the same HDF5 functions, the per-point datasets are written as
 * hyperslabs, one per rank, at the offsets MPI_Exscan gives.  A serial simulation (sim->dd
 * NULL, and every simulation of the serial build) takes the same path as one rank: offset 0,
 * its own count, HDF5's default driver and transfers. */
#ifndef MPMC_IO_MPI_H
#define MPMC_IO_MPI_H

#include "io.h"

/* This process's rank and the number of ranks of sim (0 and 1 for a serial simulation). */
void mpmc_io_ranks(const struct mpmc_sim_s *sim, int *rank, int *size);
/* The file access list of sim's files: the MPI-IO driver over its communicator, or
 * H5P_DEFAULT; release with mpmc_io_plist_close. */
hid_t mpmc_io_fapl(const struct mpmc_sim_s *sim);
/* The transfer list of the per-point writes: collective over MPI, else H5P_DEFAULT. */
hid_t mpmc_io_dxpl(const struct mpmc_sim_s *sim);
void mpmc_io_plist_close(hid_t plist);
/* n on this rank: *offset the sum over the lower ranks, *total over all (collective). */
void mpmc_io_scan(const struct mpmc_sim_s *sim, long long n, long long *offset, long long *total);
/* v[0 .. n) replaced by their bitwise or over the ranks (collective). */
void mpmc_io_or(const struct mpmc_sim_s *sim, unsigned *v, int n);
/* nbytes of buf replaced by rank 0's (collective). */
void mpmc_io_bcast(const struct mpmc_sim_s *sim, void *buf, int nbytes);
/* The records rec[n][w] (column 0: the point's id, 0 <= id < nid) moved to the rank whose
 * block of ids holds theirs (rank r: ids [r nid / size, (r + 1) nid / size)); *rec and *n
 * replaced.  Collective; a no-op on one rank. */
int mpmc_io_by_id(struct mpmc_sim_s *sim, double **rec, int *n, int w, long long nid);
/* A simulation over comm (a pointer to an MPI_Comm; NULL: a serial one), as mpmc_sim_create. */
int mpmc_io_sim_create(mpmc_context ctx, const void *comm, int dim, mpmc_sim *sim);
/* The same err on every rank of comm (NULL: err), with the lowest failing rank's message,
 * for the errors before a simulation exists (after: mpmc_dd_agree). */
int mpmc_io_agree(mpmc_context ctx, const void *comm, int err);

/* A dataset [total][cols] (cols == 0: [total]) of which this rank writes the rows
 * [offset, offset + n) from buf, with the transfer list dxpl (every rank calls it). */
herr_t mpmc_h5_rows_write(hid_t loc, const char *name, hid_t filetype, hid_t memtype,
                          long long total, size_t cols, long long offset, size_t n,
                          const void *buf, hid_t dxpl);

#endif
