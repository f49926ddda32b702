/* The frictional models' shared update: for every point of the material, b_e pushed forward
 * by dF (dF-bar with F-bar on), the return map of return_mc.c (mpmc_mc_update: an elastic
 * check without eigen-decomposition, the principal-space return for the plastic points),
 * then the Cauchy stress tau / J (J-bar with F-bar on).  The material's sines, cosines and
 * cut-off are worked out once per call (mpmc_mc_prepare).  Four points of the material in a
 * block (points 4k .. 4k + 3) go through mpmc_mc_update4 together (their trial states, series,
 * elastic checks, eigen-decompositions and recompositions as vectors; its AVX2 build unless
 * the sim runs the baseline kernels), each with mpmc_mc_update's results.  The loop over the
 * points, with the region, the plastic volume ratio, the pore pressure and the counters, is
 * stress_return.c's. */
#include <math.h>

#include "material_frictional.h"
#include "return_mc.h"
#include "stress_return.h"

int mpmc_frictional_setup(mpmc_context ctx, mpmc_material *m) {
  mpmc_material_elastic(m);
  const double *par = m->par;
  MPMC_CHECK(par[MPMC_FR_PSI_R] <= par[MPMC_FR_PHI_R], ctx, MPMC_ERR_ARG,
             "%s: residual dilation angle psi_r = %g deg must not exceed the residual friction "
             "angle phi_r = %g deg",
             m->model->name, par[MPMC_FR_PSI_R], par[MPMC_FR_PHI_R]);
  MPMC_CHECK(par[MPMC_FR_C] > 0 || par[MPMC_FR_PHI] > 0, ctx, MPMC_ERR_ARG,
             "%s: cohesion c = 0 and friction angle phi = 0 leave no strength: give c > 0 or "
             "phi > 0",
             m->model->name);
  m->plastic = 1;
  return MPMC_SUCCESS;
}

double mpmc_frictional_wave_speed(const mpmc_material *m) {
  return sqrt((m->K + 4.0 / 3.0 * m->G) / m->rho);
}

static mpmc_mc_param frictional_param(const mpmc_material *mat, int surface) {
  const double *par = mat->par;
  return (mpmc_mc_param){.K = mat->K,
                         .G = mat->G,
                         .c_p = par[MPMC_FR_C],
                         .c_r = par[MPMC_FR_C_R],
                         .phi_p = par[MPMC_FR_PHI] * MPMC_RAD,
                         .phi_r = par[MPMC_FR_PHI_R] * MPMC_RAD,
                         .psi_p = par[MPMC_FR_PSI] * MPMC_RAD,
                         .psi_r = par[MPMC_FR_PSI_R] * MPMC_RAD,
                         .eta = par[MPMC_FR_ETA],
                         .sigma_t = par[MPMC_FR_SIGMA_T],
                         .surface = surface};
}

/* the material's model (stress_return.h): its mpmc_mc_pre and the block update of the sim's
 * kernel set (mpmc_mc_update4_for) */
typedef struct {
  mpmc_mc_pre pre;
  mpmc_mc_update4_fn update4;
} frictional_model;

/* one point's return (stress_return.h) */
static int frictional_point(const void *model, mpmc_rm_ws *ws, int solver, double F[3][3],
                            double be[6], double *eps_p, double tau[6], mpmc_return_out *out) {
  const frictional_model *fm = model;
  mpmc_mc_info info = {0};
  const int err = mpmc_mc_update(ws, solver, &fm->pre, F, be, eps_p, tau, &out->Je, &info);
  out->plastic = info.plastic;
  out->fallback = info.fallback;
  out->region = info.region;
  return err;
}

static int frictional_fail(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                           const void *model, mpmc_rm_ws *ws, mpmc_return_point *pt) {
  const int solver = sim->cfg.solver;
  const frictional_model *fm = model;
  double tau[6], Je;
  mpmc_mc_info info = {0};
  const int err = mpmc_mc_update(ws, solver, &fm->pre, pt->F, pt->be, &pt->eps_p, tau, &Je, &info);
  return MPMC_ERROR(sim->ctx, err ? err : MPMC_ERR_NUMERIC,
                    "step %lld, t = %g: %s return map of point %s at (%g, %g, %g) (material %d, "
                    "solver %s) failed: region %d, eps_p = %g, dgamma = %g, |f| = %g Pa, "
                    "KINSOL flag %d, J = %g",
                    (long long)sim->stats.steps, sim->time, mat->model->name, pt->name,
                    pt->x[0], pt->x[1], pt->x[2], id, mpmc_solver_name(solver), info.region,
                    sim->p.eps_p[pt->q], info.dgamma, info.residual, info.kinsol_flag, pt->J);
}

/* four points' returns (stress_return.h), by mpmc_mc_update4 (or its AVX2 build) */
static void frictional_block(const void *model, mpmc_rm_ws *ws, int solver, double F[4][3][3],
                             double be[4][6], double eps_p[4], double tau[4][6],
                             mpmc_return_out out[4], int err[4]) {
  const frictional_model *fm = model;
  mpmc_mc_info info[4] = {{0}};
  double Je[4];
  fm->update4(ws, solver, &fm->pre, 4, F, be, eps_p, tau, Je, info, err);
  for (int l = 0; l < 4; ++l) {
    out[l].Je = Je[l];
    out[l].plastic = info[l].plastic;
    out[l].fallback = info[l].fallback;
    out[l].region = info[l].region;
  }
}

static const mpmc_return_ops frictional_ops = {frictional_point, frictional_fail};

int mpmc_frictional_update(struct mpmc_sim_s *sim, const mpmc_material *mat, int id,
                           int surface) {
  const mpmc_mc_param mp = frictional_param(mat, surface);
  frictional_model fm;
  mpmc_mc_prepare(&mp, &fm.pre);
  fm.update4 = mpmc_mc_update4_for(sim->cfg.kernels);
  return mpmc_return_update_blocks(sim, mat, id, &frictional_ops, frictional_block, &fm);
}
