/* The F-bar projection (paper Algorithm 1, eqs 19-27), run only when enabled:
 *   scatter  V_i = sum w V_p,  (V J)_i = sum w V_p j_p                          (step 3)
 *   average  Jbar_i = (V J)_i / V_i                                             (step 3)
 *   gather   Pi_p = sum w Jbar_i,  dFbar = (Pi_p / (Jbar_p^n dJ_p))^(1/dim) dF (step 4)
 * with j_p = Jbar_p^n dJ_p in MPMC_FBAR_PAPER (eq 26, Algorithm 1 as published) and
 * j_p = J_p^{n+1} = det F in MPMC_FBAR_TOTAL (eqs 18-21: the projection of the Jacobian
 * itself, inserted in eq 25).  The paper's recursion re-projects Jbar every step, so in a
 * long quasi-static run the smoothing of a non-uniform Jbar near boundaries accumulates
 * into a creep of the true volume (docs/theory.md); the total form has no such memory but
 * follows the points' own J, which drifts in large flows.  MPMC_FBAR_ANCHORED, the default,
 * projects j_p = Janc_p, the point's Jacobian times the Jbar / J it was last anchored to,
 * re-anchored to Algorithm 1's Jbar^n dJ by the share of the step's volume change and travel
 * (transfer.h, mpmc_anchor): Algorithm 1 where the points change volume or move, the total
 * form where they rest.
 * MPMC_FBAR_STABLE projects det F like the total form, but onto a space one order below
 * the basis instead of the basis itself (docs/theory.md, "The J-bar space"): linear hats on
 * the grid of spacing 2h (nodes x = lo, lo + 2h, ...) for linear and uGIMP, linear hats
 * centred on the cells for quadratic B-splines, quadratic B-splines centred on the cells for
 * cubic ones.  With w the weights of that space the formulas above are unchanged.
 * V_p is the volume at t^n.
 *
 * The life of F-bar's state in a step (sim->fb, mpmc_fbar_state; step.c calls in this order):
 *   prepare  mpmc_sim_prepare -> mpmc_fbar_prepare: the points' Jbar (and Janc) and, for the
 *            form in use, the nodal sums, zeroed, and the arrays that keep x^n; before each
 *            step mpmc_fbar_reserve makes room in them for every point.
 *   clear    mpmc_fbar_clear(BOX): the last step's active box of fb and fbj to zero (the
 *            grid's own clear zeroes the records, their MPMC_VSLOT with them).
 *   P2G      (p2g.c) the paper, total and anchored forms: V_i into the records' MPMC_VSLOT
 *            beside the mass (the points are at x^n there, as the projection has them).
 *   G2P      (g2p.c) the scatter, fused, with the weights at hand: (V J)_i into fbj, one
 *            value per node, or in the stable form both sums into fb, in pairs (on private
 *            copies, priv, when P2G ran so); keeps x^n, as the weights' offsets and first
 *            nodes (xoff, xnode; transfer.h, mpmc_kept_weights4), or in the stable form as
 *            positions (xn); sets scattered.  Over MPI the halo sums follow (mpi.c).
 *   F-bar    mpmc_fbar: the nodal average into fbj, then the gather of every point with its
 *            dF scaled, or, when every material's update runs the gather itself, deferred.
 *   stress   (stress_j2.c, stress_blocks.c through batch4.h) the deferred gather chunk by
 *            chunk into scale (mpmc_fbar_gather_range), dF scaled as it is loaded;
 *            stress_update.c clears deferred.
 * Called on its own (tests), with no scatter since the clear, the projection scatters here
 * and gathers, both at x, recovering V_p as V0 J^{n+1} / dJ (G2P has already updated J).
 * The scatter leaves Jbar^n dJ in Jbar for the gather, which replaces it with Pi.
 * Dilatant plastic flow (the frictional models with psi > 0) changes a point's volume with
 * no elastic volume change; projecting it with the rest made a plastic dilation at one point
 * compress the elastic volume of its neighbours and a dilating shear band fed itself until
 * the run blew up.  Where such models exist (p->Jp), each point scatters j / Jp, Jp its
 * plastic volume ratio J / J_e (material_frictional.c), and takes Jp x Pi: the projection
 * smooths the volume change that is not plastic, and a point's plastic dilation stays its own.
 * Touches nothing but dF (handed to the material), Jbar, its own state and the records'
 * MPMC_VSLOT. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "transfer.h"
#if defined(__AVX__)
#include <immintrin.h>
#endif

/* What point q scatters, (V^n, V^n j), V^n recovered as V0 J^{n+1} / dJ; leaves Jbar^n dJ
 * in Jbar until the gather (the denominator of eq 27). */
