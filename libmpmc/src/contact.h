/* Rigid bodies of contact_barrier.c, shared with checkpoint.c (which saves them). */
#ifndef MPMC_CONTACT_H
#define MPMC_CONTACT_H

enum { BODY_BOX = 0, BODY_POLYGON = 1 };

typedef struct {
  int active, kind;
  double lo[3], hi[3]; /* the box, or the polygon's bounding box, at creation          */
  int nvert;
  double *xy;          /* polygon vertices [nvert][2] at creation, counter-clockwise   */
  double mu;           /* Coulomb friction coefficient                                  */
  double v[3];         /* prescribed velocity                                           */
  double offset[3];    /* displacement since creation                                   */
  double reaction[3];  /* force of the points on the body in the last step              */
  int nanchor;         /* points the anchors cover (grown with the point count)         */
  double *anchor;      /* friction: per point [nanchor][3] tangential displacement since
                        * it stuck (elastic stick, docs/contact.md); NULL until mu > 0 */
} mpmc_body;

struct mpmc_bodies_s {
  mpmc_body *b;
  int n, cap;
  double dhat, kappa; /* the caller's values; 0 = derive (docs/contact.md)          */
  /* within one mpmc_sim_step (mpmc_contact_step): the derived values, held for its three
   * uses (the time-step check, the forces, the crossing check), which would each sum the
   * points' volumes again; nothing can change them in between */
  double step_dhat, step_kappa;
  int step_held;
};

/* Friction anchors for every point (points added since the last contact pass start at
 * rest: NaN, out of contact); contact_barrier.c and sort.c. */
struct mpmc_sim_s;
int mpmc_contact_grow_anchors(struct mpmc_sim_s *sim, mpmc_body *b);
/* The same for the first n points (mpi.c: before arrivals are written). */
int mpmc_contact_reserve_anchors(struct mpmc_sim_s *sim, mpmc_body *b, int n);

#endif
