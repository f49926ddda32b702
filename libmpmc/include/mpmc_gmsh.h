/* libmpmc: seeding material points from gmsh meshes.  A public header of its own, beside
 * mpmc.h: the function below lives in the separate library libmpmc_gmsh (mpmc::mpmc_gmsh,
 * -lmpmc_gmsh), so that programs which do not seed from gmsh never load libgmsh. */
#ifndef MPMC_GMSH_H
#define MPMC_GMSH_H

#include "mpmc.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- seeding from gmsh (seed_gmsh.c, in the separate library libmpmc_gmsh) ---------- */
typedef enum {
  MPMC_SEED_LATTICE = 0,   /* ppc points per cell per axis on the grid, kept inside the mesh */
  MPMC_SEED_QUADRATURE = 1 /* points at the elements' quadrature points (ppc = order)        */
} mpmc_seed_mode;
/* Mesh a .geo (or read a .msh) and add points for the physical group `region` (surface in
 * 2D, volume in 3D).  Points near the boundary physical groups (curves in 2D, surfaces in
 * 3D) and physical point groups become particle sets named after the groups, and node sets
 * of the grid nodes near them (for walls: mpmc_sim_add_wall_nodes).  On failure no points
 * are added (the sets of the groups added before a failing set stay). */
int mpmc_seed_gmsh(mpmc_sim sim, const char *file, const char *region, mpmc_seed_mode mode, int ppc,
                   int material, int *first, int *count);

#ifdef __cplusplus
}
#endif
#endif /* MPMC_GMSH_H */
