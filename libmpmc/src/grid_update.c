/* Grid update (eq 9): nodal velocities from momentum and forces, gravity, local damping,
 * adaptive viscous damping, wall constraints, on the nodes of the active box.  Leaves the new
 * velocity in the node record's momentum slots and the increment v^{n+1} - v^n in its force
 * slots, which is what G2P's FLIP/PIC blend needs. */
#include "mpmc_impl.h"

static inline void update_impl(mpmc_sim sim, const int DIM, double dt) {
  mpmc_grid *g = &sim->grid;
  const int R = MPMC_NREC, F = MPMC_FOFF;
  const double alpha = sim->cfg.damping;
  const double *gr = sim->cfg.gravity;
  double *restrict rec = g->node;
  const unsigned short *restrict fx = g->fixed;
  /* only the active box holds mass */
  const long nrow = mpmc_grid_active_rows(g);
  const long box = (long)(g->act_hi[0] - g->act_lo[0]);
  /* adaptive damping (damping.c): c from the last step; each node's force against its
   * force of the last step, if it held mass then, into this row's sums */
  const int adr = sim->cfg.adr;
  const double cdt = sim->adr_c * dt < 2.0 ? sim->adr_c * dt : 2.0; /* (2 - c dt) >= 0 */
  const double stamp = (double)sim->stats.steps;
  const double ca = (2.0 - cdt) / (2.0 + cdt), cb = 2.0 * dt / (2.0 + cdt);
  double *restrict fprev = sim->adr_f;
  double *restrict rowsum = sim->scr.adr_rows;
  const int oax = adr ? sim->adr_own[0] : -1; /* MPI: the nodes this rank sums (damping.c) */
  const long olo = sim->adr_own[1], ohi = sim->adr_own[2];
#pragma omp parallel for schedule(static) if (nrow * box > MPMC_OMP_MIN)
  for (long row = 0; row < nrow; ++row) {
    size_t len;
    const size_t first = mpmc_grid_active_row(g, row, &len);
    double num = 0.0, den = 0.0;
    for (size_t i = first; i < first + len; ++i) {
      double *restrict r = rec + i * R;
      const double m = r[0];
      if (m <= 0.0) continue;
      const double inv_m = 1.0 / m;
      double v0[3], f[3], v1[3];
      for (int a = 0; a < DIM; ++a) {
        v0[a] = r[1 + a] * inv_m;
        f[a] = r[F + a] + m * gr[a];
      }
      const unsigned fl = fx[i];
      if (adr) {
        /* the Rayleigh quotient's terms over the free components: dx = v dt moved the
         * material, df = f^n - f^{n-1} = -K dx, so omega^2 = v.(f^{n-1} - f^n) / (dt m v.v) */
        double *restrict fp = fprev + i * (size_t)(1 + DIM);
        int both = fp[0] == stamp - 1.0;
        if (oax >= 0) {
          const long k = mpmc_grid_plane(g, oax, i);
          both &= k >= olo && k < ohi;
        }
        for (int a = 0; a < DIM; ++a) {
          if (both && !(fl & (73u << a))) {
            num += v0[a] * (fp[1 + a] - f[a]);
            den += dt * m * v0[a] * v0[a];
          }
          fp[1 + a] = f[a];
        }
        fp[0] = stamp;
      }
      if (alpha > 0.0) mpmc_damping_apply(alpha, f, v0, DIM);
      /* adaptive damping c m v, central difference: (2 + c dt) v1 = (2 - c dt) v0 + 2 dt f/m */
      if (adr)
        for (int a = 0; a < DIM; ++a) v1[a] = ca * v0[a] + cb * f[a] * inv_m;
      else
        for (int a = 0; a < DIM; ++a) v1[a] = v0[a] + dt * f[a] * inv_m;
      if (fl) {
        for (int a = 0; a < DIM; ++a) {
          if (fl & (1u << a)) v1[a] = 0.0;
          if ((fl & (8u << a)) && v1[a] < 0.0) v1[a] = 0.0;
          if ((fl & (64u << a)) && v1[a] > 0.0) v1[a] = 0.0;
        }
      }
      for (int a = 0; a < DIM; ++a) {
        r[1 + a] = v1[a];
        r[F + a] = v1[a] - v0[a];
      }
    }
    if (adr) {
      rowsum[2 * row] = num;
      rowsum[2 * row + 1] = den;
    }
  }
}

/* Row (j, k)'s x range (grid.rowx) widened to hold [lo, hi); an empty range becomes it. */
static void widen_range(int *rx, int lo, int hi) {
  if (hi <= lo) return;
  if (rx[1] <= rx[0]) {
    rx[0] = lo;
    rx[1] = hi;
    return;
  }
  rx[0] = lo < rx[0] ? lo : rx[0];
  rx[1] = hi > rx[1] ? hi : rx[1];
}

/* The rows of planes [from, to) along axis a (1 or 2) within the box's other axis: empty. */
static void rows_empty(mpmc_grid *g, int a, int from, int to) {
  const int b = a == 1 ? 2 : 1;
  for (int i = from; i < to; ++i)
    for (int o = g->act_lo[b]; o < g->act_hi[b]; ++o) {
      int *rx = g->rowx + 2 * (a == 1 ? (size_t)i + (size_t)g->n[1] * (size_t)o
                                       : (size_t)o + (size_t)g->n[1] * (size_t)i);
      rx[0] = rx[1] = g->act_lo[0];
    }
}

/* The ghosts in the active box fold into partners across the wall that may lie outside it:
 * grow the box to hold them (nodes outside it are zero, so nothing needs clearing), and the
 * partners' row ranges: across an x wall each row's range to the partners of its ghosts,
 * across a y or z wall the partner row's range to its ghost row's. */
