/* Seeding from gmsh (library libmpmc_gmsh, so that programs which do not seed from gmsh
 * never load libgmsh).  A .geo is meshed through the gmsh C API, a .msh is read as it is;
 * the physical group `region` (a surface in 2D, a volume in 3D) is filled either with
 * lattice points of the sim's grid kept inside its elements, or with points at the
 * elements' Gauss points carrying weight * det J as volume (summing to the mesh's area or
 * volume to round-off).  Every lower-dimensional physical group becomes a particle set of
 * the new points near it (curves/surfaces: within half a point spacing; points: the
 * nearest point) and a node set of the grid nodes near it (within half a cell; points: the
 * nearest node), both named after the group. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gmshc.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "seed.h"

/* ---- the gmsh session: initialise, capture messages, finalise ---------------------------- */

typedef struct {
  mpmc_context ctx;
  const char *file;
  int up;
  int threads; /* the caller's OpenMP threads, which gmsh sets to its General.NumThreads */
} session;

/* gmshInitialize and gmshFinalize set the process's OpenMP threads to gmsh's own count (1):
 * the caller's (OMP_NUM_THREADS, the cores, or its omp_set_num_threads) are put back. */
static void keep_threads(session *s, int save) {
#ifdef _OPENMP
  if (save)
    s->threads = omp_get_max_threads();
  else if (s->threads > 0)
    omp_set_num_threads(s->threads);
#else
  (void)s, (void)save;
#endif
}

/* The last error gmsh logged (e.g. "'x.geo', line 3 : syntax error (...)"), or "". */
static void gmsh_last_error(char *buf, size_t len) {
  int ierr = 0;
  char **log = NULL;
  size_t n = 0;
  buf[0] = '\0';
  gmshLoggerGet(&log, &n, &ierr);
  for (size_t i = 0; i < n; ++i) {
    if (!buf[0] && log[i] && strncmp(log[i], "Error", 5) == 0) {
      const char *s = log[i] + 5;
      while (*s == ' ' || *s == ':') ++s;
      snprintf(buf, len, "%s", s);
    }
    gmshFree(log[i]);
  }
  gmshFree(log);
}

static int gmsh_error(session *s, int code, const char *what) {
  char msg[512];
  gmsh_last_error(msg, sizeof msg);
  return MPMC_ERROR(s->ctx, code, "gmsh: %s '%s'%s%s", what, s->file, msg[0] ? ": " : "", msg);
}

static void session_end(session *s) {
  int ierr = 0;
  if (!s->up) return;
  gmshLoggerStop(&ierr);
  gmshFinalize(&ierr);
  keep_threads(s, 0);
  s->up = 0;
}

static int has_suffix(const char *s, const char *suf) {
  const size_t n = strlen(s), m = strlen(suf);
  return n >= m && strcmp(s + n - m, suf) == 0;
}

/* The private directory of a .geo's mesh (mesh_in_child) and the .msh in it, removed once
 * the mesh is read or meshing failed; msh may not exist yet. */
static void drop_mesh_dir(const char *dir, const char *msh) {
  remove(msh);
  rmdir(dir);
}

/* gmsh 4.8's .geo parser keeps a broken state for the rest of the process after a syntax
 * error (every later file fails with "line 0: syntax error", even after gmshFinalize and
 * gmshInitialize).  So a .geo is parsed and meshed in a forked child that writes a .msh
 * into a private temporary directory and reports gmsh's error through a pipe; this process
 * only ever reads .msh files, whose reader has no such state. */
