/* Shared pieces of the particle-grid transfers, instantiated per (dim, basis) at compile
 * time: each phase writes one always-inline per-point body taking DIM and BASIS as constants
 * and a loop macro that MPMC_KERNELS expands once for each of the eight combinations. */
#ifndef MPMC_TRANSFER_H
#define MPMC_TRANSFER_H

#include "basis.h"
#include "mpmc_impl.h"

/* GCC cannot see that mpmc_basis_1d fills exactly the stencil that the loops read. */
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

/* The 1D weights and gradients of four points, lanes the points: w[a][k][l] of point l's
 * k-th stencil node along axis a (so a point's weights lie MPMC_PW4_AXIS doubles apart
 * between axes and 4 apart between nodes), node0 each point's first stencil node; off[a][l]
 * (where asked for) point l's offset along axis a from which the basis gives its weights
 * (basis.h, mpmc_poly_at and mpmc_ugimp_at). */
typedef struct {
  double w[3][MPMC_MAX_STENCIL][4] __attribute__((aligned(32)));
  double dw[3][MPMC_MAX_STENCIL][4] __attribute__((aligned(32)));
  double off[3][4] __attribute__((aligned(32)));
  long long node0[4];
} mpmc_pw4;
#define MPMC_PW4_AXIS (MPMC_MAX_STENCIL * 4)

/* The weights of points idx[0..3] at x (GRAD = 0: w alone; OFF = 1: and their offsets):
 * per axis one evaluation for the four, the same operations per lane as mpmc_point_weights1
 * for one point (the same bits).  A batch of fewer points repeats one of them. */
MPMC_ALWAYS_INLINE void mpmc_point_weights4(const int DIM, const int BASIS, const int GRAD,
                                            const int OFF, const mpmc_grid *g, const double *x,
                                            const double *lp, const int *idx, mpmc_pw4 *t) {
  mpmc_b4i b[3] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
  const size_t i0 = (size_t)idx[0] * DIM, i1 = (size_t)idx[1] * DIM, i2 = (size_t)idx[2] * DIM,
               i3 = (size_t)idx[3] * DIM;
  for (int a = 0; a < DIM; ++a) {
    const mpmc_b4d xv = {x[i0 + a], x[i1 + a], x[i2 + a], x[i3 + a]};
    const mpmc_b4d s = (xv - g->origin[a]) * g->inv_h;
    if (BASIS == MPMC_BASIS_UGIMP) {
      const mpmc_b4d lv = (mpmc_b4d){lp[idx[0]], lp[idx[1]], lp[idx[2]], lp[idx[3]]} * g->inv_h;
      mpmc_ugimp_axes(&s, &lv, g->inv_h, &b[a], (mpmc_b4da *)t->w[a],
                      GRAD ? (mpmc_b4da *)t->dw[a] : NULL, OFF ? (mpmc_b4da *)t->off[a] : NULL);
    } else {
      mpmc_poly_lanes(BASIS, &s, g->inv_h, &b[a], (mpmc_b4da *)t->w[a],
                      GRAD ? (mpmc_b4da *)t->dw[a] : NULL, OFF ? (mpmc_b4da *)t->off[a] : NULL);
    }
  }
  /* the linear indices, in 32 bits (the grid has at most 2^31 nodes: mpmc_grid_setup) */
  typedef unsigned u4 __attribute__((vector_size(4 * sizeof(unsigned))));
  const u4 nd = (u4)b[0] + (unsigned)g->n[0] * ((u4)b[1] + (unsigned)g->n[1] * (u4)b[2]) -
                (unsigned)g->lin; /* the held nodes' (grid.off), modulo 2^32 */
  const mpmc_b4l ni = __builtin_convertvector(nd, mpmc_b4l);
  memcpy(t->node0, &ni, sizeof ni);
}

/* Lane 0 of t: the weights of point q alone (GRAD = 0: w alone; OFF = 1: and its offsets),
 * axis by axis in scalars (mpmc_basis_1d: the same bits as a lane of mpmc_point_weights4).
 * For G2P's linear basis (MPMC_BATCHES4) and F-bar's single points (fbar.c). */
