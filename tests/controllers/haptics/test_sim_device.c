// Simulated haptic device: defaults of its class, every field validated,
// motion against closed forms and a fine independent integration, the
// device's own clamp, encoder quantization and sampling.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/haptics/sim_device.h"
#include "tactus/model.h"

#include <math.h>
#include <string.h>

// the defaults are those of a Touch-class device, and put Colgate's bound 2b/T
// at 1 kHz near the nominal stiffness
static void defaults_are_of_the_class(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  assert_int_equal(tx_sim_device_def_check(&d), 0);
  assert_true(d.max_force == 3.3);
  assert_true(d.nominal_stiffness >= 400 && d.nominal_stiffness <= 700);
  assert_true(d.period == 1e-3);
  double bound = 2 * d.damping / d.period;
  assert_true(bound >= d.nominal_stiffness && bound <= 2 * d.nominal_stiffness);
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  tx_device_info info;
  tx_sim_device_info(&dev, &info);
  assert_true(info.max_force == d.max_force && info.max_stiffness == d.nominal_stiffness && info.damping == d.damping);
  for (int i = 0; i < 3; i++) assert_true(info.workspace_min[i] < 0 && info.workspace_max[i] > 0);
  // at rest at the origin, identity orientation, time zero
  assert_true(dev.state.pos[0] == 0 && dev.state.vel[1] == 0 && dev.state.quat[0] == 1 && dev.state.t_ns == 0);
}

// NaN, Inf, negative and out-of-range values in every field: one message
// naming the field, init refuses, and the device is left as it was
static void bad_fields_are_refused(void** state) {
  (void)state;
  const double bad[] = {NAN, INFINITY, -INFINITY, -1, 1e12};
  const struct {
    const char* name;
    size_t offset;
  } fields[] = {
      {"mass", offsetof(tx_sim_device_def, mass)},
      {"damping", offsetof(tx_sim_device_def, damping)},
      {"period", offsetof(tx_sim_device_def, period)},
      {"quantum", offsetof(tx_sim_device_def, quantum)},
      {"max_force", offsetof(tx_sim_device_def, max_force)},
      {"nominal_stiffness", offsetof(tx_sim_device_def, nominal_stiffness)},
      {"hand_stiffness", offsetof(tx_sim_device_def, hand_stiffness)},
      {"hand_damping", offsetof(tx_sim_device_def, hand_damping)},
      {"workspace_min", offsetof(tx_sim_device_def, workspace_min) + sizeof(double)},
      {"workspace_max", offsetof(tx_sim_device_def, workspace_max) + 2 * sizeof(double)},
  };
  tx_sim_device_def good = tx_sim_device_def_default();
  tx_sim_device dev, copy;
  assert_true(tx_sim_device_init(&dev, &good));
  tx_sim_device_step(&dev, (double[3]){0.1, 0, 0}, NULL);
  memcpy(&copy, &dev, sizeof dev);
  for (size_t f = 0; f < sizeof fields / sizeof fields[0]; f++) {
    for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++) {
      if (bad[b] == -1 && !strcmp(fields[f].name, "workspace_min")) continue; // a box may start below zero
      tx_sim_device_def d = good;
      memcpy((char*)&d + fields[f].offset, &bad[b], sizeof(double));
      const char* msg = tx_sim_device_def_check(&d) ? tx_error() : NULL;
      assert_non_null(msg);
      assert_non_null(strstr(msg, fields[f].name));
      assert_false(tx_sim_device_init(&dev, &d));
      assert_non_null(strstr(tx_error(), fields[f].name));
      assert_memory_equal(&dev, &copy, sizeof dev);
    }
  }
  // zero is invalid where it would divide, valid where it means "none"
  tx_sim_device_def d = good;
  d.mass = 0;
  assert_int_equal(tx_sim_device_def_check(&d), -1);
  d = good, d.period = 0;
  assert_int_equal(tx_sim_device_def_check(&d), -1);
  d = good, d.quantum = 0, d.damping = 0, d.hand_stiffness = 0, d.hand_damping = 0;
  assert_int_equal(tx_sim_device_def_check(&d), 0);
  // an empty workspace
  d = good, d.workspace_min[0] = d.workspace_max[0];
  assert_int_equal(tx_sim_device_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "workspace"));
}

