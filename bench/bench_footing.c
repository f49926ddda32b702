/* Strip footing on Tresca soil (paper section 4.2), run by hand:
 *
 *   bench_footing [key=value ...]
 *     n=20          cells per footing width B (h = B/n)
 *     size=12       soil width and depth in B (half model: x in [0, size B], y in [0, size B])
 *     basis=bspline2  ugimp | bspline2 | bspline3 | linear
 *     fbar=3        3: F-bar, stable form (det F projected one order below the basis); 2: F-bar,
 *                   projection of det F (total); 1: F-bar, Algorithm 1 (paper); 0: standard
 *     rate=0.0025   footing velocity in B per second (after a ramp over the first ramp B)
 *     ramp=0.001    settlement over which the velocity ramps up linearly [B]
 *     delta=0.006   final settlement [B]
 *     damping=0.002 local damping alpha (the paper's)
 *     cfl=0.4       dt = cfl h / c
 *     flip=1        FLIP/PIC blend
 *     mu=1000       footing friction (large: rough)
 *     dhat=0        barrier range [m] (0: the default, half the point spacing)
 *     kappa=0       barrier stiffness [Pa/m] (0: the default, docs/contact.md)
 *     threads=0     OpenMP threads (0: default)
 *     csv=FILE      write delta/B, q/su per output interval
 *
 * Soil: Hencky-J2, E = 1000 kPa, nu = 0.49, su = 0.1 kPa (kappa = sqrt(3) su, the von Mises
 * q at yield in plane strain), rho = 1000 kg/m^3, no gravity, 2x2 points per cell.  Walls:
 * slip at x = 0 (symmetry) and x = size B, fixed at y = 0.  The defaults are those of
 * workflows/strip_footing.yaml (docs/contact.md has every run).  The footing is a rigid box from
 * x = -B/2 to B/2 resting on the surface y = size B, pushed down; q = reaction / (B/2).
 * bearing_capacity_ratio = mean q/su over the second half of the settlement (docs/contact.md).
 * Prandtl: 2 + pi = 5.1416. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpmc.h"
#include "bench_util.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
  int n, basis, fbar, threads;
  double size, rate, ramp, delta, damping, cfl, flip, mu, dhat, kappa;
  const char *csv;
} opts;

#define CALL(expr)                                                                       \
  do {                                                                                   \
    int e_ = (expr);                                                                     \
    if (e_) {                                                                            \
      fprintf(stderr, "%s failed: %s\n", #expr, mpmc_context_last_error(ctx));           \
      return e_;                                                                         \
    }                                                                                    \
  } while (0)

static int run(const opts *o) {
  const double B = 1.0, E = 1.0e6, nu = 0.49, su = 100.0, rho = 1000.0;
  const double h = B / o->n, W = o->size * B, D = o->size * B;
  mpmc_context ctx;
  mpmc_sim sim;
  if (mpmc_context_create(&ctx)) return 1;
  CALL(mpmc_sim_create(ctx, 2, &sim));
  const double glo[2] = {0.0, 0.0}, ghi[2] = {W, D + 0.25 * B};
  CALL(mpmc_sim_set_grid(sim, glo, ghi, h));
  CALL(mpmc_sim_set_basis(sim, o->basis));
  CALL(mpmc_sim_set_fbar(sim, o->fbar));
  CALL(mpmc_sim_set_flip_blend(sim, o->flip));
  CALL(mpmc_sim_set_damping(sim, o->damping));
  CALL(mpmc_sim_set_threads(sim, o->threads));
  int mat;
  const double kappa = sqrt(3.0) * su;
  CALL(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, kappa, kappa, 0.0, &mat));
  const int nx = 2 * (int)lround(W / h), ny = 2 * (int)lround(D / h), np = nx * ny;
  double *x = malloc(sizeof(double) * 2 * (size_t)np), *vol = malloc(sizeof(double) * (size_t)np);
  for (int j = 0, q = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i, ++q) {
      x[2 * q] = (i + 0.5) * 0.5 * h;
      x[2 * q + 1] = (j + 0.5) * 0.5 * h;
      vol[q] = 0.25 * h * h;
    }
  CALL(mpmc_sim_add_particles(sim, np, x, vol, mat, NULL));
  free(x);
  free(vol);
  CALL(mpmc_sim_add_wall_face(sim, 0, MPMC_WALL_SLIP, NULL));
  CALL(mpmc_sim_add_wall_face(sim, 1, MPMC_WALL_SLIP, NULL));
  CALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  /* the footing's base at gap dhat from the top row of points (the surface y = D for the
   * default dhat = half the point spacing) */
  const double ytop = D - 0.25 * h, ybase = o->dhat > 0 ? ytop + o->dhat : D;
  const double flo[2] = {-0.5 * B, ybase}, fhi[2] = {0.5 * B, ybase + B};
  int foot;
  CALL(mpmc_sim_add_rigid_box(sim, flo, fhi, o->mu, &foot));
  CALL(mpmc_sim_set_contact_params(sim, o->dhat, o->kappa));
  const double c = sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho);
  const double dt = o->cfl * h / c, V = o->rate * B;
  FILE *csv = o->csv ? fopen(o->csv, "w") : NULL;
  if (csv) fprintf(csv, "delta_over_B,q_over_su\n");
  double dhat, kb;
  CALL(mpmc_sim_get_contact_params(sim, &dhat, &kb));
  printf("# n=%d size=%g basis=%d fbar=%d points=%d dt=%.4g s rate=%g B/s ramp=%g B delta=%g B "
         "damping=%g flip=%g mu=%g dhat=%.4g kappa=%.4g\n",
         o->n, o->size, o->basis, o->fbar, np, dt, o->rate, o->ramp, o->delta, o->damping,
         o->flip, o->mu, dhat, kb);
  const double t0 = now();
  double settle = 0.0, qsum = 0.0, gmin = INFINITY;
  int nq = 0, err = 0, next_out = 0;
  long step = 0;
  const int nout = 200;
  double qwin[200] = {0};
  int nwin[200] = {0};
  while (settle < o->delta * B) {
    /* linear ramp of the velocity over the first `ramp` of settlement (v^2 = 2 a s) */
    const double s_r = o->ramp * B;
    const double v = settle < s_r ? fmax(sqrt(2.0 * settle * V * V / (2.0 * s_r)), 0.02 * V) : V;
    const double vb[2] = {0.0, -v};
    CALL(mpmc_sim_set_rigid_velocity(sim, foot, vb));
    err = mpmc_sim_step(sim, dt);
    if (err) break;
    settle += v * dt;
    ++step;
    double r[2], gap;
    CALL(mpmc_sim_get_rigid_reaction(sim, foot, r));
    CALL(mpmc_sim_get_rigid_gap(sim, foot, &gap, NULL));
    if (gap < gmin) gmin = gap;
    const double q = r[1] / (0.5 * B) / su;
    const int bin = (int)(settle / (o->delta * B) * nout);
    if (bin < nout) {
      qwin[bin] += q;
      nwin[bin]++;
    }
    if (settle >= 0.5 * o->delta * B) {
      qsum += q;
      nq++;
    }
    while (next_out < nout && bin > next_out) {
      const double qb = nwin[next_out] ? qwin[next_out] / nwin[next_out] : NAN;
      if (csv) fprintf(csv, "%.6g,%.6g\n", (next_out + 0.5) * o->delta / nout, qb);
      if (next_out % 20 == 19)
        printf("delta/B %.4f  q/su %.4f  (step %ld, %.0f s, min gap/dhat %.3f)\n",
               (next_out + 0.5) * o->delta / nout, qb, step, now() - t0, gmin / dhat);
      ++next_out;
    }
  }
  const double wall = now() - t0;
  if (csv) fclose(csv);
  if (err) {
    printf("FAILED at step %ld, delta/B = %.5f: %s\n", step, settle / B, mpmc_context_last_error(ctx));
  } else {
    printf("bearing_capacity_ratio %.4f (Prandtl 2+pi = %.4f, error %+.2f %%)\n", qsum / nq,
           2 + M_PI, 100 * (qsum / nq / (2 + M_PI) - 1));
  }
  printf("steps %ld, points %d, wall %.1f s, %.3g particle-steps/s, min gap/dhat %.3f\n", step, np,
         wall, (double)np * step / wall, gmin / dhat);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  return err;
}

