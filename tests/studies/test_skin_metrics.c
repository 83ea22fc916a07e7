// The skin-paper metrics on made-up runs whose answers are known: a linear
// push then a rupture, a noisy push, a sawtooth slide, and the 1 ms steps of a
// held force against a followed one.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "studies/skin_metrics.h"

#include <math.h>
#include <string.h>

#define N 2000

static double t[N], pos[N], force[N], tangent[N], contacts[N], pierced[N], torn[N], skin_t[N];

// at 1 kHz: contact at tick 500 (y = -1 mm), a 20 N/m push at 5 mm/s, links
// torn from tick 1200, the force zero from tick 1501 (the skin of tick 1496)
static tx_skin_series push(double noise, int hold) {
  for (int i = 0; i < N; i++) {
    t[i] = i * 1e-3;
    pos[i] = -1e-3 + 5e-3 * (i - 500) * 1e-3;
    contacts[i] = i >= 500 ? 1 : 0;
    pierced[i] = i >= 1501 ? 1 : 0;
    torn[i] = i >= 1500 ? 3 : i >= 1200 ? 1 : 0;
    skin_t[i] = (i - i % 17) * 1e-3; // a 60 Hz-ish physics: publishes every 17 ticks (1.496 s, 1.513 s, ...)
    int k = hold > 1 ? i - i % hold : i; // sample-and-hold of the sampled value
    force[i] = i >= 500 && i < 1501 ? -20 * (pos[k] + 1e-3) + noise * ((i % 2) ? 1 : -1) : 0;
  }
  return (tx_skin_series){N, t, pos, force, NULL, contacts, pierced, torn, skin_t};
}

static void test_linear_push_and_rupture(void** state) {
  (void)state;
  tx_skin_series s = push(0, 1);
  tx_skin_metrics m = tx_skin_measure(&s, 0, 0);
  assert_int_equal(m.contact, 500);
  assert_int_equal(m.rupture, 1501);
  assert_true(fabs(m.contact_pos + 1e-3) < 1e-12);
  assert_true(fabs(m.r2 - 1) < 1e-9);
  assert_true(fabs(m.slope + 20) < 1e-6);
  assert_true(fabs(m.peak - 20 * 5e-3 * 1.0) < 1e-9);      // 1000 ticks at 5 um each
  assert_true(fabs(m.max_step - 20 * 5e-6) < 1e-12);        // one tick of motion
  assert_true(fabs(m.zero_after_s - 5e-3) < 1e-9);          // skin of 1.496 s, zero at 1.501 s
  assert_true(m.roughness < 1e-9);                           // a straight line has no second difference
  assert_true(isnan(m.tangent_mean));
}

static void test_noise_lowers_r2_and_raises_roughness(void** state) {
  (void)state;
  tx_skin_series s = push(0.02, 1);
  tx_skin_metrics m = tx_skin_measure(&s, 0, 0);
  assert_true(m.r2 < 0.95);
  assert_true(m.roughness > 0.5);
}

static void test_hold_steps_sixteen_times_larger(void** state) {
  (void)state;
  tx_skin_series s = push(0, 16);
  tx_skin_metrics held = tx_skin_measure(&s, 0, 0);
  s = push(0, 1);
  tx_skin_metrics followed = tx_skin_measure(&s, 0, 0);
  assert_true(fabs(held.max_step / followed.max_step - 16) < 1e-6);
}

static void test_sawtooth_slide_is_steady(void** state) {
  (void)state;
  tx_skin_series s = push(0, 1);
  // a drag building to 0.06 N and falling to 0.3 of it every 0.21 s
  for (int i = 0; i < N; i++) tangent[i] = -0.06 * (0.3 + 0.7 * fmod(i * 1e-3, 0.21) / 0.21);
  s.tangent = tangent;
  tx_skin_metrics m = tx_skin_measure(&s, 0.0, 2.0);
  assert_true(fabs(m.tangent_mean + 0.06 * 0.65) < 0.003);
  assert_true(m.tangent_cv < 0.05);
  // a drag that dies away is not steady
  for (int i = 0; i < N; i++) tangent[i] = -0.06 * exp(-i * 1e-3 / 0.3);
  m = tx_skin_measure(&s, 0.0, 2.0);
  assert_true(m.tangent_cv > 0.5);
}

static void test_no_contact(void** state) {
  (void)state;
  tx_skin_series s = push(0, 1);
  memset(contacts, 0, sizeof contacts);
  tx_skin_metrics m = tx_skin_measure(&s, 0, 0);
  assert_int_equal(m.contact, -1);
  assert_true(isnan(m.r2) && isnan(m.contact_pos) && m.peak == 0);
}

