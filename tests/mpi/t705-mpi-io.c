/* t705: snapshots and checkpoints over MPI, one file each written collectively with the
 * parallel HDF5 (io_mpi.c), on 2 and 3 ranks (tests/mpi.cmake).  The column of t701 (quadratic
 * B-splines, F-bar, points sorted every 7 steps, a particle set of its top points) runs K
 * steps over MPI_COMM_WORLD, writes a checkpoint and a snapshot, and runs K more:
 *  - the snapshot holds every point once, in the order of the ids (row i: id i), with the
 *    ranks' positions and stresses to the bit; the XDMF file names them all;
 *  - the checkpoint, read by one process (N ranks -> 1), is the ranks' state to the bit,
 *    point by point by global id, the set included; its K steps then give the uninterrupted
 *    run over N ranks within max(1e-12, 3 x how far that run lies from the same run in one
 *    process): F-bar's nodal sums near a slab boundary are summed in another order by the
 *    ranks (t701), 1.7e-11 of the stresses after 20 steps, the band 2.3e-11 to 2.6e-11
 *    (MPMC_TEST_VERBOSE=1 prints both);
 *  - the same run on one rank (MPI_COMM_SELF, through the collective path) and in one
 *    process without MPI write the same snapshot file, dataset by dataset to the bit, and a
 *    restart from the one-rank checkpoint gives the uninterrupted run to the bit. */
#include <hdf5.h>
#include <unistd.h>

#include "mpi_test.h"

#define K 20
#define DT 1e-4
#define TOL 1e-12

#define FAIL(...)                                                                         \
  do {                                                                                    \
    fprintf(stderr, "rank %d: ", test_rank);                                              \
    fprintf(stderr, __VA_ARGS__);                                                         \
    fputc('\n', stderr);                                                                  \
    test_failed = 1;                                                                      \
  } while (0)

/* 1: the column damped by adaptive damping (its node store in the checkpoint, the last
 * step's nodal forces of the whole grid, each rank holding its slab's) and lying along x
 * (gravity along -x), so that the slabs cut the grid's rows, not its node order; else
 * standing, viscous damping 0.1 */
static int adaptive;

/* The column (t701's, 10 m x 1 m, h = 0.5, 2 x 2 points a cell) on comm, or alone
 * (MPI_COMM_NULL); set "top": its points above 9 m (each rank names its own). */
static mpmc_sim column(mpmc_context ctx, MPI_Comm comm, int *ntotal) {
  const double H = 10.0, W = 1.0, h = 0.5;
  const int u = adaptive ? 0 : 1; /* the column's axis */
  mpmc_sim sim = test_sim(ctx, comm, 2);
  const double lo[2] = {0, 0}, hi[2] = {u ? W : 11.0, u ? 11.0 : W},
               gv[2] = {u ? 0 : -9.81, u ? -9.81 : 0};
  MCALL(ctx, mpmc_sim_set_grid(sim, lo, hi, h));
  MCALL(ctx, mpmc_sim_set_basis(sim, MPMC_BASIS_BSPLINE2));
  MCALL(ctx, mpmc_sim_set_fbar(sim, 1));
  MCALL(ctx, mpmc_sim_set_gravity(sim, gv));
  if (adaptive)
    MCALL(ctx, mpmc_sim_set_adaptive_damping(sim, 0.7));
  else
    MCALL(ctx, mpmc_sim_set_damping(sim, 0.1));
  MCALL(ctx, mpmc_sim_set_flip_blend(sim, 0.95));
  MCALL(ctx, mpmc_sim_set_threads(sim, 1));
  MCALL(ctx, mpmc_sim_set_sort_interval(sim, 7));
  int mat;
  MCALL(ctx, mpmc_sim_add_material_hencky(sim, 10e6, 0.3, 2000.0, &mat));
  double *x, *vol;
  const double plo[2] = {0, 0}, phi[2] = {u ? W : H, u ? H : W};
  *ntotal = test_lattice2(plo, phi, h, 2, &x, &vol);
  MCALL(ctx, mpmc_sim_add_particles(sim, *ntotal, x, vol, mat, NULL));
  if (u) {
    test_walls2(ctx, sim);
  } else { /* the base at x = 0, slip along y */
    MCALL(ctx, mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_FIXED, NULL));
    MCALL(ctx, mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_SLIP, NULL));
    MCALL(ctx, mpmc_sim_add_wall_face(sim, 3, MPMC_WALL_SLIP, NULL));
  }
  int n, m = 0;
  double *xs;
  MCALL(ctx, mpmc_sim_get_num_particles(sim, &n));
  MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xs, NULL));
  int *top = malloc(sizeof(int) * (size_t)(n > 0 ? n : 1));
  for (int q = 0; q < n; ++q)
    if (xs[2 * q + u] > 9.0) top[m++] = q;
  MCALL(ctx, mpmc_sim_add_particle_set(sim, "top", m, top, NULL));
  free(top);
  free(x);
  free(vol);
  return sim;
}

