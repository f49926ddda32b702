/* Grid to particle: velocity with the FLIP/PIC blend (eqs 11-13), relative deformation
 * gradient dF = 1 + dt sum v_i (x) grad w (eq 16), J <- J det(dF) so that V = J V0 (eq 15),
 * position (eq 17), in place.  With F-bar the projection's gather, in the material update,
 * still needs the weights at x^n: in the paper, total and anchored forms G2P keeps them, as
 * the offsets from which the basis gives them and the first nodes (xoff, xnode: transfer.h,
 * mpmc_keep_weights), in the stable form, whose space has weights of its own, the old
 * positions (xn).  The projection's scatter (fbar.c) is fused in here, where those weights
 * are at hand (in the paper, total and anchored forms only of V^n j: P2G scattered V^n,
 * p2g.c). */
#include <limits.h>
#include <math.h>

#include "transfer.h"
#if defined(__AVX2__)
#include <immintrin.h>
#endif

typedef struct {
  double eta;             /* FLIP/PIC blend                                             */
  double travel_scale;    /* dt / h, once a step: the anchored form's travel per |v^n|_1  */
  double *xold;           /* with F-bar's stable form xn, which gets x^n for the gather  */
  double xmin[3], xmax[3];/* points may drift up to one cell beyond the box (walls act on
                             the nodes there); further out the support leaves the grid   */
} g2p_ctx;

/* F-bar's scatter along a stencil row: f[i] += v[i], i < S, as whole vectors (the lanes'
 * sums are the scalar ones).  Three nodes: with WIDE all four lanes (v[3] = 0 adds nothing
 * to a node that no other thread writes meanwhile: fb_scatter), else AVX2's masked load and
 * store, which leave the fourth node alone, else two plus one. */
MPMC_ALWAYS_INLINE void fb_row(const int S, const int WIDE, double *restrict f,
                               const mpmc_b4d *vp) { /* by pointer: basis.h, mpmc_floor4 */
  const mpmc_b4d v = *vp;
  if (S == 2) {
    MPMC_V2(f) += (mpmc_v2d){v[0], v[1]};
  } else if (S == 4 || WIDE) {
    *(mpmc_b4du *)f += v;
  } else {
#if defined(__AVX2__)
    const __m256i m3 = _mm256_set_epi64x(0, -1, -1, -1);
    _mm256_maskstore_pd(f, m3, _mm256_add_pd(_mm256_maskload_pd(f, m3), (__m256d)v));
#else
    MPMC_V2(f) += (mpmc_v2d){v[0], v[1]};
    f[2] += v[2];
#endif
  }
}

/* Algorithm 1 step 3's scatter of V^n j (vj) into fbj with a point's weights W (lane of a
 * mpmc_pw4, node k of axis a at W[MPMC_PW4_AXIS a + 4 k]) from node0:
 * fbj_i += ((w_x vj) w_z) w_y, per plane of rows the x-weights times vj times w_z as one
 * vector, then per row one vector multiply and add (fbar.c's scatter_point the same).
 * WIDE: rows of three nodes as four (the fourth plus 0), where the node after a row is
 * written by this thread alone: with slabs across y or z that node lies in the row's plane,
 * one of this slab's, which no point of a slab of the same colour reaches; it is in the same
 * grid row (a stencil ends at least one node before a row's last ghost node). */
MPMC_ALWAYS_INLINE void fb_scatter(const int DIM, const int BASIS, const int WIDE,
                                   const mpmc_grid *g, double *restrict fb, const double *W,
                                   size_t node0, double vj) {
  const int S = mpmc_stencil(BASIS), AX = MPMC_PW4_AXIS;
  const size_t sy = (size_t)g->n[0], sz = (size_t)g->n[0] * (size_t)g->n[1];
  const mpmc_b4d wxv = (mpmc_b4d){W[0], W[4], S > 2 ? W[8] : 0.0, S > 3 ? W[12] : 0.0} * vj;
  double *f = fb + node0;
  for (int k = 0; k < (DIM == 3 ? S : 1); ++k, f += sz) {
    const mpmc_b4d wzv = DIM == 3 ? wxv * W[2 * AX + 4 * k] : wxv;
    double *r = f;
    for (int j = 0; j < S; ++j, r += sy) {
      const mpmc_b4d add = wzv * W[AX + 4 * j];
      fb_row(S, WIDE, r, &add);
    }
  }
}