// a free damped mass under a held force: x(t) = (F/b)(t - tau (1 - e^(-t/tau))), tau = m/b
static void a_held_force_moves_the_mass_as_the_closed_form(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  d.hand_stiffness = 0, d.hand_damping = 0, d.quantum = 0;
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  const double f[3] = {0.2, -0.1, 0.05};
  for (int k = 0; k < 300; k++) tx_sim_device_step(&dev, f, NULL);
  double t = 300 * d.period, tau = d.mass / d.damping;
  for (int i = 0; i < 3; i++) {
    double x = f[i] / d.damping * (t - tau * (1 - exp(-t / tau)));
    double v = f[i] / d.damping * (1 - exp(-t / tau));
    assert_true(fabs(dev.x[i] - x) <= 1e-12 + 1e-10 * fabs(x));
    assert_true(fabs(dev.v[i] - v) <= 1e-12 + 1e-10 * fabs(v));
  }
  // the motors' work is the held force times the distance
  double w = f[0] * dev.x[0] + f[1] * dev.x[1] + f[2] * dev.x[2];
  assert_true(fabs(dev.work - w) <= 1e-12 * fabs(w));
  assert_true(dev.state.t_ns == 300000000);
}

// (x, v)' for one axis with the force, target and target velocity held
static void deriv(const tx_sim_device_def* d, double f, double xt, double vt, const double s[2], double out[2]) {
  out[0] = s[1];
  out[1] = (f + d->hand_stiffness * (xt - s[0]) + d->hand_damping * (vt - s[1]) - d->damping * s[1]) / d->mass;
}

// the hand as a spring-damper toward a moving target, against a fine
// fourth-order integration (T / 1000) of the same equation
static void the_hand_pulls_as_a_fine_integration(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  d.quantum = 0;
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  double s[2] = {0, 0}, target_prev = 0;
  for (int k = 0; k < 400; k++) {
    double target = 0.02 * sin(k * 0.02), f = k < 200 ? 0.5 : -1.0; // a sweep, and a force step
    tx_sim_device_step(&dev, (double[3]){f, 0, 0}, (double[3]){target, 0, 0});
    double vt = (target - target_prev) / d.period, h = d.period / 1000;
    target_prev = target;
    for (int j = 0; j < 1000; j++) {
      double k1[2], k2[2], k3[2], k4[2], t[2];
      deriv(&d, f, target, vt, s, k1);
      t[0] = s[0] + 0.5 * h * k1[0], t[1] = s[1] + 0.5 * h * k1[1];
      deriv(&d, f, target, vt, t, k2);
      t[0] = s[0] + 0.5 * h * k2[0], t[1] = s[1] + 0.5 * h * k2[1];
      deriv(&d, f, target, vt, t, k3);
      t[0] = s[0] + h * k3[0], t[1] = s[1] + h * k3[1];
      deriv(&d, f, target, vt, t, k4);
      s[0] += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
      s[1] += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
    }
    assert_true(fabs(dev.x[0] - s[0]) < 1e-10);
    assert_true(fabs(dev.v[0] - s[1]) < 1e-8);
  }
  // the other axes had no force and a still target: they never moved
  assert_true(dev.x[1] == 0 && dev.x[2] == 0 && dev.v[1] == 0 && dev.v[2] == 0);
}

// the three axes are the same system, each on its own
static void axes_are_independent_and_alike(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  tx_sim_device a, b;
  assert_true(tx_sim_device_init(&a, &d) && tx_sim_device_init(&b, &d));
  for (int k = 0; k < 500; k++) {
    double f = 0.3 * cos(k * 0.05), xt = 0.01 * sin(k * 0.01);
    tx_sim_device_step(&a, (double[3]){f, 0, 0}, (double[3]){xt, 0, 0});
    tx_sim_device_step(&b, (double[3]){0, 0, f}, (double[3]){0, 0, xt});
  }
  assert_true(a.x[0] == b.x[2] && a.v[0] == b.v[2] && a.state.pos[0] == b.state.pos[2]);
  assert_true(a.x[1] == 0 && a.x[2] == 0 && b.x[0] == 0 && b.x[1] == 0);
}

