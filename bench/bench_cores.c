/* What the machine's second core adds (issue 6: "two threads >= 1.8x one thread"), measured
 * without libmpmc: the same work on one thread and on two at once.
 *   fma    12 independent chains of 4-wide fused multiply-adds per thread (AVX2 + FMA where
 *          the processor has them, else the same arithmetic as plain vectors): the floating-
 *          point units' throughput, what the transfer kernels' stencil sums are bound by;
 *   triad  a[i] = b[i] + s c[i] over three arrays of 32 MiB each (far beyond the caches),
 *          each thread its half: memory bandwidth.
 * Prints per test the one-thread and two-thread rates and their ratio.  Two physical cores
 * give about 2 for fma; two hardware threads of one core (SMT), which share its units, about
 * 1; a memory-bound code scales at most as triad does.
 *   bench_cores [seconds per test (default 1)] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

typedef double v4 __attribute__((vector_size(32)));
#define CHAINS 12

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
__attribute__((target("avx2,fma"))) static double fma_avx2(long iters) {
  __m256d a[CHAINS];
  for (int k = 0; k < CHAINS; ++k) a[k] = _mm256_set1_pd(1.0 + k * 1e-9);
  const __m256d m = _mm256_set1_pd(0.999999999), c = _mm256_set1_pd(1e-9);
  for (long i = 0; i < iters; ++i)
    for (int k = 0; k < CHAINS; ++k) a[k] = _mm256_fmadd_pd(a[k], m, c);
  double s = 0.0, t[4];
  for (int k = 0; k < CHAINS; ++k) {
    _mm256_storeu_pd(t, a[k]);
    s += t[0] + t[3];
  }
  return s;
}
#endif
/* iters rounds of the chains (multiply and add: the FMA's arithmetic without the fusion);
 * returns a sum so that the work is not optimised away */
static double fma_plain(long iters) {
  v4 a[CHAINS];
  for (int k = 0; k < CHAINS; ++k) a[k] = (v4){1.0, 1.0, 1.0, 1.0} + k * 1e-9;
  const v4 m = {0.999999999, 0.999999999, 0.999999999, 0.999999999};
  for (long i = 0; i < iters; ++i)
    for (int k = 0; k < CHAINS; ++k) a[k] = a[k] * m + 1e-9;
  double s = 0.0;
  for (int k = 0; k < CHAINS; ++k) s += a[k][0] + a[k][3];
  return s;
}

static double fma_chains(long iters, int avx2) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (avx2) return fma_avx2(iters);
#endif
  (void)avx2;
  return fma_plain(iters);
}

/* rate of test t (0 fma: G double flops/s; 1 triad: GB/s) on nt threads over ~secs */
static double rate(int t, int nt, double secs, int avx2, double *a, double *b, double *c,
                   size_t n) {
  long reps = 1;
  for (;;) {
    double sink = 0.0;
    const double t0 = omp_get_wtime();
#pragma omp parallel num_threads(nt) reduction(+ : sink)
    {
      const int id = omp_get_thread_num();
      if (t == 0) {
        sink += fma_chains(reps * 1000000L, avx2);
      } else {
        const size_t i0 = n * (size_t)id / (size_t)nt, i1 = n * (size_t)(id + 1) / (size_t)nt;
        for (long r = 0; r < reps; ++r) {
          for (size_t i = i0; i < i1; ++i) a[i] = b[i] + 0.5 * c[i];
          sink += a[i0];
        }
      }
    }
    const double dt = omp_get_wtime() - t0;
    if (sink == 42.0) printf(" ");
    if (dt >= secs) {
      const double work = t == 0 ? (double)nt * (double)reps * 1e6 * CHAINS * 4 * 2
                                 : (double)reps * (double)n * 3 * sizeof(double);
      return work / dt / 1e9;
    }
    reps = dt < secs / 16 ? reps * 8 : (long)((double)reps * 1.2 * secs / dt) + 1;
  }
}

int main(int argc, char **argv) {
  const double secs = argc > 1 ? atof(argv[1]) : 1.0;
  if (!(secs > 0.0 && secs <= 60.0)) {
    fprintf(stderr, "bench_cores: seconds per test '%s' must be in (0, 60]\n", argv[1]);
    return 1;
  }
  int avx2 = 0;
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif
  const size_t n = (size_t)4 << 20; /* 32 MiB per array */
  double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
  if (!a || !b || !c) {
    fprintf(stderr, "bench_cores: cannot allocate 96 MiB\n");
    return 1;
  }
#pragma omp parallel for schedule(static) num_threads(2)
  for (size_t i = 0; i < n; ++i) a[i] = 0.0, b[i] = 1.0, c[i] = 2.0;
  printf("test     unit                 1 thread  2 threads  ratio\n");
  for (int t = 0; t < 2; ++t) {
    const double r1 = rate(t, 1, secs, avx2, a, b, c, n), r2 = rate(t, 2, secs, avx2, a, b, c, n);
    printf("%-8s %-20s %8.2f  %9.2f  %5.2f\n", t ? "triad" : "fma",
           t ? "GB/s" : avx2 ? "G flop/s (AVX2 FMA)" : "G flop/s (vectors)", r1, r2, r2 / r1);
  }
  free(a), free(b), free(c);
  return 0;
}
