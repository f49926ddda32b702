/* Named particle and node sets (sets.c): private structure, shared with checkpoint.c,
 * io_hdf5.c and boundary.c. */
#ifndef MPMC_SETS_H
#define MPMC_SETS_H

#include "mpmc_impl.h"

typedef struct {
  char *name;
  int n;
  int *idx; /* [n] point indices, or [n][dim] node coordinates, as given */
} mpmc_set;

struct mpmc_sets_s {
  int n, cap;
  mpmc_set *s;
};

#endif
