/* Nearly incompressible Newtonian fluid: sigma = K (J - 1) 1 + 2 mu dev(D), with J the
 * F-bar Jacobian when F-bar is on and D = sym(dF - 1)/dt the rate of deformation. */
#include <math.h>

#include "mpmc_impl.h"

static int newtonian_update(mpmc_sim sim, const mpmc_material *mat, int id, double dt) {
  mpmc_particles *p = &sim->p;
  const int d = sim->dim;
  const double K = mat->K, mu2 = 2.0 * mat->mu, inv_dt = dt > 0 ? 1.0 / dt : 0.0;
  const double *Jm = sim->fbar ? p->Jbar : p->J;
#pragma omp parallel for schedule(static) if (p->n > MPMC_OMP_MIN)
  for (int q = 0; q < p->n; ++q) {
    if (p->mat[q] != id) continue;
    const double *f = p->dF + (size_t)q * d * d;
    double D[3][3] = {{0}};
    for (int a = 0; a < d; ++a)
      for (int b = 0; b < d; ++b) D[a][b] = 0.5 * (f[a * d + b] + f[b * d + a]) * inv_dt;
    for (int a = 0; a < d; ++a) D[a][a] -= inv_dt;
    const double trD = (D[0][0] + D[1][1] + D[2][2]) / 3.0;
    const double pr = K * (Jm[q] - 1.0);
    double *s = p->stress + (size_t)q * 6;
    s[0] = pr + mu2 * (D[0][0] - trD);
    s[1] = pr + mu2 * (D[1][1] - trD);
    s[2] = pr + mu2 * (D[2][2] - trD);
    s[3] = mu2 * D[1][2];
    s[4] = mu2 * D[0][2];
    s[5] = mu2 * D[0][1];
  }
  return MPMC_SUCCESS;
}

static double newtonian_wave_speed(const mpmc_material *m) { return sqrt(m->K / m->rho); }

const mpmc_material_ops mpmc_ops_newtonian = {"newtonian", newtonian_update, newtonian_wave_speed, 0, 0};
