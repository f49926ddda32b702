/* The front end over MPI (docs/mpi.md, "The mpmc front end").
 *
 * In a build with -DMPMC_WITH_MPI=ON a run whose program has initialised MPI with more than
 * one rank in MPI_COMM_WORLD (`mpirun -np 4 mpmc run SCENE.yaml`) is one simulation over those
 * ranks (mpmc_sim_create_mpi); otherwise, and always in the serial build, it is the
 * one-process run, unchanged.  Every rank runs the same workflow: it reads the scene, makes
 * the same library calls (all collective) and takes the same decisions; rank 0 alone writes
 * the files of the front end (series.csv, summary.json, plots) and the log.
 *
 * The series' metrics read each rank's own points (wf_own_*) and reduce what a reduction
 * gives exactly in any order: a maximum, the value of the one rank that holds a point, and
 * sums in exact arithmetic (wf_xsum, wf_par_xsum), so every rank has the same metrics, to
 * the bit, whatever the number of ranks; so do the metrics' set-up and the factor of
 * safety's verdict.  Only what rank 0 writes point by point (the plots' CSVs, the factor of
 * safety's mechanism) goes through wf_root_*: in one process the library's arrays as they
 * are; over MPI every rank's points gathered on rank 0 alone and put in the order of their
 * global ids.  A gather costs O(all points) on rank 0 per call: it is done per plot and
 * stage, not per step; the points' order by global id is kept between steps
 * (order_update). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "wf.h"

/* A rank without points may hold no array: its part is empty; the others' code decides (in
 * one process e as it is: wf_par_agree). */
static int local_part(mpmc_sim sim, int e) {
  int n = 0;
  mpmc_sim_get_num_particles(sim, &n);
  return wf_par_agree(n == 0 ? 0 : e);
}

/* ---- exact sums ---------------------------------------------------------------------- */

#define XSUM_LOW 1074 /* the bit of 2^0: the lowest bit is 2^-1074 */
#define XSUM_MASK 0xffffffffu

/* The digits to [0, 2^32), carrying upwards; the top digit keeps the sign.  The value is
 * unchanged: each digit's excess is an exact multiple of 2^32 (the division is exact). */
static void xsum_normalize(wf_xsum *s) {
  for (int i = 0; i + 1 < WF_XSUM_DIGITS; ++i) {
    const int64_t low = (int64_t)((uint64_t)s->d[i] & XSUM_MASK);
    s->d[i + 1] += (s->d[i] - low) / ((int64_t)1 << 32);
    s->d[i] = low;
  }
  s->adds = 0;
}

/* x = m 2^(p - 1074) with m < 2^53 an integer: m's bits into digits p / 32 .. p / 32 + 2.
 * A digit takes at most two parts below 2^32 an addition, so 2^29 additions between two
 * normalisations stay far below 2^63. */
void wf_xsum_add(wf_xsum *s, double x) {
  if (!isfinite(x)) {
    s->special += x;
    return;
  }
  if (x == 0.0) return;
  if (++s->adds >= (1L << 29)) xsum_normalize(s);
  int e;
  uint64_t m = (uint64_t)ldexp(frexp(fabs(x), &e), 53); /* exact: 53 bits */
  int p = e - 53 + XSUM_LOW;
  if (p < 0) { /* a subnormal: its bits below 2^-1074 are zero */
    m >>= -p;
    p = 0;
  }
  const int k = p / 32, sh = p % 32;
  const uint64_t lo = (m & XSUM_MASK) << sh, hi = (m >> 32) << sh; /* below 2^64, 2^53 */
  const int64_t a0 = (int64_t)(lo & XSUM_MASK), a1 = (int64_t)((lo >> 32) + (hi & XSUM_MASK)),
                a2 = (int64_t)(hi >> 32);
  const int64_t sg = x < 0 ? -1 : 1;
  s->d[k] += sg * a0;
  s->d[k + 1] += sg * a1;
  s->d[k + 2] += sg * a2;
}

static int xsum_bit(const wf_xsum *s, int i) { return (int)((uint64_t)s->d[i / 32] >> (i % 32) & 1u); }

/* Normalised, the magnitude's bits read off from the highest one: 53 of them, rounded to
 * nearest (ties to even) by the next bit and the rest; below 2^-1022 every bit is kept. */
