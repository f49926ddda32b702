/* The Hencky-J2 stress update over blocks of four points (issue 6: "materials called over
 * batches"), one of the kernel files compiled for each instruction set: baseline x86-64,
 * AVX2, AVX2 with fused multiply-adds and AVX-512 (mpmc_impl.h, MPMC_ISA).
 *
 * Most points of a slope or a column are elastic in a given step: their trial state
 * b = dF b_e dF^T, its Hencky strain by the series of linalg.h (mpmc_sym3_log_series), the
 * trial von Mises stress and the check against kappa(eps_p) are the same arithmetic for
 * every point, so four neighbouring points go through them at once in vectors of four
 * doubles (one AVX2 register, two SSE2 ones).  The series takes the degree the largest
 * strain of the four needs (the terms beyond a point's own degree are below its 2^-54
 * tolerance).  With the auto solver a block's plastic points go on together from their trial
 * states (plastic4: the scalar solve's operations lane by lane); a lane that the vectors
 * cannot finish, and every plastic point with the newton or kinsol solver, continues alone
 * (the scalar solve and b_e, mpmc_j2_plastic); one whose strain is too large for the series, or not finite, goes
 * to the scalar return map (material_hencky_j2.c, mpmc_j2_return_map) from its unchanged
 * inputs; points of other materials in a block are masked out.  The blocks are
 * fixed by the point index (points 4k .. 4k+3), so the results do not depend on the thread
 * count; baseline and AVX2 give the same bits (ISO C: no contraction), as do the fused
 * sets, fma and avx512, between themselves. */
#include <limits.h>
#include <math.h>
#include <stdint.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "batch4.h"
#include "linalg.h"
#include "return_map.h"
#if defined(__AVX__)
#include <immintrin.h>
#endif

/* The plastic lanes of a block (mask *pl) returned together, for the auto solver:
 * return_map.c's Newton iteration (solve_newton, strict) lane by lane in vectors -- the
 * same operations in the same order, the branches taken per lane, so each lane gets the
 * scalar solve's bits -- then mpmc_j2_plastic's b_e = b exp(2 (f - 1) e), the series at the
 * degree the largest lane needs.  Inputs: the trial b, its deviatoric strain e and trace tr,
 * qtr > k0 = kappa(eps_p).  Outputs for each lane it returns: dg, be, the scaled deviator es.
 * A lane the iteration calls stiff (KINSOL's case), whose result fails the solve's checks or
 * ended on a round-off step (its residual needs libm's exp), or whose correction is beyond
 * the series, leaves *pl: mpmc_j2_plastic repeats it alone and reports or falls back. */
static inline void plastic4(const mpmc_j2_param *m, const v4 *bt, const v4 *e, const v4 *qtrp,
                            const v4 *k0p, l4 *pl, v4 *dg, v4 *be, v4 *es) {
  /* (vectors through pointers: by value they would change the baseline build's ABI) */
  const v4 qtr = *qtrp, k0 = *k0p;
  const double kr = m->kappa_r, c = m->eta / (3.0 * m->G);
  const v4 a = k0 - kr;
  v4 lo = k0 * 0.0 + kr, hi = k0, y, rprev = k0 * 0.0 + INFINITY, tol;
  for (int l = 0; l < 4; ++l) {
    tol[l] = mpmc_rm_tol_k(m, k0[l]);
    if (hi[l] < lo[l]) hi[l] = lo[l];
  }
  /* the lanes' branches as masks: P plastic4's lanes (pl), R those still iterating */
  l4 P = *pl, R = P;
  y = hi;
  for (int it = 0; it < MPMC_RM_MAX_ITERS && mask_bits(&R); ++it) {
    const v4 x = c * (qtr - y);
    v4 ex = MPMC_RM_EXP_NEG_POLY(x);
    const l4 big = R & ~(ABS4(x) <= MPMC_RM_EXP_SMALL);
    for (int bits = mask_bits(&big), l = 0; bits; bits >>= 1, ++l)
      if (bits & 1) ex[l] = exp(-x[l]);
    const v4 ee = a * ex;
    const v4 dr = 1.0 - c * ee;
    const v4 r = y - (kr + ee);
    const v4 yn = y - r / dr;
    R &= ~(ABS4(r) <= tol); /* converged at an evaluated iterate */
    const l4 neg = r < 0.0;
    lo = SEL4(R & neg, y, lo);
    hi = SEL4(R & ~neg, y, hi);
    const v4 slack = 8.0 * DBL_EPSILON * hi;
    v4 ynl = yn;
    ynl = SEL4((ynl > hi) & (ynl <= hi + slack), hi, ynl);
    ynl = SEL4((ynl < lo) & (ynl >= lo - slack), lo, ynl);
    l4 stiff = (dr <= 0.0) | ~((ynl >= lo) & (ynl <= hi)) |
               (ABS4(ynl - y) <= 2.0 * DBL_EPSILON * ABS4(ynl));
    if (it >= 3) stiff |= ABS4(r) > 0.5 * ABS4(rprev);
    P &= ~(R & stiff); /* stiff, or a round-off stop: the scalar path */
    R &= ~stiff;
    rprev = SEL4(R, r, rprev);
    y = SEL4(R, ynl, y);
  }
  P &= ~R; /* the iteration limit: the scalar path */
  int n = 1;
  v4 en[6], r2;
  *dg = (qtr - y) / (3.0 * m->G);
  const v4 f = y / qtr, s2 = 2.0 * (f - 1.0);
  for (int k = 0; k < 6; ++k) en[k] = s2 * e[k];
  norm2_4(en, &r2);
  /* the solve's checks; the series' degree: that of the largest lane */
  P &= (*dg >= 0.0) & ((*dg - *dg) == 0.0) & (y > 0.0) & (r2 <= mpmc_exp_rho2_max[16]);
  const int any = mask_bits(&P) != 0;
  *pl = P;
  const double rmax = max_lane(&r2, &P);
  while (rmax > mpmc_exp_rho2_max[n]) ++n;
  if (!any) return;
  /* exp(en) as mpmc_sym3_exp_series, then b_e = b exp(en) */
  v4 p[6];
  MPMC_SYM3_EXP_HORNER(sym_mul4, en, n, p);
  sym_mul4(bt, p, be);
  for (int k = 0; k < 6; ++k) es[k] = e[k] * f;
}

