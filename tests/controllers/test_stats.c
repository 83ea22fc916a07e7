// Timing samples: nearest-rank percentiles, and the ring once full; the
// histogram against exact percentiles of the same samples.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/stats.h"

#include <math.h>
#include <stdlib.h>

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

static void histogram_is_exact_below_256_ns(void** state) {
  (void)state;
  static tx_hist h;
  tx_hist_clear(&h);
  tx_percentiles p = tx_hist_percentiles(&h);
  assert_true(p.p50 == 0 && p.p99 == 0 && p.max == 0); // empty
  for (int v = 100; v >= 1; v--) tx_hist_add(&h, v);
  p = tx_hist_percentiles(&h);
  assert_true(p.p50 == 50 && p.p99 == 99 && p.max == 100);
  tx_hist_add(&h, -5);        // clamped to 0
  tx_hist_add(&h, 1ll << 40); // saturated
  assert_true(tx_hist_percentiles(&h).max == 4294967295.0);
  assert_int_equal(h.count, 102);
}

// every decade from 1 us to 4 s: the histogram's percentiles lie within 1/256
// of the exact nearest-rank ones, and its maximum is exact
static void histogram_matches_exact_percentiles_within_0_4_percent(void** state) {
  (void)state;
  static tx_hist h;
  tx_samples s;
  const int n = 200000;
  assert_true(tx_samples_init(&s, n));
  srand(7);
  for (double scale = 1e3; scale <= 4e9; scale *= 10) {
    tx_hist_clear(&h);
    s.count = 0;
    for (int i = 0; i < n; i++) {
      double u = (double)rand() / RAND_MAX;
      int64_t v = (int64_t)(scale * (0.5 + u * u * 3)); // skewed, like step times
      if (v > (int64_t)UINT32_MAX) v = UINT32_MAX;
      tx_hist_add(&h, v);
      tx_samples_add(&s, v);
    }
    tx_percentiles a = tx_hist_percentiles(&h), b = tx_samples_percentiles(&s);
    assert_true(a.max == b.max);
    assert_true(fabs(a.p50 - b.p50) <= b.p50 / 256 + 1);
    assert_true(fabs(a.p99 - b.p99) <= b.p99 / 256 + 1);
  }
  tx_samples_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(percentiles_of_known_values),
      cmocka_unit_test(full_ring_keeps_the_newest),
      cmocka_unit_test(histogram_is_exact_below_256_ns),
      cmocka_unit_test(histogram_matches_exact_percentiles_within_0_4_percent),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
