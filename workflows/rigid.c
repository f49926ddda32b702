/* Rigid bodies in scenes (scene key rigid_bodies, stage key rigid_bodies) and the
 * bearing_capacity_ratio metric (docs/contact.md, docs/workflows.md).
 *
 * A stage sets a body's velocity; with `ramp: T` the velocity goes linearly in time from the
 * one in force before the stage to the stage's over the first T seconds (a sudden start
 * sends a stress wave rho c v into the soil).
 *
 * bearing_capacity_ratio: after every step the footing's settlement delta = -offset[axis]
 * and its load q = reaction[axis] / loaded_width are recorded; the ratio is the mean of
 * q/su over the steps whose settlement is at least `from` (default 1/2) of the final one,
 * i.e. over the second half of the settlement, where the load-displacement curve has
 * levelled off.  Prandtl: 2 + pi for a strip footing on weightless Tresca soil.
 *
 * The metric's `su` is the strength the load is divided by, the soil's cohesion in the
 * Mohr-Coulomb failure criterion: su = kappa_p / sqrt(3) for hencky_j2 (Tresca's strength in
 * plane strain), c for mohr_coulomb and drucker_prager (Prandtl's q/c = N_c(phi), 14.83 at
 * phi = 20 degrees).  The column keeps the name q_over_su for every model.  When the scene
 * has one material with such a strength, `su` must equal it (an override of the material's
 * strength without the metric's would report a ratio to the wrong strength). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wf.h"

struct wf_bearing {
  int n, cap;
  double *delta, *q; /* settlement / B and q / su per step */
  int mark, prev;    /* series rows average the samples [mark, n), or [prev, mark) */
};

/** @brief Add the scene's rigid bodies (ids 0, 1, ... in scene order) and barrier parameters. */
int wf_rigid_build(mpmc_sim sim, wf_scene *sc, char *msg, size_t len) {
  if (sc->nrigid == 0) return 0;
  for (int i = 0; i < sc->nrigid; ++i) {
    wf_rigid *b = &sc->rigid[i];
    const int e = b->type == WF_GEOM_BOX ? mpmc_sim_add_rigid_box(sim, b->lo, b->hi, b->friction, &b->id)
                                         : mpmc_sim_add_rigid_polygon(sim, b->nvert, b->xy, b->friction, &b->id);
    if (e) {
      snprintf(msg, len, "rigid_bodies.%s", b->name);
      return e;
    }
  }
  const int e = mpmc_sim_set_contact_params(sim, sc->contact_dhat, sc->contact_kappa);
  if (e) snprintf(msg, len, "contact");
  return e;
}

/* The velocity of body k in force during stage i at t_stage into it. */
static void body_velocity(const wf_scene *sc, int k, int stage, double t_stage, double *v) {
  double prev[3] = {0, 0, 0}, cur[3] = {0, 0, 0};
  double ramp = 0.0;
  for (int j = 0; j <= stage; ++j)
    for (int m = 0; m < sc->stages[j].nmotion; ++m) {
      const wf_rigid_motion *mo = &sc->stages[j].motion[m];
      if (mo->body != k) continue;
      memcpy(prev, cur, sizeof prev);
      memcpy(cur, mo->velocity, sizeof cur);
      ramp = j == stage ? mo->ramp : 0.0;
    }
  const double f = ramp > 0 && t_stage < ramp ? t_stage / ramp : 1.0;
  for (int a = 0; a < 3; ++a) v[a] = prev[a] + f * (cur[a] - prev[a]);
}

/** @brief Set every rigid body's velocity for the next step of stage `stage`. */
int wf_rigid_before_step(mpmc_sim sim, const wf_scene *sc, int stage, double t_stage, char *msg, size_t len) {
  for (int k = 0; k < sc->nrigid; ++k) {
    double v[3];
    body_velocity(sc, k, stage, t_stage, v);
    const int e = mpmc_sim_set_rigid_velocity(sim, sc->rigid[k].id, v);
    if (e) {
      snprintf(msg, len, "stages.%d.rigid_bodies.%s", stage, sc->rigid[k].name);
      return e;
    }
  }
  return 0;
}

/* The strength q is divided by (see the top of the file) of the scene's one material that
 * has one, in *s with the key's name; 0 when none or several have one. */
