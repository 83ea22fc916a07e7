// The HIP's ray sets: 26 and 98 unit directions, symmetric, 45 and 22.5
// degrees apart on average in each axis plane (the journal paper's counts).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/collision/hip_rays.h"

#include <math.h>

static void check_set(int count, double step_deg) {
  double d[TX_HIP_RAYS_MAX][3];
  assert_int_equal(tx_hip_rays(count, d), count);
  // unit length, and -d in the set for every d
  for (int i = 0; i < count; i++) {
    assert_true(fabs(d[i][0] * d[i][0] + d[i][1] * d[i][1] + d[i][2] * d[i][2] - 1) < 1e-12);
    int opposite = 0;
    for (int j = 0; j < count; j++)
      if (fabs(d[i][0] + d[j][0]) + fabs(d[i][1] + d[j][1]) + fabs(d[i][2] + d[j][2]) < 1e-12) opposite++;
    assert_int_equal(opposite, 1);
    for (int j = 0; j < i; j++) // no two alike
      assert_true(fabs(d[i][0] - d[j][0]) + fabs(d[i][1] - d[j][1]) + fabs(d[i][2] - d[j][2]) > 1e-6);
  }
  // the rays in the x-y plane go round it in equal mean steps of step_deg
  int in_plane = 0;
  for (int i = 0; i < count; i++)
    if (fabs(d[i][2]) < 1e-12) in_plane++;
  assert_int_equal(in_plane, (int)lround(360.0 / step_deg));
}

static void test_26_rays_45_degrees(void** state) {
  (void)state;
  check_set(26, 45.0);
}

static void test_98_rays_22_5_degrees(void** state) {
  (void)state;
  check_set(98, 22.5);
}

static void test_other_counts_rejected(void** state) {
  (void)state;
  double d[TX_HIP_RAYS_MAX][3];
  assert_int_equal(tx_hip_rays(27, d), 0);
  assert_int_equal(tx_hip_rays(0, d), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_26_rays_45_degrees),
      cmocka_unit_test(test_98_rays_22_5_degrees),
      cmocka_unit_test(test_other_counts_rejected),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
