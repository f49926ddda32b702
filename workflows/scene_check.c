/* CTest driver for one scene: run it at the small size its .expected.yaml gives (`set:`),
 * then compare summary.json's metrics with the expected values or bounds stored there.
 *   mpmc_scene_check SCENE.yaml SCENE.expected.yaml OUTDIR
 * Prints nothing when every check passes; otherwise what was expected and what was got. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wf.h"

static int num(const wf_node *n, double *v) {
  if (!n || n->kind != WF_SCALAR) return -1;
  char *end;
  *v = strtod(n->value, &end);
  return *end ? -1 : 0;
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s SCENE.yaml SCENE.expected.yaml OUTDIR\n", argv[0]);
    return 2;
  }
  char msg[WF_MSG];
  int code = 0;
  wf_node *exp = wf_yaml_load(argv[2], "expected-values file", &code, msg, sizeof msg);
  if (!exp) {
    fprintf(stderr, "%s\n", msg);
    return 1;
  }
  const wf_node *set = wf_map_get(exp, "set"), *metrics = wf_map_get(exp, "metrics");
  const char *sets[64];
  int nset = 0;
  for (int i = 0; set && set->kind == WF_SEQ && i < set->n && i < 64; ++i) sets[nset++] = set->items[i]->value;
  if (!metrics || metrics->kind != WF_MAP || metrics->n == 0) {
    fprintf(stderr, "%s: no metrics to check\n", argv[2]);
    return 1;
  }
  mpmc_context ctx;
  mpmc_context_create(&ctx);
  const int err = mpmc_workflow_run(ctx, argv[1], argv[3], nset, sets, MPMC_WORKFLOW_FORCE | MPMC_WORKFLOW_QUIET);
  if (err) {
    fprintf(stderr, "%s: run failed (%d): %s\n", argv[1], err, mpmc_context_last_error(ctx));
    return 1;
  }
  mpmc_context_destroy(&ctx);
  char path[WF_PATH + 32];
  snprintf(path, sizeof path, "%s/summary.json", argv[3]);
  wf_node *sum = wf_yaml_load(path, "summary", &code, msg, sizeof msg);
  if (!sum) {
    fprintf(stderr, "%s\n", msg);
    return 1;
  }
  int bad = 0;
  const wf_node *status = wf_map_get(sum, "status");
  if (!status || status->kind != WF_SCALAR || strcmp(status->value, "completed")) {
    fprintf(stderr, "%s: status expected 'completed', got '%s'\n", path, status ? status->value : "(none)");
    bad = 1;
  }
  for (int i = 0; i < metrics->n; ++i) {
    const char *name = metrics->keys[i];
    const wf_node *spec = metrics->items[i];
    double got, value, tol, lo, hi;
    if (num(wf_map_get(sum, name), &got)) {
      fprintf(stderr, "%s: metric %s missing from summary.json\n", argv[1], name);
      bad = 1;
      continue;
    }
    if (!num(wf_map_get(spec, "value"), &value)) {
      int rel = !num(wf_map_get(spec, "rel_tol"), &tol);
      if (!rel && num(wf_map_get(spec, "abs_tol"), &tol)) {
        fprintf(stderr, "%s: metric %s needs rel_tol or abs_tol\n", argv[2], name);
        bad = 1;
        continue;
      }
      const double e = rel ? fabs(got - value) / fabs(value) : fabs(got - value);
      if (!(e <= tol)) {
        fprintf(stderr, "%s: %s expected %.6g (%s tolerance %g), got %.6g (error %.3g)\n", argv[1], name, value,
                rel ? "relative" : "absolute", tol, got, e);
        bad = 1;
      }
    } else if (!num(wf_map_get(spec, "min"), &lo) && !num(wf_map_get(spec, "max"), &hi)) {
      if (!(got >= lo && got <= hi)) {
        fprintf(stderr, "%s: %s expected in [%g, %g], got %.6g\n", argv[1], name, lo, hi, got);
        bad = 1;
      }
    } else {
      fprintf(stderr, "%s: metric %s needs value + rel_tol/abs_tol or min + max\n", argv[2], name);
      bad = 1;
    }
  }
  wf_node_free(sum);
  wf_node_free(exp);
  return bad;
}