MPMC_ALWAYS_INLINE mpmc_v2d scatter_values(mpmc_sim sim, const int DIM, int q) {
  mpmc_particles *p = &sim->p;
  const double dJ = mpmc_det_dim(DIM, p->dF + (size_t)q * DIM * DIM);
  const double Vn = p->vol0[q] * p->J[q] / dJ;
  const double jd = p->Jbar[q] * dJ;
  /* no step to measure the travel: the anchored form re-anchors fully (Algorithm 1's) */
  const double j = mpmc_fbar_j(sim->cfg.fbar == MPMC_FBAR_ANCHORED, sim->cfg.fbar, p, q, dJ, jd, INFINITY);
  p->Jbar[q] = jd;
  return (mpmc_v2d){Vn, p->Jp ? Vn * j / p->Jp[q] : Vn * j};
}

/* Scatter point q: V^n and V^n j onto its nodes (Algorithm 1, step 3), where P2G and G2P
 * put them in a step: the records' MPMC_VSLOT and fbj. */
MPMC_ALWAYS_INLINE void scatter_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int S = mpmc_stencil(BASIS);
  double *restrict rec = g->node, *restrict fj = sim->fb.fbj;
  mpmc_pw4 t; /* lane 0 */
  mpmc_point_weights1(DIM, BASIS, 0, 0, g, p->x, p->lp, q, &t);
  const mpmc_v2d vv = scatter_values(sim, DIM, q);
  /* in the products' order of P2G (V: w_x (w_y (w_z V))) and G2P (V j: ((w_x V j) w_z) w_y) */
  const size_t sy = (size_t)g->n[0], sz = (size_t)g->n[0] * (size_t)g->n[1];
  for (int k = 0; k < (DIM == 3 ? S : 1); ++k)
    for (int j = 0; j < S; ++j) {
      const size_t row = (size_t)t.node0[0] + sy * (size_t)j + sz * (size_t)k;
      const double wz = DIM == 3 ? t.w[2][k][0] : 1.0, wyzv = t.w[1][j][0] * (wz * vv[0]);
      for (int i = 0; i < S; ++i) {
        const double wxj = t.w[0][i][0] * vv[1];
        rec[(row + i) * MPMC_NREC + MPMC_VSLOT] += t.w[0][i][0] * wyzv;
        fj[row + i] += (DIM == 3 ? wxj * wz : wxj) * t.w[1][j][0];
      }
    }
}

/* a b + c: in the fma set one fused multiply-add (one rounding), elsewhere a product and a
 * sum.  This file is compiled without contraction in every set (CMakeLists.txt), so that the
 * gather's four-point path and its point-by-point path, which GCC would contract differently,
 * give the same bits; the row sums, most of the gather's arithmetic, fuse explicitly here,
 * alike in both. */
#if defined(MPMC_ISA_FMA) /* MADD4V: a a vector; MADD4: a a scalar */
#define MADD4V(a, b, c) ((mpmc_b4d)_mm256_fmadd_pd((__m256d)(a), (__m256d)(b), (__m256d)(c)))
#define MADD4(a, b, c) MADD4V(_mm256_set1_pd(a), b, c)
#define MADD(a, b, c) __builtin_fma(a, b, c)
#else /* macros: a vector returned by value would change the baseline build's ABI (basis.h) */
#define MADD4V(a, b, c) ((a) * (b) + (c))
#define MADD4(a, b, c) ((a) * (b) + (c))
#define MADD(a, b, c) ((a) * (b) + (c))
#endif

/* cbrt_near1's polynomial in e (e2 = e e), (1 + e/3) + e2 ((-1/9 + 5e/81) + e2 (-10/243 +
 * 22e/729)), for scalars (M = MADD, C(c) = c) and for gather_scale4's vectors (MADD4V, C(c)
 * the vector of c) */
#define CBRT_NEAR1_POLY(e, e2, M, C)                                                          \
  M(e2, M(e2, M(e, C(22.0 / 729.0), C(-10.0 / 243.0)), M(e, C(5.0 / 81.0), C(-1.0 / 9.0))),   \
    M(e, C(1.0 / 3.0), C(1.0)))
#define SCALAR_C(c) (c)
#define VECTOR_C(c) ((mpmc_b4d){c, c, c, c})

/* r^(1/3) for r near 1 (e = r - 1).  |e| < 0.004, the usual case: the Taylor polynomial to
 * e^5 (truncation below 1e-16) in Estrin's form, a short dependency chain; |e| < 0.05:
 * y = r^(-1/3) by Newton's division-free iteration y <- y + y (1 - r y^3) / 3 from
 * 1 - e/3 + 2e^2/9, then r y^2; both within a few ulp (the divisions of a Newton
 * iteration on x^3 = r made a third of the gather's time).  libm's cbrt elsewhere. */
static inline double cbrt_near1(double r) {
  const double e = r - 1.0;
  if (fabs(e) < 0.004) {
    const double e2 = e * e;
    return CBRT_NEAR1_POLY(e, e2, MADD, SCALAR_C);
  }
  if (!(fabs(e) < 0.05)) return cbrt(r);
  double y = 1.0 + e * (-1.0 / 3.0 + e * (2.0 / 9.0));
  for (int i = 0; i < 2; ++i) y += y * (1.0 - r * (y * y * y)) * (1.0 / 3.0);
  return r * y * y;
}

