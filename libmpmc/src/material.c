/* Material registration and validation; the models live in material_*.c. */
#include <math.h>
#include <stdlib.h>

#include "mpmc_impl.h"

int mpmc_material_validate_elastic(mpmc_context ctx, double E, double nu, double rho) {
  MPMC_CHECK(isfinite(E) && E > 0, ctx, MPMC_ERR_ARG, "Young's modulus E = %g must be > 0", E);
  MPMC_CHECK(isfinite(nu) && nu >= 0 && nu < 0.5, ctx, MPMC_ERR_ARG,
             "Poisson's ratio nu = %g must be in [0, 0.5)", nu);
  MPMC_CHECK(isfinite(rho) && rho > 0, ctx, MPMC_ERR_ARG, "density rho = %g must be > 0", rho);
  return MPMC_SUCCESS;
}

static int push_material(mpmc_sim sim, const mpmc_material *m, int *id) {
  if (sim->nmat == sim->capmat) {
    const int cap = sim->capmat ? 2 * sim->capmat : 4;
    mpmc_material *a = realloc(sim->mats, sizeof *a * (size_t)cap);
    MPMC_CHECK(a, sim->ctx, MPMC_ERR_MEMORY, "cannot add a material");
    sim->mats = a;
    sim->capmat = cap;
  }
  sim->mats[sim->nmat] = *m;
  if (id) *id = sim->nmat;
  sim->nmat++;
  sim->prepared = 0;
  return MPMC_SUCCESS;
}

static void elastic_constants(mpmc_material *m, double E, double nu, double rho) {
  m->E = E;
  m->nu = nu;
  m->rho = rho;
  m->G = E / (2.0 * (1.0 + nu));
  m->K = E / (3.0 * (1.0 - 2.0 * nu));
  m->lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  m->solid = 1;
}

static int add_elastic(mpmc_sim sim, int kind, const mpmc_material_ops *ops, double E, double nu,
                       double rho, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CALL(mpmc_material_validate_elastic(sim->ctx, E, nu, rho));
  mpmc_material m = {0};
  m.kind = kind;
  m.ops = ops;
  elastic_constants(&m, E, nu, rho);
  return push_material(sim, &m, id);
}

/**
 * @brief Add a compressible Neo-Hookean material,
 *        psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2.
 * @param E Young's modulus [Pa], > 0
 * @param nu Poisson's ratio, in [0, 0.5)
 * @param rho density [kg/m^3], > 0
 * @param[out] id the material's id (may be NULL)
 */
int mpmc_sim_add_material_neo_hookean(mpmc_sim sim, double E, double nu, double rho, int *id) {
  return add_elastic(sim, MPMC_MAT_NEO_HOOKEAN, &mpmc_ops_neo_hookean, E, nu, rho, id);
}

/**
 * @brief Add a Hencky (logarithmic-strain) elastic material, tau = K tr(eps) 1 + 2G dev(eps).
 */
int mpmc_sim_add_material_hencky(mpmc_sim sim, double E, double nu, double rho, int *id) {
  return add_elastic(sim, MPMC_MAT_HENCKY, &mpmc_ops_hencky, E, nu, rho, id);
}

/**
 * @brief Add Hencky elasticity with von Mises plasticity and exponential softening.
 * @param kappa_p peak strength (von Mises equivalent stress q at yield) [Pa], > 0
 * @param kappa_r residual strength [Pa], 0 < kappa_r <= kappa_p
 * @param eta softening rate, >= 0 (0: perfect plasticity at kappa_p)
 */
int mpmc_sim_add_material_hencky_j2(mpmc_sim sim, double E, double nu, double rho, double kappa_p,
                                    double kappa_r, double eta, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CALL(mpmc_material_validate_elastic(ctx, E, nu, rho));
  MPMC_CHECK(isfinite(kappa_p) && kappa_p > 0, ctx, MPMC_ERR_ARG,
             "peak strength kappa_p = %g must be > 0", kappa_p);
  MPMC_CHECK(isfinite(kappa_r) && kappa_r > 0, ctx, MPMC_ERR_ARG,
             "residual strength kappa_r = %g must be > 0", kappa_r);
  MPMC_CHECK(kappa_r <= kappa_p, ctx, MPMC_ERR_ARG,
             "residual strength kappa_r = %g must not exceed peak strength kappa_p = %g", kappa_r,
             kappa_p);
  MPMC_CHECK(isfinite(eta) && eta >= 0, ctx, MPMC_ERR_ARG, "softening rate eta = %g must be >= 0",
             eta);
  mpmc_material m = {0};
  m.kind = MPMC_MAT_HENCKY_J2;
  m.ops = &mpmc_ops_hencky_j2;
  elastic_constants(&m, E, nu, rho);
  m.kappa_p = kappa_p;
  m.kappa_r = kappa_r;
  m.eta = eta;
  m.plastic = 1;
  return push_material(sim, &m, id);
}

/**
 * @brief Add a nearly incompressible Newtonian fluid: sigma = K (J - 1) 1 + 2 mu dev(D).
 * @param K bulk modulus [Pa], > 0
 * @param mu dynamic viscosity [Pa s], >= 0
 * @param rho density [kg/m^3], > 0
 */
int mpmc_sim_add_material_newtonian(mpmc_sim sim, double K, double mu, double rho, int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(isfinite(K) && K > 0, ctx, MPMC_ERR_ARG, "bulk modulus K = %g must be > 0", K);
  MPMC_CHECK(isfinite(mu) && mu >= 0, ctx, MPMC_ERR_ARG, "viscosity mu = %g must be >= 0", mu);
  MPMC_CHECK(isfinite(rho) && rho > 0, ctx, MPMC_ERR_ARG, "density rho = %g must be > 0", rho);
  mpmc_material m = {0};
  m.kind = MPMC_MAT_NEWTONIAN;
  m.ops = &mpmc_ops_newtonian;
  m.K = K;
  m.mu = mu;
  m.rho = rho;
  return push_material(sim, &m, id);
}

/** @brief Number of materials added so far. */
int mpmc_sim_get_num_materials(const mpmc_sim sim, int *n) {
  if (!sim || !n) return MPMC_ERR_ARG;
  *n = sim->nmat;
  return MPMC_SUCCESS;
}

/**
 * @brief Divide the strengths of a plastic material (or all, material = -1) by factor
 *        (strength reduction between stages); accumulated plastic strain is kept.
 */
int mpmc_sim_reduce_strength(mpmc_sim sim, int material, double factor) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(isfinite(factor) && factor > 0, ctx, MPMC_ERR_ARG,
             "strength reduction factor = %g must be > 0", factor);
  MPMC_CHECK(material >= -1 && material < sim->nmat, ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  int count = 0;
  for (int i = 0; i < sim->nmat; ++i) {
    if (material != -1 && i != material) continue;
    if (!sim->mats[i].plastic) continue;
    sim->mats[i].kappa_p /= factor;
    sim->mats[i].kappa_r /= factor;
    ++count;
  }
  MPMC_CHECK(count > 0, ctx, MPMC_ERR_ARG,
             material == -1 ? "no plastic material to reduce (material %d)"
                            : "material %d is not plastic: nothing to reduce",
             material);
  return MPMC_SUCCESS;
}
