/* The F-bar projection (paper Algorithm 1, eqs 19-27), run only when enabled:
 *   scatter  V_i = sum w V_p,  (V J)_i = sum w V_p j_p                          (step 3)
 *   gather   Pi_p = sum w Jbar_i,  dFbar = (Pi_p / (Jbar_p^n dJ_p))^(1/dim) dF (step 4)
 * with j_p = Jbar_p^n dJ_p in MPMC_FBAR_PAPER (eq 26, Algorithm 1 as published) and
 * j_p = J_p^{n+1} = det F in MPMC_FBAR_TOTAL (eqs 18-21: the projection of the Jacobian
 * itself, inserted in eq 25).  The paper's recursion re-projects Jbar every step, so in a
 * long quasi-static run the smoothing of a non-uniform Jbar near boundaries accumulates
 * into a creep of the true volume (docs/theory.md); the total form has no such memory.
 * MPMC_FBAR_STABLE projects det F like the total form, but onto a space one order below
 * the basis instead of the basis itself (docs/theory.md, "The J-bar space"): linear hats on
 * the grid of spacing 2h (nodes x = lo, lo + 2h, ...) for linear and uGIMP, linear hats
 * centred on the cells for quadratic B-splines, quadratic B-splines centred on the cells for
 * cubic ones.  With w the weights of that space the formulas above are unchanged.
 * V_p is the volume at t^n.  In a step the scatter runs fused into G2P (which has the
 * weights at x^n at hand and sets grid.fb_done), except in the stable form, whose weights
 * G2P does not have; called on its own (tests), or in the stable form, the projection
 * scatters here, recovering V_p as V0 J^{n+1} / dJ (G2P has already updated J).  The scatter
 * leaves Jbar^n dJ in Jbar for the gather, which replaces it with Pi.
 * Touches nothing but dF (handed to the material), Jbar and the grid's fb. */
#include <math.h>
#include <string.h>

#include "transfer.h"

/* Scatter point q: V^n and V^n j onto its nodes (Algorithm 1, step 3). */
MPMC_ALWAYS_INLINE void scatter_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  mpmc_grid *g = &sim->grid;
  const mpmc_particles *p = &sim->p;
  const int S = mpmc_stencil(BASIS);
  double *restrict fb = g->fb;
  mpmc_pw pw;
  mpmc_point_weights(DIM, BASIS, g, p->x + (size_t)q * DIM,
                     BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
  const double dJ = mpmc_det_dim(DIM, p->dF + (size_t)q * DIM * DIM);
  const double Vn = p->vol0[q] * p->J[q] / dJ;
  const double jd = p->Jbar[q] * dJ;
  const double val = sim->fbar == MPMC_FBAR_TOTAL ? p->J[q] : jd;
  p->Jbar[q] = jd; /* until the gather: Jbar^n dJ, the denominator of eq 27 */
  const double Vv = Vn * val;
  const mpmc_v2d vv = {Vn, Vv};
  MPMC_ROW_LOOP(DIM, BASIS, g, pw, {
    const mpmc_v2d cv = wyz * vv;
    double *restrict r = fb + row * 2;
    for (int i = 0; i < S; ++i) MPMC_V2(r + 2 * i) += pw.w[0][i] * cv;
  });
}

/* r^(1/3) for r near 1 (e = r - 1).  |e| < 0.004, the usual case: the Taylor polynomial to
 * e^5 (truncation below 1e-16) in Estrin's form, a short dependency chain; |e| < 0.05:
 * y = r^(-1/3) by Newton's division-free iteration y <- y + y (1 - r y^3) / 3 from
 * 1 - e/3 + 2e^2/9, then r y^2; both within a few ulp (the divisions of a Newton
 * iteration on x^3 = r made a third of the gather's time).  libm's cbrt elsewhere. */
