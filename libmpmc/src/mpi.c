/* Distributed runs over MPI (issue 47; docs/mpi.md).  Compiled into every build; the
 * functions below do something only in a build with MPMC_HAVE_MPI and for a simulation made
 * by mpmc_sim_create_mpi (sim->dd set): a serial run never calls MPI.
 *
 * Decomposition.  The grid's cells along its longest axis (ties: the outermost) are cut
 * into one slab per rank, cut[r] .. cut[r + 1] - 1, as even as whole cells allow.  Rank r
 * owns the points whose cell along that axis lies in its slab.  A point in cell c reaches
 * nodes c - 1 .. c + 2 along each axis (the cubic B-spline's stencil, the widest; transfer.h),
 * so rank r's points touch node planes cut[r] - 1 .. cut[r + 1] + 1 and its neighbours'
 * touch planes from cut[r + 1] - 1 on: the planes b - 1 .. b + 1 around each cut b, which
 * both sides' stencils reach, form the boundary's halo, which only the two ranks either side
 * of it reach when every slab is at least MPMC_DD_MIN_CELLS wide.  A point's cell is the
 * kernels' own, floor((x - origin) inv_h) (slab_cell; transfer.h), and migration after every
 * step keeps each point in its rank's slab, so no stencil reaches beyond these planes (the
 * stable F-bar form's coarser hats included: the 2h grid's and the cell centres' nodes of a
 * point in cell c lie within c - 1 .. c + 2 too).
 *
 * Halo sums.  After P2G (mass, momentum, force, and F-bar's nodal volume in the records'
 * MPMC_VSLOT) and after G2P's F-bar scatter (fbj, or fb in the stable form) each rank sends
 * its partial sums over its active box's part of each halo to the neighbour across it and
 * adds the neighbour's to its own: every halo node then holds the same sum, own + other, on
 * both ranks (one addition of two numbers, which is commutative: the same bits whatever
 * the order of arrival).  Both ranks then run the grid update on the halo nodes with the
 * same inputs and get the same velocities, so no second exchange is needed before G2P: the
 * owner's "send the updated halo back" is replaced by the same arithmetic done twice.  The
 * receiver's active box (and its rows' x ranges) grows to cover the sender's, so the
 * nodes it was sent are updated and cleared like its own.  The only difference from the
 * serial run is that order: a halo node's sum is (lower rank's points) + (upper rank's
 * points) instead of one sum in the serial slab order (round-off, tests/mpi).
 *
 * Migration.  After each step a point whose cell left the slab moves, with every per-point
 * field, its material id, global id, particle-set membership and friction anchors, to the
 * neighbour whose slab it entered; a point that went further than a neighbour stops the run.
 *
 * Load balance (mpmc_sim_set_mpi_balance, off by default).  Before a step, when due, the
 * ranks count the points per cell along the axis, place each cut where the points below it
 * come nearest to its share (slabs of MPMC_DD_MIN_CELLS or more, cuts clear of mirrored
 * walls, as check_mirrors requires), and every point goes to its new owner, any rank away.
 *
 * Failures.  Every phase of an MPI step ends with mpmc_dd_agree: a failure on any rank
 * becomes the same error code and message on every rank (the lowest failing rank's,
 * prefixed with "rank r of n: "), so that no rank waits in an exchange the others left. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "mpmc_impl.h"
#include "sets.h"

#ifndef MPMC_HAVE_MPI

int mpmc_dd_agree(const struct mpmc_sim_s *sim, int err) { return (void)sim, err < 0 ? MPMC_SUCCESS : err; }
int mpmc_dd_halo(struct mpmc_sim_s *sim, int what) { return (void)sim, (void)what, MPMC_SUCCESS; }
int mpmc_dd_migrate(struct mpmc_sim_s *sim) { return (void)sim, MPMC_SUCCESS; }
void mpmc_dd_slab_box(const struct mpmc_sim_s *sim, double *xmin, double *xmax) { (void)sim, (void)xmin, (void)xmax; }
void mpmc_dd_leaving(struct mpmc_sim_s *sim, int any) { (void)sim, (void)any; }
int mpmc_dd_agree_leaving(struct mpmc_sim_s *sim, int err, int *any) {
  return (void)sim, *any = 0, err < 0 ? MPMC_SUCCESS : err;
}
int mpmc_dd_balance_due(struct mpmc_sim_s *sim) { return (void)sim, MPMC_SUCCESS; }
int mpmc_dd_setup(struct mpmc_sim_s *sim) { return (void)sim, MPMC_SUCCESS; }
int mpmc_dd_keep(const struct mpmc_sim_s *sim, const double *x) { return (void)sim, (void)x, 1; }
void mpmc_dd_sum(const struct mpmc_sim_s *sim, double *v, int n) { (void)sim, (void)v, (void)n; }
void mpmc_dd_max(const struct mpmc_sim_s *sim, double *v, int n) { (void)sim, (void)v, (void)n; }
int mpmc_dd_owner(const struct mpmc_sim_s *sim, double v) { return (void)sim, (void)v, 1; }
void mpmc_dd_minloc(const struct mpmc_sim_s *sim, double *v, int *id) { (void)sim, (void)v, (void)id; }
void mpmc_dd_free(struct mpmc_sim_s *sim) { (void)sim; }
int mpmc_dd_ranks(const struct mpmc_sim_s *sim) { return (void)sim, 1; }
const void *mpmc_dd_comm(const struct mpmc_sim_s *sim) { return (void)sim, NULL; }

#else /* MPMC_HAVE_MPI */

#include <mpi.h>

#include "mpmc_mpi.h"

struct mpmc_dd_s {
  MPI_Comm comm;      /* a duplicate of the caller's: our messages never meet theirs */
  int rank, size;
  int axis;           /* the slab axis; -1 until the grid is set                        */
  int *cut;           /* [size + 1] each rank's first cell along axis; cut[size]: cells  */
  double *buf;        /* message buffers: send lower, send upper, receive lower, upper   */
  size_t cap;         /* doubles in each of the four                                      */
  double *gather;     /* [size * n] mpmc_dd_sum's                                         */
  int cap_gather;
  /* what this rank sent since creation (mpmc_sim_get_mpi_traffic): bytes and messages of
   * the halo sums, and of migration (its counts and records; rebalancing's included) */
  double halo_bytes, migrate_bytes;
  long halo_msgs, migrate_msgs;
  /* load balance (mpmc_sim_set_mpi_balance): every so many steps and/or beyond a max/mean
   * points threshold (0: not); the step of the last balance; balances done */
  int bal_every;
  double bal_threshold;
  long long bal_last;
  long bal_count;
  int leaving;        /* this step's G2P moved a point beyond the slab's box (mpmc_dd_slab_box) */
};

enum { TAG_HALO = 4701, TAG_MIGRATE_N = 4702, TAG_MIGRATE = 4703 };