static int mesh_in_child(session *s, int dim, char *dir, size_t dirlen, char *msh, size_t mshlen) {
  const char *tmpdir = getenv("TMPDIR");
  snprintf(dir, dirlen, "%s/mpmc-gmsh-XXXXXX", tmpdir && tmpdir[0] ? tmpdir : "/tmp");
  MPMC_CHECK(mkdtemp(dir), s->ctx, MPMC_ERR_IO, "gmsh: cannot create a temporary directory '%s': %s",
             dir, strerror(errno));
  snprintf(msh, mshlen, "%s/mesh.msh", dir);
  int pfd[2];
  if (pipe(pfd) != 0) {
    drop_mesh_dir(dir, msh);
    return MPMC_ERROR(s->ctx, MPMC_ERR_IO, "gmsh: cannot create a pipe: %s", strerror(errno));
  }
  fflush(NULL);
  const pid_t pid = fork();
  if (pid < 0) {
    close(pfd[0]);
    close(pfd[1]);
    drop_mesh_dir(dir, msh);
    return MPMC_ERROR(s->ctx, MPMC_ERR_IO, "gmsh: cannot fork: %s", strerror(errno));
  }
  if (pid == 0) { /* the child: parse, check, mesh, write; report an error and exit */
    close(pfd[0]);
    int ierr = 0, code = 0;
    char msg[600] = "";
    gmshInitialize(0, NULL, 0, &ierr);
    gmshOptionSetNumber("General.Terminal", 0, &ierr);
    gmshOptionSetNumber("General.NumThreads", 1, &ierr);
    gmshOptionSetNumber("Mesh.Binary", 1, &ierr);
    gmshLoggerStart(&ierr);
    gmshOpen(s->file, &ierr);
    gmsh_last_error(msg, sizeof msg);
    if (ierr || msg[0]) {
      code = 2;
      if (!msg[0]) snprintf(msg, sizeof msg, "unknown error");
    } else {
      const int mdim = gmshModelGetDimension(&ierr);
      if (ierr || mdim < dim) {
        code = 3;
        snprintf(msg, sizeof msg, "defines no %dD geometry (model dimension %d)", dim, mdim);
      }
    }
    if (!code) {
      gmshModelMeshGenerate(dim, &ierr);
      gmsh_last_error(msg, sizeof msg);
      if (ierr) code = 4;
    }
    if (!code) { /* empty groups would silently vanish from the .msh */
      int *dt = NULL;
      size_t ndt = 0;
      gmshModelGetPhysicalGroups(&dt, &ndt, -1, &ierr);
      for (size_t i = 0; i + 1 < ndt && !code; i += 2) {
        size_t nn = 0, nc = 0;
        size_t *tags = NULL;
        double *coord = NULL;
        gmshModelMeshGetNodesForPhysicalGroup(dt[i], dt[i + 1], &tags, &nn, &coord, &nc, &ierr);
        if (nn == 0) {
          char *name = NULL;
          gmshModelGetPhysicalName(dt[i], dt[i + 1], &name, &ierr);
          code = 7;
          snprintf(msg, sizeof msg, "physical group '%s' (dimension %d) has no mesh elements",
                   name ? name : "", dt[i]);
          gmshFree(name);
        }
        gmshFree(tags);
        gmshFree(coord);
      }
      gmshFree(dt);
    }
    if (!code) {
      gmshWrite(msh, &ierr);
      if (ierr) code = 5, snprintf(msg, sizeof msg, "cannot write the mesh to '%s'", msh);
    }
    if (code) {
      const size_t len = strlen(msg);
      if (write(pfd[1], msg, len) != (ssize_t)len) code = 6;
    }
    close(pfd[1]);
    _exit(code); /* no atexit handlers, no flush of the parent's stdio buffers */
  }
  close(pfd[1]);
  char msg[600];
  size_t len = 0;
  for (;;) {
    const ssize_t r = read(pfd[0], msg + len, sizeof msg - 1 - len);
    if (r > 0 && len + (size_t)r < sizeof msg - 1) {
      len += (size_t)r;
      continue;
    }
    if (r < 0 && errno == EINTR) continue;
    break;
  }
  msg[len] = '\0';
  close(pfd[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return MPMC_SUCCESS;
  drop_mesh_dir(dir, msh);
  if (!WIFEXITED(status))
    return MPMC_ERROR(s->ctx, MPMC_ERR_FORMAT, "gmsh: meshing '%s' crashed (signal %d)", s->file,
                      WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  const int code = WEXITSTATUS(status);
  return MPMC_ERROR(s->ctx, MPMC_ERR_FORMAT, "gmsh: %s '%s': %s",
                    code == 2 ? "cannot read" : code == 3 ? "no geometry in" : code == 7 ? "empty group in" : "cannot mesh", s->file,
                    msg[0] ? msg : "unknown error");
}

/* gmsh keeps a physical group without elements only as a name in the file's
 * $PhysicalNames section (the model API does not list it): report such a group. */
static int check_empty_groups(session *s, const char *path) {
  FILE *fp = fopen(path, "rb");
  if (!fp) return MPMC_SUCCESS; /* gmshOpen read it: nothing more to learn here */
  char line[512];
  int in = 0, err = MPMC_SUCCESS, ierr = 0;
  int *dt = NULL;
  size_t ndt = 0;
  gmshModelGetPhysicalGroups(&dt, &ndt, -1, &ierr);
  for (int lines = 0; !err && lines < 100000 && fgets(line, sizeof line, fp); ++lines) {
    if (strncmp(line, "$PhysicalNames", 14) == 0) {
      in = 1;
      if (!fgets(line, sizeof line, fp)) break; /* the count */
      continue;
    }
    if (!in) {
      if (strncmp(line, "$Nodes", 6) == 0 || strncmp(line, "$Entities", 9) == 0) break;
      continue;
    }
    if (strncmp(line, "$EndPhysicalNames", 17) == 0) break;
    int d = -1, tag = -1, found = 0;
    char name[256] = "";
    if (sscanf(line, "%d %d \"%255[^\"]\"", &d, &tag, name) < 2) continue;
    for (size_t i = 0; i + 1 < ndt && !found; i += 2) found = dt[i] == d && dt[i + 1] == tag;
    if (!found)
      err = MPMC_ERROR(s->ctx, MPMC_ERR_FORMAT,
                       "gmsh: physical group '%s' (dimension %d) in '%s' has no mesh elements", name,
                       d, s->file);
  }
  gmshFree(dt);
  fclose(fp);
  return err;
}

/* Open the file (a .geo through mesh_in_child); its model must have dimension >= dim. */
static int session_open(session *s, int dim) {
  int ierr = 0;
  char dir[512] = "", msh[600] = "";
  const int geo = !has_suffix(s->file, ".msh");
  if (geo) MPMC_CALL(mesh_in_child(s, dim, dir, sizeof dir, msh, sizeof msh));
  keep_threads(s, 1);
  gmshInitialize(0, NULL, 0, &ierr);
  keep_threads(s, 0);
  if (ierr) {
    if (geo) drop_mesh_dir(dir, msh);
    return MPMC_ERROR(s->ctx, MPMC_ERR_UNSUPPORTED, "gmsh: cannot initialise the gmsh library");
  }
  s->up = 1;
  gmshOptionSetNumber("General.Terminal", 0, &ierr);
  gmshLoggerStart(&ierr);
  gmshOpen(geo ? msh : s->file, &ierr);
  char msg[512];
  gmsh_last_error(msg, sizeof msg);
  const int err = ierr || msg[0] ? 0 : check_empty_groups(s, geo ? msh : s->file);
  if (geo) drop_mesh_dir(dir, msh);
  if (ierr || msg[0])
    return MPMC_ERROR(s->ctx, MPMC_ERR_FORMAT, "gmsh: cannot read '%s': %s", s->file,
                      msg[0] ? msg : "unknown error");
  if (err) return err;
  const int mdim = gmshModelGetDimension(&ierr);
  MPMC_CHECK(!ierr && mdim >= dim, s->ctx, MPMC_ERR_FORMAT,
             "gmsh: '%s' defines no %dD geometry (model dimension %d)", s->file, dim, mdim);
  return MPMC_SUCCESS;
}

/* ---- mesh data ------------------------------------------------------------------------------ */

typedef struct {
  double *xyz;    /* node coordinates indexed by node tag: [maxtag+1][3] */
  size_t maxtag;
} nodes;

static int load_nodes(session *s, nodes *nd) {
  int ierr = 0;
  size_t *tags = NULL, ntags = 0, nc = 0, np = 0;
  double *coord = NULL, *par = NULL;
  gmshModelMeshGetNodes(&tags, &ntags, &coord, &nc, &par, &np, -1, -1, 0, 0, &ierr);
  if (ierr) return gmsh_error(s, MPMC_ERR_FORMAT, "cannot read the nodes of");
  nd->maxtag = 0;
  for (size_t i = 0; i < ntags; ++i)
    if (tags[i] > nd->maxtag) nd->maxtag = tags[i];
  nd->xyz = calloc(3 * (nd->maxtag + 1), sizeof(double));
  if (nd->xyz)
    for (size_t i = 0; i < ntags; ++i) memcpy(nd->xyz + 3 * tags[i], coord + 3 * i, 3 * sizeof(double));
  gmshFree(tags);
  gmshFree(coord);
  gmshFree(par);
  MPMC_CHECK(nd->xyz, s->ctx, MPMC_ERR_MEMORY, "gmsh: cannot store %zu nodes", ntags);
  return MPMC_SUCCESS;
}

/* Linear simplices of a physical group: their corner coordinates [ns][dim+1 or fewer][3]. */
typedef struct {
  int nv;         /* vertices per simplex: 1 point, 2 segment, 3 triangle, 4 tetrahedron */
  size_t n, cap;
  double *v;      /* [n][nv][3] */
} simplices;

static int push_simplex(mpmc_context ctx, simplices *S, const nodes *nd, const size_t *tag,
                        const int *pick) {
  if (S->n == S->cap) {
    const size_t cap = S->cap ? 2 * S->cap : 256;
    double *a = realloc(S->v, sizeof(double) * 3 * (size_t)S->nv * cap);
    MPMC_CHECK(a, ctx, MPMC_ERR_MEMORY, "gmsh: cannot store %zu elements", cap);
    S->v = a;
    S->cap = cap;
  }
  for (int k = 0; k < S->nv; ++k) {
    const size_t t = tag[pick[k]];
    MPMC_CHECK(t <= nd->maxtag, ctx, MPMC_ERR_FORMAT, "gmsh: element refers to node %zu", t);
    memcpy(S->v + 3 * (S->n * (size_t)S->nv + (size_t)k), nd->xyz + 3 * t, 3 * sizeof(double));
  }
  S->n++;
  return MPMC_SUCCESS;
}

/* The elements of one entity, by type, as gmsh hands them out: element tags etags[t] and
 * node tags ntags[t] for type types[t]; released with elements_free. */
typedef struct {
  int *types;
  size_t ntypes, **etags, *etags_n, etags_nn, **ntags, *ntags_n, ntags_nn;
} elements;

static void elements_get(elements *el, int dim, int tag, int *ierr) {
  memset(el, 0, sizeof *el);
  gmshModelMeshGetElements(&el->types, &el->ntypes, &el->etags, &el->etags_n, &el->etags_nn, &el->ntags,
                           &el->ntags_n, &el->ntags_nn, dim, tag, ierr);
}

static void elements_free(elements *el) {
  for (size_t t = 0; t < el->etags_nn; ++t) gmshFree(el->etags[t]);
  for (size_t t = 0; t < el->ntags_nn; ++t) gmshFree(el->ntags[t]);
  gmshFree(el->etags);
  gmshFree(el->etags_n);
  gmshFree(el->ntags);
  gmshFree(el->ntags_n);
  gmshFree(el->types);
}

/* Split the elements (by their primary, i.e. corner, nodes) of the entities in a physical
 * group into simplices of dimension gdim. */
static int group_simplices(session *s, const nodes *nd, int gdim, int ptag, const char *gname,
                           simplices *S) {
  int ierr = 0;
  int *ents = NULL;
  size_t nent = 0;
  S->nv = gdim + 1;
  gmshModelGetEntitiesForPhysicalGroup(gdim, ptag, &ents, &nent, &ierr);
  if (ierr) return gmsh_error(s, MPMC_ERR_FORMAT, "cannot list the entities of a group in");
  int err = MPMC_SUCCESS;
  for (size_t e = 0; e < nent && !err; ++e) {
    elements els;
    elements_get(&els, gdim, ents[e], &ierr);
    if (ierr) err = gmsh_error(s, MPMC_ERR_FORMAT, "cannot read the elements of");
    for (size_t t = 0; t < els.ntypes && !err; ++t) {
      char *ename = NULL;
      int edim = 0, order = 0, nnode = 0, nprim = 0;
      double *lc = NULL;
      size_t nlc = 0;
      gmshModelMeshGetElementProperties(els.types[t], &ename, &edim, &order, &nnode, &lc, &nlc, &nprim,
                                        &ierr);
      /* corner-node splits into simplices (gmsh node order) */
      static const int pt[1][1] = {{0}}, seg[1][2] = {{0, 1}}, tri[1][3] = {{0, 1, 2}},
                       quad[2][3] = {{0, 1, 2}, {0, 2, 3}}, tet[1][4] = {{0, 1, 2, 3}},
                       hex[6][4] = {{0, 1, 3, 5}, {1, 2, 3, 5}, {0, 3, 4, 5}, {3, 4, 5, 7},
                                    {2, 3, 5, 6}, {3, 5, 6, 7}},
                       prism[3][4] = {{0, 1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4, 5}};
      const int *split = NULL;
      int nsplit = 0;
      if (gdim == 0 && nprim == 1) split = pt[0], nsplit = 1;
      else if (gdim == 1 && nprim == 2) split = seg[0], nsplit = 1;
      else if (gdim == 2 && nprim == 3) split = tri[0], nsplit = 1;
      else if (gdim == 2 && nprim == 4) split = quad[0], nsplit = 2;
      else if (gdim == 3 && nprim == 4) split = tet[0], nsplit = 1;
      else if (gdim == 3 && nprim == 8) split = hex[0], nsplit = 6;
      else if (gdim == 3 && nprim == 6) split = prism[0], nsplit = 3;
      if (!split)
        err = MPMC_ERROR(s->ctx, MPMC_ERR_UNSUPPORTED,
                         "gmsh: group '%s' in '%s' has elements of type '%s' (not supported)",
                         gname, s->file, ename ? ename : "?");
      for (size_t el = 0; el < els.etags_n[t] && !err; ++el)
        for (int k = 0; k < nsplit && !err; ++k)
          err = push_simplex(s->ctx, S, nd, els.ntags[t] + el * (size_t)nnode, split + k * S->nv);
      gmshFree(ename);
      gmshFree(lc);
    }
    elements_free(&els);
  }
  gmshFree(ents);
  if (!err && S->n == 0)
    err = MPMC_ERROR(s->ctx, MPMC_ERR_FORMAT,
                     "gmsh: physical group '%s' (dimension %d) in '%s' has no mesh elements", gname,
                     gdim, s->file);
  return err;
}

/* ---- geometry ----------------------------------------------------------------------------------- */

/* Barycentric inclusion in a triangle (2D) or tetrahedron (3D), closed with a tolerance so
 * that points on an element face count (the paper's Cook count keeps points on the edge). */
static int in_simplex(int d, const double *v, const double *x) {
  const double eps = 1e-10;
  if (d == 2) {
    const double *a = v, *b = v + 3, *c = v + 6;
    const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if (det == 0) return 0;
    const double l1 = ((x[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (x[1] - a[1])) / det;
    const double l2 = ((b[0] - a[0]) * (x[1] - a[1]) - (x[0] - a[0]) * (b[1] - a[1])) / det;
    return l1 >= -eps && l2 >= -eps && 1 - l1 - l2 >= -eps;
  }
  double m[3][3], r[3];
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) m[k][i] = v[3 * (i + 1) + k] - v[k];
    r[i] = x[i] - v[i];
  }
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  if (det == 0) return 0;
  double l[3];
  for (int c = 0; c < 3; ++c) { /* Cramer's rule */
    double mc[3][3];
    memcpy(mc, m, sizeof mc);
    for (int k = 0; k < 3; ++k) mc[k][c] = r[k];
    l[c] = (mc[0][0] * (mc[1][1] * mc[2][2] - mc[1][2] * mc[2][1]) -
            mc[0][1] * (mc[1][0] * mc[2][2] - mc[1][2] * mc[2][0]) +
            mc[0][2] * (mc[1][0] * mc[2][1] - mc[1][1] * mc[2][0])) /
           det;
  }
  return l[0] >= -eps && l[1] >= -eps && l[2] >= -eps && 1 - l[0] - l[1] - l[2] >= -eps;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Squared distance from p to the segment ab. */
static double dist2_segment(const double *a, const double *b, const double *p) {
  double e[3], w[3];
  for (int k = 0; k < 3; ++k) e[k] = b[k] - a[k], w[k] = p[k] - a[k];
  const double l2 = dot3(e, e);
  double t = l2 > 0 ? dot3(w, e) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  double r = 0;
  for (int k = 0; k < 3; ++k) r += (w[k] - t * e[k]) * (w[k] - t * e[k]);
  return r;
}

/* Squared distance from p to the triangle abc: the plane distance when p projects inside,
 * else the nearest edge. */
static double dist2_triangle(const double *a, const double *b, const double *c, const double *p) {
  double u[3], v[3], w[3], n[3];
  for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = p[k] - a[k];
  n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
  const double nn = dot3(n, n);
  if (nn > 0) {
    const double uu = dot3(u, u), uv = dot3(u, v), vv = dot3(v, v), wu = dot3(w, u), wv = dot3(w, v);
    const double den = uv * uv - uu * vv;
    const double s = (uv * wv - vv * wu) / den, t = (uv * wu - uu * wv) / den;
    if (s >= 0 && t >= 0 && s + t <= 1) {
      const double h = dot3(w, n);
      return h * h / nn;
    }
  }
  double d = dist2_segment(a, b, p), e = dist2_segment(b, c, p), f = dist2_segment(c, a, p);
  return d < e ? (d < f ? d : f) : (e < f ? e : f);
}

/* ---- seeding ---------------------------------------------------------------------------------- */

static void bbox(const simplices *S, int d, double *lo, double *hi) {
  for (int a = 0; a < 3; ++a) lo[a] = INFINITY, hi[a] = -INFINITY;
  for (size_t i = 0; i < S->n * (size_t)S->nv; ++i)
    for (int a = 0; a < d; ++a) {
      const double c = S->v[3 * i + a];
      if (c < lo[a]) lo[a] = c;
      if (c > hi[a]) hi[a] = c;
    }
}

static int seed_lattice(mpmc_sim sim, const simplices *R, int ppc, int material, int *first,
                        int *count, double *spacing) {
  const int d = sim->cfg.dim;
  double lo[3], hi[3];
  bbox(R, d, lo, hi);
  mpmc_lattice lat;
  MPMC_CALL(mpmc_lattice_init(sim, lo, hi, ppc, "gmsh lattice seeding", &lat));
  /* rasterise each element: the lattice points of its bounding box that it contains;
   * a point on a face shared by two elements is marked once */
  for (size_t e = 0; e < R->n; ++e) {
    const double *v = R->v + 3 * e * (size_t)R->nv;
    double elo[3] = {INFINITY, INFINITY, INFINITY}, ehi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < R->nv; ++k)
      for (int a = 0; a < d; ++a) {
        if (v[3 * k + a] < elo[a]) elo[a] = v[3 * k + a];
        if (v[3 * k + a] > ehi[a]) ehi[a] = v[3 * k + a];
      }
    long m0[3], m1[3], m[3];
    if (!mpmc_lattice_range(&lat, elo, ehi, m0, m1)) continue;
    for (m[2] = m0[2]; m[2] <= m1[2]; ++m[2])
      for (m[1] = m0[1]; m[1] <= m1[1]; ++m[1])
        for (m[0] = m0[0]; m[0] <= m1[0]; ++m[0]) {
          const size_t id = mpmc_lattice_index(&lat, m);
          if (lat.mark[id]) continue;
          double x[3] = {0, 0, 0};
          mpmc_lattice_point(&lat, m, x);
          if (in_simplex(d, v, x)) lat.mark[id] = 1;
        }
  }
  *spacing = lat.dx;
  return mpmc_lattice_add(sim, &lat, material, "gmsh lattice seeding", first, count);
}

static int seed_quadrature(session *s, mpmc_sim sim, int ptag, const char *region, int order,
                           int material, int *first, int *count) {
  mpmc_context ctx = sim->ctx;
  const int d = sim->cfg.dim;
  int ierr = 0, err = MPMC_SUCCESS;
  int *ents = NULL;
  size_t nent = 0, n = 0, cap = 0;
  double *x = NULL, *vol = NULL;
  char itype[32];
  gmshModelGetEntitiesForPhysicalGroup(d, ptag, &ents, &nent, &ierr);
  for (size_t e = 0; e < nent && !err; ++e) {
    elements els;
    elements_get(&els, d, ents[e], &ierr);
    for (size_t t = 0; t < els.ntypes && !err; ++t) {
      double *lc = NULL, *w = NULL, *jac = NULL, *det = NULL, *xq = NULL;
      size_t nlc = 0, nw = 0, njac = 0, ndet = 0, nxq = 0;
      /* the lowest Gauss rule of at least the requested order whose weights are all
       * positive (gmsh's order-3 triangle rule has a negative weight: no point volume) */
      for (int o = order; o <= order + 4; ++o) {
        snprintf(itype, sizeof itype, "Gauss%d", o);
        gmshModelMeshGetIntegrationPoints(els.types[t], itype, &lc, &nlc, &w, &nw, &ierr);
        int positive = !ierr && nw > 0;
        for (size_t k = 0; k < nw && positive; ++k) positive = w[k] > 0;
        if (positive || ierr) break;
        gmshFree(lc);
        gmshFree(w);
        lc = w = NULL;
        nw = 0;
      }
      if (!ierr)
        gmshModelMeshGetJacobians(els.types[t], lc, nlc, &jac, &njac, &det, &ndet, &xq, &nxq, ents[e],
                                  0, 1, &ierr);
      if (ierr || nw == 0 || ndet != els.etags_n[t] * nw) {
        err = gmsh_error(s, MPMC_ERR_FORMAT, "cannot integrate the elements of");
      } else {
        if (n + ndet > cap) {
          while (n + ndet > cap) cap = cap ? 2 * cap : 1024;
          double *a = realloc(x, sizeof(double) * (size_t)d * cap), *b = a ? realloc(vol, sizeof(double) * cap) : NULL;
          if (a) x = a;
          if (b) vol = b;
          if (!a || !b) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "gmsh: cannot store %zu points", cap);
        }
        for (size_t q = 0; q < ndet && !err; ++q, ++n) {
          for (int a = 0; a < d; ++a) x[n * (size_t)d + a] = xq[3 * q + (size_t)a];
          vol[n] = w[q % nw] * fabs(det[q]); /* V_p = w_q |det J| */
        }
      }
      gmshFree(lc);
      gmshFree(w);
      gmshFree(jac);
      gmshFree(det);
      gmshFree(xq);
    }
    elements_free(&els);
  }
  gmshFree(ents);
  if (!err && n == 0)
    err = MPMC_ERROR(ctx, MPMC_ERR_FORMAT, "gmsh: region '%s' in '%s' gave no quadrature points",
                     region, s->file);
  if (!err) {
    /* the region as a whole must lie in the grid box: one clear message, not one per point */
    const mpmc_grid *g = &sim->grid;
    for (size_t q = 0; q < n && !err; ++q)
      for (int a = 0; a < d && !err; ++a)
        if (!(x[q * (size_t)d + a] >= g->lo[a] && x[q * (size_t)d + a] <= g->hi[a]))
          err = MPMC_ERROR(ctx, MPMC_ERR_OUTSIDE,
                           "gmsh: region '%s' of '%s' reaches %g on axis %d, outside the grid box "
                           "[%g, %g]",
                           region, s->file, x[q * (size_t)d + a], a, g->lo[a], g->hi[a]);
  }
  if (!err) err = mpmc_sim_add_particles(sim, (int)n, x, vol, material, first);
  if (!err && count) *count = (int)n;
  free(x);
  free(vol);
  return err;
}

/* The points [first, first+count) bucketed by grid cell (a counting sort), so that the
 * points near an element are found without scanning them all. */
typedef struct {
  int first, count;
  long nc[3];   /* cells per axis (physical box)      */
  int *start;   /* [ncell + 1] offsets into pts        */
  int *pts;     /* [count] point indices, by cell      */
} buckets;

static long cell_of(const mpmc_grid *g, int a, double x, long nc) {
  long c = (long)floor((x - g->lo[a]) * g->inv_h);
  return c < 0 ? 0 : (c >= nc ? nc - 1 : c);
}

static int buckets_build(mpmc_sim sim, int first, int count, buckets *bk) {
  const mpmc_grid *g = &sim->grid;
  const int d = sim->cfg.dim;
  size_t ncell = 1;
  bk->first = first, bk->count = count;
  for (int a = 0; a < 3; ++a) {
    bk->nc[a] = a < d ? g->ng[a] - 1 - 2 * MPMC_GHOST : 1;
    ncell *= (size_t)bk->nc[a];
  }
  bk->start = calloc(ncell + 1, sizeof(int));
  bk->pts = malloc(sizeof(int) * (size_t)(count > 0 ? count : 1));
  int *cell = malloc(sizeof(int) * (size_t)(count > 0 ? count : 1));
  if (!bk->start || !bk->pts || !cell) {
    free(cell);
    return MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "gmsh: cannot bucket %d points", count);
  }
  for (int q = 0; q < count; ++q) {
    const double *x = sim->p.x + (size_t)(first + q) * d;
    long c = 0;
    for (int a = d - 1; a >= 0; --a) c = c * bk->nc[a] + cell_of(g, a, x[a], bk->nc[a]);
    cell[q] = (int)c;
    bk->start[c + 1]++;
  }
  for (size_t c = 0; c < ncell; ++c) bk->start[c + 1] += bk->start[c];
  for (int q = 0; q < count; ++q) bk->pts[bk->start[cell[q]]++] = first + q;
  for (size_t c = ncell; c > 0; --c) bk->start[c] = bk->start[c - 1];
  bk->start[0] = 0;
  free(cell);
  return MPMC_SUCCESS;
}

static void buckets_free(buckets *bk) {
  free(bk->start);
  free(bk->pts);
}

/* Half-width of the band that a boundary element claims: a point (node) belongs when its
 * tributary square/cube of side `spacing` touches the element, i.e. its distance is at most
 * spacing/2 * |n|_1 for the element's unit normal n (half a spacing for axis-aligned
 * boundaries, spacing/sqrt(2) at 45 degrees). */
static double band(const simplices *B, const double *v, double spacing) {
  double nrm[3] = {0, 0, 0};
  if (B->nv == 2) {
    nrm[0] = -(v[4] - v[1]), nrm[1] = v[3] - v[0];
  } else {
    double u[3], w[3];
    for (int k = 0; k < 3; ++k) u[k] = v[3 + k] - v[k], w[k] = v[6 + k] - v[k];
    nrm[0] = u[1] * w[2] - u[2] * w[1], nrm[1] = u[2] * w[0] - u[0] * w[2],
    nrm[2] = u[0] * w[1] - u[1] * w[0];
  }
  const double len = sqrt(dot3(nrm, nrm));
  const double l1 = len > 0 ? (fabs(nrm[0]) + fabs(nrm[1]) + fabs(nrm[2])) / len : 1.0;
  return 0.5 * spacing * l1 * (1 + 1e-6);
}

static double dist2_element(const simplices *B, const double *v, const double *p) {
  return B->nv == 2 ? dist2_segment(v, v + 3, p) : dist2_triangle(v, v + 3, v + 6, p);
}

/* Element e's bounding box grown by tol. */
static void element_box(const simplices *B, const double *v, int d, double tol, double *lo,
                        double *hi) {
  for (int a = 0; a < 3; ++a) lo[a] = INFINITY, hi[a] = -INFINITY;
  for (int k = 0; k < B->nv; ++k)
    for (int a = 0; a < d; ++a) {
      if (v[3 * k + a] - tol < lo[a]) lo[a] = v[3 * k + a] - tol;
      if (v[3 * k + a] + tol > hi[a]) hi[a] = v[3 * k + a] + tol;
    }
}

/* The points near a boundary group or, for a point group, the nearest point to each of its
 * vertices: their indices in *idx (malloc'ed), their number in *n. */
static int group_points(mpmc_sim sim, const simplices *B, const char *name, const buckets *bk,
                        double spacing, int **idx, int *n) {
  const int d = sim->cfg.dim, first = bk->first, count = bk->count;
  const mpmc_grid *g = &sim->grid;
  const double *x = sim->p.x;
  unsigned char *in = calloc((size_t)(count > 0 ? count : 1), 1);
  MPMC_CHECK(in, sim->ctx, MPMC_ERR_MEMORY, "gmsh: cannot allocate set '%s'", name);
  for (size_t e = 0; e < B->n; ++e) {
    const double *v = B->v + 3 * e * (size_t)B->nv;
    if (B->nv == 1) { /* few vertices: a scan of the points each */
      double best = INFINITY;
      int arg = -1;
      for (int q = 0; q < count; ++q) {
        double r = 0;
        for (int a = 0; a < d; ++a) {
          const double c = x[(size_t)(first + q) * d + a] - v[a];
          r += c * c;
        }
        if (r < best) best = r, arg = q;
      }
      if (arg >= 0) in[arg] = 1;
      continue;
    }
    const double tol = band(B, v, spacing), tol2 = tol * tol;
    double lo[3], hi[3];
    element_box(B, v, d, tol, lo, hi);
    long c0[3] = {0, 0, 0}, c1[3] = {0, 0, 0}, c[3];
    for (int a = 0; a < d; ++a) {
      c0[a] = cell_of(g, a, lo[a], bk->nc[a]);
      c1[a] = cell_of(g, a, hi[a], bk->nc[a]);
    }
    for (c[2] = c0[2]; c[2] <= c1[2]; ++c[2])
      for (c[1] = c0[1]; c[1] <= c1[1]; ++c[1])
        for (c[0] = c0[0]; c[0] <= c1[0]; ++c[0]) {
          const long cell = c[0] + bk->nc[0] * (c[1] + bk->nc[1] * c[2]);
          for (int k = bk->start[cell]; k < bk->start[cell + 1]; ++k) {
            const int q = bk->pts[k] - first;
            if (in[q]) continue;
            double p[3] = {0, 0, 0};
            for (int a = 0; a < d; ++a) p[a] = x[(size_t)bk->pts[k] * d + a];
            if (dist2_element(B, v, p) <= tol2) in[q] = 1;
          }
        }
  }
  int m = 0;
  for (int q = 0; q < count; ++q) m += in[q];
  *idx = malloc(sizeof(int) * (size_t)(m > 0 ? m : 1));
  if (!*idx) {
    free(in);
    return MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "gmsh: cannot allocate set '%s'", name);
  }
  m = 0;
  for (int q = 0; q < count; ++q)
    if (in[q]) (*idx)[m++] = first + q;
  free(in);
  /* over MPI another rank may hold the group's points: no warning from a rank alone */
  if (m == 0 && !sim->dd) mpmc_log(sim->ctx, MPMC_LOG_WARNING, "gmsh: no seeded point lies near group '%s'", name);
  *n = m;
  return MPMC_SUCCESS;
}

