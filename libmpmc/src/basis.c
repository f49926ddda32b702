/* Out-of-line entry to the basis functions (the hot kernels inline basis.h directly). */
#include "basis.h"

void mpmc_basis_eval_1d(int basis, double s, double l, double inv_h, int *base, double *w,
                        double *dw) {
  mpmc_basis_1d(basis, s, l, inv_h, base, w, dw);
}
