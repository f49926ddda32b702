/* `mpmc`: the command-line front end of the staged workflow (docs/workflows.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpmc.h"
#include "mpmc_workflow.h"
#ifdef MPMC_HAVE_MPI
#include <mpi.h>

/* Started by an MPI launcher (mpirun/mpiexec of OpenMPI, or a PMI/PMIx one): the run is one
 * simulation over MPI_COMM_WORLD (docs/mpi.md); run plainly, MPI is not started at all. */
static int launched(void) {
  return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") || getenv("PMIX_RANK");
}
#endif

static const char usage[] =
    "usage: mpmc run SCENE.yaml [--out DIR] [--set key.path=value ...] [--threads N] [--force] [--quiet]\n"
    "       mpmc check SCENE.yaml [--set key.path=value ...]\n"
    "       mpmc fos SCENE.yaml [--out DIR] [--set key.path=value ...] [--threads N] [--force] [--quiet]\n"
    "       mpmc resume DIR [--set key.path=value ...] [--threads N] [--quiet]\n"
    "       mpmc models\n"
    "       mpmc --help | --version\n"
    "\n"
    "  run     run every stage of the scene; outputs go to DIR (default out/<scene>):\n"
    "          summary.json, series.csv, snapshots.h5/.xdmf, checkpoint.h5, PNG plots\n"
    "  fos     the factor of safety: the scene's stages up to its factor_of_safety stage,\n"
    "          which searches for it by strength reduction (summary.json, fos_trials.csv)\n"
    "  check   validate the scene (and the --set overrides) and print what would run\n"
    "  models  print the material models a scene may name, with their parameters (units,\n"
    "          ranges, defaults) as Markdown: the table of docs/materials.md\n"
    "  resume  continue a run from the last checkpoint in DIR (--set: after the run's own\n"
    "          overrides); a finished run goes on once its scene has another stage or a\n"
    "          later end for its last one, e.g. --set stages.runout.end.time=8\n"
    "\n"
    "  --set key.path=value  override any scene value, e.g. --set grid.cell_size=0.5\n"
    "                        --set fbar=false --set stages.runout.end.time=2\n"
    "                        (list items by index from 0 or by name)\n"
    "  --threads N           OpenMP threads (the same as --set threads=N)\n"
    "  --force               write into an existing, non-empty DIR\n"
    "  --quiet               no log and no progress\n"
    "\n"
    "Exit status 0 only when every stage completed.  Scene keys: docs/workflows.md.\n";

/* The library's message without its "<code>: " prefix and " [file.c:line]" suffix. */
static void print_error(mpmc_context ctx, int code) {
  char msg[4096]; /* the library keeps up to MPMC_MSG_LEN = 4096 */
  snprintf(msg, sizeof msg, "%s", mpmc_context_last_error(ctx));
  const char *pre = mpmc_error_string(code);
  char *body = msg;
  if (!strncmp(body, pre, strlen(pre)) && !strncmp(body + strlen(pre), ": ", 2)) body += strlen(pre) + 2;
  char *tail = strrchr(body, '[');
  if (tail && tail > body && tail[-1] == ' ' && strchr(tail, ']') && !strchr(tail, ' ')) tail[-1] = '\0';
  fprintf(stderr, "mpmc: error: %s\n", body[0] ? body : mpmc_error_string(code));
}

/* One model's parameters as a Markdown table, from the library's model table. */
static void print_model(int k) {
  mpmc_model_info mi;
  if (mpmc_model_get_info(k, &mi) || mi.needs_function) return;
  printf("### `%s`\n\n%s.\n\n| key | unit | meaning | valid | default |\n|---|---|---|---|---|\n",
         mi.name, mi.doc);
  for (int j = 0; j < mi.nparam; ++j) {
    mpmc_param_info pi;
    if (mpmc_model_get_param(k, j, &pi)) continue;
    char valid[160], def[160] = "required";
    if (pi.nwords > 0) {
      size_t l = 0;
      valid[0] = 0;
      for (int w = 0; w < pi.nwords && l < sizeof valid; ++w)
        l += (size_t)snprintf(valid + l, sizeof valid - l, "%s`%s`", w ? ", " : "", pi.words[w]);
    } else if (pi.hi == INFINITY) {
      snprintf(valid, sizeof valid, "%s %g", pi.lo_open ? ">" : "≥", pi.lo);
    } else {
      snprintf(valid, sizeof valid, "%c%g, %g%c", pi.lo_open ? '(' : '[', pi.lo, pi.hi,
               pi.hi_open ? ')' : ']');
    }
    if (pi.at_most >= 0) {
      mpmc_param_info top;
      if (!mpmc_model_get_param(k, pi.at_most, &top))
        snprintf(valid + strlen(valid), sizeof valid - strlen(valid), ", ≤ `%s`", top.name);
    }
    if (pi.alias_of >= 0) {
      mpmc_param_info of;
      mpmc_model_get_param(k, pi.alias_of, &of);
      snprintf(def, sizeof def, "instead of `%s` (= %.9g × this)", of.name, pi.scale);
    } else if (pi.optional && pi.default_of >= 0) {
      mpmc_param_info of;
      mpmc_model_get_param(k, pi.default_of, &of);
      snprintf(def, sizeof def, "`%s`", of.name);
    } else if (pi.optional && pi.nwords > 0) {
      snprintf(def, sizeof def, "`%s`", pi.words[(int)pi.def]);
    } else if (pi.optional) {
      if (pi.def == INFINITY)
        snprintf(def, sizeof def, "none");
      else
        snprintf(def, sizeof def, "%g", pi.def);
    }
    const char *srm = pi.strength == 1 ? " (÷ F in strength reduction)"
                      : pi.strength == 2 ? " (tan ÷ F in strength reduction)"
                                         : "";
    printf("| `%s` | %s | %s%s | %s | %s |\n", pi.name, pi.unit, pi.doc, srm, valid, def);
  }
  printf("\n");
}