static void steps(mpmc_context ctx, mpmc_sim sim, int k) {
  for (int s = 0; s < k; ++s) MCALL(ctx, mpmc_sim_step(sim, DT));
}

/* Runs a and b of n points the same to the bit (positions, velocities, stresses by id). */
static void same_bits(int n, const double *a, const double *b, const char *what) {
  const size_t len = sizeof(double) * (size_t)n * TEST_REC(2);
  if (memcmp(a, b, len) != 0) {
    double rel[3];
    test_compare(2, n, a, b, rel);
    FAIL("%s: not the same bits: position %.3g, velocity %.3g, stress %.3g relative", what, rel[0],
         rel[1], rel[2]);
  }
}

/* The ids of the members of set "top" of a sim in one process, as 0/1 flags by id. */
static void top_flags(mpmc_context ctx, mpmc_sim sim, int ntotal, unsigned char *flag) {
  int sid, m;
  const int *idx, *ids;
  MCALL(ctx, mpmc_sim_find_particle_set(sim, "top", &sid));
  MCALL(ctx, mpmc_sim_get_particle_set(sim, sid, NULL, &m, &idx));
  MCALL(ctx, mpmc_sim_get_particle_ids(sim, &ids));
  memset(flag, 0, (size_t)ntotal);
  for (int j = 0; j < m; ++j) flag[ids[idx[j]]] = 1;
}