/* The lower and upper neighbours (MPI_PROC_NULL at the ends: messages to it are no-ops). */
static int lower(const struct mpmc_dd_s *dd) { return dd->rank > 0 ? dd->rank - 1 : MPI_PROC_NULL; }
static int upper(const struct mpmc_dd_s *dd) {
  return dd->rank + 1 < dd->size ? dd->rank + 1 : MPI_PROC_NULL;
}

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
int mpmc_sim_get_mpi_slab(mpmc_const_sim sim, int *rank, int *nranks, int *axis, int *cell_lo,
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

/** @brief Bytes and messages this rank sent since creation (mpmc_mpi.h); NULL: skipped. */
int mpmc_sim_get_mpi_traffic(mpmc_const_sim sim, double *halo_bytes, long *halo_msgs,
                             double *migrated_bytes, long *migrate_msgs) {
  if (!sim) return MPMC_ERR_ARG;
  const struct mpmc_dd_s *dd = sim->dd;
  MPMC_CHECK(dd, sim->ctx, MPMC_ERR_STATE, "not a simulation of mpmc_sim_create_mpi");
  if (halo_bytes) *halo_bytes = dd->halo_bytes;
  if (halo_msgs) *halo_msgs = dd->halo_msgs;
  if (migrated_bytes) *migrated_bytes = dd->migrate_bytes;
  if (migrate_msgs) *migrate_msgs = dd->migrate_msgs;
  return MPMC_SUCCESS;
}

/* Count a message of n elements of size bytes each to neighbour to (none: MPI_PROC_NULL). */
static void count_sent(double *bytes, long *msgs, int to, size_t n, size_t size) {
  if (to == MPI_PROC_NULL) return;
  *bytes += (double)n * (double)size;
  ++*msgs;
}

int mpmc_dd_ranks(const struct mpmc_sim_s *sim) { return sim->dd ? sim->dd->size : 1; }
const void *mpmc_dd_comm(const struct mpmc_sim_s *sim) { return sim->dd ? &sim->dd->comm : NULL; }

void mpmc_dd_free(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd) return;
  int fin = 0;
  MPI_Finalized(&fin);
  if (!fin) MPI_Comm_free(&dd->comm);
  free(dd->cut);
  free(dd->buf);
  free(dd->gather);
  free(dd);
  sim->dd = NULL;
}

/* The grid's nodes this rank holds: its slab's cells' nodes and MPMC_GHOST planes either
 * side (the stencils reach one plane below a slab and two above its last cell; the halo
 * sums and the mirrored walls' folds stay within them).  When they change the grid's and
 * F-bar's node arrays are made anew at the next mpmc_sim_prepare, and adaptive damping's
 * node store keeps the planes held before and after. */
static int hold_slab(struct mpmc_sim_s *sim) {
  const struct mpmc_dd_s *dd = sim->dd;
  mpmc_grid *g = &sim->grid;
  const int ax = dd->axis, w = 1 + sim->cfg.dim;
  const mpmc_grid old = *g;
  if (!mpmc_grid_span(g, ax, dd->cut[dd->rank] - MPMC_GHOST, dd->cut[dd->rank + 1] + MPMC_GHOST))
    return MPMC_SUCCESS;
  sim->fb.nn = 0; /* F-bar's sums anew (fbar.c, mpmc_fbar_prepare) */
  sim->scr.prepared = 0;
  sim->scr.walls_dirty = 1;
  if (!sim->adr_nf) return MPMC_SUCCESS;
  const size_t need = g->nn * (size_t)w;
  double *f = malloc(need * sizeof *f);
  MPMC_CHECK(f, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate adaptive damping's node store");
  for (size_t i = 0; i < g->nn; ++i) { /* -2: no mass in the last step (damping.c) */
    long c[3]; /* node i's indices among the nodes held before */
    for (int a = 0; a < 3; ++a) c[a] = mpmc_grid_plane(g, a, i) + g->off[a] - old.off[a];
    if (c[ax] >= 0 && c[ax] < old.n[ax]) {
      const size_t o = (size_t)c[0] + (size_t)old.n[0] * ((size_t)c[1] + (size_t)old.n[1] * (size_t)c[2]);
      memcpy(f + i * (size_t)w, sim->adr_f + o * (size_t)w, sizeof(double) * (size_t)w);
    } else
      for (int k = 0; k < w; ++k) f[i * (size_t)w + k] = -2.0;
  }
  free(sim->adr_f);
  sim->adr_f = f;
  sim->adr_nf = need;
  return MPMC_SUCCESS;
}

/* The slabs of the grid just set (mpmc_sim_set_grid), and the nodes this rank holds. */
int mpmc_dd_setup(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd) return MPMC_SUCCESS;
  const mpmc_grid *g = &sim->grid;
  int ax = sim->cfg.dim - 1;
  for (int a = sim->cfg.dim - 2; a >= 0; --a)
    if (g->ng[a] > g->ng[ax]) ax = a;
  const int cells = g->ng[ax] - 1;
  MPMC_CHECK(cells >= MPMC_DD_MIN_CELLS * dd->size, sim->ctx, MPMC_ERR_ARG,
             "the grid has %d cells (ghost layers included) along its longest axis %d: too few "
             "for %d ranks, whose slabs need %d cells each; use at most %d ranks or a finer grid",
             cells, ax, dd->size, MPMC_DD_MIN_CELLS, cells / MPMC_DD_MIN_CELLS);
  int *cut = realloc(dd->cut, sizeof(int) * (size_t)(dd->size + 1));
  MPMC_CHECK(cut, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the slab cuts");
  for (int r = 0; r <= dd->size; ++r) cut[r] = (int)((long long)cells * r / dd->size);
  dd->cut = cut;
  dd->axis = ax;
  return hold_slab(sim);
}

/* The global cell of position x along the slab axis, clamped to the grid (as p2g.c's
 * count_chunk). */
static int slab_cell(const struct mpmc_sim_s *sim, const double *x) {
  const mpmc_grid *g = &sim->grid;
  const int ax = sim->dd->axis;
  const double s = (x[ax] - g->origin[ax]) * g->inv_h;
  return s >= 0.0 ? (s < g->ng[ax] - 1 ? (int)s : g->ng[ax] - 2) : 0;
}

/* The rank whose slab holds cell c. */
static int rank_of_cell(const struct mpmc_dd_s *dd, int c) {
  int lo = 0, hi = dd->size - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (dd->cut[mid] <= c)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

int mpmc_dd_keep(const struct mpmc_sim_s *sim, const double *x) {
  if (!sim->dd) return 1;
  const int c = slab_cell(sim, x);
  return c >= sim->dd->cut[sim->dd->rank] && c < sim->dd->cut[sim->dd->rank + 1];
}

/* ---- agreement and reductions --------------------------------------------------------- */

/* mpmc_dd_agree, and with any (not NULL) in the same reduction whether *any is set on some
 * rank, into *any on every rank */
static int agree(const struct mpmc_sim_s *sim, int err, int *any) {
  struct mpmc_dd_s *dd = sim->dd;
  /* a real failure first, then a follower's (MPMC_DD_FOLLOW: a rank that knows the run
   * fails but leaves the message to the rank that has the point), lowest rank first */
  const int key = err > 0 ? dd->rank : err < 0 ? dd->size + dd->rank : 2 * dd->size;
  int in[2] = {key, any && *any ? 0 : 1}, out[2] = {0, 1};
  MPI_Allreduce(in, out, any ? 2 : 1, MPI_INT, MPI_MIN, dd->comm);
  if (any) *any = !out[1];
  int root = out[0];
  if (root == 2 * dd->size) return MPMC_SUCCESS;
  root %= dd->size;
  mpmc_context ctx = sim->ctx;
  int code = err;
  char msg[MPMC_MSG_LEN];
  if (dd->rank == root) {
    if (code <= 0) code = MPMC_ERR_STATE; /* a follower without a leader: cannot happen */
    /* the message names the rank once (an error agreed already keeps its name) */
    const int k = strncmp(ctx->last_msg, "rank ", 5) ? snprintf(msg, 32, "rank %d of %d: ", dd->rank, dd->size) : 0;
    memcpy(msg + k, ctx->last_msg, MPMC_MSG_LEN - (size_t)k - 1);
    msg[MPMC_MSG_LEN - 1] = '\0';
  }
  MPI_Bcast(&code, 1, MPI_INT, root, dd->comm);
  MPI_Bcast(msg, MPMC_MSG_LEN, MPI_CHAR, root, dd->comm);
  msg[MPMC_MSG_LEN - 1] = '\0';
  ctx->last_code = code;
  memcpy(ctx->last_msg, msg, MPMC_MSG_LEN);
  return code;
}

int mpmc_dd_agree(const struct mpmc_sim_s *sim, int err) {
  if (!sim->dd) return err < 0 ? MPMC_SUCCESS : err;
  return agree(sim, err, NULL);
}

/* The step's agreement before migration: the error as mpmc_dd_agree, and *any whether a
 * point on some rank left its slab's box in this step's G2P (mpmc_dd_leaving). */
int mpmc_dd_agree_leaving(struct mpmc_sim_s *sim, int err, int *any) {
  *any = sim->dd ? sim->dd->leaving : 0;
  if (!sim->dd) return err < 0 ? MPMC_SUCCESS : err;
  return agree(sim, err, any);
}

/* G2P's box (g2p.c: a point beyond it fails the step) narrowed along the slab axis to this
 * rank's slab less a millionth of a cell, except at the grid's ends: a point still inside
 * has not left the slab (its cell, slab_cell's floor, is the slab's), one beyond it may
 * have; G2P then tells which (mpmc_dd_leaving), and only then do the ranks migrate. */
void mpmc_dd_slab_box(const struct mpmc_sim_s *sim, double *xmin, double *xmax) {
  const struct mpmc_dd_s *dd = sim->dd;
  if (!dd || dd->size == 1 || dd->axis < 0) return;
  const mpmc_grid *g = &sim->grid;
  const int a = dd->axis, lo = dd->cut[dd->rank], hi = dd->cut[dd->rank + 1];
  const double tol = 1e-6 * g->h;
  if (lo > 0) xmin[a] = g->origin[a] + lo * g->h + tol;
  if (hi < g->ng[a] - 1) xmax[a] = g->origin[a] + hi * g->h - tol;
}

void mpmc_dd_leaving(struct mpmc_sim_s *sim, int any) {
  if (sim->dd) sim->dd->leaving = any;
}

/* v[0 .. n) summed over the ranks in rank order on every rank: the same bits everywhere
 * and from run to run (an MPI_Allreduce may sum in any order). */
void mpmc_dd_sum(const struct mpmc_sim_s *sim, double *v, int n) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd || n <= 0) return;
  double local[16];
  if (n > 16 || dd->size * n > dd->cap_gather) {
    double *gb = realloc(dd->gather, sizeof(double) * (size_t)dd->size * (size_t)(n > 16 ? n : 16));
    if (!gb) { /* cannot happen for the few values summed; fall back to MPI's order */
      MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, dd->comm);
      return;
    }
    dd->gather = gb;
    dd->cap_gather = dd->size * (n > 16 ? n : 16);
  }
  double *in = v;
  if (n <= 16) {
    memcpy(local, v, sizeof(double) * (size_t)n);
    in = local;
  }
  MPI_Allgather(in, n, MPI_DOUBLE, dd->gather, n, MPI_DOUBLE, dd->comm);
  for (int k = 0; k < n; ++k) {
    double s = dd->gather[k];
    for (int r = 1; r < dd->size; ++r) s += dd->gather[(size_t)r * n + k];
    v[k] = s;
  }
}