/* Gather point q; returns 0 if its volume inverted or it left the grid.  The sums over the
 * stencil's node records are factored by axis (rows along x, then planes, then z; below),
 * all whole-vector multiply-adds in record layout; the components are picked out once.
 * FB = 1 (3: in rows of four, fb_scatter): also scatter V^n j of Algorithm 1 step 3 into fb
 * (F-bar's fbj, one value per node) with the same weights (the points are still at x^n;
 * V^n itself P2G scattered into the records' MPMC_VSLOT); FB = 2 (the stable form): scatter
 * V^n and V^n J into fb (F-bar's fb, pairs) with the weights of its own space
 * (transfer.h); either way the caller runs the points in slab colours.  FB + 4 (5, 7): FB's
 * scatter in the anchored form, j the point's anchored Jacobian (transfer.h, mpmc_anchor),
 * a kernel of its own so that the other forms do not pay for it. */
MPMC_ALWAYS_INLINE int g2p_point(mpmc_sim sim, const int DIM, const int BASIS, const int FB,
                                 double dt, const g2p_ctx *c, double *restrict fb, int q,
                                 const mpmc_pw4 *t, int l, double *v2max) {
  mpmc_grid *g = &sim->grid;
  mpmc_particles *p = &sim->p;
  const int R = MPMC_NREC, S = mpmc_stencil(BASIS), NV = MPMC_NV, NC = MPMC_NC, AX = MPMC_PW4_AXIS;
  const double *restrict rec = g->node;
  const size_t qd = (size_t)q * DIM, node0 = (size_t)t->node0[l];
  const double *W = &t->w[0][0][l], *DW = &t->dw[0][0][l]; /* node k, axis a: [AX a + 4 k] */
  const mpmc_vd zero = {0.0}; /* the other lanes zero as well */
  /* With 2-wide vectors the whole record's sums and accumulators (16 vectors) overflow the
   * 16 SSE registers: the first sweep then takes the velocity half (v_pic, L) and the second
   * the increment half (dv).  The fused F-bar scatter, which needs dJ, has a loop of its own. */
  const int SPLIT = NC > 1, N1 = SPLIT ? NC : NV;
  mpmc_vd A[MPMC_NV], B0[MPMC_NC], B1[MPMC_NC], B2[MPMC_NC];
  for (int k = 0; k < NV; ++k) A[k] = zero;
  for (int k = 0; k < NC; ++k) B0[k] = B1[k] = B2[k] = zero;
  /* Sums factored by axis: per row along x sw = sum_i w_x rec, sd = sum_i w_x' rec; per
   * plane of rows (one in 2D) P = sum_j w_y sw, Pd = sum_j w_y sd, Py = sum_j w_y' sw; then
   *   (v_pic, dv) += w_z P,  L_a. += (w_z Pd_va, w_z Py_va, w_z' P_va).
   * In 2D w_z = 1 and the sums are those of a row-by-row loop, bit for bit. */
  const size_t sy = (size_t)g->n[0], sz = (size_t)g->n[0] * (size_t)g->n[1];
  for (int kz = 0; kz < (DIM == 3 ? S : 1); ++kz) {
    mpmc_vd P[MPMC_NV], Pd[MPMC_NC], Py[MPMC_NC];
    for (int k = 0; k < N1; ++k) P[k] = zero;
    for (int k = 0; k < NC; ++k) Pd[k] = Py[k] = zero;
    for (int j = 0; j < S; ++j) {
      mpmc_vd sw[MPMC_NV], sd[MPMC_NC];
      for (int k = 0; k < N1; ++k) sw[k] = zero;
      for (int k = 0; k < NC; ++k) sd[k] = zero;
      const double *restrict r = rec + (node0 + sy * (size_t)j + sz * (size_t)kz) * R;
      for (int i = 0; i < S; ++i) {
        const double wx = W[4 * i], dx = DW[4 * i];
        const double *ri = r + i * R;
        for (int k = 0; k < N1; ++k) sw[k] += wx * MPMC_VC(ri + MPMC_VW * k);
        for (int k = 0; k < NC; ++k) sd[k] += dx * MPMC_VC(ri + MPMC_VW * k);
      }
      const double wy = W[AX + 4 * j], dy = DW[AX + 4 * j];
      for (int k = 0; k < N1; ++k) P[k] += wy * sw[k];
      for (int k = 0; k < NC; ++k) {
        Pd[k] += wy * sd[k];
        Py[k] += dy * sw[k];
      }
    }
    if (DIM == 3) {
      const double wz = W[2 * AX + 4 * kz], dz = DW[2 * AX + 4 * kz];
      for (int k = 0; k < N1; ++k) A[k] += wz * P[k];
      for (int k = 0; k < NC; ++k) {
        B0[k] += wz * Pd[k];
        B1[k] += wz * Py[k];
        B2[k] += dz * P[k];
      }
    } else {
      for (int k = 0; k < N1; ++k) A[k] += P[k];
      for (int k = 0; k < NC; ++k) {
        B0[k] += Pd[k];
        B1[k] += Py[k];
      }
    }
  }
  /* B_b = (., L_.b) in record slots */
  double L[3][3];
  for (int i = 0; i < DIM; ++i) {
    const int sv = 1 + i;
    L[i][0] = B0[sv / MPMC_VW][sv % MPMC_VW];
    L[i][1] = B1[sv / MPMC_VW][sv % MPMC_VW];
    if (DIM == 3) L[i][2] = B2[sv / MPMC_VW][sv % MPMC_VW];
  }
  double *dF = p->dF + (size_t)q * DIM * DIM;
  for (int a = 0; a < DIM; ++a)
    for (int b = 0; b < DIM; ++b) dF[a * DIM + b] = (a == b) + dt * L[a][b];
  const double dJ = mpmc_det_dim(DIM, dF);
  const double Jn = p->J[q];
  p->J[q] = Jn * dJ;
  int ok = dJ > 0.0 && isfinite(dJ);
  mpmc_v2d vv = {0.0, 0.0};
  const int FS = FB & 3; /* the scatter's form */
  double *v = p->v + qd, vn[3] = {0.0, 0.0, 0.0}; /* v^n */
  if (FB) {
    const double Vn = p->vol0[q] * Jn;
    const double jd = p->Jbar[q] * dJ; /* kept for the gather (fbar.c) */
    double travel = 0.0; /* the anchored form's |v^n|_1 dt / h (transfer.h, mpmc_anchor) */
    if (FB & 4) { /* v^n loaded here once, for the travel and the velocity's update below
                   * (read on its own ahead of the gather, the travel took 17 instructions a
                   * point; moved with the scatter after the update, it cost the gather's
                   * sums registers: 8 instructions more) */
      for (int a = 0; a < DIM; ++a) vn[a] = v[a];
      double s = fabs(vn[0]) + fabs(vn[1]);
      if (DIM == 3) s += fabs(vn[2]);
      travel = s * c->travel_scale; /* dt h^-1 taken once a step: the same product */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
      /* the product as it was when read ahead of the gather, in a block of its own: not fused
       * into the share's sum (mpmc_anchor) by the contracting kernel sets, same bits */
      __asm__("" : "+x"(travel));
#endif
    }
    vv = (mpmc_v2d){Vn, Vn * mpmc_fbar_j(FB & 4, sim->cfg.fbar, p, q, dJ, jd, travel)};
    if (p->Jp) vv[1] /= p->Jp[q]; /* the volume change that is not plastic (fbar.c) */
    p->Jbar[q] = jd;
  }
  const double vj = vv[1];
  if (FS == 2) {
    mpmc_spw sp;
    mpmc_stable_weights(DIM, BASIS, g, p->x + qd, &sp);
    MPMC_STABLE_LOOP(DIM, BASIS, sp, { MPMC_V2(fb + 2 * node) += w * vv; });
  }
  if (FS == 1 || FS == 3) fb_scatter(DIM, BASIS, FS == 3, g, fb, W, node0, vj);
  if (SPLIT) /* the increment half, factored as above */
    for (int kz = 0; kz < (DIM == 3 ? S : 1); ++kz) {
      mpmc_vd P[MPMC_NV];
      for (int k = N1; k < NV; ++k) P[k] = zero;
      for (int j = 0; j < S; ++j) {
        mpmc_vd sw[MPMC_NV];
        for (int k = N1; k < NV; ++k) sw[k] = zero;
        const double *restrict r = rec + (node0 + sy * (size_t)j + sz * (size_t)kz) * R;
        for (int i = 0; i < S; ++i) {
          const double wx = W[4 * i];
          for (int k = N1; k < NV; ++k) sw[k] += wx * MPMC_VC(r + i * R + MPMC_VW * k);
        }
        for (int k = N1; k < NV; ++k) P[k] += W[AX + 4 * j] * sw[k];
      }
      for (int k = N1; k < NV; ++k) A[k] += (DIM == 3 ? W[2 * AX + 4 * kz] : 1.0) * P[k];
    }
  /* A = (., v_pic | dv) */
  double vpic[3], dv[3];
  for (int i = 0; i < DIM; ++i) {
    const int sv = 1 + i, sf = MPMC_FOFF + i;
    vpic[i] = A[sv / MPMC_VW][sv % MPMC_VW];
    dv[i] = A[sf / MPMC_VW][sf % MPMC_VW];
  }
  const double eta = c->eta, pic = 1.0 - eta; /* in registers: v and xold might alias c */
  double v2 = 0.0; /* |v|^2 summed as stability.c's pass sums it */
  for (int a = 0; a < DIM; ++a) {
    const double va = eta * ((FB & 4 ? vn[a] : v[a]) + dv[a]) + pic * vpic[a];
    v[a] = va;
    v2 += va * va;
    const double x0 = p->x[qd + a], xa = x0 + dt * vpic[a];
    if (FS == 2) c->xold[qd + a] = x0;
    p->x[qd + a] = xa;
    ok &= (xa >= c->xmin[a]) & (xa <= c->xmax[a]);
  }
  *v2max = v2 > *v2max ? v2 : *v2max; /* NaN skipped, as there */
  return ok;
}