static inline double cbrt_near1(double r) {
  const double e = r - 1.0;
  if (fabs(e) < 0.004) {
    const double e2 = e * e;
    return (1.0 + e * (1.0 / 3.0)) +
           e2 * ((-1.0 / 9.0 + e * (5.0 / 81.0)) + e2 * (-10.0 / 243.0 + e * (22.0 / 729.0)));
  }
  if (!(fabs(e) < 0.05)) return cbrt(r);
  double y = 1.0 + e * (-1.0 / 3.0 + e * (2.0 / 9.0));
  for (int i = 0; i < 2; ++i) y += y * (1.0 - r * (y * y * y)) * (1.0 / 3.0);
  return r * y * y;
}

/* Gather point q: Pi = sum w Jbar_i, scale dF (Algorithm 1, step 4). */
MPMC_ALWAYS_INLINE void gather_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const int S = mpmc_stencil(BASIS);
  const double *restrict fb = g->fb;
  mpmc_pw pw;
  mpmc_point_weights(DIM, BASIS, g, p->x + (size_t)q * DIM,
                     BASIS == MPMC_BASIS_UGIMP ? p->lp[q] : 0.0, &pw);
  double pi = 0.0;
  MPMC_ROW_LOOP(DIM, BASIS, g, pw, {
    const double *restrict r = fb + row * 2 + 1;
    double sr = 0.0;
    for (int i = 0; i < S; ++i) sr += pw.w[0][i] * r[2 * i];
    pi += wyz * sr;
  });
  double *dF = p->dF + (size_t)q * DIM * DIM;
  const double r = pi / p->Jbar[q]; /* the scatter left Jbar^n dJ there */
  const double scale = DIM == 2 ? sqrt(r) : cbrt_near1(r);
  for (int k = 0; k < DIM * DIM; ++k) dF[k] *= scale;
  p->Jbar[q] = pi;
}

/* ---- the stable form's J-bar space ---------------------------------------------------- */
/* Nodes per axis in a point's support in the J-bar space of the stable form. */
MPMC_ALWAYS_INLINE int stable_stencil(const int BASIS) { return BASIS == MPMC_BASIS_BSPLINE3 ? 3 : 2; }

/* 1D weights w of the stable form's space at s = (x - origin)/h: *base is the grid node that
 * stores the first of its nodes, the return value the step in grid nodes to the next one.
 * Linear, uGIMP: hats of spacing 2h on the grid nodes of the parity of lo's (x = lo, lo + 2h,
 * ...); quadratic B-splines: hats of spacing h centred on the cells (the hat at lo + (k + 1/2)
 * h kept in node k); cubic: quadratic B-splines centred on the cells, kept likewise. */
MPMC_ALWAYS_INLINE int stable_1d(const int BASIS, double s, int *base, double *w) {
  double dw[3];
  int b;
  if (BASIS == MPMC_BASIS_LINEAR || BASIS == MPMC_BASIS_UGIMP) {
    const int par = MPMC_GHOST % 2; /* node of x = lo */
    mpmc_basis_1d(MPMC_BASIS_LINEAR, 0.5 * (s - par), 0.0, 1.0, &b, w, dw);
    *base = par + 2 * b;
    return 2;
  }
  mpmc_basis_1d(BASIS == MPMC_BASIS_BSPLINE3 ? MPMC_BASIS_BSPLINE2 : MPMC_BASIS_LINEAR, s - 0.5,
                0.0, 1.0, &b, w, dw);
  *base = b;
  return 1;
}

typedef struct {
  size_t node0;  /* grid node of the support's first node      */
  size_t st[3];  /* step in node index to the next node per axis */
  double w[3][3];
} stable_pw;

MPMC_ALWAYS_INLINE void stable_weights(const int DIM, const int BASIS, const mpmc_grid *g,
                                       const double *x, stable_pw *sp) {
  size_t node0 = 0, str = 1;
  sp->st[1] = sp->st[2] = 0;
  for (int a = 0; a < DIM; ++a) {
    int b;
    const int k = stable_1d(BASIS, (x[a] - g->origin[a]) * g->inv_h, &b, sp->w[a]);
    node0 += str * (size_t)b;
    sp->st[a] = str * (size_t)k;
    str *= (size_t)g->n[a];
  }
  sp->node0 = node0;
}

