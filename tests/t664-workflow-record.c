/* The workflow's checkpoint record (workflows/record.c): every field survives the text form
 * to the bit (a resumed run must take the same steps), and a record with an unknown or
 * malformed line, or without its header, scene or stage, is refused with a message naming
 * the line, not half read. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "wf.h"

static void test_round_trip(void **state) {
  (void)state;
  char *sets[] = {"grid.cell_size=0.5", "stages.runout.end.time=2"};
  int walls[] = {3, -1, 7};
  wf_stage_record done[2] = {{.sim_time = 0.61562639100000004, .steps = 1831, .wall_seconds = 0.278,
                              .reason = "quasi_static", .strength = 0.5},
                             {.sim_time = 0, .steps = 0, .wall_seconds = 4.4, .reason = "fos", .strength = 1.375}};
  wf_record r = {.stage = 2, .setup = 1, .steps = 123456789012L, .ke_below = 0.1 / 3, .strength = 1.375,
                 .clock = {.t_stage = 1.0 / 3, .dt = 2.5e-4 / 7, .ke = 1e-300, .ke_max = 12.5, .ratio = 3.141592653589793,
                           .next_series = 0.1 * 3, .next_snap = nextafter(1.0, 2.0)},
                 .nset = 2, .sets = sets, .nwall = 3, .walls = walls, .ndone = 2, .done = done};
  snprintf(r.scene, sizeof r.scene, "/a b/scene with spaces.yaml");
  char text[4096], msg[256] = "";
  assert_int_equal(wf_record_format(&r, text, sizeof text), 0);
  wf_record q;
  assert_int_equal(wf_record_parse(text, &q, msg, sizeof msg), 0);
  assert_string_equal(q.scene, r.scene);
  assert_int_equal(q.stage, 2);
  assert_int_equal(q.setup, 1);
  assert_true(q.steps == r.steps);
  assert_memory_equal(&q.clock, &r.clock, sizeof r.clock);
  assert_true(q.ke_below == r.ke_below && q.strength == r.strength);
  assert_int_equal(q.nset, 2);
  assert_string_equal(q.sets[1], sets[1]);
  assert_int_equal(q.nwall, 3);
  assert_memory_equal(q.walls, walls, sizeof walls);
  assert_int_equal(q.ndone, 2);
  assert_true(q.done[0].sim_time == done[0].sim_time && q.done[1].strength == 1.375);
  assert_string_equal(q.done[0].reason, "quasi_static");
  assert_string_equal(q.done[1].reason, "fos");
  assert_int_equal(wf_record_add_set(&q, "threads=1"), 0);
  assert_int_equal(q.nset, 3);
  wf_record_free(&q);
  assert_int_equal(wf_record_format(&r, text, 64), -1); /* too long: refused, not cut */
}

static void expect_refused(const char *text, const char *says) {
  wf_record q;
  char msg[256] = "";
  assert_int_equal(wf_record_parse(text, &q, msg, sizeof msg), MPMC_ERR_FORMAT);
  if (!strstr(msg, says)) fail_msg("expected \"%s\" in \"%s\"", says, msg);
  wf_record_free(&q);
}

static void test_refused(void **state) {
  (void)state;
  expect_refused(NULL, "no workflow record");
  expect_refused("mpmc-workflow 2\nscene s\nstage 0\n", "no workflow record");
  expect_refused("mpmc-workflow 1\nscene s\n", "no scene or stage");
  expect_refused("mpmc-workflow 1\nscene s\nstage 0\ncolour blue\n", "line 4: 'colour blue'");
  expect_refused("mpmc-workflow 1\nscene s\nstage x\n", "line 3: 'stage x'");
  expect_refused("mpmc-workflow 1\nscene s\nstage 0\ndone 1 2 3 melted 1\n", "line 4");
  expect_refused("mpmc-workflow 1\nscene s\nstage 0\nwall 3x\n", "line 4: 'wall 3x'");
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_round_trip), cmocka_unit_test(test_refused)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
