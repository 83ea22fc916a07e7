// physics.skin through the loader, in lockstep beside the haptics
// controller's scripted pierce-down: what it publishes, the HIP following
// device0.pose through the skin, parameter checks, and the warning a fault
// leaves.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static tx_scenario* load(const char* skin_params, double rate) {
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":%g,\"params\":{%s}},"
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:pierce-down\"}}]}",
           rate, skin_params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

// the papers' two densities, published whole at 60 Hz
static void publishes_the_skin(void** state) {
  (void)state;
  tx_scenario* s = load("", 60);
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.5);
  tx_snapshot x = latest_snapshot(s, "skin.x"), tri = latest_snapshot(s, "skin.tri"), h = latest_snapshot(s, "skin.thickness"),
              torn = latest_snapshot(s, "skin.torn");
  assert_int_equal(x.rows, 1764);
  assert_int_equal(x.cols, 3);
  assert_int_equal(tri.rows, 3362);
  assert_int_equal(x.seq, 31); // the publish of init, then 30 steps
  assert_int_equal(tri.seq, 31);
  assert_float_equal(((const double*)h.data)[0], 0.004, 1e-12);
  assert_int_equal(((const int*)torn.data)[0], 0);
  // a corner particle at the edge of 10 cm plus one spacing
  const float* p = x.data;
  assert_float_equal(p[0], -0.05125, 1e-6);
  assert_float_equal(p[3] - p[0], 0.0025, 1e-6);
  tx_scenario_free(s);

  s = load("\"spacing_m\":0.001", 60);
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0 / 60);
  assert_int_equal(latest_snapshot(s, "skin.x").rows, 10404);
  assert_int_equal(latest_snapshot(s, "skin.tri").rows, 2 * 101 * 101);
  tx_scenario_free(s);
}

// pierce-down moves the HIP from 1 cm above to 1 cm below at 5 mm/s: the
// skin goes down under it, tears, and the HIP ends below a hole
static void hip_follows_the_device_and_pierces(void** state) {
  (void)state;
  tx_scenario* s = load("\"hip_radius_m\":0.0005", 60);
  if (!s) fail_msg("%s", tx_error());
  run(s, 2.6); // the HIP at 0.5 mm, the skin's surface 2.5 mm below it
  const float* x = latest_snapshot(s, "skin.x").data;
  float low = 1;
  for (int i = 0; i < 1764; i++) low = x[3 * i + 1] < low ? x[3 * i + 1] : low;
  print_message("  HIP at %.2f mm: skin lowest at %.2f mm\n", ((const double*)latest_snapshot(s, "device0.pose").data)[1] * 1e3,
                low * 1e3);
  assert_true(low < -0.001);
  assert_int_equal(((const int*)latest_snapshot(s, "skin.torn").data)[0], 0);
  tx_scenario_free(s);
  s = load("\"hip_radius_m\":0.0005", 60); // a run starts the script again
  run(s, 5.0); // on to -1 cm: through
  int torn = ((const int*)latest_snapshot(s, "skin.torn").data)[0];
  tx_snapshot tri = latest_snapshot(s, "skin.tri");
  print_message("  at the end: %d links torn, %u triangles left\n", torn, tri.rows);
  assert_true(torn > 0);
  assert_true(tri.rows < 3362);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  // every published coordinate is finite and every live triangle indexes a particle
  x = latest_snapshot(s, "skin.x").data;
  for (int i = 0; i < 1764 * 3; i++) assert_true(isfinite(x[i]));
  const int* t = tri.data;
  for (uint32_t i = 0; i < tri.rows * 3; i++) assert_true(t[i] >= 0 && t[i] < 1764);
  tx_scenario_free(s);
}