MPMC_ALWAYS_INLINE void mpmc_point_weights1(const int DIM, const int BASIS, const int GRAD,
                                            const int OFF, const mpmc_grid *g, const double *x,
                                            const double *lp, int q, mpmc_pw4 *t) {
  size_t node0 = 0, stride = 1;
  for (int a = 0; a < DIM; ++a) {
    int b;
    double w[MPMC_MAX_STENCIL], dw[MPMC_MAX_STENCIL];
    mpmc_basis_1d_off(BASIS, (x[(size_t)q * DIM + a] - g->origin[a]) * g->inv_h,
                      BASIS == MPMC_BASIS_UGIMP ? lp[q] * g->inv_h : 0.0, g->inv_h, &b, w, dw,
                      OFF ? &t->off[a][0] : NULL);
    for (int k = 0; k < mpmc_stencil(BASIS); ++k) {
      t->w[a][k][0] = w[k];
      if (GRAD) t->dw[a][k][0] = dw[k];
    }
    node0 += stride * (size_t)b;
    stride *= (size_t)g->n[a];
  }
  t->node0[0] = (long long)node0 - g->lin;
}

/* Runs body with point q and its weights, lane l of t, for the points order[k] (order NULL:
 * k), k0 <= k < k1: in batches of four (mpmc_point_weights4; the last batch repeats its last
 * point as needed, the repeats' weights computed, not used), or, if ONE, one by one
 * (mpmc_point_weights1, l = 0).  G2P takes the linear basis's one by one: batched, its
 * point body took 10 instructions more, the weights saving 1 (P2G's, batched, save 5).
 * KEEP = 1 (G2P with F-bar's paper, total and anchored forms): the points' weights are kept
 * where kp says for the gather (mpmc_keep_weights) before the body runs. */
#define MPMC_BATCHES4(ONE, DIM, BASIS, GRAD, KEEP, kp, g, x, lp, order, k0, k1, q, l, t, body) \
  if (ONE) {                                                                                \
    for (int kb_ = (k0); kb_ < (k1); ++kb_) {                                               \
      const int q = (order) ? (order)[kb_] : kb_, l = 0;                                    \
      mpmc_pw4 t;                                                                           \
      mpmc_point_weights1(DIM, BASIS, GRAD, KEEP, g, x, lp, q, &t);                         \
      if (KEEP) mpmc_keep_weights(DIM, kp, &t, &q, 1, 0);                                   \
      body;                                                                                 \
    }                                                                                       \
  } else                                                                                    \
    for (int kb_ = (k0); kb_ < (k1); kb_ += 4) {                                            \
      const int nb_ = (k1) - kb_ < 4 ? (k1) - kb_ : 4;                                      \
      int idx_[4];                                                                          \
      for (int l_ = 0; l_ < 4; ++l_) {                                                      \
        const int k_ = kb_ + (l_ < nb_ ? l_ : nb_ - 1);                                     \
        idx_[l_] = (order) ? (order)[k_] : k_;                                              \
      }                                                                                     \
      mpmc_pw4 t;                                                                           \
      mpmc_point_weights4(DIM, BASIS, GRAD, KEEP, g, x, lp, idx_, &t);                      \
      if (KEEP) mpmc_keep_weights(DIM, kp, &t, idx_, nb_, !(order));                        \
      for (int l = 0; l < nb_; ++l) {                                                       \
        const int q = idx_[l];                                                              \
        body;                                                                               \
      }                                                                                     \
    }

/* Vectors of doubles (GCC/Clang vector extension) for the node records: the per-node updates
 * are then whole-vector operations without relying on the auto-vectoriser finding them.
 * MPMC_VW doubles wide: 2 (SSE2, any x86-64) unless the build enables AVX (e.g. -march=
 * x86-64-v3), then 4.  Memory is accessed through MPMC_V(p), an unaligned, aliasing lvalue at
 * p (MPMC_VC: read-only). */
