/* Seeding from gmsh through libmpmc_gmsh, loaded with dlopen only when a scene asks for it:
 * libgmsh costs about 0.12 s and 60 MB to load (OpenCASCADE, FLTK), so the `mpmc` program
 * and libmpmc_workflow do not link it, and box or polygon scenes never map it. */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wf.h"

typedef int (*seed_fn)(mpmc_sim, const char *, const char *, int, int, int, int *, int *);

static void *plugin;

/* Candidates: $MPMC_GMSH_PLUGIN, the build tree's library, then the loader's search path. */
static void *open_plugin(char *why, size_t len) {
  const char *cands[4];
  int n = 0;
  const char *env = getenv("MPMC_GMSH_PLUGIN");
  if (env && env[0]) cands[n++] = env;
#ifdef MPMC_GMSH_PLUGIN_PATH
  cands[n++] = MPMC_GMSH_PLUGIN_PATH;
#endif
  cands[n++] = "libmpmc_gmsh.so.0";
  cands[n++] = "libmpmc_gmsh.so";
  why[0] = '\0';
  for (int i = 0; i < n; ++i) {
    void *h = dlopen(cands[i], RTLD_NOW | RTLD_LOCAL);
    if (h) return h;
    if (!why[0]) {
      const char *e = dlerror();
      snprintf(why, len, "%s", e ? e : cands[i]);
    }
  }
  return NULL;
}

/** @brief mpmc_seed_gmsh from the lazily loaded libmpmc_gmsh. */
int wf_seed_gmsh(mpmc_sim sim, const char *file, const char *region, int mode, int ppc, int material,
                 int *first, int *count, char *msg, size_t len) {
  char why[512];
  if (!plugin) plugin = open_plugin(why, sizeof why);
  if (!plugin) {
    snprintf(msg, len, "gmsh seeding is not available (libmpmc_gmsh: %s); build with -DMPMC_WITH_GMSH=ON", why);
    return MPMC_ERR_UNSUPPORTED;
  }
  void *sym = dlsym(plugin, "mpmc_seed_gmsh");
  if (!sym) {
    snprintf(msg, len, "libmpmc_gmsh has no mpmc_seed_gmsh");
    return MPMC_ERR_UNSUPPORTED;
  }
  seed_fn fn;
  memcpy(&fn, &sym, sizeof fn); /* POSIX: object pointer to function pointer */
  const int e = fn(sim, file, region, mode, ppc, material, first, count);
  if (e) {
    mpmc_context ctx;
    mpmc_sim_get_context(sim, &ctx);
    snprintf(msg, len, "%s", mpmc_context_last_error(ctx));
  }
  return e;
}
