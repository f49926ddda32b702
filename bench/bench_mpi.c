/* MPI benchmark (issue 47, docs/mpi.md): the 64,000-point 3D column of bench_throughput (a
 * 2 x 0.5 x 1 m box at h = 0.025 m, a 0.5 m cube of Hencky-J2 soil with 2x2x2 points per
 * cell, gravity, slip walls, fixed base; quadratic B-splines with the default, anchored F-bar)
 * stepped over the ranks of MPI_COMM_WORLD, and the traffic between them.
 *
 *   mpiexec -n R bench_mpi [steps] [threads] [scene]   (R = 1 or more; bench/mpi_scaling.sh)
 *   mpiexec -n 2 bench_mpi --model [steps] [scene]
 *
 * steps: timed steps (default 100, after 3 warm-up steps); threads: OpenMP threads per rank
 * (mpmc_sim_set_threads; default 1); scene: `column`, bench_throughput's column as it is (the
 * cube at the low end of the 2 m axis, the slab axis: on 2 ranks every point is in rank 0's
 * slab, there being no load balancing yet), or `centred` (default; the same cube moved to the
 * middle of that axis, x in [0.75, 1.25], so the cut halves it).  Rank 0 prints one line of
 * key=value pairs: the wall time per step and the busiest rank's time outside MPI calls (the
 * time in them, MPI_Waitall's and the collectives', is waiting for the neighbours: for their
 * work, or on a loaded machine for their turn on a core), the CPU time outside MPI calls of
 * the busiest rank and of all ranks (the work, whatever the load: with one thread a rank, the
 * ratio of one rank's to the busiest rank's is the speed-up free cores would give, but for
 * the waits' latency), points x steps per second, the points per rank, and per step and rank
 * (the largest over the ranks) the bytes and messages each rank sent: halo sums (P2G's and
 * F-bar's), migration (the counts and the points), collectives.
 *
 * Halo and migration traffic are libmpmc's counts (mpmc_sim_get_mpi_traffic).  The
 * collectives, which it does not count, are counted with the MPI profiling interface: this
 * program defines MPI_Allreduce, MPI_Allgather and MPI_Bcast, and MPI_Isend, MPI_Send and
 * MPI_Sendrecv, counts, and calls the PMPI_ functions (libmpmc's calls land here); the
 * point-to-point sends so counted (but to MPI_PROC_NULL) must add up to libmpmc's halo and
 * migration counts, or the run fails.
 *
 * --model (on 2 ranks) measures its inputs and prints the projected parallel efficiency at 16,
 * 64 and 1,024 ranks with 10^6 points per rank: the compute time per point-step on rank 0
 * alone (MPI_COMM_SELF, one thread, CPU time, the least of 3 runs; rank 1 sleeps), and on
 * both ranks the halo bytes per node of the cut's cross-section and step, the messages per
 * neighbour and step and the collectives per step.
 * The model's assumptions are printed with its table (model() below). */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpmc.h"
#include "mpmc_bench.h" /* the grid's active box and node size (libmpmc/src, the internal archive) */
#include "mpmc_mpi.h"

/* ---- counting through the profiling interface ---------------------------------------- */

/* halo and migration: libmpmc's counts; the others counted here */
enum { K_HALO, K_MIGRATE, K_P2P, K_ALLREDUCE, K_ALLGATHER, K_BCAST, K_COUNT };
static const char *const kind_name[K_COUNT] = {"halo", "migration", "p2p", "allreduce",
                                               "allgather", "bcast"};
static double sent_bytes[K_COUNT];
static long sent_msgs[K_COUNT];
static double mpi_seconds, mpi_cpu; /* wall and CPU time inside the MPI calls below */