static void read_ds(hid_t f, const char *path, hid_t type, void *buf) {
  hid_t ds = H5Dopen2(f, path, H5P_DEFAULT);
  if (ds < 0 || H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
    FAIL("%s: cannot read the dataset", path);
  if (ds >= 0) H5Dclose(ds);
}

/* The snapshot of rec (gathered by id, n points): rows in id order, the same bits. */
static void check_snapshot(const char *h5, const char *xdmf, int n, const double *rec) {
  hid_t f = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) {
    FAIL("%s: cannot open", h5);
    return;
  }
  double *pos = malloc(sizeof(double) * 3 * (size_t)n), *st = malloc(sizeof(double) * 6 * (size_t)n);
  int *id = malloc(sizeof(int) * (size_t)n);
  hid_t ds = H5Dopen2(f, "/snapshot_000000/position", H5P_DEFAULT);
  hid_t sp = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  H5Sget_simple_extent_dims(sp, dims, NULL);
  H5Sclose(sp);
  H5Dclose(ds);
  if (dims[0] != (hsize_t)n || dims[1] != 3)
    FAIL("%s: position is [%llu][%llu], expected [%d][3]", h5, (unsigned long long)dims[0],
         (unsigned long long)dims[1], n);
  read_ds(f, "/snapshot_000000/position", H5T_NATIVE_DOUBLE, pos);
  read_ds(f, "/snapshot_000000/stress", H5T_NATIVE_DOUBLE, st);
  read_ds(f, "/snapshot_000000/id", H5T_NATIVE_INT, id);
  H5Fclose(f);
  for (int i = 0; i < n && !test_failed; ++i) {
    const double *r = rec + (size_t)i * TEST_REC(2);
    if (id[i] != i) FAIL("%s: row %d holds id %d, expected the rows in id order", h5, i, id[i]);
    if (pos[3 * i] != r[0] || pos[3 * i + 1] != r[1] || pos[3 * i + 2] != 0.0)
      FAIL("%s: position of id %d: y %.17g, the ranks' %.17g", h5, i, pos[3 * i + 1], r[1]);
    for (int c = 0; c < 6; ++c)
      if (st[6 * i + c] != r[4 + c])
        FAIL("%s: stress %d of id %d: %.17g, the ranks' %.17g", h5, c, i, st[6 * i + c], r[4 + c]);
  }
  free(pos);
  free(st);
  free(id);
  FILE *fp = fopen(xdmf, "r");
  char text[4096] = "", want[64];
  if (fp) {
    text[fread(text, 1, sizeof text - 1, fp)] = '\0';
    fclose(fp);
  }
  snprintf(want, sizeof want, "NumberOfElements=\"%d\"", n);
  if (!strstr(text, want)) FAIL("%s: no %s", xdmf, want);
}

/* Every dataset of /snapshot_000000 of file a is in file b with the same bytes (and b has
 * no other): H5Literate's callback. */
typedef struct {
  hid_t other;
  int count;
} cmp_state;

static herr_t same_dataset(hid_t g, const char *name, const H5L_info_t *info, void *data) {
  (void)info;
  cmp_state *s = data;
  hid_t a = H5Dopen2(g, name, H5P_DEFAULT), b = H5Dopen2(s->other, name, H5P_DEFAULT);
  int same = a >= 0 && b >= 0;
  if (same) {
    hid_t ta = H5Dget_type(a), sa = H5Dget_space(a), tb = H5Dget_type(b), sb = H5Dget_space(b);
    const size_t na = H5Tget_size(ta) * (size_t)H5Sget_simple_extent_npoints(sa);
    same = H5Tequal(ta, tb) > 0 && H5Sextent_equal(sa, sb) > 0;
    char *ba = malloc(na + 1), *bb = malloc(na + 1);
    same = same && H5Dread(a, ta, H5S_ALL, H5S_ALL, H5P_DEFAULT, ba) >= 0 &&
           H5Dread(b, ta, H5S_ALL, H5S_ALL, H5P_DEFAULT, bb) >= 0 && memcmp(ba, bb, na) == 0;
    free(ba);
    free(bb);
    H5Tclose(ta), H5Tclose(tb), H5Sclose(sa), H5Sclose(sb);
  }
  if (!same) FAIL("snapshot dataset %s differs between one rank and one process", name);
  if (a >= 0) H5Dclose(a);
  if (b >= 0) H5Dclose(b);
  s->count++;
  return 0;
}

