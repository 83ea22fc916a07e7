// The safety chain: each stage on its own, and a property test over random
// force models, NaNs, infinities and huge values: no force above the clamp
// and no step above the impulse limit ever leaves it.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/haptics/render.h"
#include "controllers/haptics/safety.h"

#include <math.h>
#include <string.h>

static tx_safety_limits omni(void) {
  tx_device_info info = {.max_force = 3.3, .max_stiffness = 500, .damping = 0.25,
                         .workspace_min = {-0.08, -0.06, -0.035}, .workspace_max = {0.08, 0.06, 0.035}};
  return tx_safety_limits_from_device(&info);
}

static double norm(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static const double origin[3] = {0, 0, 0};

static void defaults_are_consistent_and_checked(void** state) {
  (void)state;
  tx_safety_limits l = omni();
  assert_int_equal(tx_safety_limits_check(&l), 0);
  tx_safety_limits bad = l;
  bad.max_force = NAN;
  assert_int_equal(tx_safety_limits_check(&bad), -1);
  assert_non_null(strstr(tx_error(), "max_force"));
  bad = l;
  bad.ramp_s = 0.02; // the watchdog must reach zero within 10 ms
  assert_int_equal(tx_safety_limits_check(&bad), -1);
  assert_non_null(strstr(tx_error(), "ramp_s"));
  bad = l;
  bad.max_force_rate = l.max_force / l.ramp_s / 2; // would slow the ramp
  assert_int_equal(tx_safety_limits_check(&bad), -1);
  assert_non_null(strstr(tx_error(), "max_force_rate"));
  bad = l;
  bad.workspace_min[1] = 1;
  assert_int_equal(tx_safety_limits_check(&bad), -1);
  // a scenario can only lower limits
  tx_safety_limits wanted = l;
  wanted.max_force = 100;
  wanted.model_timeout_s = 0.01;
  tx_safety_limits low = tx_safety_limits_lower(&l, &wanted);
  assert_true(low.max_force == 3.3);
  assert_true(low.model_timeout_s == 0.01);
}

static void clamp_keeps_direction(void** state) {
  (void)state;
  tx_safety_limits l = omni();
  l.max_force_rate = 1e9; // isolate the clamp
  tx_safety s;
  tx_safety_init(&s);
  double in[3] = {30, 40, 0}, out[3];
  tx_safety_apply(&s, &l, 1e-3, in, origin, 0, 0, out);
  assert_true(fabs(norm(out) - 3.3) < 1e-12);
  assert_true(fabs(out[0] / out[1] - 0.75) < 1e-12);
  assert_int_equal(s.counts.clamped, 1);
}

static void impulse_limit_per_tick(void** state) {
  (void)state;
  tx_safety_limits l = omni(); // 660 N/s: 0.66 N per 1 ms tick
  tx_safety s;
  tx_safety_init(&s);
  double in[3] = {0, 3, 0}, out[3];
  tx_safety_apply(&s, &l, 1e-3, in, origin, 0, 0, out);
  assert_true(fabs(out[1] - l.max_force_rate * 1e-3) < 1e-12);
  assert_int_equal(s.counts.rate_limited, 1);
  for (int k = 0; k < 10; k++) tx_safety_apply(&s, &l, 1e-3, in, origin, 0, 0, out);
  assert_true(out[1] == 3);
}

static void non_finite_becomes_zero_within_ten_ms(void** state) {
  (void)state;
  tx_safety_limits l = omni();
  tx_safety s;
  tx_safety_init(&s);
  double in[3] = {0, 3, 0}, out[3];
  for (int k = 0; k < 20; k++) tx_safety_apply(&s, &l, 1e-3, in, origin, 0, 0, out);
  assert_true(out[1] == 3);
  double bad[3] = {NAN, 1, INFINITY};
  for (int k = 0; k < 10; k++) {
    tx_safety_apply(&s, &l, 1e-3, bad, origin, 0, 0, out);
    assert_true(isfinite(out[0]) && isfinite(out[1]) && isfinite(out[2]));
  }
  assert_true(norm(out) == 0);
  assert_int_equal(s.counts.non_finite, 10);
  double nan_pos[3] = {NAN, 0, 0}; // a broken device sample is no better
  tx_safety_apply(&s, &l, 1e-3, in, nan_pos, 0, 0, out);
  assert_true(norm(out) == 0);
}

// a stale model or a silent device: zero within 10 ms, and back when fresh
static void watchdog_ramps_to_zero_within_ten_ms(void** state) {
  (void)state;
  tx_safety_limits l = omni();
  const double ages[][2] = {{1.0, 0}, {0, 1.0}, {NAN, 0}};
  for (size_t c = 0; c < 3; c++) {
    tx_safety s;
    tx_safety_init(&s);
    double in[3] = {3.3, 0, 0}, out[3];
    for (int k = 0; k < 20; k++) tx_safety_apply(&s, &l, 1e-3, in, origin, 0, 0, out);
    int ticks = 0;
    do {
      tx_safety_apply(&s, &l, 1e-3, in, origin, ages[c][0], ages[c][1], out);
      ticks++;
    } while (norm(out) > 0 && ticks < 100);
    print_message("  case %zu: zero after %d ticks of 1 ms\n", c, ticks);
    assert_true(ticks <= 10);
    for (int k = 0; k < 30; k++) tx_safety_apply(&s, &l, 1e-3, in, origin, 0, 0, out);
    assert_true(fabs(out[0] - 3.3) < 1e-12); // recovered
  }
}

static void workspace_drops_outward_force(void** state) {
  (void)state;
  tx_safety_limits l = omni();
  l.max_force_rate = 1e9;
  tx_safety s;
  tx_safety_init(&s);
  double outside[3] = {0.2, 0, 0}, out[3];
  double push_out[3] = {1, 0.5, 0}, push_in[3] = {-1, 0.5, 0};
  tx_safety_apply(&s, &l, 1e-3, push_out, outside, 0, 0, out);
  assert_true(out[0] == 0 && out[1] == 0.5);
  assert_int_equal(s.counts.workspace, 1);
  tx_safety_apply(&s, &l, 1e-3, push_in, outside, 0, 0, out);
  assert_true(out[0] == -1); // pushing back in is allowed
}

// xorshift64*: a fixed, portable sequence
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void) {
  rng ^= rng >> 12, rng ^= rng << 25, rng ^= rng >> 27;
  return (double)((rng * 2685821657736338717ull) >> 11) * 0x1.0p-53;
}

