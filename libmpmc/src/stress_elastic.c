/* The Neo-Hookean stress update (material_neo_hookean.c) over blocks of four points, one of
 * the kernel files compiled once per instruction set (mpmc_impl.h, MPMC_ISA):
 *   b <- dF b dF^T,  J = sqrt(det b),  tau = mu (b - 1) + lambda ln J 1,  sigma = tau / J
 * (formulas.md; plane strain: b_zz stays 1, dF embedded in 3 x 3).  Four points of the
 * material in a row (points 4k .. 4k + 3) go through it as vectors of four doubles, lanes the
 * points, with the operations of the point-by-point form in the same order (batch4.h), so the
 * same bits as one point alone in a set without contraction (baseline, avx2: tests/t303);
 * ln J stays libm's log per lane.  A block that holds another material's points or the end
 * of the arrays goes point by point.  The blocks are fixed by the index, so the results do not
 * depend on the thread count.  The update keeps the stress guard itself (ops->checks_stress:
 * the lowest non-finite point into sim->stress_bad). */
#include <limits.h>
#include <math.h>

#include "batch4.h"
#include "linalg.h"
#include "mpmc_impl.h"

/* point q alone; returns 0 if its stress is not finite */
static inline int nh_point(mpmc_particles *p, const int d, double mu, double lam, int q) {
  double F[3][3];
  mpmc_embed(d, p->dF + (size_t)q * d * d, F);
  double *b = p->be + (size_t)q * 6;
  mpmc_push_forward(F, b);
  const double J = sqrt(mpmc_det_sym(b));
  const double lnJ = log(J), inv_J = 1.0 / J;
  double *s = p->stress + (size_t)q * 6;
  for (int k = 0; k < 6; ++k) {
    const double tau = mu * (b[k] - (k < 3)) + (k < 3 ? lam * lnJ : 0.0);
    s[k] = tau * inv_J;
  }
  return mpmc_stress_finite(s);
}

/* the four points q0 .. q0 + 3, all of the material, as vectors: nh_point's operations;
 * returns the lowest of them whose stress is not finite (mpmc_stress_finite's sum), or
 * INT_MAX */
static inline int nh_block(mpmc_particles *p, const int d, double mu, double lam, int q0) {
  const v4 one = {1.0, 1.0, 1.0, 1.0}, zero = {0.0, 0.0, 0.0, 0.0};
  v4 F[9], b[6], bt[6], s[6];
  load_dF4(d, p->dF + (size_t)q0 * d * d, &one, F);
  double *be = p->be + (size_t)q0 * 6;
  load_rows6(be, b);
  push_forward4(F, b, bt);
  /* mpmc_det_sym's order */
  const v4 det = bt[0] * (bt[1] * bt[2] - bt[3] * bt[3]) - bt[5] * (bt[5] * bt[2] - bt[3] * bt[4]) +
                 bt[4] * (bt[5] * bt[3] - bt[1] * bt[4]);
  v4 J;
  sqrt4(&det, &J);
  const v4 lnJ = {log(J[0]), log(J[1]), log(J[2]), log(J[3])}, inv_J = 1.0 / J;
  for (int k = 0; k < 6; ++k)
    s[k] = (mu * (bt[k] - (k < 3 ? one : zero)) + (k < 3 ? lam * lnJ : zero)) * inv_J;
  store_rows6(bt, be);
  store_rows6(s, p->stress + (size_t)q0 * 6);
  const v4 sum = s[0] + s[1] + s[2] + s[3] + s[4] + s[5], nf = sum - sum; /* 0 if finite */
  for (int l = 0; l < 4; ++l)
    if (!(nf[l] == 0.0)) return q0 + l;
  return INT_MAX;
}

/** The stress update of material id's points (Neo-Hookean: mat->G, mat->lambda). */
int MPMC_ISA(mpmc_nh_batch)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id) {
  mpmc_particles *p = &sim->p;
  const int d = sim->dim, n = p->n, nblk = (n + 3) / 4, *restrict m = p->mat;
  const double mu = mat->G, lam = mat->lambda;
  int first_nf = INT_MAX;
#pragma omp parallel for schedule(static) reduction(min : first_nf) if (n > MPMC_OMP_MIN)
  for (int blk = 0; blk < nblk; ++blk) {
    const int q0 = 4 * blk;
    if (q0 + 3 < n && m[q0] == id && m[q0 + 1] == id && m[q0 + 2] == id && m[q0 + 3] == id) {
      const int bad = nh_block(p, d, mu, lam, q0);
      first_nf = bad < first_nf ? bad : first_nf;
    } else {
      for (int q = q0; q < q0 + 4 && q < n; ++q)
        if (m[q] == id && !nh_point(p, d, mu, lam, q) && q < first_nf) first_nf = q;
    }
  }
  if (first_nf < sim->stress_bad) sim->stress_bad = first_nf; /* stress_update.c's guard */
  return MPMC_SUCCESS;
}
