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

// the observer alone sums what it is given, and skips a non-finite period
static void the_observer_sums_what_was_sent(void** state) {
  (void)state;
  tx_passivity p = {0};
  const double f[3] = {1, -2, 0.5}, v[3] = {0.1, 0.2, -0.4};
  tx_passivity_observe(&p, f, v, 1e-3);
  assert_true(fabs(p.energy - (-(0.1 - 0.4 - 0.2) * 1e-3)) < 1e-18);
  double e = p.energy;
  const double bad[3] = {NAN, 0, 0};
  tx_passivity_observe(&p, bad, v, 1e-3);
  tx_passivity_observe(&p, f, bad, 1e-3);
  assert_true(p.energy == e);
}

// a negative damper with the controller in the loop: the observer sees the
// force sent, damping included, so the energy it reports is the port's own;
// each shortfall is paid back the next period, within one period's gain
static void the_controller_pays_back_what_it_observed(void** state) {
  (void)state;
  tx_passivity p = {0};
  double sent[3] = {0, 0, 0}, worst_tick = 0;
  for (int k = 0; k < 1000; k++) {
    double v[3] = {0.2 + 0.01 * sin(k * 0.02), -0.1, 0.05};
    double gain = -(sent[0] * v[0] + sent[1] * v[1] + sent[2] * v[2]) * 1e-3;
    worst_tick = fmin(worst_tick, gain);
    tx_passivity_observe(&p, sent, v, 1e-3); // what was held over the period just measured
    double a = tx_passivity_damping(&p, v, 1e-3, 100);
    for (int i = 0; i < 3; i++) sent[i] = 3 * v[i] - a * v[i];
  }
  print_message("  energy %.3g J, lowest %.3g J, worst environment tick %.3g J\n", p.energy, p.min_energy, worst_tick);
  assert_true(p.activations > 900);
  assert_true(p.min_energy >= -3 * 0.3 * 0.3 * 1e-3 * 1.1); // one period of the negative damper at most
  assert_true(p.energy > -1e-3);
}

// the damping force never asks more than the clamp could send
static void the_damping_is_bounded_by_the_force_limit(void** state) {
  (void)state;
  tx_passivity p = {.energy = -10};
  double v[3] = {0.01, 0, 0};
  double a = tx_passivity_damping(&p, v, 1e-3, 3.3);
  assert_true(a > 0 && fabs(a * 0.01 - 3.3) < 1e-12);
  p.energy = 1;
  assert_true(tx_passivity_damping(&p, v, 1e-3, 3.3) == 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_damper_is_passive),
      cmocka_unit_test(a_negative_damper_is_seen_and_corrected),
      cmocka_unit_test(no_motion_no_energy),
      cmocka_unit_test(the_observer_sums_what_was_sent),
      cmocka_unit_test(the_controller_pays_back_what_it_observed),
      cmocka_unit_test(the_damping_is_bounded_by_the_force_limit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