static void same_snapshots(const char *a, const char *b) {
  hid_t fa = H5Fopen(a, H5F_ACC_RDONLY, H5P_DEFAULT), fb = H5Fopen(b, H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t ga = H5Gopen2(fa, "/snapshot_000000", H5P_DEFAULT), gb = H5Gopen2(fb, "/snapshot_000000", H5P_DEFAULT);
  cmp_state s = {gb, 0};
  H5G_info_t ia, ib;
  if (ga < 0 || gb < 0 || H5Gget_info(ga, &ia) < 0 || H5Gget_info(gb, &ib) < 0 || ia.nlinks != ib.nlinks)
    FAIL("%s and %s: not the same datasets", a, b);
  else
    H5Literate(ga, H5_INDEX_NAME, H5_ITER_INC, NULL, same_dataset, &s);
  if (s.count < 10) FAIL("%s: %d datasets compared, expected 10 or more", a, s.count);
  H5Gclose(ga), H5Gclose(gb), H5Fclose(fa), H5Fclose(fb);
}

/* How far the column's 2 K steps over the ranks (end) lie from the same in one process: the
 * round-off band of the order of the sums near the slab boundaries (t701). */
static void ranks_band(mpmc_context ctx, int n, const double *end, double band[3]) {
  double *r = malloc(sizeof(double) * (size_t)n * TEST_REC(2));
  mpmc_sim sim = column(ctx, MPI_COMM_NULL, &n);
  steps(ctx, sim, 2 * K);
  test_gather(ctx, sim, 2, n, 0, r);
  mpmc_sim_destroy(&sim);
  test_compare(2, n, end, r, band);
  free(r);
}

/* N ranks (MPI_COMM_WORLD) -> one process. */
static void world_to_one(void) {
  char ckpt[64], h5[64], xdmf[64], tmp[80];
  snprintf(ckpt, sizeof ckpt, "t705-np%d-world.ckpt", test_size);
  snprintf(h5, sizeof h5, "t705-np%d-world.h5", test_size);
  snprintf(xdmf, sizeof xdmf, "t705-np%d-world.xdmf", test_size);
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  int n;
  mpmc_sim sim = column(ctx, MPI_COMM_WORLD, &n);
  double *at_k = test_rank == 0 ? malloc(sizeof(double) * (size_t)n * TEST_REC(2)) : NULL;
  double *end = test_rank == 0 ? malloc(sizeof(double) * (size_t)n * TEST_REC(2)) : NULL;
  steps(ctx, sim, K);
  test_gather(ctx, sim, 2, n, 1, at_k);
  MCALL(ctx, mpmc_sim_checkpoint_write(sim, ckpt, "t705"));
  mpmc_output out;
  MCALL(ctx, mpmc_output_create(sim, h5, xdmf, &out));
  MCALL(ctx, mpmc_output_write(out));
  MCALL(ctx, mpmc_output_destroy(&out));
  steps(ctx, sim, K);
  test_gather(ctx, sim, 2, n, 1, end);
  mpmc_sim_destroy(&sim);
  if (test_rank == 0) {
    check_snapshot(h5, xdmf, n, at_k);
    snprintf(tmp, sizeof tmp, "%s.tmp", ckpt);
    if (access(tmp, F_OK) == 0) FAIL("%s: left behind", tmp);
    char *meta = NULL;
    MCALL(ctx, mpmc_sim_checkpoint_read(ctx, ckpt, &sim, &meta));
    if (strcmp(meta, "t705") != 0) FAIL("%s: meta text '%s', expected 't705'", ckpt, meta);
    mpmc_free(meta);
    double *rec = malloc(sizeof(double) * (size_t)n * TEST_REC(2));
    test_gather(ctx, sim, 2, n, 0, rec);
    same_bits(n, rec, at_k, "N ranks -> one process: the state read");
    unsigned char *flag = malloc((size_t)n);
    double *x0;
    top_flags(ctx, sim, n, flag);
    MCALL(ctx, mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, NULL));
    const int *ids;
    MCALL(ctx, mpmc_sim_get_particle_ids(sim, &ids));
    for (int q = 0; q < n; ++q)
      if (flag[ids[q]] != (x0[2 * q + 1] > 9.0))
        FAIL("set top: id %d (y0 %g) member %d after the restart", ids[q], x0[2 * q + 1], flag[ids[q]]);
    steps(ctx, sim, K);
    test_gather(ctx, sim, 2, n, 0, rec);
    double rel[3], band[3];
    test_compare(2, n, rec, end, rel);
    ranks_band(ctx, n, end, band);
    for (int f = 0; f < 3; ++f)
      if (!(rel[f] <= fmax(TOL, 3 * band[f])))
        FAIL("%s: field %d after the restart on one process: %.3g from the run over the ranks "
             "(tolerance max(%g, 3 x %.3g))", ckpt, f, rel[f], TOL, band[f]);
    if (test_verbose())
      printf("t705: %d ranks -> one process, %d steps after the restart: max |difference| / max "
             "|value| against the run over %d ranks: position %.3g, velocity %.3g, stress %.3g "
             "(the run over the ranks against one process: %.3g, %.3g, %.3g)\n",
             test_size, K, test_size, rel[0], rel[1], rel[2], band[0], band[1], band[2]);
    mpmc_sim_destroy(&sim);
    free(rec);
    free(flag);
    remove(ckpt), remove(h5), remove(xdmf);
  }
  free(at_k);
  free(end);
  mpmc_context_destroy(&ctx);
}