void mpmc_dd_max(const struct mpmc_sim_s *sim, double *v, int n) {
  if (!sim->dd || n <= 0) return;
  MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_MAX, sim->dd->comm);
}

/* 1 on the lowest rank whose v is the largest over the ranks, 0 on the others. */
int mpmc_dd_owner(const struct mpmc_sim_s *sim, double v) {
  const struct mpmc_dd_s *dd = sim->dd;
  if (!dd) return 1;
  struct {
    double v;
    int r;
  } in = {v, dd->rank}, out;
  MPI_Allreduce(&in, &out, 1, MPI_DOUBLE_INT, MPI_MAXLOC, dd->comm);
  return out.r == dd->rank;
}

void mpmc_dd_minloc(const struct mpmc_sim_s *sim, double *v, int *id) {
  if (!sim->dd) return;
  struct {
    double v;
    int id;
  } in = {*v, *id >= 0 ? *id : INT_MAX}, out;
  MPI_Allreduce(&in, &out, 1, MPI_DOUBLE_INT, MPI_MINLOC, sim->dd->comm);
  *v = out.v;
  *id = out.id == INT_MAX ? -1 : out.id;
}

/* ---- halo sums ---------------------------------------------------------------------- */

static int reserve_buf(struct mpmc_sim_s *sim, size_t each) {
  struct mpmc_dd_s *dd = sim->dd;
  if (each <= dd->cap) return MPMC_SUCCESS;
  free(dd->buf);
  dd->buf = malloc(sizeof(double) * 4 * each);
  dd->cap = dd->buf ? each : 0;
  MPMC_CHECK(dd->buf, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate %zu halo values", 4 * each);
  return MPMC_SUCCESS;
}

/* Grow the active box to hold [lo, hi) and each of the box's rows' x ranges to hold
 * [lo[0], hi[0]) in the rows of [lo, hi): rows new to the box start empty. */
static void grow_box(mpmc_grid *g, const int *lo, const int *hi) {
  int olo[3], ohi[3], empty = 0;
  for (int a = 0; a < 3; ++a) {
    olo[a] = g->act_lo[a];
    ohi[a] = g->act_hi[a];
    empty |= ohi[a] <= olo[a];
  }
  int nlo[3], nhi[3];
  for (int a = 0; a < 3; ++a) {
    nlo[a] = empty || lo[a] < olo[a] ? lo[a] : olo[a];
    nhi[a] = empty || hi[a] > ohi[a] ? hi[a] : ohi[a];
  }
  const size_t n1 = (size_t)g->n[1];
  for (int k = nlo[2]; k < nhi[2]; ++k)
    for (int j = nlo[1]; j < nhi[1]; ++j) {
      int *rx = g->rowx + 2 * ((size_t)j + n1 * (size_t)k);
      if (empty || j < olo[1] || j >= ohi[1] || k < olo[2] || k >= ohi[2]) rx[0] = rx[1] = nlo[0];
      if (j < lo[1] || j >= hi[1] || k < lo[2] || k >= hi[2]) continue;
      if (rx[1] <= rx[0]) {
        rx[0] = lo[0];
        rx[1] = hi[0];
      } else {
        rx[0] = lo[0] < rx[0] ? lo[0] : rx[0];
        rx[1] = hi[0] > rx[1] ? hi[0] : rx[1];
      }
    }
  for (int a = 0; a < 3; ++a) {
    g->act_lo[a] = nlo[a];
    g->act_hi[a] = nhi[a];
  }
}

/* The halo of the cut between ranks r - 1 and r (r in 1 .. size - 1) within the active box,
 * into lo/hi; 0 if empty. */
static int halo_box(const struct mpmc_sim_s *sim, int r, int *lo, int *hi) {
  const mpmc_grid *g = &sim->grid;
  const int ax = sim->dd->axis, b = sim->dd->cut[r] - g->off[ax]; /* the held nodes' */
  int empty = 0;
  for (int a = 0; a < 3; ++a) {
    lo[a] = g->act_lo[a];
    hi[a] = g->act_hi[a];
    if (a == ax) {
      lo[a] = b - 1 > lo[a] ? b - 1 : lo[a];
      hi[a] = b + 2 < hi[a] ? b + 2 : hi[a];
    }
    empty |= hi[a] <= lo[a];
  }
  return !empty;
}

/* Pack the box [lo, hi) of arr (width doubles per node) after a header of the box (in
 * global node indices: the neighbour holds other nodes). */
static size_t pack(const mpmc_grid *g, const double *arr, int width, int ok, const int *lo,
                   const int *hi, double *out) {
  for (int a = 0; a < 3; ++a) {
    out[a] = ok ? lo[a] + g->off[a] : 0;
    out[3 + a] = ok ? hi[a] + g->off[a] : 0;
  }
  size_t k = 6;
  if (!ok) return k;
  const size_t len = (size_t)(hi[0] - lo[0]) * (size_t)width;
  for (int z = lo[2]; z < hi[2]; ++z)
    for (int y = lo[1]; y < hi[1]; ++y) {
      const size_t i0 = (size_t)lo[0] + (size_t)g->n[0] * ((size_t)y + (size_t)g->n[1] * (size_t)z);
      memcpy(out + k, arr + i0 * (size_t)width, len * sizeof(double));
      k += len;
    }
  return k;
}

/* Add a neighbour's packed box into arr (growing the active box to hold it). */
static void unpack_add(mpmc_grid *g, double *arr, int width, const double *in) {
  int lo[3], hi[3], empty = 0;
  for (int a = 0; a < 3; ++a) {
    lo[a] = (int)in[a] - g->off[a];
    hi[a] = (int)in[3 + a] - g->off[a];
    empty |= hi[a] <= lo[a];
  }
  if (empty) return;
  grow_box(g, lo, hi);
  size_t k = 6;
  const size_t len = (size_t)(hi[0] - lo[0]) * (size_t)width;
  for (int z = lo[2]; z < hi[2]; ++z)
    for (int y = lo[1]; y < hi[1]; ++y) {
      const size_t i0 = (size_t)lo[0] + (size_t)g->n[0] * ((size_t)y + (size_t)g->n[1] * (size_t)z);
      double *restrict d = arr + i0 * (size_t)width;
      const double *restrict s = in + k;
      for (size_t i = 0; i < len; ++i) d[i] += s[i];
      k += len;
    }
}

/* Walls that mirror ghost nodes across a node plane along the slab axis fold nodes up to
 * MPMC_GHOST planes either side of it into one another (grid_update.c): those planes must
 * not reach a halo, whose nodes only the halo sums complete. */
static int check_mirrors(struct mpmc_sim_s *sim) {
  const struct mpmc_dd_s *dd = sim->dd;
  for (int w = 0; w < sim->scr.nmirror; ++w) {
    const mpmc_mirror *m = &sim->scr.mirrors[w];
    if (m->axis != dd->axis) continue;
    const int plane = m->plane + sim->grid.off[m->axis]; /* global, as the cuts */
    for (int r = 1; r < dd->size; ++r) {
      const int b = dd->cut[r];
      MPMC_CHECK(plane + MPMC_GHOST < b - 1 || plane - MPMC_GHOST > b + 1, sim->ctx,
                 MPMC_ERR_UNSUPPORTED,
                 "a wall on node plane %d of axis %d lies within %d cells of the cut between "
                 "ranks %d and %d (cell %d): walls so close to a slab boundary are not supported "
                 "over MPI yet; use another number of ranks",
                 plane, m->axis, MPMC_GHOST + 1, r - 1, r, b);
    }
  }
  return MPMC_SUCCESS;
}

/* Exchange and add the halo sums of what (MPMC_DD_NODES: the node records after P2G;
 * MPMC_DD_FBAR: F-bar's fbj or fb after G2P's scatter) with both neighbours. */
int mpmc_dd_halo(struct mpmc_sim_s *sim, int what) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd || dd->size == 1) return MPMC_SUCCESS;
  mpmc_grid *g = &sim->grid;
  double *arr;
  int width;
  if (what == MPMC_DD_NODES) {
    if (sim->scr.walls_dirty) MPMC_CALL(mpmc_boundary_apply_flags(sim)); /* the mirrors */
    MPMC_CALL(check_mirrors(sim));
    arr = g->node;
    width = MPMC_NREC;
  } else if (sim->cfg.fbar == MPMC_FBAR_STABLE) {
    arr = sim->fb.fb;
    width = 2;
  } else {
    arr = sim->fb.fbj;
    width = 1;
  }
  const int ax = dd->axis;
  size_t plane = 1;
  for (int a = 0; a < 3; ++a)
    if (a != ax) plane *= (size_t)g->n[a];
  const size_t each = 6 + 5 * plane * (size_t)width;
  MPMC_CALL(reserve_buf(sim, each));
  double *sl = dd->buf, *su = sl + each, *rl = su + each, *ru = rl + each;
  int lo[3], hi[3];
  /* the box of what this rank sends is its active box before the neighbours' grow it */
  const int okl = dd->rank > 0 && halo_box(sim, dd->rank, lo, hi);
  const size_t nl = pack(g, arr, width, okl, lo, hi, sl);
  const int oku = dd->rank + 1 < dd->size && halo_box(sim, dd->rank + 1, lo, hi);
  const size_t nu = pack(g, arr, width, oku, lo, hi, su);
  MPI_Request req[4];
  MPI_Irecv(rl, (int)each, MPI_DOUBLE, lower(dd), TAG_HALO, dd->comm, &req[0]);
  MPI_Irecv(ru, (int)each, MPI_DOUBLE, upper(dd), TAG_HALO, dd->comm, &req[1]);
  MPI_Isend(sl, (int)nl, MPI_DOUBLE, lower(dd), TAG_HALO, dd->comm, &req[2]);
  MPI_Isend(su, (int)nu, MPI_DOUBLE, upper(dd), TAG_HALO, dd->comm, &req[3]);
  count_sent(&dd->halo_bytes, &dd->halo_msgs, lower(dd), nl, sizeof(double));
  count_sent(&dd->halo_bytes, &dd->halo_msgs, upper(dd), nu, sizeof(double));
  MPI_Waitall(4, req, MPI_STATUSES_IGNORE);
  /* the sends are done before the adds change arr; the two halos share no node */
  if (dd->rank > 0) unpack_add(g, arr, width, rl);
  if (dd->rank + 1 < dd->size) unpack_add(g, arr, width, ru);
  return MPMC_SUCCESS;
}

