/* Helpers of the MPI tests (tests/mpi): a simulation in one process or over MPI_COMM_WORLD,
 * and the comparison of a distributed run with the serial one, point by point by global id.
 * The tests print nothing when they pass (MPMC_TEST_VERBOSE=1: their numbers, rank 0). */
#ifndef MPMC_MPI_TEST_H
#define MPMC_MPI_TEST_H

#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc.h"
#include "mpmc_mpi.h"

static int test_rank, test_size, test_failed;

/* Fail on every rank (each rank calls the same collective functions, so each fails alike). */
#define MCALL(ctx, expr)                                                                  \
  do {                                                                                    \
    int mcall_ierr_ = (expr);                                                             \
    if (mcall_ierr_) {                                                                    \
      fprintf(stderr, "rank %d: %s:%d: %s -> %d: %s\n", test_rank, __FILE__, __LINE__, #expr, \
              mcall_ierr_, mpmc_context_last_error(ctx));                                 \
      MPI_Abort(MPI_COMM_WORLD, 1);                                                       \
    }                                                                                     \
  } while (0)

/* MPI_Init, and this process's rank and the number of ranks in test_rank, test_size. */
static inline void test_init(int *argc, char ***argv) {
  MPI_Init(argc, argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &test_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &test_size);
}

static inline int test_verbose(void) {
  const char *v = getenv("MPMC_TEST_VERBOSE");
  return v && *v && strcmp(v, "0") != 0;
}

/* A sim in one process (comm == MPI_COMM_NULL) or over comm. */
static inline mpmc_sim test_sim(mpmc_context ctx, MPI_Comm comm, int dim) {
  mpmc_sim sim;
  if (comm == MPI_COMM_NULL)
    MCALL(ctx, mpmc_sim_create(ctx, dim, &sim));
  else
    MCALL(ctx, mpmc_sim_create_mpi(ctx, comm, dim, &sim));
  return sim;
}

/* Points on a lattice of ppc x ppc per cell of size h in the 2D box [lo, hi]. */
static inline int test_lattice2(const double *lo, const double *hi, double h, int ppc, double **x,
                         double **vol) {
  const int nx = (int)lround((hi[0] - lo[0]) / h) * ppc, ny = (int)lround((hi[1] - lo[1]) / h) * ppc;
  const int n = nx * ny;
  *x = malloc(sizeof(double) * 2 * (size_t)n);
  *vol = malloc(sizeof(double) * (size_t)n);
  const double dx = h / ppc;
  for (int j = 0, q = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i, ++q) {
      (*x)[2 * q] = lo[0] + (i + 0.5) * dx;
      (*x)[2 * q + 1] = lo[1] + (j + 0.5) * dx;
      (*vol)[q] = dx * dx;
    }
  return n;
}

/* The 2D box's walls of the tests: slip sides (faces x lo and x hi), fixed base (y lo). */
static inline void test_walls2(mpmc_context ctx, mpmc_sim sim) {
  MCALL(ctx, mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, NULL));
  MCALL(ctx, mpmc_sim_add_wall_face(sim, 1, MPMC_WALL_SLIP, NULL));
  MCALL(ctx, mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
}

/* A Hencky block (E 1e5 Pa, nu 0.3, 1000 kg/m^3), 2 x 2 points a cell, x in [0, 1] and y in
 * [ylo, yhi] of a 1 x 30 m grid of 0.5 m cells (B-spline2, anchored F-bar, gravity, slip
 * sides, fixed base), moving at vy (1 + stretch (y - its middle)): the top faster than the
 * bottom for stretch > 0, so it stretches and rings as it flies.  *n: the points over all
 * ranks. */
static inline mpmc_sim test_block(mpmc_context ctx, MPI_Comm comm, double ylo, double yhi, double vy,
                                  double stretch, int *n) {
  mpmc_sim sim = test_sim(ctx, comm, 2);
  const double lo[2] = {0, 0}, hi[2] = {1, 30};
  MCALL(ctx, mpmc_sim_set_grid(sim, lo, hi, 0.5));
  MCALL(ctx, mpmc_sim_set_basis(sim, MPMC_BASIS_BSPLINE2));
  MCALL(ctx, mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  const double gv[2] = {0, -9.81};
  MCALL(ctx, mpmc_sim_set_gravity(sim, gv));
  MCALL(ctx, mpmc_sim_set_threads(sim, 1));
  int mat;
  MCALL(ctx, mpmc_sim_add_material_hencky(sim, 1e5, 0.3, 1000.0, &mat));
  double *x, *vol;
  const double plo[2] = {0, ylo}, phi[2] = {1, yhi};
  *n = test_lattice2(plo, phi, 0.5, 2, &x, &vol);
  MCALL(ctx, mpmc_sim_add_particles(sim, *n, x, vol, mat, NULL));
  free(x);
  free(vol);
  test_walls2(ctx, sim);
  int nl;
  double *v;
  MCALL(ctx, mpmc_sim_get_num_particles(sim, &nl));
  MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
  const double mid = 0.5 * (ylo + yhi);
  for (int q = 0; q < nl; ++q) v[2 * q + 1] = vy * (1.0 + stretch * (x[2 * q + 1] - mid));
  MCALL(ctx, mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v));
  return sim;
}