// a value that is usually ordinary and sometimes hostile
static double wild(double scale) {
  double u = uniform();
  if (u < 0.02) return NAN;
  if (u < 0.04) return u < 0.03 ? INFINITY : -INFINITY;
  if (u < 0.08) return (uniform() - 0.5) * 1e300;
  if (u < 0.10) return (uniform() - 0.5) * 1e-300;
  return (uniform() - 0.5) * 2 * scale;
}

static void property_nothing_above_the_limits_ever_leaves(void** state) {
  (void)state;
  tx_safety_limits l = omni();
  tx_safety s;
  tx_safety_init(&s);
  double prev[3] = {0, 0, 0};
  const int ticks = 2000000;
  double worst_force = 0, worst_step = 0;
  for (int k = 0; k < ticks; k++) {
    tx_force_model m;
    for (int i = 0; i < 3; i++) m.f0[i] = wild(5), m.x0[i] = wild(0.05);
    for (int i = 0; i < 9; i++) m.k[i] = wild(2000);
    double x[3] = {wild(0.1), wild(0.1), wild(0.1)};
    double f[3], out[3];
    tx_render_force(&m, uniform() < 0.5 ? TX_RENDER_LOCAL_MODEL : TX_RENDER_SAMPLE_HOLD, x, f);
    double dt = uniform() < 0.01 ? wild(1e-3) : 1e-3 * (0.1 + uniform());
    double model_age = uniform() < 0.05 ? wild(1) : 0.01, silent = uniform() < 0.05 ? wild(1) : 0;
    tx_safety_apply(&s, &l, dt, f, x, model_age, silent, out);
    double step[3] = {out[0] - prev[0], out[1] - prev[1], out[2] - prev[2]};
    double allowed = isfinite(dt) && dt > 0 ? l.max_force_rate * dt : 0;
    for (int i = 0; i < 3; i++) assert_true(isfinite(out[i]));
    assert_true(norm(out) <= l.max_force);
    assert_true(norm(step) <= allowed * (1 + 1e-12) + 1e-15);
    worst_force = fmax(worst_force, norm(out));
    worst_step = fmax(worst_step, norm(step) / fmax(allowed, 1e-300));
    memcpy(prev, out, sizeof prev);
  }
  print_message("  %d ticks: largest force %.6f N (clamp %.1f), largest step %.6f of the limit\n", ticks, worst_force,
                l.max_force, worst_step);
  print_message("  counts: non-finite %llu, clamped %llu, rate %llu, watchdog %llu, workspace %llu\n",
                (unsigned long long)s.counts.non_finite, (unsigned long long)s.counts.clamped,
                (unsigned long long)s.counts.rate_limited, (unsigned long long)s.counts.watchdog,
                (unsigned long long)s.counts.workspace);
  // every stage was exercised
  assert_true(s.counts.non_finite > 0 && s.counts.clamped > 0 && s.counts.rate_limited > 0);
  assert_true(s.counts.watchdog > 0 && s.counts.workspace > 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(defaults_are_consistent_and_checked),
      cmocka_unit_test(clamp_keeps_direction),
      cmocka_unit_test(impulse_limit_per_tick),
      cmocka_unit_test(non_finite_becomes_zero_within_ten_ms),
      cmocka_unit_test(watchdog_ramps_to_zero_within_ten_ms),
      cmocka_unit_test(workspace_drops_outward_force),
      cmocka_unit_test(property_nothing_above_the_limits_ever_leaves),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
