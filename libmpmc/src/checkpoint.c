/* Checkpoint and restart: one HDF5 file holding everything needed to continue a run
 * bit for bit (configuration with the kernel set and the run monitor's state, grid,
 * materials, every allocated particle array, walls, particle sets, run statistics and the
 * caller's text).  Written atomically: the file is
 * built as path.tmp, flushed and fsync'ed, then renamed over path, so a process killed
 * during the write leaves the previous checkpoint intact.
 *
 * The file is a list of blocks; each block is a writer and a reader below and one line in
 * `blocks`.  Not saved: user-material functions (the caller re-attaches them with
 * mpmc_sim_set_material_user_fn) and scratch arrays (dF, xn, xoff, xnode, grid arrays) that
 * every step recomputes.  Rigid bodies (contact.h) are saved with their motion, last reaction and
 * friction anchors.  A checksum over everything else (root attribute checksum_fnv1a64) is
 * verified once every block has read.
 *
 * Over MPI (io_mpi.h) the ranks write the one file collectively: the global blocks alike on
 * every rank, the points as one hyperslab a rank, rank after rank, each in its storage order
 * (a restart on as many ranks gives each its points in the same order: the same bits); the
 * sets' members as those points' rows.  Rank 0 then adds the checksum and renames the file.
 * A restart on any number of ranks reads the file on every rank and keeps the points of the
 * rank's slab, with their ids and every field. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "contact.h"
#include "io_mpi.h"
#include "kernels.h"
#ifdef MPMC_HAVE_MPI
#include "mpmc_mpi.h"
#endif
#include "sets.h"

#define CKPT_FORMAT "libmpmc-checkpoint"
#define CKPT_VERSION 2
#define CKPT_CHECKSUM "checksum_fnv1a64"

/* ---- small HDF5 helpers --------------------------------------------------------------- */

/* Read dataset `name` of shape [rows] (cols == 0) or [rows][cols] into buf; < 0 if absent
 * or of another shape. */
static herr_t read_dataset(hid_t loc, const char *name, hid_t memtype, size_t rows, size_t cols,
                           void *buf) {
  if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) return -1;
  hid_t ds = H5Dopen2(loc, name, H5P_DEFAULT);
  if (ds < 0) return -1;
  hid_t sp = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  const int rank = sp < 0 ? -1 : H5Sget_simple_extent_ndims(sp);
  herr_t st = -1;
  if (rank == (cols ? 2 : 1)) {
    H5Sget_simple_extent_dims(sp, dims, NULL);
    if (dims[0] == rows && (!cols || dims[1] == cols))
      st = rows ? H5Dread(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) : 0;
  }
  if (sp >= 0) H5Sclose(sp);
  H5Dclose(ds);
  return st;
}

static int exists(hid_t loc, const char *name) { return H5Lexists(loc, name, H5P_DEFAULT) > 0; }

/* Dataset rows of `name` in g ([rows][cols]); -1 if absent or of another width. */
static long dataset_rows(hid_t g, const char *name, hsize_t cols) {
  hid_t ds = exists(g, name) ? H5Dopen2(g, name, H5P_DEFAULT) : -1;
  if (ds < 0) return -1;
  hid_t sp = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  const int rank = sp >= 0 ? H5Sget_simple_extent_dims(sp, dims, NULL) : -1;
  if (sp >= 0) H5Sclose(sp);
  H5Dclose(ds);
  return rank == 2 && dims[1] == cols && dims[0] < 1000000 ? (long)dims[0] : -1;
}

/* The points a reading rank keeps: over MPI (more than one rank) the file rows of its slab's
 * points, ascending; rows NULL: every row (one process). */
typedef struct {
  int *rows;
  int n;           /* rows kept                                  */
  long long total; /* the file's points                          */
} ckpt_rows;

enum { CKPT_CHUNK = 65536 }; /* rows read at a time when keeping some */

/* Rows [r0, r0 + n) of dataset ds ([*][cols], cols 0: 1-D) into buf. */
static herr_t read_slab(hid_t ds, hid_t memtype, hsize_t r0, hsize_t n, size_t cols, void *buf) {
  const hsize_t start[2] = {r0, 0}, count[2] = {n, (hsize_t)cols};
  hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(cols ? 2 : 1, count, NULL);
  herr_t st = fs < 0 || ms < 0 ? -1 : H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL);
  if (st >= 0) st = H5Dread(ds, memtype, ms, fs, H5P_DEFAULT, buf);
  if (ms >= 0) H5Sclose(ms);
  if (fs >= 0) H5Sclose(fs);
  return st;
}

/* The rows k keeps of dataset `name` [k->total][cols] into out, one after another. */
static herr_t read_kept(hid_t loc, const char *name, hid_t memtype, size_t cols, const ckpt_rows *k,
                        void *out) {
  if (!k->rows) return read_dataset(loc, name, memtype, (size_t)k->total, cols, out);
  if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) return -1;
  hid_t ds = H5Dopen2(loc, name, H5P_DEFAULT);
  if (ds < 0) return -1;
  hid_t sp = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  const int rank = sp < 0 ? -1 : H5Sget_simple_extent_dims(sp, dims, NULL);
  if (sp >= 0) H5Sclose(sp);
  const size_t w = (cols ? cols : 1) * H5Tget_size(memtype);
  char *tmp = rank == (cols ? 2 : 1) && dims[0] == (hsize_t)k->total && (!cols || dims[1] == cols)
                  ? malloc(w * CKPT_CHUNK)
                  : NULL;
  herr_t st = tmp ? 0 : -1;
  for (int i = 0; i < k->n && st >= 0;) {
    const long long r0 = k->rows[i], r1 = r0 + CKPT_CHUNK < k->total ? r0 + CKPT_CHUNK : k->total;
    st = read_slab(ds, memtype, (hsize_t)r0, (hsize_t)(r1 - r0), cols, tmp);
    for (; st >= 0 && i < k->n && k->rows[i] < r1; ++i)
      memcpy((char *)out + (size_t)i * w, tmp + (size_t)(k->rows[i] - r0) * w, w);
  }
  free(tmp);
  H5Dclose(ds);
  return st;
}

/* Over MPI: the rows of /particles/x [k->total][dim] that lie in this rank's slab. */
static int select_rows(hid_t g, mpmc_sim sim, ckpt_rows *k) {
  const int d = sim->cfg.dim;
  hid_t ds = exists(g, "x") ? H5Dopen2(g, "x", H5P_DEFAULT) : -1;
  double *x = malloc(sizeof(double) * CKPT_CHUNK * (size_t)d);
  int cap = 0, err = ds >= 0 && x ? MPMC_SUCCESS
                                  : MPMC_ERROR(sim->ctx, MPMC_ERR_FORMAT, "checkpoint /particles/x: unreadable");
  for (long long r0 = 0; r0 < k->total && !err; r0 += CKPT_CHUNK) {
    const long long n = k->total - r0 < CKPT_CHUNK ? k->total - r0 : CKPT_CHUNK;
    if (read_slab(ds, H5T_NATIVE_DOUBLE, (hsize_t)r0, (hsize_t)n, (size_t)d, x) < 0) {
      err = MPMC_ERROR(sim->ctx, MPMC_ERR_FORMAT, "checkpoint /particles/x: not [%lld][%d]", k->total, d);
      break;
    }
    for (long long i = 0; i < n && !err; ++i) {
      if (!mpmc_dd_keep(sim, x + i * d)) continue; /* another rank's */
      if (k->n == cap) {
        cap = cap ? 2 * cap : 1024;
        int *r = realloc(k->rows, sizeof(int) * (size_t)cap);
        if (!r) err = MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "checkpoint: no memory for %d rows", cap);
        else k->rows = r;
      }
      if (!err) k->rows[k->n++] = (int)(r0 + i);
    }
  }
  free(x);
  if (ds >= 0) H5Dclose(ds);
  /* a rank that keeps none still reads over MPI (rows NULL would read every row) */
  if (!err && !k->rows && !(k->rows = malloc(sizeof(int))))
    err = MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "checkpoint: out of memory");
  return err;
}

/* ---- block: configuration, grid, time, statistics ----------------------------------------- */

/* The whole grid's nodes whose planes along axis a are [lo, hi) (global planes), the other
 * axes whole, as rows of [global nodes]: {start, stride, count, block} (io.h) */
static void plane_pattern(const mpmc_grid *g, int a, long lo, long hi, size_t pat[4]) {
  size_t inner = 1, outer = 1;
  for (int b = 0; b < a; ++b) inner *= (size_t)g->ng[b];
  for (int b = a + 1; b < 3; ++b) outer *= (size_t)g->ng[b];
  pat[0] = inner * (size_t)lo;
  pat[1] = inner * (size_t)g->ng[a];
  pat[2] = outer;
  pat[3] = inner * (size_t)(hi - lo);
}

/* Adaptive damping's node store as one dataset over the whole grid: in one process the
 * rank's own; over MPI each rank writes the nodes of the planes it counts (damping.c: a node
 * with mass last step holds the same values on every rank that has it; the ranks' planes
 * cover the grid once), a hyperslab of its held nodes in their order (the other axes are
 * whole): no rank holds the whole grid's store.  A restart on any number of ranks then
 * finds every node's last force. */
static herr_t write_adaptive_nodes(hid_t g, mpmc_const_sim sim) {
  const mpmc_grid *gr = &sim->grid;
  const size_t cols = (size_t)(1 + sim->cfg.dim), all = mpmc_grid_global_nodes(gr);
  int own[3];
  mpmc_adaptive_damping_own(sim, own);
  if (own[0] < 0)
    return mpmc_h5_dataset_write(g, "adaptive_damping_nodes", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, all, cols,
                                 sim->adr_f);
  const int a = own[0];
  size_t pat[4];
  plane_pattern(gr, a, own[1] + gr->off[a], own[2] + gr->off[a], pat);
  double *buf = malloc(sizeof *buf * cols * (pat[2] * pat[3] > 0 ? pat[2] * pat[3] : 1));
  hid_t dxpl = mpmc_io_dxpl(sim);
  if (mpmc_dd_agree(sim, buf && dxpl >= 0 ? MPMC_SUCCESS : MPMC_ERR_MEMORY)) {
    free(buf);
    mpmc_io_plist_close(dxpl);
    return -1;
  }
  size_t k = 0;
  for (size_t i = 0; i < gr->nn; ++i) {
    const long pl = mpmc_grid_plane(gr, a, i);
    if (pl >= own[1] && pl < own[2]) memcpy(buf + cols * k++, sim->adr_f + cols * i, sizeof *buf * cols);
  }
  const herr_t st = mpmc_h5_pattern_write(g, "adaptive_damping_nodes", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, all,
                                          cols, pat, buf, dxpl);
  mpmc_io_plist_close(dxpl);
  free(buf);
  return st;
}