// the device clamps the magnitude as hardware does, keeping the direction,
// and renders nothing for a command it cannot read
static void the_device_clamps_and_rejects(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  tx_sim_device_step(&dev, (double[3]){30, 40, 0}, NULL);
  double n = sqrt(dev.force[0] * dev.force[0] + dev.force[1] * dev.force[1] + dev.force[2] * dev.force[2]);
  assert_true(fabs(n - d.max_force) < 1e-12);
  assert_true(fabs(dev.force[0] / dev.force[1] - 0.75) < 1e-12);
  assert_int_equal(dev.clamped, 1);
  tx_sim_device_step(&dev, (double[3]){NAN, 0, 1}, NULL);
  tx_sim_device_step(&dev, (double[3]){0, INFINITY, 0}, NULL);
  assert_true(dev.force[0] == 0 && dev.force[1] == 0 && dev.force[2] == 0);
  assert_int_equal(dev.rejected, 2);
  tx_sim_device_step(&dev, (double[3]){1, 1, 1}, NULL); // below the limit: as commanded
  assert_true(dev.force[0] == 1 && dev.force[2] == 1);
  assert_int_equal(dev.clamped, 1);
  tx_sim_device_step(&dev, NULL, (double[3]){NAN, 0, 0}); // no force, a target it cannot read: kept
  assert_true(dev.force[0] == 0 && isfinite(dev.target[0]));
  assert_true(isfinite(dev.x[0]) && isfinite(dev.state.pos[0]) && isfinite(dev.state.vel[0]));
}

// positions come in whole quanta, within half a quantum of the truth, and
// the velocity is their backward difference
static void the_encoder_quantizes(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  d.hand_stiffness = 0, d.hand_damping = 0;
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  double prev = dev.state.pos[0];
  int moved = 0;
  for (int k = 0; k < 200; k++) {
    tx_sim_device_step(&dev, (double[3]){0.05, 0, 0}, NULL);
    double counts = dev.state.pos[0] / d.quantum;
    assert_true(fabs(counts - nearbyint(counts)) < 1e-9);
    assert_true(fabs(dev.state.pos[0] - dev.x[0]) <= 0.5 * d.quantum * (1 + 1e-12));
    assert_true(fabs(dev.state.vel[0] - (dev.state.pos[0] - prev) / d.period) < 1e-12);
    if (dev.state.pos[0] != prev) moved++;
    prev = dev.state.pos[0];
  }
  assert_true(moved > 10);
  // reset: the first velocity is as if the device had been moving
  tx_sim_device_reset(&dev, (double[3]){0.01, 0, 0}, (double[3]){0.1, 0, 0});
  assert_true(fabs(dev.state.vel[0] - 0.1) <= d.quantum / d.period);
  assert_true(dev.ticks == 0 && dev.state.t_ns == 0 && dev.work == 0 && dev.target[0] == 0.01);
}

// with no force the device and hand only lose energy: the hand settles it on the target
static void the_hand_settles_the_device(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  tx_sim_device_place_hand(&dev, (double[3]){0.01, -0.02, 0.005});
  double energy_prev = INFINITY;
  for (int k = 0; k < 2000; k++) {
    tx_sim_device_step(&dev, NULL, NULL);
    double e = 0;
    for (int i = 0; i < 3; i++) {
      double dx = dev.x[i] - dev.target[i];
      e += 0.5 * d.mass * dev.v[i] * dev.v[i] + 0.5 * d.hand_stiffness * dx * dx;
    }
    assert_true(e <= energy_prev * (1 + 1e-12) + 1e-24); // rounding of x - target near the end
    energy_prev = e;
  }
  assert_true(fabs(dev.x[0] - 0.01) < 1e-6 && fabs(dev.x[1] + 0.02) < 1e-6 && fabs(dev.x[2] - 0.005) < 1e-6);
}

// the same inputs give the same bits
static void runs_are_deterministic(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  d.period = 0.25e-3;
  uint64_t h[2];
  for (int r = 0; r < 2; r++) {
    tx_sim_device dev;
    assert_true(tx_sim_device_init(&dev, &d));
    h[r] = TX_HASH_SEED;
    for (int k = 0; k < 1000; k++) {
      double f[3] = {-500 * dev.state.pos[0], 0.2, -0.1};
      tx_sim_device_step(&dev, f, (double[3]){0.01, 0, 0});
      h[r] = tx_hash(h[r], dev.state.pos, sizeof dev.state.pos);
      h[r] = tx_hash(h[r], dev.state.vel, sizeof dev.state.vel);
      h[r] = tx_hash(h[r], &dev.state.t_ns, sizeof dev.state.t_ns);
    }
  }
  assert_true(h[0] == h[1]);
}