static double cpu_now(clockid_t clock) {
  struct timespec ts;
  clock_gettime(clock, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static int timed(int rc, double t0, double c0) {
  mpi_seconds += PMPI_Wtime() - t0;
  mpi_cpu += cpu_now(CLOCK_THREAD_CPUTIME_ID) - c0;
  return rc;
}

static void count(int kind, int n, MPI_Datatype type) {
  int size = 0;
  PMPI_Type_size(type, &size);
  sent_bytes[kind] += (double)n * size;
  sent_msgs[kind]++;
}
static void count_p2p(int n, MPI_Datatype type, int dest) {
  if (dest != MPI_PROC_NULL) count(K_P2P, n, type);
}

int MPI_Isend(const void *buf, int n, MPI_Datatype type, int dest, int tag, MPI_Comm comm,
              MPI_Request *req) {
  count_p2p(n, type, dest);
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Isend(buf, n, type, dest, tag, comm, req), t0, c0);
}
int MPI_Send(const void *buf, int n, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
  count_p2p(n, type, dest);
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Send(buf, n, type, dest, tag, comm), t0, c0);
}
int MPI_Sendrecv(const void *sbuf, int sn, MPI_Datatype stype, int dest, int stag, void *rbuf,
                 int rn, MPI_Datatype rtype, int src, int rtag, MPI_Comm comm,
                 MPI_Status *status) {
  count_p2p(sn, stype, dest);
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Sendrecv(sbuf, sn, stype, dest, stag, rbuf, rn, rtype, src, rtag, comm, status),
               t0, c0);
}
int MPI_Allreduce(const void *sbuf, void *rbuf, int n, MPI_Datatype type, MPI_Op op,
                  MPI_Comm comm) {
  count(K_ALLREDUCE, n, type);
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Allreduce(sbuf, rbuf, n, type, op, comm), t0, c0);
}
int MPI_Allgather(const void *sbuf, int sn, MPI_Datatype stype, void *rbuf, int rn,
                  MPI_Datatype rtype, MPI_Comm comm) {
  count(K_ALLGATHER, sn, stype);
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Allgather(sbuf, sn, stype, rbuf, rn, rtype, comm), t0, c0);
}
int MPI_Bcast(void *buf, int n, MPI_Datatype type, int root, MPI_Comm comm) {
  count(K_BCAST, n, type);
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Bcast(buf, n, type, root, comm), t0, c0);
}
int MPI_Waitall(int n, MPI_Request reqs[], MPI_Status *statuses) {
  const double t0 = PMPI_Wtime(), c0 = cpu_now(CLOCK_THREAD_CPUTIME_ID);
  return timed(PMPI_Waitall(n, reqs, statuses), t0, c0);
}

/* ---- one run ------------------------------------------------------------------------- */

#define HALO_PLANES 3 /* mpi.c's halo: node planes b - 1 .. b + 1 around each cut b */

typedef struct {
  double seconds;                           /* wall time of the timed steps (rank 0's)  */
  double outside;                           /* of it outside MPI calls, the busiest rank */
  double cpu_max, cpu_sum;                  /* CPU time outside MPI calls: the busiest
                                               rank's, all ranks' (waiting for a core
                                               excluded)                                  */
  long points, pmin, pmax;                  /* over the ranks                            */
  double bytes[K_COUNT], msgs[K_COUNT];     /* per step, this rank                       */
  long area;                                /* nodes of the active box's cross-section
                                               normal to the slab axis, this rank          */
  int neighbours;                           /* ranks this rank exchanges with             */
  double rec_bytes;                         /* bytes a halo node carries per step: record
                                               and F-bar's sum                            */
  double grid_node_bytes;                   /* bytes the grid holds per node: those and
                                               the fixed flags                            */
  long held_max, whole;                     /* grid nodes held: the most on a rank; the
                                               whole grid's                               */
} result;

static int my_rank;