/* Without F-bar the points run in index order, split evenly among the threads; with it by
 * the slabs of this step's P2G (positions unchanged since) in two colours, so that the
 * fused scatter is race-free (through the slab order, or by index where the points are stored
 * in that order, sim->scr.order_ident: the same sequence, 7 instructions a point fewer on the
 * linear column), or, when P2G scattered into one grid per thread, in P2G's
 * chunks, each thread scattering into its own copy of fb.  The scatter's form FB (g2p_point)
 * is chosen outside the loops: one form per loop body keeps the gather's sums in registers
 * (with the three forms inlined into one loop GCC spilled some, 15 instructions a point). */
#define G2P_CHUNKS(D, B, FBV)                                                                 \
  do {                                                                                        \
    const size_t per = sim->grid.nn * (size_t)((FBV) == 2 ? 2 : 1);                           \
    _Pragma("omp parallel for schedule(static, 1) reduction(min : first_bad) reduction(max : v2m) num_threads(nc)") \
    for (int t = 0; t < nc; ++t) {                                                            \
      double *f_ = t ? fbp + per * (size_t)(t - 1) : fb0;                                     \
      const int k1_ = mpmc_chunk_start(sim->p.n, t + 1, nc);                                  \
      MPMC_BATCHES4(B == MPMC_BASIS_LINEAR, D, B, 1, (FBV) != 2, &keep, &sim->grid,           \
                    sim->p.x, sim->p.lp, order, mpmc_chunk_start(sim->p.n, t, nc), k1_, q, l, \
                    w4,                                                                       \
                    if (!g2p_point(sim, D, B, FBV, dt, c, f_, q, &w4, l, &v2m) &&             \
                        q < first_bad) first_bad = q);                                        \
    }                                                                                         \
  } while (0)