/* The run monitor's state (mpmc_monitor) as doubles, and back (the steps exact below 2^53) */
enum { MONITOR_DOUBLES = 16 };
static void monitor_pack(const mpmc_monitor *m, double *d) {
  d[0] = m->factor, d[1] = (double)m->base_step, d[2] = m->e0[0], d[3] = m->e0[1];
  d[4] = m->gx0, d[5] = m->fx0;
  memcpy(d + 6, m->sig, sizeof m->sig);
  d[14] = m->ke_last, d[15] = (double)m->next_check;
}
static void monitor_unpack(const double *d, mpmc_monitor *m) {
  m->factor = d[0], m->base_step = (int64_t)d[1], m->e0[0] = d[2], m->e0[1] = d[3];
  m->gx0 = d[4], m->fx0 = d[5];
  memcpy(m->sig, d + 6, sizeof m->sig);
  m->ke_last = d[14], m->next_check = (int64_t)d[15];
}
_Static_assert(sizeof(((mpmc_monitor *)0)->sig) == 8 * sizeof(double), "monitor_pack's layout");

static int write_config(hid_t f, mpmc_const_sim sim) {
  hid_t g = H5Gcreate2(f, "config", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) return -1;
  const mpmc_grid *gr = &sim->grid;
  const int ints[] = {sim->cfg.dim, sim->cfg.basis, sim->cfg.fbar, sim->cfg.solver, sim->cfg.nthreads, sim->cfg.force_dt};
  /* over MPI every rank writes the same attributes: the counts summed over the ranks (exact
   * in doubles below 2^53), the times the slowest rank's */
  double counts[3] = {(double)sim->stats.particle_steps, (double)sim->stats.return_maps,
                      (double)sim->stats.kinsol_fallbacks};
  double secs[1 + MPMC_PHASE_COUNT];
  secs[0] = sim->stats.wall_seconds;
  memcpy(secs + 1, sim->stats.phase_seconds, sizeof sim->stats.phase_seconds);
  mpmc_dd_sum(sim, counts, 3);
  mpmc_dd_max(sim, secs, 1 + MPMC_PHASE_COUNT);
  const int64_t stats[] = {sim->stats.steps, (int64_t)counts[0], (int64_t)counts[1],
                           (int64_t)counts[2]};
  herr_t st = 0;
  st |= mpmc_h5_attr_write(g, "dim_basis_fbar_solver_nthreads_forcedt", H5T_NATIVE_INT, 6, ints);
  st |= mpmc_h5_attr_write(g, "flip", H5T_NATIVE_DOUBLE, 1, &sim->cfg.flip);
  st |= mpmc_h5_attr_write(g, "pic_diffusivity", H5T_NATIVE_DOUBLE, 1, &sim->cfg.pic_diff);
  st |= mpmc_h5_attr_write(g, "gravity", H5T_NATIVE_DOUBLE, 3, sim->cfg.gravity);
  st |= mpmc_h5_attr_write(g, "damping", H5T_NATIVE_DOUBLE, 1, &sim->cfg.damping);
  const double kd[2] = {sim->cfg.kdamp, sim->kd_ke}; /* kinetic damping: on, E_k of the last step */
  st |= mpmc_h5_attr_write(g, "kinetic_damping", H5T_NATIVE_DOUBLE, 2, kd);
  /* adaptive damping: zeta (0: off), c, the running sums; with the last step's nodal forces
   * the next step goes on as without the restart */
  const double ad[4] = {sim->cfg.adr ? sim->cfg.adr_zeta : 0.0, sim->adr_c, sim->adr_sum[0],
                        sim->adr_sum[1]};
  st |= mpmc_h5_attr_write(g, "adaptive_damping", H5T_NATIVE_DOUBLE, 4, ad);
  if (sim->cfg.adr && sim->adr_nf) st |= write_adaptive_nodes(g, sim);
  st |= mpmc_h5_attr_write(g, "time", H5T_NATIVE_DOUBLE, 1, &sim->time);
  st |= mpmc_h5_attr_write(g, "grid_lo", H5T_NATIVE_DOUBLE, 3, gr->lo);
  st |= mpmc_h5_attr_write(g, "grid_hi", H5T_NATIVE_DOUBLE, 3, gr->hi);
  st |= mpmc_h5_attr_write(g, "grid_h", H5T_NATIVE_DOUBLE, 1, &gr->h);
  st |= mpmc_h5_attr_write(g, "stats_steps_particlesteps_returnmaps_kinsol", H5T_NATIVE_INT64, 4,
                           stats);
  st |= mpmc_h5_attr_write(g, "stats_wall_seconds", H5T_NATIVE_DOUBLE, 1, secs);
  st |= mpmc_h5_attr_write(g, "stats_phase_seconds", H5T_NATIVE_DOUBLE, MPMC_PHASE_COUNT,
                           secs + 1);
  int64_t sort[2] = {sim->cfg.sort_every, sim->sort_last}; /* interval, step of the last */
  /* the axis the last sort ordered by and the last slab build's: whether the next step sorts
   * because the slab axis changed (sort.c, mpmc_sort_due) */
  int axes[2] = {sim->sort_axis, sim->scr.slab_axis};
  int rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  if (size > 1) { /* each rank sorts its own points: every rank's, rank 0's as the attributes */
    const int64_t mine[3] = {sim->sort_last, sim->sort_axis, sim->scr.slab_axis};
    hid_t dxpl = mpmc_io_dxpl(sim);
    st |= mpmc_h5_rows_write(g, "rank_sort_last_sort_axis_slab_axis", H5T_STD_I64LE,
                             H5T_NATIVE_INT64, size, 3, rank, 1, mine, dxpl);
    mpmc_io_plist_close(dxpl);
    mpmc_io_bcast(sim, sort, sizeof sort);
    mpmc_io_bcast(sim, axes, sizeof axes);
  }
  st |= mpmc_h5_attr_write(g, "sort_interval_last", H5T_NATIVE_INT64, 2, sort);
  st |= mpmc_h5_attr_write(g, "sort_axis_slab_axis", H5T_NATIVE_INT, 2, axes);
  /* the kernel set the steps ran (the same on every rank), and the run monitor's setting and
   * state (global sums, the same on every rank), so that a restart checks as the run would */
  st |= mpmc_h5_attr_write(g, "kernels", H5T_NATIVE_INT, 1, &sim->cfg.kernels);
  double mon[MONITOR_DOUBLES];
  monitor_pack(&sim->monitor, mon);
  st |= mpmc_h5_attr_write(g, "monitor", H5T_NATIVE_DOUBLE, MONITOR_DOUBLES, mon);
  const mpmc_water_table *wt = &sim->wt; /* kind, gamma_w, plane; the polyline's vertices */
  if (wt->kind != MPMC_WATER_NONE) {
    const double w[5] = {wt->kind, wt->gamma_w, wt->plane[0], wt->plane[1], wt->plane[2]};
    st |= mpmc_h5_attr_write(g, "water_table", H5T_NATIVE_DOUBLE, 5, w);
    if (wt->n > 0)
      st |= mpmc_h5_attr_write(g, "water_table_xh", H5T_NATIVE_DOUBLE, 2 * wt->n, wt->xh);
  }
  H5Gclose(g);
  return st < 0 ? -1 : 0;
}

/* The water table (config attributes water_table and water_table_xh; absent: none).  The
 * masses were the table's when written: they stay as they are. */
static int read_water_table(hid_t f, mpmc_sim sim) {
  hid_t g = H5Gopen2(f, "config", H5P_DEFAULT);
  if (g < 0 || H5Aexists(g, "water_table") <= 0) {
    if (g >= 0) H5Gclose(g);
    return MPMC_SUCCESS;
  }
  double w[5], *xh = NULL;
  int n = 0;
  herr_t st = mpmc_h5_attr_read(g, "water_table", H5T_NATIVE_DOUBLE, 5, w);
  hid_t a = H5Aexists(g, "water_table_xh") > 0 ? H5Aopen(g, "water_table_xh", H5P_DEFAULT) : -1;
  if (a >= 0) {
    hid_t sp = H5Aget_space(a);
    const hssize_t np = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
    if (sp >= 0) H5Sclose(sp);
    H5Aclose(a);
    n = np > 0 && np % 2 == 0 && np < INT32_MAX ? (int)(np / 2) : 0;
    xh = n ? malloc(sizeof *xh * 2 * (size_t)n) : NULL;
    st |= xh ? mpmc_h5_attr_read(g, "water_table_xh", H5T_NATIVE_DOUBLE, 2 * n, xh) : -1;
  }
  H5Gclose(g);
  const int err = st < 0 ? MPMC_ERROR(sim->ctx, MPMC_ERR_FORMAT,
                                      "checkpoint /config: malformed water_table attributes")
                         : mpmc_water_set(sim, (int)w[0], n, xh, w + 2, w[1], 0);
  free(xh);
  return err;
}

/* Adaptive damping's node store (config dataset adaptive_damping_nodes [nn][1 + dim], the
 * whole grid's nn, of which a rank reads its held nodes alone: a hyperslab of the planes it
 * holds along the one axis it does not hold whole; absent: the next step measures no
 * quotient). */
