// Passivity observer and controller: energy bookkeeping, and a controller
// that never lets the observed energy go below zero.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/haptics/passivity.h"

#include <math.h>

// a damper (F = -b v) only absorbs energy: the observer sees E grow, the controller stays idle
static void a_damper_is_passive(void** state) {
  (void)state;
  tx_passivity p = {0};
  for (int k = 0; k < 1000; k++) {
    double v[3] = {sin(k * 0.01), 0.2, 0};
    double f[3] = {-2 * v[0], -2 * v[1], 0};
    assert_true(tx_passivity_tick(&p, f, v, 1e-3, true) == 0);
  }
  assert_true(p.energy > 0);
  assert_true(p.min_energy >= 0);
  assert_int_equal(p.activations, 0);
}

// a negative damper (F = +b v) generates energy: observed E < 0 without control
static void a_negative_damper_is_seen_and_corrected(void** state) {
  (void)state;
  tx_passivity off = {0}, on = {0};
  for (int k = 0; k < 1000; k++) {
    double v[3] = {cos(k * 0.02), -0.1, 0.05};
    double f_off[3] = {3 * v[0], 3 * v[1], 3 * v[2]};
    double f_on[3] = {3 * v[0], 3 * v[1], 3 * v[2]};
    tx_passivity_tick(&off, f_off, v, 1e-3, false);
    tx_passivity_tick(&on, f_on, v, 1e-3, true);
    assert_true(on.energy >= -1e-12); // held at zero, every tick
  }
  assert_true(off.energy < -1.0);
  assert_true(on.activations > 900);
  assert_true(fabs(on.dissipated + off.energy) < 1e-9 * fabs(off.energy) + 1e-9);
}

// with no motion no energy flows and nothing is added
static void no_motion_no_energy(void** state) {
  (void)state;
  tx_passivity p = {.energy = -1};
  double f[3] = {1, 2, 3}, v[3] = {0, 0, 0};
  assert_true(tx_passivity_tick(&p, f, v, 1e-3, true) == 0);
  assert_true(f[0] == 1 && f[1] == 2 && f[2] == 3);
  assert_true(p.energy == -1);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_damper_is_passive),
      cmocka_unit_test(a_negative_damper_is_seen_and_corrected),
      cmocka_unit_test(no_motion_no_energy),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
