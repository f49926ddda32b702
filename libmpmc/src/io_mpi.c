/* Snapshots and checkpoints over MPI: the communicator's part of io_hdf5.c and checkpoint.c
 * (io_mpi.h).  Compiled into every build; without MPMC_HAVE_MPI, and for a serial simulation,
 * every function is the one-process case and no MPI is called. */
#include <stdlib.h>
#include <string.h>

#include "io_mpi.h"

#ifdef MPMC_HAVE_MPI
#include <mpi.h>

#include "mpmc_mpi.h"

#ifndef H5_HAVE_PARALLEL
#error "an MPI build needs the parallel HDF5 (CMakeLists.txt: HDF5_PREFER_PARALLEL)"
#endif

/* The simulation's communicator (mpi.c's decomposition holds it). */
static MPI_Comm comm_of(const struct mpmc_sim_s *sim) { return *(const MPI_Comm *)mpmc_dd_comm(sim); }

void mpmc_io_ranks(const struct mpmc_sim_s *sim, int *rank, int *size) {
  *rank = 0;
  *size = 1;
  if (!sim->dd) return;
  MPI_Comm_rank(comm_of(sim), rank);
  MPI_Comm_size(comm_of(sim), size);
}

hid_t mpmc_io_fapl(const struct mpmc_sim_s *sim) {
  if (!sim->dd) return H5P_DEFAULT;
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (fapl >= 0 && H5Pset_fapl_mpio(fapl, comm_of(sim), MPI_INFO_NULL) < 0) {
    H5Pclose(fapl);
    return -1;
  }
  return fapl;
}

hid_t mpmc_io_dxpl(const struct mpmc_sim_s *sim) {
  if (!sim->dd) return H5P_DEFAULT;
  hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
  if (dxpl >= 0 && H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0) {
    H5Pclose(dxpl);
    return -1;
  }
  return dxpl;
}

void mpmc_io_scan(const struct mpmc_sim_s *sim, long long n, long long *offset, long long *total) {
  *offset = 0;
  *total = n;
  if (!sim->dd) return;
  MPI_Comm c = comm_of(sim);
  int rank;
  MPI_Comm_rank(c, &rank);
  MPI_Exscan(&n, offset, 1, MPI_LONG_LONG, MPI_SUM, c);
  if (rank == 0) *offset = 0; /* MPI_Exscan leaves rank 0's undefined */
  MPI_Allreduce(&n, total, 1, MPI_LONG_LONG, MPI_SUM, c);
}

void mpmc_io_or(const struct mpmc_sim_s *sim, unsigned *v, int n) {
  if (sim->dd) MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_UNSIGNED, MPI_BOR, comm_of(sim));
}

void mpmc_io_bcast(const struct mpmc_sim_s *sim, void *buf, int nbytes) {
  if (sim->dd) MPI_Bcast(buf, nbytes, MPI_BYTE, 0, comm_of(sim));
}

