/* The stress update of the materials whose return map takes one point at a time: the
 * frictional models (material_frictional.c, return_mc.c) and the user yield surfaces
 * (material_user_yield.c, return_cpp.c).  stress_return.c runs their loop over the points
 * (the frictional ones also in blocks of four, mpmc_return_update_blocks);
 * each model gives its return map, what else it keeps of an accepted return, and its error
 * message.  Hencky-J2 has its own loop, four points at a time (stress_j2.c). */
#ifndef MPMC_STRESS_RETURN_H
#define MPMC_STRESS_RETURN_H

#include "mpmc_impl.h"
#include "return_map.h"

/* What one point's return tells the loop besides the state and the stress. */
typedef struct {
  int plastic;  /* a plastic correction (sim->stats.return_maps)                        */
  int fallback; /* the auto solver handed it to KINSOL (sim->stats.kinsol_fallbacks)    */
  int region;   /* where the stress returned to (MPMC_MODEL_REGION: MPMC_FIELD_REGION)   */
  double Je;    /* the elastic volume ratio after the return, sqrt(det b_e)             */
} mpmc_return_out;

/* The lowest failed point, as the error message repeats it. */
typedef struct {
  int q;
  double F[3][3];                 /* its increment dF (dF-bar with F-bar on), 3 x 3      */
  double be[6], eps_p;            /* copies of its state, to hand to the return again    */
  double J;                       /* J (J-bar with F-bar on) the stress is divided by    */
  double x[3];                    /* its position (z = 0 in plane strain)                */
  char name[MPMC_POINT_NAME_LEN]; /* mpmc_point_name                                     */
} mpmc_return_point;

/* The error of the failed point: repeat its return with ws and say why; returns the error
 * code (set with MPMC_ERROR). */
typedef int (*mpmc_return_fail_fn)(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                                   const void *model, mpmc_rm_ws *ws, mpmc_return_point *pt);

typedef struct {
  /* The return map of one point: F its increment, be and *eps_p the point's state (copies:
   * the loop writes them back when the return is accepted), tau the Kirchhoff stress.
   * Called from several threads, each with its own workspace.  Returns 0 or an error. */
  int (*point)(const void *model, mpmc_rm_ws *ws, int solver, double F[3][3], double be[6],
               double *eps_p, double tau[6], mpmc_return_out *out);
  mpmc_return_fail_fn fail;
} mpmc_return_ops;

/* The update of material id's points: b_e pushed forward by dF (dF-bar), ops->point, then
 * sigma = tau / J (J-bar), less the water table's pore pressure (effective to total stress,
 * water.c); a model with MPMC_MODEL_REGION (the frictional ones) keeps where the return went
 * and, with F-bar on, the plastic volume ratio Jp (fbar.c).  Points in parallel, each thread with its own workspace
 * (mpmc_rm_sim_workspaces).  A point whose return fails, whose stress is not finite or whose
 * J is not positive keeps its state; then mpmc_return_finish. */
int mpmc_return_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                       const mpmc_return_ops *ops, const void *model);

/* The return map of four points at once (lane l: F[l], be[l], eps_p[l], tau[l], out[l], its
 * return value in err[l]), each with the results ops->point would give it. */
typedef void (*mpmc_return_block_fn)(const void *model, mpmc_rm_ws *ws, int solver,
                                     double F[4][3][3], double be[4][6], double eps_p[4],
                                     double tau[4][6], mpmc_return_out out[4], int err[4]);

/* mpmc_return_update with the blocks of four points of material id (points 4k .. 4k + 3)
 * handed to block (the frictional models, mpmc_mc_update4), the others to ops->point; the
 * same results as mpmc_return_update (block NULL). */
int mpmc_return_update_blocks(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                              const mpmc_return_ops *ops, mpmc_return_block_fn block,
                              const void *model);

/* The end of every return-mapping update (a loop of its own too, e.g. Hencky-J2's batches):
 * the plastic corrections nret and KINSOL fallbacks nfb counted into sim->stats; when a
 * point failed (first_bad < INT_MAX, the lowest), its trial state handed to fail with
 * ws[0], whose code is returned. */
int mpmc_return_finish(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                       mpmc_return_fail_fn fail, const void *model, mpmc_rm_ws **ws,
                       int64_t nret, int64_t nfb, int first_bad);

#endif