#if defined(__AVX__)
#define MPMC_VW 4
#else
#define MPMC_VW 2
#endif
typedef double mpmc_vd __attribute__((vector_size(MPMC_VW * sizeof(double))));
typedef double mpmc_v2d __attribute__((vector_size(2 * sizeof(double))));
/* the same, for access to memory: no alignment beyond a double's, aliasing doubles */
typedef double mpmc_vdu
    __attribute__((vector_size(MPMC_VW * sizeof(double)), aligned(8), may_alias));
typedef double mpmc_v2du __attribute__((vector_size(2 * sizeof(double)), aligned(8), may_alias));
/* four doubles at any double's address, aliasing (rows of a stencil's scalar node values) */
typedef double mpmc_b4du __attribute__((vector_size(4 * sizeof(double)), aligned(8), may_alias));
/* four ints at any int's address, aliasing */
typedef int mpmc_b4iu __attribute__((vector_size(4 * sizeof(int)), aligned(4), may_alias));
#define MPMC_V(p) (*(mpmc_vdu *)(p))
#define MPMC_VC(p) (*(const mpmc_vdu *)(p))
#define MPMC_V2(p) (*(mpmc_v2du *)(p))
/* a vector of record slots VW k .. VW k + VW - 1, F(slot) giving each slot's value */
#if MPMC_VW == 4
#define MPMC_VSET(F, k) ((mpmc_vd){F(4 * (k)), F(4 * (k) + 1), F(4 * (k) + 2), F(4 * (k) + 3)})
#else
#define MPMC_VSET(F, k) ((mpmc_vd){F(2 * (k)), F(2 * (k) + 1)})
#endif
/* vectors per record, and those of its mass-momentum half */
#define MPMC_NV (MPMC_NREC / MPMC_VW)
#define MPMC_NC (MPMC_FOFF / MPMC_VW)

/* F-bar's gather (fbar.c) takes the weights of the points at x^n from what G2P kept of them
 * (g2p.c, MPMC_BATCHES4's KEEP): their offsets (axis a's at f->xoff + a f->cap) and first
 * nodes (f->xnode); lp the points' uGIMP half-lengths.  mpmc_kept_weights4: points q .. q + 3,
 * lanes; mpmc_kept_weights1: point q, lane 0.  The same bits as each other, and the weights
 * the basis gives at those offsets. */
MPMC_ALWAYS_INLINE void mpmc_kept_weights4(const int DIM, const int BASIS, const mpmc_grid *g,
                                           const mpmc_fbar_state *f, const double *lp, int q,
                                           mpmc_pw4 *t) {
  for (int a = 0; a < DIM; ++a) {
    const mpmc_b4d off = *(const mpmc_b4du *)(f->xoff + (size_t)a * (size_t)f->cap + (size_t)q);
    if (BASIS == MPMC_BASIS_UGIMP) {
      const mpmc_b4d lv = *(const mpmc_b4du *)(lp + q) * g->inv_h;
      mpmc_ugimp_at(&off, &lv, g->inv_h, (mpmc_b4da *)t->w[a], NULL);
    } else {
      mpmc_poly_at(BASIS, &off, g->inv_h, (mpmc_b4da *)t->w[a], NULL);
    }
  }
  const mpmc_b4l ni = __builtin_convertvector(*(const mpmc_b4iu *)(f->xnode + q), mpmc_b4l);
  memcpy(t->node0, &ni, sizeof ni);
}
MPMC_ALWAYS_INLINE void mpmc_kept_weights1(const int DIM, const int BASIS, const mpmc_grid *g,
                                           const mpmc_fbar_state *f, const double *lp, int q,
                                           mpmc_pw4 *t) {
  for (int a = 0; a < DIM; ++a) {
    double w[MPMC_MAX_STENCIL];
    mpmc_basis_1d_at(BASIS, f->xoff[(size_t)a * (size_t)f->cap + (size_t)q],
                     BASIS == MPMC_BASIS_UGIMP ? lp[q] * g->inv_h : 0.0, w);
    for (int k = 0; k < mpmc_stencil(BASIS); ++k) t->w[a][k][0] = w[k];
  }
  t->node0[0] = f->xnode[q];
}

/* Where G2P keeps the weights for F-bar's gather (above): F-bar's xoff, axis by axis, and
 * xnode, taken once before a kernel's loops */
