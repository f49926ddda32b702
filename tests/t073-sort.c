/* Sorting the points by cell (issue 6, sort.c).  A run that sorts its points every few steps
 * gives the run that never sorts, point by point through the ids, to round-off (the nodes sum
 * in another order): a column of Hencky-J2 soil collapsing under gravity with its points
 * stored in random order, 2D and 3D, every basis, F-bar off / Algorithm 1, with a particle
 * set, external forces and a rigid body with friction (the anchors move with the points);
 * and a user material whose state is each point's own history.  Also: the sort really puts
 * the points in cell order, field pointers stay valid, the ids are the indices points were
 * added with (new points too), a checkpoint carries ids and the sort schedule (the restarted
 * run is the same bits as the straight one), a change of the slab axis brings the next sort
 * forward (restarts alike), an error names a moved point by index and id, and bad input is
 * refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "mpmc_impl.h"
#include "test_util.h"

#define NF 6 /* fields compared: x, v, stress, J, eps_p, the user state */

typedef struct {
  int n, dim;
  double *f[NF];
  int nc[NF];
  int *set; /* the set's points, as ids */
  int nset;
} result;

/* user material: Hencky-like response is not needed, only a history per point */
static int user_history(void *data, const double *dF, double dt, double *state, double *stress) {
  (void)data;
  (void)dt;
  const double J = dF[0] * (dF[4] * dF[8] - dF[5] * dF[7]) - dF[1] * (dF[3] * dF[8] - dF[5] * dF[6]) +
                   dF[2] * (dF[3] * dF[7] - dF[4] * dF[6]);
  state[0] += log(J);
  state[1] += dF[1] - dF[3];
  const double K = 2e5;
  for (int k = 0; k < 3; ++k) stress[k] = K * state[0];
  stress[5] = 1e4 * state[1];
  return 0;
}

/* shuffle every per-point field of the freshly seeded points (only x, x0 and vol0 differ) */
static void shuffle(mpmc_sim sim, unsigned seed) {
  mpmc_particles *p = &sim->p;
  const int d = p->dim;
  srand(seed);
  for (int q = p->n - 1; q > 0; --q) {
    const int r = rand() % (q + 1);
    for (int a = 0; a < d; ++a) {
      double t = p->x[q * d + a];
      p->x[q * d + a] = p->x[r * d + a], p->x[r * d + a] = t;
      t = p->x0[q * d + a];
      p->x0[q * d + a] = p->x0[r * d + a], p->x0[r * d + a] = t;
    }
    double t = p->vol0[q];
    p->vol0[q] = p->vol0[r], p->vol0[r] = t;
    t = p->m[q];
    p->m[q] = p->m[r], p->m[r] = t;
    if (p->lp) t = p->lp[q], p->lp[q] = p->lp[r], p->lp[r] = t;
  }
}