/* The grid nodes of a boundary group: those whose cell of influence (side h, centred on the
 * node) touches an element, i.e. within band(h) of it; for a point group the node nearest to
 * each vertex.  Node coordinates ijk in *ijk (malloc'ed, [n][dim]). */
static int group_nodes(mpmc_sim sim, const simplices *B, const char *name, int **ijk, int *n) {
  const int d = sim->cfg.dim;
  const mpmc_grid *g = &sim->grid;
  long nn[3] = {1, 1, 1};
  size_t total = 1;
  for (int a = 0; a < d; ++a) {
    nn[a] = g->ng[a] - 2 * MPMC_GHOST; /* nodes 0 .. cells */
    total *= (size_t)nn[a];
  }
  unsigned char *in = calloc(total, 1);
  MPMC_CHECK(in, sim->ctx, MPMC_ERR_MEMORY, "gmsh: cannot allocate node set '%s'", name);
  for (size_t e = 0; e < B->n; ++e) {
    const double *v = B->v + 3 * e * (size_t)B->nv;
    const double tol = B->nv == 1 ? 0.5 * g->h : band(B, v, g->h), tol2 = tol * tol;
    double lo[3], hi[3];
    element_box(B, v, d, tol, lo, hi);
    long i0[3] = {0, 0, 0}, i1[3] = {0, 0, 0}, i[3];
    int empty = 0;
    for (int a = 0; a < d; ++a) {
      i0[a] = (long)ceil((lo[a] - g->lo[a]) * g->inv_h);
      i1[a] = (long)floor((hi[a] - g->lo[a]) * g->inv_h);
      if (i0[a] < 0) i0[a] = 0;
      if (i1[a] > nn[a] - 1) i1[a] = nn[a] - 1;
      empty |= i1[a] < i0[a];
    }
    if (empty) continue;
    long best_node = -1;
    double best = INFINITY;
    for (i[2] = i0[2]; i[2] <= i1[2]; ++i[2])
      for (i[1] = i0[1]; i[1] <= i1[1]; ++i[1])
        for (i[0] = i0[0]; i[0] <= i1[0]; ++i[0]) {
          double p[3] = {0, 0, 0};
          for (int a = 0; a < d; ++a) p[a] = g->lo[a] + (double)i[a] * g->h;
          const long node = i[0] + nn[0] * (i[1] + nn[1] * i[2]);
          if (B->nv == 1) {
            double r = 0;
            for (int a = 0; a < d; ++a) r += (p[a] - v[a]) * (p[a] - v[a]);
            if (r < best) best = r, best_node = node;
          } else if (dist2_element(B, v, p) <= tol2) {
            in[node] = 1;
          }
        }
    if (best_node >= 0) in[best_node] = 1;
  }
  int m = 0;
  for (size_t k = 0; k < total; ++k) m += in[k];
  *ijk = malloc(sizeof(int) * (size_t)d * (size_t)(m > 0 ? m : 1));
  if (!*ijk) {
    free(in);
    return MPMC_ERROR(sim->ctx, MPMC_ERR_MEMORY, "gmsh: cannot allocate node set '%s'", name);
  }
  m = 0;
  for (size_t k = 0; k < total; ++k)
    if (in[k]) {
      size_t r = k;
      for (int a = 0; a < d; ++a) {
        (*ijk)[(size_t)m * d + a] = (int)(r % (size_t)nn[a]);
        r /= (size_t)nn[a];
      }
      ++m;
    }
  free(in);
  if (m == 0) mpmc_log(sim->ctx, MPMC_LOG_WARNING, "gmsh: no grid node lies near group '%s'", name);
  *n = m;
  return MPMC_SUCCESS;
}

