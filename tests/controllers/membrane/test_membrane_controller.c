// physics.membrane through the loader, in lockstep beside a scripted pair of
// hands (a test class writing the hook's pose and pedal, the scissors' pose
// and jaw, a probe's pose): two membranes under their own names, placed
// across the scene's x-y plane; a 30 W hook held on one with the pedal down
// boils a hole (peak at the boiling point, all the power deposited while it
// touches), the other untouched; without the pedal nothing heats; scissors
// closing across the patch cut a slit about as long as the blades' crossing,
// and out of reach cut nothing; a probe moved through the slit counts a pass,
// through intact tissue a warning; bad parameters are refused naming the key.
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

// the membrane under test: centre C, normal +z, axis +x, so its local z is
// the scene's -y; 3 x 3 cm at 1 mm (31 x 31 particles)
#define CX 0.01
#define CY 0.05
#define CZ -0.02

// a point at local (x, y, z) of the membrane, in the scene
static void scene_of(double x, double y, double z, double out[3]) {
  out[0] = CX + x, out[1] = CY - z, out[2] = CZ + y;
}

// --- the scripted hands ------------------------------------------------------

enum { HOOK, SHEARS, SHEARS_AWAY };
static int script; // what the hands do in the next run
static double pedal_bit = 1; // the buttons while the pedal is down

typedef struct hands {
  tx_port hook, grip, shears, probe;
} hands;

static int hands_configure(tx_setup* s, void** self) {
  hands* h = calloc(1, sizeof *h);
  if (!h) return -1;
  *self = h;
  h->hook = tx_setup_write(s, &TX_COMPONENT_OF("hook.pose", tx_pose, 1));
  h->grip = tx_setup_write(s, &TX_COMPONENT_OF("hook.grip", tx_device_grip, 1));
  h->shears = tx_setup_write(s, &TX_COMPONENT_OF("shears.pose", tx_instrument_pose, 1));
  h->probe = tx_setup_write(s, &TX_COMPONENT_OF("probe.pose", tx_pose, 1));
  return 0;
}

static double lerp(double a, double b, double f) { return a + (b - a) * fmin(fmax(f, 0), 1); }

static void hands_step(tx_ctx* c, void* self) {
  hands* h = self;
  const double t = tx_sim_ns(c) * 1e-9;
  // the hook: 0.5 mm off the membrane's centre on its +y side; pedal down from 0.1 s to 1.1 s
  tx_pose* hook = tx_write(c, h->hook);
  *hook = (tx_pose){.quat = {1, 0, 0, 0}};
  scene_of(0, script == HOOK ? 0.0005 : 0.02, 0, hook->pos);
  tx_device_grip* g = tx_write(c, h->grip);
  *g = (tx_device_grip){0, t >= 0.1 && t < 1.1 ? pedal_bit : 0};
  // the scissors: pivot 12 mm left of the centre, blades 15 mm along local +x, half a
  // spacing off the grid's row (0.5 mm); open, closed at 0.2 s; out of reach: 10 mm above
  tx_instrument_pose* sh = tx_write(c, h->shears);
  *sh = (tx_instrument_pose){.quat = {1, 0, 0, 0}, .jaw = lerp(0.5, 0, (t - 0.1) / 0.1)};
  scene_of(-0.012, script == SHEARS_AWAY ? 0.01 : 0, 0.0005, sh->pos);
  // the probe: down through the slit (local x -5 mm) at 0.3 to 0.4 s, then, from
  // below, up through intact tissue (local z 8 mm) at 0.6 to 0.7 s
  tx_pose* p = tx_write(c, h->probe);
  *p = (tx_pose){.quat = {1, 0, 0, 0}};
  double z = t < 0.5 ? 0.0005 : 0.008, y = t < 0.5 ? lerp(0.005, -0.005, (t - 0.3) / 0.1) : lerp(-0.005, 0.005, (t - 0.6) / 0.1);
  scene_of(-0.005, y, z, p->pos);
}

static void hands_fini(void* self) { free(self); }

static const tx_controller_class hands_class = {
    .type = "test.hands", .summary = "scripted hook, scissors and probe", .configure = hands_configure, .step = hands_step, .fini = hands_fini};

// --- helpers -------------------------------------------------------------------