static int read_adaptive_nodes(hid_t f, mpmc_sim sim) {
  hid_t g = H5Gopen2(f, "config", H5P_DEFAULT);
  if (g < 0) return MPMC_ERROR(sim->ctx, MPMC_ERR_FORMAT, "checkpoint has no /config group");
  int err = MPMC_SUCCESS;
  if (exists(g, "adaptive_damping_nodes")) {
    const mpmc_grid *gr = &sim->grid;
    const size_t cols = (size_t)(1 + sim->cfg.dim), all = mpmc_grid_global_nodes(gr), n = gr->nn * cols;
    int a = 0; /* the axis held in part (any, when the rank holds the whole grid) */
    for (int b = 0; b < 3; ++b)
      if (gr->n[b] != gr->ng[b]) a = b;
    size_t pat[4];
    plane_pattern(gr, a, gr->off[a], gr->off[a] + gr->n[a], pat);
    double *buf = malloc(n * sizeof *buf);
    if (!buf)
      err = MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "cannot allocate adaptive damping's node store");
    else if (mpmc_h5_pattern_read(g, "adaptive_damping_nodes", H5T_NATIVE_DOUBLE, all, cols, pat, buf) < 0)
      err = MPMC_ERROR(sim->ctx, MPMC_ERR_FORMAT,
                       "checkpoint /config: adaptive_damping_nodes is not [%zu][%zu] (the grid's "
                       "nodes)",
                       all, cols);
    if (err) {
      free(buf);
    } else {
      free(sim->adr_f);
      sim->adr_f = buf;
      sim->adr_nf = n;
    }
  }
  H5Gclose(g);
  return err;
}

/* A checkpoint written over MPI holds each rank's sort state: a restart on as many ranks
 * takes its own row (on another number, rank 0's, in the attributes). */
static int read_rank_sort(hid_t f, mpmc_sim sim) {
  int rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  hid_t g = H5Gopen2(f, "config", H5P_DEFAULT);
  const char *name = "rank_sort_last_sort_axis_slab_axis";
  const long rows = g >= 0 ? dataset_rows(g, name, 3) : -1;
  int64_t mine[3];
  herr_t st = 0;
  if (rows == size && size > 1) {
    hid_t ds = H5Dopen2(g, name, H5P_DEFAULT);
    st = ds < 0 ? -1 : read_slab(ds, H5T_NATIVE_INT64, (hsize_t)rank, 1, 3, mine);
    if (ds >= 0) H5Dclose(ds);
  }
  if (g >= 0) H5Gclose(g);
  MPMC_CHECK(st >= 0, sim->ctx, MPMC_ERR_FORMAT, "checkpoint /config/%s: unreadable", name);
  if (rows != size || size == 1) return MPMC_SUCCESS;
  MPMC_CHECK(mine[0] >= -1 && mine[0] <= sim->stats.steps && mine[1] >= -1 && mine[1] < sim->cfg.dim &&
                 mine[2] >= 0 && mine[2] < sim->cfg.dim,
             sim->ctx, MPMC_ERR_FORMAT, "checkpoint /config/%s: bad row %d", name, rank);
  sim->sort_last = mine[0];
  sim->sort_axis = (int)mine[1];
  sim->scr.slab_axis = (int)mine[2];
  return MPMC_SUCCESS;
}

/* The configuration goes through the public setters, which validate it. */
static int read_config(hid_t f, mpmc_sim sim, ckpt_rows *k) {
  (void)k;
  mpmc_context ctx = sim->ctx;
  hid_t g = exists(f, "config") ? H5Gopen2(f, "config", H5P_DEFAULT) : -1;
  MPMC_CHECK(g >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint has no /config group");
  int ints[6];
  int64_t stats[4];
  double flip, grav[3], damp, time, lo[3], hi[3], h, wall;
  herr_t st = 0;
  st |= mpmc_h5_attr_read(g, "dim_basis_fbar_solver_nthreads_forcedt", H5T_NATIVE_INT, 6, ints);
  st |= mpmc_h5_attr_read(g, "flip", H5T_NATIVE_DOUBLE, 1, &flip);
  st |= mpmc_h5_attr_read(g, "gravity", H5T_NATIVE_DOUBLE, 3, grav);
  st |= mpmc_h5_attr_read(g, "damping", H5T_NATIVE_DOUBLE, 1, &damp);
  st |= mpmc_h5_attr_read(g, "time", H5T_NATIVE_DOUBLE, 1, &time);
  st |= mpmc_h5_attr_read(g, "grid_lo", H5T_NATIVE_DOUBLE, 3, lo);
  st |= mpmc_h5_attr_read(g, "grid_hi", H5T_NATIVE_DOUBLE, 3, hi);
  st |= mpmc_h5_attr_read(g, "grid_h", H5T_NATIVE_DOUBLE, 1, &h);
  st |= mpmc_h5_attr_read(g, "stats_steps_particlesteps_returnmaps_kinsol", H5T_NATIVE_INT64, 4,
                          stats);
  st |= mpmc_h5_attr_read(g, "stats_wall_seconds", H5T_NATIVE_DOUBLE, 1, &wall);
  double phase[MPMC_PHASE_COUNT] = {0}; /* absent in files of before the phase timers */
  if (H5Aexists(g, "stats_phase_seconds") > 0)
    st |= mpmc_h5_attr_read(g, "stats_phase_seconds", H5T_NATIVE_DOUBLE, MPMC_PHASE_COUNT, phase);
  int64_t sort[2] = {0, -1}; /* absent in files of before the sort: never sorted */
  if (H5Aexists(g, "sort_interval_last") > 0)
    st |= mpmc_h5_attr_read(g, "sort_interval_last", H5T_NATIVE_INT64, 2, sort);
  double pic_diff = 0.0; /* absent in files of before the PIC diffusivity: off */
  if (H5Aexists(g, "pic_diffusivity") > 0)
    st |= mpmc_h5_attr_read(g, "pic_diffusivity", H5T_NATIVE_DOUBLE, 1, &pic_diff);
  double kd[2] = {0.0, -1.0}; /* absent in files of before kinetic damping: off */
  if (H5Aexists(g, "kinetic_damping") > 0)
    st |= mpmc_h5_attr_read(g, "kinetic_damping", H5T_NATIVE_DOUBLE, 2, kd);
  double ad[4] = {0.0, 0.0, 0.0, 0.0}; /* absent in files of before adaptive damping: off */
  if (H5Aexists(g, "adaptive_damping") > 0)
    st |= mpmc_h5_attr_read(g, "adaptive_damping", H5T_NATIVE_DOUBLE, 4, ad);
  int axes[2] = {-1, 0}; /* absent in files of before: no sort for an axis change until the next */
  if (H5Aexists(g, "sort_axis_slab_axis") > 0)
    st |= mpmc_h5_attr_read(g, "sort_axis_slab_axis", H5T_NATIVE_INT, 2, axes);
  int kernels = MPMC_KERNELS_AUTO; /* absent in files of before: the process's choice */
  if (H5Aexists(g, "kernels") > 0) st |= mpmc_h5_attr_read(g, "kernels", H5T_NATIVE_INT, 1, &kernels);
  const int has_mon = H5Aexists(g, "monitor") > 0; /* absent: the default, a new baseline */
  double mon[MONITOR_DOUBLES];
  if (has_mon) st |= mpmc_h5_attr_read(g, "monitor", H5T_NATIVE_DOUBLE, MONITOR_DOUBLES, mon);
  H5Gclose(g);
  MPMC_CHECK(st >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint /config: missing or malformed attributes");
  MPMC_CHECK(ints[0] == sim->cfg.dim, ctx, MPMC_ERR_FORMAT,
             "checkpoint /config: dim = %d differs from the file's dim = %d", ints[0], sim->cfg.dim);
  MPMC_CALL(mpmc_sim_set_basis(sim, ints[1]));
  MPMC_CALL(mpmc_sim_set_fbar(sim, ints[2]));
  MPMC_CALL(mpmc_sim_set_solver(sim, ints[3]));
  MPMC_CALL(mpmc_sim_set_threads(sim, ints[4]));
  MPMC_CALL(mpmc_sim_set_force_dt(sim, ints[5]));
  MPMC_CALL(mpmc_sim_set_flip_blend(sim, flip));
  MPMC_CALL(mpmc_sim_set_pic_diffusivity(sim, pic_diff));
  MPMC_CALL(mpmc_sim_set_gravity(sim, grav));
  MPMC_CALL(mpmc_sim_set_damping(sim, damp));
  MPMC_CALL(mpmc_sim_set_kinetic_damping(sim, kd[0] != 0.0));
  sim->kd_ke = kd[1]; /* the peak test of the next step goes on as without the restart */
  MPMC_CALL(mpmc_sim_set_adaptive_damping(sim, ad[0]));
  MPMC_CALL(read_water_table(f, sim));
  MPMC_CALL(mpmc_sim_set_time(sim, time));
  MPMC_CALL(mpmc_sim_set_grid(sim, lo, hi, h));
  sim->adr_c = ad[1]; /* the estimate and, below, the last step's nodal forces: the next */
  sim->adr_sum[0] = ad[2]; /* step goes on as without the restart */
  sim->adr_sum[1] = ad[3];
  if (sim->cfg.adr) MPMC_CALL(read_adaptive_nodes(f, sim));
  for (int a = 0; a < sim->cfg.dim; ++a)
    MPMC_CHECK(sim->grid.hi[a] == hi[a], ctx, MPMC_ERR_FORMAT,
               "checkpoint /config: grid axis %d does not hold whole cells (hi %g, rebuilt %g)", a,
               hi[a], sim->grid.hi[a]);
  sim->stats.steps = stats[0];
  sim->stats.particle_steps = stats[1];
  sim->stats.return_maps = stats[2];
  sim->stats.kinsol_fallbacks = stats[3];
  int rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  if (rank > 0) /* over MPI the file's counts are every rank's: rank 0 carries them on */
    sim->stats.particle_steps = sim->stats.return_maps = sim->stats.kinsol_fallbacks = 0;
  sim->stats.wall_seconds = wall;
  for (int k = 0; k < MPMC_PHASE_COUNT; ++k) sim->stats.phase_seconds[k] = phase[k];
  MPMC_CHECK(sort[0] >= 0 && sort[0] <= INT32_MAX && sort[1] >= -1 && sort[1] <= stats[0], ctx,
             MPMC_ERR_FORMAT, "checkpoint /config: bad sort_interval_last = [%lld, %lld]",
             (long long)sort[0], (long long)sort[1]);
  sim->cfg.sort_every = (int)sort[0];
  sim->sort_last = sort[1];
  MPMC_CHECK(axes[0] >= -1 && axes[0] < sim->cfg.dim && axes[1] >= 0 && axes[1] < sim->cfg.dim, ctx,
             MPMC_ERR_FORMAT, "checkpoint /config: bad sort_axis_slab_axis = [%d, %d]", axes[0], axes[1]);
  sim->sort_axis = axes[0];
  sim->scr.slab_axis = axes[1];
  /* the steps' kernel set (the sets differ by round-off: mpmc_sim_set_kernels) */
  MPMC_CALL(mpmc_kernels_restore(sim, kernels));
  if (has_mon) {
    MPMC_CHECK(isfinite(mon[0]) && (mon[0] > 1.0 || mon[0] <= 0.0) && mon[1] >= 0.0 &&
                   mon[1] <= (double)stats[0] && mon[15] >= 0.0,
               ctx, MPMC_ERR_FORMAT, "checkpoint /config: bad monitor = [%g, %g, ..., %g]",
               mon[0], mon[1], mon[15]);
    monitor_unpack(mon, &sim->monitor);
  }
  return read_rank_sort(f, sim);
}

/* ---- block: materials ------------------------------------------------------------------------ */

/* Per material: its model's name, its stored parameters as given (par0) and the strength
 * reduction factor applied (the current parameters follow from both), and for user
 * materials nothing more (the caller re-attaches the function).  Rows of MPMC_MAX_PARAM. */
#define NPARAM MPMC_MAX_PARAM
#define NAME_LEN 32

static int write_materials(hid_t f, mpmc_const_sim sim) {
  const int nm = sim->nmat;
  const size_t nr = (size_t)(nm > 0 ? nm : 1);
  double *par = calloc(NPARAM * nr, sizeof(double)), *srm = calloc(nr, sizeof(double));
  char *names = calloc(nr, NAME_LEN);
  herr_t st = par && srm && names ? 0 : -1;
  for (int i = 0; i < nm && st == 0; ++i) {
    const mpmc_material *m = &sim->mats[i];
    memcpy(par + (size_t)i * NPARAM, m->par0, sizeof m->par0);
    srm[i] = m->srm;
    snprintf(names + (size_t)i * NAME_LEN, NAME_LEN, "%s", m->model->name);
  }
  hid_t g = st == 0 ? H5Gcreate2(f, "materials", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
  if (g < 0) st = -1;
  if (st == 0) {
    st |= mpmc_h5_attr_write(g, "count", H5T_NATIVE_INT, 1, &nm);
    st |= mpmc_h5_dataset_write(g, "params", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)nm,
                                NPARAM, par);
    st |= mpmc_h5_dataset_write(g, "strength_reduction", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                                (size_t)nm, 0, srm);
    st |= mpmc_h5_dataset_write(g, "model", H5T_STD_I8LE, H5T_NATIVE_CHAR, (size_t)nm, NAME_LEN,
                                names);
  }
  if (g >= 0) H5Gclose(g);
  free(par);
  free(srm);
  free(names);
  return st < 0 ? -1 : 0;
}

/* A restored user material until the caller re-attaches its function. */
static int unattached_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id, double dt) {
  (void)dt;
  return MPMC_ERROR(sim->ctx, MPMC_ERR_STATE,
                    "%s material %d was restored from a checkpoint without its function: "
                    "call %s first",
                    mat->model->name, id,
                    mat->model == mpmc_model_named("user") ? "mpmc_sim_set_material_user_fn"
                                                            : "mpmc_sim_set_material_yield_fn");
}
static double unattached_wave_speed(const mpmc_material *m) {
  return m->model->ops->wave_speed(m);
}
static const mpmc_material_ops ops_unattached = {"user (unattached)", unattached_update,
                                                 unattached_wave_speed, 0, 0};

static int read_materials(hid_t f, mpmc_sim sim, ckpt_rows *k) {
  (void)k;
  mpmc_context ctx = sim->ctx;
  hid_t g = exists(f, "materials") ? H5Gopen2(f, "materials", H5P_DEFAULT) : -1;
  MPMC_CHECK(g >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint has no /materials group");
  int nm = -1;
  if (mpmc_h5_attr_read(g, "count", H5T_NATIVE_INT, 1, &nm) < 0 || nm < 0 || nm > 1000000) {
    H5Gclose(g);
    return MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /materials: bad count %d", nm);
  }
  const size_t nr = (size_t)(nm > 0 ? nm : 1);
  double *par = calloc(NPARAM * nr, sizeof(double)), *srm = calloc(nr, sizeof(double));
  char *names = calloc(nr, NAME_LEN);
  sim->mats = calloc(nr, sizeof *sim->mats);
  herr_t st = par && srm && names && sim->mats ? 0 : -1;
  if (st == 0) st |= read_dataset(g, "params", H5T_NATIVE_DOUBLE, (size_t)nm, NPARAM, par);
  if (st == 0) st |= read_dataset(g, "strength_reduction", H5T_NATIVE_DOUBLE, (size_t)nm, 0, srm);
  if (st == 0) st |= read_dataset(g, "model", H5T_NATIVE_CHAR, (size_t)nm, NAME_LEN, names);
  H5Gclose(g);
  int err = st < 0 ? MPMC_ERROR(ctx, MPMC_ERR_FORMAT,
                                "checkpoint /materials: model/params/strength_reduction datasets "
                                "missing or not [%d][%d]",
                                nm, NPARAM)
                   : MPMC_SUCCESS;
  sim->capmat = (int)nr;
  for (int i = 0; i < nm && !err; ++i) {
    mpmc_material *m = &sim->mats[i];
    char *name = names + (size_t)i * NAME_LEN;
    name[NAME_LEN - 1] = 0;
    m->model = mpmc_model_named(name);
    if (!m->model) {
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint material %d: unknown model '%s'", i,
                       name);
      break;
    }
    memcpy(m->par0, par + (size_t)i * NPARAM, sizeof m->par0);
    /* a parameter added to the model after the file was written (rho_sat) reads 0 there,
     * out of its range: its default */
    for (int k = 0; k < m->model->nstore; ++k) {
      const mpmc_param_desc *pd = &m->model->param[k];
      if (m->par0[k] == 0.0 && (pd->flags & MPMC_PARAM_OPTIONAL) &&
          (pd->flags & MPMC_PARAM_LO_OPEN) && pd->lo == 0.0)
        m->par0[k] = NAN;
    }
    m->srm = srm[i];
    m->ops = (m->model->flags & MPMC_MODEL_CALLBACK) ? &ops_unattached : m->model->ops;
    if (!(isfinite(m->srm) && m->srm > 0))
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint material %d: strength reduction %g", i,
                       m->srm);
    if (!err) {
      /* the current parameters: par0 reduced by srm as mpmc_sim_set_strength_reduction does */
      err = mpmc_material_restore(ctx, m);
      if (err) {
        char why[256];
        snprintf(why, sizeof why, "%s", mpmc_context_last_error(ctx));
        err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint material %d (%s): %s", i, name, why);
      }
    }
    if (!err) sim->nmat = i + 1;
  }
  free(par);
  free(srm);
  free(names);
  return err;
}

