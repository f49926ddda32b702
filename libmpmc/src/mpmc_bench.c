/* The benchmarks' view of a simulation's internals (mpmc_bench.h). */
#include "mpmc_bench.h"
#include "mpmc_impl.h"

int mpmc_bench_grid(mpmc_sim sim, int lo[3], int hi[3], size_t *record_bytes, size_t *node_bytes) {
  if (!sim) return MPMC_ERR_ARG;
  const mpmc_grid *g = &sim->grid;
  for (int a = 0; a < 3; ++a) lo[a] = g->act_lo[a], hi[a] = g->act_hi[a];
  const mpmc_fbar_state *f = &sim->fb;
  *record_bytes = sizeof(double) * MPMC_NREC + (f->fb ? 2 * sizeof(double) : f->fbj ? sizeof(double) : 0);
  *node_bytes = *record_bytes + sizeof *g->fixed;
  return MPMC_SUCCESS;
}

int mpmc_bench_grid_held(mpmc_sim sim, size_t *held, size_t *whole) {
  if (!sim) return MPMC_ERR_ARG;
  *held = sim->grid.nn;
  *whole = mpmc_grid_global_nodes(&sim->grid);
  return MPMC_SUCCESS;
}

void mpmc_bench_layout(int *ghost_cells, int *min_slab_cells) {
  *ghost_cells = MPMC_GHOST;
  *min_slab_cells = MPMC_DD_MIN_CELLS;
}

double mpmc_bench_bytes_per_point(mpmc_sim sim) {
  if (!sim) return 0.0;
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const struct {
    const void *a;
    int n;
  } f[] = {{p->x, d},      {p->x0, d},     {p->v, d},          {p->m, 1},      {p->vol0, 1},
           {p->J, 1},      {p->stress, 6}, {p->Jbar, 1},       {p->Janc, 1},   {p->be, 6},
           {p->eps_p, 1},  {p->region, 1}, {p->Jp, 1},         {p->pw, 1},     {p->lp, 1},
           {p->force, d},  {p->cforce, d}, {p->ustate, p->nustate},            {p->dF, d * d},
           {sim->fb.xn, d}, {sim->fb.xoff, d}};
  double b = sizeof(int) * (p->id ? 3.0 : 2.0); /* material id, slab order, point id (sort) */
  if (sim->fb.xnode) b += sizeof(int);          /* F-bar's kept first nodes (transfer.h) */
  if (sim->fb.scale) b += sizeof(double);       /* F-bar's deferred factors (stress_j2.c) */
  for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i)
    if (f[i].a) b += sizeof(double) * (double)f[i].n;
  return b;
}