/* Point q's projected Jacobian pi: the factor (pi / (Jbar^n dJ))^(1/dim) of dF (eq 27; the
 * scatter left Jbar^n dJ in Jbar, inv = its reciprocal: taken by the callers before the
 * gather, the division runs beside it instead of after it); keeps pi as Jbar. */
MPMC_ALWAYS_INLINE double projection_scale(mpmc_particles *p, const int DIM, int q, double pi,
                                           double inv) {
  if (p->Jp) pi *= p->Jp[q]; /* the point's own plastic dilation on top of the projection */
  const double r = pi * inv;
  p->Jbar[q] = pi;
  return DIM == 2 ? sqrt(r) : cbrt_near1(r);
}

/* The row sums of the gather: every row of the stencil has the same x-weights and a row's
 * nodes are four contiguous doubles of fbj (those beyond the stencil unused), so
 * acc = sum_k wz_k (sum_j wy_j J_row(j,k)), one multiply-add per row and one per plane of
 * rows, and Pi = sum_i wx_i acc_i (gather_dot); wy, wz the point's 1D weights (ws doubles
 * apart). */
MPMC_ALWAYS_INLINE void gather_rows(const mpmc_grid *g, const double *restrict jb, const int DIM,
                                    const int BASIS, size_t node0, const double *wy,
                                    const double *wz, const int ws, mpmc_b4d *accp) {
  const int S = mpmc_stencil(BASIS);
  const size_t sy = (size_t)g->n[0], sz = (size_t)g->n[0] * (size_t)g->n[1];
  mpmc_b4d acc = {0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < (DIM == 3 ? S : 1); ++k) {
    const double *r = jb + node0 + sz * (size_t)k;
    mpmc_b4d t = wy[0] * *(const mpmc_b4du *)r;
    for (int j = 1; j < S; ++j) t = MADD4(wy[j * ws], *(const mpmc_b4du *)(r + sy * (size_t)j), t);
    if (DIM == 3)
      acc = MADD4(wz[k * ws], t, acc);
    else
      acc = t;
  }
  *accp = acc;
}

/* Pi = sum_i wx_i acc_i, i in order: one point's (wx: its x-weights, ws doubles apart) */
MPMC_ALWAYS_INLINE double gather_dot(const int BASIS, const double *wx, const int ws,
                                     const mpmc_b4d *acc) {
  double pi = wx[0] * (*acc)[0];
  for (int i = 1; i < mpmc_stencil(BASIS); ++i) pi = MADD(wx[i * ws], (*acc)[i], pi);
  return pi;
}

/* Gather point q, at x^n = xs[q] (xs NULL: with the weights G2P kept, transfer.h's
 * mpmc_kept_weights1): Pi = sum w Jbar_i (Algorithm 1, step 4); returns the factor of dF. */
MPMC_ALWAYS_INLINE double gather_scale(mpmc_sim sim, const int DIM, const int BASIS,
                                       const double *xs, int q) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double inv = 1.0 / p->Jbar[q];
  mpmc_pw4 t; /* lane 0 */
  if (xs)
    mpmc_point_weights1(DIM, BASIS, 0, 0, g, xs, p->lp, q, &t);
  else
    mpmc_kept_weights1(DIM, BASIS, g, &sim->fb, p->lp, q, &t);
  mpmc_b4d acc;
  gather_rows(g, sim->fb.fbj, DIM, BASIS, (size_t)t.node0[0], &t.w[1][0][0], &t.w[2][0][0], 4, &acc);
  return projection_scale(p, DIM, q, gather_dot(BASIS, &t.w[0][0][0], 4, &acc), inv);
}

/* The projected Jacobians pi of the four points of t (lanes), each lane with the same
 * operations as one point alone (same bits): the row sums point by point, then, with them
 * transposed, gather_dot as a vector. */
MPMC_ALWAYS_INLINE void gather_pi4(const mpmc_grid *g, const double *restrict jb, const int DIM,
                                   const int BASIS, const mpmc_pw4 *t, mpmc_b4d *pip) {
  mpmc_b4d a[4];
  for (int l = 0; l < 4; ++l)
    gather_rows(g, jb, DIM, BASIS, (size_t)t->node0[l], &t->w[1][0][l], &t->w[2][0][l], 4, &a[l]);
  /* c[i] = (a[0][i], .., a[3][i]): lanes the points, as t's weights */
  mpmc_b4d c[4];
  mpmc_transpose4(a, c);
  const mpmc_b4da *wx = (const mpmc_b4da *)t->w[0];
  mpmc_b4d pi = wx[0] * c[0];
  for (int i = 1; i < mpmc_stencil(BASIS); ++i) pi = MADD4V(wx[i], c[i], pi);
  *pip = pi;
}