static mpmc_sim build(mpmc_context ctx, int dim, int basis, int fbar, int user, int sort_every) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, dim, &sim));
  const double h = dim == 2 ? 0.05 : 0.1;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, h));
  TCALL(mpmc_sim_set_basis(sim, basis));
  TCALL(mpmc_sim_set_fbar(sim, fbar));
  TCALL(mpmc_sim_set_threads(sim, 1));
  TCALL(mpmc_sim_set_sort_interval(sim, sort_every));
  TCALL(mpmc_sim_set_flip_blend(sim, 0.95));
  int mat, n;
  if (user)
    TCALL(mpmc_sim_add_material_user(sim, user_history, NULL, 2, 1500.0, 30.0, &mat));
  else
    TCALL(mpmc_sim_add_material_hencky_j2(sim, 1e6, 0.45, 2000, 8e3, 2e3, 50, &mat));
  const int up = dim - 1;
  double blo[3] = {0, 0, 0}, bhi[3] = {0.6, 0.6, 0.6};
  blo[up] = 0.2, bhi[up] = 0.8; /* above a rigid plate */
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, &n));
  shuffle(sim, 7u + (unsigned)dim);
  for (int f = 0; f < 2 * dim; ++f)
    if (f != 2 * up + 1) TCALL(mpmc_sim_add_wall_face(sim, f, f == 2 * up ? MPMC_WALL_FIXED : MPMC_WALL_SLIP, NULL));
  double plo[3] = {0, 0, 0}, phi[3] = {2, 1, 1};
  plo[up] = 0.0, phi[up] = 0.2;
  int plate;
  TCALL(mpmc_sim_add_rigid_box(sim, plo, phi, 0.4, &plate));
  double pv[3] = {0.3, 0.1, 0};
  pv[up] = 0.0;
  TCALL(mpmc_sim_set_rigid_velocity(sim, plate, pv));
  double g[3] = {0, 0, 0};
  g[up] = -9.81;
  TCALL(mpmc_sim_set_gravity(sim, g));
  /* thrown down onto the plate and sideways */
  double *v;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
  for (int q = 0; q < n; ++q) v[q * dim] = 0.2, v[q * dim + up] = -0.5;
  /* a set (points with x0 in the upper left corner) and a pull on it */
  double *x0;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, NULL));
  int *idx = malloc(sizeof(int) * (size_t)n), ns = 0;
  for (int q = 0; q < n; ++q)
    if (x0[q * dim] < 0.2 && x0[q * dim + up] > 0.6) idx[ns++] = q;
  if (ns < 4) fail_msg("set too small: %d", ns);
  TCALL(mpmc_sim_add_particle_set(sim, "corner", ns, idx, NULL));
  double *f = calloc((size_t)n * dim, sizeof *f);
  for (int j = 0; j < ns; ++j) f[idx[j] * dim] = 2.0;
  TCALL(mpmc_sim_set_particle_forces(sim, 0, n, f));
  free(f);
  free(idx);
  return sim;
}

/* the state by id */
static void collect(mpmc_sim sim, result *r) {
  const int *ids;
  TCALL(mpmc_sim_get_particle_ids(sim, &ids));
  TCALL(mpmc_sim_get_num_particles(sim, &r->n));
  TCALL(mpmc_sim_get_dim(sim, &r->dim));
  const int fields[NF - 1] = {MPMC_FIELD_POSITION, MPMC_FIELD_VELOCITY, MPMC_FIELD_STRESS,
                              MPMC_FIELD_J, MPMC_FIELD_EPS_P};
  for (int k = 0; k < NF; ++k) {
    double *a = NULL;
    int nc = 0;
    if (k < NF - 1) {
      if (mpmc_sim_get_field(sim, fields[k], &a, &nc)) {
        mpmc_context_clear_error(test_ctx);
        a = NULL;
      }
    } else if (sim->p.ustate) {
      a = sim->p.ustate;
      nc = sim->p.nustate;
    }
    r->nc[k] = a ? nc : 0;
    r->f[k] = a ? malloc(sizeof(double) * (size_t)r->n * nc) : NULL;
    for (int q = 0; q < r->n && a; ++q)
      memcpy(r->f[k] + (size_t)ids[q] * nc, a + (size_t)q * nc, sizeof(double) * nc);
  }
  int sid, ns;
  const int *idx;
  const char *name;
  TCALL(mpmc_sim_find_particle_set(sim, "corner", &sid));
  TCALL(mpmc_sim_get_particle_set(sim, sid, &name, &ns, &idx));
  r->nset = ns;
  r->set = malloc(sizeof(int) * (size_t)ns);
  for (int j = 0; j < ns; ++j) r->set[j] = ids[idx[j]];
}

static void release(result *r) {
  for (int k = 0; k < NF; ++k) free(r->f[k]);
  free(r->set);
}

