/* Plane geometry shared by the polygon seeding (seed.c) and the rigid polygons
 * (contact_barrier.c).  Internal; not installed. */
#ifndef MPMC_GEOM_H
#define MPMC_GEOM_H

/* Twice the signed area of triangle abc: > 0 when c lies left of the line a -> b. */
static inline double mpmc_orient2(const double *a, const double *b, const double *c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Do u and v lie on opposite sides (touching: or is either on the line)? */
static inline int mpmc_sides_differ(double u, double v, int touching) {
  return touching ? !((u > 0 && v > 0) || (u < 0 && v < 0)) : (u > 0 && v < 0) || (u < 0 && v > 0);
}

/* Do segments ab and cd cross: properly only (touching = 0), or also when an end point lies
 * on the other segment's line (touching = 1; collinear segments count as crossing). */
static inline int mpmc_segments_cross(const double *a, const double *b, const double *c, const double *d,
                                      int touching) {
  return mpmc_sides_differ(mpmc_orient2(c, d, a), mpmc_orient2(c, d, b), touching) &&
         mpmc_sides_differ(mpmc_orient2(a, b, c), mpmc_orient2(a, b, d), touching);
}

#endif