#define G2P_SLABS_BY(D, B, FBV, ORD)                                                          \
  do {                                                                                        \
    for (int colour = 0; colour < 2; ++colour) {                                              \
      _Pragma("omp parallel for schedule(static, 1) num_threads(sim->scr.slab_nt) reduction(min : first_bad) reduction(max : v2m) if (sim->p.n > MPMC_OMP_MIN)") \
      MPMC_SLABS_OF(sim, colour, sl)                                                          \
        MPMC_BATCHES4(B == MPMC_BASIS_LINEAR, D, B, 1, (FBV) != 2, &keep, &sim->grid,         \
                      sim->p.x, sim->p.lp, ORD, start[sl], start[sl + 1], q, l, w4,           \
                      if (!g2p_point(sim, D, B, FBV, dt, c, fb0, q, &w4, l, &v2m) &&          \
                          q < first_bad) first_bad = q);                                      \
    }                                                                                         \
  } while (0)
/* the slab order, or index order where that is the same sequence (sim->scr.order_ident) */
#define G2P_SLABS(D, B, FBV)                                                                  \
  do {                                                                                        \
    if (sim->scr.order_ident)                                                                 \
      G2P_SLABS_BY(D, B, FBV, (const int *)NULL);                                             \
    else                                                                                      \
      G2P_SLABS_BY(D, B, FBV, order);                                                         \
  } while (0)