static void compare(const result *a, const result *b, const char *what) {
  static const char *const name[NF] = {"x", "v", "stress", "J", "eps_p", "user state"};
  if (a->n != b->n) fail_msg("%s: %d against %d points", what, a->n, b->n);
  for (int k = 0; k < NF; ++k) {
    if (a->nc[k] != b->nc[k]) fail_msg("%s: field %s present in one run only", what, name[k]);
    /* 1e-7 of the field's largest value: most cases agree to 1e-12, but the 3D linear one
     * (a third of the time step, points crossing into empty cells, yield reached) amplifies
     * the nodes' summation order to 1e-9 .. 1e-8 (2.1e-9 of eps_p before the slabs went by
     * plane, 1.0e-8 after); a sort that leaves a field behind errs by far more (be not
     * permuted: x off by 1.5e-4 of its largest value, first case) */
    double scale = 0;
    for (size_t i = 0; i < (size_t)a->n * a->nc[k]; ++i) scale = fmax(scale, fabs(a->f[k][i]));
    for (size_t i = 0; i < (size_t)a->n * a->nc[k]; ++i)
      if (!(fabs(a->f[k][i] - b->f[k][i]) <= 1e-7 * scale + 1e-300))
        fail_msg("%s: %s of point id %zu component %zu: %.17g sorted, %.17g unsorted (scale %g)",
                 what, name[k], i / a->nc[k], i % a->nc[k], a->f[k][i], b->f[k][i], scale);
  }
  if (a->nset != b->nset) fail_msg("%s: set of %d against %d points", what, a->nset, b->nset);
  for (int j = 0; j < a->nset; ++j)
    if (a->set[j] != b->set[j]) fail_msg("%s: set entry %d is id %d, unsorted %d", what, j, a->set[j], b->set[j]);
}

/* points out of cell order: the key runs over the slab axis (mpmc_slab_axis's rule) first,
 * then the other axes from the outermost in */
static long out_of_order(mpmc_sim sim) {
  const mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int q = 0; q < p->n; ++q)
    for (int a = 0; a < d; ++a) {
      const double c = floor((p->x[q * d + a] - g->origin[a]) * g->inv_h);
      clo[a] = fmin(clo[a], c), chi[a] = fmax(chi[a], c);
    }
  int ax = d - 1; /* the outermost axis when it spans MPMC_SLAB_PLANES planes, else the longest */
  if (chi[d - 1] - clo[d - 1] + 1 < MPMC_SLAB_PLANES)
    for (int a = d - 2; a >= 0; --a)
      if (chi[a] - clo[a] > chi[ax] - clo[ax]) ax = a;
  long bad = 0;
  double prev = -1;
  for (int q = 0; q < p->n; ++q) {
    double key = floor((p->x[q * d + ax] - g->origin[ax]) * g->inv_h);
    for (int a = d - 1; a >= 0; --a)
      if (a != ax) key = key * 1e4 + floor((p->x[q * d + a] - g->origin[a]) * g->inv_h);
    bad += key < prev;
    prev = key;
  }
  return bad;
}