static int soil_strength(const wf_scene *sc, double *s, const char **key) {
  int found = 0;
  for (int i = 0; i < sc->nmat; ++i) {
    const wf_material *mat = &sc->mats[i];
    for (int k = 0; k < mat->npar; ++k) {
      mpmc_param_info pi;
      if (mpmc_model_get_param(mat->model, k, &pi)) continue;
      if (!strcmp(pi.name, "kappa_p")) *s = mat->par[k] / sqrt(3.0), *key = "su = kappa_p / sqrt(3)";
      else if (!strcmp(pi.name, "c")) *s = mat->par[k], *key = "c";
      else continue;
      ++found;
      break;
    }
  }
  return found == 1;
}

/** @brief Record the footing's settlement and load after a step (bearing_capacity_ratio). */
int wf_rigid_after_step(mpmc_sim sim, const wf_scene *sc, char *msg, size_t len) {
  const wf_metrics *m = &sc->metrics;
  if (!m->enabled[WF_METRIC_BEARING]) return 0;
  struct wf_bearing *b = m->bearing;
  if (!b) {
    b = calloc(1, sizeof *b);
    if (!b) return snprintf(msg, len, "bearing_capacity_ratio: out of memory"), MPMC_ERR_MEMORY;
    ((wf_scene *)sc)->metrics.bearing = b; /* the record is run-time state, not scene input */
    double s;
    const char *key;
    if (soil_strength(sc, &s, &key) && fabs(s - m->bearing_su) > 1e-9 * s)
      return snprintf(msg, len,
                      "metrics.bearing_capacity_ratio.su = %g Pa is not the soil's strength (%s = %g Pa): "
                      "the ratio divides by it, set the two alike",
                      m->bearing_su, key, s),
             MPMC_ERR_ARG;
  }
  if (b->n == b->cap) {
    const int cap = b->cap ? 2 * b->cap : 4096;
    double *d = realloc(b->delta, sizeof *d * (size_t)cap);
    if (d) b->delta = d;
    double *q = d ? realloc(b->q, sizeof *q * (size_t)cap) : NULL;
    if (!q) return snprintf(msg, len, "bearing_capacity_ratio: out of memory"), MPMC_ERR_MEMORY;
    b->q = q;
    b->cap = cap;
  }
  const int id = sc->rigid[m->bearing_body].id;
  double off[3] = {0, 0, 0}, f[3] = {0, 0, 0};
  int e = mpmc_sim_get_rigid_offset(sim, id, off);
  if (!e) e = mpmc_sim_get_rigid_reaction(sim, id, f);
  if (e) return snprintf(msg, len, "metrics.bearing_capacity_ratio"), e;
  b->delta[b->n] = -off[m->bearing_axis] / m->bearing_B;
  b->q[b->n] = f[m->bearing_axis] / m->bearing_width / m->bearing_su;
  b->n++;
  return 0;
}

/** @brief delta/B, q/su (mean since the previous series row) and the bearing ratio. */
void wf_bearing_values(const wf_scene *sc, int mark, double *delta_b, double *q_su, double *ratio) {
  struct wf_bearing *b = sc->metrics.bearing;
  *delta_b = *q_su = *ratio = NAN;
  if (!b || b->n == 0) return;
  *delta_b = b->delta[b->n - 1];
  int lo = b->mark, hi = b->n;
  if (lo >= hi) lo = b->prev, hi = b->mark; /* nothing new: the last row's interval */
  double s = 0;
  for (int i = lo; i < hi; ++i) s += b->q[i];
  *q_su = hi > lo ? s / (hi - lo) : b->q[b->n - 1];
  if (mark && b->mark < b->n) {
    b->prev = b->mark;
    b->mark = b->n;
  }
  double dmax = -INFINITY;
  for (int i = 0; i < b->n; ++i) dmax = fmax(dmax, b->delta[i]);
  const double from = sc->metrics.bearing_from * dmax;
  double sum = 0;
  int cnt = 0;
  for (int i = 0; i < b->n; ++i)
    if (b->delta[i] >= from) sum += b->q[i], ++cnt;
  *ratio = cnt ? sum / cnt : NAN;
}

void wf_rigid_free(wf_scene *sc) {
  for (int i = 0; i < sc->nrigid && sc->rigid; ++i) free(sc->rigid[i].xy);
  free(sc->rigid);
  sc->rigid = NULL;
  sc->nrigid = 0;
  for (int i = 0; i < sc->nstage && sc->stages; ++i) {
    free(sc->stages[i].motion);
    sc->stages[i].motion = NULL;
  }
  struct wf_bearing *b = sc->metrics.bearing;
  if (b) {
    free(b->delta);
    free(b->q);
    free(b);
  }
  sc->metrics.bearing = NULL;
}
