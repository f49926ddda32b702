/* HDF5 snapshots of the particle fields: one file per run, one group per snapshot
 * (/snapshot_000000, ...), plus the XDMF file (io_xdmf.c) through which ParaView opens the
 * series as points with attributes.  The HDF5 file is opened and closed around each
 * snapshot so that a run that dies between snapshots leaves a readable file. */
#ifndef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700 /* realpath */
#endif
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io_mpi.h"
#include "sets.h"

void mpmc_h5_quiet_begin(mpmc_h5_quiet *q) {
  H5Eget_auto2(H5E_DEFAULT, &q->fn, &q->data);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

void mpmc_h5_quiet_end(const mpmc_h5_quiet *q) { H5Eset_auto2(H5E_DEFAULT, q->fn, q->data); }

herr_t mpmc_h5_attr_write(hid_t loc, const char *name, hid_t type, int n, const void *buf) {
  const hsize_t dims[1] = {(hsize_t)n};
  hid_t space = n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, dims, NULL);
  if (space < 0) return -1;
  hid_t a = H5Acreate2(loc, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  herr_t st = a < 0 ? -1 : H5Awrite(a, type, buf);
  if (a >= 0) H5Aclose(a);
  H5Sclose(space);
  return st;
}

herr_t mpmc_h5_attr_write_string(hid_t loc, const char *name, const char *s) {
  hid_t t = H5Tcopy(H5T_C_S1);
  if (t < 0) return -1;
  H5Tset_size(t, strlen(s) + 1);
  H5Tset_strpad(t, H5T_STR_NULLTERM);
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t a = space < 0 ? -1 : H5Acreate2(loc, name, t, space, H5P_DEFAULT, H5P_DEFAULT);
  herr_t st = a < 0 ? -1 : H5Awrite(a, t, s);
  if (a >= 0) H5Aclose(a);
  if (space >= 0) H5Sclose(space);
  H5Tclose(t);
  return st;
}

herr_t mpmc_h5_attr_read(hid_t loc, const char *name, hid_t type, int n, void *buf) {
  if (H5Aexists(loc, name) <= 0) return -1;
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  if (a < 0) return -1;
  hid_t space = H5Aget_space(a);
  const hssize_t np = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
  herr_t st = np == n ? H5Aread(a, type, buf) : -1;
  if (space >= 0) H5Sclose(space);
  H5Aclose(a);
  return st;
}

herr_t mpmc_h5_attr_read_string(hid_t loc, const char *name, char **s) {
  *s = NULL;
  if (H5Aexists(loc, name) <= 0) return -1;
  hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
  if (a < 0) return -1;
  hid_t ft = H5Aget_type(a);
  herr_t st = -1;
  if (ft >= 0 && H5Tget_class(ft) == H5T_STRING && !H5Tis_variable_str(ft)) {
    const size_t len = H5Tget_size(ft);
    hid_t mt = H5Tcopy(H5T_C_S1);
    H5Tset_size(mt, len + 1);
    H5Tset_strpad(mt, H5T_STR_NULLTERM);
    *s = calloc(len + 1, 1);
    if (*s) st = H5Aread(a, mt, *s);
    if (st < 0) {
      free(*s);
      *s = NULL;
    }
    H5Tclose(mt);
  }
  if (ft >= 0) H5Tclose(ft);
  H5Aclose(a);
  return st;
}

herr_t mpmc_h5_dataset_write(hid_t loc, const char *name, hid_t filetype, hid_t memtype,
                             size_t rows, size_t cols, const void *buf) {
  const hsize_t dims[2] = {(hsize_t)rows, (hsize_t)cols};
  hid_t space = H5Screate_simple(cols ? 2 : 1, dims, NULL);
  if (space < 0) return -1;
  hid_t ds = H5Dcreate2(loc, name, filetype, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  herr_t st = ds < 0 ? -1 : rows ? H5Dwrite(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) : 0;
  if (ds >= 0) H5Dclose(ds);
  H5Sclose(space);
  return st;
}

herr_t mpmc_h5_rows_write(hid_t loc, const char *name, hid_t filetype, hid_t memtype,
                          long long total, size_t cols, long long offset, size_t n,
                          const void *buf, hid_t dxpl) {
  const hsize_t dims[2] = {(hsize_t)total, (hsize_t)cols};
  const hsize_t start[2] = {(hsize_t)offset, 0}, count[2] = {(hsize_t)n, (hsize_t)cols};
  hid_t space = H5Screate_simple(cols ? 2 : 1, dims, NULL);
  hid_t mem = H5Screate_simple(cols ? 2 : 1, count, NULL);
  hid_t ds = space < 0 || mem < 0 ? -1
                                  : H5Dcreate2(loc, name, filetype, space, H5P_DEFAULT, H5P_DEFAULT,
                                               H5P_DEFAULT);
  herr_t st = ds < 0 ? -1 : 0;
  if (st >= 0 && total > 0) { /* every rank takes part, one with no rows selects none */
    st = n ? H5Sselect_hyperslab(space, H5S_SELECT_SET, start, NULL, count, NULL)
           : H5Sselect_none(space);
    if (st >= 0 && !n) st = H5Sselect_none(mem);
    if (st >= 0) st = H5Dwrite(ds, memtype, mem, space, dxpl, buf);
  }
  if (ds >= 0) H5Dclose(ds);
  if (mem >= 0) H5Sclose(mem);
  if (space >= 0) H5Sclose(space);
  return st;
}

/* pat's rows of a [rows][cols] space selected, and a memory space of them */
static herr_t select_pattern(hid_t space, size_t cols, const size_t pat[4], hid_t *mem) {
  const hsize_t start[2] = {(hsize_t)pat[0], 0}, stride[2] = {(hsize_t)(pat[1] > 0 ? pat[1] : 1), 1},
                count[2] = {(hsize_t)pat[2], 1}, block[2] = {(hsize_t)pat[3], (hsize_t)cols},
                n[2] = {(hsize_t)(pat[2] * pat[3]), (hsize_t)cols};
  *mem = H5Screate_simple(2, n, NULL);
  return *mem < 0 ? -1 : H5Sselect_hyperslab(space, H5S_SELECT_SET, start, stride, count, block);
}

herr_t mpmc_h5_pattern_write(hid_t loc, const char *name, hid_t filetype, hid_t memtype, size_t rows,
                             size_t cols, const size_t pat[4], const void *buf, hid_t dxpl) {
  const hsize_t dims[2] = {(hsize_t)rows, (hsize_t)cols};
  hid_t space = H5Screate_simple(2, dims, NULL), mem = -1;
  hid_t ds = space < 0 ? -1 : H5Dcreate2(loc, name, filetype, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  herr_t st = ds < 0 ? -1 : select_pattern(space, cols, pat, &mem);
  if (st >= 0) st = H5Dwrite(ds, memtype, mem, space, dxpl, buf);
  if (mem >= 0) H5Sclose(mem);
  if (ds >= 0) H5Dclose(ds);
  if (space >= 0) H5Sclose(space);
  return st;
}

herr_t mpmc_h5_pattern_read(hid_t loc, const char *name, hid_t memtype, size_t rows, size_t cols,
                            const size_t pat[4], void *buf) {
  hid_t ds = H5Lexists(loc, name, H5P_DEFAULT) > 0 ? H5Dopen2(loc, name, H5P_DEFAULT) : -1;
  hid_t space = ds < 0 ? -1 : H5Dget_space(ds), mem = -1;
  hsize_t dims[2] = {0, 0};
  herr_t st = space >= 0 && H5Sget_simple_extent_ndims(space) == 2 ? 0 : -1;
  if (st >= 0) H5Sget_simple_extent_dims(space, dims, NULL);
  if (st >= 0 && (dims[0] != rows || dims[1] != cols)) st = -1;
  if (st >= 0) st = select_pattern(space, cols, pat, &mem);
  if (st >= 0) st = H5Dread(ds, memtype, mem, space, H5P_DEFAULT, buf);
  if (mem >= 0) H5Sclose(mem);
  if (space >= 0) H5Sclose(space);
  if (ds >= 0) H5Dclose(ds);
  return st;
}

int mpmc_fsync_path(const char *path) {
  int fd = open(path, O_RDONLY);
  if (fd < 0) return -1;
  int st = fsync(fd);
  close(fd);
  char *copy = strdup(path);
  if (!copy) return -1;
  fd = open(dirname(copy), O_RDONLY);
  free(copy);
  if (fd >= 0) { /* the rename itself is made durable by syncing the directory */
    fsync(fd);
    close(fd);
  }
  return st;
}

static char *dup_str(const char *s) {
  const size_t n = strlen(s) + 1;
  char *c = malloc(n);
  if (c) memcpy(c, s, n);
  return c;
}

/* The HDF5 file's name as the XDMF file refers to it: relative when both lie in the same
 * directory (the pair can then be moved together), else absolute. */
static char *h5_reference(const char *h5path, const char *xdmfpath) {
  char *a = dup_str(h5path), *b = dup_str(xdmfpath), *ref = NULL;
  if (a && b) {
    char *da = dup_str(dirname(a));
    char *db = dup_str(dirname(b));
    if (da && db && strcmp(da, db) == 0) {
      free(a);
      a = dup_str(h5path);
      if (a) ref = dup_str(basename(a));
    } else {
      char buf[PATH_MAX];
      if (realpath(h5path, buf)) ref = dup_str(buf);
    }
    free(da);
    free(db);
  }
  free(a);
  free(b);
  return ref;
}

/* The XDMF file, by rank 0 over MPI (it names the one HDF5 file and every point). */
static int write_xdmf(mpmc_output o) {
  int rank, size;
  mpmc_io_ranks(o->sim, &rank, &size);
  return mpmc_dd_agree(o->sim, rank == 0 ? mpmc_xdmf_write(o) : MPMC_SUCCESS);
}

/**
 * @brief Start an output series: create (truncate) h5path and write an XDMF file xdmfpath
 *        that lists the snapshots (rewritten after each one).
 * @param h5path the HDF5 file, one per run
 * @param xdmfpath the XDMF file ParaView opens
 * @param[out] out the output handle; release with mpmc_output_destroy
 */
int mpmc_output_create(mpmc_sim sim, const char *h5path, const char *xdmfpath, mpmc_output *out) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(out, ctx, MPMC_ERR_ARG, "output handle pointer out is NULL");
  MPMC_CHECK(h5path && h5path[0], ctx, MPMC_ERR_ARG, "HDF5 path h5path is NULL or empty");
  MPMC_CHECK(xdmfpath && xdmfpath[0], ctx, MPMC_ERR_ARG, "XDMF path xdmfpath is NULL or empty");
  MPMC_CHECK(strcmp(h5path, xdmfpath) != 0, ctx, MPMC_ERR_ARG,
             "h5path and xdmfpath are the same file '%s'", h5path);
  *out = NULL;
  mpmc_h5_quiet q;
  mpmc_h5_quiet_begin(&q);
  hid_t fapl = mpmc_io_fapl(sim); /* over MPI: every rank creates the one file */
  hid_t f = fapl < 0 ? -1 : H5Fcreate(h5path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  mpmc_io_plist_close(fapl);
  herr_t st = f < 0 ? -1 : 0;
  if (f >= 0) {
    if (mpmc_h5_attr_write_string(f, "format", "libmpmc-output") < 0) st = -1;
    if (mpmc_h5_attr_write(f, "dim", H5T_NATIVE_INT, 1, &sim->cfg.dim) < 0) st = -1;
    if (H5Fclose(f) < 0) st = -1;
  }
  mpmc_h5_quiet_end(&q);
  int err = st < 0 ? MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot create the HDF5 output file '%s'", h5path)
                   : MPMC_SUCCESS;
  mpmc_output o = err ? NULL : calloc(1, sizeof *o);
  if (o) {
    o->sim = sim;
    o->h5path = dup_str(h5path);
    o->xdmfpath = dup_str(xdmfpath);
    o->h5ref = h5_reference(h5path, xdmfpath);
  }
  if (!err && (!o || !o->h5path || !o->xdmfpath || !o->h5ref))
    err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot store the output paths ('%s')", h5path);
  err = mpmc_dd_agree(sim, err);
  if (!err) err = write_xdmf(o);
  if (err) {
    mpmc_output_destroy(&o);
    return err;
  }
  *out = o;
  return MPMC_SUCCESS;
}

/* Record a field of the snapshot being written (for the XDMF file). */
static int note_field(mpmc_context ctx, mpmc_snap *s, const char *name, int ncomp, int type) {
  mpmc_snap_field *f = realloc(s->fields, sizeof *f * (size_t)(s->nfield + 1));
  MPMC_CHECK(f, ctx, MPMC_ERR_MEMORY, "cannot record snapshot field '%s'", name);
  s->fields = f;
  snprintf(f[s->nfield].name, sizeof f[s->nfield].name, "%s", name);
  f[s->nfield].ncomp = ncomp;
  f[s->nfield].type = type;
  s->nfield++;
  return MPMC_SUCCESS;
}

/* A set name as an HDF5 link name: '/' and a leading '.' are not allowed there. */
static void set_dataset_name(char *dst, size_t len, const char *name) {
  snprintf(dst, len, "set_%s", name);
  for (char *c = dst; *c; ++c)
    if (*c == '/') *c = '_';
}

/* A snapshot's points as records of doubles, one row a point, which go to the rank that
 * writes them and are sorted by id there: column 0 the id, then the datasets' columns in
 * the order of `cols` (ints and set flags are exact in a double). */
enum { SNAP_SCALARS = 6 };
typedef struct {
  int w;                       /* doubles per record                                     */
  unsigned has;                /* bit k: scalar k present (on some rank); bit 30: ids    */
  int nset;
} snap_layout;

static const char *const scalar_name[SNAP_SCALARS] = {"J", "Jbar", "eps_p", "region",
                                                      "pore_pressure", "mass"};
#define SNAP_HAS_ID (1u << 30)

static const double *scalar_of(const mpmc_particles *p, int k) {
  const double *a[SNAP_SCALARS] = {p->J, p->Jbar, p->eps_p, p->region, p->pw, p->m};
  return a[k];
}

/* The records of this rank's points (ids: p->id, or the index when the points have none). */
static int snap_records(mpmc_sim sim, const snap_layout *L, double **out) {
  const mpmc_particles *p = &sim->p;
  const int n = p->n, d = sim->cfg.dim, w = L->w;
  double *rec = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1) * (size_t)w);
  MPMC_CHECK(rec, sim->ctx, MPMC_ERR_MEMORY, "output: cannot allocate a buffer for %d points", n);
  for (size_t q = 0; q < (size_t)n; ++q) {
    double *r = rec + q * (size_t)w;
    int k = 0;
    r[k++] = p->id ? p->id[q] : (double)q;
    for (int a = 0; a < 3; ++a) r[k++] = a < d ? p->x[q * (size_t)d + a] : 0.0; /* 2D: z = 0 */
    for (int a = 0; a < 3; ++a) r[k++] = a < d ? p->v[q * (size_t)d + a] : 0.0;
    for (int c = 0; c < 6; ++c) r[k++] = p->stress[6 * q + c];
    r[k++] = (p->stress[6 * q] + p->stress[6 * q + 1] + p->stress[6 * q + 2]) / 3.0;
    for (int s = 0; s < SNAP_SCALARS; ++s)
      if (L->has >> s & 1u) {
        const double *a = scalar_of(p, s);
        r[k++] = a ? a[q] : s < 2 ? 1.0 : 0.0; /* a rank without the field: J, Jbar 1 */
      }
    r[k++] = p->mat[q];
    for (int j = 0; j < L->nset; ++j) r[k + j] = 0.0;
  }
  for (int j = 0; j < L->nset; ++j) { /* set membership, one 0/1 column per set */
    const mpmc_set *set = &sim->sets->s[j];
    for (int i = 0; i < set->n; ++i)
      if (set->idx[i] >= 0 && set->idx[i] < n) rec[(size_t)set->idx[i] * (size_t)w + (size_t)(w - L->nset + j)] = 1.0;
  }
  *out = rec;
  return MPMC_SUCCESS;
}

static int by_id(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Write columns [c0, c0 + nc) of the n records as dataset `name` of ncomp columns (1:
 * [total]) in the rows from offset; type 0 double, 1 int32, 2 uint8. */
static herr_t write_cols(hid_t g, const char *name, const double *rec, int n, int w, int c0,
                         int nc, int type, long long offset, long long total, hid_t dxpl,
                         void *buf) {
  for (size_t q = 0; q < (size_t)n; ++q)
    for (int c = 0; c < nc; ++c) {
      const double v = rec[q * (size_t)w + (size_t)(c0 + c)];
      const size_t i = q * (size_t)nc + (size_t)c;
      if (type == 0)
        ((double *)buf)[i] = v;
      else if (type == 1)
        ((int *)buf)[i] = (int)v;
      else
        ((unsigned char *)buf)[i] = (unsigned char)v;
    }
  const hid_t ft[3] = {H5T_IEEE_F64LE, H5T_STD_I32LE, H5T_STD_U8LE};
  const hid_t mt[3] = {H5T_NATIVE_DOUBLE, H5T_NATIVE_INT, H5T_NATIVE_UCHAR};
  return mpmc_h5_rows_write(g, name, ft[type], mt[type], total, (size_t)(nc > 1 ? nc : 0), offset,
                            (size_t)n, buf, dxpl);
}

/* The snapshot's datasets from the records (this rank's rows from offset), each noted for
 * the XDMF file. */
static int write_snapshot(mpmc_output out, hid_t g, mpmc_snap *s, const snap_layout *L,
                          const double *rec, int n, long long offset, long long total) {
  mpmc_sim sim = out->sim;
  mpmc_context ctx = sim->ctx;
  const int w = L->w;
  void *buf = malloc(sizeof(double) * 6 * (size_t)(n > 0 ? n : 1));
  hid_t dxpl = mpmc_io_dxpl(sim);
  int err = buf && dxpl >= 0 ? MPMC_SUCCESS
                             : MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "output: cannot allocate a buffer for %d points", n);
  herr_t st = 0;
  typedef struct {
    const char *name;
    int nc, type;
  } column;
  column col[4 + SNAP_SCALARS + 1];
  int nd = 0;
  col[nd++] = (column){"position", 3, 0}; /* 2D padded with z = 0 for ParaView */
  col[nd++] = (column){"velocity", 3, 0};
  col[nd++] = (column){"stress", 6, 0};   /* Voigt xx yy zz yz xz xy */
  col[nd++] = (column){"mean_stress", 1, 0};
  for (int k = 0; k < SNAP_SCALARS; ++k)
    if (L->has >> k & 1u) col[nd++] = (column){scalar_name[k], 1, 0};
  col[nd++] = (column){"material", 1, 1};
  int c0 = 1;
  for (int k = 0; k < nd && !err; ++k) {
    st |= write_cols(g, col[k].name, rec, n, w, c0, col[k].nc, col[k].type, offset, total, dxpl, buf);
    err = note_field(ctx, s, col[k].name, col[k].nc, col[k].type);
    c0 += col[k].nc;
  }
  if (!err && (L->has & SNAP_HAS_ID)) { /* each point's id, for ParaView to follow it */
    st |= write_cols(g, "id", rec, n, w, 0, 1, 1, offset, total, dxpl, buf);
    err = note_field(ctx, s, "id", 1, 1);
  }
  for (int k = 0; k < L->nset && !err; ++k) {
    char name[272];
    set_dataset_name(name, sizeof name, sim->sets->s[k].name);
    st |= write_cols(g, name, rec, n, w, c0 + k, 1, 2, offset, total, dxpl, buf);
    err = note_field(ctx, s, name, 1, 2);
  }
  mpmc_io_plist_close(dxpl);
  free(buf);
  if (!err && st < 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write snapshot %d to '%s'", out->nsnap, out->h5path);
  return err;
}

/* The file's group of snapshot s from the records: opened, written, closed (every rank). */
static int write_group(mpmc_output out, mpmc_snap *s, const snap_layout *L, const double *rec,
                       int n, long long offset, long long total) {
  mpmc_sim sim = out->sim;
  mpmc_context ctx = sim->ctx;
  int err = MPMC_SUCCESS;
  hid_t fapl = mpmc_io_fapl(sim);
  hid_t f = fapl < 0 ? -1 : H5Fopen(out->h5path, H5F_ACC_RDWR, fapl);
  mpmc_io_plist_close(fapl);
  if (f < 0)
    return MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot open the HDF5 output file '%s' for snapshot %d",
                      out->h5path, out->nsnap);
  char gname[32];
  snprintf(gname, sizeof gname, "snapshot_%06d", out->nsnap);
  hid_t g = H5Gcreate2(f, gname, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) {
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot create group /%s in '%s'", gname, out->h5path);
  } else {
    const int64_t step = s->step;
    if (mpmc_h5_attr_write(g, "time", H5T_NATIVE_DOUBLE, 1, &s->time) < 0 ||
        mpmc_h5_attr_write(g, "step", H5T_NATIVE_INT64, 1, &step) < 0)
      err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot write time/step of /%s", gname);
    if (!err) err = write_snapshot(out, g, s, L, rec, n, offset, total);
    H5Gclose(g);
  }
  if (H5Fclose(f) < 0 && !err)
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot close the HDF5 output file '%s'", out->h5path);
  return err;
}

/**
 * @brief Append one snapshot at the current time: position and velocity (padded to 3
 *        components in 2D), stress (Voigt xx yy zz yz xz xy), mean_stress, J, and where the
 *        scene has them Jbar, eps_p; mass, material id, id (the point's index when added,
 *        once the points are sorted, mpmc_sim_set_sort_interval, and over MPI) and
 *        set_<name> membership (0/1).  The rows are the points in the order of their ids,
 *        whatever the storage order, the threads or the number of MPI ranks (over MPI the
 *        ranks write one file collectively).
 *        The group carries the attributes time and step.  The XDMF file is then rewritten.
 */
int mpmc_output_write(mpmc_output out) {
  if (!out) return MPMC_ERR_ARG;
  mpmc_sim sim = out->sim;
  mpmc_context ctx = sim->ctx;
  long long offset = 0, total = 0;
  mpmc_io_scan(sim, sim->p.n, &offset, &total);
  MPMC_CHECK(total > 0, ctx, MPMC_ERR_STATE, "output: no material points to write");
  MPMC_CHECK(total <= INT32_MAX, ctx, MPMC_ERR_UNSUPPORTED, "output: %lld points", total);
  /* allocate the fields the scene will have from its first step on, so that every snapshot
   * lists the same fields */
  int err = mpmc_sim_prepare(sim);
  if (!err && sim->cfg.sort_every > 0) { /* the ids, which the first sort would create */
    const int *ids;
    err = mpmc_sim_get_particle_ids(sim, &ids);
  }
  err = mpmc_dd_agree(sim, err);
  if (err) return err;
  const mpmc_particles *p = &sim->p;
  snap_layout L = {0, p->id ? SNAP_HAS_ID : 0u, sim->sets ? sim->sets->n : 0};
  for (int k = 0; k < SNAP_SCALARS; ++k)
    if (scalar_of(p, k)) L.has |= 1u << k;
  mpmc_io_or(sim, &L.has, 1); /* a field any rank has is written by all */
  L.w = 1 + 3 + 3 + 6 + 1 + 1 + L.nset;
  for (int k = 0; k < SNAP_SCALARS; ++k) L.w += (int)(L.has >> k & 1u);
  if (out->nsnap == out->capsnap) {
    const int cap = out->capsnap ? 2 * out->capsnap : 16;
    mpmc_snap *a = realloc(out->snaps, sizeof *a * (size_t)cap);
    MPMC_CHECK(a, ctx, MPMC_ERR_MEMORY, "cannot record %d snapshots", cap);
    out->snaps = a;
    out->capsnap = cap;
  }
  mpmc_snap *s = &out->snaps[out->nsnap];
  memset(s, 0, sizeof *s);
  s->time = sim->time;
  s->step = sim->stats.steps;
  s->n = (int)total;
  double *rec = NULL;
  int n = p->n;
  err = mpmc_dd_agree(sim, snap_records(sim, &L, &rec));
  if (!err) { /* each rank's block of ids, up to the largest over every rank */
    double nid = 0.0;
    for (int q = 0; q < n; ++q) nid = fmax(nid, rec[(size_t)q * (size_t)L.w] + 1.0);
    mpmc_dd_max(sim, &nid, 1);
    err = mpmc_io_by_id(sim, &rec, &n, L.w, (long long)nid);
  }
  if (!err) {
    qsort(rec, (size_t)n, sizeof(double) * (size_t)L.w, by_id);
    mpmc_io_scan(sim, n, &offset, &total);
    mpmc_h5_quiet q;
    mpmc_h5_quiet_begin(&q);
    err = mpmc_dd_agree(sim, write_group(out, s, &L, rec, n, offset, total));
    mpmc_h5_quiet_end(&q);
  }
  free(rec);
  if (err) {
    free(s->fields);
    return err;
  }
  out->nsnap++;
  return write_xdmf(out);
}

/** @brief Close an output series; accepts NULL and sets the handle to NULL. */
int mpmc_output_destroy(mpmc_output *out) {
  if (!out || !*out) return MPMC_SUCCESS;
  mpmc_output o = *out;
  for (int k = 0; k < o->nsnap; ++k) free(o->snaps[k].fields);
  free(o->snaps);
  free(o->h5path);
  free(o->xdmfpath);
  free(o->h5ref);
  free(o);
  *out = NULL;
  return MPMC_SUCCESS;
}