/* The support of point q in the stable space: the body sees `node` and its weight `w`. */
#define STABLE_LOOP(DIM, BASIS, sp, ...)                                                   \
  do {                                                                                     \
    const int S_ = stable_stencil(BASIS);                                                  \
    for (int k_ = 0; k_ < (DIM == 3 ? S_ : 1); ++k_)                                       \
      for (int j_ = 0; j_ < S_; ++j_) {                                                    \
        const size_t r_ = (sp).node0 + (sp).st[1] * (size_t)j_ + (sp).st[2] * (size_t)k_;  \
        const double wr_ = (sp).w[1][j_] * (DIM == 3 ? (sp).w[2][k_] : 1.0);               \
        for (int i_ = 0; i_ < S_; ++i_) {                                                  \
          const size_t node = r_ + (sp).st[0] * (size_t)i_;                                \
          const double w = (sp).w[0][i_] * wr_;                                            \
          __VA_ARGS__                                                                      \
        }                                                                                  \
      }                                                                                    \
  } while (0)

MPMC_ALWAYS_INLINE void scatter_stable_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  double *restrict fb = g->fb;
  stable_pw sp;
  stable_weights(DIM, BASIS, g, p->x + (size_t)q * DIM, &sp);
  const double dJ = mpmc_det_dim(DIM, p->dF + (size_t)q * DIM * DIM);
  const double Vn = p->vol0[q] * p->J[q] / dJ;
  p->Jbar[q] *= dJ; /* until the gather: Jbar^n dJ, the denominator of eq 27 */
  const mpmc_v2d vv = {Vn, Vn * p->J[q]};
  STABLE_LOOP(DIM, BASIS, sp, { MPMC_V2(fb + 2 * node) += w * vv; });
}

MPMC_ALWAYS_INLINE void gather_stable_point(mpmc_sim sim, const int DIM, const int BASIS, int q) {
  const mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const double *restrict fb = g->fb;
  stable_pw sp;
  stable_weights(DIM, BASIS, g, p->x + (size_t)q * DIM, &sp);
  double pi = 0.0;
  STABLE_LOOP(DIM, BASIS, sp, { pi += w * fb[2 * node + 1]; });
  double *dF = p->dF + (size_t)q * DIM * DIM;
  const double r = pi / p->Jbar[q];
  const double scale = DIM == 2 ? sqrt(r) : cbrt_near1(r);
  for (int k = 0; k < DIM * DIM; ++k) dF[k] *= scale;
  p->Jbar[q] = pi;
}

/* scatter by the slabs of this step's P2G (positions unchanged since): race-free by parity */
#define FBAR_KERNELS(D, B)                                                                   \
  static void scatter_##D##_##B(mpmc_sim sim) {                                              \
    const int *restrict order = sim->order, *restrict start = sim->slab_start;               \
    for (int colour = 0; colour < 2; ++colour) {                                             \
      _Pragma("omp parallel for schedule(dynamic, 1) if (sim->p.n > MPMC_OMP_MIN)")          \
      for (int sl = colour; sl < sim->nslab; sl += 2)                                        \
        for (int k = start[sl]; k < start[sl + 1]; ++k) scatter_point(sim, D, B, order[k]);  \
    }                                                                                        \
  }                                                                                          \
  static void gather_##D##_##B(mpmc_sim sim) {                                               \
    _Pragma("omp parallel for schedule(static) if (sim->p.n > MPMC_OMP_MIN)")                \
    for (int q = 0; q < sim->p.n; ++q) gather_point(sim, D, B, q);                           \
  }                                                                                          \
  /* the stable form's supports reach one node past the basis' (cubic's reach): the slabs,  \
   * three cells wide at least, keep same-coloured ones apart all the same */                \
  static void scatter_stable_##D##_##B(mpmc_sim sim) {                                       \
    const int *restrict order = sim->order, *restrict start = sim->slab_start;               \
    for (int colour = 0; colour < 2; ++colour) {                                             \
      _Pragma("omp parallel for schedule(dynamic, 1) if (sim->p.n > MPMC_OMP_MIN)")          \
      for (int sl = colour; sl < sim->nslab; sl += 2)                                        \
        for (int k = start[sl]; k < start[sl + 1]; ++k)                                      \
          scatter_stable_point(sim, D, B, order[k]);                                         \
    }                                                                                        \
  }                                                                                          \
  static void gather_stable_##D##_##B(mpmc_sim sim) {                                        \
    _Pragma("omp parallel for schedule(static) if (sim->p.n > MPMC_OMP_MIN)")                \
    for (int q = 0; q < sim->p.n; ++q) gather_stable_point(sim, D, B, q);                    \
  }
