/* Water at rest, the full benchmark of tests/t505-water-at-rest.c: the same columns of nearly
 * incompressible Newtonian water (rho = 997.5 kg/m^3, mu = 1e-3 Pa s), H = 0.5 m high,
 * 0.1 m wide (2D, plane strain) or 0.1 x 0.1 m (3D), slip side walls, fixed base, h = 0.05 m
 * with 2 points per cell per axis (80 / 320 points), gravity switched on at t = 0 with local
 * damping 0.1 and PIC as the diffusivity D = 1 m^2/s (mpmc_sim_set_pic_diffusivity: the PIC
 * share D dt / h^2, 0.134 a step at K = 2e6 and 0.0042 at 2e9), dt = 0.3 h / c, the default
 * F-bar (anchored), one
 * thread; every basis, K = 2e6, 2e7, 2e8 and 2e9 Pa, run to T = 5 s simulated (t505 stops
 * after 20,000 steps).  Per case, the kinetic energy sampled every 10 steps: its largest
 * value over the second half of the run over its peak, and the time after which it stayed
 * below 1e-8 of its peak (the last sample at or above 1e-8 of the peak so far); the RMS error
 * of the pressure -tr(sigma)/3 against rho g depth (below the compressed surface) at T over
 * rho g H; the steps; the CPU seconds; PASS when the first is below 1e-8 and the pressure
 * error below 1 % (a case whose step fails, an inverted point, prints the time).
 *
 *   water_at_rest [T] [dim] [basis] [fbar] [flip]
 *
 * T in s (default 5); dim 2 or 3 (default 0: both); basis 0-3 (linear, uGIMP, B-spline2,
 * B-spline3; default -1: all); fbar an mpmc_fbar_mode (default MPMC_FBAR_ANCHORED); flip a
 * fixed FLIP/PIC blend in [0, 1] in place of the diffusivity (default -1: D = 1 m^2/s; 0.95
 * was the benchmark's blend before).  Exits with 1 when a case fails. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mpmc.h"

#define CHECK(expr)                                                                        \
  do {                                                                                     \
    if (expr) {                                                                            \
      fprintf(stderr, "%s failed: %s\n", #expr, mpmc_context_last_error(ctx));             \
      exit(2);                                                                             \
    }                                                                                      \
  } while (0)

typedef struct {
  double late_ke; /* the largest kinetic energy over the second half, over its peak */
  double rms;     /* pressure RMS error over rho g H */
  double settle;  /* the last time E_k stood at or above 1e-8 of its peak so far, s */
  double failed;  /* the time of a step that failed (inverted point, ...), else 0 */
  long steps;
  double cpu; /* s */
} rest;

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#define PIC_DIFFUSIVITY 1.0 /* m^2/s */

