// The stability cases (shortened): stiff springs, e = 1, tiny masses, the
// needle at 1 m/s and overlapping voxels. No NaN leaves the guard or stays in
// the block, the energy stays under its bound, and the guard's detections
// are counted consistently.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "studies/experiments/needle_stability.h"
#include "tactus/model.h"

#include <math.h>
#include <string.h>

static void every_case_stays_finite_and_bounded(void** state) {
  (void)state;
  const char* names[TX_NEEDLE_STABILITY_CASES] = {"baseline", "stiff", "elastic", "light", "fast", "overlap"};
  for (int k = 0; k < TX_NEEDLE_STABILITY_CASES; k++) {
    tx_needle_stability_result r;
    // 1.4 s: 0.1 s still, then 2.9 mm deep at 3 mm/s, past the puncture; the fast case runs whole
    assert_true(tx_needle_stability_run(k, 1.4, &r));
    assert_string_equal(r.name, names[k]);
    print_message("  %-9s %4d steps, energy %.3g of %.3g J, %llu recovered (%llu from NaN), %llu voxel faults, peak %.3f N, "
                  "%d substeps\n",
                  r.name, r.steps, r.energy_max, r.energy_bound, (unsigned long long)r.recoveries,
                  (unsigned long long)r.recovered_nan, (unsigned long long)r.voxel_faults, r.peak_force, r.max_substeps);
    assert_int_equal(r.nan_out, 0);
    assert_int_equal(r.nan_state, 0);
    assert_true(r.bounded && isfinite(r.energy_max) && r.energy_max <= r.energy_bound);
    assert_true(r.recovered_nan <= r.recoveries);
    assert_true(isfinite(r.peak_force));
    if (k == 4) assert_int_equal(r.steps, 211); // 1 m/s: 5 ms in, 5 ms out, 0.2 s still
    else assert_int_equal(r.steps, 1400);
    // a needle at 1 m/s crosses a voxel in a fraction of a frame: the frame is split
    if (k == 4) assert_true(r.max_substeps >= 20);
    if (k == 0 || k == 2 || k == 5) assert_true(r.peak_force > 0.05 && r.cuts > 0); // it did go in
  }
  tx_needle_stability_result r;
  assert_false(tx_needle_stability_run(TX_NEEDLE_STABILITY_CASES, 1, &r));
  assert_non_null(strstr(tx_error(), "no case"));
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(every_case_stays_finite_and_bounded)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