/* ---- migration ------------------------------------------------------------------------ */

/* The per-point fields that move with a point: doubles, with the value a receiver that
 * lacks the field (not yet allocated there) fills in for its own points. */
typedef struct {
  double **a;
  int nc;
  double fill;
} field;

static int fields_of(struct mpmc_sim_s *sim, field *f) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  int k = 0;
  f[k++] = (field){&p->x, d, 0.0};
  f[k++] = (field){&p->x0, d, 0.0};
  f[k++] = (field){&p->v, d, 0.0};
  f[k++] = (field){&p->m, 1, 0.0};
  f[k++] = (field){&p->vol0, 1, 0.0};
  f[k++] = (field){&p->J, 1, 1.0};
  f[k++] = (field){&p->stress, 6, 0.0};
  f[k++] = (field){&p->Jbar, 1, 1.0};
  f[k++] = (field){&p->Janc, 1, 1.0};
  f[k++] = (field){&p->be, 6, NAN}; /* NAN: the identity */
  f[k++] = (field){&p->eps_p, 1, 0.0};
  f[k++] = (field){&p->region, 1, 0.0};
  f[k++] = (field){&p->Jp, 1, 1.0};
  f[k++] = (field){&p->pw, 1, 0.0};
  f[k++] = (field){&p->lp, 1, 0.0};
  f[k++] = (field){&p->force, d, 0.0};
  f[k++] = (field){&p->cforce, d, 0.0};
  f[k++] = (field){&p->ustate, p->nustate, 0.0};
  return k;
}
#define MAX_FIELDS 18