/**
 * @brief Re-attach the stress function of user material `material` after
 *        mpmc_sim_checkpoint_read (function pointers cannot be saved in a file).
 * @param fn the same stress update the material was created with, not NULL
 * @param data passed back to fn (may be NULL)
 */
int mpmc_sim_set_material_user_fn(mpmc_sim sim, int material, mpmc_user_stress_fn fn, void *data) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(material >= 0 && material < sim->nmat, sim->ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  MPMC_CHECK(sim->mats[material].model == mpmc_model_named("user"), sim->ctx, MPMC_ERR_ARG,
             "material %d is a '%s' material, not a user material", material,
             sim->mats[material].ops->name);
  MPMC_CHECK(fn, sim->ctx, MPMC_ERR_ARG, "user material %d: stress function fn is NULL", material);
  sim->mats[material].user_fn = fn;
  sim->mats[material].user_data = data;
  sim->mats[material].ops = sim->mats[material].model->ops;
  return MPMC_SUCCESS;
}

/* ---- block: particles --------------------------------------------------------------------- */

/* Every double array of the particle store that a checkpoint carries; NULL ones are skipped
 * on writing and left unallocated on reading.  ncomp: 0 = dim, -1 = nustate. */
typedef struct {
  const char *name;
  size_t off;
  int ncomp;
  int required;
  int fill; /* over MPI, for a rank that has not allocated it: 0 zeros, 1 ones, 2 identity */
} pfield;
#define PF(f, nc, req, fill) {#f, offsetof(mpmc_particles, f), nc, req, fill}
static const pfield pfields[] = {PF(x, 0, 1, 0),      PF(x0, 0, 1, 0),    PF(v, 0, 1, 0),
                                 PF(m, 1, 1, 0),      PF(vol0, 1, 1, 0),  PF(J, 1, 1, 1),
                                 PF(stress, 6, 1, 0), PF(Jbar, 1, 0, 1),  PF(be, 6, 0, 2),
                                 PF(eps_p, 1, 0, 0),  PF(lp, 1, 0, 0),    PF(force, 0, 0, 0),
                                 PF(cforce, 0, 0, 0), PF(ustate, -1, 0, 0), PF(Janc, 1, 0, 1),
                                 PF(region, 1, 0, 0), PF(Jp, 1, 0, 1)};
#undef PF
#define NPFIELD (sizeof pfields / sizeof pfields[0])

static double **pfield_ptr(mpmc_particles *p, const pfield *f) {
  return (double **)(void *)((char *)p + f->off);
}
static int pfield_ncomp(const mpmc_particles *p, const pfield *f) {
  return f->ncomp == 0 ? p->dim : f->ncomp < 0 ? p->nustate : f->ncomp;
}

/* Over MPI each rank writes its points as the rows from its offset, in its storage order;
 * a field some rank has is written by all (the others' rows filled as the field starts). */