#define G2P_KERNEL(D, B)                                                                      \
  static void g2p_##D##_##B(mpmc_sim sim, double dt, const g2p_ctx *c, int *bad, double *vm) { \
    int first_bad = INT_MAX;                                                                  \
    double v2m = 0.0;                                                                         \
    const int nc = sim->p.n > MPMC_OMP_MIN ? mpmc_max_threads() : 1; /* chunks */            \
    _Pragma("omp parallel for schedule(static, 1) reduction(min : first_bad) reduction(max : v2m) num_threads(nc)") \
    for (int t = 0; t < nc; ++t)                                                              \
      MPMC_BATCHES4(B == MPMC_BASIS_LINEAR, D, B, 1, 0, NULL, &sim->grid, sim->p.x,           \
                    sim->p.lp, (const int *)NULL, mpmc_chunk_start(sim->p.n, t, nc),          \
                    mpmc_chunk_start(sim->p.n, t + 1, nc), q, l, w4,                          \
                    if (!g2p_point(sim, D, B, 0, dt, c, NULL, q, &w4, l, &v2m) &&             \
                        q < first_bad) first_bad = q);                                        \
    *bad = first_bad == INT_MAX ? -1 : first_bad;                                             \
    *vm = v2m;                                                                                \
  }                                                                                           \
  static void g2pfb_##D##_##B(mpmc_sim sim, double dt, const g2p_ctx *c, double *fbp, int nc, \
                              int *bad, double *vm) {                                         \
    const int *restrict order = sim->scr.order, *restrict start = sim->scr.slab_start;        \
    const int stable = sim->cfg.fbar == MPMC_FBAR_STABLE, anc = sim->cfg.fbar == MPMC_FBAR_ANCHORED; \
    const mpmc_keep keep = mpmc_keep_of(&sim->fb, D);                                         \
    double *fb0 = stable ? sim->fb.fb : sim->fb.fbj;                                          \
    int first_bad = INT_MAX;                                                                  \
    double v2m = 0.0;                                                                         \
    if (fbp) { /* P2G's chunks, each scattering into its own copy (p2g.c) */                  \
      if (stable)                                                                             \
        G2P_CHUNKS(D, B, 2);                                                                  \
      else if (anc)                                                                           \
        G2P_CHUNKS(D, B, 5);                                                                  \
      else                                                                                    \
        G2P_CHUNKS(D, B, 1);                                                                  \
    } else if (stable) {                                                                      \
      G2P_SLABS(D, B, 2);                                                                     \
    } else if (sim->scr.slab_axis != 0) { /* rows along x lie within a slab: fb_scatter's WIDE */ \
      if (anc)                                                                                \
        G2P_SLABS(D, B, 7);                                                                   \
      else                                                                                    \
        G2P_SLABS(D, B, 3);                                                                   \
    } else if (anc) {                                                                         \
      G2P_SLABS(D, B, 5);                                                                     \
    } else {                                                                                  \
      G2P_SLABS(D, B, 1);                                                                     \
    }                                                                                         \
    *bad = first_bad == INT_MAX ? -1 : first_bad;                                             \
    *vm = v2m;                                                                                \
  }
MPMC_KERNELS(G2P_KERNEL)

