// Timing samples: nearest-rank percentiles, and the ring once full.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/stats.h"

static void percentiles_of_known_values(void** state) {
  (void)state;
  tx_samples s;
  assert_true(tx_samples_init(&s, 1000));
  tx_percentiles p = tx_samples_percentiles(&s);
  assert_true(p.p50 == 0 && p.max == 0); // empty
  for (int v = 100; v >= 1; v--) tx_samples_add(&s, v);
  p = tx_samples_percentiles(&s);
  assert_true(p.p50 == 50);
  assert_true(p.p99 == 99);
  assert_true(p.max == 100);
  tx_samples_free(&s);
}

static void full_ring_keeps_the_newest(void** state) {
  (void)state;
  tx_samples s;
  assert_true(tx_samples_init(&s, 10));
  for (int v = 1; v <= 25; v++) tx_samples_add(&s, v * 1000);
  tx_percentiles p = tx_samples_percentiles(&s);
  assert_true(p.max == 25000);
  assert_true(p.p50 == 20000); // the last ten are 16..25 thousand
  tx_samples_add(&s, -5);          // clamped to 0
  tx_samples_add(&s, 1ll << 40);   // saturated
  assert_true(tx_samples_percentiles(&s).max == 4294967295.0);
  tx_samples_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(percentiles_of_known_values),
      cmocka_unit_test(full_ring_keeps_the_newest),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
