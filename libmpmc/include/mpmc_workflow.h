/* libmpmc: the staged workflow of YAML scenes (`mpmc run`).  A public header of its own,
 * beside mpmc.h: the functions below live in the separate library libmpmc_workflow
 * (mpmc::mpmc_workflow, -lmpmc_workflow), with the `mpmc` program. */
#ifndef MPMC_WORKFLOW_H
#define MPMC_WORKFLOW_H

#include "mpmc.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the staged workflow (workflows/, library libmpmc_workflow) ---------------------- */
/* Run a YAML scene: the same as `mpmc run scene --out outdir --set ...`.  overrides are
 * noverride "key.path=value" strings; flags: bit 0 = force (write over outdir).  The
 * summary's figures are then in outdir/summary.json. */
int mpmc_workflow_run(mpmc_context ctx, const char *scene, const char *outdir, int noverride,
                      const char *const *overrides, int flags);
#define MPMC_WORKFLOW_FORCE 1 /* write into an existing, non-empty outdir              */
#define MPMC_WORKFLOW_QUIET 2 /* no log and no progress display                        */
#define MPMC_WORKFLOW_CHECK 4 /* validate the scene and print the plan; run nothing     */
#define MPMC_WORKFLOW_FOS 8   /* stop after the factor_of_safety stage (`mpmc fos`)     */
/* Continue the run in outdir from its last checkpoint (`mpmc resume`); flags: QUIET.  A
 * finished run's checkpoint goes on once the scene has another stage, or a later end for its
 * last one if that stage ended on its time (not on coming to rest); with overrides
 * (`mpmc resume DIR --set ...`) applied after the run's own. */
int mpmc_workflow_resume(mpmc_context ctx, const char *outdir, int flags);
int mpmc_workflow_resume_set(mpmc_context ctx, const char *outdir, int noverride,
                             const char *const *overrides, int flags);

#ifdef __cplusplus
}
#endif
#endif /* MPMC_WORKFLOW_H */