// skin.contact: nothing before the HIP arrives; pressing, the skin's reaction up
// (along +y) at the HIP position of the step, the indentation since first touch and
// a tangent stiffness between |f|/w and 3|f|/w (a membrane's p in |f| ~ w^p, 1 to 3)
static void publishes_the_contact(void** state) {
  (void)state;
  tx_scenario* s = load("\"hip_radius_m\":0.0005", 60);
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0); // the HIP at 7.5 mm, out of reach (2.5 mm)
  const tx_skin_contact* k = latest_snapshot(s, "skin.contact").data;
  assert_true(k->touching == 0 && k->f[0] == 0 && k->f[1] == 0 && k->f[2] == 0 && k->k == 0);
  tx_scenario_free(s);
  s = load("\"hip_radius_m\":0.0005", 60);
  run(s, 2.6); // the HIP at -0.5 mm: 3 mm past first touch
  tx_snapshot ks = latest_snapshot(s, "skin.contact");
  k = ks.data;
  double pose_y = ((const double*)latest_snapshot(s, "device0.pose").data)[1];
  double f = sqrt(k->f[0] * k->f[0] + k->f[1] * k->f[1] + k->f[2] * k->f[2]);
  print_message("  HIP %.3f mm: f %.4f N along (%.3f %.3f %.3f), w %.3f mm, k %.1f N/m\n", k->x[1] * 1e3, f, k->n[0],
                k->n[1], k->n[2], k->depth * 1e3, k->k);
  assert_true(k->touching == 1);
  assert_true(k->f[1] > 0 && k->n[1] > 0.95);
  assert_true(fabs(k->n[0] * k->n[0] + k->n[1] * k->n[1] + k->n[2] * k->n[2] - 1) < 1e-9);
  assert_true(fabs(k->x[1] - pose_y) < 0.005 / 60 + 1e-9); // the HIP of the last step: at most one step behind
  assert_true(fabs(k->depth - (0.0025 - k->x[1])) < 3e-4);  // pushed from where it first touched
  assert_true(k->k >= f / k->depth * (1 - 1e-9) && k->k <= 3 * f / k->depth * (1 + 1e-9));
  assert_true(k->torn == ((const int*)latest_snapshot(s, "skin.torn").data)[0]);
  // skin.rupture: the pressed skin under tension, below the rupture tension, not torn in the step
  const tx_skin_rupture* r = latest_snapshot(s, "skin.rupture").data;
  print_message("  peak membrane tension %.2f N/m\n", r->tension);
  assert_true(r->tension > 0 && r->tension < 80 && r->broke == 0);
  assert_true(r->at[0] == 0 && r->at[1] == 0 && r->at[2] == 0);
  tx_scenario_free(s);
}

