/* The material model table: every model the library knows, each described once in its own
 * file (material_*.c: name, parameters with units and ranges, per-point state, strength
 * reduction, stress update).  Adding a model is its file and one entry in models[] below.
 * Validation, the generic constructor, strength reduction and the public description the
 * scene reader, `mpmc check`, checkpoints and the docs' parameter table read live here. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc_impl.h"

extern const mpmc_model mpmc_model_neo_hookean, mpmc_model_hencky, mpmc_model_hencky_j2,
    mpmc_model_newtonian, mpmc_model_user, mpmc_model_mohr_coulomb, mpmc_model_drucker_prager,
    mpmc_model_user_yield;

/* The table; the order is the model numbering of the public description (mpmc_model_*). */
static const mpmc_model *const models[] = {
    &mpmc_model_hencky_j2, &mpmc_model_hencky, &mpmc_model_neo_hookean, &mpmc_model_newtonian,
    &mpmc_model_user, &mpmc_model_mohr_coulomb, &mpmc_model_drucker_prager,
    &mpmc_model_user_yield,
};
#define NMODEL ((int)(sizeof models / sizeof models[0]))

int mpmc_model_table_size(void) { return NMODEL; }
const mpmc_model *mpmc_model_at(int k) { return k >= 0 && k < NMODEL ? models[k] : NULL; }
const mpmc_model *mpmc_model_named(const char *name) {
  for (int k = 0; name && k < NMODEL; ++k)
    if (!strcmp(models[k]->name, name)) return models[k];
  return NULL;
}

/* The range of parameter d as text, e.g. "[0, 0.5)" or "> 0". */
static void range_text(const mpmc_param_desc *d, char *buf, size_t len) {
  if (d->words) {
    size_t l = 0;
    buf[0] = 0;
    for (int w = 0; d->words[w] && l < len; ++w)
      l += (size_t)snprintf(buf + l, len - l, "%s%s", w ? ", " : "one of ", d->words[w]);
  } else if (isinf(d->hi)) {
    snprintf(buf, len, "%s %g", (d->flags & MPMC_PARAM_LO_OPEN) ? ">" : ">=", d->lo);
  } else {
    snprintf(buf, len, "in %c%g, %g%c", (d->flags & MPMC_PARAM_LO_OPEN) ? '(' : '[', d->lo,
             d->hi, (d->flags & MPMC_PARAM_HI_OPEN) ? ')' : ']');
  }
}

static int in_range(const mpmc_param_desc *d, double v) {
  if (isnan(v)) return 0;
  if (d->words) {
    int nw = 0;
    while (d->words[nw]) ++nw;
    return v == floor(v) && v >= 0 && v < nw;
  }
  const int lo_ok = (d->flags & MPMC_PARAM_LO_OPEN) ? v > d->lo : v >= d->lo;
  const int hi_ok = (d->flags & MPMC_PARAM_HI_OPEN) ? v < d->hi : v <= d->hi;
  return lo_ok && hi_ok && (isfinite(v) || (isinf(v) && isinf(d->hi) && v > 0));
}

/* Fill the defaults of par (NAN entries) and check every value against the table. */
static int validate(mpmc_context ctx, const mpmc_model *md, double *par) {
  for (int k = 0; k < md->nstore; ++k) {
    const mpmc_param_desc *d = &md->param[k];
    if (isnan(par[k]) && (d->flags & MPMC_PARAM_OPTIONAL))
      par[k] = d->default_of >= 0 ? par[d->default_of] : d->def;
    char rt[160];
    range_text(d, rt, sizeof rt);
    const char *unit = strcmp(d->unit, "1") ? d->unit : "";
    MPMC_CHECK(!isnan(par[k]), ctx, MPMC_ERR_ARG, "%s: %s %s [%s] is required", md->name, d->doc,
               d->name, d->unit);
    MPMC_CHECK(in_range(d, par[k]), ctx, MPMC_ERR_ARG, "%s: %s %s = %g%s%s must be %s", md->name,
               d->doc, d->name, par[k], unit[0] ? " " : "", unit, rt);
  }
  for (int k = 0; k < md->nstore; ++k) {
    const mpmc_param_desc *d = &md->param[k];
    if (d->at_most >= 0)
      MPMC_CHECK(par[k] <= par[d->at_most], ctx, MPMC_ERR_ARG,
                 "%s: %s %s = %g must not exceed %s %s = %g", md->name, d->doc, d->name, par[k],
                 md->param[d->at_most].doc, md->param[d->at_most].name, par[d->at_most]);
  }
  return MPMC_SUCCESS;
}

/** Re-derive m's constants from m->par (the model's setup). */
int mpmc_material_setup(mpmc_context ctx, mpmc_material *m) {
  const mpmc_model *md = m->model;
  m->solid = (md->flags & MPMC_MODEL_SOLID) != 0;
  m->plastic = (md->flags & MPMC_MODEL_PLASTIC) != 0;
  if (md->setup) MPMC_CALL(md->setup(ctx, m));
  m->rho_sat = m->rho; /* the saturated density where the model has one (water.c) */
  for (int k = 0; k < md->nstore; ++k)
    if (!strcmp(md->param[k].name, "rho_sat")) m->rho_sat = m->par[k];
  return MPMC_SUCCESS;
}