/* Points q .. q + 3 from their pi and inv = 1 / (Jbar^n dJ): pi into Jbar, the factors of
 * their dF into scale[0..3]; the reciprocals and the cube roots near 1 as vectors. */
MPMC_ALWAYS_INLINE void gather_finish4(mpmc_particles *p, const int DIM, int q,
                                       const mpmc_b4d *pip, const mpmc_b4d *invp,
                                       double *scale) {
  mpmc_b4d pi = *pip;
  if (p->Jp) pi *= *(const mpmc_b4du *)(p->Jp + q); /* as projection_scale */
  *(mpmc_b4du *)(p->Jbar + q) = pi;
  const mpmc_b4d r = pi * *invp, e = r - 1.0;
  const mpmc_b4l magn = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX}; /* all but the sign */
  const mpmc_b4l small = (mpmc_b4d)((mpmc_b4l)e & magn) < 0.004;       /* |e| < 0.004, not NaN */
#if defined(__AVX__)
  const int all_small = _mm256_movemask_pd((__m256d)small) == 15;
#else
  const int all_small = small[0] & small[1] & small[2] & small[3];
#endif
  if (DIM == 3 && all_small) { /* cbrt_near1's first branch in every lane */
    const mpmc_b4d e2 = e * e;
    *(mpmc_b4du *)scale = CBRT_NEAR1_POLY(e, e2, MADD4V, VECTOR_C);
  } else {
    for (int l = 0; l < 4; ++l) scale[l] = DIM == 2 ? sqrt(r[l]) : cbrt_near1(r[l]);
  }
}

/* gather_scale for the four points q .. q + 3 of t into scale[0..3], each lane with the
 * same operations as one point alone (same bits). */
MPMC_ALWAYS_INLINE void gather_scale4(mpmc_sim sim, const int DIM, const int BASIS,
                                      const mpmc_pw4 *t, int q, double *scale) {
  mpmc_particles *p = &sim->p;
  const mpmc_b4d inv = 1.0 / *(const mpmc_b4du *)(p->Jbar + q);
  mpmc_b4d pi;
  gather_pi4(&sim->grid, sim->fb.fbj, DIM, BASIS, t, &pi);
  gather_finish4(p, DIM, q, &pi, &inv, scale);
}

/* gather_scale4 for the eight points q .. q + 7 of t[0] and t[1]: the two fours' sums side
 * by side, so that the processor works on both dependency chains (weights, row sums, the
 * transpose, the dot) at once; the same operations per point, so the same bits. */
MPMC_ALWAYS_INLINE void gather_scale8(mpmc_sim sim, const int DIM, const int BASIS,
                                      const mpmc_pw4 *t, int q, double *scale) {
  mpmc_particles *p = &sim->p;
  const mpmc_b4d inv0 = 1.0 / *(const mpmc_b4du *)(p->Jbar + q);
  const mpmc_b4d inv1 = 1.0 / *(const mpmc_b4du *)(p->Jbar + q + 4);
  mpmc_b4d pi0, pi1;
  gather_pi4(&sim->grid, sim->fb.fbj, DIM, BASIS, &t[0], &pi0);
  gather_pi4(&sim->grid, sim->fb.fbj, DIM, BASIS, &t[1], &pi1);
  gather_finish4(p, DIM, q, &pi0, &inv0, scale);
  gather_finish4(p, DIM, q + 4, &pi1, &inv1, scale + 4);
}

MPMC_ALWAYS_INLINE void scatter_stable_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  double *restrict fb = sim->fb.fb;
  mpmc_spw sp;
  mpmc_stable_weights(DIM, BASIS, g, p->x + (size_t)q * DIM, &sp);
  const mpmc_v2d vv = scatter_values(sim, DIM, q);
  MPMC_STABLE_LOOP(DIM, BASIS, sp, { MPMC_V2(fb + 2 * node) += w * vv; });
}

MPMC_ALWAYS_INLINE double gather_stable_scale(mpmc_sim sim, const int DIM, const int BASIS,
                                              const double *xs, int q) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double *restrict jb = sim->fb.fbj;
  const double inv = 1.0 / p->Jbar[q];
  mpmc_spw sp;
  mpmc_stable_weights(DIM, BASIS, g, xs + (size_t)q * DIM, &sp);
  double pi = 0.0;
  MPMC_STABLE_LOOP(DIM, BASIS, sp, { pi += w * jb[node]; });
  return projection_scale(p, DIM, q, pi, inv);
}

/* gather_stable_scale for the four points q .. q + 3 (positions xs) into scale[0..3], each
 * lane with the same operations as one point alone (same bits): the weights of the four at
 * once, the sum over each lane's nodes in MPMC_STABLE_LOOP's order, the finish as a vector */