/* Make sure the optional field f exists here (a sender had it). */
static int ensure_field(struct mpmc_sim_s *sim, const field *f) {
  if (*f->a || f->nc <= 0) return MPMC_SUCCESS;
  mpmc_particles *p = &sim->p;
  MPMC_CALL(mpmc_particles_ensure(sim->ctx, p, f->a, f->nc, isnan(f->fill) ? 0.0 : f->fill));
  if (isnan(f->fill))
    for (int q = 0; q < p->n; ++q)
      for (int c = 0; c < 3; ++c) (*f->a)[(size_t)q * 6 + c] = 1.0;
  return MPMC_SUCCESS;
}

/* Doubles per point in a message with the fields of mask, and the sets' flags. */
static int record_len(const field *f, int nf, unsigned mask, int nsets) {
  int len = 2 + nsets; /* material id, global id, set flags */
  for (int k = 0; k < nf; ++k)
    if (mask >> k & 1u) len += f[k].nc;
  return len;
}

/* Move the rows of the staying points (map[q] >= 0) of a [n][nc] array to map[q]. */
static void compact(double *a, int nc, const int *map, int n) {
  for (int q = 0; q < n; ++q)
    if (map[q] >= 0 && map[q] != q)
      memcpy(a + (size_t)map[q] * (size_t)nc, a + (size_t)q * (size_t)nc, (size_t)nc * sizeof(double));
}

/* Append one arriving point from its record o (fields of the sender's mask msk). */
static void unpack_point(struct mpmc_sim_s *sim, const field *f, int nf, unsigned msk, int nsets,
                         const double *o) {
  mpmc_particles *p = &sim->p;
  const int q = p->n++;
  int k = 0;
  p->mat[q] = (int)o[k++];
  p->id[q] = (int)o[k++];
  for (int t = 0; t < nsets; ++t)
    if (o[k++] != 0.0) {
      mpmc_set *st = &sim->sets->s[t];
      st->idx[st->n++] = q;
    }
  for (int i = 0; i < nf; ++i) {
    if (!*f[i].a || f[i].nc <= 0) continue;
    double *a = *f[i].a + (size_t)q * f[i].nc;
    if (msk >> i & 1u) {
      for (int c = 0; c < f[i].nc; ++c) a[c] = o[k++];
    } else {
      for (int c = 0; c < f[i].nc; ++c) a[c] = isnan(f[i].fill) ? (c < 3) : f[i].fill;
    }
  }
  for (int b = 0; sim->bodies && b < sim->bodies->n; ++b) {
    mpmc_body *B = &sim->bodies->b[b];
    if (B->mu > 0.0)
      for (int c = 0; c < 3; ++c) B->anchor[3 * (size_t)q + c] = o[k++];
  }
}

/* Bodies with friction (mu > 0): each point carries 3 anchor values per such body (NaN:
 * out of contact), the same bodies on every rank. */
static int anchor_bodies(const struct mpmc_sim_s *sim) {
  int k = 0;
  for (int b = 0; sim->bodies && b < sim->bodies->n; ++b) k += sim->bodies->b[b].mu > 0.0;
  return k;
}

/* The anchors of every body with friction cover n points (new ones NaN). */
static int reserve_anchors(struct mpmc_sim_s *sim, int n, int only_allocated) {
  for (int b = 0; sim->bodies && b < sim->bodies->n; ++b) {
    mpmc_body *B = &sim->bodies->b[b];
    if (B->mu > 0.0 && (B->anchor || !only_allocated))
      MPMC_CALL(mpmc_contact_reserve_anchors(sim, B, n));
  }
  return MPMC_SUCCESS;
}

/* A migration header per destination: points, field mask, sets, bodies with anchors. */
enum { HDR = 4 };

/* Doubles per point of a sender's header h. */
static size_t sender_len(const field *f, int nf, const int *h) {
  return (size_t)record_len(f, nf, (unsigned)h[1], h[2]) + 3 * (size_t)h[3];
}

/* Exchange count ints per rank of snd into rcv (int) or doubles (at displacements) with the
 * neighbours only (far == 0) or with every rank (far == 1), counting what is sent. */
static void exchange(struct mpmc_dd_s *dd, int far, MPI_Datatype type, const void *snd,
                     const int *scount, const int *sdispl, void *rcv, const int *rcount,
                     const int *rdispl, int tag) {
  const size_t size = type == MPI_INT ? sizeof(int) : sizeof(double);
  if (far) {
    MPI_Alltoallv(snd, scount, sdispl, type, rcv, rcount, rdispl, type, dd->comm);
    for (int r = 0; r < dd->size; ++r)
      if (r != dd->rank && (scount[r] > 0 || type == MPI_INT))
        count_sent(&dd->migrate_bytes, &dd->migrate_msgs, r, (size_t)scount[r], size);
    return;
  }
  MPI_Request req[4];
  int k = 0;
  for (int s = -1; s <= 1; s += 2) {
    const int r = dd->rank + s;
    if (r < 0 || r >= dd->size) continue;
    MPI_Irecv((char *)rcv + size * (size_t)rdispl[r], rcount[r], type, r, tag, dd->comm, &req[k++]);
    MPI_Isend((const char *)snd + size * (size_t)sdispl[r], scount[r], type, r, tag, dd->comm, &req[k++]);
    count_sent(&dd->migrate_bytes, &dd->migrate_msgs, r, (size_t)scount[r], size);
  }
  MPI_Waitall(k, req, MPI_STATUSES_IGNORE);
}