/* Physical groups of the model: dimension, tag and name. */
typedef struct {
  int dim, tag;
  char *name;
} pgroup;

static int list_groups(session *s, pgroup **out, size_t *n) {
  int ierr = 0, *dt = NULL;
  size_t ndt = 0;
  *out = NULL;
  *n = 0;
  gmshModelGetPhysicalGroups(&dt, &ndt, -1, &ierr);
  if (ierr) return gmsh_error(s, MPMC_ERR_FORMAT, "cannot list the physical groups of");
  pgroup *g = calloc(ndt / 2 + 1, sizeof *g);
  if (!g) {
    gmshFree(dt);
    return MPMC_ERROR(s->ctx, MPMC_ERR_MEMORY, "gmsh: cannot list %zu groups", ndt / 2);
  }
  for (size_t i = 0; i < ndt / 2; ++i) {
    g[i].dim = dt[2 * i];
    g[i].tag = dt[2 * i + 1];
    gmshModelGetPhysicalName(g[i].dim, g[i].tag, &g[i].name, &ierr);
  }
  gmshFree(dt);
  *out = g;
  *n = ndt / 2;
  return MPMC_SUCCESS;
}

/**
 * @brief Seed the physical group `region` of a gmsh .geo (meshed here) or .msh file.
 * @param file a .geo or .msh file; its 2D geometry lies in the x-y plane
 * @param region name of a physical surface (2D) or volume (3D)
 * @param mode MPMC_SEED_LATTICE: ppc points per cell per axis of the sim's grid kept inside
 *        the mesh, volume (h/ppc)^dim; MPMC_SEED_QUADRATURE: the elements' Gauss points of
 *        order ppc, volume weight * |det J|
 * @param[out] first index of the first new point (may be NULL)
 * @param[out] count number of points added (may be NULL)
 * Every other physical group of lower dimension becomes a particle set and a node set named
 * after it: curves (2D) / surfaces (3D) take the new points within half a point spacing and
 * the grid nodes within half a cell (for a slanted boundary the band is widened to the
 * tributary square/cube that touches it), physical points the nearest new point and node.
 * On failure the sim is left as it was (no points, no sets added).
 */