int mpmc_io_by_id(struct mpmc_sim_s *sim, double **rec, int *n, int w, long long nid) {
  int rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  if (size == 1) return MPMC_SUCCESS;
  MPI_Comm c = comm_of(sim);
  mpmc_context ctx = sim->ctx;
  const size_t sz = (size_t)size;
  int *cnt = calloc(4 * sz, sizeof(int)); /* send counts, displacements; receive alike */
  int *dest = malloc(sizeof(int) * (size_t)(*n > 0 ? *n : 1));
  double *sbuf = malloc(sizeof(double) * (size_t)(*n > 0 ? *n : 1) * (size_t)w);
  int err = cnt && dest && sbuf ? MPMC_SUCCESS
                                : MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "output: no memory for %d points", *n);
  for (int q = 0; q < *n && !err; ++q) {
    const long long id = (long long)(*rec)[(size_t)q * (size_t)w];
    const long long r = id * size / nid;
    dest[q] = r < 0 ? 0 : r >= size ? size - 1 : (int)r;
    cnt[dest[q]]++;
  }
  err = mpmc_dd_agree(sim, err);
  int *sc = cnt, *sd = cnt + sz, *rc = cnt + 2 * sz, *rd = cnt + 3 * sz;
  long long nin = 0;
  if (!err) {
    MPI_Alltoall(sc, 1, MPI_INT, rc, 1, MPI_INT, c);
    for (int r = 0; r < size; ++r) nin += rc[r];
    if ((long long)*n * w > INT32_MAX || nin * w > INT32_MAX)
      err = MPMC_ERROR(ctx, MPMC_ERR_UNSUPPORTED,
                       "output: %lld points of %d values on one rank: more than one MPI message "
                       "holds; use more ranks", nin > *n ? nin : *n, w);
  }
  double *rbuf = err ? NULL : malloc(sizeof(double) * (size_t)(nin > 0 ? nin : 1) * (size_t)w);
  if (!err && !rbuf) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "output: no memory for %lld points", nin);
  err = mpmc_dd_agree(sim, err);
  if (!err) {
    int ps = 0, pr = 0;
    for (int r = 0; r < size; ++r) { /* in doubles from here on */
      sd[r] = ps, rd[r] = pr;
      ps += sc[r] * w, pr += rc[r] * w;
      sc[r] *= w, rc[r] *= w;
    }
    for (int q = 0; q < *n; ++q) { /* packed by destination, in the points' order */
      memcpy(sbuf + sd[dest[q]], *rec + (size_t)q * (size_t)w, sizeof(double) * (size_t)w);
      sd[dest[q]] += w;
    }
    for (int r = 0; r < size; ++r) sd[r] -= sc[r];
    MPI_Alltoallv(sbuf, sc, sd, MPI_DOUBLE, rbuf, rc, rd, MPI_DOUBLE, c);
    free(*rec);
    *rec = rbuf;
    *n = (int)nin;
  } else {
    free(rbuf);
  }
  free(cnt);
  free(dest);
  free(sbuf);
  return err;
}

int mpmc_io_sim_create(mpmc_context ctx, const void *comm, int dim, mpmc_sim *sim) {
  return comm ? mpmc_sim_create_mpi(ctx, *(const MPI_Comm *)comm, dim, sim)
              : mpmc_sim_create(ctx, dim, sim);
}

int mpmc_io_agree(mpmc_context ctx, const void *comm, int err) {
  if (!comm) return err;
  int any = err != 0;
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, *(const MPI_Comm *)comm);
  if (any && !err)
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "another rank of the communicator failed to read the file "
                                       "(its error is reported there)");
  return err;
}

#else /* one process */

void mpmc_io_ranks(const struct mpmc_sim_s *sim, int *rank, int *size) {
  (void)sim;
  *rank = 0;
  *size = 1;
}
hid_t mpmc_io_fapl(const struct mpmc_sim_s *sim) { return (void)sim, H5P_DEFAULT; }
hid_t mpmc_io_dxpl(const struct mpmc_sim_s *sim) { return (void)sim, H5P_DEFAULT; }
void mpmc_io_scan(const struct mpmc_sim_s *sim, long long n, long long *offset, long long *total) {
  (void)sim;
  *offset = 0;
  *total = n;
}
void mpmc_io_or(const struct mpmc_sim_s *sim, unsigned *v, int n) { (void)sim, (void)v, (void)n; }
void mpmc_io_bcast(const struct mpmc_sim_s *sim, void *buf, int nbytes) {
  (void)sim, (void)buf, (void)nbytes;
}
int mpmc_io_by_id(struct mpmc_sim_s *sim, double **rec, int *n, int w, long long nid) {
  return (void)sim, (void)rec, (void)n, (void)w, (void)nid, MPMC_SUCCESS;
}
int mpmc_io_sim_create(mpmc_context ctx, const void *comm, int dim, mpmc_sim *sim) {
  return (void)comm, mpmc_sim_create(ctx, dim, sim);
}
int mpmc_io_agree(mpmc_context ctx, const void *comm, int err) { return (void)ctx, (void)comm, err; }

#endif /* MPMC_HAVE_MPI */

void mpmc_io_plist_close(hid_t plist) {
  if (plist >= 0 && plist != H5P_DEFAULT) H5Pclose(plist);
}