/* Points whose cell is not in this rank's slab go, with all their state, to the rank whose
 * slab holds it: a neighbour after a step (far == 0; further fails), any rank after the
 * cuts moved (far == 1, a load balance).  Arrivals are appended in their senders' rank
 * order, each sender's in its storage order. */
static int migrate(struct mpmc_sim_s *sim, int far) {
  struct mpmc_dd_s *dd = sim->dd;
  mpmc_context ctx = sim->ctx;
  mpmc_particles *p = &sim->p;
  const int n = p->n, me = dd->rank, P = dd->size;
  int *dest = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
  /* per rank: headers sent and received, then counts and displacements (doubles) */
  int *ib = calloc((size_t)P * (2 * HDR + 4), sizeof(int));
  int err = dest && ib ? MPMC_SUCCESS : MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory");
  int *hs = ib, *hr = hs + (size_t)P * HDR, *sc = hr + (size_t)P * HDR, *sd = sc + P, *rc = sd + P,
      *rd = rc + P;
  int nout = 0;
  for (int q = 0; q < n && !err; ++q) {
    const int c = slab_cell(sim, p->x + (size_t)q * sim->cfg.dim);
    const int r = c < dd->cut[me] || c >= dd->cut[me + 1] ? rank_of_cell(dd, c) : me;
    dest[q] = r;
    if (!far && (r < me - 1 || r > me + 1)) {
      char nb[MPMC_POINT_NAME_LEN];
      const double *x = p->x + (size_t)q * sim->cfg.dim;
      err = MPMC_ERROR(ctx, MPMC_ERR_UNSTABLE,
                       "step %lld, t = %g: point %s at (%g, %g, %g) moved from rank %d's slab "
                       "(cells %d .. %d along axis %d) to rank %d's in one step, across more "
                       "than one subdomain: reduce the time step or use fewer ranks",
                       (long long)sim->stats.steps, sim->time, mpmc_point_name(p, q, nb), x[0],
                       x[1], sim->cfg.dim == 3 ? x[2] : 0.0, me, dd->cut[me], dd->cut[me + 1] - 1,
                       dd->axis, r);
    } else if (r != me) {
      hs[(size_t)r * HDR]++;
      nout++;
    }
  }
  if (!err) err = reserve_anchors(sim, n, 1); /* points added since the last contact pass */
  err = mpmc_dd_agree(sim, err);
  if (err) {
    free(dest);
    free(ib);
    return err;
  }
  field f[MAX_FIELDS];
  const int nf = fields_of(sim, f);
  unsigned mask = 0;
  for (int k = 0; k < nf; ++k)
    if (*f[k].a && f[k].nc > 0) mask |= 1u << k;
  const int nsets = sim->sets ? sim->sets->n : 0, nanc = anchor_bodies(sim);
  const int len = record_len(f, nf, mask, nsets) + 3 * nanc;
  for (int r = 0; r < P; ++r) {
    int *h = hs + (size_t)r * HDR;
    h[1] = (int)mask;
    h[2] = nsets;
    h[3] = nanc;
    sc[r] = rc[r] = HDR;
    sd[r] = rd[r] = r * HDR;
  }
  exchange(dd, far, MPI_INT, hs, sc, sd, hr, rc, rd, TAG_MIGRATE_N);
  size_t stot = 0, rtot = 0;
  int nin = 0;
  for (int r = 0; r < P; ++r) {
    const int *h = hr + (size_t)r * HDR;
    sd[r] = (int)stot;
    sc[r] = hs[(size_t)r * HDR] * len;
    stot += (size_t)sc[r];
    rd[r] = (int)rtot;
    rc[r] = r == me ? 0 : (int)((size_t)h[0] * sender_len(f, nf, h));
    rtot += (size_t)rc[r];
    if (r == me || h[0] <= 0) continue;
    nin += h[0];
    if ((h[2] != nsets || h[3] != nanc) && !err)
      err = MPMC_ERROR(ctx, MPMC_ERR_STATE,
                       "migration: rank %d has %d particle sets and %d rigid bodies with "
                       "friction, rank %d %d and %d: add sets and bodies on every rank alike",
                       me, nsets, nanc, r, h[2], h[3]);
  }
  /* set membership of this rank's points, one flag array per set */
  int *member = NULL;
  if (nsets > 0 && nout) {
    member = calloc((size_t)nsets * (size_t)(n > 0 ? n : 1), sizeof(int));
    if (!member && !err) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory");
    for (int k = 0; k < nsets && member; ++k) {
      const mpmc_set *st = &sim->sets->s[k];
      for (int j = 0; j < st->n; ++j)
        if (st->idx[j] >= 0 && st->idx[j] < n) member[(size_t)k * n + st->idx[j]] = 1;
    }
  }
  double *sb = malloc(sizeof(double) * (stot + rtot + 1));
  if (!sb && !err) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory for the messages");
  err = mpmc_dd_agree(sim, err);
  if (err) {
    free(dest);
    free(ib);
    free(member);
    free(sb);
    return err;
  }
  double *rb = sb + stot;
  size_t *pos = calloc((size_t)P, sizeof(size_t));
  for (int q = 0; q < n && pos; ++q) {
    if (dest[q] == me) continue;
    double *o = sb + sd[dest[q]] + pos[dest[q]];
    int k = 0;
    o[k++] = p->mat[q];
    o[k++] = p->id ? p->id[q] : q;
    for (int j = 0; j < nsets; ++j) o[k++] = member[(size_t)j * n + q];
    for (int i = 0; i < nf; ++i)
      if (mask >> i & 1u)
        for (int c = 0; c < f[i].nc; ++c) o[k++] = (*f[i].a)[(size_t)q * f[i].nc + c];
    for (int b = 0; sim->bodies && b < sim->bodies->n; ++b) {
      const mpmc_body *B = &sim->bodies->b[b];
      if (!(B->mu > 0.0)) continue;
      for (int c = 0; c < 3; ++c) o[k++] = B->anchor ? B->anchor[3 * (size_t)q + c] : NAN;
    }
    pos[dest[q]] += (size_t)len;
  }
  if (!pos) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory");
  free(pos);
  err = mpmc_dd_agree(sim, err);
  if (!err) exchange(dd, far, MPI_DOUBLE, sb, sc, sd, rb, rc, rd, TAG_MIGRATE);

  /* the staying points close ranks, in order; sets renumbered */
  int m = 0;
  if (!err && nout) {
    int *map = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (!map) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory");
    for (int q = 0; q < n && map; ++q) map[q] = dest[q] != me ? -1 : m++;
    if (map) {
      for (int i = 0; i < nf; ++i)
        if (*f[i].a && f[i].nc > 0) compact(*f[i].a, f[i].nc, map, n);
      for (int b = 0; sim->bodies && b < sim->bodies->n; ++b)
        if (sim->bodies->b[b].mu > 0.0 && sim->bodies->b[b].anchor)
          compact(sim->bodies->b[b].anchor, 3, map, n);
      for (int q = 0; q < n; ++q)
        if (map[q] >= 0) {
          p->mat[map[q]] = p->mat[q];
          if (p->id) p->id[map[q]] = p->id[q];
        }
      for (int k = 0; k < nsets; ++k) {
        mpmc_set *st = &sim->sets->s[k];
        int j2 = 0;
        for (int j = 0; j < st->n; ++j)
          if (st->idx[j] >= 0 && st->idx[j] < n && map[st->idx[j]] >= 0) st->idx[j2++] = map[st->idx[j]];
        st->n = j2;
      }
      free(map);
    }
  } else {
    m = n;
  }
  if (!err) p->n = m;
  /* the arrivals, in their senders' rank order */
  if (!err && nin > 0) {
    int cap = p->cap ? p->cap : 64;
    while (cap < m + nin) cap *= 2;
    err = mpmc_particles_reserve(ctx, p, cap);
    unsigned any = 0;
    for (int r = 0; r < P; ++r)
      if (r != me && hr[(size_t)r * HDR] > 0) any |= (unsigned)hr[(size_t)r * HDR + 1];
    for (int i = 0; i < nf && !err; ++i)
      if (any >> i & 1u) err = ensure_field(sim, &f[i]);
    if (!err) err = reserve_anchors(sim, m + nin, 0);
    if (!err && !p->id) {
      p->id = malloc(sizeof(int) * (size_t)p->cap);
      if (!p->id) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory for the ids");
      for (int q = 0; q < m && p->id; ++q) p->id[q] = q;
    }
    for (int k = 0; k < nsets && !err; ++k) { /* room for every arrival in every set */
      mpmc_set *st = &sim->sets->s[k];
      int *idx = realloc(st->idx, sizeof(int) * (size_t)(st->n + nin));
      if (!idx) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "migration: no memory for the sets");
      else st->idx = idx;
    }
    for (int r = 0; r < P && !err; ++r) {
      const int *h = hr + (size_t)r * HDR;
      if (r == me || h[0] <= 0) continue;
      const unsigned msk = (unsigned)h[1];
      const size_t rl = sender_len(f, nf, h);
      for (int j = 0; j < h[0]; ++j)
        unpack_point(sim, f, nf, msk, nsets, rb + rd[r] + (size_t)j * rl);
    }
  }
  free(dest);
  free(ib);
  free(member);
  free(sb);
  if (nin > 0 || nout) {
    sim->scr.order_ident = 0;
    sim->scr.v2max_ok = 0; /* the stability limit takes its pass over v (stability.c) */
  }
  return mpmc_dd_agree(sim, err);
}