// the "sim:" spec: every key set, each at most once, every value in a range
// that keeps the integration finite; a refusal is one line naming the key
static void the_spec_is_parsed_and_checked(void** state) {
  (void)state;
  tx_sim_device_def d = tx_sim_device_def_default();
  char hand[32] = "pierce-down";
  assert_true(tx_sim_device_parse("", &d, hand, sizeof hand));
  tx_sim_device_def defaults = tx_sim_device_def_default();
  assert_memory_equal(&d, &defaults, sizeof d);
  assert_true(tx_sim_device_parse("mass=0.1,damping=0.5,quantum=0,max_force=7,hand_stiffness=300,hand_damping=3,"
                                  "hand=slide-x-over",
                                  &d, hand, sizeof hand));
  assert_true(d.mass == 0.1 && d.damping == 0.5 && d.quantum == 0 && d.max_force == 7 && d.hand_stiffness == 300 &&
              d.hand_damping == 3);
  assert_string_equal(hand, "slide-x-over");
  const struct {
    const char* spec;
    const char* names; // in the message
  } bad[] = {
      {"mass=1e-300", "mass = 1e-300 kg"}, // NaN poses for the whole run before
      {"mass=0.0009", "mass"},
      {"mass=0.1,mass=0.2", "mass: given twice"},
      {"hand=pierce-up,hand=pierce-down", "hand: given twice"},
      {"damping=1,quantum=0,damping=1", "damping: given twice"},
      {"mass=1e999", "mass"},
      {"mass=nan", "mass"},
      {"max_force=-1", "max_force"},
      {"hand_stiffness=1e7", "hand_stiffness"},
      {"hand_damping=abc", "hand_damping: expected a number"},
      {"quantum= 1e-5", "quantum: expected a number"},
      {"damping=", "damping: expected a number"},
      {"mass", "mass: expected key=value"},
      {"weight=1", "weight: unknown key"},
      {"hand=", "hand: expected"},
      {"hand=a-motion-name-longer-than-the-buffer-holds", "hand: too long"},
      {"ma\nss=1", "ma?ss: unknown key"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    d = tx_sim_device_def_default();
    tx_set_error("%s", "");
    if (tx_sim_device_parse(bad[i].spec, &d, hand, sizeof hand)) fail_msg("'%s' accepted", bad[i].spec);
    if (!strstr(tx_error(), bad[i].names) || strchr(tx_error(), '\n')) fail_msg("'%s': %s", bad[i].spec, tx_error());
  }
  // the lightest device the check takes, with the stiffest hand and no damping, at the longest
  // period, integrates stably: the state stays bounded under a bounded force
  d = tx_sim_device_def_default();
  assert_true(tx_sim_device_parse("mass=0.001,damping=0,hand_damping=0,hand_stiffness=1e6", &d, hand, sizeof hand));
  d.period = 0.1;
  tx_sim_device dev;
  assert_true(tx_sim_device_init(&dev, &d));
  for (int k = 0; k < 100000; k++) tx_sim_device_step(&dev, (double[3]){3.3, -3.3, k % 2 ? 3.3 : -3.3}, NULL);
  for (int i = 0; i < 3; i++) assert_true(isfinite(dev.x[i]) && fabs(dev.x[i]) < 1 && isfinite(dev.v[i]));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(defaults_are_of_the_class),
      cmocka_unit_test(bad_fields_are_refused),
      cmocka_unit_test(a_held_force_moves_the_mass_as_the_closed_form),
      cmocka_unit_test(the_hand_pulls_as_a_fine_integration),
      cmocka_unit_test(axes_are_independent_and_alike),
      cmocka_unit_test(the_device_clamps_and_rejects),
      cmocka_unit_test(the_encoder_quantizes),
      cmocka_unit_test(the_hand_settles_the_device),
      cmocka_unit_test(runs_are_deterministic),
      cmocka_unit_test(the_spec_is_parsed_and_checked),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