static int report(mpmc_sim sim, int q) {
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const double *x = p->x + (size_t)q * d; /* where it went */
  const double *dF = p->dF + (size_t)q * d * d;
  const double dJ = d == 2 ? mpmc_det_dim(2, dF) : mpmc_det_dim(3, dF);
  char nb[MPMC_POINT_NAME_LEN];
  mpmc_point_name(p, q, nb);
  if (!(p->J[q] > 0.0) || !isfinite(p->J[q]))
    return MPMC_ERROR(sim->ctx, MPMC_ERR_NUMERIC,
                      "step %lld, t = %g: point %s at (%g, %g, %g) inverted or lost its volume "
                      "(J = %g%s): reduce the time step",
                      (long long)sim->stats.steps, sim->time, nb, x[0], x[1], d == 3 ? x[2] : 0.0,
                      p->J[q], dJ <= 0 ? ", dJ <= 0" : "");
  return MPMC_ERROR(sim->ctx, MPMC_ERR_OUTSIDE,
                    "step %lld, t = %g: point %s left the grid box at (%g, %g, %g)",
                    (long long)sim->stats.steps, sim->time, nb, x[0], x[1], d == 3 ? x[2] : 0.0);
}

/* Over MPI G2P's box along the slab axis is the rank's slab (mpmc_dd_slab_box), so that the
 * kernels' check also finds the points that left it, at no cost a point: of the points from
 * first, the first kernel's one, on, the first that fails the step (a degenerate dF, or out
 * of the grid's box lo, hi), or -1; whether any lies beyond the slab's box (xmin, xmax)
 * goes to the migration (mpmc_dd_leaving). */
static int slab_exits(mpmc_sim sim, int first, const double *lo, const double *hi,
                      const double *xmin, const double *xmax) {
  const mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  int beyond = 0;
  for (int q = first; q < p->n; ++q) {
    const double *x = p->x + (size_t)q * d, *dF = p->dF + (size_t)q * d * d;
    const double dJ = d == 2 ? mpmc_det_dim(2, dF) : mpmc_det_dim(3, dF);
    int ok = dJ > 0.0 && isfinite(dJ), in = 1;
    for (int a = 0; a < d; ++a) {
      ok &= (x[a] >= lo[a]) & (x[a] <= hi[a]);
      in &= (x[a] >= xmin[a]) & (x[a] <= xmax[a]);
    }
    if (!ok) return q;
    beyond |= !in;
  }
  mpmc_dd_leaving(sim, beyond);
  return -1;
}

/** Phase 3 of the step. */
int MPMC_ISA(mpmc_g2p)(mpmc_sim sim, double dt) {
  const mpmc_grid *g = &sim->grid;
  const double D = sim->cfg.pic_diff; /* PIC as a diffusivity: the blend of this step's dt */
  g2p_ctx c = {.eta = D > 0 ? 1.0 - fmin(1.0, D * dt * g->inv_h * g->inv_h) : sim->cfg.flip,
               .travel_scale = dt * g->inv_h,
               .xold = sim->cfg.fbar == MPMC_FBAR_STABLE ? sim->fb.xn : NULL};
  double lo[3], hi[3]; /* the grid's box */
  for (int a = 0; a < sim->cfg.dim; ++a) {
    c.xmin[a] = lo[a] = g->lo[a] - g->h;
    c.xmax[a] = hi[a] = g->hi[a] + g->h;
  }
  if (sim->dd) {
    mpmc_dd_slab_box(sim, c.xmin, c.xmax);
    mpmc_dd_leaving(sim, 0);
  }
  int bad = -1;
  double v2max = 0.0;
  mpmc_fbar_state *f = &sim->fb;
  if (sim->cfg.fbar && f->fbj) { /* fb and fbj are zero (the step's mpmc_fbar_clear) */
    const int nc = g->nprivate, width = sim->cfg.fbar == MPMC_FBAR_STABLE ? 2 : 1;
    double *fbp = nc ? mpmc_grid_copies(g, &f->priv, &f->cap_priv, width, nc - 1) : NULL;
    MPMC_KERNEL_CALL(g2pfb_, sim, sim, dt, &c, fbp, nc, &bad, &v2max);
    if (fbp) mpmc_grid_add_copies(g, width == 2 ? f->fb : f->fbj, fbp, width, nc - 1);
    f->scattered = 1;
  } else {
    MPMC_KERNEL_CALL(g2p_, sim, sim, dt, &c, &bad, &v2max);
  }
  if (bad >= 0 && sim->dd) bad = slab_exits(sim, bad, lo, hi, c.xmin, c.xmax);
  /* the stability limit's max |v|^2 (stability.c), unless v is on loan to a caller */
  sim->scr.v2max = v2max;
  sim->scr.v2max_ok = bad < 0 && !sim->v_borrowed;
  if (bad >= 0) return report(sim, bad);
  return MPMC_SUCCESS;
}