int mpmc_dd_migrate(struct mpmc_sim_s *sim) {
  if (!sim->dd || sim->dd->size == 1) return MPMC_SUCCESS;
  return migrate(sim, 0);
}

/* ---- load balance --------------------------------------------------------------------- */

/** @brief Move the cuts every every_n_steps steps and/or when max/mean points exceeds
 *         threshold (mpmc_mpi.h); 0 and 0: fixed slabs (the default). */
int mpmc_sim_set_mpi_balance(mpmc_sim sim, int every_n_steps, double threshold) {
  if (!sim) return MPMC_ERR_ARG;
  struct mpmc_dd_s *dd = sim->dd;
  MPMC_CHECK(dd, sim->ctx, MPMC_ERR_STATE, "not a simulation of mpmc_sim_create_mpi");
  MPMC_CHECK(every_n_steps >= 0, sim->ctx, MPMC_ERR_ARG,
             "every_n_steps = %d must be >= 0 (0: no periodic balance)", every_n_steps);
  MPMC_CHECK(threshold == 0 || (isfinite(threshold) && threshold >= 1), sim->ctx, MPMC_ERR_ARG,
             "threshold = %g must be 0 (none) or >= 1 (the most points on a rank over the mean)",
             threshold);
  dd->bal_every = every_n_steps;
  dd->bal_threshold = threshold;
  dd->bal_last = sim->stats.steps;
  return MPMC_SUCCESS;
}

/* The most points on a rank over the mean (1: even; collective). */
static double imbalance(const struct mpmc_sim_s *sim) {
  long long n = sim->p.n, mx = 0, sum = 0;
  MPI_Allreduce(&n, &mx, 1, MPI_LONG_LONG, MPI_MAX, sim->dd->comm);
  MPI_Allreduce(&n, &sum, 1, MPI_LONG_LONG, MPI_SUM, sim->dd->comm);
  return sum > 0 ? (double)mx * sim->dd->size / (double)sum : 1.0;
}

/** @brief The most points on a rank over the mean over the ranks (collective; mpmc_mpi.h). */
int mpmc_sim_get_mpi_imbalance(mpmc_const_sim sim, double *value, long *balances) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(sim->dd, sim->ctx, MPMC_ERR_STATE, "not a simulation of mpmc_sim_create_mpi");
  if (value) *value = imbalance(sim);
  if (balances) *balances = sim->dd->bal_count;
  return MPMC_SUCCESS;
}

/* Cut c moved out of the reach of the walls mirrored along the slab axis (check_mirrors:
 * planes within MPMC_GHOST + 1 of a cut), to the nearer allowed side within [lo, hi];
 * -1 if there is none. */
static int clear_of_mirrors(const struct mpmc_sim_s *sim, int c, int lo, int hi) {
  const int reach = MPMC_GHOST + 1;
  for (int pass = 0; pass <= sim->scr.nmirror; ++pass) {
    int moved = 0;
    for (int w = 0; w < sim->scr.nmirror; ++w) {
      const mpmc_mirror *m = &sim->scr.mirrors[w];
      const int plane = m->plane + sim->grid.off[m->axis]; /* global, as the cuts */
      if (m->axis != sim->dd->axis || c < plane - reach || c > plane + reach) continue;
      const int below = plane - reach - 1, above = plane + reach + 1;
      const int okb = below >= lo && below <= hi, oka = above >= lo && above <= hi;
      if (!okb && !oka) return -1;
      c = okb && (!oka || c - below <= above - c) ? below : above;
      moved = 1;
    }
    if (!moved) return c;
  }
  return -1;
}

/* The nodes of the new cuts' slab, then every point to its new owner (collective). */
static int recut(struct mpmc_sim_s *sim) {
  int err = hold_slab(sim); /* the new slab's nodes, made before the step's phases */
  if (!err) err = mpmc_sim_prepare(sim);
  err = mpmc_dd_agree(sim, err);
  return err ? err : migrate(sim, 1);
}

/* New cuts that split the points evenly (whole cells, slabs of MPMC_DD_MIN_CELLS or more,
 * clear of mirrored walls), then every point to its new owner (collective). */