static int write_particles(hid_t f, mpmc_const_sim sim) {
  mpmc_particles *p = (mpmc_particles *)&sim->p;
  long long off = 0, total = 0;
  mpmc_io_scan(sim, p->n, &off, &total);
  double nus = p->nustate;
  mpmc_dd_max(sim, &nus, 1);
  unsigned has = p->id ? 1u << NPFIELD : 0u; /* bit k: pfields[k] allocated; NPFIELD: ids */
  for (size_t k = 0; k < NPFIELD; ++k)
    if (*pfield_ptr(p, &pfields[k])) has |= 1u << k;
  mpmc_io_or(sim, &has, 1);
  const int n = p->n, ntot = (int)total, nustate = (int)nus;
  hid_t g = H5Gcreate2(f, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  hid_t dxpl = mpmc_io_dxpl(sim);
  double *fill = NULL;
  herr_t st = g < 0 || dxpl < 0 ? -1 : 0;
  if (st >= 0) {
    st |= mpmc_h5_attr_write(g, "n", H5T_NATIVE_INT, 1, &ntot);
    st |= mpmc_h5_attr_write(g, "nustate", H5T_NATIVE_INT, 1, &nustate);
  }
  for (size_t k = 0; k < NPFIELD && st >= 0; ++k) {
    const double *a = *pfield_ptr(p, &pfields[k]);
    const int nc = pfields[k].ncomp < 0 ? nustate : pfield_ncomp(p, &pfields[k]);
    if (!(has >> k & 1u) || nc == 0) continue;
    if (!a) { /* another rank's points have it */
      free(fill);
      fill = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1) * (size_t)nc);
      if (!fill) st = -1;
      for (size_t i = 0; fill && i < (size_t)n * (size_t)nc; ++i)
        fill[i] = pfields[k].fill == 2 ? (i % 6 < 3) : pfields[k].fill;
      a = fill;
    }
    if (st >= 0)
      st |= mpmc_h5_rows_write(g, pfields[k].name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, total,
                               nc > 1 ? (size_t)nc : 0, off, (size_t)n, a, dxpl);
  }
  if (st >= 0)
    st |= mpmc_h5_rows_write(g, "mat", H5T_STD_I32LE, H5T_NATIVE_INT, total, 0, off, (size_t)n,
                             p->mat, dxpl);
  if (st >= 0 && (has >> NPFIELD & 1u)) /* the points' ids once a sort moved them, or over MPI */
    st |= mpmc_h5_rows_write(g, "id", H5T_STD_I32LE, H5T_NATIVE_INT, total, 0, off, (size_t)n,
                             p->id, dxpl);
  free(fill);
  mpmc_io_plist_close(dxpl);
  if (g >= 0) H5Gclose(g);
  return st < 0 ? -1 : 0;
}

/* Over MPI (k->rows) this rank's points are the rows of its slab. */
static int read_particles(hid_t f, mpmc_sim sim, ckpt_rows *k) {
  mpmc_context ctx = sim->ctx;
  mpmc_particles *p = &sim->p;
  hid_t g = exists(f, "particles") ? H5Gopen2(f, "particles", H5P_DEFAULT) : -1;
  MPMC_CHECK(g >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint has no /particles group");
  int nt = -1, nus = -1;
  int err = MPMC_SUCCESS;
  if (mpmc_h5_attr_read(g, "n", H5T_NATIVE_INT, 1, &nt) < 0 || nt < 0 ||
      mpmc_h5_attr_read(g, "nustate", H5T_NATIVE_INT, 1, &nus) < 0 || nus < 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /particles: bad n = %d or nustate = %d", nt,
                     nus);
  k->total = nt;
  k->n = nt;
  if (!err && mpmc_dd_ranks(sim) > 1) {
    k->n = 0;
    err = select_rows(g, sim, k);
  }
  const int n = k->n;
  if (!err) err = mpmc_particles_reserve(ctx, p, n > 64 ? n : 64);
  if (!err) {
    p->n = n;
    p->nustate = nus;
  }
  for (size_t i = 0; i < NPFIELD && !err; ++i) {
    const pfield *pf = &pfields[i];
    double **a = pfield_ptr(p, pf);
    const int nc = pfield_ncomp(p, pf);
    if (!exists(g, pf->name)) {
      if (pf->required || (pf->ncomp < 0 && nc > 0))
        err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /particles: dataset '%s' is missing",
                         pf->name);
      continue;
    }
    if (!*a) err = mpmc_particles_ensure(ctx, p, a, nc, 0.0);
    if (!err && read_kept(g, pf->name, H5T_NATIVE_DOUBLE, nc > 1 ? (size_t)nc : 0, k, *a) < 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT,
                       "checkpoint /particles/%s: unreadable or not of shape [%d][%d]", pf->name,
                       nt, nc);
  }
  if (!err && read_kept(g, "mat", H5T_NATIVE_INT, 0, k, p->mat) < 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /particles/mat: missing or not [%d]", nt);
  for (int q = 0; q < n && !err; ++q)
    if (p->mat[q] < 0 || p->mat[q] >= sim->nmat)
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint point %d: material id %d of %d", q,
                       p->mat[q], sim->nmat);
  sim->np_global = nt; /* the points added so far: the next one's id over MPI */
  const int has_id = exists(g, "id");
  if (!err && (has_id || sim->dd)) { /* over MPI the ids are global: a point keeps its row's */
    p->id = malloc(sizeof(int) * (size_t)p->cap);
    if (!p->id || (has_id && read_kept(g, "id", H5T_NATIVE_INT, 0, k, p->id) < 0))
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /particles/id: unreadable or not [%d]", nt);
    for (int q = 0; q < n && !err && !has_id; ++q) p->id[q] = k->rows ? k->rows[q] : q;
    p->global_ids = sim->dd != NULL;
    /* a permutation of 0 .. nt-1: each id once (over MPI each rank checks its own) */
    unsigned char *seen = err ? NULL : calloc((size_t)nt + 1, 1);
    if (!err && !seen) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "checkpoint: out of memory");
    for (int q = 0; q < n && !err; ++q) {
      if (p->id[q] < 0 || p->id[q] >= nt || seen[p->id[q]])
        err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT,
                         "checkpoint /particles/id: point %d has id %d (not a permutation of 0 .. %d)",
                         q, p->id[q], nt - 1);
      else
        seen[p->id[q]] = 1;
    }
    free(seen);
  }
  H5Gclose(g);
  return err;
}

/* ---- block: walls ------------------------------------------------------------------------- */

#define WALLCOLS 10 /* active kind axis side lo[3] hi[3] */

static int write_walls(hid_t f, mpmc_const_sim sim) {
  const int nw = sim->nwall;
  double *w = malloc(sizeof(double) * WALLCOLS * (size_t)(nw > 0 ? nw : 1));
  if (!w) return -1;
  for (int i = 0; i < nw; ++i) {
    const mpmc_wall *s = &sim->walls[i];
    double *r = w + (size_t)i * WALLCOLS;
    r[0] = s->active, r[1] = s->kind, r[2] = s->axis, r[3] = s->side;
    for (int a = 0; a < 3; ++a) r[4 + a] = s->lo[a], r[7 + a] = s->hi[a];
  }
  herr_t st =
      mpmc_h5_dataset_write(f, "walls", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)nw, WALLCOLS, w);
  /* walls on node sets: the set ids, in a dataset of their own so that checkpoints without
   * it (written before node sets existed) still read */
  int *ns = malloc(sizeof(int) * (size_t)(nw > 0 ? nw : 1));
  if (!ns) st = -1;
  for (int i = 0; i < nw && ns; ++i) ns[i] = sim->walls[i].nodeset;
  if (st >= 0)
    st = mpmc_h5_dataset_write(f, "walls_nodeset", H5T_STD_I32LE, H5T_NATIVE_INT, (size_t)nw, 0, ns);
  free(ns);
  free(w);
  return st < 0 ? -1 : 0;
}