// q = 0.1 + 0.02 h^2 on h = 1, 1/2, 1/4, 1/8: order 2, the exact limit, errors falling
static void test_converge_second_order(void** state) {
  (void)state;
  double q[4], err[4];
  for (int l = 0; l < 4; l++) q[l] = 0.1 + 0.02 * pow(0.5, 2 * l);
  tx_convergence c = tx_converge(q, 4, 2, err);
  assert_int_equal(c.status, TX_CONV_CONVERGING);
  assert_true(fabs(c.p - 2) < 1e-9);
  assert_true(fabs(c.reference - 0.1) < 1e-12);
  assert_true(c.monotone);
  for (int l = 0; l < 4; l++) assert_true(fabs(err[l] - 0.2 * pow(0.25, l)) < 1e-9);
  // from below, first order, ratio 3
  for (int l = 0; l < 3; l++) q[l] = 2 - 0.5 * pow(1.0 / 3, l);
  c = tx_converge(q, 3, 3, err);
  assert_true(fabs(c.p - 1) < 1e-9 && fabs(c.reference - 2) < 1e-12 && c.monotone);
}

// what is not convergence is said, and the finest level stands in
static void test_converge_refuses_what_does_not_converge(void** state) {
  (void)state;
  double err[4];
  // the steps grow towards the finest level
  double grow[3] = {0.80, 0.81, 0.83};
  tx_convergence c = tx_converge(grow, 3, 2, err);
  assert_int_equal(c.status, TX_CONV_DIVERGING);
  assert_true(fabs(c.p + 1) < 1e-9 && c.reference == 0.83 && !c.monotone);
  // shrinking so slowly that the extrapolation would run away (p = 0.06)
  double slow[3] = {0.0666, 0.0476, 0.0476 - 0.019 * pow(2, -0.06)};
  c = tx_converge(slow, 3, 2, err);
  assert_int_equal(c.status, TX_CONV_SLOW);
  assert_true(fabs(c.p - 0.06) < 1e-9 && c.reference == slow[2] && !c.monotone);
  // a step that changes sign
  double zig[4] = {1.0, 1.2, 1.1, 1.15};
  c = tx_converge(zig, 4, 2, err);
  assert_int_equal(c.status, TX_CONV_OSCILLATING);
  assert_true(isnan(c.p) && c.reference == 1.15 && !c.monotone);
  // barely moving, then a jump to the finest (the old spacing sweep)
  double jump[3] = {0.50, 0.50, 0.30};
  c = tx_converge(jump, 3, 2, err);
  assert_int_equal(c.status, TX_CONV_OSCILLATING);
  // converging from the three finest, but the coarsest is closer than the next: not monotone
  double bump[4] = {0.1001, 0.14, 0.12, 0.11};
  c = tx_converge(bump, 4, 2, err);
  assert_int_equal(c.status, TX_CONV_CONVERGING);
  assert_true(fabs(c.p - 1) < 1e-9 && fabs(c.reference - 0.1) < 1e-12);
  assert_false(c.monotone);
  // unchanged along the path: constant, error 0, no order
  double flat[3] = {0.3, 0.3, 0.3};
  c = tx_converge(flat, 3, 2, err);
  assert_int_equal(c.status, TX_CONV_CONSTANT);
  assert_true(isnan(c.p) && err[0] == 0 && !c.monotone);
  double rounding[3] = {0.0802, 0.0802 * (1 + 1e-14), 0.0802 * (1 - 1e-14)};
  c = tx_converge(rounding, 3, 2, err);
  assert_int_equal(c.status, TX_CONV_CONSTANT);
  // a level without a value, or too few levels
  double gap[3] = {0.1, NAN, 0.3};
  c = tx_converge(gap, 3, 2, err);
  assert_int_equal(c.status, TX_CONV_MISSING);
  assert_true(isnan(c.reference) && isnan(err[0]));
  c = tx_converge(gap, 2, 2, NULL);
  assert_int_equal(c.status, TX_CONV_MISSING);
  assert_string_equal(tx_conv_status_name(TX_CONV_DIVERGING), "diverging");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_linear_push_and_rupture),
      cmocka_unit_test(test_noise_lowers_r2_and_raises_roughness),
      cmocka_unit_test(test_hold_steps_sixteen_times_larger),
      cmocka_unit_test(test_sawtooth_slide_is_steady),
      cmocka_unit_test(test_no_contact),
      cmocka_unit_test(test_converge_second_order),
      cmocka_unit_test(test_converge_refuses_what_does_not_converge),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