int mpmc_material_add(struct mpmc_sim_s *sim, const mpmc_model *md, const double *par_in,
                      int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(md, ctx, MPMC_ERR_ARG, "unknown material model");
  mpmc_material m = {0};
  m.model = md;
  m.ops = md->ops;
  m.srm = 1.0;
  for (int k = 0; k < md->nstore; ++k) m.par[k] = par_in ? par_in[k] : NAN;
  MPMC_CALL(validate(ctx, md, m.par));
  memcpy(m.par0, m.par, sizeof m.par);
  MPMC_CALL(mpmc_material_setup(ctx, &m));
  if (sim->nmat == sim->capmat) {
    const int cap = sim->capmat ? 2 * sim->capmat : 4;
    mpmc_material *a = realloc(sim->mats, sizeof *a * (size_t)cap);
    MPMC_CHECK(a, ctx, MPMC_ERR_MEMORY, "cannot add a material");
    sim->mats = a;
    sim->capmat = cap;
  }
  sim->mats[sim->nmat] = m;
  if (id) *id = sim->nmat;
  sim->nmat++;
  sim->scr.prepared = 0;
  return MPMC_SUCCESS;
}

/**
 * @brief Add a material of a model of the table by name, from its parameters.
 * @param model the model's name (mpmc_model_get_info; e.g. "hencky_j2")
 * @param par the model's stored parameters in the table's order (mpmc_model_get_param, k <
 *        nstore), in the table's units; NAN for an optional parameter takes its default
 * @param npar entries in par, at most the model's nstore: the parameters after them are left
 *        out (their defaults; an error naming the first required one)
 * @param[out] id the material's id (may be NULL)
 */
int mpmc_sim_add_material(mpmc_sim sim, const char *model, const double *par, int npar,
                          int *id) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  const mpmc_model *md = mpmc_model_named(model);
  MPMC_CHECK(md, ctx, MPMC_ERR_ARG, "unknown material model '%s'", model ? model : "(null)");
  MPMC_CHECK(!(md->flags & MPMC_MODEL_CALLBACK), ctx, MPMC_ERR_ARG,
             "model '%s' needs the caller's function: add it with its own constructor", md->name);
  MPMC_CHECK(npar >= 0 && npar <= md->nstore && (par || npar == 0), ctx, MPMC_ERR_ARG,
             "model '%s' takes at most %d parameters, got %d", md->name, md->nstore, npar);
  double full[MPMC_MAX_PARAM];
  for (int k = 0; k < md->nstore; ++k) full[k] = k < npar ? par[k] : NAN;
  return mpmc_material_add(sim, md, full, id);
}

/** @brief Number of material models in the table. */
int mpmc_model_count(int *n) {
  if (!n) return MPMC_ERR_ARG;
  *n = NMODEL;
  return MPMC_SUCCESS;
}

/** @brief The table index of the model called name (MPMC_ERR_ARG if there is none). */
int mpmc_model_find(const char *name, int *model) {
  if (!model) return MPMC_ERR_ARG;
  for (int k = 0; name && k < NMODEL; ++k)
    if (!strcmp(models[k]->name, name)) return *model = k, MPMC_SUCCESS;
  *model = -1;
  return MPMC_ERR_ARG;
}

/** @brief A model's description: name, one line, parameter counts, state. */
int mpmc_model_get_info(int model, mpmc_model_info *info) {
  const mpmc_model *md = mpmc_model_at(model);
  if (!md || !info) return MPMC_ERR_ARG;
  *info = (mpmc_model_info){.name = md->name,
                            .doc = md->doc,
                            .nparam = md->nparam,
                            .nstore = md->nstore,
                            .plastic = (md->flags & MPMC_MODEL_PLASTIC) != 0,
                            .needs_function = (md->flags & MPMC_MODEL_CALLBACK) != 0};
  return MPMC_SUCCESS;
}

/** @brief Parameter k of a model: name, unit, range, default, rules (mpmc_param_info). */
int mpmc_model_get_param(int model, int k, mpmc_param_info *info) {
  const mpmc_model *md = mpmc_model_at(model);
  if (!md || !info || k < 0 || k >= md->nparam) return MPMC_ERR_ARG;
  const mpmc_param_desc *d = &md->param[k];
  int nw = 0;
  while (d->words && d->words[nw]) ++nw;
  *info = (mpmc_param_info){.name = d->name,
                            .unit = d->unit,
                            .doc = d->doc,
                            .lo = d->lo,
                            .hi = d->hi,
                            .lo_open = (d->flags & MPMC_PARAM_LO_OPEN) != 0,
                            .hi_open = (d->flags & MPMC_PARAM_HI_OPEN) != 0,
                            .optional = (d->flags & MPMC_PARAM_OPTIONAL) != 0,
                            .def = d->def,
                            .default_of = d->default_of,
                            .at_most = d->at_most,
                            .alias_of = d->alias_of,
                            .scale = d->scale,
                            .strength = k < md->nstore ? md->strength[k] : 0,
                            .nwords = nw,
                            .words = d->words};
  return MPMC_SUCCESS;
}

