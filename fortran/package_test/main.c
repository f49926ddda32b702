/* Out-of-tree C consumer of the installed package: one step of a free-falling point. */
#include <math.h>
#include <stdio.h>

#include <mpmc.h>

int main(void) {
  mpmc_context ctx;
  mpmc_sim sim;
  int mat, major, minor, patch;
  const double lo[2] = {0, 0}, hi[2] = {1, 1}, x[2] = {0.5, 0.5}, vol = 0.01, g[2] = {0, -10};
  if (mpmc_context_create(&ctx) || mpmc_sim_create(ctx, 2, &sim)) return 1;
  if (mpmc_sim_set_grid(sim, lo, hi, 0.25) || mpmc_sim_set_gravity(sim, g) ||
      mpmc_sim_add_material_hencky(sim, 1e6, 0.3, 1000, &mat) ||
      mpmc_sim_add_particles(sim, 1, x, &vol, mat, NULL) || mpmc_sim_step(sim, 1e-4)) {
    printf("FAILED: %s\n", mpmc_context_last_error(ctx));
    return 1;
  }
  double *v;
  if (mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, &v, NULL)) return 1;
  /* one explicit step under gravity: v_y = g dt */
  if (fabs(v[1] + 1e-3) > 1e-12) {
    printf("FAILED: expected v_y = -1e-3 after one step, got %.17g\n", v[1]);
    return 1;
  }
  mpmc_version(&major, &minor, &patch);
  printf("consumer_c: mpmc %d.%d.%d ok\n", major, minor, patch);
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  return 0;
}