typedef struct {
  double *off[3];
  int *node;
} mpmc_keep;
MPMC_ALWAYS_INLINE mpmc_keep mpmc_keep_of(const mpmc_fbar_state *f, int dim) {
  const size_t cap = (size_t)f->cap;
  mpmc_keep k = {{NULL, NULL, NULL}, f->xnode};
  for (int a = 0; a < dim && f->xoff; ++a) k.off[a] = f->xoff + (size_t)a * cap;
  return k;
}

/* What G2P keeps for the gather of the points idx[0 .. nb - 1], t's lanes (SEQ: consecutive
 * points, a batch of four stored as whole vectors). */
MPMC_ALWAYS_INLINE void mpmc_keep_weights(const int DIM, const mpmc_keep *k, const mpmc_pw4 *t,
                                          const int *idx, int nb, const int SEQ) {
  if (SEQ && nb == 4) {
    for (int a = 0; a < DIM; ++a)
      *(mpmc_b4du *)(k->off[a] + idx[0]) = *(const mpmc_b4da *)t->off[a];
    mpmc_b4l n0;
    memcpy(&n0, t->node0, sizeof n0);
    *(mpmc_b4iu *)(k->node + idx[0]) = __builtin_convertvector(n0, mpmc_b4iu);
  } else {
    for (int l = 0; l < nb; ++l) {
      for (int a = 0; a < DIM; ++a) k->off[a][idx[l]] = t->off[a][l];
      k->node[idx[l]] = (int)t->node0[l];
    }
  }
}

/* det of a dim x dim row-major matrix (the relative deformation gradient) */
MPMC_ALWAYS_INLINE double mpmc_det_dim(const int DIM, const double *F) {
  return DIM == 2 ? F[0] * F[3] - F[1] * F[2]
                  : F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
                        F[2] * (F[3] * F[7] - F[4] * F[6]);
}

/* How fast F-bar's anchored form re-anchors a point (docs/theory.md): the share
 * alpha = (|dJ - 1| + |v^n|_1 dt / h) / MPMC_ANCHOR_STRAIN of the way per step (at most all of
 * it), by the change of volume the point undergoes and the cells it travels, not by the number
 * of steps: what drifts in a flow is the points' J, as they change volume and cross cells, and
 * a point that does neither keeps its anchor.  1e-2: the self-weight column settles within
 * 0.1 % of the total form's settlement; the dam break and the landslides follow Algorithm 1
 * (docs/theory.md). */
#define MPMC_ANCHOR_STRAIN 1e-2

/* F-bar's anchored form (fbar.c): point q's anchored Jacobian Janc (J times the Jbar / J it
 * was last anchored to) carried by this step's dJ and re-anchored to Algorithm 1's
 * jd = Jbar^n dJ by the share alpha of the step (travel = |v^n|_1 dt / h, the sum of the
 * magnitudes of the point's velocity components before G2P's update, which loads them once
 * for both: g2p.c; a square root a point, the Euclidean norm, cost G2P 4 %):
 * Janc <- Janc dJ + alpha (jd - Janc dJ).  alpha = 1 is Algorithm 1 (it projects jd),
 * alpha = 0 the projection of J calibrated by the point's last anchoring.  Returns Janc, the
 * value the point scatters.  (The magnitude of the whole strain increment in place of dJ's
 * cost G2P a quarter more: its sum stood between the point's gather and its scatter.) */
MPMC_ALWAYS_INLINE double mpmc_anchor(mpmc_particles *p, int q, double dJ, double jd,
                                      double travel) {
  const double r = (fabs(dJ - 1.0) + travel) * (1.0 / MPMC_ANCHOR_STRAIN);
  const double alpha = r < 1.0 ? r : 1.0, carried = p->Janc[q] * dJ;
  return p->Janc[q] = carried + alpha * (jd - carried);
}

/* What point q scatters as V^n j in the forms that project onto the basis: ANC (the anchored
 * form, a constant in G2P's kernels) its anchored Jacobian, else Jbar^n dJ = jd in Algorithm 1
 * (MPMC_FBAR_PAPER) or J^{n+1} in the total form. */