static void run_pair(int dim, int basis, int fbar, int user, int steps) {
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim s0 = build(ctx, dim, basis, fbar, user, 0), s1 = build(ctx, dim, basis, fbar, user, 3);
  double dt;
  TCALL(mpmc_sim_stable_dt(s0, 0.3, &dt));
  if (basis == MPMC_BASIS_LINEAR) dt /= 3, steps *= 3; /* a point entering an empty cell */
  double *x_before;
  TCALL(mpmc_sim_get_field(s1, MPMC_FIELD_POSITION, &x_before, NULL));
  if (out_of_order(s1) == 0) fail_msg("the shuffled points are already in cell order");
  for (int s = 0; s < steps; ++s) {
    TCALL(mpmc_sim_step(s0, dt));
    TCALL(mpmc_sim_step(s1, dt));
  }
  double *x_after;
  TCALL(mpmc_sim_get_field(s1, MPMC_FIELD_POSITION, &x_after, NULL));
  if (x_after != x_before) fail_msg("the sort moved the position array (pointer changed)");
  /* the last sort was at step steps - steps % 3 (or steps - 3): sort once more and check */
  TCALL(mpmc_sim_sort_particles(s1));
  const long bad = out_of_order(s1);
  if (bad) fail_msg("dim %d: %ld points out of cell order after a sort", dim, bad);
  int nfix;
  TCALL(mpmc_sim_get_num_particles(s1, &nfix));
  result a, b;
  collect(s1, &a);
  collect(s0, &b);
  char what[96];
  snprintf(what, sizeof what, "dim %d basis %d fbar %d%s", dim, basis, fbar, user ? " user" : "");
  compare(&a, &b, what);
  /* the comparison is worth something only if the points crossed cells and hit the plate */
  double moved = 0, *x0;
  TCALL(mpmc_sim_get_field(s1, MPMC_FIELD_X0, &x0, NULL));
  for (size_t i = 0; i < (size_t)nfix * dim; ++i) moved = fmax(moved, fabs(x_after[i] - x0[i]));
  if (!(moved > 0.25 * s1->grid.h)) fail_msg("%s: the points hardly moved (%g)", what, moved);
  double react[3] = {0, 0, 0};
  TCALL(mpmc_sim_get_rigid_reaction(s1, 0, react));
  if (!(fabs(react[dim - 1]) > 0) || !(fabs(react[0]) > 0))
    fail_msg("%s: no contact with the plate (reaction %g, %g)", what, react[0], react[dim - 1]);
  release(&a);
  release(&b);
  mpmc_sim_destroy(&s0);
  mpmc_sim_destroy(&s1);
  mpmc_context_destroy(&ctx);
}

static void test_sorted_equals_unsorted(void **state) {
  (void)state;
  const int bases[4] = {MPMC_BASIS_LINEAR, MPMC_BASIS_UGIMP, MPMC_BASIS_BSPLINE2, MPMC_BASIS_BSPLINE3};
  for (int dim = 2; dim <= 3; ++dim)
    for (int b = 0; b < 4; ++b) run_pair(dim, bases[b], b % 2 ? MPMC_FBAR_PAPER : MPMC_FBAR_OFF, 0, dim == 2 ? 100 : 120);
  run_pair(2, MPMC_BASIS_BSPLINE2, MPMC_FBAR_PAPER, 1, 100);
  run_pair(3, MPMC_BASIS_UGIMP, MPMC_FBAR_STABLE, 1, 120);
}

