// The window's device plots: each device its own ring, the oldest sample
// dropped when full, a frame drawn twice sampled once, |F| and mm.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "views/graphics/gui_series.h"

#include <math.h>

static void rings_scroll_and_hold_the_latest(void** state) {
  (void)state;
  static tx_series_set s;
  const double pos[3] = {0.001, -0.002, 0.003}, f[3] = {3, 0, 4};
  for (int k = 0; k < TX_SERIES_LEN + 10; k++) {
    double p[3] = {pos[0], (double)k * 1e-3, pos[2]};
    assert_true(tx_series_push(&s, "device0", k / 30.0, p, f));
  }
  assert_int_equal(s.count, 1);
  const tx_series* d = &s.dev[0];
  assert_int_equal(d->count, TX_SERIES_LEN);
  // full: the oldest held is sample 10, at the ring's offset
  assert_true(fabsf(d->pos[1][tx_series_offset(d)] - 10.0f) < 1e-4f);
  int last = (d->next + TX_SERIES_LEN - 1) % TX_SERIES_LEN;
  assert_true(fabsf(d->pos[1][last] - (float)(TX_SERIES_LEN + 9)) < 1e-3f);
  assert_true(d->force[last] == 5.0f); // |(3, 0, 4)|
  assert_true(d->has_force);
  // the same frame again (the screenshot at the end) is not a new sample
  assert_true(tx_series_push(&s, "device0", (TX_SERIES_LEN + 9) / 30.0, pos, f));
  assert_true(fabsf(d->pos[1][last] - (float)(TX_SERIES_LEN + 9)) < 1e-3f);
  // a device without a force read, then too many devices
  assert_true(tx_series_push(&s, "device1", 0, pos, NULL));
  assert_false(s.dev[1].has_force);
  assert_int_equal(s.dev[1].count, 1);
  assert_true(s.dev[1].pos[0][0] == 1.0f && s.dev[1].pos[2][0] == 3.0f); // mm
  assert_true(tx_series_push(&s, "device2", 0, pos, NULL));
  assert_true(tx_series_push(&s, "device3", 0, pos, NULL));
  assert_false(tx_series_push(&s, "device4", 0, pos, NULL));
  assert_int_equal(s.count, TX_SERIES_DEVICES);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(rings_scroll_and_hold_the_latest)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