// the membrane "pars" with its params (JSON members) and, where they leave
// them out, the placement and the scripted hands; "his" elsewhere, untouched
static tx_scenario* load(const char* params) {
  static const char* const defaults[][2] = {
      {"center_m", "[0.01,0.05,-0.02]"}, {"normal", "[0,0,1]"}, {"axis", "[1,0,0]"}, {"pose", "\"hook.pose\""},
      {"grip", "\"hook.grip\""}, {"scissors", "\"shears.pose\""}, {"tools", "[\"probe.pose\"]"}};
  char all[2048] = "", key[64];
  for (size_t k = 0; k < sizeof defaults / sizeof defaults[0]; k++) {
    snprintf(key, sizeof key, "\"%s\"", defaults[k][0]);
    if (strstr(params, key)) continue;
    size_t used = strlen(all);
    snprintf(all + used, sizeof all - used, "%s%s:%s", used ? "," : "", key, defaults[k][1]);
  }
  char text[4096];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"hands\",\"type\":\"test.hands\",\"rate_hz\":1000},"
           "{\"name\":\"pars\",\"type\":\"physics.membrane\",\"rate_hz\":100,\"params\":{%s%s%s}},"
           "{\"name\":\"his\",\"type\":\"physics.membrane\",\"rate_hz\":100,\"params\":{\"center_m\":[0,0.2,0],"
           "\"size_m\":[0.02,0.01],\"pose\":\"hook.pose\",\"grip\":\"hook.grip\"}}]}",
           all, params[0] ? "," : "", params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static tx_membrane_state state_of(tx_scenario* s, const char* name) {
  char key[64];
  snprintf(key, sizeof key, "%s.state", name);
  return *(const tx_membrane_state*)latest(s, key);
}

// --- the tests -------------------------------------------------------------------

// the patch at rest: in the scene frame, at the body's temperature, whole;
// both instances under their own names
static void placed_in_the_scene(void** state) {
  (void)state;
  script = SHEARS_AWAY;
  tx_scenario* s = load("\"scissors\":\"\"");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.05);
  tx_snapshot x = latest_snapshot(s, "pars.x"), tri = latest_snapshot(s, "pars.tri"), t = latest_snapshot(s, "pars.temperature");
  assert_int_equal(x.rows, 31 * 31);
  assert_int_equal(tri.rows, 2 * 30 * 30);
  assert_int_equal(t.rows, 31 * 31);
  const float* p = x.data;
  const int mid = 15 + 31 * 15, corner = 0;
  assert_true(fabs(p[3 * mid] - CX) < 1e-6 && fabs(p[3 * mid + 1] - CY) < 1e-6 && fabs(p[3 * mid + 2] - CZ) < 1e-6);
  double want[3];
  scene_of(-0.015, 0, -0.015, want); // particle 0: local x and z at their least
  for (int a = 0; a < 3; a++) assert_true(fabs(p[3 * corner + a] - want[a]) < 1e-6);
  for (uint32_t i = 0; i < t.rows; i++) assert_true(((const tx_temperature*)t.data)[i].t == 310.15f);
  assert_int_equal(latest_snapshot(s, "his.x").rows, 21 * 11);
  tx_membrane_state st = state_of(s, "pars");
  assert_true(st.opening_m == 0 && st.removed == 0 && st.peak_k == 310.15);
  tx_scenario_free(s);
}

// the hook held on the membrane, pedal down 1 s: particles boil away with
// their triangles, the hole opens; the power all goes in while the tip
// touches live tissue; the other membrane is untouched
static void hook_boils_a_hole(void** state) {
  (void)state;
  script = HOOK;
  pedal_bit = 1;
  // when the first particle boils: the shortest run that removes something (10 ms steps)
  double first = 0;
  for (int k = 11; k <= 60 && first == 0; k++) {
    tx_scenario* s = load("\"scissors\":\"\"");
    if (!s) fail_msg("%s", tx_error());
    run(s, k * 0.01);
    if (state_of(s, "pars").removed > 0) first = k * 0.01;
    tx_scenario_free(s);
  }
  tx_scenario* s = load("\"scissors\":\"\"");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.5);
  tx_membrane_state st = state_of(s, "pars");
  const double active = result(s, "pars.active_s"), energy = result(s, "pars.energy_j");
  print_message("  30 W, pedal down 1 s: first boiled at %.2f s (pedal at 0.10 s); %g triangles removed (%g burnt), opening %.1f mm, "
                "peak %.2f K, %.1f mm^2 with Omega > 1; active %.2f s, %.2f J deposited, %.2f J boiled; step p50 %.3f ms, p99 %.3f ms\n",
                first, st.removed, st.burnt, st.opening_m * 1e3, result(s, "pars.peak_k"), st.damaged_m2 * 1e6, active, energy,
                result(s, "pars.boiled_j"), result(s, "pars.step_p50_ms"), result(s, "pars.step_p99_ms"));
  assert_true(first > 0.1 && first < 0.5);
  assert_true(st.removed > 0 && st.burnt == st.removed && st.cut == 0);
  assert_true(st.opening_m > 0.002);
  assert_true(result(s, "pars.peak_k") == 373.15);
  assert_true(st.damaged_m2 > 0);
  assert_true(active > 0.1 && active <= 1.0 + 1e-9);
  assert_true(fabs(energy - 30 * active) < 1e-9 * energy);
  assert_true(result(s, "pars.boiled_j") > 0 && result(s, "pars.boiled_j") < energy);
  // no row of pars.tri has a boiled particle; every temperature in range
  tx_snapshot tri = latest_snapshot(s, "pars.tri"), t = latest_snapshot(s, "pars.temperature");
  assert_int_equal(tri.rows, 2 * 30 * 30 - (int)st.removed);
  for (uint32_t i = 0; i < t.rows; i++) {
    float v = ((const tx_temperature*)t.data)[i].t;
    assert_true(v >= 310.15f - 1e-3f && v <= 373.15f + 1e-3f);
  }
  assert_true(result(s, "his.energy_j") == 0 && result(s, "his.removed") == 0 && result(s, "his.peak_k") == 310.15);
  assert_int_equal(warnings(s, "pars.numerical_fault"), 0);
  assert_true(result(s, "pars.faults") == 0);
  tx_scenario_free(s);
}