int main(int argc, char **argv) {
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
    fputs(usage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (!strcmp(argv[1], "--version")) {
    int a, b, c;
    mpmc_version(&a, &b, &c);
    printf("mpmc %d.%d.%d (libmpmc, F-bar MPM of Zhao, Jiang & Choo 2023)\n", a, b, c);
    return 0;
  }
  const char *cmd = argv[1];
  if (!strcmp(cmd, "models")) {
    int n = 0;
    mpmc_model_count(&n);
    for (int k = 0; k < n; ++k) print_model(k);
    return 0;
  }
  if (strcmp(cmd, "run") && strcmp(cmd, "check") && strcmp(cmd, "resume") && strcmp(cmd, "fos")) {
    fprintf(stderr, "mpmc: unknown command '%s'\n%s", cmd, usage);
    return 2;
  }
  const char *target = NULL, *out = NULL;
  int flags = 0, nset = 0;
  const char **sets = calloc((size_t)argc + 1, sizeof *sets);
  char **owned = calloc((size_t)argc + 1, sizeof *owned);
  int nowned = 0;
  if (!sets || !owned) return 1;
  for (int i = 2; i < argc; ++i) {
    const char *a = argv[i];
    if (!strcmp(a, "--out") && i + 1 < argc)
      out = argv[++i];
    else if (!strcmp(a, "--set") && i + 1 < argc)
      sets[nset++] = argv[++i];
    else if (!strncmp(a, "--set=", 6))
      sets[nset++] = a + 6;
    else if (!strcmp(a, "--threads") && i + 1 < argc) {
      const size_t n = strlen(argv[i + 1]) + 16;
      char *s = malloc(n);
      if (!s) return 1;
      snprintf(s, n, "threads=%s", argv[++i]);
      sets[nset++] = owned[nowned++] = s;
    } else if (!strcmp(a, "--force"))
      flags |= MPMC_WORKFLOW_FORCE;
    else if (!strcmp(a, "--quiet"))
      flags |= MPMC_WORKFLOW_QUIET;
    else if (a[0] == '-' || target) {
      fprintf(stderr, "mpmc %s: unexpected argument '%s'\n%s", cmd, a, usage);
      return 2;
    } else
      target = a;
  }
  if (!target) {
    fprintf(stderr, "mpmc %s: missing %s\n%s", cmd, strcmp(cmd, "resume") ? "SCENE.yaml" : "DIR", usage);
    return 2;
  }
  if (!strcmp(cmd, "resume") && (out || (flags & MPMC_WORKFLOW_FORCE))) {
    fprintf(stderr, "mpmc resume: %s does not apply: the run goes on in its own directory %s\n%s",
            out ? "--out" : "--force", target, usage);
    return 2;
  }
  int rank = 0, mpi = 0;
#ifdef MPMC_HAVE_MPI
  if (launched()) { /* OpenMP threads inside each rank; MPI called from the main thread */
    int provided;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    mpi = 1;
  }
#endif
  mpmc_context ctx;
  if (mpmc_context_create(&ctx)) return 1;
  int err;
  if (!strcmp(cmd, "resume"))
    err = mpmc_workflow_resume_set(ctx, target, nset, sets, flags & MPMC_WORKFLOW_QUIET);
  else
    err = mpmc_workflow_run(ctx, target, out, nset, sets,
                            flags | (!strcmp(cmd, "check") ? MPMC_WORKFLOW_CHECK : 0) |
                                (!strcmp(cmd, "fos") ? MPMC_WORKFLOW_FOS : 0));
  if (err && rank == 0) print_error(ctx, err); /* over MPI every rank has the error: rank 0 says it */
  mpmc_context_destroy(&ctx);
#ifdef MPMC_HAVE_MPI
  if (mpi) MPI_Finalize();
#endif
  (void)mpi;
  for (int i = 0; i < nowned; ++i) free(owned[i]);
  free(owned);
  free(sets);
  return err ? 1 : 0;
}