static int read_walls(hid_t f, mpmc_sim sim, ckpt_rows *k) {
  (void)k;
  mpmc_context ctx = sim->ctx;
  hid_t ds = exists(f, "walls") ? H5Dopen2(f, "walls", H5P_DEFAULT) : -1;
  MPMC_CHECK(ds >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint has no /walls dataset");
  hid_t sp = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  const int rank = sp >= 0 ? H5Sget_simple_extent_dims(sp, dims, NULL) : -1;
  if (sp >= 0) H5Sclose(sp);
  H5Dclose(ds);
  MPMC_CHECK(rank == 2 && dims[1] == WALLCOLS && dims[0] < 1000000, ctx, MPMC_ERR_FORMAT,
             "checkpoint /walls is not [n][%d]", WALLCOLS);
  const int nw = (int)dims[0];
  double *w = malloc(sizeof(double) * WALLCOLS * (size_t)(nw > 0 ? nw : 1));
  sim->walls = calloc((size_t)(nw > 0 ? nw : 1), sizeof *sim->walls);
  MPMC_CHECK(w && sim->walls, ctx, MPMC_ERR_MEMORY, "cannot allocate %d walls", nw);
  sim->capwall = nw > 0 ? nw : 1;
  if (read_dataset(f, "walls", H5T_NATIVE_DOUBLE, (size_t)nw, WALLCOLS, w) < 0) {
    free(w);
    return MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /walls: unreadable");
  }
  for (int i = 0; i < nw; ++i) {
    const double *r = w + (size_t)i * WALLCOLS;
    mpmc_wall *s = &sim->walls[i];
    s->active = (int)r[0], s->kind = (int)r[1], s->axis = (int)r[2], s->side = (int)r[3];
    for (int a = 0; a < 3; ++a) s->lo[a] = r[4 + a], s->hi[a] = r[7 + a];
    s->nodeset = -1;
  }
  free(w);
  if (exists(f, "walls_nodeset")) {
    int *ns = malloc(sizeof(int) * (size_t)(nw > 0 ? nw : 1));
    MPMC_CHECK(ns, ctx, MPMC_ERR_MEMORY, "cannot allocate %d wall node-set ids", nw);
    if (read_dataset(f, "walls_nodeset", H5T_NATIVE_INT, (size_t)nw, 0, ns) < 0) {
      free(ns);
      return MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /walls_nodeset: not [%d] integers", nw);
    }
    for (int i = 0; i < nw; ++i) sim->walls[i].nodeset = ns[i];
    free(ns);
  }
  sim->nwall = nw;
  sim->scr.walls_dirty = 1;
  return MPMC_SUCCESS;
}

/* ---- block: particle sets ------------------------------------------------------------------ */

/* One group per kind of set: a dataset per set ([n] point indices, or [n][dim] node
 * coordinates), named by number, with the set's name as an attribute. */
/* Over MPI the particle sets' members are the rows of the points in /particles (each rank's
 * from its offset), rank after rank; node sets are the same on every rank. */
static int write_set_group(hid_t f, mpmc_const_sim sim, const char *gname,
                           const struct mpmc_sets_s *S, int ncomp) {
  hid_t g = H5Gcreate2(f, gname, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) return -1;
  long long off = 0, total = 0, soff = 0, stotal = 0;
  mpmc_io_scan(sim, sim->p.n, &off, &total);
  hid_t dxpl = ncomp == 1 ? mpmc_io_dxpl(sim) : H5P_DEFAULT;
  const int ns = S ? S->n : 0;
  herr_t st = dxpl < 0 ? -1 : mpmc_h5_attr_write(g, "count", H5T_NATIVE_INT, 1, &ns);
  for (int k = 0; k < ns && st >= 0; ++k) {
    const mpmc_set *s = &S->s[k];
    char name[32];
    snprintf(name, sizeof name, "%06d", k); /* set names may hold '/' : kept as attributes */
    if (ncomp == 1) {
      int *rows = malloc(sizeof(int) * (size_t)(s->n > 0 ? s->n : 1));
      for (int j = 0; rows && j < s->n; ++j) rows[j] = (int)off + s->idx[j];
      mpmc_io_scan(sim, s->n, &soff, &stotal);
      st |= rows ? mpmc_h5_rows_write(g, name, H5T_STD_I32LE, H5T_NATIVE_INT, stotal, 0, soff,
                                      (size_t)s->n, rows, dxpl)
                 : -1;
      free(rows);
    } else {
      st |= mpmc_h5_dataset_write(g, name, H5T_STD_I32LE, H5T_NATIVE_INT, (size_t)s->n,
                                  (size_t)ncomp, s->idx);
    }
    hid_t ds = st >= 0 ? H5Dopen2(g, name, H5P_DEFAULT) : -1;
    if (ds < 0 || mpmc_h5_attr_write_string(ds, "name", s->name) < 0) st = -1;
    if (ds >= 0) H5Dclose(ds);
  }
  mpmc_io_plist_close(dxpl);
  H5Gclose(g);
  return st < 0 ? -1 : 0;
}

static int write_sets(hid_t f, mpmc_const_sim sim) {
  if (write_set_group(f, sim, "sets", sim->sets, 1) < 0) return -1;
  return write_set_group(f, sim, "node_sets", sim->node_sets, sim->cfg.dim);
}

static int cmp_int(const void *a, const void *b) {
  const int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

/* Over MPI (k->rows) the members among this rank's rows, as its indices. */
static int local_members(const ckpt_rows *k, int *idx, int n) {
  if (!k->rows) return n;
  int m = 0;
  for (int j = 0; j < n; ++j) {
    const int *at = bsearch(&idx[j], k->rows, (size_t)k->n, sizeof(int), cmp_int);
    if (at) idx[m++] = (int)(at - k->rows);
  }
  return m;
}

static int read_set_group(hid_t f, mpmc_sim sim, const char *gname, int ncomp,
                          const ckpt_rows *kr) {
  mpmc_context ctx = sim->ctx;
  hid_t g = exists(f, gname) ? H5Gopen2(f, gname, H5P_DEFAULT) : -1;
  MPMC_CHECK(g >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint has no /%s group", gname);
  int ns = -1, err = MPMC_SUCCESS;
  if (mpmc_h5_attr_read(g, "count", H5T_NATIVE_INT, 1, &ns) < 0 || ns < 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /%s: bad count %d", gname, ns);
  for (int k = 0; k < ns && !err; ++k) {
    char dname[32];
    snprintf(dname, sizeof dname, "%06d", k);
    hid_t ds = exists(g, dname) ? H5Dopen2(g, dname, H5P_DEFAULT) : -1;
    char *name = NULL;
    hssize_t n = -1;
    if (ds >= 0) {
      hid_t sp = H5Dget_space(ds);
      n = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
      if (sp >= 0) H5Sclose(sp);
      if (mpmc_h5_attr_read_string(ds, "name", &name) < 0 || n % ncomp != 0) n = -1;
      H5Dclose(ds);
    }
    int *idx = n >= 0 && n < INT32_MAX ? malloc(sizeof(int) * (size_t)(n > 0 ? n : 1)) : NULL;
    const size_t rows = n > 0 ? (size_t)n / (size_t)ncomp : 0;
    if (!idx || read_dataset(g, dname, H5T_NATIVE_INT, rows, ncomp > 1 ? (size_t)ncomp : 0, idx) < 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /%s/%s: unreadable", gname, dname);
    else if (ncomp == 1)
      err = mpmc_sim_add_particle_set(sim, name, local_members(kr, idx, (int)rows), idx, NULL);
    else
      err = mpmc_sim_add_node_set(sim, name, (int)rows, idx, NULL);
    free(idx);
    free(name);
  }
  H5Gclose(g);
  return err;
}

static int read_sets(hid_t f, mpmc_sim sim, ckpt_rows *k) {
  MPMC_CALL(read_set_group(f, sim, "sets", 1, k));
  /* checkpoints written before node sets existed have none */
  return exists(f, "node_sets") ? read_set_group(f, sim, "node_sets", sim->cfg.dim, k) : MPMC_SUCCESS;
}

/* ---- block: rigid bodies (contact_barrier.c) ---------------------------------------------- */

/* One row per body: active kind mu nvert lo[3] hi[3] v[3] offset[3] reaction[3]; the polygons'
 * vertices concatenated in /bodies/vertices [sum nvert][2].  "present" records whether the
 * sim had a contact record at all (mpmc_sim_set_contact_params alone creates one), so that a
 * restart zeroes p->cforce on the same steps as the uninterrupted run. */
#define BODYCOLS 19

/* Body i's friction anchors over MPI: a row per point ([points][3]), each rank's from its
 * offset in /particles; points beyond the anchors' count (added since the last contact
 * pass) start at zero, as mpmc_contact_grow_anchors starts them. */
static herr_t write_anchors_mpi(hid_t g, mpmc_const_sim sim, int i) {
  const mpmc_body *b = &sim->bodies->b[i];
  const int n = sim->p.n;
  long long off = 0, total = 0;
  mpmc_io_scan(sim, n, &off, &total);
  double *a = calloc(3 * (size_t)(n > 0 ? n : 1), sizeof(double));
  hid_t dxpl = mpmc_io_dxpl(sim);
  const int m = b->anchor ? (b->nanchor < n ? b->nanchor : n) : 0;
  if (a && m) memcpy(a, b->anchor, sizeof(double) * 3 * (size_t)m);
  char name[32];
  snprintf(name, sizeof name, "anchor%d", i);
  herr_t st = a && dxpl >= 0 ? mpmc_h5_rows_write(g, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, total,
                                                  3, off, (size_t)n, a, dxpl)
                             : -1;
  mpmc_io_plist_close(dxpl);
  free(a);
  return st;
}

static int write_bodies(hid_t f, mpmc_const_sim sim) {
  const struct mpmc_bodies_s *B = sim->bodies;
  const int present = B != NULL, nb = B ? B->n : 0;
  const double par[2] = {B ? B->dhat : 0.0, B ? B->kappa : 0.0};
  int nv = 0;
  for (int i = 0; i < nb; ++i) nv += B->b[i].kind == BODY_POLYGON ? B->b[i].nvert : 0;
  double *rows = malloc(sizeof(double) * BODYCOLS * (size_t)(nb > 0 ? nb : 1));
  double *xy = malloc(sizeof(double) * 2 * (size_t)(nv > 0 ? nv : 1));
  hid_t g = rows && xy ? H5Gcreate2(f, "bodies", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
  herr_t st = g < 0 ? -1 : 0;
  for (int i = 0, k = 0; i < nb && st >= 0; ++i) {
    const mpmc_body *b = &B->b[i];
    double *r = rows + (size_t)i * BODYCOLS;
    r[0] = b->active, r[1] = b->kind, r[2] = b->mu, r[3] = b->kind == BODY_POLYGON ? b->nvert : 0;
    for (int a = 0; a < 3; ++a) {
      r[4 + a] = b->lo[a], r[7 + a] = b->hi[a], r[10 + a] = b->v[a];
      r[13 + a] = b->offset[a], r[16 + a] = b->reaction[a];
    }
    if (b->kind == BODY_POLYGON) {
      memcpy(xy + 2 * (size_t)k, b->xy, sizeof(double) * 2 * (size_t)b->nvert);
      k += b->nvert;
    }
  }
  if (st >= 0) {
    st |= mpmc_h5_attr_write(g, "present", H5T_NATIVE_INT, 1, &present);
    st |= mpmc_h5_attr_write(g, "dhat_kappa", H5T_NATIVE_DOUBLE, 2, par);
    st |= mpmc_h5_dataset_write(g, "bodies", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)nb,
                                BODYCOLS, rows);
    st |= mpmc_h5_dataset_write(g, "vertices", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)nv, 2,
                                xy);
    st |= mpmc_h5_attr_write_string(
        g, "bodies_columns", "active kind mu nvert lo[3] hi[3] v[3] offset[3] reaction[3]");
  }
  int rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  for (int i = 0; i < nb && st >= 0 && size > 1; ++i) { /* over MPI: per point, as /particles */
    unsigned has = B->b[i].anchor != NULL;
    mpmc_io_or(sim, &has, 1);
    if (has) st |= write_anchors_mpi(g, sim, i);
  }
  for (int i = 0; i < nb && st >= 0 && size == 1; ++i) /* friction anchors (elastic stick) */
    if (B->b[i].anchor) {
      char name[32];
      snprintf(name, sizeof name, "anchor%d", i);
      st |= mpmc_h5_dataset_write(g, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                                  (size_t)B->b[i].nanchor, 3, B->b[i].anchor);
    }
  if (g >= 0) H5Gclose(g);
  free(rows);
  free(xy);
  return st < 0 ? -1 : 0;
}

/* A checkpoint without the group (written before bodies were saved) has no bodies. */
static int read_bodies(hid_t f, mpmc_sim sim, ckpt_rows *kr) {
  mpmc_context ctx = sim->ctx;
  if (!exists(f, "bodies")) return MPMC_SUCCESS;
  hid_t g = H5Gopen2(f, "bodies", H5P_DEFAULT);
  MPMC_CHECK(g >= 0, ctx, MPMC_ERR_FORMAT, "checkpoint /bodies: cannot open the group");
  int present = 0, err = MPMC_SUCCESS;
  double par[2] = {0, 0};
  const long nb = dataset_rows(g, "bodies", BODYCOLS), nv = dataset_rows(g, "vertices", 2);
  double *rows = NULL, *xy = NULL;
  if (mpmc_h5_attr_read(g, "present", H5T_NATIVE_INT, 1, &present) < 0 ||
      mpmc_h5_attr_read(g, "dhat_kappa", H5T_NATIVE_DOUBLE, 2, par) < 0 || nb < 0 || nv < 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT,
                     "checkpoint /bodies: attributes present/dhat_kappa or datasets bodies "
                     "[n][%d] / vertices [n][2] missing",
                     BODYCOLS);
  if (!err) {
    rows = malloc(sizeof(double) * BODYCOLS * (size_t)(nb > 0 ? nb : 1));
    xy = malloc(sizeof(double) * 2 * (size_t)(nv > 0 ? nv : 1));
    if (!rows || !xy) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot allocate %ld bodies", nb);
  }
  if (!err && (read_dataset(g, "bodies", H5T_NATIVE_DOUBLE, (size_t)nb, BODYCOLS, rows) < 0 ||
               read_dataset(g, "vertices", H5T_NATIVE_DOUBLE, (size_t)nv, 2, xy) < 0))
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /bodies: datasets unreadable");
  if (!err && present) {
    sim->bodies = calloc(1, sizeof *sim->bodies);
    if (sim->bodies) sim->bodies->b = calloc((size_t)(nb > 0 ? nb : 1), sizeof(mpmc_body));
    if (!sim->bodies || !sim->bodies->b)
      err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot allocate %ld rigid bodies", nb);
    else {
      sim->bodies->cap = nb > 0 ? (int)nb : 1;
      sim->bodies->dhat = par[0];
      sim->bodies->kappa = par[1];
    }
  }
  long k = 0;
  for (long i = 0; i < nb && !err && present; ++i) {
    const double *r = rows + (size_t)i * BODYCOLS;
    mpmc_body *b = &sim->bodies->b[i];
    b->active = (int)r[0], b->kind = (int)r[1], b->mu = r[2], b->nvert = (int)r[3];
    for (int a = 0; a < 3; ++a) {
      b->lo[a] = r[4 + a], b->hi[a] = r[7 + a], b->v[a] = r[10 + a];
      b->offset[a] = r[13 + a], b->reaction[a] = r[16 + a];
    }
    if (b->kind != BODY_BOX && !(b->kind == BODY_POLYGON && sim->cfg.dim == 2 && b->nvert >= 3 &&
                                 k + b->nvert <= nv)) {
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT,
                       "checkpoint rigid body %ld: kind %d with %d vertices (%ld stored) is "
                       "not a box or a 2D polygon",
                       i, b->kind, b->nvert, nv - k);
      break;
    }
    if (b->kind == BODY_POLYGON) {
      b->xy = malloc(sizeof(double) * 2 * (size_t)b->nvert);
      if (!b->xy) {
        err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot allocate polygon %ld", i);
        break;
      }
      memcpy(b->xy, xy + 2 * (size_t)k, sizeof(double) * 2 * (size_t)b->nvert);
      k += b->nvert;
    } else {
      b->nvert = 0;
    }
    sim->bodies->n = (int)i + 1; /* mpmc_contact_free releases what was read so far */
    char aname[32];
    snprintf(aname, sizeof aname, "anchor%ld", i);
    const long na = dataset_rows(g, aname, 3);
    if (exists(g, aname) && na < 0) {
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /bodies/%s is not [n][3]", aname);
      break;
    }
    /* over MPI the rows of this rank's points below the anchors' count (a prefix of them) */
    ckpt_rows sub = {kr->rows, 0, na};
    while (kr->rows && sub.n < kr->n && kr->rows[sub.n] < na) sub.n++;
    const long nk = kr->rows ? sub.n : na;
    if (nk > 0) {
      b->anchor = malloc(sizeof(double) * 3 * (size_t)nk);
      if (!b->anchor || read_kept(g, aname, H5T_NATIVE_DOUBLE, 3, &sub, b->anchor) < 0) {
        err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint /bodies/%s: unreadable", aname);
        break;
      }
      b->nanchor = (int)nk;
    }
  }
  H5Gclose(g);
  free(rows);
  free(xy);
  return err;
}

/* ---- checksum ----------------------------------------------------------------------------- */

/* FNV-1a 64 over every attribute and dataset of the file but the checksum itself, in name
 * order, group by group: each name and then the stored bytes (read in the file's own type).
 * HDF5 checks neither the raw data nor the attributes of these files, so a flipped bit would
 * otherwise load silently.  err: an HDF5 call failed (the file is damaged or unreadable). */
typedef struct {
  uint64_t h;
  int err;
} fnv1a;

static void fnv1a_add(fnv1a *s, const void *p, size_t n) {
  const unsigned char *b = p;
  uint64_t h = s->h;
  for (size_t i = 0; i < n; ++i) {
    h ^= b[i];
    h *= 0x100000001b3ULL;
  }
  s->h = h;
}

/* The stored bytes of attribute (is_attr) or dataset `id`, read in its own type. */
static void hash_data(fnv1a *s, hid_t id, int is_attr) {
  hid_t t = is_attr ? H5Aget_type(id) : H5Dget_type(id);
  hid_t sp = is_attr ? H5Aget_space(id) : H5Dget_space(id);
  const hssize_t np = sp >= 0 ? H5Sget_simple_extent_npoints(sp) : -1;
  const size_t size = t >= 0 && np >= 0 ? H5Tget_size(t) * (size_t)np : 0;
  void *buf = t >= 0 && np >= 0 ? malloc(size ? size : 1) : NULL;
  if (!buf || (size && (is_attr ? H5Aread(id, t, buf) : H5Dread(id, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf)) < 0))
    s->err = 1;
  else
    fnv1a_add(s, buf, size);
  free(buf);
  if (sp >= 0) H5Sclose(sp);
  if (t >= 0) H5Tclose(t);
}

static herr_t hash_attr(hid_t loc, const char *name, const H5A_info_t *info, void *data) {
  (void)info;
  fnv1a *s = data;
  if (!strcmp(name, CKPT_CHECKSUM)) return 0;
  fnv1a_add(s, name, strlen(name) + 1);
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  if (a < 0) return s->err = 1, -1;
  hash_data(s, a, 1);
  H5Aclose(a);
  return s->err ? -1 : 0;
}

static herr_t hash_link(hid_t g, const char *name, const H5L_info_t *info, void *data) {
  (void)info;
  fnv1a *s = data;
  fnv1a_add(s, name, strlen(name) + 1);
  hid_t o = H5Oopen(g, name, H5P_DEFAULT);
  if (o < 0) return s->err = 1, -1;
  hsize_t at = 0;
  if (H5Aiterate2(o, H5_INDEX_NAME, H5_ITER_INC, &at, hash_attr, s) < 0) s->err = 1;
  const H5I_type_t kind = H5Iget_type(o);
  hsize_t next = 0;
  if (!s->err && kind == H5I_GROUP && H5Literate(o, H5_INDEX_NAME, H5_ITER_INC, &next, hash_link, s) < 0)
    s->err = 1;
  if (!s->err && kind == H5I_DATASET) hash_data(s, o, 0);
  H5Oclose(o);
  return s->err ? -1 : 0;
}

/* The checksum of file f; < 0 when a part of it cannot be read. */
static int checksum(hid_t f, uint64_t *h) {
  fnv1a s = {0xcbf29ce484222325ULL, 0};
  hid_t root = H5Gopen2(f, "/", H5P_DEFAULT);
  hsize_t at = 0, next = 0;
  if (root < 0 || H5Aiterate2(root, H5_INDEX_NAME, H5_ITER_INC, &at, hash_attr, &s) < 0 ||
      H5Literate(root, H5_INDEX_NAME, H5_ITER_INC, &next, hash_link, &s) < 0)
    s.err = 1;
  if (root >= 0) H5Gclose(root);
  *h = s.h;
  return s.err ? -1 : 0;
}

/* ---- the file ------------------------------------------------------------------------------ */

typedef struct {
  const char *name;
  int (*write)(hid_t f, mpmc_const_sim sim); /* < 0 on an HDF5 failure             */
  int (*read)(hid_t f, mpmc_sim sim, ckpt_rows *k); /* an MPMC error code with a message */
} block;

/* Materials before particles (ids are checked), particles before sets (indices are). */
static const block blocks[] = {{"config", write_config, read_config},
                               {"materials", write_materials, read_materials},
                               {"particles", write_particles, read_particles},
                               {"walls", write_walls, read_walls},
                               {"sets", write_sets, read_sets},
                               {"bodies", write_bodies, read_bodies}};
#define NBLOCK (sizeof blocks / sizeof blocks[0])

/**
 * @brief Write everything needed to continue the run to `path`, atomically: the file is
 *        written as path.tmp, flushed, fsync'ed and renamed over path.  On failure path is
 *        left as it was.
 * @param meta the caller's text stored alongside (e.g. the workflow stage), may be NULL
 */
int mpmc_sim_checkpoint_write(mpmc_const_sim sim, const char *path, const char *meta) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(path && path[0], ctx, MPMC_ERR_ARG, "checkpoint path is NULL or empty");
  MPMC_CHECK(sim->grid.valid, ctx, MPMC_ERR_STATE, "checkpoint: no grid set, nothing to save");
  int rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  const size_t len = strlen(path) + 5;
  char *tmp = malloc(len);
  MPMC_CHECK(tmp, ctx, MPMC_ERR_MEMORY, "cannot allocate a path");
  snprintf(tmp, len, "%s.tmp", path);
  mpmc_h5_quiet q;
  mpmc_h5_quiet_begin(&q);
  int err = MPMC_SUCCESS;
  hid_t fapl = mpmc_io_fapl(sim); /* over MPI: every rank writes the one file */
  hid_t f = fapl < 0 ? -1 : H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  mpmc_io_plist_close(fapl);
  if (f < 0) {
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot create the checkpoint file '%s'", tmp);
  } else {
    const int version = CKPT_VERSION;
    herr_t st = 0;
    st |= mpmc_h5_attr_write_string(f, "format", CKPT_FORMAT);
    st |= mpmc_h5_attr_write(f, "format_version", H5T_NATIVE_INT, 1, &version);
    st |= mpmc_h5_attr_write_string(f, "library_version", MPMC_VERSION_STRING);
    st |= mpmc_h5_attr_write_string(f, "meta", meta ? meta : "");
    if (st < 0) err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write the header of '%s'", tmp);
    for (size_t b = 0; b < NBLOCK && !err; ++b)
      if (blocks[b].write(f, sim) < 0)
        err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write the '%s' block of '%s'", blocks[b].name,
                         tmp);
    if (H5Fclose(f) < 0 && !err) err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot close '%s'", tmp);
  }
  err = mpmc_dd_agree(sim, err);
  /* the checksum over the whole file, by one process (rank 0 over MPI, after every rank
   * closed it), then the file made durable and renamed */
  if (!err && rank == 0) {
    f = H5Fopen(tmp, H5F_ACC_RDWR, H5P_DEFAULT);
    uint64_t sum = 0;
    if (f < 0 || checksum(f, &sum) < 0 || mpmc_h5_attr_write(f, CKPT_CHECKSUM, H5T_STD_U64LE, 1, &sum) < 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write the checksum of '%s'", tmp);
    if (!err && H5Fflush(f, H5F_SCOPE_GLOBAL) < 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot flush '%s'", tmp);
    if (f >= 0 && H5Fclose(f) < 0 && !err) err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot close '%s'", tmp);
  }
  mpmc_h5_quiet_end(&q);
  if (rank == 0) {
    if (!err && mpmc_fsync_path(tmp) != 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot fsync '%s': %s", tmp, strerror(errno));
    if (!err && rename(tmp, path) != 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot rename '%s' to '%s': %s", tmp, path,
                       strerror(errno));
    if (err)
      remove(tmp);
    else
      mpmc_fsync_path(path); /* the directory entry of the rename */
  }
  free(tmp);
  return mpmc_dd_agree(sim, err);
}

/* The file's checksum against its record.  Files written before the checksum have none:
 * they are read unchecked. */
static int verify_checksum(mpmc_context ctx, const char *path, hid_t f) {
  if (H5Aexists(f, CKPT_CHECKSUM) <= 0) return MPMC_SUCCESS;
  uint64_t stored = 0, sum = 0;
  MPMC_CHECK(mpmc_h5_attr_read(f, CKPT_CHECKSUM, H5T_NATIVE_UINT64, 1, &stored) >= 0, ctx,
             MPMC_ERR_FORMAT, "checkpoint '%s': its checksum attribute is unreadable", path);
  MPMC_CHECK(checksum(f, &sum) >= 0, ctx, MPMC_ERR_FORMAT,
             "checkpoint '%s' is damaged: a dataset or attribute cannot be read", path);
  MPMC_CHECK(sum == stored, ctx, MPMC_ERR_FORMAT,
             "checkpoint '%s' is damaged: its contents give the checksum %016llx, the file "
             "records %016llx (FNV-1a 64 over every dataset and attribute)",
             path, (unsigned long long)sum, (unsigned long long)stored);
  return MPMC_SUCCESS;
}

/* The file's format, version and dimension. */
static int read_header(mpmc_context ctx, const char *path, hid_t f, int *dim) {
  char *fmt = NULL;
  int version = -1;
  if (mpmc_h5_attr_read_string(f, "format", &fmt) < 0 || strcmp(fmt, CKPT_FORMAT) != 0) {
    const int err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT,
                               "'%s' is an HDF5 file but not a libmpmc checkpoint (format '%s')",
                               path, fmt ? fmt : "none");
    free(fmt);
    return err;
  }
  free(fmt);
  MPMC_CHECK(mpmc_h5_attr_read(f, "format_version", H5T_NATIVE_INT, 1, &version) >= 0, ctx,
             MPMC_ERR_FORMAT, "checkpoint '%s' has no format_version", path);
  MPMC_CHECK(version == CKPT_VERSION, ctx, MPMC_ERR_FORMAT,
             "checkpoint '%s' has format version %d; this library (%s) reads version %d", path,
             version, MPMC_VERSION_STRING, CKPT_VERSION);
  hid_t g = exists(f, "config") ? H5Gopen2(f, "config", H5P_DEFAULT) : -1;
  int ints[6] = {0};
  *dim = 0;
  if (g >= 0) {
    if (mpmc_h5_attr_read(g, "dim_basis_fbar_solver_nthreads_forcedt", H5T_NATIVE_INT, 6, ints) >= 0)
      *dim = ints[0];
    H5Gclose(g);
  }
  MPMC_CHECK(*dim == 2 || *dim == 3, ctx, MPMC_ERR_FORMAT,
             "checkpoint '%s': /config missing or dimension %d is not 2 or 3", path, *dim);
  return MPMC_SUCCESS;
}

/* The simulation of the file, over comm (NULL: one process): every rank reads the file and
 * keeps the points of its slab. */
static int read_file(mpmc_context ctx, const void *comm, const char *path, hid_t f, int dim,
                     mpmc_sim *out, char **meta) {
  mpmc_sim sim = NULL;
  MPMC_CALL(mpmc_io_sim_create(ctx, comm, dim, &sim));
  ckpt_rows k = {NULL, 0, 0};
  int err = MPMC_SUCCESS, rank, size;
  mpmc_io_ranks(sim, &rank, &size);
  for (size_t b = 0; b < NBLOCK && !err; ++b) err = blocks[b].read(f, sim, &k);
  err = mpmc_dd_agree(sim, err);
  /* after the blocks: a block that does not make sense is named by its own message; a file
   * whose every block reads is still refused when a bit of it changed (over MPI: rank 0
   * reads it all once) */
  if (!err && rank == 0) err = verify_checksum(ctx, path, f);
  err = mpmc_dd_agree(sim, err);
  if (!err && size > 1) { /* every point on one rank */
    long long off, total;
    mpmc_io_scan(sim, sim->p.n, &off, &total);
    if (total != k.total)
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint '%s': the ranks kept %lld of its %lld points",
                       path, total, k.total);
  }
  free(k.rows);
  char *m = NULL;
  if (!err && meta && mpmc_h5_attr_read_string(f, "meta", &m) < 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "checkpoint '%s' has no meta text", path);
  if (err) {
    mpmc_sim_destroy(&sim);
    free(m);
    return err;
  }
  sim->scr.prepared = 0;
  sim->scr.walls_dirty = 1;
  *out = sim;
  if (meta) *meta = m;
  return MPMC_SUCCESS;
}

static int read_path(mpmc_context ctx, const void *comm, const char *path, mpmc_sim *sim, char **meta) {
  int err = MPMC_SUCCESS, dim = 0;
  hid_t f = -1;
  mpmc_h5_quiet q;
  mpmc_h5_quiet_begin(&q);
  if (access(path, R_OK) != 0) {
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot read checkpoint '%s': %s", path, strerror(errno));
  } else {
    const htri_t is = H5Fis_hdf5(path);
    f = is > 0 ? H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT) : -1; /* over MPI: on every rank */
    if (is <= 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "'%s' is not an HDF5 file (foreign or truncated)", path);
    else if (f < 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "'%s' is a damaged HDF5 file (truncated?)", path);
    else
      err = read_header(ctx, path, f, &dim);
  }
  err = mpmc_io_agree(ctx, comm, err);
  if (!err) err = read_file(ctx, comm, path, f, dim, sim, meta);
  if (f >= 0) H5Fclose(f);
  mpmc_h5_quiet_end(&q);
  return err;
}

/**
 * @brief Create a simulation from a checkpoint written by mpmc_sim_checkpoint_write (by one
 *        process or by any number of MPI ranks: the one process keeps every point).
 *        User materials come back without their function: re-attach it with
 *        mpmc_sim_set_material_user_fn before stepping.
 * @param[out] sim the new simulation (untouched on failure)
 * @param[out] meta a copy of the caller's text (may be NULL), released with mpmc_free
 * @return MPMC_ERR_IO for a missing or unreadable file, MPMC_ERR_FORMAT for a truncated,
 *         foreign or incompatible one
 */
int mpmc_sim_checkpoint_read(mpmc_context ctx, const char *path, mpmc_sim *sim, char **meta) {
  if (!ctx) return MPMC_ERR_ARG;
  MPMC_CHECK(path && path[0], ctx, MPMC_ERR_ARG, "checkpoint path is NULL or empty");
  MPMC_CHECK(sim, ctx, MPMC_ERR_ARG, "sim pointer is NULL");
  return read_path(ctx, NULL, path, sim, meta);
}

#ifdef MPMC_HAVE_MPI
/**
 * @brief mpmc_sim_checkpoint_read over the ranks of comm (collective), whatever the number
 *        of ranks that wrote the file: each rank keeps the points of its slab, with their
 *        ids and every field; the rest of the state is the same on every rank.
 * @param comm an intra-communicator (duplicated, as by mpmc_sim_create_mpi)
 */
int mpmc_sim_checkpoint_read_mpi(mpmc_context ctx, MPI_Comm comm, const char *path, mpmc_sim *sim,
                                 char **meta) {
  if (!ctx) return MPMC_ERR_ARG;
  MPMC_CHECK(path && path[0], ctx, MPMC_ERR_ARG, "checkpoint path is NULL or empty");
  MPMC_CHECK(sim, ctx, MPMC_ERR_ARG, "sim pointer is NULL");
  MPMC_CHECK(comm != MPI_COMM_NULL, ctx, MPMC_ERR_ARG, "checkpoint read: comm is MPI_COMM_NULL");
  return read_path(ctx, &comm, path, sim, meta);
}

/** @brief mpmc_sim_checkpoint_read_mpi for Fortran: comm is MPI's Fortran handle. */
int mpmc_sim_checkpoint_read_mpi_f(mpmc_context ctx, MPI_Fint comm, const char *path, mpmc_sim *sim,
                                   char **meta) {
  return mpmc_sim_checkpoint_read_mpi(ctx, MPI_Comm_f2c(comm), path, sim, meta);
}
#endif

/** @brief Release memory the library handed out (e.g. the meta text of a checkpoint). */
void mpmc_free(void *ptr) { free(ptr); }
