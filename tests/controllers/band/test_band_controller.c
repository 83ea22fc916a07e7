// physics.band through the loader, in lockstep: it publishes band.x/.tri
// (the two parts' nodes and their boundary faces: closed, outward) and band.state at rest;
// a substep far past the stable one faults, and the fault is counted and
// recovered, never published; bad parameters and assets are refused with one
// line naming the key and the file.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static tx_scenario* load(const char* params) {
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":[{\"name\":\"band\",\"type\":\"physics.band\",\"rate_hz\":60,\"params\":{%s}}]}",
           params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static int cmp_long(const void* a, const void* b) {
  long p = *(const long*)a, q = *(const long*)b;
  return (p > q) - (p < q);
}

static bool all_finite(tx_snapshot x) {
  const float* p = x.data;
  for (uint32_t i = 0; i < 3 * x.rows; i++)
    if (!isfinite(p[i])) return false;
  return true;
}

static void publishes_the_band(void** state) {
  (void)state;
  tx_scenario* s = load("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.1);
  tx_snapshot x = latest_snapshot(s, "band.x"), t = latest_snapshot(s, "band.tri");
  assert_int_equal(x.rows, 150 + 164); // the ring's nodes, then the tube's
  assert_true(all_finite(x));
  // every face's nodes in range, and the surface closed: each edge in two faces, run both ways
  const int32_t* f = t.data;
  for (uint32_t i = 0; i < 3 * t.rows; i++) assert_true(f[i] >= 0 && f[i] < (int32_t)x.rows);
  long* e = malloc(sizeof(long) * 3 * t.rows);
  assert_non_null(e);
  for (uint32_t i = 0; i < t.rows; i++)
    for (int k = 0; k < 3; k++) e[3 * i + k] = (long)f[3 * i + k] * x.rows + f[3 * i + (k + 1) % 3];
  qsort(e, 3 * t.rows, sizeof(long), cmp_long);
  for (uint32_t i = 0; i < 3 * t.rows; i++) {
    long a = e[i] / x.rows, b = e[i] % x.rows, back = b * x.rows + a;
    assert_true(i == 0 || e[i] != e[i - 1]);                                  // no edge run twice the same way
    assert_non_null(bsearch(&back, e, 3 * t.rows, sizeof(long), cmp_long)); // and each run back by its neighbour
  }
  free(e);
  // the boundary's signed volume: the two parts' (5.17 and 1.35 cm^3), positive (outward)
  const float* p = x.data;
  double vol = 0;
  for (uint32_t i = 0; i < t.rows; i++) {
    const float *a = p + 3 * f[3 * i], *b = p + 3 * f[3 * i + 1], *c = p + 3 * f[3 * i + 2];
    vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
  }
  print_message("  band.x %u rows, band.tri %u rows, volume %.4g cm^3\n", x.rows, t.rows, vol * 1e6);
  assert_true(fabs(vol * 1e6 - 6.52) < 0.05);
  const tx_band_state* st = latest_snapshot(s, "band.state").data;
  assert_true(st->locked == 0);
  assert_true(fabs(st->joint_length - 0.003) < 3e-5 && fabs(st->joint_error) < 0.01);
  assert_true(st->tip_to_buckle > 0.05);
  assert_true(result(s, "band.substeps") == 667);
  assert_true(result(s, "band.faults") == 0);
  tx_scenario_free(s);
}

static void fault_is_recovered(void** state) {
  (void)state;
  tx_scenario* s = load("\"max_substep_s\":0.0002");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.1);
  assert_true(warnings(s, "band.numerical_fault") > 0);
  assert_true(result(s, "band.faults") > 0);
  assert_true(all_finite(latest_snapshot(s, "band.x")));
  tx_scenario_free(s);
}

static void expect_refused(const char* params, const char* needle) { assert_refused(load(params), needle); }

static void bad_parameters_and_assets(void** state) {
  (void)state;
  expect_refused("\"tube_poisson\":0.5", "tube_poisson");
  expect_refused("\"buckle_radius_m\":0", "buckle_radius_m");
  expect_refused("\"assets\":\"/nonexistent/lagb\"", "/nonexistent/lagb/band_ring.node");
  expect_refused("\"pull\":\"nothing.here\"", "nothing.here");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(publishes_the_band),
      cmocka_unit_test(fault_is_recovered),
      cmocka_unit_test(bad_parameters_and_assets),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