int main(int argc, char **argv) {
  opts o = {.n = 20, .basis = MPMC_BASIS_BSPLINE2, .fbar = MPMC_FBAR_STABLE, .threads = 0, .size = 12, .rate = 0.0025,
            .ramp = 0.001, .delta = 0.006, .damping = 0.002, .cfl = 0.4, .flip = 1.0, .mu = 1000,
            .dhat = 0.0, .kappa = 0.0, .csv = NULL};
  for (int i = 1; i < argc; ++i) {
    const char *a = argv[i], *eq = strchr(a, '=');
    if (!eq) {
      fprintf(stderr, "usage: %s [key=value ...] (see the source)\n", argv[0]);
      return 2;
    }
    const char *v = eq + 1;
    const size_t k = (size_t)(eq - a);
#define KEY(s) (k == strlen(s) && strncmp(a, s, k) == 0)
    if (KEY("n")) o.n = atoi(v);
    else if (KEY("size")) o.size = atof(v);
    else if (KEY("basis"))
      o.basis = !strcmp(v, "ugimp") ? MPMC_BASIS_UGIMP : !strcmp(v, "bspline2") ? MPMC_BASIS_BSPLINE2
              : !strcmp(v, "bspline3") ? MPMC_BASIS_BSPLINE3 : MPMC_BASIS_LINEAR;
    else if (KEY("fbar")) o.fbar = atoi(v);
    else if (KEY("rate")) o.rate = atof(v);
    else if (KEY("ramp")) o.ramp = atof(v);
    else if (KEY("delta")) o.delta = atof(v);
    else if (KEY("damping")) o.damping = atof(v);
    else if (KEY("cfl")) o.cfl = atof(v);
    else if (KEY("flip")) o.flip = atof(v);
    else if (KEY("mu")) o.mu = atof(v);
    else if (KEY("threads")) o.threads = atoi(v);
    else if (KEY("dhat")) o.dhat = atof(v);
    else if (KEY("kappa")) o.kappa = atof(v);
    else if (KEY("csv")) o.csv = v;
    else {
      fprintf(stderr, "unknown option %s\n", a);
      return 2;
    }
#undef KEY
  }
  return run(&o) ? 1 : 0;
}
