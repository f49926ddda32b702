/* The scene schema: typed, range-checked reading of a scene file's tree (yaml.c: the tree,
 * with file:line:column for every key and value, and the `--set` overrides) into wf_scene.
 * Every error names the position and the key: "slope.yaml:12:5: key 'grid.cell_size': must
 * be > 0 (got -1)". */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "wf.h"

/* ---- reading with checks ----------------------------------------------------------- */
typedef struct {
  char *msg;
  size_t len;
  int failed;
} rd;

static void where_of(const wf_node *n, char *buf, size_t len) {
  if (!n)
    snprintf(buf, len, "(scene)");
  else if (n->line > 0)
    snprintf(buf, len, "%s:%d:%d", n->origin, n->line, n->col);
  else
    snprintf(buf, len, "%s", n->origin);
}

static int fail_at(rd *r, const wf_node *n, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int fail_at(rd *r, const wf_node *n, const char *path, const char *fmt, ...) {
  if (r->failed) return -1; /* keep the first message */
  char where[WF_PATH + 32], body[WF_MSG];
  where_of(n, where, sizeof where);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(body, sizeof body, fmt, ap);
  va_end(ap);
  snprintf(r->msg, r->len, "%s: key '%s': %s", where, path, body);
  r->failed = 1;
  return -1;
}

static int edit_distance(const char *a, const char *b) {
  const size_t la = strlen(a), lb = strlen(b);
  if (la > 63 || lb > 63) return 99;
  int d[64][64];
  for (size_t i = 0; i <= la; ++i) d[i][0] = (int)i;
  for (size_t j = 0; j <= lb; ++j) d[0][j] = (int)j;
  for (size_t i = 1; i <= la; ++i)
    for (size_t j = 1; j <= lb; ++j) {
      const int c = tolower((unsigned char)a[i - 1]) != tolower((unsigned char)b[j - 1]);
      int v = d[i - 1][j] + 1;
      if (d[i][j - 1] + 1 < v) v = d[i][j - 1] + 1;
      if (d[i - 1][j - 1] + c < v) v = d[i - 1][j - 1] + c;
      d[i][j] = v;
    }
  return d[la][lb];
}

/* A map whose keys must all be in allowed (NULL-terminated). */
static int check_map(rd *r, const wf_node *n, const char *path, const char *const *allowed) {
  if (!n || n->kind != WF_MAP)
    return fail_at(r, n, path, "expected a map of keys (got %s)",
                   !n ? "nothing" : n->kind == WF_SEQ ? "a list" : "a value");
  for (int i = 0; i < n->n; ++i) {
    int ok = 0, best = 99;
    const char *sugg = NULL;
    for (const char *const *a = allowed; *a; ++a) {
      if (strcmp(*a, n->keys[i]) == 0) ok = 1;
      const int dist = edit_distance(*a, n->keys[i]);
      if (dist < best) {
        best = dist;
        sugg = *a;
      }
    }
    if (!ok) {
      char full[512], where[WF_PATH + 32];
      wf_key_join(full, sizeof full, path, n->keys[i]);
      if (r->failed) return -1;
      snprintf(where, sizeof where, "%s:%d:%d", n->origin, n->key_line[i], n->key_col[i]);
      if (n->line == 0 || n->key_line[i] == 0) snprintf(where, sizeof where, "--set");
      char valid[512] = "";
      for (const char *const *a = allowed; *a; ++a) {
        const size_t l = strlen(valid);
        snprintf(valid + l, sizeof valid - l, "%s%s", l ? ", " : "", *a);
      }
      if (sugg && best <= 3)
        snprintf(r->msg, r->len, "%s: key '%s': unknown key (did you mean '%s'?)", where, full, sugg);
      else
        snprintf(r->msg, r->len, "%s: key '%s': unknown key (valid keys: %s)", where, full, valid);
      r->failed = 1;
      return -1;
    }
  }
  return 0;
}

static int parse_number(const wf_node *n, double *v) {
  if (!n || n->kind != WF_SCALAR || n->quoted || !n->value[0]) return -1;
  const char *s = n->value;
  if (!strcmp(s, ".inf") || !strcmp(s, "+.inf")) return *v = INFINITY, 0;
  char *end;
  errno = 0;
  const double x = strtod(s, &end);
  while (*end == ' ') ++end;
  if (*end || errno == ERANGE || isnan(x)) return -1;
  *v = x;
  return 0;
}

static const char *shown(const wf_node *n) {
  if (!n) return "nothing";
  if (n->kind == WF_SEQ) return "a list";
  if (n->kind == WF_MAP) return "a map";
  return n->value;
}

/* Range: value must satisfy lo (<= or <) v (<= or <) hi. */
typedef struct {
  double lo, hi;
  int lo_open, hi_open;
} range;
static const range ANY = {-INFINITY, INFINITY, 0, 0};
static const range POS = {0, INFINITY, 1, 0};
static const range NONNEG = {0, INFINITY, 0, 0};
static const range UNIT = {0, 1, 0, 0};

static int check_range(rd *r, const wf_node *n, const char *path, double v, range g) {
  const int below = g.lo_open ? !(v > g.lo) : !(v >= g.lo);
  const int above = g.hi_open ? !(v < g.hi) : !(v <= g.hi);
  if (!below && !above && isfinite(v)) return 0;
  if (isinf(g.hi))
    return fail_at(r, n, path, "must be %s %g (got %g)", g.lo_open ? ">" : ">=", g.lo, v);
  if (isinf(g.lo))
    return fail_at(r, n, path, "must be %s %g (got %g)", g.hi_open ? "<" : "<=", g.hi, v);
  return fail_at(r, n, path, "must be in %c%g, %g%c (got %g)", g.lo_open ? '(' : '[', g.lo, g.hi,
                 g.hi_open ? ')' : ']', v);
}

/* Read map[key] as a number; absent: def if !required. */
static int get_num(rd *r, const wf_node *map, const char *path, const char *key, int required,
                   double def, range g, double *out) {
  char full[512];
  wf_key_join(full, sizeof full, path, key);
  const wf_node *n = wf_map_get(map, key);
  if (!n) {
    if (required) return fail_at(r, map, full, "required key is missing");
    *out = def;
    return 0;
  }
  double v;
  if (parse_number(n, &v)) return fail_at(r, n, full, "expected a number (got '%s')", shown(n));
  if (check_range(r, n, full, v, g)) return -1;
  *out = v;
  return 0;
}

static int get_int(rd *r, const wf_node *map, const char *path, const char *key, int required,
                   int def, int lo, int hi, int *out) {
  double v = 0.0;
  char full[512];
  wf_key_join(full, sizeof full, path, key);
  const range g = {lo, hi, 0, 0};
  if (get_num(r, map, path, key, required, def, g, &v)) return -1;
  if (v != floor(v)) return fail_at(r, wf_map_get(map, key), full, "expected a whole number (got %g)", v);
  *out = (int)v;
  return 0;
}

/* 1 or 0 for a YAML boolean word, -1 for anything else */
static int bool_word(const wf_node *n) {
  static const char *yes[] = {"true", "yes", "on", "True", "TRUE", NULL};
  static const char *no[] = {"false", "no", "off", "False", "FALSE", NULL};
  if (n->kind == WF_SCALAR && !n->quoted) {
    for (int i = 0; yes[i]; ++i)
      if (!strcmp(n->value, yes[i])) return 1;
    for (int i = 0; no[i]; ++i)
      if (!strcmp(n->value, no[i])) return 0;
  }
  return -1;
}

static int get_bool(rd *r, const wf_node *map, const char *path, const char *key, int def, int *out) {
  char full[512];
  wf_key_join(full, sizeof full, path, key);
  const wf_node *n = wf_map_get(map, key);
  if (!n) return *out = def, 0;
  const int b = bool_word(n);
  if (b >= 0) return *out = b, 0;
  return fail_at(r, n, full, "expected true or false (got '%s')", shown(n));
}

static int get_str(rd *r, const wf_node *map, const char *path, const char *key, int required,
                   const char *def, char *out, size_t len) {
  char full[512];
  wf_key_join(full, sizeof full, path, key);
  const wf_node *n = wf_map_get(map, key);
  if (!n) {
    if (required) return fail_at(r, map, full, "required key is missing");
    snprintf(out, len, "%s", def);
    return 0;
  }
  if (n->kind != WF_SCALAR) return fail_at(r, n, full, "expected a text value (got %s)", shown(n));
  if (strlen(n->value) >= len)
    return fail_at(r, n, full, "longer than %zu characters", len - 1);
  snprintf(out, len, "%s", n->value);
  return 0;
}

/* One of a fixed set of words; returns its index in *out. */
static int get_enum(rd *r, const wf_node *map, const char *path, const char *key, int required,
                    int def, const char *const *words, int *out) {
  char full[512], buf[WF_NAME];
  wf_key_join(full, sizeof full, path, key);
  if (get_str(r, map, path, key, required, "", buf, sizeof buf)) return -1;
  if (!wf_map_get(map, key)) return *out = def, 0;
  char list[256] = "";
  for (int i = 0; words[i]; ++i) {
    if (!strcmp(buf, words[i])) return *out = i, 0;
    const size_t l = strlen(list);
    snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", words[i]);
  }
  return fail_at(r, wf_map_get(map, key), full, "must be one of %s (got '%s')", list, buf);
}

/* A list of exactly n numbers. */
static int get_vec(rd *r, const wf_node *map, const char *path, const char *key, int required,
                   int n, range g, double *out) {
  char full[512];
  wf_key_join(full, sizeof full, path, key);
  const wf_node *v = wf_map_get(map, key);
  if (!v) {
    if (required) return fail_at(r, map, full, "required key is missing");
    return 0;
  }
  if (v->kind != WF_SEQ || v->n != n)
    return fail_at(r, v, full, "expected a list of %d numbers, e.g. [%s] (got %s%s)", n,
                   n == 2 ? "0, 0" : "0, 0, 0",
                   v->kind == WF_SEQ ? "a list of " : "'", v->kind == WF_SEQ ? "" : shown(v));
  for (int i = 0; i < n; ++i) {
    char item[560];
    snprintf(item, sizeof item, "%s.%d", full, i);
    if (parse_number(v->items[i], &out[i]))
      return fail_at(r, v->items[i], item, "expected a number (got '%s')", shown(v->items[i]));
    if (check_range(r, v->items[i], item, out[i], g)) return -1;
  }
  return 0;
}

/* A list of at least `min` points [x, y] under key (required) into a new array *xy of *n pairs. */
static int get_points(rd *r, const wf_node *map, const char *path, const char *key, int min, double **xy,
                      int *n) {
  char full[512];
  wf_key_join(full, sizeof full, path, key);
  const wf_node *v = wf_map_get(map, key);
  if (!v) return fail_at(r, map, full, "required key is missing");
  if (v->kind != WF_SEQ || v->n < min)
    return fail_at(r, v, full, "expected a list of at least %d [x, y] point%s", min, min == 1 ? "" : "s");
  *xy = malloc(sizeof(double) * 2 * (size_t)v->n);
  if (!*xy) return fail_at(r, v, full, "out of memory");
  *n = v->n;
  for (int k = 0; k < v->n; ++k) {
    char item[560];
    snprintf(item, sizeof item, "%s.%d", full, k);
    const wf_node *p = v->items[k];
    double *q = *xy + 2 * k;
    if (!p || p->kind != WF_SEQ || p->n != 2 || parse_number(p->items[0], &q[0]) || parse_number(p->items[1], &q[1]))
      return fail_at(r, p, item, "expected a point [x, y] (got %s)", shown(p));
    if (!isfinite(q[0]) || !isfinite(q[1]))
      return fail_at(r, p, item, "expected finite coordinates (got [%g, %g])", q[0], q[1]);
  }
  return 0;
}

/* ---- the scene schema ------------------------------------------------------------------ */
static const char *const basis_words[] = {"linear", "ugimp", "bspline2", "bspline3", NULL};
static const char *const wall_kind_words[] = {"fixed", "slip", "separable", NULL};
static const char *const axis_words[] = {"x", "y", "z", NULL};
static const char *const face_words[] = {"x_lo", "x_hi", "y_lo", "y_hi", "z_lo", "z_hi", NULL};
static const char *const solver_words[] = {"auto", "newton", "kinsol", NULL};

const char *wf_basis_name(int b) { return b >= 0 && b < 4 ? basis_words[b] : "?"; }
const char *wf_model_name(int m) {
  mpmc_model_info mi;
  return mpmc_model_get_info(m, &mi) ? "?" : mi.name;
}

/* The models a scene may name: those of the library's table that need no function. */
static int scene_models(const char **words, int cap) {
  int n = 0, nm = 0;
  mpmc_model_count(&nm);
  for (int k = 0; k < nm && n < cap - 1; ++k) {
    mpmc_model_info mi;
    if (!mpmc_model_get_info(k, &mi) && !mi.needs_function) words[n++] = mi.name;
  }
  words[n] = NULL;
  return n;
}

/* One material: its keys are the model's parameters in the library's table (names, units,
 * ranges, defaults, aliases and "must not exceed" rules), so the scene, `mpmc check` and
 * the library validate alike; messages name the file, line and key. */
static int read_material(rd *r, const wf_node *mn, const char *path, wf_material *m) {
  const char *words[WF_MAX_MODELS + 1];
  scene_models(words, WF_MAX_MODELS + 1);
  int w;
  if (get_enum(r, mn, path, "model", 1, 0, words, &w)) return -1;
  if (mpmc_model_find(words[w], &m->model)) return fail_at(r, mn, path, "unknown model");
  mpmc_model_info mi;
  mpmc_model_get_info(m->model, &mi);
  const char *keys[MPMC_MAX_PARAMS + 8];
  mpmc_param_info pi[MPMC_MAX_PARAMS + 8];
  int nk = 0;
  keys[nk++] = "model";
  for (int k = 0; k < mi.nparam && k < MPMC_MAX_PARAMS + 6; ++k) {
    mpmc_model_get_param(m->model, k, &pi[k]);
    keys[nk++] = pi[k].name;
  }
  keys[nk] = NULL;
  if (check_map(r, mn, path, keys)) return -1;
  m->npar = mi.nstore;
  char full[512];
  for (int k = 0; k < mi.nstore; ++k) m->par[k] = NAN;
  /* aliases first: su gives kappa_p = sqrt(3) su, unless kappa_p is given too */
  for (int k = mi.nstore; k < mi.nparam; ++k) {
    const mpmc_param_info *a = &pi[k];
    const wf_node *an = wf_map_get(mn, a->name);
    if (!an) continue;
    wf_key_join(full, sizeof full, path, a->name);
    if (wf_map_get(mn, pi[a->alias_of].name))
      return fail_at(r, an, full, "give %s or %s, not both", pi[a->alias_of].name, a->name);
    const range g = {a->lo, a->hi, a->lo_open, a->hi_open};
    double v;
    if (get_num(r, mn, path, a->name, 1, 0, g, &v)) return -1;
    m->par[a->alias_of] = a->scale * v;
  }
  for (int k = 0; k < mi.nstore; ++k) {
    const mpmc_param_info *q = &pi[k];
    if (!isnan(m->par[k])) continue; /* given by its alias */
    const wf_node *qn = wf_map_get(mn, q->name);
    wf_key_join(full, sizeof full, path, q->name);
    if (!qn && !q->optional) {
      char alias[64] = "";
      for (int a = mi.nstore; a < mi.nparam; ++a)
        if (pi[a].alias_of == k) snprintf(alias, sizeof alias, " (or %s)", pi[a].name);
      return fail_at(r, mn, full, "required key is missing%s: %s [%s]", alias, q->doc, q->unit);
    }
    if (!qn) continue; /* the library's default */
    if (q->nwords > 0) {
      int c;
      if (get_enum(r, mn, path, q->name, 1, 0, q->words, &c)) return -1;
      m->par[k] = c;
      continue;
    }
    const range g = {q->lo, q->hi, q->lo_open, q->hi_open};
    if (get_num(r, mn, path, q->name, 1, 0, g, &m->par[k])) return -1;
  }
  /* defaults as the library takes them, then the "must not exceed" rules */
  for (int k = 0; k < mi.nstore; ++k)
    if (isnan(m->par[k]) && pi[k].optional)
      m->par[k] = pi[k].default_of >= 0 ? m->par[pi[k].default_of] : pi[k].def;
  for (int k = 0; k < mi.nstore; ++k) {
    const int t = pi[k].at_most;
    if (t < 0 || !(m->par[k] > m->par[t])) continue;
    const char *key = pi[k].name;
    for (int a = mi.nstore; a < mi.nparam; ++a)
      if (pi[a].alias_of == k && wf_map_get(mn, pi[a].name)) key = pi[a].name;
    const wf_node *kn = wf_map_get(mn, key);
    wf_key_join(full, sizeof full, path, key);
    return fail_at(r, kn ? kn : mn, full, "must not exceed %s = %g (got %g)", pi[t].name,
                   m->par[t], m->par[k]);
  }
  return 0;
}

static int read_materials(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *ms = wf_map_get(root, "materials");
  if (!ms) return fail_at(r, root, "materials", "required key is missing");
  if (ms->kind != WF_MAP || ms->n == 0)
    return fail_at(r, ms, "materials", "expected a map of named materials, e.g. clay: {model: hencky_j2, ...}");
  sc->nmat = ms->n;
  sc->mats = calloc((size_t)ms->n, sizeof *sc->mats);
  if (!sc->mats) return fail_at(r, ms, "materials", "out of memory");
  for (int i = 0; i < ms->n; ++i) {
    wf_material *m = &sc->mats[i];
    char path[256];
    snprintf(path, sizeof path, "materials.%s", ms->keys[i]);
    snprintf(m->name, sizeof m->name, "%s", ms->keys[i]);
    if (read_material(r, ms->items[i], path, m)) return -1;
  }
  return 0;
}

static int find_material(rd *r, const wf_scene *sc, const wf_node *map, const char *path, int *out) {
  char name[WF_NAME], full[512];
  wf_key_join(full, sizeof full, path, "material");
  if (get_str(r, map, path, "material", sc->nmat != 1, sc->mats[0].name, name, sizeof name)) return -1;
  for (int i = 0; i < sc->nmat; ++i)
    if (!strcmp(sc->mats[i].name, name)) return *out = i, 0;
  char list[256] = "";
  for (int i = 0; i < sc->nmat; ++i) {
    const size_t l = strlen(list);
    snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", sc->mats[i].name);
  }
  return fail_at(r, wf_map_get(map, "material"), full, "no material '%s' (materials: %s)", name, list);
}

static int file_exists(const char *p) {
  struct stat s;
  return stat(p, &s) == 0 && S_ISREG(s.st_mode);
}

static int read_geometry(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *gs = wf_map_get(root, "geometry");
  if (!gs) return fail_at(r, root, "geometry", "required key is missing");
  if (gs->kind != WF_SEQ || gs->n == 0)
    return fail_at(r, gs, "geometry", "expected a list of bodies, e.g. - {type: box, lo: [..], hi: [..]}");
  sc->nbody = gs->n;
  sc->bodies = calloc((size_t)gs->n, sizeof *sc->bodies);
  if (!sc->bodies) return fail_at(r, gs, "geometry", "out of memory");
  static const char *const types[] = {"box", "polygon", "gmsh", NULL};
  static const char *const modes[] = {"lattice", "quadrature", NULL};
  static const char *const keys[] = {"type", "material", "ppc", "lo", "hi", "vertices", "file",
                                     "seeding", "region", "velocity", NULL};
  for (int i = 0; i < gs->n; ++i) {
    wf_body *b = &sc->bodies[i];
    const wf_node *g = gs->items[i];
    char path[64], full[512];
    snprintf(path, sizeof path, "geometry.%d", i);
    if (check_map(r, g, path, keys)) return -1;
    if (get_enum(r, g, path, "type", 1, 0, types, &b->type)) return -1;
    if (find_material(r, sc, g, path, &b->material)) return -1;
    if (get_int(r, g, path, "ppc", 0, 2, 1, 8, &b->ppc)) return -1;
    if (get_vec(r, g, path, "velocity", 0, sc->dim, ANY, b->velocity)) return -1;
    if (b->type == WF_GEOM_BOX) {
      if (get_vec(r, g, path, "lo", 1, sc->dim, ANY, b->lo) || get_vec(r, g, path, "hi", 1, sc->dim, ANY, b->hi))
        return -1;
      for (int a = 0; a < sc->dim; ++a)
        if (b->hi[a] <= b->lo[a]) {
          wf_key_join(full, sizeof full, path, "hi");
          return fail_at(r, wf_map_get(g, "hi"), full, "component %d must be > lo (%g) (got %g)", a,
                         b->lo[a], b->hi[a]);
        }
    } else if (b->type == WF_GEOM_POLYGON) {
      wf_key_join(full, sizeof full, path, "vertices");
      if (sc->dim != 2) return fail_at(r, wf_map_get(g, "type"), full, "polygons are 2D only (dim = %d)", sc->dim);
      if (get_points(r, g, path, "vertices", 3, &b->xy, &b->nvert)) return -1;
    } else {
      char file[WF_PATH];
      wf_key_join(full, sizeof full, path, "file");
      if (get_str(r, g, path, "file", 1, "", file, sizeof file)) return -1;
      if (file[0] == '/')
        snprintf(b->file, sizeof b->file, "%s", file);
      else if (snprintf(b->file, sizeof b->file, "%s/%s", sc->dir, file) >= (int)sizeof b->file)
        return fail_at(r, wf_map_get(g, "file"), full, "path too long");
      if (!file_exists(b->file))
        return fail_at(r, wf_map_get(g, "file"), full, "mesh file '%s' not found (paths are relative to the scene file)",
                       b->file);
      if (get_enum(r, g, path, "seeding", 0, MPMC_SEED_LATTICE, modes, &b->mode)) return -1;
      if (get_str(r, g, path, "region", 1, "", b->region, sizeof b->region)) return -1;
    }
  }
  return 0;
}

static int read_walls(rd *r, const wf_node *list, const char *path, const wf_scene *sc, wf_stage *s) {
  if (list->kind != WF_SEQ) return fail_at(r, list, path, "expected a list of walls");
  s->nwalls = list->n;
  s->walls = calloc((size_t)list->n + 1, sizeof *s->walls);
  if (!s->walls) return fail_at(r, list, path, "out of memory");
  static const char *const keys[] = {"name", "kind", "face", "axis", "side", "position", "lo", "hi", "set", NULL};
  static const char *const sides[] = {"below", "above", NULL};
  for (int i = 0; i < list->n; ++i) {
    wf_wall *w = &s->walls[i];
    const wf_node *n = list->items[i];
    char p[256], full[512];
    snprintf(p, sizeof p, "%s.%d", path, i);
    if (check_map(r, n, p, keys)) return -1;
    if (get_str(r, n, p, "name", 0, "", w->name, sizeof w->name)) return -1;
    if (get_enum(r, n, p, "kind", 1, 0, wall_kind_words, &w->kind)) return -1;
    int side = 0;
    if (wf_map_get(n, "face")) {
      w->form = 0;
      if (get_enum(r, n, p, "face", 1, 0, face_words, &w->face)) return -1;
      wf_key_join(full, sizeof full, p, "face");
      if (w->face >= 2 * sc->dim) return fail_at(r, wf_map_get(n, "face"), full, "no such face in %dD", sc->dim);
    } else if (wf_map_get(n, "position")) {
      w->form = 1;
      if (get_enum(r, n, p, "axis", 1, 0, axis_words, &w->axis)) return -1;
      if (get_num(r, n, p, "position", 1, 0, ANY, &w->position)) return -1;
      if (get_enum(r, n, p, "side", 1, 0, sides, &side)) return -1;
      w->side = side ? 1 : -1;
    } else if (wf_map_get(n, "lo") || wf_map_get(n, "hi")) {
      w->form = 2;
      if (get_vec(r, n, p, "lo", 1, sc->dim, ANY, w->lo) || get_vec(r, n, p, "hi", 1, sc->dim, ANY, w->hi))
        return -1;
      if (get_enum(r, n, p, "axis", w->kind != MPMC_WALL_FIXED, 0, axis_words, &w->axis)) return -1;
      if (get_enum(r, n, p, "side", w->kind == MPMC_WALL_SEPARABLE, 0, sides, &side)) return -1;
      w->side = side ? 1 : -1;
    } else if (wf_map_get(n, "set")) {
      /* the nodes of a gmsh boundary group (node set); checked against the mesh at run time */
      w->form = 3;
      if (get_str(r, n, p, "set", 1, "", w->set, sizeof w->set)) return -1;
      if (get_enum(r, n, p, "axis", w->kind != MPMC_WALL_FIXED, 0, axis_words, &w->axis)) return -1;
      if (get_enum(r, n, p, "side", w->kind == MPMC_WALL_SEPARABLE, 0, sides, &side)) return -1;
      w->side = side ? 1 : -1;
    } else {
      return fail_at(r, n, p, "a wall needs face, or axis+position+side, or a box lo+hi, or a node set");
    }
    wf_key_join(full, sizeof full, p, "axis");
    if (w->axis >= sc->dim) return fail_at(r, wf_map_get(n, "axis"), full, "no axis z in 2D");
  }
  return 0;
}

/* rigid_bodies: a list of {name, type: box|polygon, lo/hi | vertices, friction}; contact:
 * {dhat, kappa} (rigid.c, docs/contact.md).  Read before the stages, which move them. */
static int read_rigid(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *cn = wf_map_get(root, "contact");
  if (cn) {
    static const char *const ck[] = {"dhat", "kappa", NULL};
    if (check_map(r, cn, "contact", ck)) return -1;
    if (get_num(r, cn, "contact", "dhat", 0, 0, NONNEG, &sc->contact_dhat) ||
        get_num(r, cn, "contact", "kappa", 0, 0, NONNEG, &sc->contact_kappa))
      return -1;
  }
  const wf_node *rs = wf_map_get(root, "rigid_bodies");
  if (!rs) return 0;
  if (rs->kind != WF_SEQ || rs->n == 0)
    return fail_at(r, rs, "rigid_bodies", "expected a list of bodies, e.g. - {name: footing, type: box, lo: [..], hi: [..]}");
  sc->rigid = calloc((size_t)rs->n, sizeof *sc->rigid);
  if (!sc->rigid) return fail_at(r, rs, "rigid_bodies", "out of memory");
  sc->nrigid = rs->n;
  static const char *const types[] = {"box", "polygon", NULL};
  static const char *const keys[] = {"name", "type", "lo", "hi", "vertices", "friction", NULL};
  for (int i = 0; i < rs->n; ++i) {
    wf_rigid *b = &sc->rigid[i];
    const wf_node *g = rs->items[i];
    char path[64], full[512], def[WF_NAME];
    snprintf(path, sizeof path, "rigid_bodies.%d", i);
    snprintf(def, sizeof def, "body%d", i + 1);
    b->id = i; /* bodies are added in scene order to a fresh simulation (and a checkpoint) */
    if (check_map(r, g, path, keys)) return -1;
    if (get_str(r, g, path, "name", 0, def, b->name, sizeof b->name)) return -1;
    for (int j = 0; j < i; ++j)
      if (!strcmp(sc->rigid[j].name, b->name)) {
        wf_key_join(full, sizeof full, path, "name");
        return fail_at(r, wf_map_get(g, "name"), full, "a rigid body named '%s' exists already", b->name);
      }
    if (get_enum(r, g, path, "type", 1, 0, types, &b->type)) return -1;
    if (get_num(r, g, path, "friction", 0, 0, NONNEG, &b->friction)) return -1;
    if (b->type == WF_GEOM_BOX) {
      if (get_vec(r, g, path, "lo", 1, sc->dim, ANY, b->lo) || get_vec(r, g, path, "hi", 1, sc->dim, ANY, b->hi))
        return -1;
      for (int a = 0; a < sc->dim; ++a)
        if (b->hi[a] <= b->lo[a]) {
          wf_key_join(full, sizeof full, path, "hi");
          return fail_at(r, wf_map_get(g, "hi"), full, "component %d must be > lo (%g) (got %g)", a, b->lo[a],
                         b->hi[a]);
        }
      continue;
    }
    wf_key_join(full, sizeof full, path, "vertices");
    if (sc->dim != 2) return fail_at(r, wf_map_get(g, "type"), full, "rigid polygons are 2D only (dim = %d)", sc->dim);
    if (get_points(r, g, path, "vertices", 3, &b->xy, &b->nvert)) return -1;
  }
  return 0;
}

/* stages.N.rigid_bodies: {NAME: {velocity: [..], ramp: T}} */
static int read_motion(rd *r, const wf_node *n, const char *path, const wf_scene *sc, wf_stage *s) {
  char full[512];
  wf_key_join(full, sizeof full, path, "rigid_bodies");
  if (n->kind != WF_MAP || n->n == 0)
    return fail_at(r, n, full, "expected a map of body names, e.g. footing: {velocity: [0, -0.01], ramp: 0.2}");
  s->motion = calloc((size_t)n->n, sizeof *s->motion);
  if (!s->motion) return fail_at(r, n, full, "out of memory");
  s->nmotion = n->n;
  static const char *const keys[] = {"velocity", "ramp", NULL};
  for (int k = 0; k < n->n; ++k) {
    char p[600];
    snprintf(p, sizeof p, "%s.%s", full, n->keys[k]);
    wf_rigid_motion *m = &s->motion[k];
    m->body = -1;
    for (int b = 0; b < sc->nrigid; ++b)
      if (!strcmp(sc->rigid[b].name, n->keys[k])) m->body = b;
    if (m->body < 0) {
      char list[256] = "";
      for (int b = 0; b < sc->nrigid; ++b) {
        const size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s%s", b ? ", " : "", sc->rigid[b].name);
      }
      return fail_at(r, n->items[k], p, "no rigid body '%s' (rigid_bodies: %s)", n->keys[k],
                     sc->nrigid ? list : "none");
    }
    if (check_map(r, n->items[k], p, keys)) return -1;
    if (get_vec(r, n->items[k], p, "velocity", 1, sc->dim, ANY, m->velocity)) return -1;
    if (get_num(r, n->items[k], p, "ramp", 0, 0, NONNEG, &m->ramp)) return -1;
  }
  return 0;
}

/* metrics.bearing_capacity_ratio: {body, width, loaded_width, su, axis, from} (rigid.c) */
static int read_bearing(rd *r, const wf_node *v, const char *p, wf_scene *sc) {
  static const char *const keys[] = {"body", "width", "loaded_width", "su", "axis", "from", NULL};
  wf_metrics *m = &sc->metrics;
  char name[WF_NAME], full[512];
  if (check_map(r, v, p, keys)) return -1;
  if (get_str(r, v, p, "body", sc->nrigid != 1, sc->nrigid ? sc->rigid[0].name : "", name, sizeof name)) return -1;
  m->bearing_body = -1;
  for (int b = 0; b < sc->nrigid; ++b)
    if (!strcmp(sc->rigid[b].name, name)) m->bearing_body = b;
  wf_key_join(full, sizeof full, p, "body");
  if (m->bearing_body < 0)
    return fail_at(r, wf_map_get(v, "body") ? wf_map_get(v, "body") : v, full, "no rigid body '%s'", name);
  const range from = {0, 1, 0, 1};
  if (get_num(r, v, p, "width", 1, 0, POS, &m->bearing_B) ||
      get_num(r, v, p, "loaded_width", 0, m->bearing_B, POS, &m->bearing_width) ||
      get_num(r, v, p, "su", 1, 0, POS, &m->bearing_su) ||
      get_enum(r, v, p, "axis", 0, sc->dim - 1, axis_words, &m->bearing_axis) ||
      get_num(r, v, p, "from", 0, 0.5, from, &m->bearing_from))
    return -1;
  wf_key_join(full, sizeof full, p, "axis");
  if (m->bearing_axis >= sc->dim) return fail_at(r, wf_map_get(v, "axis"), full, "no axis z in 2D");
  m->enabled[WF_METRIC_SETTLEMENT_B] = m->enabled[WF_METRIC_Q_SU] = m->enabled[WF_METRIC_BEARING] = 1;
  return 0;
}

static int read_stages(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *ss = wf_map_get(root, "stages");
  if (!ss) return fail_at(r, root, "stages", "required key is missing");
  if (ss->kind != WF_SEQ || ss->n == 0) return fail_at(r, ss, "stages", "expected a list of stages");
  sc->nstage = ss->n;
  sc->stages = calloc((size_t)ss->n, sizeof *sc->stages);
  if (!sc->stages) return fail_at(r, ss, "stages", "out of memory");
  static const char *const keys[] = {"name", "gravity", "damping", "kinetic_damping", "adaptive_damping", "initial_stress", "flip", "pic_diffusivity", "walls", "remove_walls", "tractions",
                                     "strength_reduction", "reset_velocity", "end", "dt_factor", "dt",
                                     "snapshots", "series_points", "rigid_bodies", "force_dt",
                                     "factor_of_safety", NULL};
  static const char *const fos_keys[] = {"lo", "hi", "tolerance", "displacement_limit", "growth", "max_trials",
                                         "jobs", NULL};
  static const char *const end_keys[] = {"time", "kinetic_energy_ratio", "max_time", "min_time", NULL};
  static const char *const tr_keys[] = {"set", "lo", "hi", "traction", NULL};
  for (int i = 0; i < ss->n; ++i) {
    wf_stage *s = &sc->stages[i];
    const wf_node *n = ss->items[i];
    char p[64], full[512], def[WF_NAME];
    snprintf(p, sizeof p, "stages.%d", i);
    snprintf(def, sizeof def, "stage%d", i + 1);
    if (check_map(r, n, p, keys)) return -1;
    if (get_str(r, n, p, "name", 0, def, s->name, sizeof s->name)) return -1;
    if (wf_map_get(n, "gravity")) {
      s->has_gravity = 1;
      if (get_vec(r, n, p, "gravity", 1, sc->dim, ANY, s->gravity)) return -1;
    }
    const range damp = {0, 1, 0, 1};
    if (get_num(r, n, p, "damping", 0, 0, damp, &s->damping)) return -1;
    if (get_bool(r, n, p, "kinetic_damping", 0, &s->kinetic_damping)) return -1;
    /* the damping ratio zeta of the estimated mode; true: 0.7 (the Rayleigh quotient bounds the
     * lowest mode from above; docs/workflows.md), false: off */
    const wf_node *ad = wf_map_get(n, "adaptive_damping");
    const int adb = ad ? bool_word(ad) : -1;
    if (adb >= 0) {
      s->adaptive_damping = adb ? 0.7 : 0.0;
    } else if (ad) {
      wf_key_join(full, sizeof full, p, "adaptive_damping");
      if (parse_number(ad, &s->adaptive_damping))
        return fail_at(r, ad, full, "expected true, false or a damping ratio in [0, 2] (got '%s')",
                       shown(ad));
      const range zeta = {0, 2, 0, 0};
      if (check_range(r, ad, full, s->adaptive_damping, zeta)) return -1;
    }
    /* absent: the scene's blend (a quasi-static stage of a FLIP scene takes a little PIC:
     * docs/theory.md) */
    if (get_num(r, n, p, "flip", 0, sc->flip, UNIT, &s->flip)) return -1;
    /* or PIC as a diffusivity (mpmc_sim_set_pic_diffusivity): the share D dt / h^2 a step */
    if (get_num(r, n, p, "pic_diffusivity", 0, 0.0, NONNEG, &s->pic_diffusivity)) return -1;
    if (wf_map_get(n, "flip") && wf_map_get(n, "pic_diffusivity")) {
      wf_key_join(full, sizeof full, p, "pic_diffusivity");
      return fail_at(r, wf_map_get(n, "pic_diffusivity"), full,
                     "a stage takes either flip (a fixed share a step) or pic_diffusivity, not both");
    }
    const range srf = {0, INFINITY, 1, 0};
    /* 0: unchanged from the previous stage */
    if (get_num(r, n, p, "strength_reduction", 0, 0.0, srf, &s->strength_reduction)) return -1;
    if (get_bool(r, n, p, "reset_velocity", 0, &s->reset_velocity)) return -1;
    /* a time step above the stability limit is refused unless forced (mpmc_sim_set_force_dt) */
    if (get_bool(r, n, p, "force_dt", 0, &s->force_dt)) return -1;
    const range fac = {0, 1, 1, 0};
    if (get_num(r, n, p, "dt_factor", 0, 0.3, fac, &s->dt_factor)) return -1;
    if (get_num(r, n, p, "dt", 0, 0, NONNEG, &s->dt)) return -1;
    const wf_node *is = wf_map_get(n, "initial_stress");
    if (is) {
      static const char *const ik[] = {"k0", NULL};
      wf_key_join(full, sizeof full, p, "initial_stress");
      if (check_map(r, is, full, ik) || get_num(r, is, full, "k0", 1, 0, POS, &s->k0)) return -1;
    }
    if (get_int(r, n, p, "snapshots", 0, 4, 0, 100000, &s->snapshots)) return -1;
    if (get_int(r, n, p, "series_points", 0, 200, 1, 10000000, &s->series_points)) return -1;
    char wp[128];
    snprintf(wp, sizeof wp, "%s.walls", p);
    if (wf_map_get(n, "walls") && read_walls(r, wf_map_get(n, "walls"), wp, sc, s)) return -1;
    if (wf_map_get(n, "rigid_bodies") && read_motion(r, wf_map_get(n, "rigid_bodies"), p, sc, s)) return -1;
    const wf_node *rm = wf_map_get(n, "remove_walls");
    if (rm) {
      wf_key_join(full, sizeof full, p, "remove_walls");
      if (rm->kind != WF_SEQ) return fail_at(r, rm, full, "expected a list of wall names");
      s->nremove = rm->n;
      s->remove = calloc((size_t)rm->n + 1, sizeof *s->remove);
      if (!s->remove) return fail_at(r, rm, full, "out of memory");
      for (int k = 0; k < rm->n; ++k) {
        if (rm->items[k]->kind != WF_SCALAR) return fail_at(r, rm->items[k], full, "expected a wall name");
        snprintf(s->remove[k], WF_NAME, "%s", rm->items[k]->value);
        /* the name must belong to a wall of an earlier stage */
        int found = 0;
        for (int j = 0; j < i && !found; ++j)
          for (int w = 0; w < sc->stages[j].nwalls; ++w)
            if (!strcmp(sc->stages[j].walls[w].name, s->remove[k])) found = 1;
        if (!found)
          return fail_at(r, rm->items[k], full, "no wall named '%s' in an earlier stage", s->remove[k]);
      }
    }
    const wf_node *tr = wf_map_get(n, "tractions");
    if (tr) {
      wf_key_join(full, sizeof full, p, "tractions");
      if (tr->kind != WF_SEQ) return fail_at(r, tr, full, "expected a list of tractions");
      s->ntractions = tr->n;
      s->tractions = calloc((size_t)tr->n + 1, sizeof *s->tractions);
      if (!s->tractions) return fail_at(r, tr, full, "out of memory");
      for (int k = 0; k < tr->n; ++k) {
        char tp[600];
        snprintf(tp, sizeof tp, "%s.%d", full, k);
        wf_traction *t = &s->tractions[k];
        if (check_map(r, tr->items[k], tp, tr_keys)) return -1;
        if (get_str(r, tr->items[k], tp, "set", 0, "", t->set, sizeof t->set)) return -1;
        t->has_region = wf_map_get(tr->items[k], "lo") != NULL;
        if (t->has_region && (get_vec(r, tr->items[k], tp, "lo", 1, sc->dim, ANY, t->lo) ||
                              get_vec(r, tr->items[k], tp, "hi", 1, sc->dim, ANY, t->hi)))
          return -1;
        if (!t->has_region && !t->set[0])
          return fail_at(r, tr->items[k], tp, "a traction needs a particle set or a region lo/hi");
        if (get_vec(r, tr->items[k], tp, "traction", 1, sc->dim, ANY, t->traction)) return -1;
      }
    }
    const wf_node *fn = wf_map_get(n, "factor_of_safety");
    if (fn) {
      /* a search: trials from this stage's start, each as long as its end (docs/workflows.md) */
      wf_key_join(full, sizeof full, p, "factor_of_safety");
      if (check_map(r, fn, full, fos_keys)) return -1;
      wf_fos *f = &s->fos;
      s->has_fos = 1;
      if (get_num(r, fn, full, "lo", 0, 1.0, POS, &f->lo) || get_num(r, fn, full, "hi", 0, 2.0, POS, &f->hi) ||
          get_num(r, fn, full, "tolerance", 0, 0.01, POS, &f->tolerance) ||
          get_num(r, fn, full, "displacement_limit", 1, 0, POS, &f->displacement_limit) ||
          get_num(r, fn, full, "growth", 0, 0.05, UNIT, &f->growth) ||
          get_int(r, fn, full, "max_trials", 0, 30, 2, 64, &f->max_trials) ||
          get_int(r, fn, full, "jobs", 0, 1, 1, WF_FOS_MAX_JOBS, &f->jobs))
        return -1;
      char hp[600];
      wf_key_join(hp, sizeof hp, full, "hi");
      if (!(f->hi > f->lo)) return fail_at(r, fn, hp, "must be above lo = %g (got %g)", f->lo, f->hi);
      if (wf_map_get(n, "strength_reduction"))
        return fail_at(r, wf_map_get(n, "strength_reduction"), full,
                       "a factor-of-safety stage sets its own factors: remove strength_reduction");
    }
    const wf_node *e = wf_map_get(n, "end");
    wf_key_join(full, sizeof full, p, "end");
    if (!e) return fail_at(r, n, full, "required key is missing (time: T, or kinetic_energy_ratio: tol with max_time: T)");
    if (check_map(r, e, full, end_keys)) return -1;
    const int has_t = wf_map_get(e, "time") != NULL, has_k = wf_map_get(e, "kinetic_energy_ratio") != NULL;
    if (has_t == has_k)
      return fail_at(r, e, full, "give exactly one of time (a duration) or kinetic_energy_ratio (quasi-static)");
    if (has_t) {
      s->end_kind = WF_END_TIME;
      if (get_num(r, e, full, "time", 1, 0, POS, &s->end_time)) return -1;
    } else {
      s->end_kind = WF_END_QUASI_STATIC;
      const range tol = {0, 1, 1, 1};
      if (get_num(r, e, full, "kinetic_energy_ratio", 1, 0, tol, &s->ke_ratio)) return -1;
      if (get_num(r, e, full, "max_time", 1, 0, POS, &s->max_time)) return -1;
      if (get_num(r, e, full, "min_time", 0, 0, NONNEG, &s->min_time)) return -1;
      char mt[560];
      wf_key_join(mt, sizeof mt, full, "min_time");
      if (s->min_time > s->max_time)
        return fail_at(r, wf_map_get(e, "min_time"), mt, "must not exceed max_time = %g (got %g)", s->max_time,
                       s->min_time);
      s->end_time = s->max_time;
    }
  }
  return 0;
}

/* A stage named in `map`.`key` (by name or index); absent: def. */
static int find_stage(rd *r, const wf_node *map, const char *path, const char *key, const wf_scene *sc, int def,
                      int *out) {
  char name[WF_NAME], full[512];
  wf_key_join(full, sizeof full, path, key);
  if (get_str(r, map, path, key, 0, "", name, sizeof name)) return -1;
  if (!name[0]) return *out = def, 0;
  for (int i = 0; i < sc->nstage; ++i)
    if (!strcmp(sc->stages[i].name, name)) return *out = i, 0;
  char *end;
  const long k = strtol(name, &end, 10);
  if (!*end && k >= 0 && k < sc->nstage) return *out = (int)k, 0;
  char list[256] = "";
  for (int i = 0; i < sc->nstage; ++i) {
    const size_t l = strlen(list);
    snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", sc->stages[i].name);
  }
  return fail_at(r, wf_map_get(map, key), full, "no stage '%s' (stages: %s)", name, list);
}

/* metrics.hydrostatic_pressure_error: {surface: level of the free surface, stage: the stage
 * at whose end it is evaluated (default: live, the run's end)}; g is that stage's gravity. */
static int read_hydrostatic(rd *r, const wf_node *v, const char *p, wf_scene *sc) {
  static const char *const keys[] = {"surface", "stage", NULL};
  wf_metrics *m = &sc->metrics;
  if (check_map(r, v, p, keys)) return -1;
  if (get_num(r, v, p, "surface", 1, 0, ANY, &m->surface)) return -1;
  if (find_stage(r, v, p, "stage", sc, -1, &m->hydro_stage)) return -1;
  const int last = m->hydro_stage >= 0 ? m->hydro_stage : sc->nstage - 1;
  const double *g = NULL;
  for (int i = 0; i <= last; ++i)
    if (sc->stages[i].has_gravity) g = sc->stages[i].gravity;
  double best = 0;
  for (int a = 0; g && a < sc->dim; ++a)
    if (fabs(g[a]) > best) {
      best = fabs(g[a]);
      m->hydro_axis = a;
    }
  if (best == 0) return fail_at(r, v, p, "needs gravity (no stage up to '%s' sets it)", sc->stages[last].name);
  m->hydro_g = best;
  m->enabled[WF_METRIC_HYDRO] = 1;
  return 0;
}

/* snapshot_plots: [{stage, times: [..], color, range: [lo, hi]}, ...] (snapshot_plots.c) */
static int read_snapplots(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *ls = wf_map_get(root, "snapshot_plots");
  if (!ls) return 0;
  if (ls->kind != WF_SEQ)
    return fail_at(r, ls, "snapshot_plots", "expected a list, e.g. - {stage: runout, times: [1, 2], color: eps_p}");
  if (ls->n == 0) return 0; /* [] : none (e.g. --set snapshot_plots=[] for a short run) */
  sc->snapplots = calloc((size_t)ls->n, sizeof *sc->snapplots);
  if (!sc->snapplots) return fail_at(r, ls, "snapshot_plots", "out of memory");
  sc->nsnapplot = ls->n;
  static const char *const keys[] = {"stage", "times", "color", "range", NULL};
  int plastic = 0;
  for (int i = 0; i < sc->nmat; ++i) plastic |= wf_model_plastic(sc->mats[i].model);
  for (int k = 0; k < ls->n; ++k) {
    wf_snapplot *sp = &sc->snapplots[k];
    const wf_node *n = ls->items[k];
    char p[64], full[512];
    snprintf(p, sizeof p, "snapshot_plots.%d", k);
    if (check_map(r, n, p, keys)) return -1;
    if (find_stage(r, n, p, "stage", sc, 0, &sp->stage)) return -1;
    if (get_enum(r, n, p, "color", 0, WF_COLOR_MEAN_STRESS, wf_color_names, &sp->color)) return -1;
    wf_key_join(full, sizeof full, p, "color");
    if (sp->color == WF_COLOR_EPS_P && !plastic)
      return fail_at(r, wf_map_get(n, "color"), full, "eps_p needs a plastic material (hencky_j2, mohr_coulomb, drucker_prager)");
    sp->has_range = wf_map_get(n, "range") != NULL;
    if (get_vec(r, n, p, "range", 0, 2, ANY, sp->range)) return -1;
    wf_key_join(full, sizeof full, p, "range");
    if (sp->has_range && !(sp->range[1] > sp->range[0]))
      return fail_at(r, wf_map_get(n, "range"), full, "expected [lo, hi] with hi > lo (got [%g, %g])", sp->range[0],
                     sp->range[1]);
    const wf_node *t = wf_map_get(n, "times");
    wf_key_join(full, sizeof full, p, "times");
    if (!t) return fail_at(r, n, full, "required key is missing");
    if (t->kind != WF_SEQ || t->n == 0 || t->n > 64) return fail_at(r, t, full, "expected a list of 1 to 64 times [s]");
    sp->times = calloc((size_t)t->n, sizeof *sp->times);
    if (!sp->times) return fail_at(r, t, full, "out of memory");
    sp->ntimes = t->n;
    const double T = sc->stages[sp->stage].end_time;
    for (int j = 0; j < t->n; ++j) {
      char item[560];
      snprintf(item, sizeof item, "%s.%d", full, j);
      if (parse_number(t->items[j], &sp->times[j]))
        return fail_at(r, t->items[j], item, "expected a number (got '%s')", shown(t->items[j]));
      if (!(sp->times[j] >= 0 && sp->times[j] <= T))
        return fail_at(r, t->items[j], item, "must be in [0, %g], the duration of stage %s (got %g)", T,
                       sc->stages[sp->stage].name, sp->times[j]);
    }
  }
  return 0;
}

/* water_table: {points: [[x, h], ...] | plane: [a, b, c], unit_weight: gamma_w} */
static int read_water(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *w = wf_map_get(root, "water_table");
  if (!w) return 0;
  static const char *const keys[] = {"points", "plane", "unit_weight", NULL};
  if (check_map(r, w, "water_table", keys)) return -1;
  wf_water *wt = &sc->water;
  const wf_node *pts = wf_map_get(w, "points"), *pl = wf_map_get(w, "plane");
  if (!pts == !pl)
    return fail_at(r, w, "water_table", "give the piezometric line as points: [[x, h], ...] or (3D) "
                   "plane: [a, b, c] for h = a + b x + c y, one of the two");
  if (pts) {
    if (get_points(r, w, "water_table", "points", 1, &wt->xh, &wt->n)) return -1;
    for (int k = 1; k < wt->n; ++k)
      if (wt->xh[2 * k] <= wt->xh[2 * (k - 1)]) {
        char item[96];
        snprintf(item, sizeof item, "water_table.points.%d", k);
        return fail_at(r, pts->items[k], item, "x = %g must exceed the previous point's x = %g",
                       wt->xh[2 * k], wt->xh[2 * (k - 1)]);
      }
  } else {
    if (sc->dim != 3)
      return fail_at(r, pl, "water_table.plane", "a plane is for 3D scenes: in 2D give points: [[x, h], ...]");
    if (get_vec(r, w, "water_table", "plane", 1, 3, ANY, wt->plane)) return -1;
    wt->has_plane = 1;
  }
  return get_num(r, w, "water_table", "unit_weight", 0, 9810.0, POS, &wt->gamma_w);
}

static int read_metrics(rd *r, const wf_node *root, wf_scene *sc) {
  const wf_node *m = wf_map_get(root, "metrics");
  if (!m) return 0;
  static const char *const keys[] = {"runout_distance", "tip_displacement_y", "tip_displacement_x",
                                     "center_of_mass_x", "bearing_capacity_ratio", "surge_front_x",
                                     "hydrostatic_pressure_error", NULL};
  if (check_map(r, m, "metrics", keys)) return -1;
  static const char *const rk[] = {"toe", "axis", "material", NULL};
  static const char *const tk[] = {"point", NULL};
  static const char *const none[] = {NULL};
  for (int i = 0; i < m->n; ++i) {
    char p[128];
    snprintf(p, sizeof p, "metrics.%s", m->keys[i]);
    const wf_node *v = m->items[i];
    /* an empty value ("center_of_mass_x:") means "with defaults" */
    const int empty = v->kind == WF_SCALAR && !v->quoted && (!v->value[0] || !strcmp(v->value, "~") ||
                                                              !strcmp(v->value, "null"));
    if (!strcmp(m->keys[i], "runout_distance")) {
      sc->metrics.enabled[WF_METRIC_RUNOUT] = 1;
      sc->metrics.runout_material = -1;
      if (empty) continue;
      if (check_map(r, v, p, rk)) return -1;
      const wf_node *mn = wf_map_get(v, "material");
      if (mn) { /* the slide's material (a foundation layer beyond the toe does not run out) */
        char full[160];
        snprintf(full, sizeof full, "%s.material", p);
        if (mn->kind != WF_SCALAR) return fail_at(r, mn, full, "expected a material name");
        for (int k = 0; k < sc->nmat; ++k)
          if (!strcmp(sc->mats[k].name, mn->value)) sc->metrics.runout_material = k;
        if (sc->metrics.runout_material < 0)
          return fail_at(r, mn, full, "no material named '%s' in materials", mn->value);
      }
      sc->metrics.has_toe = wf_map_get(v, "toe") != NULL;
      if (get_num(r, v, p, "toe", 0, 0, ANY, &sc->metrics.toe)) return -1;
      if (get_enum(r, v, p, "axis", 0, 0, axis_words, &sc->metrics.runout_axis)) return -1;
    } else if (!strncmp(m->keys[i], "tip_displacement", 16)) {
      sc->metrics.enabled[m->keys[i][17] == 'y' ? WF_METRIC_TIP_Y : WF_METRIC_TIP_X] = 1;
      if (check_map(r, v, p, tk)) return -1;
      if (get_vec(r, v, p, "point", 1, sc->dim, ANY, sc->metrics.point)) return -1;
    } else if (!strcmp(m->keys[i], "bearing_capacity_ratio")) {
      if (read_bearing(r, v, p, sc)) return -1;
    } else if (!strcmp(m->keys[i], "surge_front_x")) {
      sc->metrics.enabled[WF_METRIC_FRONT_X] = 1;
      if (!empty && check_map(r, v, p, none)) return -1;
    } else if (!strcmp(m->keys[i], "hydrostatic_pressure_error")) {
      if (read_hydrostatic(r, v, p, sc)) return -1;
    } else {
      sc->metrics.enabled[WF_METRIC_COM_X] = 1;
      if (!empty && check_map(r, v, p, none)) return -1;
    }
  }
  return 0;
}

static int read_scene(rd *r, const wf_node *root, wf_scene *sc) {
  static const char *const keys[] = {"scene", "description", "dim", "geometry", "grid", "basis", "fbar",
                                     "flip", "solver", "threads", "materials", "stages", "metrics",
                                     "plots", "checkpoint_interval", "progress_interval", "rigid_bodies",
                                     "contact", "snapshot_plots", "sort_interval", "water_table",
                                     "load_balance", NULL};
  if (check_map(r, root, "", keys)) return -1;
  char def[WF_NAME];
  const char *base = strrchr(sc->path, '/');
  snprintf(def, sizeof def, "%s", base ? base + 1 : sc->path);
  char *dot = strrchr(def, '.');
  if (dot) *dot = '\0';
  if (get_str(r, root, "", "scene", 0, def, sc->name, sizeof sc->name)) return -1;
  for (const char *c = sc->name; *c; ++c)
    if (!isalnum((unsigned char)*c) && *c != '_' && *c != '-')
      return fail_at(r, wf_map_get(root, "scene"), "scene", "use letters, digits, _ and - only (got '%s')", sc->name);
  if (get_int(r, root, "", "dim", 1, 2, 2, 3, &sc->dim)) return -1;
  const wf_node *g = wf_map_get(root, "grid");
  static const char *const gk[] = {"lo", "hi", "cell_size", NULL};
  if (!g) return fail_at(r, root, "grid", "required key is missing");
  if (check_map(r, g, "grid", gk)) return -1;
  if (get_vec(r, g, "grid", "lo", 1, sc->dim, ANY, sc->lo) || get_vec(r, g, "grid", "hi", 1, sc->dim, ANY, sc->hi))
    return -1;
  for (int a = 0; a < sc->dim; ++a)
    if (sc->hi[a] <= sc->lo[a])
      return fail_at(r, wf_map_get(g, "hi"), "grid.hi", "component %d must be > grid.lo (%g) (got %g)", a,
                     sc->lo[a], sc->hi[a]);
  if (get_num(r, g, "grid", "cell_size", 1, 0, POS, &sc->h)) return -1;
  for (int a = 0; a < sc->dim; ++a)
    if (sc->h > sc->hi[a] - sc->lo[a])
      return fail_at(r, wf_map_get(g, "cell_size"), "grid.cell_size",
                     "must not exceed the grid's extent %g along axis %d (got %g)", sc->hi[a] - sc->lo[a], a, sc->h);
  if (get_enum(r, root, "", "basis", 0, MPMC_BASIS_BSPLINE2, basis_words, &sc->basis)) return -1;
  /* fbar: true (= anchored, the default), false, anchored, paper (Algorithm 1 as published),
   * total or stable (docs/theory.md) */
  {
    const wf_node *fn = wf_map_get(root, "fbar");
    static const char *const words[] = {"paper", "total", "stable", "anchored"};
    static const int modes[] = {MPMC_FBAR_PAPER, MPMC_FBAR_TOTAL, MPMC_FBAR_STABLE,
                                MPMC_FBAR_ANCHORED};
    sc->fbar = -1;
    if (!fn) sc->fbar = MPMC_FBAR_ANCHORED;
    for (int i = 0; i < 4 && fn && fn->kind == WF_SCALAR && !fn->quoted; ++i)
      if (!strcmp(fn->value, words[i])) sc->fbar = modes[i];
    if (sc->fbar < 0 && fn) {
      const int b = bool_word(fn);
      if (b < 0)
        return fail_at(r, fn, "fbar", "expected true, false, anchored, paper, total or stable "
                       "(got '%s')",
                       shown(fn));
      sc->fbar = b ? MPMC_FBAR_ANCHORED : MPMC_FBAR_OFF;
    }
  }
  if (get_num(r, root, "", "flip", 0, 1.0, UNIT, &sc->flip)) return -1;
  if (get_enum(r, root, "", "solver", 0, MPMC_SOLVER_AUTO, solver_words, &sc->solver)) return -1;
  if (get_int(r, root, "", "threads", 0, 0, 0, 1024, &sc->threads)) return -1;
  if (get_int(r, root, "", "sort_interval", 0, 100, 0, 1000000000, &sc->sort_interval)) return -1;
  const wf_node *lb = wf_map_get(root, "load_balance"); /* over MPI: the slab cuts follow the points */
  if (lb) {
    static const char *const lk[] = {"every", "threshold", NULL};
    if (check_map(r, lb, "load_balance", lk) ||
        get_int(r, lb, "load_balance", "every", 0, 0, 0, 1000000000, &sc->balance_every) ||
        get_num(r, lb, "load_balance", "threshold", 0, 0, NONNEG, &sc->balance_threshold))
      return -1;
    if (sc->balance_threshold > 0 && sc->balance_threshold < 1)
      return fail_at(r, wf_map_get(lb, "threshold"), "load_balance.threshold",
                     "must be 0 (off) or >= 1, the most points on a rank over the mean (got %g)",
                     sc->balance_threshold);
  }
  if (get_bool(r, root, "", "plots", 1, &sc->plots)) return -1;
  if (get_num(r, root, "", "checkpoint_interval", 0, 300, POS, &sc->checkpoint_interval)) return -1;
  if (get_num(r, root, "", "progress_interval", 0, 5, POS, &sc->progress_interval)) return -1;
  if (read_materials(r, root, sc) || read_geometry(r, root, sc) || read_rigid(r, root, sc) || read_stages(r, root, sc) ||
      read_metrics(r, root, sc) || read_snapplots(r, root, sc) || read_water(r, root, sc))
    return -1;
  return 0;
}

/**
 * @brief Read a scene file, apply the `key.path=value` overrides and check every value.
 * @param msg receives "file:line:col: key 'a.b': what is wrong" on failure
 */
int wf_scene_load(const char *path, int noverride, const char *const *overrides, wf_scene *sc,
                  char *msg, size_t msglen) {
  memset(sc, 0, sizeof *sc);
  msg[0] = '\0';
  if (snprintf(sc->path, sizeof sc->path, "%s", path) >= (int)sizeof sc->path) {
    snprintf(msg, msglen, "%s: path too long", path);
    return MPMC_ERR_ARG;
  }
  snprintf(sc->dir, sizeof sc->dir, "%s", path);
  char *slash = strrchr(sc->dir, '/');
  if (slash)
    *slash = '\0';
  else
    snprintf(sc->dir, sizeof sc->dir, ".");
  int code = 0;
  wf_node *root = wf_yaml_load(sc->path, "scene file", &code, msg, msglen);
  if (!root) return code;
  /* messages about overridden values name the --set argument */
  char **origins = calloc((size_t)noverride + 1, sizeof *origins);
  int err = origins ? 0 : MPMC_ERR_MEMORY;
  for (int i = 0; i < noverride && !err; ++i) {
    const size_t l = overrides && overrides[i] ? strlen(overrides[i]) + 8 : 0;
    if (l) origins[i] = malloc(l);
    if (origins[i]) snprintf(origins[i], l, "--set %s", overrides[i]);
    if (!origins[i] || wf_yaml_override(root, overrides[i], origins[i], msg, msglen)) {
      if (!msg[0]) snprintf(msg, msglen, "--set: override %d is NULL", i);
      err = MPMC_ERR_ARG;
    }
  }
  rd r = {msg, msglen, 0};
  if (!err) err = read_scene(&r, root, sc) ? MPMC_ERR_ARG : 0;
  wf_node_free(root);
  for (int i = 0; i < noverride && origins; ++i) free(origins[i]);
  free(origins);
  if (err) {
    wf_scene_free(sc);
    return MPMC_ERR_ARG;
  }
  return MPMC_SUCCESS;
}

void wf_scene_free(wf_scene *sc) {
  if (!sc) return;
  wf_rigid_free(sc);
  for (int i = 0; i < sc->nbody && sc->bodies; ++i) free(sc->bodies[i].xy);
  for (int i = 0; i < sc->nstage && sc->stages; ++i) {
    free(sc->stages[i].walls);
    free(sc->stages[i].remove);
    free(sc->stages[i].tractions);
  }
  for (int i = 0; i < sc->nsnapplot && sc->snapplots; ++i) free(sc->snapplots[i].times);
  free(sc->snapplots);
  free(sc->water.xh);
  sc->water.xh = NULL;
  sc->water.n = 0;
  sc->snapplots = NULL;
  sc->nsnapplot = 0;
  free(sc->bodies);
  free(sc->stages);
  free(sc->mats);
  sc->bodies = NULL;
  sc->stages = NULL;
  sc->mats = NULL;
}