/* Per point: position, velocity (dim each) and stress (6), at [id] of out[n][2 dim + 6]
 * (comm's rank 0: every rank's points; the others pass out NULL).  Collective over comm for
 * a sim over comm; MPI_COMM_NULL: a sim in one process. */
#define TEST_REC(d) (2 * (d) + 6)
static inline void test_gather_on(mpmc_context ctx, mpmc_sim sim, int dim, int ntotal, MPI_Comm comm,
                                  double *out) {
  const int w = TEST_REC(dim);
  int n;
  const int *ids;
  double *x, *v, *s;
  MCALL(ctx, mpmc_sim_get_num_particles(sim, &n));
  MCALL(ctx, mpmc_sim_get_particle_ids(sim, &ids));
  MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
  MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &s, NULL));
  double *mine = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1) * (w + 1));
  for (int q = 0; q < n; ++q) {
    double *r = mine + (size_t)q * (w + 1);
    r[0] = ids[q];
    for (int a = 0; a < dim; ++a) r[1 + a] = x[q * dim + a], r[1 + dim + a] = v[q * dim + a];
    for (int k = 0; k < 6; ++k) r[1 + 2 * dim + k] = s[6 * q + k];
  }
  MCALL(ctx, mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, &v));
  int count = n * (w + 1), *counts = NULL, *displ = NULL, total = count;
  double *all = mine;
  if (comm != MPI_COMM_NULL) {
    int rank, size;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    if (rank == 0) {
      counts = malloc(sizeof(int) * (size_t)size);
      displ = malloc(sizeof(int) * (size_t)size);
    }
    MPI_Gather(&count, 1, MPI_INT, counts, 1, MPI_INT, 0, comm);
    if (rank == 0) {
      total = 0;
      for (int r = 0; r < size; ++r) displ[r] = total, total += counts[r];
      all = malloc(sizeof(double) * (size_t)(total > 0 ? total : 1));
    }
    MPI_Gatherv(mine, count, MPI_DOUBLE, all, counts, displ, MPI_DOUBLE, 0, comm);
  }
  if (out) {
    for (int i = 0; i < ntotal * w; ++i) out[i] = NAN;
    for (int k = 0; k < total / (w + 1); ++k) {
      const double *r = all + (size_t)k * (w + 1);
      const int id = (int)r[0];
      if (id >= 0 && id < ntotal) memcpy(out + (size_t)id * w, r + 1, sizeof(double) * (size_t)w);
    }
  }
  if (all != mine) free(all);
  free(mine);
  free(counts);
  free(displ);
}

/* test_gather_on over MPI_COMM_WORLD (mpi) or in one process. */
static inline void test_gather(mpmc_context ctx, mpmc_sim sim, int dim, int ntotal, int mpi,
                               double *out) {
  test_gather_on(ctx, sim, dim, ntotal, mpi ? MPI_COMM_WORLD : MPI_COMM_NULL, out);
}

/* The largest difference of each of position, velocity and stress between runs a and b
 * relative to b's largest magnitude of that field (a point missing from a: infinite). */
static inline void test_compare(int dim, int ntotal, const double *a, const double *b, double rel[3]) {
  const int w = TEST_REC(dim), lo[3] = {0, dim, 2 * dim}, hi[3] = {dim, 2 * dim, 2 * dim + 6};
  for (int f = 0; f < 3; ++f) {
    double scale = 0.0, diff = 0.0;
    for (int q = 0; q < ntotal; ++q)
      for (int k = lo[f]; k < hi[f]; ++k) {
        const double x = a[(size_t)q * w + k], y = b[(size_t)q * w + k];
        scale = fmax(scale, fabs(y));
        diff = fmax(diff, isnan(x) ? INFINITY : fabs(x - y));
      }
    rel[f] = scale > 0 ? diff / scale : diff;
  }
}

#endif
