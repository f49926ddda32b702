/* Checkpoints carry a checksum (FNV-1a 64 over every dataset and attribute, the root
 * attribute checksum_fnv1a64) verified on reading (issue 44): a bit flipped in the particle
 * positions (raw data HDF5 does not check) or in the time (an attribute of /config) is
 * refused with MPMC_ERR_FORMAT and a message naming the file, where it used to load
 * silently.  The untouched file still reads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "test_util.h"

#define CK MPMC_BINARY_DIR "/t663.ck"
#define BAD MPMC_BINARY_DIR "/t663-flipped.ck"

static mpmc_context ctx;

/* The file's bytes in buf (malloc'ed), their number in *n. */
static unsigned char *read_all(const char *path, size_t *n) {
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  const long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *buf = malloc((size_t)len + 1);
  assert_non_null(buf);
  assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
  fclose(f);
  *n = (size_t)len;
  return buf;
}

/* Copy CK to BAD with one bit flipped in the single place `pat` (plen bytes) stands. */
static void flip_in(const void *pat, size_t plen, const char *what) {
  size_t n;
  unsigned char *buf = read_all(CK, &n), *at = NULL;
  int hits = 0;
  for (size_t i = 0; i + plen <= n; ++i)
    if (!memcmp(buf + i, pat, plen)) at = buf + i, ++hits;
  if (hits != 1) fail_msg("%s: expected its bytes once in %s, found them %d times", what, CK, hits);
  at[plen - 2] ^= 0x10; /* a bit of the exponent's neighbour: the value stays finite */
  FILE *f = fopen(BAD, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(buf, 1, n, f), n);
  fclose(f);
  free(buf);
}

static void expect_refused(const char *what) {
  mpmc_sim back = NULL;
  char *meta = NULL;
  const int e = mpmc_sim_checkpoint_read(ctx, BAD, &back, &meta);
  if (e == 0) {
    mpmc_sim_destroy(&back);
    mpmc_free(meta);
    fail_msg("%s: a checkpoint with a flipped bit loaded without an error", what);
  }
  assert_null(back);
  const char *msg = mpmc_context_last_error(ctx);
  if (e != MPMC_ERR_FORMAT || !strstr(msg, BAD) || !strstr(msg, "checksum"))
    fail_msg("%s: expected MPMC_ERR_FORMAT and a message naming %s and its checksum, got %d: %s", what, BAD, e,
             msg);
}

static void test_flipped_bits(void **state) {
  (void)state;
  TCALL(mpmc_context_create(&ctx));
  test_ctx = ctx;
  mpmc_sim sim;
  TCALL(mpmc_sim_create(ctx, 2, &sim));
  const double lo[2] = {0, 0}, hi[2] = {2, 2}, g[2] = {0.1, -9.81}, b0[2] = {0.5, 0}, b1[2] = {1.5, 1};
  int m;
  TCALL(mpmc_sim_set_grid(sim, lo, hi, 0.25));
  TCALL(mpmc_sim_set_gravity(sim, g));
  TCALL(mpmc_sim_add_material_hencky(sim, 1e6, 0.3, 1000, &m));
  TCALL(mpmc_sim_seed_box(sim, b0, b1, 2, m, NULL, NULL));
  TCALL(mpmc_sim_add_wall_face(sim, 2, MPMC_WALL_FIXED, NULL));
  for (int s = 0; s < 7; ++s) TCALL(mpmc_sim_step(sim, 1.234e-4));
  TCALL(mpmc_sim_checkpoint_write(sim, CK, "meta"));
  /* the whole file reads */
  mpmc_sim back = NULL;
  TCALL(mpmc_sim_checkpoint_read(ctx, CK, &back, NULL));
  mpmc_sim_destroy(&back);
  /* the first three coordinates of /particles/x (raw data) */
  double *x;
  TCALL(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, &x, NULL));
  flip_in(x, 3 * sizeof(double), "/particles/x");
  TCALL(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, &x));
  expect_refused("a bit flipped in /particles/x");
  /* the time, an attribute of /config */
  double t;
  TCALL(mpmc_sim_get_time(sim, &t));
  flip_in(&t, sizeof t, "the time attribute");
  expect_refused("a bit flipped in /config's time");
  mpmc_sim_destroy(&sim);
  test_ctx = NULL;
  mpmc_context_destroy(&ctx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_flipped_bits),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