MPMC_ALWAYS_INLINE double mpmc_fbar_j(const int ANC, int fbar, mpmc_particles *p, int q,
                                      double dJ, double jd, double travel) {
  return ANC ? mpmc_anchor(p, q, dJ, jd, travel) : fbar == MPMC_FBAR_PAPER ? jd : p->J[q];
}

/* ---- the J-bar space of the stable form of F-bar (fbar.c, fused into g2p.c) ---------- */
/* Nodes per axis in a point's support in the J-bar space of the stable form. */
MPMC_ALWAYS_INLINE int mpmc_stable_stencil(const int BASIS) { return BASIS == MPMC_BASIS_BSPLINE3 ? 3 : 2; }

/* The stable form's space along one axis.  Linear, uGIMP: hats of spacing 2h on the grid
 * nodes of the parity of lo's (x = lo, lo + 2h, ...); quadratic B-splines: hats of spacing h
 * centred on the cells (the hat at lo + (k + 1/2) h kept in node k); cubic: quadratic
 * B-splines centred on the cells, kept likewise.  Each is a basis of this file's
 * (mpmc_stable_basis) of unit spacing at the argument MPMC_STABLE_ARG of s = (x - origin)/h;
 * that basis's first node b is the grid node MPMC_STABLE_NODE(b), and its next ones follow
 * mpmc_stable_step grid nodes apart.  The macros take scalars and vectors alike
 * (mpmc_stable_1d, mpmc_stable_weights4: the same operations). */
MPMC_ALWAYS_INLINE int mpmc_stable_hats2h(const int BASIS) {
  return BASIS == MPMC_BASIS_LINEAR || BASIS == MPMC_BASIS_UGIMP;
}
MPMC_ALWAYS_INLINE int mpmc_stable_basis(const int BASIS) {
  return BASIS == MPMC_BASIS_BSPLINE3 ? MPMC_BASIS_BSPLINE2 : MPMC_BASIS_LINEAR;
}
MPMC_ALWAYS_INLINE int mpmc_stable_step(const int BASIS) { return mpmc_stable_hats2h(BASIS) ? 2 : 1; }
#define MPMC_STABLE_ARG(BASIS, s) \
  (mpmc_stable_hats2h(BASIS) ? 0.5 * ((s) - MPMC_GHOST % 2) : (s) - 0.5)
#define MPMC_STABLE_NODE(BASIS, b) (mpmc_stable_hats2h(BASIS) ? MPMC_GHOST % 2 + 2 * (b) : (b))

/* 1D weights w of the stable form's space at s = (x - origin)/h: *base is the grid node that
 * stores the first of its nodes, the return value the step in grid nodes to the next one. */
MPMC_ALWAYS_INLINE int mpmc_stable_1d(const int BASIS, double s, int *base, double *w) {
  double dw[3];
  int b;
  mpmc_basis_1d(mpmc_stable_basis(BASIS), MPMC_STABLE_ARG(BASIS, s), 0.0, 1.0, &b, w, dw);
  *base = MPMC_STABLE_NODE(BASIS, b);
  return mpmc_stable_step(BASIS);
}

typedef struct {
  size_t node0;  /* grid node of the support's first node      */
  size_t st[3];  /* step in node index to the next node per axis */
  double w[3][3];
} mpmc_spw;

MPMC_ALWAYS_INLINE void mpmc_stable_weights(const int DIM, const int BASIS, const mpmc_grid *g,
                                       const double *x, mpmc_spw *sp) {
  size_t node0 = 0, str = 1;
  sp->st[1] = sp->st[2] = 0;
  for (int a = 0; a < DIM; ++a) {
    int b;
    const int k = mpmc_stable_1d(BASIS, (x[a] - g->origin[a]) * g->inv_h, &b, sp->w[a]);
    node0 += str * (size_t)b;
    sp->st[a] = str * (size_t)k;
    str *= (size_t)g->n[a];
  }
  sp->node0 = node0 - (size_t)g->lin;
}

/* mpmc_stable_weights of the four points idx[0..3] at x, lanes the points: per axis one
 * evaluation of mpmc_stable_1d's basis for the four (mpmc_poly_lanes: the same operations per
 * lane as mpmc_basis_1d, so the same bits); w[a][k][l] the weight of lane l's k-th node along
 * axis a, node0[l] its first node, st[a] the step in node index along axis a (the lanes'
 * alike). */