/* One rank over MPI (MPI_COMM_SELF) against one process without MPI (rank 0 only). */
static void one_rank(void) {
  char ckpt[64], h5[2][64], xdmf[2][64];
  snprintf(ckpt, sizeof ckpt, "t705-np%d-self.ckpt", test_size);
  for (int k = 0; k < 2; ++k) {
    snprintf(h5[k], sizeof h5[k], "t705-np%d-%s.h5", test_size, k ? "serial" : "self");
    snprintf(xdmf[k], sizeof xdmf[k], "t705-np%d-%s.xdmf", test_size, k ? "serial" : "self");
  }
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  int n;
  double *end[2] = {NULL, NULL};
  for (int k = 0; k < 2; ++k) {
    mpmc_sim sim = column(ctx, k ? MPI_COMM_NULL : MPI_COMM_SELF, &n);
    end[k] = malloc(sizeof(double) * (size_t)n * TEST_REC(2));
    steps(ctx, sim, K);
    if (!k) MCALL(ctx, mpmc_sim_checkpoint_write(sim, ckpt, NULL));
    mpmc_output out;
    MCALL(ctx, mpmc_output_create(sim, h5[k], xdmf[k], &out));
    MCALL(ctx, mpmc_output_write(out));
    MCALL(ctx, mpmc_output_destroy(&out));
    steps(ctx, sim, K);
    test_gather(ctx, sim, 2, n, 0, end[k]);
    mpmc_sim_destroy(&sim);
  }
  same_bits(n, end[0], end[1], "one rank against one process");
  same_snapshots(h5[0], h5[1]);
  mpmc_sim sim;
  MCALL(ctx, mpmc_sim_checkpoint_read(ctx, ckpt, &sim, NULL));
  steps(ctx, sim, K);
  test_gather(ctx, sim, 2, n, 0, end[1]);
  same_bits(n, end[1], end[0], "one rank -> one process: the run after the restart");
  mpmc_sim_destroy(&sim);
  for (int k = 0; k < 2; ++k) {
    remove(h5[k]), remove(xdmf[k]);
    free(end[k]);
  }
  remove(ckpt);
  mpmc_context_destroy(&ctx);
}

/* The first n ranks of MPI_COMM_WORLD (MPI_COMM_NULL on the others). */
static MPI_Comm first(int n) {
  MPI_Comm c;
  MPI_Comm_split(MPI_COMM_WORLD, test_rank < n ? 0 : MPI_UNDEFINED, test_rank, &c);
  return c;
}

/* N ranks -> M ranks over MPI: the first nw ranks run the column K steps, write the
 * checkpoint and run K more; the first nr read it (mpmc_sim_checkpoint_read_mpi, each keeps
 * its slab's points) and run K steps: the state read is the writers' to the bit, and the run
 * the uninterrupted one to the bit when nr == nw, else within max(1e-12, 3 x the larger
 * distance of either run from one process). */