static rest column(int dim, int basis, double K, int fbar, double T, double flip) {
  const double mu = 1e-3, rho = 997.5, g = 9.81, H = 0.5, W = 0.1, h = 0.05;
  mpmc_context ctx;
  mpmc_sim sim;
  if (mpmc_context_create(&ctx)) exit(2);
  const double t0 = cpu_now();
  CHECK(mpmc_sim_create(ctx, dim, &sim));
  const double lo[3] = {0, 0, 0}, hi[3] = {W, dim == 2 ? H + 4 * h : W, H + 4 * h};
  CHECK(mpmc_sim_set_grid(sim, lo, hi, h));
  CHECK(mpmc_sim_set_basis(sim, basis));
  CHECK(mpmc_sim_set_fbar(sim, fbar));
  if (flip >= 0)
    CHECK(mpmc_sim_set_flip_blend(sim, flip));
  else
    CHECK(mpmc_sim_set_pic_diffusivity(sim, PIC_DIFFUSIVITY));
  CHECK(mpmc_sim_set_threads(sim, 1));
  int mat, n;
  CHECK(mpmc_sim_add_material_newtonian(sim, K, mu, rho, &mat));
  const double plo[3] = {0, 0, 0}, phi[3] = {W, dim == 2 ? H : W, H};
  CHECK(mpmc_sim_seed_box(sim, plo, phi, 2, mat, NULL, &n));
  const int up = dim - 1; /* the vertical axis */
  for (int a = 0; a < up; ++a) {
    CHECK(mpmc_sim_add_wall_face(sim, 2 * a, MPMC_WALL_SLIP, NULL));
    CHECK(mpmc_sim_add_wall_face(sim, 2 * a + 1, MPMC_WALL_SLIP, NULL));
  }
  CHECK(mpmc_sim_add_wall_face(sim, 2 * up, MPMC_WALL_FIXED, NULL));
  const double grav[3] = {0, dim == 2 ? -g : 0, -g};
  CHECK(mpmc_sim_set_gravity(sim, grav));
  CHECK(mpmc_sim_set_damping(sim, 0.1));
  double dt;
  CHECK(mpmc_sim_stable_dt(sim, 0.3, &dt));
  const long nsteps = (long)ceil(T / dt - 1e-9);
  double peak = 0.0, late = 0.0, settle = 0.0;
  for (long s = 1; s <= nsteps; ++s) {
    if (mpmc_sim_step(sim, dt)) { /* reported as a failed case, the others still run */
      fprintf(stderr, "%s\n", mpmc_context_last_error(ctx));
      mpmc_sim_destroy(&sim);
      mpmc_context_destroy(&ctx);
      return (rest){NAN, NAN, NAN, (double)s * dt, s, cpu_now() - t0};
    }
    if (s % 10 == 0 || s == nsteps) {
      double ke;
      CHECK(mpmc_sim_get_kinetic_energy(sim, &ke));
      peak = ke > peak ? ke : peak;
      if (2 * s > nsteps) late = ke > late ? ke : late;
      if (!(ke < 1e-8 * peak)) settle = (double)s * dt;
    }
  }
  double *sg, *xp;
  CHECK(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, &sg, NULL));
  CHECK(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &xp, NULL));
  const double top = H * (1 - rho * g * H / (2 * K)); /* the surface after compression */
  double se = 0.0;
  for (int q = 0; q < n; ++q) {
    const double p = -(sg[6 * q] + sg[6 * q + 1] + sg[6 * q + 2]) / 3;
    const double e = p - rho * g * (top - xp[(size_t)q * dim + up]);
    se += e * e;
  }
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  return (rest){peak > 0 ? late / peak : 1.0, sqrt(se / n) / (rho * g * H), settle, 0.0,
                nsteps, cpu_now() - t0};
}

int main(int argc, char **argv) {
  const double T = argc > 1 ? atof(argv[1]) : 5.0;
  const int only_dim = argc > 2 ? atoi(argv[2]) : 0;
  const int only_basis = argc > 3 ? atoi(argv[3]) : -1;
  const int fbar = argc > 4 ? atoi(argv[4]) : MPMC_FBAR_ANCHORED;
  const double flip = argc > 5 ? atof(argv[5]) : -1.0;
  if (flip > 1) {
    fprintf(stderr, "water_at_rest: flip = %g must be in [0, 1], or -1 for the PIC diffusivity\n", flip);
    return 2;
  }
  static const char *basis_name[4] = {"linear", "uGIMP", "B-spline2", "B-spline3"};
  static const double Ks[4] = {2e6, 2e7, 2e8, 2e9};
  int failed = 0;
  double total = 0.0;
  char pic[64];
  if (flip >= 0)
    snprintf(pic, sizeof pic, "FLIP/PIC %g", flip);
  else
    snprintf(pic, sizeof pic, "PIC diffusivity %g m^2/s", PIC_DIFFUSIVITY);
  printf("water at rest, %g s simulated, F-bar form %d, %s, one thread; limits: E_k < 1e-8 of "
         "its peak over the second half, pressure RMS < 1 %% of rho g H\n", T, fbar, pic);
  printf("%-3s %-9s %8s %14s %11s %14s %9s %8s %s\n", "dim", "basis", "K [Pa]",
         "late E_k/peak", "settled [s]", "p RMS/rho g H", "steps", "CPU [s]", "result");
  for (int dim = 2; dim <= 3; ++dim) {
    if (only_dim && only_dim != dim) continue;
    for (int b = 0; b < 4; ++b) {
      if (only_basis >= 0 && only_basis != b) continue;
      for (int k = 0; k < 4; ++k) {
        const rest r = column(dim, b, Ks[k], fbar, T, flip);
        const int bad = !(r.late_ke < 1e-8 && r.rms < 0.01);
        failed |= bad;
        total += r.cpu;
        printf("%dD  %-9s %8.0e %14.2e %11.2f %13.4f%% %9ld %8.1f %s", dim, basis_name[b],
               Ks[k], r.late_ke, r.settle, 100 * r.rms, r.steps, r.cpu, bad ? "FAIL" : "PASS");
        if (r.failed > 0) printf(" (the step failed at t = %.3f s)", r.failed);
        printf("\n");
        fflush(stdout);
      }
    }
  }
  printf("total CPU %.0f s; %s\n", total, failed ? "some cases FAIL" : "all cases PASS");
  return failed;
}
