/* t706: rigid bodies over MPI (docs/mpi.md, docs/contact.md) against the same run in one
 * process, point by point by global id.  A plane-strain soil block (2 x 2 points per cell
 * of 0.25 m, gravity, fixed base, slip sides) in a grid cut into slabs along x:
 *  - a footing: a rigid box 1 m wide over the first cut between ranks 0 and 1 (a quarter of
 *    it beyond the cut), pushed into the surface (Hencky smooth; J2 and Hencky with
 *    friction, the footing also moving sideways, dragging the points stuck under it across
 *    the cut);
 *  - a wall: a rigid box whose face is a quarter cell beyond the first cut, pushed into the
 *    block's side (Hencky smooth; J2 with friction, the wall also moving down).
 * Each case: 300 steps at 0.3 of the stable time step.  Checks: the stable step (contact
 * included) and the barrier's range have the same bits as in one process (the points'
 * volumes, 1/64 m^2, sum exactly in any order); the body's reaction has the same bits on
 * every rank; positions, velocities, stresses, the reaction and the smallest gap equal one
 * process within 1e-12 of their magnitudes (measured: at most 2.3e-13), or 3 x the change
 * of the run in one process when gravity is one ulp smaller where that is larger; the
 * smallest gap at the same global id; in the friction cases a point near the body changed
 * rank.  The smooth footing is bounded at 1e-10 instead: without friction's damper the
 * barrier rings, and the run is ill-conditioned in one process too -- one ulp of gravity
 * changes its velocities by 4.3e-12 to 5.6e-12, the halo sums' order by 3.2e-11 to 4.3e-11
 * (2 and 3 ranks); pushed at 0.1 m/s instead of 0.02, by 2.4e-10 to 8e-9 and 1.5e-8.  Run
 * with 2 and 3 ranks. */
#include "mpi_test.h"

#define STEPS 300
#define TOL 1e-12

enum { FOOTING = 0, WALL = 1 };
enum { J2 = 0, HENCKY = 1 };

typedef struct {
  int kind, model;
  double mu, v[2];
  double tol; /* the bound (relative to each field's largest magnitude) */
} rcase;

typedef struct {
  double dt, reaction[2], gap;
  int gap_id;
  double dhat, offset[2];
} rresult;

static const double H = 0.25, DX = 0.125, D = 2.0;

/* x of the cut between ranks 0 and 1 (rank 0's last cell + 1; grid cell 0 is the first of
 * MPMC_GHOST = 3 ghost cells below x = 0), the same on every rank. */
