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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io.h"
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
  MPMC_CHECK(mpmc_dd_ranks(sim) == 1, ctx, MPMC_ERR_UNSUPPORTED,
             "snapshots of a run over %d MPI ranks are not supported yet (issue 47: one file "
             "written collectively with parallel HDF5)", mpmc_dd_ranks(sim));
  MPMC_CHECK(h5path && h5path[0], ctx, MPMC_ERR_ARG, "HDF5 path h5path is NULL or empty");
  MPMC_CHECK(xdmfpath && xdmfpath[0], ctx, MPMC_ERR_ARG, "XDMF path xdmfpath is NULL or empty");
  MPMC_CHECK(strcmp(h5path, xdmfpath) != 0, ctx, MPMC_ERR_ARG,
             "h5path and xdmfpath are the same file '%s'", h5path);
  *out = NULL;
  mpmc_h5_quiet q;
  mpmc_h5_quiet_begin(&q);
  hid_t f = H5Fcreate(h5path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  herr_t st = f < 0 ? -1 : 0;
  if (f >= 0) {
    if (mpmc_h5_attr_write_string(f, "format", "libmpmc-output") < 0) st = -1;
    if (mpmc_h5_attr_write(f, "dim", H5T_NATIVE_INT, 1, &sim->dim) < 0) st = -1;
    if (H5Fclose(f) < 0) st = -1;
  }
  mpmc_h5_quiet_end(&q);
  MPMC_CHECK(st >= 0, ctx, MPMC_ERR_IO, "cannot create the HDF5 output file '%s'", h5path);
  mpmc_output o = calloc(1, sizeof *o);
  MPMC_CHECK(o, ctx, MPMC_ERR_MEMORY, "cannot allocate an output handle");
  o->sim = sim;
  o->h5path = dup_str(h5path);
  o->xdmfpath = dup_str(xdmfpath);
  o->h5ref = h5_reference(h5path, xdmfpath);
  if (!o->h5path || !o->xdmfpath || !o->h5ref) {
    mpmc_output_destroy(&o);
    return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "cannot store the output paths ('%s')", h5path);
  }
  const int err = mpmc_xdmf_write(o);
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

/* Write [n][ncomp] doubles, padding dim-component vectors to 3 so that ParaView shows points
 * and vectors in 2D (z = 0). */
static herr_t write_padded(hid_t g, const char *name, const double *src, int n, int d, int ncomp,
                           double *buf) {
  for (size_t q = 0; q < (size_t)n; ++q)
    for (int a = 0; a < ncomp; ++a) buf[q * (size_t)ncomp + a] = a < d ? src[q * (size_t)d + a] : 0.0;
  return mpmc_h5_dataset_write(g, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)n,
                               (size_t)(ncomp > 1 ? ncomp : 0), buf);
}

/* A set name as an HDF5 link name: '/' and a leading '.' are not allowed there. */
static void set_dataset_name(char *dst, size_t len, const char *name) {
  snprintf(dst, len, "set_%s", name);
  for (char *c = dst; *c; ++c)
    if (*c == '/') *c = '_';
}