/* ids: the index at insertion; points added after a sort get theirs */
static void test_ids(void **state) {
  (void)state;
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim sim = build(ctx, 2, MPMC_BASIS_BSPLINE2, MPMC_FBAR_OFF, 0, 0);
  int n, nc;
  TCALL(mpmc_sim_get_num_particles(sim, &n));
  const int *ids;
  TCALL(mpmc_sim_get_particle_ids(sim, &ids));
  for (int q = 0; q < n; ++q)
    if (ids[q] != q) fail_msg("before any sort ids[%d] = %d", q, ids[q]);
  double *x0, copy[2 * 4096];
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, &nc));
  if (2 * n > 4096 * 2) fail_msg("scene too big for the test's copy");
  memcpy(copy, x0, sizeof(double) * 2 * (size_t)n);
  TCALL(mpmc_sim_sort_particles(sim));
  TCALL(mpmc_sim_get_particle_ids(sim, &ids));
  int moved = 0;
  unsigned char seen[4096] = {0};
  for (int q = 0; q < n; ++q) {
    if (ids[q] < 0 || ids[q] >= n || seen[ids[q]]) fail_msg("ids not a permutation at %d: %d", q, ids[q]);
    seen[ids[q]] = 1;
    moved += ids[q] != q;
    for (int a = 0; a < 2; ++a)
      if (x0[q * 2 + a] != copy[ids[q] * 2 + a]) fail_msg("point %d (id %d): x0 did not move with it", q, ids[q]);
  }
  if (moved < n / 2) fail_msg("the sort moved only %d of %d shuffled points", moved, n);
  const double xn[4] = {1.5, 0.5, 1.6, 0.5}, vn[2] = {1e-4, 1e-4};
  int first;
  TCALL(mpmc_sim_add_particles(sim, 2, xn, vn, 0, &first));
  TCALL(mpmc_sim_get_particle_ids(sim, &ids));
  if (first != n || ids[n] != n || ids[n + 1] != n + 1)
    fail_msg("new points: first %d, ids %d %d (expected %d, %d)", first, ids[n], ids[n + 1], n, n + 1);
  TCALL(mpmc_sim_sort_particles(sim));
  TCALL(mpmc_sim_get_particle_ids(sim, &ids));
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_X0, &x0, &nc));
  for (int q = 0; q < n + 2; ++q)
    if (ids[q] >= n && x0[2 * q] != xn[2 * (ids[q] - n)]) fail_msg("new point id %d lost its position", ids[q]);
  /* an error names a moved point by index and id: throw the points out of the grid */
  {
    double *v;
    TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL));
    for (int q = 0; q < n + 2; ++q) v[2 * q] = 1e4;
    TCALL(mpmc_sim_set_force_dt(sim, 1));
    const int e = mpmc_sim_step(sim, 1e-3);
    const char *msg = mpmc_context_last_error(ctx), *at = strstr(msg, ": point ");
    int qi = -1, qid = -1;
    if (e == MPMC_SUCCESS || !at || sscanf(at, ": point %d (id %d)", &qi, &qid) != 2)
      fail_msg("a point thrown out: code %d, '%s' (expected 'point N (id M)')", e, msg);
    TCALL(mpmc_sim_get_particle_ids(sim, &ids));
    if (qi < 0 || qi >= n + 2 || ids[qi] != qid) fail_msg("message names point %d as id %d, its id is %d", qi, qid, qi >= 0 && qi < n + 2 ? ids[qi] : -1);
    mpmc_context_clear_error(ctx);
  }
  /* bad input */
  if (mpmc_sim_set_sort_interval(sim, -1) != MPMC_ERR_ARG ||
      !strstr(mpmc_context_last_error(ctx), "sort interval"))
    fail_msg("a negative sort interval: '%s'", mpmc_context_last_error(ctx));
  int every = -5;
  TCALL(mpmc_sim_get_sort_interval(sim, &every));
  if (every != 0) fail_msg("interval %d after a refused change", every);
  if (mpmc_sim_get_particle_ids(sim, NULL) != MPMC_ERR_ARG) fail_msg("NULL ids accepted");
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
}

/* a's state through a checkpoint file (path, removed after) into a new sim */
static mpmc_sim restarted(mpmc_context ctx, mpmc_sim a, const char *path) {
  TCALL(mpmc_sim_checkpoint_write(a, path, NULL));
  mpmc_sim b;
  TCALL(mpmc_sim_checkpoint_read(ctx, path, &b, NULL));
  unlink(path);
  return b;
}

/* the restarted run b is the straight run a, bit for bit: ids, positions, velocities, stresses */
static void expect_same_run(mpmc_sim a, mpmc_sim b) {
  const int *ia, *ib;
  TCALL(mpmc_sim_get_particle_ids(a, &ia));
  TCALL(mpmc_sim_get_particle_ids(b, &ib));
  const size_t n = (size_t)a->p.n, d = (size_t)a->cfg.dim;
  if (b->p.n != a->p.n || memcmp(ia, ib, sizeof(int) * n)) fail_msg("ids differ after the restart");
  if (memcmp(a->p.x, b->p.x, sizeof(double) * d * n) || memcmp(a->p.v, b->p.v, sizeof(double) * d * n) ||
      memcmp(a->p.stress, b->p.stress, sizeof(double) * 6 * n))
    fail_msg("the restarted run differs from the straight one");
}