double wf_xsum_value(wf_xsum *s) {
  if (s->special != 0.0 || isnan(s->special)) return s->special;
  xsum_normalize(s);
  wf_xsum a = *s;
  const int neg = a.d[WF_XSUM_DIGITS - 1] < 0;
  if (neg) {
    for (int i = 0; i < WF_XSUM_DIGITS; ++i) a.d[i] = -a.d[i];
    xsum_normalize(&a);
  }
  int top = 32 * WF_XSUM_DIGITS - 1;
  while (top >= 0 && !xsum_bit(&a, top)) --top;
  if (top < 0) return 0.0;
  const int lo = top >= 52 ? top - 52 : 0;
  uint64_t m = 0;
  for (int i = top; i >= lo; --i) m = m << 1 | (uint64_t)xsum_bit(&a, i);
  if (lo > 0 && xsum_bit(&a, lo - 1)) { /* at least half an ulp: up unless an exact tie at even */
    int rest = 0;
    for (int i = lo - 2; i >= 0 && !rest; --i) rest = xsum_bit(&a, i);
    if (rest || (m & 1u)) ++m;
  }
  const double v = ldexp((double)m, lo - XSUM_LOW);
  return neg ? -v : v;
}

#ifdef MPMC_HAVE_MPI
#include "mpmc_mpi.h"

static void order_forget(void); /* the gathered points' order (below) */

static int distributed(void) {
  static int known = 0, yes = 0;
  if (!known) {
    int init = 0, fin = 0, size = 1;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin) MPI_Comm_size(MPI_COMM_WORLD, &size);
    yes = size > 1;
    known = 1;
  }
  return yes;
}