static void ranks_to_ranks(int nw, int nr) {
  char ckpt[64];
  snprintf(ckpt, sizeof ckpt, "t705-np%d-%d-to-%d%s.ckpt", test_size, nw, nr, adaptive ? "-adr" : "");
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  MPI_Comm cw = first(nw), cr = first(nr);
  int n = 0;
  double *rec[3] = {NULL, NULL, NULL}; /* at the checkpoint, uninterrupted, restarted */
  for (int k = 0; k < 3 && test_rank == 0; ++k) rec[k] = malloc(sizeof(double) * 4000 * TEST_REC(2));
  if (cw != MPI_COMM_NULL) {
    mpmc_sim sim = column(ctx, cw, &n);
    steps(ctx, sim, K);
    test_gather_on(ctx, sim, 2, n, cw, rec[0]);
    MCALL(ctx, mpmc_sim_checkpoint_write(sim, ckpt, NULL));
    steps(ctx, sim, K);
    test_gather_on(ctx, sim, 2, n, cw, rec[1]);
    mpmc_sim_destroy(&sim);
    MPI_Comm_free(&cw);
  }
  MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (cr != MPI_COMM_NULL) {
    mpmc_sim sim;
    MCALL(ctx, mpmc_sim_checkpoint_read_mpi(ctx, cr, ckpt, &sim, NULL));
    test_gather_on(ctx, sim, 2, n, cr, rec[2]);
    char what[96];
    snprintf(what, sizeof what, "%d ranks -> %d ranks%s: the state read", nw, nr,
             adaptive ? " (adaptive damping)" : "");
    if (test_rank == 0) same_bits(n, rec[2], rec[0], what);
    steps(ctx, sim, K);
    test_gather_on(ctx, sim, 2, n, cr, rec[2]);
    mpmc_sim_destroy(&sim);
    MPI_Comm_free(&cr);
  }
  if (test_rank == 0) {
    double rel[3], band[3], band2[3]; /* the larger distance of either run from one process */
    test_compare(2, n, rec[2], rec[1], rel);
    ranks_band(ctx, n, rec[1], band);
    ranks_band(ctx, n, rec[2], band2);
    for (int f = 0; f < 3; ++f) band[f] = fmax(band[f], band2[f]);
    for (int f = 0; f < 3; ++f)
      if (nw == nr ? memcmp(rec[2], rec[1], sizeof(double) * (size_t)n * TEST_REC(2)) != 0
                   : !(rel[f] <= fmax(TOL, 3 * band[f])))
        FAIL("%s: field %d after the restart on %d ranks: %.3g from the run over %d (tolerance: "
             "%s)", ckpt, f, nr, rel[f], nw, nw == nr ? "the same bits" : "3 x the band");
    if (test_verbose())
      printf("t705: %d ranks -> %d ranks%s, %d steps after the restart: position %.3g, "
             "velocity %.3g, stress %.3g (either run against one process: %.3g, %.3g, %.3g)\n",
             nw, nr, adaptive ? " (adaptive damping)" : "", K, rel[0], rel[1], rel[2], band[0],
             band[1], band[2]);
    remove(ckpt);
  }
  for (int k = 0; k < 3; ++k) free(rec[k]);
  mpmc_context_destroy(&ctx);
}

int main(int argc, char **argv) {
  test_init(&argc, &argv);
  world_to_one();
  ranks_to_ranks(test_size, test_size);     /* N -> N: the same bits */
  ranks_to_ranks(test_size - 1, test_size); /* 2 -> 3 on 3 ranks, 1 -> 2 on 2 */
  ranks_to_ranks(test_size, test_size - 1); /* 3 -> 2, 2 -> 1 */
  if (test_rank == 0) one_rank();
  adaptive = 1; /* the node store read by other slabs: N -> N the same bits, N -> M the band */
  ranks_to_ranks(test_size, test_size);
  ranks_to_ranks(test_size, test_size - 1);
  MPI_Allreduce(MPI_IN_PLACE, &test_failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return test_failed;
}