static void grow_box_for_mirrors(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  const size_t n1 = (size_t)g->n[1];
  for (int w = 0; w < sim->scr.nmirror; ++w) {
    const mpmc_mirror *m = &sim->scr.mirrors[w];
    const int a = m->axis;
    if (g->act_hi[a] <= g->act_lo[a]) continue;
    for (int k = 1; k <= MPMC_GHOST; ++k) {
      const int ig = m->plane + m->side * k, im = m->plane - m->side * k;
      if (ig < g->act_lo[a] || ig >= g->act_hi[a] || im < 0 || im >= g->n[a]) continue;
      if (a == 0) {
        for (int kz = g->act_lo[2]; kz < g->act_hi[2]; ++kz)
          for (int j = g->act_lo[1]; j < g->act_hi[1]; ++j) {
            int *rx = g->rowx + 2 * ((size_t)j + n1 * (size_t)kz);
            if (ig >= rx[0] && ig < rx[1]) widen_range(rx, im, im + 1);
          }
      } else {
        if (im < g->act_lo[a]) rows_empty(g, a, im, g->act_lo[a]);
        if (im >= g->act_hi[a]) rows_empty(g, a, g->act_hi[a], im + 1);
      }
      if (im < g->act_lo[a]) g->act_lo[a] = im;
      if (im >= g->act_hi[a]) g->act_hi[a] = im + 1;
      if (a == 0) continue;
      const int b = a == 1 ? 2 : 1;
      for (int o = g->act_lo[b]; o < g->act_hi[b]; ++o) {
        const size_t rg = a == 1 ? (size_t)ig + n1 * (size_t)o : (size_t)o + n1 * (size_t)ig;
        const size_t rm = a == 1 ? (size_t)im + n1 * (size_t)o : (size_t)o + n1 * (size_t)im;
        widen_range(g->rowx + 2 * rm, g->rowx[2 * rg], g->rowx[2 * rg + 1]);
      }
    }
  }
}

/* Walls on node planes with B-spline (or uGIMP) support beyond them: the velocity field is
 * continued across the wall by reflection, odd in the constrained components (zero at the
 * wall) and even in the free ones.  The ghost node's degree of freedom is thereby that of
 * its mirror partner (basis w_m -/+ w_g), so before the update the ghost's mass, momentum
 * and force are folded into the partner (fold = 1), and after it the ghost takes the
 * partner's reflected velocity and increment (fold = 0). */
static void mirror_ghosts(mpmc_sim sim, int fold) {
  mpmc_grid *g = &sim->grid;
  const int d = sim->cfg.dim;
  const size_t R = MPMC_NREC, F = MPMC_FOFF;
  double *rec = g->node;
  const size_t stride[3] = {1, (size_t)g->n[0], (size_t)g->n[0] * (size_t)g->n[1]};
  for (int w = 0; w < sim->scr.nmirror; ++w) {
    const mpmc_mirror *m = &sim->scr.mirrors[w];
    const int a = m->axis, b = (a + 1) % d, c = (a + 2) % d;
    for (int k = 1; k <= MPMC_GHOST; ++k) {
      const int ig = m->plane + m->side * k, im = m->plane - m->side * k;
      /* ghosts with mass lie in the active box */
      if (ig < g->act_lo[a] || ig >= g->act_hi[a] || im < 0 || im >= g->n[a]) continue;
      for (int j = g->act_lo[b]; j < g->act_hi[b]; ++j)
        for (int l = (d == 3 ? g->act_lo[c] : 0); l < (d == 3 ? g->act_hi[c] : 1); ++l) {
          const size_t base = stride[b] * (size_t)j + (d == 3 ? stride[c] * (size_t)l : 0);
          double *rg = rec + R * (base + stride[a] * (size_t)ig);
          double *rm = rec + R * (base + stride[a] * (size_t)im);
          if (rg[0] <= 0.0) continue;
          if (fold) {
            for (int e = 0; e < d; ++e) {
              const double sg = (m->odd >> e & 1u) ? -1.0 : 1.0;
              rm[1 + e] += sg * rg[1 + e];
              /* gravity enters the update as (folded mass) * g; the ghost's share of the
               * body force belongs to the partner with the reflection's sign */
              rm[F + e] += sg * rg[F + e] + (sg - 1.0) * rg[0] * sim->cfg.gravity[e];
            }
            rm[0] += rg[0];
          } else {
            for (int e = 0; e < d; ++e) {
              const double sg = (m->odd >> e & 1u) ? -1.0 : 1.0;
              rg[1 + e] = sg * rm[1 + e];
              rg[F + e] = sg * rm[F + e];
            }
          }
        }
    }
  }
}

/** Phase 2 of the step. */
int MPMC_ISA(mpmc_grid_update)(mpmc_sim sim, double dt) {
  if (sim->scr.walls_dirty) MPMC_CALL(mpmc_boundary_apply_flags(sim));
  if (sim->scr.nmirror) {
    grow_box_for_mirrors(sim);
    mirror_ghosts(sim, 1);
  }
  const long nrow = mpmc_grid_active_rows(&sim->grid);
  if (sim->cfg.adr) MPMC_CALL(mpmc_adaptive_damping_prepare(sim, nrow));
  if (sim->cfg.dim == 2)
    update_impl(sim, 2, dt);
  else
    update_impl(sim, 3, dt);
  if (sim->cfg.adr) mpmc_adaptive_damping_finish(sim, nrow);
  if (sim->scr.nmirror) mirror_ghosts(sim, 0);
  return MPMC_SUCCESS;
}
