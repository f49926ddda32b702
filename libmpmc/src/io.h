/* HDF5 helpers and the output handle (io_hdf5.c, io_xdmf.c, checkpoint.c). */
#ifndef MPMC_IO_H
#define MPMC_IO_H

#include <hdf5.h>

#include "mpmc_impl.h"

/* HDF5 prints its error stack on every failure; the library reports its own messages, so
 * the automatic printing is switched off around each HDF5 section. */
typedef struct {
  H5E_auto2_t fn;
  void *data;
} mpmc_h5_quiet;
void mpmc_h5_quiet_begin(mpmc_h5_quiet *q);
void mpmc_h5_quiet_end(const mpmc_h5_quiet *q);

/* Attributes on an object (scalars when n == 1, else 1-D arrays).  Return < 0 on failure. */
herr_t mpmc_h5_attr_write(hid_t loc, const char *name, hid_t type, int n, const void *buf);
herr_t mpmc_h5_attr_write_string(hid_t loc, const char *name, const char *s);
/* Read an attribute of exactly n elements converted to type; < 0 if absent or the wrong size. */
herr_t mpmc_h5_attr_read(hid_t loc, const char *name, hid_t type, int n, void *buf);
/* Read a string attribute into a malloc'ed buffer (*s); < 0 on failure. */
herr_t mpmc_h5_attr_read_string(hid_t loc, const char *name, char **s);
/* A dataset [rows][cols] (cols == 0: 1-D) of type memtype from buf. */
herr_t mpmc_h5_dataset_write(hid_t loc, const char *name, hid_t filetype, hid_t memtype,
                             size_t rows, size_t cols, const void *buf);
/* Rows of a [rows][cols] dataset in a regular pattern, pat = {start, stride, count, block}:
 * the rows start + stride i + j, i < count, j < block (a slab of planes of a grid's nodes, one
 * block a row of planes), in that order in buf.  Write: the dataset made (collectively over
 * MPI, every rank with its own pattern and dxpl); read: the dataset must be [rows][cols]. */
herr_t mpmc_h5_pattern_write(hid_t loc, const char *name, hid_t filetype, hid_t memtype, size_t rows,
                             size_t cols, const size_t pat[4], const void *buf, hid_t dxpl);
herr_t mpmc_h5_pattern_read(hid_t loc, const char *name, hid_t memtype, size_t rows, size_t cols,
                            const size_t pat[4], void *buf);
/* Make the file's bytes durable: fsync(path) and its directory. */
int mpmc_fsync_path(const char *path);

/* One dataset written into a snapshot, as the XDMF file names it. */
typedef struct {
  char name[272];  /* dataset name inside the snapshot group                   */
  int ncomp;       /* 1 scalar, 3 vector, 6 stress (Voigt)                      */
  int type;        /* 0 Float 8 bytes, 1 Int 4 bytes, 2 UChar 1 byte            */
} mpmc_snap_field;

typedef struct {
  double time;
  int64_t step;
  int n;                 /* points                                                */
  int nfield;
  mpmc_snap_field *fields;
} mpmc_snap;

struct mpmc_output_s {
  mpmc_sim sim;
  char *h5path;
  char *xdmfpath;
  char *h5ref;   /* the HDF5 file as the XDMF file refers to it                   */
  int nsnap, capsnap;
  mpmc_snap *snaps;
};

/* io_xdmf.c: (re)write the XDMF file of every snapshot so far, atomically. */
int mpmc_xdmf_write(mpmc_output out);

#endif
