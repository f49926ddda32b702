/* libFuzzer target for the scene loader (workflows/scene.c): arbitrary bytes as a scene
 * file, plus `--set` overrides taken from leading lines "#set key.path=value" (at most 4),
 * so that the override path of the loader is fuzzed as well.
 *
 * Besides crashes, leaks and hangs (libFuzzer with ASan/UBSan) it checks two properties:
 * a failure always comes with a non-empty, terminated message of the form
 * "where: key '...': ..." (or a file/--set message), and a scene that loads satisfies the
 * ranges the loader promises (docs/workflows.md): a validation gap aborts.
 *
 * Built by scripts/fuzz-scene with clang -fsanitize=fuzzer; replayed over tests/fuzz/corpus
 * by tests/fuzz/replay.c (CTest fuzz-scene-replay, gcc). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "wf.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char scene_path[256];

static void remove_scene_file(void) {
  if (scene_path[0]) unlink(scene_path);
}

/* One scene file per process, rewritten for each input (on tmpfs when available). */
static const char *scene_file(const uint8_t *data, size_t size) {
  if (!scene_path[0]) {
    const char *dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    snprintf(scene_path, sizeof scene_path, "%s/mpmc-fuzz-%ld.yaml", dir, (long)getpid());
    atexit(remove_scene_file);
  }
  FILE *f = fopen(scene_path, "wb");
  if (!f) abort();
  if (size && fwrite(data, 1, size, f) != size) abort();
  if (fclose(f)) abort();
  return scene_path;
}

static void require(int cond, const char *what, const wf_scene *sc) {
  if (cond) return;
  fprintf(stderr, "fuzz_scene: a loaded scene violates: %s (scene %s)\n", what, sc->name);
  abort();
}

/* The ranges promised by docs/workflows.md for a scene that loaded. */
static void check_scene(const wf_scene *sc) {
  require(sc->dim == 2 || sc->dim == 3, "dim in {2, 3}", sc);
  require(isfinite(sc->h) && sc->h > 0, "grid.cell_size > 0", sc);
  for (int a = 0; a < sc->dim; ++a) {
    require(isfinite(sc->lo[a]) && isfinite(sc->hi[a]) && sc->hi[a] > sc->lo[a], "grid.lo < grid.hi", sc);
    require(sc->h <= sc->hi[a] - sc->lo[a], "cell_size <= grid extent", sc);
  }
  require(sc->basis >= 0 && sc->basis <= 3, "basis", sc);
  require(sc->fbar >= MPMC_FBAR_OFF && sc->fbar <= MPMC_FBAR_ANCHORED, "fbar", sc);
  require(sc->flip >= 0 && sc->flip <= 1, "flip in [0, 1]", sc);
  require(sc->threads >= 0, "threads >= 0", sc);
  require(sc->checkpoint_interval > 0 && sc->progress_interval > 0, "intervals > 0", sc);
  require(sc->nmat >= 1 && sc->mats, "at least one material", sc);
  /* every material the reader accepts, the library accepts too (the same model table) */
  mpmc_context ctx = NULL;
  mpmc_sim sim = NULL;
  require(!mpmc_context_create(&ctx) && !mpmc_sim_create(ctx, 2, &sim), "a simulation", sc);
  for (int i = 0; i < sc->nmat; ++i) {
    const wf_material *m = &sc->mats[i];
    require(mpmc_sim_add_material(sim, wf_model_name(m->model), m->par, m->npar, NULL) == 0,
            "the library accepts the material", sc);
  }
  mpmc_sim_destroy(&sim);
  mpmc_context_destroy(&ctx);
  require(sc->nbody >= 1 && sc->bodies, "at least one body", sc);
  for (int i = 0; i < sc->nbody; ++i) {
    const wf_body *b = &sc->bodies[i];
    require(b->material >= 0 && b->material < sc->nmat, "body material", sc);
    require(b->ppc >= 1 && b->ppc <= 8, "ppc in [1, 8]", sc);
    if (b->type == WF_GEOM_POLYGON) {
      require(b->nvert >= 3 && b->xy, "polygon >= 3 vertices", sc);
      for (int k = 0; k < 2 * b->nvert; ++k) require(isfinite(b->xy[k]), "finite polygon vertices", sc);
    }
    if (b->type == WF_GEOM_BOX)
      for (int a = 0; a < sc->dim; ++a) require(b->lo[a] < b->hi[a], "box lo < hi", sc);
  }
  require(sc->nstage >= 1 && sc->stages, "at least one stage", sc);
  for (int i = 0; i < sc->nstage; ++i) {
    const wf_stage *s = &sc->stages[i];
    require(s->damping >= 0 && s->damping < 1, "damping in [0, 1)", sc);
    require(s->strength_reduction >= 0 && isfinite(s->strength_reduction), "strength_reduction > 0", sc);
    require(s->dt_factor > 0 && s->dt_factor <= 1, "dt_factor in (0, 1]", sc);
    require(s->dt >= 0 && isfinite(s->dt), "dt >= 0", sc);
    require(isfinite(s->end_time) && s->end_time > 0, "end time > 0", sc);
    if (s->end_kind == WF_END_QUASI_STATIC) {
      require(s->ke_ratio > 0 && s->ke_ratio < 1, "kinetic_energy_ratio in (0, 1)", sc);
      require(s->min_time >= 0 && s->min_time <= s->max_time, "0 <= min_time <= max_time", sc);
    }
    require(s->snapshots >= 0 && s->series_points >= 1, "snapshots >= 0, series_points >= 1", sc);
    for (int a = 0; a < sc->dim; ++a) require(isfinite(s->gravity[a]), "finite gravity", sc);
    for (int k = 0; k < s->nwalls; ++k) {
      const wf_wall *w = &s->walls[k];
      require(w->kind >= 0 && w->kind <= 2, "wall kind", sc);
      require(w->axis >= 0 && w->axis < sc->dim, "wall axis < dim", sc);
      require(w->form != 0 || (w->face >= 0 && w->face < 2 * sc->dim), "wall face", sc);
    }
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  /* leading "#set ..." lines become overrides */
  char *sets[4];
  int nset = 0;
  size_t off = 0;
  while (nset < 4 && size - off > 5 && !memcmp(data + off, "#set ", 5)) {
    const uint8_t *nl = memchr(data + off, '\n', size - off);
    const size_t end = nl ? (size_t)(nl - data) : size;
    const size_t len = end - off - 5;
    sets[nset] = malloc(len + 1);
    if (!sets[nset]) abort();
    memcpy(sets[nset], data + off + 5, len);
    sets[nset][len] = '\0';
    if (strlen(sets[nset]) != len) { /* an embedded NUL: not a command-line argument */
      free(sets[nset]);
      break;
    }
    ++nset;
    off = nl ? end + 1 : size;
  }
  const char *path = scene_file(data, size);
  wf_scene sc;
  char msg[WF_MSG];
  memset(msg, 'x', sizeof msg);
  const int e = wf_scene_load(path, nset, (const char *const *)sets, &sc, msg, sizeof msg);
  if (!memchr(msg, '\0', sizeof msg)) {
    fprintf(stderr, "fuzz_scene: message not terminated\n");
    abort();
  }
  if (e) {
    if (!msg[0]) {
      fprintf(stderr, "fuzz_scene: failure %d without a message\n", e);
      abort();
    }
  } else {
    check_scene(&sc);
    wf_scene_free(&sc);
  }
  for (int i = 0; i < nset; ++i) free(sets[i]);
  return 0;
}