typedef struct {
  double w[3][3][4] __attribute__((aligned(32)));
  long long node0[4];
  size_t st[3];
} mpmc_spw4;
MPMC_ALWAYS_INLINE void mpmc_stable_weights4(const int DIM, const int BASIS, const mpmc_grid *g,
                                             const double *x, const int *idx, mpmc_spw4 *sp) {
  mpmc_b4l node0 = {0, 0, 0, 0};
  size_t str = 1;
  sp->st[1] = sp->st[2] = 0;
  for (int a = 0; a < DIM; ++a) {
    const mpmc_b4d xv = {x[(size_t)idx[0] * DIM + a], x[(size_t)idx[1] * DIM + a],
                         x[(size_t)idx[2] * DIM + a], x[(size_t)idx[3] * DIM + a]};
    const mpmc_b4d s = (xv - g->origin[a]) * g->inv_h, sh = MPMC_STABLE_ARG(BASIS, s);
    mpmc_b4i b;
    mpmc_poly_lanes(mpmc_stable_basis(BASIS), &sh, 1.0, &b, (mpmc_b4da *)sp->w[a], NULL, NULL);
    b = MPMC_STABLE_NODE(BASIS, b);
    node0 += (long long)str * __builtin_convertvector(b, mpmc_b4l);
    sp->st[a] = str * (size_t)mpmc_stable_step(BASIS);
    str *= (size_t)g->n[a];
  }
  node0 -= g->lin;
  memcpy(sp->node0, &node0, sizeof node0);
}

/* The support of point q in the stable space: the body sees `node` and its weight `w`. */
#define MPMC_STABLE_LOOP(DIM, BASIS, sp, ...)                                                   \
  do {                                                                                     \
    const int S_ = mpmc_stable_stencil(BASIS);                                                  \
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

/* The eight (dim, basis) instances.  A kernel's loop, with its OpenMP pragma, is written in a
 * macro X(D, B) expanded by MPMC_KERNELS with literal constants: GCC outlines OpenMP regions
 * before inlining, so constants passed into a function holding the pragma would reach the
 * outlined loop as run-time values and the basis switch would stay in the hot loop. */
#define MPMC_KERNELS(X) X(2, 0) X(2, 1) X(2, 2) X(2, 3) X(3, 0) X(3, 1) X(3, 2) X(3, 3)

/* Call fn##D##_##B(args...) for the simulation's dimension and basis.  The switch key is
 * unique for every (dim, basis) pair, whatever bases are added (dim < 4); a new basis needs
 * its instances in MPMC_KERNELS and its cases here (the assertion below is the reminder). */
#define MPMC_DIM_BASIS(d, b) ((b) * 4 + (d))
_Static_assert(MPMC_BASIS_BSPLINE3 == 3, "a new basis: add its kernel instances and cases");
#define MPMC_KERNEL_CALL(fn, sim, ...)                                  \
  do {                                                                  \
    switch (MPMC_DIM_BASIS((sim)->cfg.dim, (sim)->cfg.basis)) {         \
      case MPMC_DIM_BASIS(2, 0): fn##2_0(__VA_ARGS__); break;           \
      case MPMC_DIM_BASIS(2, 1): fn##2_1(__VA_ARGS__); break;           \
      case MPMC_DIM_BASIS(2, 2): fn##2_2(__VA_ARGS__); break;           \
      case MPMC_DIM_BASIS(2, 3): fn##2_3(__VA_ARGS__); break;           \
      case MPMC_DIM_BASIS(3, 0): fn##3_0(__VA_ARGS__); break;           \
      case MPMC_DIM_BASIS(3, 1): fn##3_1(__VA_ARGS__); break;           \
      case MPMC_DIM_BASIS(3, 2): fn##3_2(__VA_ARGS__); break;           \
      default: fn##3_3(__VA_ARGS__); break; /* MPMC_DIM_BASIS(3, 3) */  \
    }                                                                   \
  } while (0)

#endif