MPMC_ALWAYS_INLINE void gather_stable_scale4(mpmc_sim sim, const int DIM, const int BASIS,
                                             const double *xs, int q, double *scale) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double *restrict jb = sim->fb.fbj;
  const int S = mpmc_stable_stencil(BASIS), idx[4] = {q, q + 1, q + 2, q + 3};
  const mpmc_b4d inv = 1.0 / *(const mpmc_b4du *)(p->Jbar + q);
  mpmc_spw4 sp;
  mpmc_stable_weights4(DIM, BASIS, g, xs, idx, &sp);
  const mpmc_b4da *w0 = (const mpmc_b4da *)sp.w[0], *w1 = (const mpmc_b4da *)sp.w[1],
                  *w2 = (const mpmc_b4da *)sp.w[2];
  const mpmc_b4d one = {1.0, 1.0, 1.0, 1.0};
  mpmc_b4d pi = {0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < (DIM == 3 ? S : 1); ++k)
    for (int j = 0; j < S; ++j) {
      const size_t r = sp.st[1] * (size_t)j + sp.st[2] * (size_t)k;
      const mpmc_b4d wr = w1[j] * (DIM == 3 ? (mpmc_b4d)w2[k] : one);
      for (int i = 0; i < S; ++i) {
        const size_t o = r + sp.st[0] * (size_t)i;
        const mpmc_b4d v = {jb[(size_t)sp.node0[0] + o], jb[(size_t)sp.node0[1] + o],
                            jb[(size_t)sp.node0[2] + o], jb[(size_t)sp.node0[3] + o]};
        pi += (w0[i] * wr) * v;
      }
    }
  gather_finish4(p, DIM, q, &pi, &inv, scale);
}

/* dF-bar = scale dF of point q, in place */
MPMC_ALWAYS_INLINE void scale_dF(mpmc_particles *p, const int DIM, int q, double scale) {
  double *dF = p->dF + (size_t)q * DIM * DIM;
  for (int k = 0; k < DIM * DIM; ++k) dF[k] *= scale;
}

/* the weights of the consecutive points idx[0 .. 3] at xs, or those G2P kept (xs NULL) */
MPMC_ALWAYS_INLINE void gather_weights4(mpmc_sim sim, const int D, const int B, const double *xs,
                                        const int *idx, mpmc_pw4 *t) {
  if (xs)
    mpmc_point_weights4(D, B, 0, 0, &sim->grid, xs, sim->p.lp, idx, t);
  else
    mpmc_kept_weights4(D, B, &sim->grid, &sim->fb, sim->p.lp, idx[0], t);
}

/* one point's factor in either form (ST: the stable one, which takes x^n from xs) */
MPMC_ALWAYS_INLINE double gather_scale1(mpmc_sim sim, const int D, const int B, const int ST,
                                        const double *xs, int q) {
  return ST ? gather_stable_scale(sim, D, B, xs, q) : gather_scale(sim, D, B, xs, q);
}

/* The gather's factors of points q0 .. q1 - 1 at positions xs, or with xs a constant NULL
 * with the weights G2P kept (not in the stable form), into scale[q - q0] (Algorithm 1, step
 * 4): of material id's points (id < 0: of every point; the others' entries and Jbar left
 * alone).  The paper, total and anchored forms eight points at a time where they are all
 * gathered, else four, then one by one, each lane with the operations of gather_scale; the
 * stable form (ST) four at a time, else one by one (gather_stable_scale): the same bits as
 * point by point. */
MPMC_ALWAYS_INLINE void gather_points(mpmc_sim sim, const int D, const int B, const int ST,
                                      const double *xs, int id, int q0, int q1, double *scale) {
  const int *restrict mat = sim->p.mat;
  const int one = id < 0 || sim->nmat == 1; /* every point is gathered */
  int q = q0;
  for (; !ST && one && q + 8 <= q1; q += 8) {
    const int idx[8] = {q, q + 1, q + 2, q + 3, q + 4, q + 5, q + 6, q + 7};
    mpmc_pw4 t[2]; /* the same bits as mpmc_point_weights1 per point */
    gather_weights4(sim, D, B, xs, idx, &t[0]);
    gather_weights4(sim, D, B, xs, idx + 4, &t[1]);
    gather_scale8(sim, D, B, t, q, scale + (q - q0));
  }
  for (; q + 4 <= q1; q += 4) {
    if (!one && mat[q] != id && mat[q + 1] != id && mat[q + 2] != id && mat[q + 3] != id)
      continue;
    if (one || (mat[q] == id && mat[q + 1] == id && mat[q + 2] == id && mat[q + 3] == id)) {
      if (ST) {
        gather_stable_scale4(sim, D, B, xs, q, scale + (q - q0));
      } else {
        const int idx[4] = {q, q + 1, q + 2, q + 3};
        mpmc_pw4 t; /* the same bits as mpmc_point_weights1 per point */
        gather_weights4(sim, D, B, xs, idx, &t);
        gather_scale4(sim, D, B, &t, q, scale + (q - q0));
      }
    } else { /* materials mixed: the others' scale and Jbar left alone */
      for (int l = 0; l < 4; ++l)
        if (mat[q + l] == id) scale[q + l - q0] = gather_scale1(sim, D, B, ST, xs, q + l);
    }
  }
  for (; q < q1; ++q)
    if (one || mat[q] == id) scale[q - q0] = gather_scale1(sim, D, B, ST, xs, q);
}

