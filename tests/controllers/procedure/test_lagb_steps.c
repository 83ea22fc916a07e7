// Phases 2 and 3 of gastric banding as steps
// (controllers/procedure/lagb_steps.h): a whole procedure in order, with
// the two windows in either order; a band locked with no dissection (the
// steps before it skipped); and the band's loop against the stomach's axis,
// whose linking number is known in closed form for a circle round a line
// (1, its sign by the direction), beside it (0) and wound twice (2).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/procedure/lagb_steps.h"

#include <math.h>

static void expect_status(const tx_lagb_steps* s, const char* want) {
  for (int i = 0; i < TX_LAGB_STEPS; i++) {
    int st = (int)s->step[i].status;
    char c = st == TX_STEP_DONE ? 'd' : st == TX_STEP_SKIPPED ? 's' : st == TX_STEP_UNDER_WAY ? 'u' : '.';
    if (c != want[i]) fail_msg("step %s: '%c', expected '%c' (%s)", tx_lagb_step_id(i), c, want[i], want);
  }
}

static void a_whole_procedure(void** state) {
  (void)state;
  tx_lagb_steps s;
  tx_lagb_steps_start(&s, 0);
  expect_status(&s, "u.....");
  assert_int_equal(tx_lagb_steps_current(&s), TX_LAGB_RETRACT);
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_RETRACT, 2));
  expect_status(&s, "duu...");  // both windows begin with the liver up
  assert_true(s.step[TX_LAGB_HIS].t_start_s == 2 && s.step[TX_LAGB_PARS].t_start_s == 2);
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_HIS, 5)); // His first: the pars flaccida still under way
  expect_status(&s, "dud...");
  assert_false(tx_lagb_steps_done_at(&s, TX_LAGB_HIS, 6)); // already done: nothing changes
  assert_true(s.step[TX_LAGB_HIS].t_end_s == 5);
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_PARS, 7));
  expect_status(&s, "dddu..");
  assert_true(s.step[TX_LAGB_BEHIND].t_start_s == 7);
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_BEHIND, 9));
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_AROUND, 12));
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_LOCK, 13));
  expect_status(&s, "dddddd");
  assert_int_equal(tx_lagb_steps_done(&s), TX_LAGB_STEPS);
  assert_int_equal(tx_lagb_steps_current(&s), TX_LAGB_STEPS);
}

static void locked_with_no_dissection(void** state) {
  (void)state;
  tx_lagb_steps s;
  tx_lagb_steps_start(&s, 0);
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_RETRACT, 1));
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_LOCK, 4)); // everything it comes after, skipped
  expect_status(&s, "dssssd");
  assert_int_equal(tx_lagb_steps_done(&s), 2);
  tx_lagb_steps_start(&s, 0); // the same with nothing done first
  assert_true(tx_lagb_steps_done_at(&s, TX_LAGB_LOCK, 4));
  assert_int_equal((int)s.step[TX_LAGB_LOCK].status, TX_STEP_DONE);
  for (int i = 0; i < TX_LAGB_LOCK; i++) {
    assert_int_equal((int)s.step[i].status, TX_STEP_SKIPPED);
    assert_true(s.step[i].t_end_s == 4);
  }
  assert_int_equal(tx_lagb_steps_done(&s), 1);
  assert_false(tx_lagb_steps_done_at(&s, TX_LAGB_PARS, 5)); // skipped steps stay so
}

// a circle of radius r about (cx, cy) in the plane z = h, n points, turned
// `turns` times (negative: clockwise)
static void circle(float* p, int n, double cx, double cy, double r, double h, double turns) {
  for (int i = 0; i < n; i++) {
    double a = 2 * M_PI * turns * i / n;
    p[3 * i] = (float)(cx + r * cos(a)), p[3 * i + 1] = (float)(cy + r * sin(a)), p[3 * i + 2] = (float)h;
  }
}

static void linking_numbers(void** state) {
  (void)state;
  enum { N = 64 };
  float loop[3 * 2 * N];
  // the axis: a bent polyline along -z through the origin, ends far outside
  const double axis[] = {0.001, 0, 0.2, 0, 0, 0.05, 0, 0.002, -0.05, 0.01, 0, -0.2};
  circle(loop, N, 0, 0, 0.02, 0.0, 1);
  assert_int_equal(tx_lagb_linking(loop, N, axis, 4), -1); // counter-clockwise seen from +z, the axis going down
  circle(loop, N, 0.0041, 0.0029, 0.02, 0.05, -1);         // round a joint of the polyline: counted once
  assert_int_equal(tx_lagb_linking(loop, N, axis, 4), 1);
  circle(loop, N, 0.05, 0, 0.02, 0.0, 1); // beside the axis
  assert_int_equal(tx_lagb_linking(loop, N, axis, 4), 0);
  circle(loop, 2 * N, 0, 0, 0.02, 0.0, 2); // wound twice round it
  assert_int_equal(tx_lagb_linking(loop, 2 * N, axis, 4), -2);
  assert_int_equal(tx_lagb_linking(loop, 2, axis, 4), 0); // too few points
  // along the axis: the arc length to the nearest point, and the distance from it
  const double bent[] = {0, 0, 0.2, 0, 0, 0, 0, 0.1, 0}; // down z, then along y
  double off, s = tx_lagb_along(bent, 3, (const double[3]){0.03, 0.05, 0}, &off);
  assert_true(fabs(s - 0.25) < 1e-12 && fabs(off - 0.03) < 1e-12);
  s = tx_lagb_along(bent, 3, (const double[3]){0, -0.01, 0.1}, &off);
  assert_true(fabs(s - 0.1) < 1e-12 && fabs(off - 0.01) < 1e-12);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_whole_procedure),
      cmocka_unit_test(locked_with_no_dissection),
      cmocka_unit_test(linking_numbers),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