// parameters out of range name themselves; rates outside 20-120 Hz are refused
static void bad_parameters_are_named(void** state) {
  (void)state;
  struct {
    const char* params;
    double rate;
    const char* expect;
  } cases[] = {
      {"\"spacing_m\":0.003", 60, "params.spacing_m"},
      {"\"thickness_m\":-0.001", 60, "params.thickness_m"},
      {"\"iterations\":0", 60, "params.iterations"},
      {"\"gravity\":3", 60, "params.gravity"},
      {"\"rupture_tension_n_per_m\":\"x\"", 60, "params.rupture_tension_n_per_m"},
      {"\"stiffnes\":1", 60, "params.stiffnes"},
      {"", 10, "20 to 120 Hz"},
      {"", 240, "20 to 120 Hz"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    tx_scenario* s = load(cases[i].params, cases[i].rate);
    if (s) fail_msg("case %zu loaded", i);
    if (!strstr(tx_error(), cases[i].expect)) fail_msg("case %zu: '%s' does not name %s", i, tx_error(), cases[i].expect);
    assert_null(strchr(tx_error(), '\n'));
  }
}

// the gap across the wound at its middle: the particles nearest (-1.25, 0,
// -+1.25) mm at rest, the two rows beside the line z = 0 (the default 42 x
// 42 patch has none on it)
static double wound_gap(tx_scenario* s, const float* rest, int n) {
  const float* x = latest_snapshot(s, "skin.x").data;
  int side[2] = {-1, -1};
  for (int e = 0; e < 2; e++) {
    double best = 1e9, z = e ? 0.00125 : -0.00125;
    for (int i = 0; i < n; i++) {
      double d = hypot(rest[3 * i] + 0.00125, rest[3 * i + 2] - z);
      if (d < best) best = d, side[e] = i;
    }
  }
  const float *p = x + 3 * side[0], *q = x + 3 * side[1];
  return sqrt(pow(p[0] - q[0], 2) + pow(p[1] - q[1], 2) + pow(p[2] - q[2], 2));
}

// A wound cut along z = 0 from x = -15 to 15 mm before the run: the links
// across it go (the 12 stretch links between x = -13.75 and 13.75 mm and
// both shear links of each of the 13 cells it crosses: 38), with the cells'
// 26 triangles, none counted as torn. Without tension
// the edges rest a spacing apart; with the skin pre-tensioned they draw
// back, as a cut through tensed skin gapes, and further the more tension.
// Ends given alone, or a wound off the patch, are refused naming the key.
static void wound_is_cut_and_gapes_under_tension(void** state) {
  (void)state;
  static float rest[3 * 1764];
  double gap[3];
  const char* tension[] = {"0", "20", "40"};
  for (int k = 0; k < 3; k++) {
    char params[256];
    snprintf(params, sizeof params, "\"wound_a_m\":[-0.015,0,0],\"wound_b_m\":[0.015,0,0],\"pretension_n_per_m\":%s", tension[k]);
    tx_scenario* s = load(params, 60);
    if (!s) fail_msg("%s", tx_error());
    run(s, 1.0 / 60);
    if (k == 0) memcpy(rest, latest_snapshot(s, "skin.x").data, sizeof rest);
    run(s, 1.0);
    tx_snapshot tri = latest_snapshot(s, "skin.tri");
    gap[k] = wound_gap(s, rest, 1764);
    print_message("  pretension %s N/m: %g links cut, %u of 3362 triangles live, the gap %.3f mm\n", tension[k],
                  result(s, "skin.wound_links_cut"), tri.rows, 1e3 * gap[k]);
    assert_true(result(s, "skin.wound_links_cut") == 38);
    assert_int_equal(tri.rows, 3362 - 26); // each cell it crosses loses both triangles
    assert_true(result(s, "skin.torn_links") == 0);
    tx_scenario_free(s);
  }
  assert_true(fabs(gap[0] - 0.0025) < 1e-4); // at rest: one spacing
  assert_true(gap[1] > gap[0] + 1e-4 && gap[2] > gap[1] + 1e-4);
  static const char* const bad[][2] = {
      {"\"wound_a_m\":[-0.015,0,0]", "params.wound_b_m: the wound needs both ends"},
      {"\"wound_a_m\":[0.2,0,0.2],\"wound_b_m\":[0.3,0,0.2]", "params.wound_a_m: the wound to wound_b_m crosses no link"},
      {"\"wound_a_m\":[0,0],\"wound_b_m\":[0.01,0,0]", "params.wound_a_m: expected [x, y, z]"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) assert_refused(load(bad[i][0], 60), bad[i][1]);
}

// a test class standing for physics.instruments: hand 0's jaws (instrument0.pose)
// and their grasps on instruments.events. At grasp_at it grasps at point; from
// 0.2 s to 0.7 s the jaws rise by lift along y and turn by turn rad about y;
// at release_at they open
static struct {
  double point[3], lift, turn, grasp_at, release_at;
} jaws_plan;
static tx_port jaws_pose, jaws_events;
static int jaws_configure(tx_setup* s, void** self) {
  *self = NULL;
  jaws_pose = tx_setup_write(s, &TX_COMPONENT_OF("instrument0.pose", tx_instrument_pose, 1));
  jaws_events = tx_setup_emit(s, "instruments.events", 64);
  return 0;
}
// the jaws at time t: they hold the grasp point, raised and turned
static void jaws_at(double t, tx_instrument_pose* p) {
  double u = (t - 0.2) / 0.5;
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  memset(p, 0, sizeof *p);
  for (int a = 0; a < 3; a++) p->pos[a] = jaws_plan.point[a];
  p->pos[1] += u * jaws_plan.lift;
  p->quat[0] = cos(0.5 * u * jaws_plan.turn);
  p->quat[2] = sin(0.5 * u * jaws_plan.turn);
}
static void jaws_step(tx_ctx* c, void* self) {
  (void)self;
  double t = (double)tx_sim_ns(c) * 1e-9;
  jaws_at(t, tx_write(c, jaws_pose));
  uint64_t i = tx_step_index(c);
  if (i == (uint64_t)llround(jaws_plan.grasp_at * 1000)) {
    tx_event e = {.kind = TX_EVENT_GRASP, .source = 0};
    memcpy(e.grasp.point, jaws_plan.point, sizeof e.grasp.point);
    tx_emit(c, jaws_events, &e);
    tx_emit(c, jaws_events, &(tx_event){.kind = TX_EVENT_GRASP, .source = 3}); // a hand the skin does not watch
  }
  if (i == (uint64_t)llround(jaws_plan.release_at * 1000)) tx_emit(c, jaws_events, &(tx_event){.kind = TX_EVENT_RELEASE, .source = 0});
}
static const tx_controller_class jaws_class = {.type = "test.jaws", .summary = "forceps jaws", .configure = jaws_configure, .step = jaws_step};

static tx_scenario* load_with_jaws(const char* skin_params) {
  if (!tx_find_controller(jaws_class.type)) assert_int_equal(tx_register_controller(&jaws_class), 0);
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"jaws\",\"type\":\"test.jaws\",\"rate_hz\":1000},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":60,"
           "\"params\":{\"hip_radius_m\":0,\"grasp_events\":\"instruments.events\",\"grasp_hands\":1%s}}]}",
           skin_params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

// the flat patch's particles (no gravity, nothing touches it before the grasp)
static void rest_positions(float* out) {
  jaws_plan.grasp_at = jaws_plan.release_at = 100;
  tx_scenario* s = load_with_jaws("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.05);
  memcpy(out, latest_snapshot(s, "skin.x").data, 1764 * 3 * sizeof(float));
  tx_scenario_free(s);
}

// forceps grasp the skin at a cell's middle: the four particles within 2 mm
// follow the jaws (raised 5 mm and turned 0.2 rad about y) to 1e-9 m, the ring
// beside them rises part way (a tent), the far patch stays; opened, the skin
// falls back flat. A grasp from a hand the skin does not watch is ignored
static void grasped_skin_follows_the_jaws(void** state) {
  (void)state;
  static float rest[1764 * 3];
  rest_positions(rest);
  jaws_plan = (__typeof__(jaws_plan)){{0, 0, 0}, 0.005, 0.2, 0.1, 1.5};
  tx_scenario* s = load_with_jaws("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.2);
  const float* x = latest_snapshot(s, "skin.x").data;
  tx_instrument_pose jp;
  jaws_at(1.2, &jp);
  int held = 0, tent = 0;
  double worst = 0, tent_low = 1, far_high = 0;
  for (int i = 0; i < 1764; i++) {
    const float* r = &rest[i * 3];
    double d = hypot(r[0], r[2]);
    if (d <= 0.002) { // held: the rest offset turned by 0.2 rad about y and raised
      double c = cos(jaws_plan.turn), sn = sin(jaws_plan.turn);
      double want[3] = {c * r[0] + sn * r[2] + jp.pos[0], r[1] + jp.pos[1], -sn * r[0] + c * r[2] + jp.pos[2]};
      for (int a = 0; a < 3; a++) worst = fmax(worst, fabs(x[i * 3 + a] - want[a]));
      held++;
    } else if (d < 0.004) { // the ring beside: raised, below the jaws
      assert_true(x[i * 3 + 1] > 0 && x[i * 3 + 1] < 0.005);
      tent_low = fmin(tent_low, x[i * 3 + 1]);
      tent++;
    } else if (d > 0.03)
      far_high = fmax(far_high, x[i * 3 + 1]);
  }
  print_message("  %d held, furthest from the jaws' frame %.2e m; %d in the tent's first ring, from %.2f mm up; "
                "beyond 3 cm at most %.2f mm\n", held, worst, tent, tent_low * 1e3, far_high * 1e3);
  assert_true(far_high < tent_low);
  assert_int_equal(held, 4);
  assert_true(worst < 1e-9);
  assert_true(tent > 0);
  assert_true(result(s, "skin.grasps") == 1);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  tx_scenario_free(s);

  s = load_with_jaws(""); // on past the release at 1.5 s: it falls back
  run(s, 4.0);
  x = latest_snapshot(s, "skin.x").data;
  double high = 0;
  for (int i = 0; i < 1764; i++) high = fmax(high, fabs(x[i * 3 + 1]));
  print_message("  3.5 s after the release: highest particle %.3f mm\n", high * 1e3);
  assert_true(high < 0.0005);
  assert_true(result(s, "skin.grasps") == 1);
  tx_scenario_free(s);
}

// a grasp 3 cm above the skin (the needle's or the thread's) takes nothing:
// the jaws rise and the skin stays flat
static void grasp_out_of_reach_does_nothing(void** state) {
  (void)state;
  jaws_plan = (__typeof__(jaws_plan)){{0, 0.03, 0}, 0.005, 0, 0.1, 1.5};
  tx_scenario* s = load_with_jaws("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0);
  const float* x = latest_snapshot(s, "skin.x").data;
  for (int i = 0; i < 1764; i++) assert_true(x[i * 3 + 1] == 0);
  assert_true(result(s, "skin.grasps") == 0);
  tx_scenario_free(s);
}

// jaws that lift the skin 2 cm tear it at 20 N/m beside the particles they
// hold (far from the HIP: the blunt criterion): no fault, nothing
// non-finite, the held particles still on the jaws
static void tear_beside_the_jaws(void** state) {
  (void)state;
  jaws_plan = (__typeof__(jaws_plan)){{0, 0, 0}, 0.02, 0, 0.1, 100};
  tx_scenario* s = load_with_jaws(",\"blunt_rupture_tension_n_per_m\":20");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.2);
  const float* x = latest_snapshot(s, "skin.x").data;
  int torn = ((const int*)latest_snapshot(s, "skin.torn").data)[0], on = 0;
  for (int i = 0; i < 1764 * 3; i++) assert_true(isfinite(x[i]));
  for (int i = 0; i < 1764; i++) on += fabs(x[i * 3 + 1] - 0.02) < 1e-6;
  print_message("  %d links torn, %d particles on the jaws\n", torn, on);
  assert_true(torn > 0);
  assert_int_equal(on, 4);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  assert_true(result(s, "skin.freed_particles") == 0); // the jaws hold what they tore loose
  tx_scenario_free(s);
}

// jaws that lift a piece out of the skin and let go of it: the piece, held
// by nothing, is freed (counted in the report) and leaves skin.tri; skin.x
// keeps its rows, so every index a reader holds stays valid, and the piece
// stays where it was let go instead of falling (no gravity: it would float)
static void piece_let_go_is_freed(void** state) {
  (void)state;
  jaws_plan = (__typeof__(jaws_plan)){{0, 0, 0}, 0.03, 0, 0.1, 1.0};
  tx_scenario* s = load_with_jaws(",\"rupture_tension_n_per_m\":20");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.5);
  tx_snapshot xs = latest_snapshot(s, "skin.x"), tri = latest_snapshot(s, "skin.tri");
  const float* x = xs.data;
  const int* t = tri.data;
  assert_int_equal(xs.rows, 1764);
  int up = 0;
  for (int i = 0; i < 1764; i++) up += x[i * 3 + 1] > 0.01f;
  for (uint32_t k = 0; k < tri.rows * 3; k++) {
    assert_true(t[k] >= 0 && t[k] < 1764);
    assert_true(x[t[k] * 3 + 1] < 0.01f); // no triangle of the piece
  }
  print_message("  %g particles in %g piece(s) freed, %d of them still up where they were let go, %u triangles left\n",
                result(s, "skin.freed_particles"), result(s, "skin.freed_pieces"), up, tri.rows);
  assert_true(result(s, "skin.freed_particles") >= 4);
  assert_true(result(s, "skin.freed_pieces") >= 1);
  assert_true(up >= 4);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  tx_scenario_free(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(publishes_the_skin),
      cmocka_unit_test(hip_follows_the_device_and_pierces),
      cmocka_unit_test(publishes_the_contact),
      cmocka_unit_test(bad_parameters_are_named),
      cmocka_unit_test(grasped_skin_follows_the_jaws),
      cmocka_unit_test(grasp_out_of_reach_does_nothing),
      cmocka_unit_test(tear_beside_the_jaws),
      cmocka_unit_test(piece_let_go_is_freed),
      cmocka_unit_test(wound_is_cut_and_gapes_under_tension),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