/** @brief Number of materials added so far. */
int mpmc_sim_get_num_materials(mpmc_const_sim sim, int *n) {
  if (!sim || !n) return MPMC_ERR_ARG;
  *n = sim->nmat;
  return MPMC_SUCCESS;
}

/**
 * @brief A material's model (table index), its current (strength-reduced) parameters and the
 *        strength reduction factor applied to it.
 * @param[out] par the model's nstore parameters (may be NULL); room for MPMC_MAX_PARAMS
 */
int mpmc_sim_get_material(mpmc_const_sim sim, int material, int *model, double *par,
                          double *factor) {
  if (!sim) return MPMC_ERR_ARG;
  MPMC_CHECK(material >= 0 && material < sim->nmat, sim->ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  const mpmc_material *m = &sim->mats[material];
  if (model)
    for (int k = 0; k < NMODEL; ++k)
      if (models[k] == m->model) *model = k;
  if (par)
    for (int k = 0; k < m->model->nstore; ++k) par[k] = m->par[k];
  if (factor) *factor = m->srm;
  return MPMC_SUCCESS;
}

static int model_reducible(const mpmc_model *md) {
  for (int k = 0; k < md->nstore; ++k)
    if (md->strength[k] != MPMC_SRM_KEEP) return 1;
  return 0;
}

/* Strength reduction of m to the total factor F = m->srm: each strength of par0 divided by
 * F, each friction or dilation angle to atan(tan(angle) / F) (the standard SRM). */
static int apply_srm(mpmc_context ctx, mpmc_material *m) {
  const mpmc_model *md = m->model;
  for (int k = 0; k < md->nstore; ++k) {
    const double v = m->par0[k], F = m->srm;
    switch (md->strength[k]) {
      case MPMC_SRM_DIVIDE: m->par[k] = F == 1.0 ? v : v / F; break;
      case MPMC_SRM_TAN:
        m->par[k] = F == 1.0 ? v : atan(tan(v * MPMC_RAD) / F) / MPMC_RAD;
        break;
      default: m->par[k] = v;
    }
  }
  return mpmc_material_setup(ctx, m);
}

/* A material read back (checkpoint.c): par0 validated, then reduced by m->srm. */
int mpmc_material_restore(mpmc_context ctx, mpmc_material *m) {
  MPMC_CALL(validate(ctx, m->model, m->par0));
  return apply_srm(ctx, m);
}

static int srm_each(mpmc_sim sim, int material, double factor, int absolute) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  MPMC_CHECK(isfinite(factor) && factor > 0, ctx, MPMC_ERR_ARG,
             "strength reduction factor = %g must be > 0", factor);
  MPMC_CHECK(material >= -1 && material < sim->nmat, ctx, MPMC_ERR_ARG,
             "material id %d does not exist (%d materials)", material, sim->nmat);
  int count = 0;
  for (int i = 0; i < sim->nmat; ++i) {
    if (material != -1 && i != material) continue;
    mpmc_material *m = &sim->mats[i];
    if (!model_reducible(m->model)) continue;
    m->srm = absolute ? factor : m->srm * factor;
    MPMC_CALL(apply_srm(ctx, m));
    ++count;
  }
  MPMC_CHECK(count > 0, ctx, MPMC_ERR_ARG,
             material == -1 ? "no plastic material to reduce (material %d)"
                            : "material %d is not plastic: nothing to reduce",
             material);
  return MPMC_SUCCESS;
}

/**
 * @brief Divide the strengths of a plastic material (or all, material = -1) by factor
 *        (strength reduction between stages): the model's strengths (J2: kappa; Mohr-Coulomb
 *        and Drucker-Prager: c, tan phi, tan psi, the tension cut-off) are divided; factors
 *        compose.  Accumulated plastic strain is kept.
 */
int mpmc_sim_reduce_strength(mpmc_sim sim, int material, double factor) {
  return srm_each(sim, material, factor, 0);
}

/**
 * @brief Set the total strength reduction factor of a plastic material (or all, -1): the
 *        strengths as given divided by factor (1 restores them), whatever was applied before.
 */
int mpmc_sim_set_strength_reduction(mpmc_sim sim, int material, double factor) {
  return srm_each(sim, material, factor, 1);
}

/* Elastic constants from par[0..2] = E, nu, rho (the solid models' first three). */
void mpmc_material_elastic(mpmc_material *m) {
  const double E = m->par[0], nu = m->par[1];
  m->E = E;
  m->nu = nu;
  m->rho = m->par[2];
  m->G = E / (2.0 * (1.0 + nu));
  m->K = E / (3.0 * (1.0 - 2.0 * nu));
  m->lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
}