/**
 * Update the stress of every point of material id (F-bar scaled dF in p->dF, or scaled here
 * when the step deferred F-bar's gather): elastic points in blocks of four, the others by the
 * scalar return map.  *nret and *nfb count the plastic corrections and KINSOL fallbacks;
 * *first_bad is the lowest failed point (INT_MAX for none), left unchanged for
 * material_hencky_j2.c to report; the lowest point left with a non-finite stress goes into
 * sim->scr.stress_bad (stress_update.c's guard).
 */
int MPMC_ISA(mpmc_j2_batch)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                            mpmc_rm_ws **ws, int64_t *nret_out, int64_t *nfb_out,
                            int *first_bad_out) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim, solver = sim->cfg.solver, n = p->n;
  const mpmc_j2_param par = {mat->K, mat->G, mat->kappa_p, mat->kappa_r, mat->eta};
  const double G2 = 2.0 * par.G, K = par.K;
  const int nblk = (n + 3) / 4, nchunk = (nblk + MPMC_BLOCK_CHUNK - 1) / MPMC_BLOCK_CHUNK;
  const int gather = sim->fb.deferred;
  int64_t nret = 0, nfb = 0;
  int first_bad = INT_MAX, first_nf = INT_MAX; /* failed return map; non-finite stress */
  /* threads only pay off beyond a few hundred points (a parallel region costs ~us, far
     more when the cores are shared) */