static int balance(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  const int P = dd->size, cells = dd->cut[P];
  if (sim->scr.walls_dirty) MPMC_CALL(mpmc_boundary_apply_flags(sim)); /* the mirrors */
  long long *cum = calloc((size_t)cells + 1, sizeof *cum);
  int *nc = malloc(sizeof(int) * (size_t)(P + 1));
  int err = cum && nc ? MPMC_SUCCESS : MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "balance: no memory");
  err = mpmc_dd_agree(sim, err);
  if (err) {
    free(cum);
    free(nc);
    return err;
  }
  for (int q = 0; q < sim->p.n; ++q) cum[1 + slab_cell(sim, sim->p.x + (size_t)q * sim->cfg.dim)]++;
  MPI_Allreduce(MPI_IN_PLACE, cum + 1, cells, MPI_LONG_LONG, MPI_SUM, dd->comm);
  for (int c = 1; c <= cells; ++c) cum[c] += cum[c - 1]; /* cum[c]: points in cells < c */
  nc[0] = 0;
  nc[P] = cells;
  int ok = 1;
  for (int r = 1; r < P && ok; ++r) {
    const double target = (double)cum[cells] * r / P;
    const int lo = nc[r - 1] + MPMC_DD_MIN_CELLS, hi = cells - MPMC_DD_MIN_CELLS * (P - r);
    int c = lo;
    while (c < hi && (double)cum[c + 1] <= target) ++c;
    if (c < hi && target - (double)cum[c] > (double)cum[c + 1] - target) ++c;
    c = clear_of_mirrors(sim, c, lo, hi);
    ok = c >= 0;
    nc[r] = c;
  }
  int same = 1;
  for (int r = 0; r <= P && ok; ++r) same &= nc[r] == dd->cut[r];
  free(cum);
  if (ok && !same) memcpy(dd->cut, nc, sizeof(int) * (size_t)(P + 1));
  free(nc);
  if (!ok || same) return MPMC_SUCCESS; /* no better cuts (or none the walls allow) */
  dd->bal_count++;
  return recut(sim);
}

/* The cuts moved out of the reach of the walls mirrored along the slab axis, each the least
 * way (clear_of_mirrors), when the walls have changed: a wall on a node plane near a cut
 * (a scene's floor, a slab thin at its CI size on 4 ranks) is not refused (check_mirrors)
 * while a slab boundary clear of it exists.  Every rank holds every wall: the same cuts on
 * each (collective). */
static int clear_cuts(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!sim->scr.walls_dirty) return MPMC_SUCCESS; /* the cuts were cleared for these walls */
  MPMC_CALL(mpmc_boundary_apply_flags(sim)); /* the mirrors */
  const int P = dd->size, cells = dd->cut[P];
  int *nc = malloc(sizeof(int) * (size_t)(P + 1)), ok = nc != NULL, same = 1;
  MPMC_CALL(mpmc_dd_agree(sim, ok ? MPMC_SUCCESS : MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "no memory for the cuts")));
  nc[0] = 0;
  nc[P] = cells;
  for (int r = 1; r < P && ok; ++r) {
    const int lo = nc[r - 1] + MPMC_DD_MIN_CELLS, hi = cells - MPMC_DD_MIN_CELLS * (P - r);
    nc[r] = clear_of_mirrors(sim, dd->cut[r] < lo ? lo : dd->cut[r], lo, hi);
    ok = nc[r] >= 0;
    same &= nc[r] == dd->cut[r];
  }
  if (ok && !same) memcpy(dd->cut, nc, sizeof(int) * (size_t)(P + 1));
  free(nc);
  return !ok || same ? MPMC_SUCCESS : recut(sim); /* none clear: check_mirrors says so */
}

/* Before a step: the cuts clear of new walls, and a balance if due (mpmc_sim_set_mpi_balance;
 * collective). */
int mpmc_dd_balance_due(struct mpmc_sim_s *sim) {
  struct mpmc_dd_s *dd = sim->dd;
  if (!dd || dd->size == 1 || dd->axis < 0) return MPMC_SUCCESS;
  MPMC_CALL(clear_cuts(sim));
  if (!dd->bal_every && !(dd->bal_threshold > 0)) return MPMC_SUCCESS;
  int due = dd->bal_every > 0 && sim->stats.steps - dd->bal_last >= dd->bal_every;
  if (!due && dd->bal_threshold > 0) due = imbalance(sim) > dd->bal_threshold;
  if (!due) return MPMC_SUCCESS;
  dd->bal_last = sim->stats.steps;
  return balance(sim);
}

#endif /* MPMC_HAVE_MPI */

/* ---- every rank's records ------------------------------------------------------------ */

int mpmc_dd_exchange(struct mpmc_sim_s *sim, const void *send, const int *scount, size_t size, void **recv,
                     int *rcount, int *rtotal) {
  *recv = NULL;
  *rtotal = 0;
#ifdef MPMC_HAVE_MPI
  struct mpmc_dd_s *dd = sim->dd;
  if (dd) {
    const int P = dd->size;
    int *sd = malloc(sizeof *sd * 2 * (size_t)P), err = MPMC_SUCCESS;
    if (!sd) err = MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "cannot allocate the counts of %d ranks", P);
    MPMC_CALL(mpmc_dd_agree(sim, err)); /* every rank has its counts, or none goes on */
    int *rd = sd + P;
    MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, dd->comm);
    long long s = 0, r = 0;
    for (int k = 0; k < P; ++k) {
      sd[k] = (int)s;
      rd[k] = (int)r;
      s += scount[k];
      r += rcount[k];
    }
    if (r > INT_MAX)
      err = MPMC_ERROR(sim->ctx, MPMC_ERR_ARG, "%lld records for one rank: more than %d", r, INT_MAX);
    else if (!(*recv = malloc(size * (size_t)(r > 0 ? r : 1))))
      err = MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "cannot allocate %lld records of %zu bytes", r, size);
    if ((err = mpmc_dd_agree(sim, err))) {
      free(sd);
      free(*recv);
      *recv = NULL;
      return err;
    }
    MPI_Datatype rec;
    MPI_Type_contiguous((int)size, MPI_BYTE, &rec);
    MPI_Type_commit(&rec);
    MPI_Alltoallv(send, scount, sd, rec, *recv, rcount, rd, rec, dd->comm);
    MPI_Type_free(&rec);
    *rtotal = (int)r;
    free(sd);
    return MPMC_SUCCESS;
  }
#endif
  const int n = scount[0];
  MPMC_CHECK(*recv = malloc(size * (size_t)(n > 0 ? n : 1)), sim->ctx, MPMC_ERR_MEMORY,
             "cannot allocate %d records of %zu bytes", n, size);
  if (n > 0) memcpy(*recv, send, size * (size_t)n);
  rcount[0] = *rtotal = n;
  return MPMC_SUCCESS;
}

/* Of the non-negative doubles the bit patterns are ordered as the values: the least pattern
 * t with more than k values at or below it, by bisection, is the k-th smallest value. */
double mpmc_dd_kth(const struct mpmc_sim_s *sim, const double *v, int n, long long k) {
  uint64_t lo = 0, hi = UINT64_C(0x7ff0000000000000); /* +0 .. +inf */
  while (lo < hi) {
    const uint64_t mid = lo + (hi - lo) / 2;
    long long c = 0;
    for (int q = 0; q < n; ++q) {
      uint64_t b;
      memcpy(&b, v + q, sizeof b);
      c += b <= mid;
    }
#ifdef MPMC_HAVE_MPI
    if (sim->dd) MPI_Allreduce(MPI_IN_PLACE, &c, 1, MPI_LONG_LONG, MPI_SUM, sim->dd->comm);
#else
    (void)sim;
#endif
    if (c > k)
      hi = mid;
    else
      lo = mid + 1;
  }
  double t;
  memcpy(&t, &lo, sizeof t);
  return t;
}