int wf_par_size(void) {
  int size = 1;
  if (distributed()) MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

int wf_par_rank(void) {
  int rank = 0;
  if (distributed()) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

int wf_par_agree(int err) {
  if (!distributed()) return err;
  /* the code of the lowest rank that failed: rank 0's when it is the one (its files) */
  int rank, mine[2], first[2];
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  mine[0] = err ? rank : 1 << 30;
  mine[1] = err;
  MPI_Allreduce(mine, first, 1, MPI_2INT, MPI_MINLOC, MPI_COMM_WORLD);
  return first[0] == 1 << 30 ? 0 : first[1];
}

void wf_par_share(char *buf, int len) {
  if (distributed()) MPI_Bcast(buf, len, MPI_CHAR, 0, MPI_COMM_WORLD);
}

double wf_par_max(double v) {
  double m = v;
  if (distributed()) MPI_Allreduce(&v, &m, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return m;
}

int wf_par_least(double d, int id) {
  if (!distributed()) return id;
  struct {
    double d;
    int id;
  } mine = {d, id}, least;
  MPI_Allreduce(&mine, &least, 1, MPI_DOUBLE_INT, MPI_MINLOC, MPI_COMM_WORLD);
  return least.id;
}

void wf_par_one(double *v, int n, int mine) {
  if (!distributed()) return;
  for (int k = 0; k < n; ++k) /* -0 + v = v, whatever the order of the additions */
    if (!mine) v[k] = -0.0;
  MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
}

/* The digits normalised (each below 2^32 but the top one) and added as integers: exact
 * for any number of ranks below 2^31; the specials as doubles. */
void wf_par_xsum(wf_xsum *s, int n) {
  if (!distributed()) return;
  int64_t d[WF_XSUM_MAX * WF_XSUM_DIGITS];
  double sp[WF_XSUM_MAX];
  for (int k = 0; k < n; ++k) {
    xsum_normalize(&s[k]);
    memcpy(d + (size_t)k * WF_XSUM_DIGITS, s[k].d, sizeof s[k].d);
    sp[k] = s[k].special;
  }
  MPI_Allreduce(MPI_IN_PLACE, d, n * WF_XSUM_DIGITS, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, sp, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  for (int k = 0; k < n; ++k) {
    memcpy(s[k].d, d + (size_t)k * WF_XSUM_DIGITS, sizeof s[k].d);
    s[k].special = sp[k];
  }
}

long wf_par_total(long v) {
  long all = v;
  if (distributed()) MPI_Allreduce(&v, &all, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

int wf_par_sim_create(mpmc_context ctx, int dim, mpmc_sim *sim) {
  order_forget();
  return distributed() ? mpmc_sim_create_mpi(ctx, MPI_COMM_WORLD, dim, sim) : mpmc_sim_create(ctx, dim, sim);
}

int wf_par_checkpoint_read(mpmc_context ctx, const char *path, mpmc_sim *sim, char **meta) {
  order_forget();
  return distributed() ? mpmc_sim_checkpoint_read_mpi(ctx, MPI_COMM_WORLD, path, sim, meta)
                       : mpmc_sim_checkpoint_read(ctx, path, sim, meta);
}

void wf_par_plan(mpmc_sim sim, char *line, size_t len) {
  int rank, nranks, axis, lo, hi;
  line[0] = '\0';
  if (!distributed() || mpmc_sim_get_mpi_slab(sim, &rank, &nranks, &axis, &lo, &hi)) return;
  int threads = 1;
#ifdef _OPENMP
  threads = omp_get_max_threads();
#endif
  snprintf(line, len, "MPI: %d ranks x %d threads, slabs of grid cells along %c (rank 0: cells %d to %d)", nranks,
           threads, "xyz"[axis], lo, hi - 1);
}

int wf_par_threads(void) {
  if (!distributed()) return 0;
  MPI_Comm node;
  int local = 1;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
    MPI_Comm_size(node, &local);
    MPI_Comm_free(&node);
  }
#ifdef _OPENMP
  const char *env = getenv("OMP_NUM_THREADS");
  if (env && env[0]) return 0; /* the user's choice */
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const int mine = omp_get_max_threads(); /* the cores this rank may run on (its binding) */
  long t = cores > 0 ? cores / local : 1;
  if (t > mine) t = mine;
  return t < 1 ? 1 : (int)t;
#else
  return 0;
#endif
}

int wf_par_balance(mpmc_sim sim, int every, double threshold) {
  return distributed() && (every > 0 || threshold > 0) ? mpmc_sim_set_mpi_balance(sim, every, threshold) : 0;
}

void wf_par_imbalance(mpmc_sim sim, double *imbalance, long *balances) {
  *imbalance = 1.0;
  *balances = 0;
  if (distributed()) mpmc_sim_get_mpi_imbalance(sim, imbalance, balances);
}

/* ---- the gathered view ----------------------------------------------------------------- */
typedef struct {
  void *buf;
  size_t cap;
} slot;
static slot slots[MPMC_FIELD_COUNT + 2]; /* the fields, then ids and material ids */

static void *grow(slot *s, size_t bytes) {
  if (bytes > s->cap) {
    void *p = realloc(s->buf, bytes);
    if (!p) return NULL;
    s->buf = p;
    s->cap = bytes;
  }
  return s->buf;
}

/* The order of the gathered points, kept while they stay where they are: every rank's
 * count and offset, and src[j], the gathered row of the point with the j-th smallest global
 * id (those two on rank 0, which alone receives the points).  Valid for one simulation
 * between its steps (a step may migrate, sort or balance points) while no rank's points
 * change in number or order; a new simulation forgets it. */
static struct {
  mpmc_sim sim;
  int64_t steps;
  int n;          /* this rank's points when made          */
  uint64_t hash;  /* of their ids in their order           */
  int size;       /* ranks                                 */
  int *counts;    /* [2 size]: counts, then displacements  */
  long all;       /* points over the ranks                 */
  long *src;      /* [all]                                 */
} order;

static void order_forget(void) { order.sim = NULL; }

/* (Re)make the order if any rank finds it stale (collective).  *width_io: every rank's
 * largest width (a rank without points may not hold the array). */
static int order_update(mpmc_sim sim, int *width_io) {
  int n = 0;
  const int *ids = NULL;
  mpmc_stats st;
  mpmc_sim_get_num_particles(sim, &n);
  int bad = mpmc_sim_get_stats(sim, &st) || (n > 0 && mpmc_sim_get_particle_ids(sim, &ids));
  uint64_t hash = 0; /* a sort or any reordering outside a step changes it */
  for (int q = 0; q < n && ids; ++q) hash = hash * 1000003u + (uint64_t)(unsigned)ids[q];
  const int stale = order.sim != sim || order.steps != st.steps || order.n != n || order.hash != hash;
  int mine[3] = {*width_io, stale, bad}, any[3];
  MPI_Allreduce(mine, any, 3, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  *width_io = any[0];
  if (any[2]) return MPMC_ERR_STATE;
  if (!any[1]) return MPMC_SUCCESS;
  order_forget();
  const int root = wf_par_rank() == 0;
  MPI_Comm_size(MPI_COMM_WORLD, &order.size);
  int *counts = realloc(order.counts, sizeof(int) * (size_t)order.size * 2);
  bad = !counts;
  if (counts) order.counts = counts;
  if (wf_par_agree(bad ? MPMC_ERR_MEMORY : 0)) return MPMC_ERR_MEMORY;
  int *displs = counts + order.size;
  MPI_Gather(&n, 1, MPI_INT, counts, 1, MPI_INT, 0, MPI_COMM_WORLD);
  long all = 0;
  int *gid = NULL;
  if (root) {
    for (int r = 0; r < order.size; ++r) {
      displs[r] = (int)all;
      all += counts[r];
    }
    gid = malloc(sizeof(int) * (size_t)(all + 1));
    long *src = realloc(order.src, sizeof(long) * (size_t)(all + 1));
    if (src) order.src = src;
    bad = !gid || !src;
  }
  if (wf_par_agree(bad ? MPMC_ERR_MEMORY : 0)) {
    free(gid);
    return MPMC_ERR_MEMORY;
  }
  MPI_Gatherv(ids, n, MPI_INT, gid, counts, displs, MPI_INT, 0, MPI_COMM_WORLD);
  long *at = NULL;
  if (root) { /* ids are unique; order them by a table over [0, largest id] */
    int top = -1;
    for (long k = 0; k < all; ++k) top = gid[k] > top ? gid[k] : top;
    at = malloc(sizeof(long) * (size_t)(top + 2));
    bad = !at;
    if (at) {
      for (long k = 0; k <= top; ++k) at[k] = -1;
      for (long k = 0; k < all; ++k) at[gid[k]] = k;
      long j = 0;
      for (long k = 0; k <= top; ++k)
        if (at[k] >= 0) order.src[j++] = at[k];
    }
  }
  free(gid);
  free(at);
  if (wf_par_agree(bad ? MPMC_ERR_MEMORY : 0)) return MPMC_ERR_MEMORY;
  order.sim = sim;
  order.steps = st.steps;
  order.n = n;
  order.hash = hash;
  order.all = all;
  return MPMC_SUCCESS;
}

/* Every rank's n local items of `width` values (MPI type t, `size` bytes each) gathered on
 * rank 0 in the order of the points' global ids, into slot s (collective; the other ranks
 * send theirs and keep nothing). */
static int gather(mpmc_sim sim, const void *local, int *width_io, MPI_Datatype t, size_t size, slot *s) {
  int err = order_update(sim, width_io);
  if (err) return err;
  const int width = *width_io, nr = order.size, root = wf_par_rank() == 0;
  const long all = order.all;
  int *counts = NULL;
  char *vals = NULL, *out = NULL;
  if (root) {
    counts = malloc(sizeof(int) * (size_t)nr * 2);
    vals = malloc(size * (size_t)width * (size_t)(all + 1));
    out = grow(s, size * (size_t)width * (size_t)(all + 1));
  }
  if ((err = wf_par_agree(root && (!counts || !vals || !out) ? MPMC_ERR_MEMORY : 0))) {
    free(counts);
    free(vals);
    return err;
  }
  if (root)
    for (int r = 0; r < 2 * nr; ++r) counts[r] = order.counts[r] * width;
  MPI_Gatherv(local, order.n * width, t, vals, counts, root ? counts + nr : NULL, t, 0, MPI_COMM_WORLD);
  const size_t row = size * (size_t)width;
  for (long j = 0; root && j < all; ++j) memcpy(out + row * (size_t)j, vals + row * (size_t)order.src[j], row);
  free(counts);
  free(vals);
  return MPMC_SUCCESS;
}

int wf_all_count(mpmc_sim sim, int *n) {
  int e = mpmc_sim_get_num_particles(sim, n);
  if (!e && distributed()) {
    int local = *n;
    MPI_Allreduce(&local, n, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  }
  return e;
}

int wf_root_field(mpmc_sim sim, int field, double **data, int *ncomp) {
  int w = 0;
  double *local = NULL;
  int e = mpmc_sim_get_field(sim, field, &local, &w);
  if (ncomp) *ncomp = w;
  if (!distributed()) {
    *data = local;
    return e;
  }
  /* a field this simulation does not have is missing on every rank alike */
  if ((e = local_part(sim, e))) return e;
  e = gather(sim, local, &w, MPI_DOUBLE, sizeof(double), &slots[field]);
  if (ncomp) *ncomp = w;
  if (field == MPMC_FIELD_POSITION) mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &local);
  *data = e || wf_par_rank() != 0 ? NULL : slots[field].buf;
  return e;
}

static int view_ints(mpmc_sim sim, const int *local, int e, int which, const int **out) {
  if (!distributed()) {
    *out = local;
    return e;
  }
  if ((e = local_part(sim, e))) return e;
  int one = 1;
  e = gather(sim, local, &one, MPI_INT, sizeof(int), &slots[MPMC_FIELD_COUNT + which]);
  *out = e || wf_par_rank() != 0 ? NULL : slots[MPMC_FIELD_COUNT + which].buf;
  return e;
}

int wf_root_ids(mpmc_sim sim, const int **ids) {
  const int *local = NULL;
  const int e = mpmc_sim_get_particle_ids(sim, &local);
  return view_ints(sim, local, e, 0, ids);
}

void wf_root_release(void) {
  for (size_t k = 0; k < sizeof slots / sizeof *slots; ++k) {
    free(slots[k].buf);
    slots[k].buf = NULL;
    slots[k].cap = 0;
  }
  free(order.counts);
  free(order.src);
  memset(&order, 0, sizeof order);
}

#else /* one process: the library's arrays as they are */

int wf_par_size(void) { return 1; }
int wf_par_threads(void) { return 0; }
int wf_par_balance(mpmc_sim sim, int every, double threshold) { return (void)sim, (void)every, (void)threshold, 0; }
void wf_par_imbalance(mpmc_sim sim, double *imbalance, long *balances) {
  (void)sim;
  *imbalance = 1.0;
  *balances = 0;
}
void wf_par_plan(mpmc_sim sim, char *line, size_t len) {
  (void)sim;
  if (len) line[0] = '\0';
}
int wf_par_rank(void) { return 0; }
int wf_par_agree(int err) { return err; }
void wf_par_share(char *buf, int len) { (void)buf, (void)len; }
long wf_par_total(long v) { return v; }
double wf_par_max(double v) { return v; }
void wf_par_one(double *v, int n, int mine) { (void)v, (void)n, (void)mine; }
int wf_par_least(double d, int id) { return (void)d, id; }
void wf_par_xsum(wf_xsum *s, int n) { (void)s, (void)n; }
int wf_par_sim_create(mpmc_context ctx, int dim, mpmc_sim *sim) { return mpmc_sim_create(ctx, dim, sim); }
int wf_par_checkpoint_read(mpmc_context ctx, const char *path, mpmc_sim *sim, char **meta) {
  return mpmc_sim_checkpoint_read(ctx, path, sim, meta);
}
int wf_all_count(mpmc_sim sim, int *n) { return mpmc_sim_get_num_particles(sim, n); }
int wf_root_field(mpmc_sim sim, int field, double **data, int *ncomp) {
  return mpmc_sim_get_field(sim, field, data, ncomp);
}
int wf_root_ids(mpmc_sim sim, const int **ids) { return mpmc_sim_get_particle_ids(sim, ids); }
void wf_root_release(void) {}

#endif

/* ---- each rank's own points (one process: all of them) ---------------------------------- */

int wf_own(mpmc_sim sim, int *n, int nf, const int *fields, double **data, const int **ids, const int **mat) {
  int e = mpmc_sim_get_num_particles(sim, n);
  for (int k = 0; k < nf; ++k) {
    data[k] = NULL;
    if (!e && fields[k] >= 0) e = mpmc_sim_get_field(sim, (mpmc_field)fields[k], &data[k], NULL);
  }
  if (ids && !e) e = mpmc_sim_get_particle_ids(sim, ids);
  if (mat && !e) e = mpmc_sim_get_material_ids(sim, mat);
  return local_part(sim, e);
}