#define CHECK(expr)                                                                        \
  do {                                                                                     \
    int e_ = (expr);                                                                       \
    if (e_) {                                                                              \
      fprintf(stderr, "rank %d: %s failed: %s\n", my_rank, #expr, mpmc_context_last_error(ctx)); \
      MPI_Abort(MPI_COMM_WORLD, 1);                                                        \
    }                                                                                      \
  } while (0)

/* The column over comm (the same set-up as bench_throughput's column, case 4), steps timed. */
static result run(MPI_Comm comm, int centred, int threads, int steps) {
  mpmc_context ctx;
  mpmc_sim sim;
  mpmc_context_create(&ctx);
  CHECK(mpmc_sim_create_mpi(ctx, comm, 3, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {2.0, 0.5, 1.0}, g[3] = {0, 0, -9.81};
  const double x0 = centred ? 0.75 : 0.0, blo[3] = {x0, 0, 0}, bhi[3] = {x0 + 0.5, 0.5, 0.5};
  CHECK(mpmc_sim_set_grid(sim, lo, hi, 0.025));
  CHECK(mpmc_sim_set_basis(sim, MPMC_BASIS_BSPLINE2));
  CHECK(mpmc_sim_set_fbar(sim, MPMC_FBAR_ANCHORED));
  CHECK(mpmc_sim_set_threads(sim, threads));
  int mat;
  CHECK(mpmc_sim_add_material_hencky_j2(sim, 10e6, 0.3, 2000, 20e3, 5e3, 5, &mat));
  CHECK(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, NULL));
  CHECK(mpmc_sim_set_gravity(sim, g));
  for (int f = 0; f < 6; ++f)
    CHECK(mpmc_sim_add_wall_face(sim, f, f == 4 ? MPMC_WALL_FIXED : MPMC_WALL_SLIP, NULL));
  double dt;
  CHECK(mpmc_sim_stable_dt(sim, 0.3, &dt));
  for (int s = 0; s < 3; ++s) CHECK(mpmc_sim_step(sim, dt)); /* warm-up: allocations */
  memset(sent_bytes, 0, sizeof sent_bytes);
  memset(sent_msgs, 0, sizeof sent_msgs);
  mpi_seconds = mpi_cpu = 0.0;
  double lib0[2], lib1[2];
  long libm0[2], libm1[2];
  CHECK(mpmc_sim_get_mpi_traffic(sim, &lib0[0], &libm0[0], &lib0[1], &libm0[1]));
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime(), c0 = cpu_now(CLOCK_PROCESS_CPUTIME_ID);
  for (int s = 0; s < steps; ++s) CHECK(mpmc_sim_step(sim, dt));
  const double cpu = cpu_now(CLOCK_PROCESS_CPUTIME_ID) - c0 - mpi_cpu;
  MPI_Barrier(comm);
  result r = {.seconds = MPI_Wtime() - t0};
  const double outside = r.seconds - mpi_seconds;
  MPI_Allreduce(&outside, &r.outside, 1, MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(&cpu, &r.cpu_max, 1, MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(&cpu, &r.cpu_sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  CHECK(mpmc_sim_get_mpi_traffic(sim, &lib1[0], &libm1[0], &lib1[1], &libm1[1]));
  for (int k = 0; k < 2; ++k) {
    sent_bytes[K_HALO + k] = lib1[k] - lib0[k];
    sent_msgs[K_HALO + k] = libm1[k] - libm0[k];
  }
  if (sent_bytes[K_P2P] != sent_bytes[K_HALO] + sent_bytes[K_MIGRATE] ||
      sent_msgs[K_P2P] != sent_msgs[K_HALO] + sent_msgs[K_MIGRATE]) {
    fprintf(stderr, "rank %d: the sends counted here, %.0f B in %ld messages, are not libmpmc's "
            "halo and migration traffic, %.0f B in %ld\n", my_rank, sent_bytes[K_P2P],
            sent_msgs[K_P2P], sent_bytes[K_HALO] + sent_bytes[K_MIGRATE],
            sent_msgs[K_HALO] + sent_msgs[K_MIGRATE]);
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  for (int k = 0; k < K_COUNT; ++k) {
    r.bytes[k] = sent_bytes[k] / steps;
    r.msgs[k] = (double)sent_msgs[k] / steps;
  }
  int n, rank, nranks, axis;
  CHECK(mpmc_sim_get_num_particles(sim, &n));
  CHECK(mpmc_sim_get_mpi_slab(sim, &rank, &nranks, &axis, NULL, NULL));
  const long mine = n;
  MPI_Allreduce(&mine, &r.points, 1, MPI_LONG, MPI_SUM, comm);
  MPI_Allreduce(&mine, &r.pmin, 1, MPI_LONG, MPI_MIN, comm);
  MPI_Allreduce(&mine, &r.pmax, 1, MPI_LONG, MPI_MAX, comm);
  int alo[3], ahi[3];
  size_t rec_bytes, node_bytes;
  CHECK(mpmc_bench_grid(sim, alo, ahi, &rec_bytes, &node_bytes));
  r.area = 1;
  for (int a = 0; a < 3; ++a)
    if (a != axis) r.area *= ahi[a] > alo[a] ? ahi[a] - alo[a] : 0;
  r.neighbours = (rank > 0) + (rank + 1 < nranks);
  r.rec_bytes = rec_bytes;
  r.grid_node_bytes = node_bytes;
  size_t held, whole;
  CHECK(mpmc_bench_grid_held(sim, &held, &whole));
  const long lh = (long)held;
  MPI_Allreduce(&lh, &r.held_max, 1, MPI_LONG, MPI_MAX, comm);
  r.whole = (long)whole;
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  return r;
}

/* The per-step figures of r as the largest over the ranks of comm. */
static void largest(MPI_Comm comm, result *r) {
  MPI_Allreduce(MPI_IN_PLACE, r->bytes, K_COUNT, MPI_DOUBLE, MPI_MAX, comm);
  MPI_Allreduce(MPI_IN_PLACE, r->msgs, K_COUNT, MPI_DOUBLE, MPI_MAX, comm);
}

/* A barrier that leaves the core free while waiting (OpenMPI's MPI_Barrier spins). */
static void idle_barrier(void) {
  MPI_Request req;
  MPI_Ibarrier(MPI_COMM_WORLD, &req);
  for (int done = 0;;) {
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (done) return;
    nanosleep(&(struct timespec){0, 1000000}, NULL);
  }
}

/* ---- the model ----------------------------------------------------------------------- */

/* The cross-section nodes of the halos an interior rank sends per step for sub-domains of
 * ext[3] cells on a p[3] grid of ranks, the exchange staged axis by axis (6 messages in 3D,
 * not 26: an axis exchanged later sends the halos received before it along, its faces grown
 * by planes each side), and the directions it sends to (msgs). */
static double halo_faces(const double *ext, const int *p, int planes, int *msgs) {
  double nodes = 0.0;
  *msgs = 0;
  for (int a = 0; a < 3; ++a) {
    if (p[a] == 1) continue;
    double face = 1.0;
    for (int b = 0; b < 3; ++b)
      if (b != a) face *= ext[b] + 1.0 + (b < a && p[b] > 1 ? 2.0 * planes : 0.0);
    nodes += 2.0 * face;
    *msgs += 2;
  }
  return nodes;
}

/* The nodes a rank holds for sub-domains of ext[3] cells on a p[3] grid of ranks in a cube
 * of N cells a side: a cut axis its cells' nodes and ghost planes beyond each cut (mpi.c,
 * hold_slab), an axis not cut the whole grid's nodes. */
static double held_nodes(double N, const double *ext, const int *p, int ghost) {
  double n = 1.0;
  for (int a = 0; a < 3; ++a) n *= (p[a] > 1 ? ext[a] : N) + 2.0 * ghost + 1.0;
  return n;
}

static int ilog2ceil(int n) {
  int k = 0;
  while ((1 << k) < n) ++k;
  return k;
}

static void model(const result *one, const result *two, int steps) {
  int ghost, min_cells; /* the grid's ghost cells a side, a slab's fewest cells */
  mpmc_bench_layout(&ghost, &min_cells);
  /* s per point-step: CPU time, which a loaded machine's waits for a core do not inflate */
  const double tp = one->cpu_max / ((double)one->points * steps);
  const int nb = two->neighbours > 0 ? two->neighbours : 1;
  /* halo bytes per step and node of the cut's cross-section (the planes sent, headers
   * included), messages per neighbour and step */
  const double barea = two->bytes[K_HALO] / (nb * (double)two->area);
  const double mnb = (two->msgs[K_HALO] + two->msgs[K_MIGRATE]) / nb;
  const double mig = two->bytes[K_MIGRATE] / nb;
  const double nar = two->msgs[K_ALLREDUCE], nag = two->msgs[K_ALLGATHER], nbc = two->msgs[K_BCAST];
  const double bag = nag > 0 ? two->bytes[K_ALLGATHER] / nag : 0.0;
  const double gnode = two->grid_node_bytes, np = 1e6, ppc = 8.0, cells = np / ppc;
  const struct {
    double alpha, beta;
  } net[2] = {{1e-6, 25e9}, {2e-6, 10e9}};
  printf("model inputs, measured (bench_mpi --model %d):\n", steps);
  printf("  compute per point-step, 1 rank x 1 thread, CPU time, the least of 3 runs: %.1f ns "
         "(%.3f M/s, %ld points)\n",
         1e9 * tp, 1e-6 / tp, one->points);
  printf("  2 ranks: halo %.0f B/step/rank over a cross-section of %ld nodes: %.1f B per "
         "cross-section node and step, %.2f planes of %.0f B (the node record and F-bar's sum)\n",
         two->bytes[K_HALO], two->area, barea, barea / two->rec_bytes, two->rec_bytes);
  printf("  grid nodes held, the most on a rank: %ld of the whole grid's %ld (%.0f %%)\n",
         two->held_max, two->whole, 100.0 * two->held_max / two->whole);
  printf("  messages per neighbour and step: %.2f (halo %.2f, migration %.2f); migration %.0f "
         "B/step; collectives per step: %.2f allreduce, %.2f allgather (%.0f B each), %.2f bcast\n",
         mnb, two->msgs[K_HALO] / nb, two->msgs[K_MIGRATE] / nb, mig, nar, nag, bag, nbc);
  printf("assumptions: 10^6 points per rank, %.0f per cell (%.0f cells a rank); the global grid a "
         "cube of N^3 cells, N = (%.0f P)^(1/3); a rank is one core at the measured rate; no "
         "overlap of communication and compute, no load imbalance; the halo nodes' grid update, "
         "which both neighbours repeat, not counted; network A: 1 us, 25 GB/s, B: 2 us, 10 GB/s "
         "per rank; allreduce 2 log2(P) latencies, allgather and bcast log2(P) and (P - 1) x "
         "their bytes / bandwidth; the owned grid %.0f B per node (record, F-bar, flags)\n",
         ppc, cells, cells, gnode);
  printf("%-6s %-7s %-17s %5s %8s %8s %8s %5s %8s %7s %7s %7s %7s %7s\n", "ranks", "decomp",
         "cells a rank", "min", "halo MB", "owned MB", "halo/own", "msgs", "comp ms", "comm A",
         "comm B", "eff A", "eff B", "grid GB");
  static const int ranks[3] = {16, 64, 1024};
  static const int dims[3][3][3] = {{{16, 1, 1}, {4, 4, 1}, {4, 2, 2}},
                                    {{64, 1, 1}, {8, 8, 1}, {4, 4, 4}},
                                    {{1024, 1, 1}, {32, 32, 1}, {16, 8, 8}}};
  static const char *const dname[3] = {"slab", "pencil", "block"};
  for (int i = 0; i < 3; ++i) {
    const int P = ranks[i];
    const double N = cbrt(cells * P), lg = ilog2ceil(P);
    for (int d = 0; d < 3; ++d) {
      const int *p = dims[i][d];
      double ext[3], emin = INFINITY;
      for (int a = 0; a < 3; ++a) {
        ext[a] = N / p[a];
        if (p[a] > 1) emin = fmin(emin, ext[a]);
      }
      int dirs;
      const double hbytes = halo_faces(ext, p, HALO_PLANES, &dirs) * barea;
      const double owned = cells * gnode, mtot = dirs * mnb, comp = np * tp;
      double comm[2], eff[2];
      for (int k = 0; k < 2; ++k) {
        const double al = net[k].alpha, be = net[k].beta;
        comm[k] = mtot * al + (hbytes + dirs * mig) / be + nar * 2 * lg * al +
                  nag * (lg * al + (P - 1) * bag / be) + nbc * lg * al;
        eff[k] = comp / (comp + comm[k]);
      }
      char sub[40];
      snprintf(sub, sizeof sub, "%.1fx%.1fx%.1f", ext[0], ext[1], ext[2]);
      printf("%-6d %-7s %-17s %5.1f %8.2f %8.2f %7.0f%% %5.0f %8.1f %7.3f %7.3f %6.2f%% %6.2f%% "
             "%7.2f%s\n", P, dname[d], sub, emin, hbytes / 1e6, owned / 1e6, 100 * hbytes / owned,
             mtot, 1e3 * comp, 1e3 * comm[0], 1e3 * comm[1], 100 * eff[0], 100 * eff[1],
             held_nodes(N, ext, p, ghost) * gnode / 1e9,
             emin < min_cells ? "  thinner than 5 cells" : "");
    }
  }
  printf("(min: the thinnest cut extent in cells, against the slabs' minimum of %d; halo/own: the "
         "halo bytes a rank sends per step over its owned grid's bytes; msgs: messages sent per "
         "step; comm A, B: ms per step; grid GB: the grid a rank holds, its sub-domain's nodes "
         "and %d ghost planes beyond each cut, the whole grid along axes not cut; the whole "
         "grid is %.2f GB at 1,024 ranks)\n",
         min_cells, ghost, pow(cbrt(cells * 1024) + 2 * ghost + 1, 3) * gnode / 1e9);
  /* a slab w cells thick sends 2 x barea per node of its cross-section and owns w x gnode */
  const double w10 = ceil(20.0 * barea / gnode), w3 = ceil(20.0 * 3.0 * two->rec_bytes / gnode);
  printf("slabs: halo/own = 2 x %.0f B / (w x %.0f B) whatever the cross-section: <= 10 %% needs "
         "w >= %.0f cells, a cross-section of at most %.0f cells at 10^6 points per rank (w >= "
         "%.0f with a halo of 3 planes, the stencils' overlap)\n", barea, gnode, w10, cells / w10,
         w3);
  /* plane strain: the same halo record and planes a node of the cut's line, 4 points a cell
   * (2 x 2), the global grid a square; the halo alone (the compute rate measured is 3D's) */
  const double cells2 = np / 4.0;
  printf("2D (plane strain), 10^6 points per rank, 4 per cell (%.0f cells a rank), the global "
         "grid a square of N^2 cells, N = (%.0f P)^(1/2); the halo bytes per node of a cut's "
         "line as measured in 3D:\n%-6s %-7s %-15s %7s %8s %8s %9s\n", cells2, cells2, "ranks",
         "decomp", "cells a rank", "min", "halo/own", "grid MB", "whole MB");
  for (int i = 0; i < 3; ++i) {
    const int P = ranks[i], q = (int)lround(sqrt((double)P)); /* blocks: q x q ranks */
    const double N = sqrt(cells2 * P);
    for (int d = 0; d < 2; ++d) {
      const double ex = d ? N / q : N / P, ey = d ? N / q : N;
      /* the faces of the cuts: a slab's two lines of N + 1 nodes; a block's four, staged
       * (the second axis's lines grown by the first's halo planes) */
      const double faces = d ? 2.0 * (ey + 1.0) + 2.0 * (ex + 1.0 + 2.0 * HALO_PLANES)
                             : 2.0 * (ey + 1.0);
      const double held = (ex + 2.0 * ghost + 1.0) * (d ? ey + 2.0 * ghost + 1.0 : N + 2.0 * ghost + 1.0);
      char sub[32];
      snprintf(sub, sizeof sub, "%.1fx%.1f", ex, ey);
      printf("%-6d %-7s %-15s %7.1f %7.1f%% %8.1f %9.1f%s\n", P, d ? "block" : "slab", sub,
             fmin(ex, ey), 100.0 * faces * barea / (cells2 * gnode), held * gnode / 1e6,
             pow(N + 2.0 * ghost + 1.0, 2) * gnode / 1e6,
             fmin(ex, ey) < min_cells ? "  thinner than 5 cells" : "");
    }
  }
}

/* ---- main ---------------------------------------------------------------------------- */

static void usage_error(const char *msg) {
  if (my_rank == 0)
    fprintf(stderr, "bench_mpi: %s\nusage: mpiexec -n R bench_mpi [steps] [threads] "
            "[column|centred]\n       mpiexec -n 2 bench_mpi --model [steps] [column|centred]\n",
            msg);
  MPI_Finalize();
  exit(2);
}

static int parse_int(const char *s, const char *name, int lo, int hi) {
  char *end;
  const long v = strtol(s, &end, 10);
  if (*s == '\0' || *end != '\0' || v < lo || v > hi) {
    char msg[128];
    snprintf(msg, sizeof msg, "%s must be an integer in [%d, %d], got '%s'", name, lo, hi, s);
    usage_error(msg);
  }
  return (int)v;
}

static int parse_scene(const char *s) {
  if (!strcmp(s, "column")) return 0;
  if (!strcmp(s, "centred")) return 1;
  char msg[128];
  snprintf(msg, sizeof msg, "scene must be 'column' or 'centred', got '%s'", s);
  usage_error(msg);
  return -1;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int size;
  MPI_Comm_rank(MPI_COMM_WORLD, &my_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int do_model = argc > 1 && !strcmp(argv[1], "--model");
  const int a0 = do_model ? 2 : 1;
  if (argc > a0 + (do_model ? 2 : 3)) usage_error("too many arguments");
  const int steps = argc > a0 ? parse_int(argv[a0], "steps", 1, 1000000) : 100;
  const int threads = !do_model && argc > a0 + 1 ? parse_int(argv[a0 + 1], "threads", 1, 256) : 1;
  const int sc = argc > a0 + (do_model ? 1 : 2) ? parse_scene(argv[a0 + (do_model ? 1 : 2)]) : 1;
  if (do_model) {
    if (size != 2) usage_error("--model runs on 2 ranks (mpiexec -n 2)");
    result one = {0};
    for (int k = 0; k < 3 && my_rank == 0; ++k) { /* rank 1 sleeps meanwhile */
      const result o = run(MPI_COMM_SELF, sc, 1, steps);
      if (k == 0 || o.cpu_max < one.cpu_max) one = o; /* the least disturbed of 3 */
    }
    idle_barrier();
    result two = run(MPI_COMM_WORLD, sc, 1, steps);
    largest(MPI_COMM_WORLD, &two);
    if (my_rank == 0) model(&one, &two, steps);
  } else {
    result r = run(MPI_COMM_WORLD, sc, threads, steps);
    largest(MPI_COMM_WORLD, &r);
    if (my_rank == 0) {
      printf("scene=%s ranks=%d threads=%d points=%ld steps=%d ms_per_step=%.3f "
             "outside_mpi_ms_per_step=%.3f cpu_outside_mpi_ms_per_step=%.3f "
             "cpu_outside_mpi_all_ranks=%.3f Mpoint_steps_per_s=%.3f points_per_rank=%ld..%ld",
             sc ? "centred" : "column", size, threads, r.points, steps, 1e3 * r.seconds / steps,
             1e3 * r.outside / steps, 1e3 * r.cpu_max / steps, 1e3 * r.cpu_sum / steps,
             (double)r.points * steps / r.seconds / 1e6, r.pmin, r.pmax);
      printf(" grid_nodes_held=%ld grid_nodes=%ld", r.held_max, r.whole);
      for (int k = 0; k < K_COUNT; ++k)
        if (k != K_P2P) /* halo + migration */
          printf(" %s_B=%.0f %s_msgs=%.2f", kind_name[k], r.bytes[k], kind_name[k], r.msgs[k]);
      printf("\n");
    }
  }
  MPI_Finalize();
  return 0;
}
