/* Local damping for quasi-static stages (Cundall; Al-Kafaji 2013):
 * per node and component f_damp = -alpha |f_int + f_ext| sign(v). */
#include "mpmc_impl.h"

void mpmc_damping_apply(double alpha, double *restrict f, const double *restrict v, int dim) {
  for (int a = 0; a < dim; ++a) {
    const double s = v[a] > 0.0 ? 1.0 : v[a] < 0.0 ? -1.0 : 0.0;
    f[a] -= alpha * (f[a] < 0 ? -f[a] : f[a]) * s;
  }
}