/* a checkpoint in the middle of a sorting run restarts to the same bits */
static void test_checkpoint(void **state) {
  (void)state;
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  char path[64];
  snprintf(path, sizeof path, "t073-%ld.h5", (long)getpid());
  mpmc_sim a = build(ctx, 2, MPMC_BASIS_UGIMP, MPMC_FBAR_PAPER, 0, 4);
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.3, &dt));
  for (int s = 0; s < 10; ++s) TCALL(mpmc_sim_step(a, dt)); /* sorted at 0, 4, 8 */
  mpmc_sim b = restarted(ctx, a, path);
  int every;
  TCALL(mpmc_sim_get_sort_interval(b, &every));
  if (every != 4) fail_msg("restored sort interval %d", every);
  for (int s = 0; s < 10; ++s) { /* both sort at 12 and 16 */
    TCALL(mpmc_sim_step(a, dt));
    TCALL(mpmc_sim_step(b, dt));
  }
  expect_same_run(a, b);
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
  mpmc_context_destroy(&ctx);
}

/* A tall 3D block (30 cell planes along z: slab axis z) squashed to 3 planes: the slab build
 * then slabs along y (the longest extent left, ties to the outermost), and the run sorts for
 * that within a tenth of its interval instead of waiting for the interval; a checkpoint taken
 * between the axis change and that sort restarts to the same bits (it carries both axes). */
static mpmc_sim tall_block(mpmc_context ctx) {
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, 3, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 4};
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.1));
  TCALL(mpmc_sim_set_threads(sim, 1));
  TCALL(mpmc_sim_set_sort_interval(sim, 50));
  int mat, n;
  TCALL(mpmc_sim_add_material_hencky(sim, 1e5, 0.3, 1000, &mat));
  const double blo[3] = {0.2, 0.2, 0.2}, bhi[3] = {0.6, 0.6, 3.2};
  TCALL(mpmc_sim_seed_box(sim, blo, bhi, 2, mat, NULL, &n));
  shuffle(sim, 11u);
  return sim;
}

/* cell coordinate of point q along axis a */
static int cell_of(mpmc_const_sim sim, int q, int a) { return (int)(sim->p.x[(size_t)q * 3 + a] * 10.0); }

static void test_axis_change(void **state) {
  (void)state;
  mpmc_context ctx;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  char path[64];
  snprintf(path, sizeof path, "t073-axis-%ld.h5", (long)getpid());
  mpmc_sim a = tall_block(ctx);
  const int n = a->p.n;
  double dt;
  TCALL(mpmc_sim_stable_dt(a, 0.3, &dt));
  TCALL(mpmc_sim_step(a, dt)); /* sorts first, with z outermost */
  for (int q = 1; q < n; ++q)
    if (cell_of(a, q, 2) < cell_of(a, q - 1, 2)) fail_msg("after the first sort: z cells not in order at %d", q);
  double *x;
  TCALL(mpmc_sim_get_field(a, MPMC_FIELD_POSITION, &x, NULL));
  for (int q = 0; q < n; ++q) x[q * 3 + 2] = 0.2 + 0.1 * (x[q * 3 + 2] - 0.2); /* 3 planes */
  TCALL(mpmc_sim_restore_field(a, MPMC_FIELD_POSITION, &x));
  TCALL(mpmc_sim_step(a, dt)); /* its slab build picks y */
  mpmc_sim b = restarted(ctx, a, path);
  for (int s = 0; s < 5; ++s) { /* step 5 (a tenth of 50) sorts */
    TCALL(mpmc_sim_step(a, dt));
    TCALL(mpmc_sim_step(b, dt));
  }
  for (int k = 0; k < 2; ++k) {
    mpmc_const_sim s = k ? b : a;
    for (int q = 1; q < n; ++q)
      if (cell_of(s, q, 1) < cell_of(s, q - 1, 1))
        fail_msg("%s run, 5 steps after the slab axis became y: the points are not sorted by y cell (point %d)",
                 k ? "restarted" : "straight", q);
  }
  expect_same_run(a, b);
  mpmc_sim_destroy(&a);
  mpmc_sim_destroy(&b);
  mpmc_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sorted_equals_unsorted),
      cmocka_unit_test(test_ids),
      cmocka_unit_test(test_checkpoint),
      cmocka_unit_test(test_axis_change),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