/* points the gather of the fbar phase takes at a time (the deferred one goes by the batched
 * updates' chunks: batch4.h, fbar_gather_chunk) */
#define GATHER_CHUNK 256

/* The F-bar phase's gather (ST: the stable form's): every point's, at positions XS (x^n; a
 * constant NULL: with the weights G2P kept), GATHER_CHUNK at a time, its dF scaled in place;
 * in the kernels' macro, so that ST and XS reach the OpenMP region as constants (transfer.h,
 * MPMC_KERNELS) */
#define GATHER_CHUNKS(D, B, ST, XS)                                                          \
  do {                                                                                       \
    const int n = sim->p.n, nch = (n + GATHER_CHUNK - 1) / GATHER_CHUNK;                     \
    _Pragma("omp parallel for schedule(static) if (n > MPMC_OMP_MIN)")                       \
    for (int ch = 0; ch < nch; ++ch) {                                                       \
      const int q0 = ch * GATHER_CHUNK, q1 = q0 + GATHER_CHUNK < n ? q0 + GATHER_CHUNK : n;  \
      double scale[GATHER_CHUNK];                                                            \
      gather_points(sim, D, B, ST, XS, -1, q0, q1, scale);                                   \
      for (int q = q0; q < q1; ++q) scale_dF(&sim->p, D, q, scale[q - q0]);                  \
    }                                                                                        \
  } while (0)

/* scatter by the slabs of this step's P2G (positions unchanged since): race-free by parity */
#define FBAR_KERNELS(D, B)                                                                   \
  static void scatter_##D##_##B(mpmc_sim sim) {                                              \
    const int *restrict order = sim->scr.order, *restrict start = sim->scr.slab_start;       \
    for (int colour = 0; colour < 2; ++colour) {                                             \
      _Pragma("omp parallel for schedule(static, 1) num_threads(sim->scr.slab_nt) if (sim->p.n > MPMC_OMP_MIN)") \
      MPMC_SLABS_OF(sim, colour, sl)                                                         \
        for (int k = start[sl]; k < start[sl + 1]; ++k) scatter_point(sim, D, B, order[k]);  \
    }                                                                                        \
  }                                                                                          \
  /* xs NULL: with the weights G2P kept */                                                   \
  static void gather_##D##_##B(mpmc_sim sim, const double *xs) {                             \
    if (xs)                                                                                  \
      GATHER_CHUNKS(D, B, 0, xs);                                                            \
    else                                                                                     \
      GATHER_CHUNKS(D, B, 0, (const double *)NULL);                                          \
  }                                                                                          \
  static void gather_stable_##D##_##B(mpmc_sim sim, const double *xs) {                      \
    GATHER_CHUNKS(D, B, 1, xs);                                                              \
  }                                                                                          \
  /* the deferred gather of points q0 .. q1 - 1 of material id (after G2P: x^n in xn, or the \
   * weights at x^n kept) */                                                                 \
  static void gather_range_##D##_##B(mpmc_sim sim, int id, int q0, int q1, double *scale) {  \
    if (sim->cfg.fbar == MPMC_FBAR_STABLE)                                                   \
      gather_points(sim, D, B, 1, sim->fb.xn, id, q0, q1, scale);                             \
    else                                                                                     \
      gather_points(sim, D, B, 0, (const double *)NULL, id, q0, q1, scale);                  \
  }                                                                                          \
  /* the stable form's supports reach no further than the cubic B-spline's (nodes c - 1 ..  \
   * c + 2 of a point in cell c): the slabs keep same-coloured ones apart all the same */    \
  static void scatter_stable_##D##_##B(mpmc_sim sim) {                                       \
    const int *restrict order = sim->scr.order, *restrict start = sim->scr.slab_start;       \
    for (int colour = 0; colour < 2; ++colour) {                                             \
      _Pragma("omp parallel for schedule(static, 1) num_threads(sim->scr.slab_nt) if (sim->p.n > MPMC_OMP_MIN)") \
      MPMC_SLABS_OF(sim, colour, sl)                                                         \
        for (int k = start[sl]; k < start[sl + 1]; ++k)                                      \
          scatter_stable_point(sim, D, B, order[k]);                                         \
    }                                                                                        \
  }
MPMC_KERNELS(FBAR_KERNELS)

