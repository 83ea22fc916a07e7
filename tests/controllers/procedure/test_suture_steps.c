// The steps A-H of a simple interrupted suture as a state machine
// (controllers/procedure/suture_steps.h): a whole suture in order; one that
// cuts after the first knot (F skipped); the rules that must not fire (an
// exit on the same edge, a knot before any stitch, a tail still long, a
// wrap short of a turn, hands still holding after the cut).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/procedure/suture_steps.h"

#include <math.h>
#include <string.h>

static void expect_status(const tx_suture_steps* s, const char* want) {
  for (int i = 0; i < TX_SUTURE_STEPS; i++) {
    int st = (int)s->step[i].status;
    char c = st == TX_STEP_DONE ? 'd' : st == TX_STEP_SKIPPED ? 's' : st == TX_STEP_UNDER_WAY ? 'u' : '.';
    if (c != want[i]) fail_msg("step %s: '%c', expected '%c' (%s)", tx_suture_step_id(i), c, want[i], want);
  }
}

static void a_whole_suture(void** state) {
  (void)state;
  tx_suture_steps s;
  tx_suture_rules r = tx_suture_rules_default();
  tx_suture_steps_start(&s, &r, 0);
  expect_status(&s, "u.......");
  assert_false(tx_suture_steps_knot(&s, 0.5, 1, false)); // a knot in a loose thread before any stitch
  assert_false(tx_suture_steps_puncture(&s, 1.0, +1, +1)); // entered left of the wound
  assert_false(tx_suture_steps_puncture(&s, 1.5, -1, +1)); // came out on the same edge: not through both
  assert_false(tx_suture_steps_puncture(&s, 1.8, +1, -1)); // in again, on the far edge
  assert_true(tx_suture_steps_puncture(&s, 2.0, -1, -1));  // out on the far edge: through both
  expect_status(&s, "du......");
  assert_true(s.step[TX_SUTURE_A].t_start_s == 0 && s.step[TX_SUTURE_A].t_end_s == 2.0);
  assert_true(s.step[TX_SUTURE_B].t_start_s == 2.0 && isnan(s.step[TX_SUTURE_B].t_end_s));
  assert_false(tx_suture_steps_tail(&s, 3, 0.05, true)); // 5 cm left: still pulling
  assert_false(tx_suture_steps_tail(&s, 3.5, 0.02, false)); // short, but not through the wound
  assert_false(tx_suture_steps_wrap(&s, 3, 2));    // C is not under way: a wrap now means nothing
  assert_true(tx_suture_steps_tail(&s, 4, 0.025, true));
  assert_false(tx_suture_steps_wrap(&s, 5, 0.6));  // part of a turn
  assert_true(tx_suture_steps_wrap(&s, 6, -1.1));  // a turn, either way round
  assert_true(tx_suture_steps_knot(&s, 7, 1, false));
  expect_status(&s, "ddddu...");
  assert_false(tx_suture_steps_knot(&s, 7.5, 1, false)); // the same knot again
  assert_true(tx_suture_steps_knot(&s, 8, 1, true));     // fixed at the skin
  assert_true(tx_suture_steps_knot(&s, 9, 2, false));    // the second throw
  assert_false(tx_suture_steps_hands_free(&s, 9.5));     // G is under way, not H
  assert_true(tx_suture_steps_cut(&s, 10));
  expect_status(&s, "dddddddu");
  assert_true(tx_suture_steps_hands_free(&s, 11));
  expect_status(&s, "dddddddd");
  assert_int_equal(s.current, TX_SUTURE_STEPS);
  assert_int_equal(tx_suture_steps_done(&s), 8);
  for (int i = 0; i + 1 < TX_SUTURE_STEPS; i++) assert_true(s.step[i].t_end_s <= s.step[i + 1].t_start_s);
  assert_false(tx_suture_steps_cut(&s, 12)); // all over: nothing moves
}

// the script that skips the second throw: cut after the first knot is fixed
static void cut_after_the_first_knot_skips_f(void** state) {
  (void)state;
  tx_suture_steps s;
  tx_suture_steps_start(&s, NULL, 0);
  tx_suture_steps_puncture(&s, 1, +1, -1);
  tx_suture_steps_puncture(&s, 2, -1, +1);
  tx_suture_steps_tail(&s, 3, 0.01, true);
  assert_true(tx_suture_steps_knot(&s, 4, 1, true)); // found and fixed at once: C skipped, D and E done
  expect_status(&s, "ddsddu..");
  assert_true(tx_suture_steps_cut(&s, 5));
  expect_status(&s, "ddsddsdu");
  assert_true(s.step[TX_SUTURE_F].t_start_s == 4 && s.step[TX_SUTURE_F].t_end_s == 5);
  assert_int_equal(tx_suture_steps_done(&s), 5);
}

// a cut before any stitch is nothing; a run that ends mid-way leaves the rest unreached
static void early_events(void** state) {
  (void)state;
  tx_suture_steps s;
  tx_suture_rules r = {.tail_m = 0.02, .wrap_turns = 2};
  tx_suture_steps_start(&s, &r, 0.5);
  assert_false(tx_suture_steps_cut(&s, 1));
  assert_false(tx_suture_steps_puncture(&s, 1, -1, -1)); // an exit with no entry
  assert_false(tx_suture_steps_puncture(&s, 1, +1, 0));  // on no edge
  tx_suture_steps_puncture(&s, 2, +1, +1);
  tx_suture_steps_puncture(&s, 3, -1, -1);
  assert_false(tx_suture_steps_tail(&s, 4, 0.025, true)); // this run's rule: 2 cm
  assert_true(tx_suture_steps_tail(&s, 4, 0.02, true));
  assert_false(tx_suture_steps_wrap(&s, 5, 1.5));   // two turns asked
  expect_status(&s, "ddu.....");
  assert_true(s.step[TX_SUTURE_A].t_start_s == 0.5);
  assert_true(isnan(s.step[TX_SUTURE_D].t_start_s));
  assert_string_equal(tx_suture_step_id(TX_SUTURE_H), "H");
  assert_string_equal(tx_suture_step_name(TX_SUTURE_G), "cut the thread");
  assert_string_equal(tx_suture_step_id(8), "?");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_whole_suture),
      cmocka_unit_test(cut_after_the_first_knot_skips_f),
      cmocka_unit_test(early_events),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