// the pedal on another bit (the membrane listens to bit 0), or the tip 2 cm off: nothing heats
static void nothing_without_the_pedal(void** state) {
  (void)state;
  for (int k = 0; k < 2; k++) {
    script = k == 0 ? HOOK : SHEARS_AWAY; // SHEARS_AWAY holds the hook 2 cm off
    pedal_bit = k == 0 ? 2 : 1;
    tx_scenario* s = load("\"scissors\":\"\"");
    if (!s) fail_msg("%s", tx_error());
    run(s, 1.5);
    tx_membrane_state st = state_of(s, "pars");
    assert_true(result(s, "pars.energy_j") == 0 && result(s, "pars.active_s") == 0);
    assert_true(st.removed == 0 && st.opening_m == 0 && result(s, "pars.peak_k") == 310.15);
    tx_scenario_free(s);
  }
  pedal_bit = 1;
}

// scissors closing across the patch (blades from local x -12 mm to +3 mm):
// a slit of about the 15 mm crossing; the probe then passes down through it
// (a pass) and up through intact tissue (a warning); out of reach, no cut
static void scissors_cut_and_tools_pass(void** state) {
  (void)state;
  script = SHEARS;
  tx_scenario* s = load("\"power_w\":0");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0);
  tx_membrane_state st = state_of(s, "pars");
  print_message("  scissors: %g triangles cut, opening %.1f mm (the blades cross 15 mm); passes %g, through tissue %llu\n", st.cut,
                st.opening_m * 1e3, st.passes, (unsigned long long)warnings(s, "pars.passed_through_tissue"));
  assert_true(st.cut > 0 && st.removed == st.cut && st.burnt == 0);
  assert_true(fabs(st.opening_m - 0.015) <= 0.0015);
  assert_true(st.passes == 1 && result(s, "pars.passes") == 1);
  assert_int_equal(warnings(s, "pars.passed_through_tissue"), 1);
  tx_scenario_free(s);

  script = SHEARS_AWAY;
  s = load("\"power_w\":0");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0);
  st = state_of(s, "pars");
  assert_true(st.cut == 0 && st.opening_m == 0);
  assert_true(st.passes == 0); // the probe went down through intact tissue this time
  assert_int_equal(warnings(s, "pars.passed_through_tissue"), 2);
  tx_scenario_free(s);
}

static void expect_refused(const char* params, const char* needle) { assert_refused(load(params), needle); }

static void bad_parameters(void** state) {
  (void)state;
  expect_refused("\"size_m\":[0.03]", "size_m");
  expect_refused("\"size_m\":[0.03,0.0305]", "size_m");
  expect_refused("\"spacing_m\":0", "spacing_m");
  expect_refused("\"thickness_m\":-1", "thickness_m");
  expect_refused("\"normal\":[0,0,0]", "normal");
  expect_refused("\"axis\":[0,0,2]", "axis");
  expect_refused("\"center_m\":[0,\"a\",0]", "center_m");
  expect_refused("\"closed_rad\":0.3", "closed_rad");
  expect_refused("\"vaporisation_k\":320,\"blood_k\":320", "vaporisation_k");
  expect_refused("\"tissue_k\":0", "tissue_k");
  expect_refused("\"power_w\":-1", "power_w");
  expect_refused("\"button\":32", "button");
  expect_refused("\"tools\":[\"\"]", "tools");
  const char* text = "{\"name\":\"t\",\"controllers\":[{\"name\":\"m\",\"type\":\"physics.membrane\",\"rate_hz\":10}]}";
  tx_scenario* s = tx_scenario_load_text("test",
      text, strlen(text), NULL);
  assert_refused(s, "20 to 1000 Hz");
}

int main(void) {
  tx_register_builtin();
  tx_register_controller(&hands_class);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(placed_in_the_scene),
      cmocka_unit_test(hook_boils_a_hole),
      cmocka_unit_test(nothing_without_the_pedal),
      cmocka_unit_test(scissors_cut_and_tools_pass),
      cmocka_unit_test(bad_parameters),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
