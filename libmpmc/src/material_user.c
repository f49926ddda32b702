/* User materials: a stress update supplied by the caller (a C function or a Fortran bind(C)
 * procedure registered with c_funloc), called per point from inside the threaded stress
 * phase.  Its state lives in the particle array p->ustate [n][nustate], one row per point,
 * wide enough for the widest user material; each material uses the first nstate entries. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "linalg.h"
#include "mpmc_impl.h"

#define MPMC_USER_NSTATE_MAX 4096

extern const mpmc_model mpmc_model_user;

/* Widen p->ustate rows to nstate columns for the current capacity, keeping every point's
 * existing values and zeroing the new columns (the documented initial state). */
static int widen_state(mpmc_context ctx, mpmc_particles *p, int nstate) {
  if (nstate <= p->nustate) return MPMC_SUCCESS;
  /* Allocate even with no points yet: mpmc_particles_reserve only grows a field that
   * exists, so the array must exist before the first points are added. */
  const size_t cap = p->cap > 0 ? (size_t)p->cap : 1;
  double *a = calloc(cap * (size_t)nstate, sizeof(double));
  MPMC_CHECK(a, ctx, MPMC_ERR_MEMORY, "cannot allocate %d user-state values for %zu points",
             nstate, cap);
  if (p->ustate) {
    for (int q = 0; q < p->n; ++q)
      memcpy(a + (size_t)q * nstate, p->ustate + (size_t)q * p->nustate,
             sizeof(double) * (size_t)p->nustate);
    free(p->ustate);
  }
  p->ustate = a;
  p->nustate = nstate;
  return MPMC_SUCCESS;
}

/**
 * @brief Add a material whose stress update is the caller's function fn.
 *
 * fn is called for every point of the material on every step, from several OpenMP threads
 * at once (it must be thread-safe: no static or SAVE'd scratch), with the relative
 * deformation gradient dF as a 3x3 row-major array (F-bar scaled when F-bar is on; the
 * identity in the unused direction in plane strain), the step dt, the point's state[nstate]
 * (zero before its first step) and its Cauchy stress[6] in Voigt order (the previous stress
 * on entry).  A non-zero return stops the step with MPMC_ERR_SOLVER.
 * @param fn the stress update, not NULL
 * @param data passed back to fn unchanged (may be NULL)
 * @param nstate state variables per point, in [0, 4096]
 * @param rho density [kg/m^3], > 0
 * @param wave_speed the material's p-wave speed [m/s] for the stable time step, > 0
 * @param[out] id the material's id (may be NULL)
 */
int mpmc_sim_add_material_user(mpmc_sim sim, mpmc_user_stress_fn fn, void *data, int nstate,
                               double rho, double wave_speed, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(fn, ctx, MPMC_ERR_ARG, "user material: stress function fn is NULL");
  const double par[] = {rho, wave_speed, nstate};
  int mid;
  MPMC_CALL(mpmc_material_add(sim, &mpmc_model_user, par, &mid));
  const int err = widen_state(ctx, &sim->p, nstate);
  if (err) {
    sim->nmat--; /* not added after all */
    return err;
  }
  sim->mats[mid].user_fn = fn;
  sim->mats[mid].user_data = data;
  if (id) *id = mid;
  return MPMC_SUCCESS;
}

/**
 * @brief Borrow the user-material state of every point (no copy), layout [n][*nstate].
 *
 * The rows are as wide as the widest user material of the simulation; the points of
 * `material` use the first nstate entries of their rows.  Valid until points are added or a
 * user material with more state is.
 * @param material the id of a user material
 * @param[out] state the array p->ustate (NULL when no user material has state)
 * @param[out] nstate the row length (stride) of state
 */
int mpmc_sim_get_user_state(mpmc_sim sim, int material, double **state, int *nstate) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(state, ctx, MPMC_ERR_ARG, "state pointer is NULL");
  MPMC_CHECK(nstate, ctx, MPMC_ERR_ARG, "nstate pointer is NULL");
  MPMC_CHECK(material >= 0 && material < sim->nmat, ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  MPMC_CHECK(sim->mats[material].model == &mpmc_model_user, ctx, MPMC_ERR_ARG,
             "material %d is a built-in '%s' material, not a user material", material,
             sim->mats[material].ops->name);
  *state = sim->p.nustate > 0 ? sim->p.ustate : NULL;
  *nstate = sim->p.nustate;
  return MPMC_SUCCESS;
}

static int user_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  mpmc_particles *p = &sim->p;
  const int d = sim->cfg.dim;
  const size_t ns = (size_t)p->nustate;
  const mpmc_user_stress_fn fn = mat->user_fn;
  void *data = mat->user_data;
  int first_bad = INT_MAX, code = 0;
#pragma omp parallel for schedule(static) reduction(min : first_bad)
  for (int q = 0; q < p->n; ++q) {
    if (p->mat[q] != id) continue;
    double F[3][3];
    mpmc_embed(d, p->dF + (size_t)q * d * d, F);
    double *state = ns > 0 ? p->ustate + (size_t)q * ns : NULL;
    const int r = fn(data, &F[0][0], dt, state, p->stress + (size_t)q * 6);
    if (r != 0 && q < first_bad) {
      first_bad = q;
#pragma omp critical(mpmc_user_code)
      code = r;
    }
  }
  if (first_bad == INT_MAX) return MPMC_SUCCESS;
  /* Several points may fail in one step: name the lowest index and one of the codes. */
  const int q = first_bad;
  const double *x = p->x + (size_t)q * d;
  char nb[MPMC_POINT_NAME_LEN];
  return MPMC_ERROR(sim->ctx, MPMC_ERR_SOLVER,
                    "step %lld, t = %g: user material %d stress function failed at point %s "
                    "(%g, %g, %g) (returned %d)",
                    (long long)sim->stats.steps, sim->time, id, mpmc_point_name(p, q, nb), x[0], x[1],
                    d == 3 ? x[2] : 0.0, code);
}

static double user_wave_speed(const mpmc_material *m) { return m->user_wave_speed; }

static const mpmc_material_ops ops = {"user", user_update, user_wave_speed, 0, 0};

static const mpmc_param_desc params[] = {
    MPMC_PARAM("rho", "kg/m^3", "density", 0.0, INFINITY, MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN,
               0.0, -1, -1),
    MPMC_PARAM("wave_speed", "m/s", "p-wave speed for the stable time step", 0.0, INFINITY,
               MPMC_PARAM_LO_OPEN | MPMC_PARAM_HI_OPEN, 0.0, -1, -1),
    MPMC_PARAM("nstate", "1", "state variables per point", 0.0, MPMC_USER_NSTATE_MAX, 0, 0.0, -1,
               -1)};

static int user_setup(mpmc_context ctx, mpmc_material *m) {
  MPMC_CHECK(m->par[2] == floor(m->par[2]), ctx, MPMC_ERR_ARG,
             "user: parameter nstate = %g must be a whole number", m->par[2]);
  m->rho = m->par[0];
  m->user_wave_speed = m->par[1];
  m->user_nstate = (int)m->par[2];
  return MPMC_SUCCESS;
}

const mpmc_model mpmc_model_user = {.name = "user",
                                    .doc = "the caller's stress update (C or Fortran function)",
                                    .nparam = 3,
                                    .nstore = 3,
                                    .param = params,
                                    .flags = MPMC_MODEL_CALLBACK,
                                    .setup = user_setup,
                                    .ops = &ops};