/** Phase 4 of the step (only with F-bar on).  The nodes it touches: the active box, which
 * holds every point's support in every form (the cubic B-spline's reach, c - 1 .. c + 2, is
 * the widest; the stable form's spaces reach no further; t302 checks it).
 * defer: the step's call.  When every material's update runs the gather itself
 * (ops->gathers_fbar: every built-in model, not a user material), the gather is left to it
 * (sim->fb.deferred; stress_j2.c, stress_blocks.c's MPMC_BLOCKS): each thread gathers its
 * points' factors into sim->fb.scale (allocated here) just before it updates
 * them, and the update scales dF as it loads it, so dF is read once and written never
 * instead of read, scaled, written and read again (the landslide's points do not fit in the
 * cache: a pass less over 311,250 of them).  Same bits either way. */
int MPMC_ISA(mpmc_fbar)(mpmc_sim sim, int defer) {
  mpmc_grid *g = &sim->grid;
  const int stable = sim->cfg.fbar == MPMC_FBAR_STABLE;
  for (int m = 0; m < sim->nmat && defer; ++m) defer = sim->mats[m].ops->gathers_fbar;
  /* x^n: after G2P, which has moved the points, as it kept it (xn, or the weights: NULL) */
  mpmc_fbar_state *f = &sim->fb;
  const double *xs = !f->scattered ? sim->p.x : stable ? f->xn : NULL;
  if (!f->scattered) { /* called on its own, not after a step's G2P: scatter here */
    mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_VOLUMES);
    if (stable)
      MPMC_KERNEL_CALL(scatter_stable_, sim, sim);
    else
      MPMC_KERNEL_CALL(scatter_, sim, sim);
  }
  f->scattered = 0;
  /* nodal volume average (Algorithm 1 step 3) into fbj, row by row: (V J)_i from fb's pairs
   * (stable form) or fbj itself, V_i from fb or the records */
  const long nrow = mpmc_grid_active_rows(g);
  const long box = (long)(g->act_hi[0] - g->act_lo[0]);
  const double *restrict fb = f->fb, *restrict rec = g->node;
#pragma omp parallel for schedule(static) if (nrow * box > MPMC_OMP_MIN)
  for (long r = 0; r < nrow; ++r) {
    size_t len;
    const size_t first = mpmc_grid_active_row(g, r, &len);
    double *fj = f->fbj + first;
    if (stable) {
      const double *f = fb + 2 * first;
      for (size_t i = 0; i < len; ++i) fj[i] = f[2 * i] > 0.0 ? f[2 * i + 1] / f[2 * i] : 0.0;
    } else {
      const double *v = rec + first * MPMC_NREC + MPMC_VSLOT;
      for (size_t i = 0; i < len; ++i) {
        const double vi = v[i * MPMC_NREC];
        fj[i] = vi > 0.0 ? fj[i] / vi : 0.0;
      }
    }
  }
  if (defer && sim->p.n > f->cap_scale) {
    double *a = realloc(f->scale, sizeof(double) * (size_t)sim->p.n);
    MPMC_CHECK(a, sim->ctx, MPMC_ERR_MEMORY, "cannot allocate F-bar's factors of %d points",
               sim->p.n);
    f->scale = a;
    f->cap_scale = sim->p.n;
  }
  f->deferred = defer;
  if (defer)
    ; /* the material update gathers (mpmc_fbar_gather_range) into f->scale */
  else if (stable)
    MPMC_KERNEL_CALL(gather_stable_, sim, sim, xs);
  else
    MPMC_KERNEL_CALL(gather_, sim, sim, xs);
  return MPMC_SUCCESS;
}

/* The deferred gather (sim->fb.deferred) of material id's points among q0 .. q1 - 1: their
 * projected Jacobians into Jbar, and into scale[q - q0] the factor of their dF (eq 27), which
 * the caller applies as it loads dF; the other points' entries are left alone. */
void MPMC_ISA(mpmc_fbar_gather_range)(mpmc_sim sim, int id, int q0, int q1, double *scale) {
  MPMC_KERNEL_CALL(gather_range_, sim, sim, id, q0, q1, scale);
}

#if defined(MPMC_ISA_BASELINE) /* F-bar's state: once, not per instruction set */
/* Free *a and set it NULL. */
static void drop(void *a) {
  void **pa = a;
  free(*pa);
  *pa = NULL;
}

/* The state's arrays for the sim's form, and the points' Jbar and, for the anchored form,
 * Janc (anchored to the Jbar at hand); what the form does not use freed.  Without F-bar the
 * materials integrate the points' own dF, so Jbar, which no step then updates, is freed as
 * well: F-bar switched on (with the run or again later) starts from Jbar = J, the Jacobian
 * the material state has (a Jbar kept from before the switch off projected the volume change
 * of the steps without F-bar a second time, a jump in the volumetric strain). */
