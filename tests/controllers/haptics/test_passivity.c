// Passivity observer and controller: energy bookkeeping, a controller that
// pays back what the observer saw, the spring's store, and one tick's force path.
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
    tx_passivity_observe(&p, f, v, 1e-3);
    assert_true(tx_passivity_damping(&p, v, 1e-3, 100) == 0);
  }
  assert_true(p.energy > 0);
  assert_true(p.min_energy >= 0);
  assert_int_equal(p.activations, 0);
}

// a negative damper (F = +b v) generates energy: observed E < 0, and the controller asks damping
static void a_negative_damper_is_seen(void** state) {
  (void)state;
  tx_passivity p = {0};
  double v[3] = {0.3, -0.1, 0.05}, f[3] = {0.9, -0.3, 0.15};
  for (int k = 0; k < 1000; k++) tx_passivity_observe(&p, f, v, 1e-3);
  assert_true(fabs(p.energy + 3 * 0.1025 * 1.0) < 1e-9); // -3 |v|^2 over 1 s
  assert_true(p.min_energy == p.energy);
  double a = tx_passivity_damping(&p, v, 1e-3, 1e6);
  assert_true(fabs(a * 0.1025 * 1e-3 + p.energy) < 1e-12); // a |v|^2 dt pays E back
  assert_int_equal(p.activations, 1);
}

// with no motion no energy flows and nothing is added
static void no_motion_no_energy(void** state) {
  (void)state;
  tx_passivity p = {.energy = -1};
  double f[3] = {1, 2, 3}, v[3] = {0, 0, 0};
  tx_passivity_observe(&p, f, v, 1e-3);
  assert_true(tx_passivity_damping(&p, v, 1e-3, 100) == 0);
  assert_true(p.energy == -1);
}

// the spring's store from the force it pushes with: K d^2 / 2 for a wall
// -K n n^T at depth d, whatever its normal; nothing for a direction that does
// not restore, nor for broken input
static void a_spring_holds_what_its_force_says(void** state) {
  (void)state;
  double n[3] = {0.48, -0.6, 0.64}, K = 800, d = 0.004; // |n| = 1
  double k[9], f[3];
  for (int i = 0; i < 3; i++) {
    f[i] = K * d * n[i];
    for (int j = 0; j < 3; j++) k[3 * i + j] = -K * n[i] * n[j];
  }
  assert_true(fabs(tx_spring_energy(k, f) - 0.5 * K * d * d) < 1e-12 * K * d * d);
  // an isotropic spring (a coupling): |f|^2 / (2 K)
  double iso[9] = {-K, 0, 0, 0, -K, 0, 0, 0, -K}, g[3] = {1, -2, 0.5};
  assert_true(fabs(tx_spring_energy(iso, g) - 5.25 / (2 * K)) < 1e-12);
  // an anisotropic, off-diagonal one: f^T S^-1 f / 2, S^-1 of [[2,1],[1,2]] is [[2,-1],[-1,2]]/3
  double aniso[9] = {-2, -1, 0, -1, -2, 0, 0, 0, 0}, h[3] = {1, 0, 7};
  assert_true(fabs(tx_spring_energy(aniso, h) - 0.5 * 2.0 / 3) < 1e-12); // z is no spring: 7 N there hold nothing
  double active[9] = {K, 0, 0, 0, 0, 0, 0, 0, 0}, zero[9] = {0};
  assert_true(tx_spring_energy(active, g) == 0);
  assert_true(tx_spring_energy(zero, g) == 0);
  double bad[3] = {NAN, 0, 0};
  assert_true(tx_spring_energy(k, bad) == 0);
  k[4] = INFINITY;
  assert_true(tx_spring_energy(k, f) == 0);
}

static tx_safety_limits limits(void) {
  tx_device_info info = {.max_force = 3.3, .workspace_min = {-1, -1, -1}, .workspace_max = {1, 1, 1}};
  return tx_safety_limits_from_device(&info);
}

// one tick of the path: the observer sees last tick's sent force over this
// period; the spring reference takes the spring's store off and counts what
// the device's damping absorbed; the safety
// chain clamps what leaves, and that is what the next tick observes
static void the_tick_observes_what_it_sent(void** state) {
  (void)state;
  tx_safety_limits l = limits();
  tx_haptic_path p;
  tx_haptic_path_init(&p, &l, false, TX_PASSIVITY_REF_SPRING, 0.5);
  const double pos[3] = {0, 0, 0}, vel[3] = {0.1, 0, 0};
  tx_haptic_input in = {{1, 0, 0}, 0.25, false, 0, 0};
  double out[3];
  tx_haptic_tick(&p, 1e-3, &in, pos, vel, out);
  assert_true(out[0] == 1 && p.held[0] == 1);           // within the limits: sent as rendered
  assert_true(p.passivity.energy == 0);                 // nothing was held before
  // less what the spring holds, plus what b = 0.5 N s/m took: b |v|^2 dt
  assert_true(fabs(p.reference_energy - (-0.25 + 0.5 * 0.01 * 1e-3)) < 1e-15);
  in.force[0] = 100;                                    // far above the clamp and the impulse limit
  tx_haptic_tick(&p, 1e-3, &in, pos, vel, out);
  assert_true(fabs(p.passivity.energy + 1 * 0.1 * 1e-3) < 1e-15); // the 1 N held over this period
  double step = l.max_force_rate * 1e-3;
  assert_true(fabs(out[0] - (1 + step)) < 1e-12 && p.held[0] == out[0]);
  assert_true(p.safety.counts.clamped == 1 && p.safety.counts.rate_limited == 1);
  // muted, the force ramps to zero at the impulse limit
  in.mute = true;
  tx_haptic_tick(&p, 1e-3, &in, pos, vel, out);
  assert_true(fabs(out[0] - 1) < 1e-12);
  tx_haptic_tick(&p, 1e-3, &in, pos, vel, out);
  assert_true(out[0] == 0);
  // port reference: the store is not taken off; control pays a deficit back
  tx_haptic_path q;
  tx_haptic_path_init(&q, &l, true, TX_PASSIVITY_REF_PORT, 0.5); // b counts only for the spring
  q.held[0] = q.safety.last[0] = 1; // 1 N held with the motion: E goes to -1e-4 J
  in = (tx_haptic_input){{1, 0, 0}, 5, false, 0, 0};
  tx_haptic_tick(&q, 1e-3, &in, pos, vel, out);
  assert_true(fabs(q.reference_energy + 1e-4) < 1e-15 && q.reference_energy == q.passivity.energy);
  assert_true(q.damping > 0 && fabs(out[0] - (1 - q.damping * 0.1)) < 1e-12 && q.passivity.activations == 1);
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
      cmocka_unit_test(a_negative_damper_is_seen),
      cmocka_unit_test(no_motion_no_energy),
      cmocka_unit_test(a_spring_holds_what_its_force_says),
      cmocka_unit_test(the_tick_observes_what_it_sent),
      cmocka_unit_test(the_observer_sums_what_was_sent),
      cmocka_unit_test(the_controller_pays_back_what_it_observed),
      cmocka_unit_test(the_damping_is_bounded_by_the_force_limit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
