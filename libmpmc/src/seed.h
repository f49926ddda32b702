/* Lattice seeding helpers (seed.c), shared with seed_gmsh.c: the sub-lattice of the sim's
 * grid with ppc points per cell per axis, a mark per lattice point inside a bounding box,
 * and the addition of the marked points. */
#ifndef MPMC_SEED_H
#define MPMC_SEED_H

#include "mpmc_impl.h"
#include "mpmc_gmsh.h"

typedef struct {
  int dim, ppc;
  double dx;             /* h / ppc                                              */
  double glo[3];         /* grid lo: point m sits at glo + (m + 1/2) dx           */
  long m0[3], nm[3];     /* lattice indices covered by the bounding box           */
  unsigned char *mark;   /* [nm[0]*nm[1]*nm[2]] 1 = keep                          */
} mpmc_lattice;

/* The lattice points inside [bblo, bbhi]; MPMC_ERR_OUTSIDE when the box leaves the grid. */
int mpmc_lattice_init(mpmc_sim sim, const double *bblo, const double *bbhi, int ppc,
                      const char *what, mpmc_lattice *lat);
/* Index range [m0, m1] (inclusive, local to lat) of lattice points inside [lo, hi];
 * returns 0 when empty. */
int mpmc_lattice_range(const mpmc_lattice *lat, const double *lo, const double *hi, long *m0,
                       long *m1);
static inline size_t mpmc_lattice_index(const mpmc_lattice *lat, const long *m) {
  return (size_t)m[0] + (size_t)lat->nm[0] * ((size_t)m[1] + (size_t)lat->nm[1] * (size_t)m[2]);
}
static inline void mpmc_lattice_point(const mpmc_lattice *lat, const long *m, double *x) {
  for (int a = 0; a < lat->dim; ++a) x[a] = lat->glo[a] + ((double)(lat->m0[a] + m[a]) + 0.5) * lat->dx;
}
/* Add the marked points (x fastest) with volume dx^dim; frees lat->mark. */
int mpmc_lattice_add(mpmc_sim sim, mpmc_lattice *lat, int material, const char *what, int *first,
                     int *count);
void mpmc_lattice_free(mpmc_lattice *lat);

#endif