MPMC_KERNELS(FBAR_KERNELS)

/* The stable form: its supports reach at most one node beyond the active box per axis (the
 * ghost layers hold them); the nodes it touches are cleared, summed, averaged and read. */
static void fbar_stable(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  int lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  for (int a = 0; a < sim->dim; ++a) {
    lo[a] = g->act_lo[a] > 0 ? g->act_lo[a] - 1 : 0;
    hi[a] = g->act_hi[a] < g->n[a] ? g->act_hi[a] + 1 : g->n[a];
  }
  if (hi[0] <= lo[0] || g->act_hi[0] <= g->act_lo[0]) return;
  const long ny = hi[1] - lo[1], nrow = ny * (hi[2] - lo[2]);
  const size_t len = (size_t)(hi[0] - lo[0]);
  double *restrict fb = g->fb;
#define ROW(r) (fb + 2 * ((size_t)lo[0] + (size_t)g->n[0] * ((size_t)(lo[1] + (r) % ny) +             \
                                                            (size_t)g->n[1] * (size_t)(lo[2] + (r) / ny))))
  for (long r = 0; r < nrow; ++r) memset(ROW(r), 0, len * 2 * sizeof(double));
  MPMC_KERNEL_CALL(scatter_stable_, sim, sim);
#pragma omp parallel for schedule(static) if (nrow * (long)len > MPMC_OMP_MIN)
  for (long r = 0; r < nrow; ++r) {
    double *f = ROW(r);
    for (size_t i = 0; i < 2 * len; i += 2) f[i + 1] = f[i] > 0.0 ? f[i + 1] / f[i] : 0.0;
  }
#undef ROW
  MPMC_KERNEL_CALL(gather_stable_, sim, sim);
}

/** Phase 4 of the step (only with F-bar on). */
int MPMC_ISA(mpmc_fbar)(mpmc_sim sim) {
  mpmc_grid *g = &sim->grid;
  if (sim->fbar == MPMC_FBAR_STABLE) {
    g->fb_done = 0;
    fbar_stable(sim);
    double *t = sim->p.x;
    sim->p.x = sim->p.xn;
    sim->p.xn = t;
    return MPMC_SUCCESS;
  }
  /* the active box, row by row (the points' stencils lie in it) */
  const long nrow = mpmc_grid_active_rows(g);
  const size_t len = (size_t)(g->act_hi[0] - g->act_lo[0]);
  double *restrict fb = g->fb;
  if (!g->fb_done) { /* called on its own, not after a step's G2P: scatter here */
    for (long r = 0; r < nrow; ++r)
      memset(fb + mpmc_grid_active_row(g, r) * 2, 0, len * 2 * sizeof(double));
    MPMC_KERNEL_CALL(scatter_, sim, sim);
  }
  g->fb_done = 0;
  /* nodal volume average (Algorithm 1 step 3) */
#pragma omp parallel for schedule(static) if (nrow * (long)len > MPMC_OMP_MIN)
  for (long r = 0; r < nrow; ++r) {
    double *f = fb + mpmc_grid_active_row(g, r) * 2;
    for (size_t i = 0; i < 2 * len; i += 2) f[i + 1] = f[i] > 0.0 ? f[i + 1] / f[i] : 0.0;
  }
  MPMC_KERNEL_CALL(gather_, sim, sim);
  /* the projection used the weights at x^n; now the points move (eq 17) */
  double *t = sim->p.x;
  sim->p.x = sim->p.xn;
  sim->p.xn = t;
  return MPMC_SUCCESS;
}