static double first_cut(mpmc_context ctx, mpmc_sim sim) {
  int hi_cell = 0;
  if (test_rank == 0) MCALL(ctx, mpmc_sim_get_mpi_slab(sim, NULL, NULL, NULL, NULL, &hi_cell));
  MPI_Bcast(&hi_cell, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return (hi_cell - 3) * H;
}

/* The case c on comm (MPI_COMM_NULL: alone) with the cut at xc; records into out (rank 0);
 * 1 in *crossed if a point near the body changed rank (MPI; summed over the ranks). */
static void run(const rcase *c, MPI_Comm comm, double xc, int perturb, double *out, int *ntotal,
                rresult *res, int *crossed) {
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  mpmc_sim sim = test_sim(ctx, comm, 2);
  const double glo[2] = {0, 0}, ghi[2] = {6, 3};
  MCALL(ctx, mpmc_sim_set_grid(sim, glo, ghi, H));
  MCALL(ctx, mpmc_sim_set_basis(sim, MPMC_BASIS_BSPLINE2));
  const double gv[2] = {0, perturb ? nextafter(-9.81, 0.0) : -9.81}; /* perturb: one ulp less */
  MCALL(ctx, mpmc_sim_set_gravity(sim, gv));
  MCALL(ctx, mpmc_sim_set_damping(sim, 0.05));
  MCALL(ctx, mpmc_sim_set_threads(sim, 1));
  int mat;
  const double E = 10e6, nu = 0.3, rho = 2000;
  if (c->model == J2)
    MCALL(ctx, mpmc_sim_add_material_hencky_j2_su(sim, E, nu, rho, 20e3, 20e3, 0.0, &mat));
  else
    MCALL(ctx, mpmc_sim_add_material_hencky(sim, E, nu, rho, &mat));
  /* the footing's block: columns from x = 0.06, a fiftieth of a cell left of every cut; the
   * wall's: from 0.075, the column nearest the cut a tenth of a cell right of it, the
   * block's face half a spacing (the barrier's range) from the wall */
  const double x0 = c->kind == FOOTING ? 0.06 : 0.075;
  const int nx = c->kind == FOOTING ? 47 : (int)lround((xc - x0) / DX) + 1, ny = (int)(D / DX);
  const int n = nx * ny;
  double *x = malloc(sizeof(double) * 2 * (size_t)n), *vol = malloc(sizeof(double) * (size_t)n);
  for (int j = 0, q = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i, ++q) {
      x[2 * q] = x0 + (i + 0.5) * DX;
      x[2 * q + 1] = (j + 0.5) * DX;
      vol[q] = DX * DX;
    }
  MCALL(ctx, mpmc_sim_add_particles(sim, n, x, vol, mat, NULL));
  free(x);
  free(vol);
  test_walls2(ctx, sim);
  int body;
  if (c->kind == FOOTING) {
    const double lo[2] = {xc - 0.75, D}, hi[2] = {xc + 0.25, D + 0.5};
    MCALL(ctx, mpmc_sim_add_rigid_box(sim, lo, hi, c->mu, &body));
  } else {
    const double lo[2] = {x0 + nx * DX, 0.1}, hi[2] = {x0 + nx * DX + 0.5, D + 0.5};
    MCALL(ctx, mpmc_sim_add_rigid_box(sim, lo, hi, c->mu, &body));
  }
  MCALL(ctx, mpmc_sim_set_rigid_velocity(sim, body, c->v));
  MCALL(ctx, mpmc_sim_stable_dt(sim, 0.3, &res->dt));
  MCALL(ctx, mpmc_sim_get_contact_params(sim, &res->dhat, NULL));
  /* each point's rank at the start, by global id (MPI) */
  int *rank0 = NULL;
  if (comm != MPI_COMM_NULL) {
    rank0 = malloc(sizeof(int) * (size_t)n);
    int nl;
    const int *ids;
    MCALL(ctx, mpmc_sim_get_num_particles(sim, &nl));
    MCALL(ctx, mpmc_sim_get_particle_ids(sim, &ids));
    for (int q = 0; q < n; ++q) rank0[q] = -1;
    for (int q = 0; q < nl; ++q) rank0[ids[q]] = test_rank;
    MPI_Allreduce(MPI_IN_PLACE, rank0, n, MPI_INT, MPI_MAX, comm);
  }
  for (int s = 0; s < STEPS; ++s) MCALL(ctx, mpmc_sim_step(sim, res->dt));
  MCALL(ctx, mpmc_sim_get_rigid_reaction(sim, body, res->reaction));
  MCALL(ctx, mpmc_sim_get_rigid_gap(sim, body, &res->gap, &res->gap_id));
  MCALL(ctx, mpmc_sim_get_rigid_offset(sim, body, res->offset));
  *ntotal = n;
  if (comm != MPI_COMM_NULL) {
    /* points within two barrier ranges of the body that changed rank */
    int nl, k = 0;
    const int *ids;
    double *xp;
    MCALL(ctx, mpmc_sim_get_num_particles(sim, &nl));
    MCALL(ctx, mpmc_sim_get_particle_ids(sim, &ids));
    MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
    const double blo = c->kind == FOOTING ? xc - 0.75 : x0 + nx * DX, bhi = blo + (c->kind == FOOTING ? 1.0 : 0.5);
    const double ylo = c->kind == FOOTING ? D : 0.1;
    for (int q = 0; q < nl; ++q) {
      const double px = xp[2 * q] - res->offset[0], py = xp[2 * q + 1] - res->offset[1];
      const double gx = fmax(fmax(blo - px, px - bhi), 0.0), gy = fmax(ylo - py, 0.0);
      if (rank0[ids[q]] != test_rank && hypot(gx, gy) < 2 * res->dhat) ++k;
    }
    MPI_Allreduce(&k, crossed, 1, MPI_INT, MPI_SUM, comm);
    free(rank0);
  }
  test_gather(ctx, sim, 2, n, comm != MPI_COMM_NULL, out);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

/* The largest relative difference of the reactions. */
static double reaction_diff(const rresult *a, const rresult *b) {
  const double scale = fmax(fabs(b->reaction[0]), fabs(b->reaction[1]));
  return fmax(fabs(a->reaction[0] - b->reaction[0]), fabs(a->reaction[1] - b->reaction[1])) / scale;
}

static int check(const rcase *c, const char *name) {
  const int nmax = 47 * 16;
  double *par = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  double *ser = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  double *rev = test_rank == 0 ? malloc(sizeof(double) * nmax * TEST_REC(2)) : NULL;
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  mpmc_sim probe = test_sim(ctx, MPI_COMM_WORLD, 2);
  const double glo[2] = {0, 0}, ghi[2] = {6, 3};
  MCALL(ctx, mpmc_sim_set_grid(probe, glo, ghi, H));
  const double xc = first_cut(ctx, probe);
  mpmc_sim_destroy(&probe);
  mpmc_context_destroy(&ctx);
  int n = 0, crossed = 0, dummy;
  rresult rp, rs, rr;
  run(c, MPI_COMM_WORLD, xc, 0, par, &n, &rp, &crossed);
  /* the reaction has the same bits on every rank */
  double rmax[2], rmin[2];
  MPI_Allreduce(rp.reaction, rmax, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(rp.reaction, rmin, 2, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  int bad = rmax[0] != rmin[0] || rmax[1] != rmin[1];
  if (bad) fprintf(stderr, "rank %d: %s: the reaction differs between ranks\n", test_rank, name);
  if (test_rank == 0) {
    run(c, MPI_COMM_NULL, xc, 0, ser, &n, &rs, &dummy);
    run(c, MPI_COMM_NULL, xc, 1, rev, &n, &rr, &dummy);
    /* tolerance: 1e-12, or 3 x the change of the run in one process when gravity is one
     * ulp smaller, where that is larger */
    double rel[3], band[3], tol[3];
    test_compare(2, n, par, ser, rel);
    test_compare(2, n, rev, ser, band);
    int bad_fields = 0;
    for (int f = 0; f < 3; ++f) {
      tol[f] = fmax(c->tol, 3 * band[f]);
      bad_fields |= !(rel[f] <= tol[f]);
    }
    const double rdiff = reaction_diff(&rp, &rs), rband = reaction_diff(&rr, &rs);
    const double gdiff = fabs(rp.gap - rs.gap) / fabs(rs.gap), gband = fabs(rr.gap - rs.gap) / fabs(rs.gap);
    const int bad_dt = rp.dt != rs.dt || rp.dhat != rs.dhat;
    const int bad_gap = !(gdiff <= fmax(c->tol, 3 * gband)) || (rp.gap_id != rs.gap_id && rr.gap_id == rs.gap_id);
    const int bad_cross = c->mu > 0 && crossed == 0;
    const int bad_force = !(rdiff <= fmax(c->tol, 3 * rband)) || !(rs.reaction[0] != 0 || rs.reaction[1] != 0);
    bad |= bad_dt || bad_gap || bad_cross || bad_fields || bad_force;
    if (bad || test_verbose())
      printf("%-24s on %d ranks: dt %.6g (alone %.6g); reaction (%.6g, %.6g) N/m, difference "
             "%.2g (alone, g - 1 ulp: %.2g); gap %.6g at id %d (alone %.6g at %d); near the body "
             "and changed rank: %d points; position %.2g, velocity %.2g, stress %.2g (alone, "
             "g - 1 ulp: %.2g, %.2g, %.2g)%s%s%s%s%s\n",
             name, test_size, rp.dt, rs.dt, rs.reaction[0], rs.reaction[1], rdiff, rband,
             rp.gap, rp.gap_id, rs.gap, rs.gap_id, crossed, rel[0], rel[1], rel[2], band[0],
             band[1], band[2], bad_dt ? "  <- the stable step or dhat differs" : "",
             bad_gap ? "  <- the gap or its point differs" : "",
             bad_cross ? "  <- no point in contact crossed a cut" : "",
             bad_fields ? "  <- fields beyond max(bound, 3 x g - 1 ulp)" : "",
             bad_force ? "  <- reaction beyond max(bound, 3 x g - 1 ulp)" : "");
  }
  free(par);
  free(ser);
  free(rev);
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return bad;
}

int main(int argc, char **argv) {
  test_init(&argc, &argv);
  const rcase cases[] = {
      {FOOTING, HENCKY, 0.0, {0.0, -0.02}, 1e-10}, {FOOTING, J2, 0.5, {0.3, -0.1}, TOL},
      {FOOTING, HENCKY, 0.5, {0.3, -0.1}, TOL},    {WALL, HENCKY, 0.0, {-0.1, 0.0}, TOL},
      {WALL, J2, 0.5, {-0.1, -0.05}, TOL},
  };
  const char *names[] = {"footing, Hencky, smooth", "footing, J2, mu 0.5", "footing, Hencky, mu 0.5",
                         "wall, Hencky, smooth", "wall, J2, mu 0.5"};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) test_failed |= check(&cases[k], names[k]);
  MPI_Finalize();
  return test_failed;
}
