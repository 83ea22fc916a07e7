// tx_hist: nearest-rank percentiles, exact below 256, and within 1/256 of
// the exact ones (by sorting the same samples) above.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/stats.h>

#include <math.h>
#include <stdlib.h>

static int cmp_i64(const void* a, const void* b) {
  int64_t x = *(const int64_t*)a, y = *(const int64_t*)b;
  return (x > y) - (x < y);
}

// the exact nearest-rank percentile of n sorted values: the smallest with q n at or below it
static double exact_rank(const int64_t* sorted, size_t n, double q) {
  size_t k = (size_t)ceil(q * (double)n);
  return (double)sorted[(k < 1 ? 1 : k) - 1];
}

static void histogram_is_exact_below_256(void** state) {
  (void)state;
  static tx_hist h;
  tx_hist_clear(&h);
  tx_percentiles p = tx_hist_percentiles(&h);
  assert_true(p.p50 == 0 && p.p99 == 0 && p.max == 0); // empty
  for (int v = 100; v >= 1; v--) tx_hist_add(&h, v);
  p = tx_hist_percentiles(&h);
  assert_true(p.p50 == 50 && p.p99 == 99 && p.max == 100);
  assert_true(tx_hist_percentile(&h, 0) == 1 && tx_hist_percentile(&h, 1) == 100);
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
  enum { N = 200000 };
  int64_t* v = malloc(N * sizeof *v);
  assert_non_null(v);
  srand(7);
  for (double scale = 1e3; scale <= 4e9; scale *= 10) {
    tx_hist_clear(&h);
    for (int i = 0; i < N; i++) {
      double u = (double)rand() / RAND_MAX;
      v[i] = (int64_t)(scale * (0.5 + u * u * 3)); // skewed, like step times
      if (v[i] > (int64_t)UINT32_MAX) v[i] = UINT32_MAX;
      tx_hist_add(&h, v[i]);
    }
    qsort(v, N, sizeof *v, cmp_i64);
    tx_percentiles a = tx_hist_percentiles(&h);
    assert_true(a.max == (double)v[N - 1]);
    for (double q = 0.01; q < 1; q += 0.07) {
      double e = exact_rank(v, N, q);
      assert_true(fabs(tx_hist_percentile(&h, q) - e) <= e / 256 + 1);
    }
    assert_true(fabs(a.p50 - exact_rank(v, N, 0.5)) <= exact_rank(v, N, 0.5) / 256 + 1);
    assert_true(fabs(a.p99 - exact_rank(v, N, 0.99)) <= exact_rank(v, N, 0.99) / 256 + 1);
  }
  free(v);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(histogram_is_exact_below_256),
      cmocka_unit_test(histogram_matches_exact_percentiles_within_0_4_percent),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