int mpmc_fbar_prepare(mpmc_sim sim) {
  mpmc_context ctx = sim->ctx;
  mpmc_particles *p = &sim->p;
  mpmc_fbar_state *f = &sim->fb;
  const int form = sim->cfg.fbar, stable = form == MPMC_FBAR_STABLE;
  if (form && !p->Jbar) {
    MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->Jbar, 1, 1.0));
    for (int q = 0; q < p->n; ++q) p->Jbar[q] = p->J[q];
  }
  if (form == MPMC_FBAR_ANCHORED && !p->Janc) {
    MPMC_CALL(mpmc_particles_ensure(ctx, p, &p->Janc, 1, 1.0));
    memcpy(p->Janc, p->Jbar, sizeof(double) * (size_t)p->n);
  } else if (form != MPMC_FBAR_ANCHORED) {
    drop(&p->Janc);
  }
  if (f->nn != sim->grid.nn || !form) { /* a new grid (or none needed): new sums */
    drop(&f->fb);
    drop(&f->fbj);
    drop(&f->priv);
    f->cap_priv = 0;
    f->nn = 0;
  }
  if (!stable) drop(&f->fb);
  if (!stable) drop(&f->xn);
  if (!form || stable) {
    drop(&f->xoff);
    drop(&f->xnode);
  }
  if (!form) {
    drop(&p->Jbar);
    drop(&f->scale);
    f->cap_scale = 0;
    f->cap = 0;
    f->scattered = f->deferred = 0;
    return MPMC_SUCCESS;
  }
  const size_t nn = sim->grid.nn;
  if (stable) MPMC_CALL(mpmc_grid_array(ctx, &f->fb, nn * 2));
  MPMC_CALL(mpmc_grid_array(ctx, &f->fbj, nn + 4)); /* the gather reads 4 from a row start */
  f->nn = nn;
  mpmc_fbar_clear(sim, MPMC_FBAR_CLEAR_ALL); /* a grid set anew has its active box anew */
  if ((stable && !f->xn) || (!stable && !f->xoff)) f->cap = 0; /* the form's kept arrays anew */
  return mpmc_fbar_reserve(sim);
}

/* Grow *a to n entries of size bytes (contents not kept: scratch within a step). */
static int regrow(mpmc_context ctx, void *a, size_t n, size_t size) {
  void **pa = a;
  free(*pa);
  *pa = malloc(n * size);
  MPMC_CHECK(*pa, ctx, MPMC_ERR_MEMORY, "cannot allocate F-bar's arrays for %zu points", n);
  return MPMC_SUCCESS;
}

int mpmc_fbar_reserve(mpmc_sim sim) {
  mpmc_fbar_state *f = &sim->fb;
  const int cap = sim->p.cap;
  if (!sim->cfg.fbar || f->cap >= cap) return MPMC_SUCCESS;
  const size_t d = (size_t)sim->cfg.dim, n = (size_t)cap;
  if (sim->cfg.fbar == MPMC_FBAR_STABLE) {
    MPMC_CALL(regrow(sim->ctx, &f->xn, d * n, sizeof(double)));
  } else {
    MPMC_CALL(regrow(sim->ctx, &f->xoff, d * n, sizeof(double)));
    MPMC_CALL(regrow(sim->ctx, &f->xnode, n, sizeof(int)));
  }
  f->cap = cap;
  return MPMC_SUCCESS;
}

/* Zero the sums, and with the points' volumes too (vslot: the records' MPMC_VSLOT, which P2G
 * fills in a step), over the active box's rows, on all threads; every form's supports lie
 * in the box (t302). */
static void clear_rows(mpmc_sim sim, int vslot) {
  mpmc_grid *g = &sim->grid;
  double *node = g->node, *fb = sim->fb.fb, *fbj = sim->fb.fbj;
  const long nrow = mpmc_grid_active_rows(g);
  const long box = (long)(g->act_hi[0] - g->act_lo[0]);
#pragma omp parallel for schedule(static) if (nrow * box > MPMC_OMP_MIN)
  for (long r = 0; r < nrow; ++r) {
    size_t len;
    const size_t first = mpmc_grid_active_row(g, r, &len);
    if (vslot)
      for (size_t i = first; i < first + len; ++i) node[i * MPMC_NREC + MPMC_VSLOT] = 0.0;
    if (fb) memset(fb + first * 2, 0, len * 2 * sizeof(double));
    if (fbj) memset(fbj + first, 0, len * sizeof(double));
  }
}

void mpmc_fbar_clear(mpmc_sim sim, int what) {
  mpmc_fbar_state *f = &sim->fb;
  if (what == MPMC_FBAR_CLEAR_ALL) {
    if (f->fb) memset(f->fb, 0, f->nn * 2 * sizeof(double));
    if (f->fbj) memset(f->fbj, 0, f->nn * sizeof(double));
  } else if (f->fbj) {
    clear_rows(sim, what == MPMC_FBAR_CLEAR_VOLUMES);
  }
  f->scattered = 0;
}

void mpmc_fbar_free(mpmc_sim sim) {
  mpmc_fbar_state *f = &sim->fb;
  drop(&f->fb);
  drop(&f->fbj);
  drop(&f->priv);
  drop(&f->xn);
  drop(&f->xoff);
  drop(&f->xnode);
  drop(&f->scale);
  memset(f, 0, sizeof *f);
}
#endif