int mpmc_seed_gmsh(mpmc_sim sim, const char *file, const char *region, mpmc_seed_mode mode, int ppc,
                   int material, int *first, int *count) {
  if (!sim) return MPMC_ERR_ARG;
  mpmc_context ctx = sim->ctx;
  const int d = sim->cfg.dim;
  MPMC_CHECK(file && file[0], ctx, MPMC_ERR_ARG, "gmsh: file name is NULL or empty");
  MPMC_CHECK(region && region[0], ctx, MPMC_ERR_ARG, "gmsh: region name is NULL or empty");
  MPMC_CHECK(mode == MPMC_SEED_LATTICE || mode == MPMC_SEED_QUADRATURE, ctx, MPMC_ERR_ARG,
             "gmsh: seeding mode = %d is not lattice (0) or quadrature (1)", mode);
  MPMC_CHECK(ppc >= 1 && ppc <= 16, ctx, MPMC_ERR_ARG,
             "gmsh: ppc = %d (points per cell per axis, or quadrature order) must be in [1, 16]",
             ppc);
  MPMC_CHECK(sim->grid.valid, ctx, MPMC_ERR_STATE, "gmsh: set the grid before seeding");
  MPMC_CHECK(material >= 0 && material < sim->nmat, ctx, MPMC_ERR_ARG,
             "gmsh: material id %d does not exist (%d materials)", material, sim->nmat);
  /* gmsh 4.8 opens a missing file "successfully" into an empty model */
  MPMC_CHECK(access(file, R_OK) == 0, ctx, MPMC_ERR_IO, "gmsh: cannot read '%s': %s", file,
             strerror(errno));
  session s = {ctx, file, 0, 0};
  nodes nd = {NULL, 0};
  pgroup *groups = NULL;
  size_t ngroup = 0;
  simplices R = {0, 0, 0, NULL};
  int f0 = 0, cnt = 0;
  int err = session_open(&s, d);
  if (!err) err = list_groups(&s, &groups, &ngroup);
  size_t ireg = ngroup;
  for (size_t i = 0; i < ngroup && !err; ++i)
    if (groups[i].dim == d && groups[i].name && strcmp(groups[i].name, region) == 0) ireg = i;
  if (!err && ireg == ngroup) {
    char names[400] = "";
    for (size_t i = 0; i < ngroup; ++i)
      if (groups[i].dim == d && groups[i].name && strlen(names) + strlen(groups[i].name) + 3 < sizeof names) {
        if (names[0]) strcat(names, ", ");
        strcat(names, groups[i].name);
      }
    err = MPMC_ERROR(ctx, MPMC_ERR_ARG,
                     "gmsh: '%s' has no non-empty %s physical group named '%s' (it has: %s)", file,
                     d == 2 ? "surface" : "volume", region, names[0] ? names : "none");
  }
  if (!err) err = load_nodes(&s, &nd);
  if (!err) err = group_simplices(&s, &nd, d, groups[ireg].tag, region, &R);
  double spacing = 0;
  if (!err) {
    if (mode == MPMC_SEED_LATTICE)
      err = seed_lattice(sim, &R, ppc, material, &f0, &cnt, &spacing);
    else
      err = seed_quadrature(&s, sim, groups[ireg].tag, region, ppc, material, &f0, &cnt);
  }
  /* the points this process holds: over MPI its slab's of the cnt seeded (mpi.c) */
  const int mine = err ? 0 : sim->p.n - f0;
  if (!err && mode == MPMC_SEED_QUADRATURE && mine > 0) { /* mean spacing of the Gauss points */
    double v = 0;
    for (int q = 0; q < mine; ++q) v += sim->p.vol0[f0 + q];
    spacing = pow(v / mine, 1.0 / d);
  }
  /* boundary and point groups -> particle sets of the new points and node sets; all are
   * computed before any is added, so that a failure leaves the sim as it was */
  typedef struct {
    const char *name;
    int np, nn;
    int *pidx, *ijk;
  } groupset;
  groupset *gs = err ? NULL : calloc(ngroup + 1, sizeof *gs);
  if (!err && !gs) err = MPMC_ERROR(ctx, MPMC_ERR_MEMORY, "gmsh: cannot allocate %zu sets", ngroup);
  buckets bk = {0, 0, {1, 1, 1}, NULL, NULL};
  if (!err) err = buckets_build(sim, f0, mine, &bk);
  for (size_t i = 0; i < ngroup && !err; ++i) {
    if (groups[i].dim >= d || !groups[i].name || !groups[i].name[0]) continue;
    if (groups[i].dim > 0 && groups[i].dim < d - 1) continue; /* curves in 3D: not a boundary */
    simplices B = {0, 0, 0, NULL};
    gs[i].name = groups[i].name;
    err = group_simplices(&s, &nd, groups[i].dim, groups[i].tag, groups[i].name, &B);
    if (!err) err = group_points(sim, &B, groups[i].name, &bk, spacing, &gs[i].pidx, &gs[i].np);
    if (!err) err = group_nodes(sim, &B, groups[i].name, &gs[i].ijk, &gs[i].nn);
    free(B.v);
  }
  buckets_free(&bk);
  for (size_t i = 0; gs && i < ngroup && !err; ++i)
    if (gs[i].name) {
      err = mpmc_sim_add_particle_set(sim, gs[i].name, gs[i].np, gs[i].pidx, NULL);
      if (!err) err = mpmc_sim_add_node_set(sim, gs[i].name, gs[i].nn, gs[i].ijk, NULL);
    }
  for (size_t i = 0; gs && i < ngroup; ++i) free(gs[i].pidx), free(gs[i].ijk);
  free(gs);
  /* a failure after the points were added takes them back */
  if (err && mine > 0 && sim->p.n == f0 + mine) {
    sim->p.n = f0;
    sim->scr.prepared = 0;
  }
  for (size_t i = 0; i < ngroup; ++i) gmshFree(groups[i].name);
  free(groups);
  free(nd.xyz);
  free(R.v);
  session_end(&s);
  if (err) return err;
  if (first) *first = f0;
  if (count) *count = cnt;
  return MPMC_SUCCESS;
}