#pragma omp parallel if (n >= 256) reduction(+ : nret, nfb) reduction(min : first_bad, first_nf)
  {
    int tid = 0;
#ifdef _OPENMP
    tid = omp_get_thread_num();
#endif
    mpmc_rm_ws *w = ws[tid];
    /* Static: each thread one contiguous half (nt-th) of the points, those it updated in
     * G2P (its index chunk, or with F-bar about its slabs: p2g.c, slab_groups), whose fields
     * are still in its core's caches.  Plastic points cost several elastic ones and gather
     * where the soil fails, which after a sort by cell is one stretch of the index range,
     * so a dynamic schedule balanced better; but it moved the points between the cores
     * every step, which cost more (the landslide's states at the run-out's start and 4 s
     * on two threads: the update 8.7 -> 7.7 and 9.6 -> 8.2 ms a step, docs/benchmarks.md).
     * Chunks of MPMC_BLOCK_CHUNK blocks.  With F-bar's gather deferred to here (sim->fb.deferred,
     * fbar.c) each thread first gathers all of its chunks' points into sim->fb.scale, then
     * updates them, forming dF-bar = scale dF as dF is loaded; the two loops' static
     * schedules give a thread the same chunks, so it reads only factors it wrote (nowait).
     * Gathered chunk by chunk between the updates instead, the update's streams (dF, b_e,
     * stress) waited behind the gather's (x^n, Jbar): docs/benchmarks.md. */
    if (gather) {
#pragma omp for schedule(static) nowait
      for (int ch = 0; ch < nchunk; ++ch) fbar_gather_chunk(sim, id, ch, nblk, n);
    }
#pragma omp for schedule(static)
    for (int ch = 0; ch < nchunk; ++ch) {
      const int b0 = ch * MPMC_BLOCK_CHUNK;
      const int b1 = b0 + MPMC_BLOCK_CHUNK < nblk ? b0 + MPMC_BLOCK_CHUNK : nblk;
      const int c0 = 4 * b0;
      const double *scale = gather ? sim->fb.scale + c0 : NULL; /* [q - c0] */
      for (int blk = b0; blk < b1; ++blk) {
        const int q0 = 4 * blk;
        int act[4], nact = 0;
        v4 F[9], b[6];
        if (q0 + 3 < n && p->mat[q0] == id && p->mat[q0 + 1] == id && p->mat[q0 + 2] == id &&
            p->mat[q0 + 3] == id) {
          /* four points of this material: whole vectors (lane by lane through memory, the
           * vectors' loads would wait on four scalar stores each; in 2D that stall was the
           * update's largest cost); in 2D dF's 2x2 in the plane, the rest of the identity */
          const v4 sc = gather ? (v4)*(const v4u *)(scale + (q0 - c0)) : (v4){1.0, 1.0, 1.0, 1.0};
          load_dF4(d, p->dF + (size_t)q0 * d * d, &sc, F);
          const double *be = p->be + (size_t)q0 * 6;
          load_rows6(be, b);
          for (int l = 0; l < 4; ++l) act[l] = 1;
          nact = 4;
        } else
          for (int l = 0; l < 4; ++l) {
            const int q = q0 + l;
            act[l] = q < n && p->mat[q] == id;
            nact += act[l];
            if (act[l]) {
              const double *f = p->dF + (size_t)q * d * d, *be = p->be + (size_t)q * 6;
              const double sc = gather ? scale[q - c0] : 1.0; /* dF-bar = sc dF */
              for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                  F[3 * i + j][l] = (i < d && j < d) ? f[i * d + j] * sc : (i == j);
              for (int k = 0; k < 6; ++k) b[k][l] = be[k];
            } else { /* identity: a finite, elastic dummy */
              for (int k = 0; k < 9; ++k) F[k][l] = (k % 4 == 0);
              for (int k = 0; k < 6; ++k) b[k][l] = k < 3;
            }
          }
        if (!nact) continue;
        v4 bt[6]; /* trial b = F b_e F^T */
        push_forward4(F, b, bt);
        v4 eps[6], e[6];
        const l4 am = {-(long long)act[0], -(long long)act[1], -(long long)act[2],
                       -(long long)act[3]};
        l4 fail;
        sym_log_series4(bt, &am, eps, &fail);
        const v4 tr = eps[0] + eps[1] + eps[2];
        for (int k = 0; k < 6; ++k) e[k] = eps[k];
        for (int k = 0; k < 3; ++k) e[k] -= tr / 3.0;
        v4 q2;
        norm2_4(e, &q2);
        q2 *= 1.5;
        /* J = sqrt(det b) = exp(tr eps), without the exp */
        v4 detb;
        det_sym4(bt, &detb);
        /* elastic lanes finish here (the rest: todo); with the auto solver the plastic ones go
         * on together (plastic4, pl), the others and any plastic4 hands back one by one; the
         * lanes' cases as masks */
        /* the four strengths kappa(eps_p) in one vector (mpmc_j2_kappa's bits) */
        const double *epb = p->eps_p + q0;
        const v4 epv = nact == 4 ? (v4)*(const v4u *)epb
                                 : (v4){act[0] ? epb[0] : 0.0, act[1] ? epb[1] : 0.0,
                                        act[2] ? epb[2] : 0.0, act[3] ? epb[3] : 0.0};
        v4 k0all, qtr;
        mpmc_j2_kappa4(&par, &epv, &k0all);
        sqrt4(&q2, &qtr);
        qtr *= G2;
        const v4 one = {1.0, 1.0, 1.0, 1.0};
        const l4 ok = am & ~fail & ((qtr - qtr) == 0.0) & (detb > 0.0); /* qtr finite */
        const l4 mel = ok & (qtr <= k0all);  /* elastic: b_e = trial b */
        const l4 todo = am & ~mel;
        l4 pl = solver == MPMC_SOLVER_AUTO ? todo & ok : (l4){0, 0, 0, 0};
        /* finite dummies for plastic4's unused lanes */
        const v4 k0v = SEL4(todo, k0all, one), qtrv = SEL4(todo, qtr, one);
        int npl = __builtin_popcount((unsigned)mask_bits(&pl));
        int ndone = __builtin_popcount((unsigned)mask_bits(&mel));
        /* b_e and sigma = tau / J, J = sqrt(det b), of the lanes done here in vectors:
         * tau = 2G e + K tr 1 elastic (mel), 2G es + K tr 1 as mpmc_j2_plastic's (series_tau)
         * from plastic4 (pl); the elastic lanes' shear terms plus +0 as the scalar form adds
         * it (-0, a no-op, in the others) */
        v4 dg = {0.0, 0.0, 0.0, 0.0}, bo[6], xs[6];
        for (int k = 0; k < 6; ++k) bo[k] = bt[k], xs[k] = e[k];
        if (npl) {
          v4 bn[6], es[6];
          for (int k = 0; k < 6; ++k) bn[k] = es[k] = dg; /* (lanes it hands back) */
          plastic4(&par, bt, e, &qtrv, &k0v, &pl, &dg, bn, es);
          npl = __builtin_popcount((unsigned)mask_bits(&pl)); /* those it did not hand back */
          ndone += npl;
          for (int k = 0; k < 6; ++k)
            bo[k] = SEL4(mel, bt[k], bn[k]), xs[k] = SEL4(mel, e[k], es[k]);
        }
        if (ndone) {
          const v4 zs = (v4)(~mel & (l4)(v4){-0.0, -0.0, -0.0, -0.0});
          v4 inv_J, so[6];
          sqrt4(&detb, &inv_J);
          inv_J = 1.0 / inv_J;
          for (int k = 0; k < 6; ++k)
            so[k] = (k < 3 ? G2 * xs[k] + K * tr : G2 * xs[k] + zs) * inv_J;
          const v4 sum = so[0] + so[1] + so[2] + so[3] + so[4] + so[5]; /* mpmc_stress_finite */
          const l4 done = mel | pl, bad = done & ~((sum - sum) == 0.0);
          if (ndone == 4) { /* a whole block: transposed stores */
            store_rows6(bo, p->be + (size_t)q0 * 6);
            store_rows6(so, p->stress + (size_t)q0 * 6);
            if (npl) *(v4u *)(p->eps_p + q0) = SEL4(mel, epv, epv + dg);
          } else
            for (int bits = mask_bits(&done), l = 0; bits; bits >>= 1, ++l) {
              if (!(bits & 1)) continue;
              const size_t q6 = (size_t)(q0 + l) * 6;
              for (int k = 0; k < 6; ++k) p->be[q6 + k] = bo[k][l], p->stress[q6 + k] = so[k][l];
              if (pl[l]) p->eps_p[q0 + l] += dg[l];
            }
          const int bbits = mask_bits(&bad);
          if (bbits && q0 + __builtin_ctz((unsigned)bbits) < first_nf)
            first_nf = q0 + __builtin_ctz((unsigned)bbits);
          nret += npl;
        }
        const l4 rest = todo & ~pl;
        for (int bits = mask_bits(&rest), l = 0; bits; bits >>= 1, ++l) {
          if (!(bits & 1)) continue;
          const int q = q0 + l;
          double *ep = p->eps_p + q;
          const double k0 = k0v[l], qtr = qtrv[l];
          double *sg = p->stress + (size_t)q * 6, *be = p->be + (size_t)q * 6;
          double tau[6], J;
          mpmc_j2_info info = {0};
          int err;
          if (!fail[l] && isfinite(qtr) && detb[l] > 0.0) {
            /* plastic: the scalar solve and b_e from this trial state */
            double bl[6], el[6];
            for (int k = 0; k < 6; ++k) bl[k] = bt[k][l], el[k] = e[k][l];
            err = mpmc_j2_plastic(w, solver, &par, bl, el, tr[l], qtr, k0, be, ep, tau, NULL, &info);
            J = sqrt(detb[l]); /* = exp(tr eps): the flow is isochoric */
          } else { /* outside the series or not finite: the scalar map from b_e^n and dF */
            double Fl[3][3];
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) Fl[i][j] = F[3 * i + j][l];
            err = mpmc_j2_return_map(w, solver, &par, Fl, be, ep, tau, &J, &info);
          }
          if (err) {
            if (q < first_bad) first_bad = q;
            if (gather) /* the report (material_hencky_j2.c) repeats it from dF-bar */
              for (int k = 0; k < d * d; ++k) p->dF[(size_t)q * d * d + k] = F[3 * (k / d) + k % d][l];
            continue;
          }
          nret += info.plastic;
          nfb += info.fallback;
          const double inv_J = 1.0 / J;
          for (int k = 0; k < 6; ++k) sg[k] = tau[k] * inv_J;
          if (!mpmc_stress_finite(sg) && q < first_nf) first_nf = q;
        }
      }
    }
  }
  *nret_out = nret;
  *nfb_out = nfb;
  *first_bad_out = first_bad;
  if (first_nf < sim->scr.stress_bad) sim->scr.stress_bad = first_nf; /* stress_update.c's guard */
  return MPMC_SUCCESS;
}