static int write_snapshot(mpmc_output out, hid_t g, mpmc_snap *s, double *buf,
                          unsigned char *mark) {
  mpmc_sim sim = out->sim;
  mpmc_context ctx = sim->ctx;
  const mpmc_particles *p = &sim->p;
  const int n = p->n, d = sim->dim;
  herr_t st = 0;
  /* vectors */
  st |= write_padded(g, "position", p->x, n, d, 3, buf);
  MPMC_CALL(note_field(ctx, s, "position", 3, 0));
  st |= write_padded(g, "velocity", p->v, n, d, 3, buf);
  MPMC_CALL(note_field(ctx, s, "velocity", 3, 0));
  /* stress in Voigt order xx yy zz yz xz xy, and the mean stress tr(sigma)/3 */
  st |= mpmc_h5_dataset_write(g, "stress", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)n, 6,
                              p->stress);
  MPMC_CALL(note_field(ctx, s, "stress", 6, 0));
  for (size_t q = 0; q < (size_t)n; ++q)
    buf[q] = (p->stress[6 * q] + p->stress[6 * q + 1] + p->stress[6 * q + 2]) / 3.0;
  st |= mpmc_h5_dataset_write(g, "mean_stress", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)n, 0,
                              buf);
  MPMC_CALL(note_field(ctx, s, "mean_stress", 1, 0));
  /* scalars the scene has */
  const struct {
    const char *name;
    const double *a;
  } scal[] = {{"J", p->J}, {"Jbar", p->Jbar}, {"eps_p", p->eps_p}, {"region", p->region},
                 {"pore_pressure", p->pw}, {"mass", p->m}};
  for (size_t k = 0; k < sizeof scal / sizeof scal[0]; ++k) {
    if (!scal[k].a) continue;
    st |= mpmc_h5_dataset_write(g, scal[k].name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, (size_t)n, 0,
                                scal[k].a);
    MPMC_CALL(note_field(ctx, s, scal[k].name, 1, 0));
  }
  st |= mpmc_h5_dataset_write(g, "material", H5T_STD_I32LE, H5T_NATIVE_INT, (size_t)n, 0, p->mat);
  MPMC_CALL(note_field(ctx, s, "material", 1, 1));
  if (p->id) { /* once the points are sorted by cell (sort.c), each point's id to follow it */
    st |= mpmc_h5_dataset_write(g, "id", H5T_STD_I32LE, H5T_NATIVE_INT, (size_t)n, 0, p->id);
    MPMC_CALL(note_field(ctx, s, "id", 1, 1));
  }
  /* set membership, one 0/1 array per set */
  const int nset = sim->sets ? sim->sets->n : 0;
  for (int k = 0; k < nset; ++k) {
    const mpmc_set *set = &sim->sets->s[k];
    memset(mark, 0, (size_t)n);
    for (int i = 0; i < set->n; ++i)
      if (set->idx[i] < n) mark[set->idx[i]] = 1;
    char name[272];
    set_dataset_name(name, sizeof name, set->name);
    st |= mpmc_h5_dataset_write(g, name, H5T_STD_U8LE, H5T_NATIVE_UCHAR, (size_t)n, 0, mark);
    MPMC_CALL(note_field(ctx, s, name, 1, 2));
  }
  MPMC_CHECK(st >= 0, ctx, MPMC_ERR_IO, "cannot write snapshot %d to '%s'", out->nsnap,
             out->h5path);
  return MPMC_SUCCESS;
}

/**
 * @brief Append one snapshot at the current time: position and velocity (padded to 3
 *        components in 2D), stress (Voigt xx yy zz yz xz xy), mean_stress, J, and where the
 *        scene has them Jbar, eps_p; mass, material id, id (the point's index when added,
 *        once the points are sorted: mpmc_sim_set_sort_interval) and set_<name> membership
 *        (0/1).
 *        The group carries the attributes time and step.  The XDMF file is then rewritten.
 */
int mpmc_output_write(mpmc_output out) {
  if (!out) return MPMC_ERR_ARG;
  mpmc_sim sim = out->sim;
  mpmc_context ctx = sim->ctx;
  const int n = sim->p.n;
  MPMC_CHECK(n > 0, ctx, MPMC_ERR_STATE, "output: no material points to write");
  /* allocate the fields the scene will have from its first step on, so that every snapshot
   * lists the same fields */
  MPMC_CALL(mpmc_sim_prepare(sim));
  if (sim->sort_every > 0) { /* the ids, which the first sort would create */
    const int *ids;
    MPMC_CALL(mpmc_sim_get_particle_ids(sim, &ids));
  }
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
  s->n = n;
  double *buf = malloc(sizeof(double) * 3 * (size_t)n);
  unsigned char *mark = malloc((size_t)n);
  if (!buf || !mark) {
    free(buf);
    free(mark);
    return MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "output: cannot allocate a buffer for %d points", n);
  }
  mpmc_h5_quiet q;
  mpmc_h5_quiet_begin(&q);
  int err = MPMC_SUCCESS;
  hid_t f = H5Fopen(out->h5path, H5F_ACC_RDWR, H5P_DEFAULT);
  if (f < 0) {
    err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot open the HDF5 output file '%s' for snapshot %d",
                     out->h5path, out->nsnap);
  } else {
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
      if (!err) err = write_snapshot(out, g, s, buf, mark);
      H5Gclose(g);
    }
    if (H5Fclose(f) < 0 && !err)
      err = MPMC_ERROR(ctx, MPMC_ERR_IO, "cannot close the HDF5 output file '%s'", out->h5path);
  }
  mpmc_h5_quiet_end(&q);
  free(buf);
  free(mark);
  if (err) {
    free(s->fields);
    return err;
  }
  out->nsnap++;
  return mpmc_xdmf_write(out);
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
