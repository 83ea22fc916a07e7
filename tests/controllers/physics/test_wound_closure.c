// A stitch closes the wound: physics.thread's pull at its punctures
// (thread.puncture_loads) on physics.skin's particles (thread_loads).
//
// The stitch: a fixture stands for the needle and drives the thread's head
// down through one edge of a 3 cm wound, under it and up through the other
// edge, then over the wound and along it, as a throw drawn tight; the
// thread's tail is pinned 3 mm above the wound's middle, where a knot would
// sit (a hairpin start shape keeps the thread slack until the pull). The gap
// across the wound at the stitch is read from the skin at the end, with the
// loads and, as a control, without them.
//
// The skin alone: a fixture publishes a pair of loads across the wound, equal
// and opposite, stiff or not; and rows that are not the skin's.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "controllers/system.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

// the skin's default grid: 42 x 42 particles 2.5 mm apart, x fastest, from -51.25 mm
#define SIDE 42
#define SPACING 0.0025
#define FIRST (-0.05125)
#define ROW 20                   // z = -1.25 mm: the stitch's row
#define ENTRY (ROW * SIDE + 19)  // x = -3.75 mm: a 3.75 mm bite on the -x edge
#define EXIT (ROW * SIDE + 22)   // x = +3.75 mm: and on the +x edge
#define EDGE_L (ROW * SIDE + 20) // x = -1.25 mm and +1.25 mm: the wound's edges there (the cut at x = 0)
#define EDGE_R (ROW * SIDE + 21)
#define NODES 21
#define LENGTH 0.04

static const double head_x[2] = {FIRST + 19 * SPACING, FIRST + 22 * SPACING}, row_z = FIRST + ROW * SPACING;

static double distance(const float* x, int i, int j) {
  double d = 0;
  for (int a = 0; a < 3; a++) d += pow((double)x[3 * i + a] - x[3 * j + a], 2);
  return sqrt(d);
}

static double ramp(double t, double t0, double t1) { return fmin(1, fmax(0, (t - t0) / (t1 - t0))); }

// --- the stitch --------------------------------------------------------------

static tx_port head_out, punct_out, shape_out;
static double pull_to; // m, the head's x at the end of the pull

static int stitch_configure(tx_setup* s, void** self) {
  *self = NULL;
  head_out = tx_setup_write(s, &TX_COMPONENT_OF("hand.pose", tx_pose, 1));
  punct_out = tx_setup_write(s, &TX_COMPONENT_OF("needle.punctures", tx_puncture, 3));
  shape_out = tx_setup_write(s, &TX_COMPONENT_OF("fixture.shape", tx_thread_node, NODES));
  return 0;
}

// the start shape: from the head up, across to the wound's middle and down to
// 3 mm above it (the knot's place, where the tail is pinned), sampled a link apart
static void hairpin(tx_thread_node out[NODES]) {
  const double l0 = LENGTH / (NODES - 1), up = (LENGTH - 0.00375 - 0.007) / 2;
  const double corner[4][2] = {{head_x[0], 0.01}, {head_x[0], 0.01 + up}, {0, 0.01 + up}, {0, 0.003}};
  for (int i = 0; i < NODES; i++) {
    double s = i * l0, len = 0;
    int leg = 0;
    for (; leg < 2; leg++, s -= len) {
      len = hypot(corner[leg + 1][0] - corner[leg][0], corner[leg + 1][1] - corner[leg][1]);
      if (s <= len) break;
    }
    len = hypot(corner[leg + 1][0] - corner[leg][0], corner[leg + 1][1] - corner[leg][1]);
    double f = fmin(1, s / len);
    out[i] = (tx_thread_node){{corner[leg][0] + f * (corner[leg + 1][0] - corner[leg][0]),
                               corner[leg][1] + f * (corner[leg + 1][1] - corner[leg][1]), row_z},
                              0.00025};
  }
}

static void stitch_step(tx_ctx* c, void* self) {
  (void)self;
  double t = (double)tx_step_index(c) * 1e-3;
  // down through the entry, under the wound, up through the exit, over to the
  // entry's side, then the pull along -x
  double down = ramp(t, 0, 0.2), across = ramp(t, 0.2, 0.4), up = ramp(t, 0.4, 0.6), over = ramp(t, 0.6, 0.8),
         pull = ramp(t, 0.8, 1.6);
  double x = head_x[0] + across * (head_x[1] - head_x[0]) + over * (-0.01 - head_x[1]) + pull * (pull_to + 0.01);
  double y = 0.01 - 0.013 * down + 0.013 * up - 0.006 * pull;
  *(tx_pose*)tx_write(c, head_out) = (tx_pose){{x, y, row_z + 0.001 * over}, {1, 0, 0, 0}};
  tx_puncture* p = tx_write(c, punct_out);
  p[0] = (tx_puncture){{ENTRY, ENTRY + 1, ENTRY + SIDE}, {1, 0, 0}, 1};
  p[1] = (tx_puncture){{EXIT, EXIT + 1, EXIT + SIDE}, {1, 0, 0}, -1};
  p[2] = (tx_puncture){{-1, -1, -1}, {0, 0, 0}, 0};
  hairpin(tx_write(c, shape_out));
}

static const tx_controller_class stitch_class = {
    .type = "test.stitch", .summary = "a needle's path through a wound", .configure = stitch_configure, .step = stitch_step};

static tx_scenario* load_stitch(const char* loads, double to, const char* skin_params) {
  if (!tx_find_controller(stitch_class.type)) assert_int_equal(tx_register_controller(&stitch_class), 0);
  pull_to = to;
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"fixture\",\"type\":\"test.stitch\",\"rate_hz\":1000},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":60,\"params\":{\"hip_radius_m\":0,"
           "\"wound_a_m\":[0,0,-0.015],\"wound_b_m\":[0,0,0.015],\"thread_loads\":\"%s\"%s}},"
           "{\"name\":\"thread\",\"type\":\"physics.thread\",\"rate_hz\":1000,\"params\":{\"head\":\"hand.pose\","
           "\"nodes\":%d,\"length_m\":%g,\"pin_tail\":true,\"start_shape\":\"fixture.shape\",\"skin\":\"skin\","
           "\"punctures\":\"needle.punctures\",\"tension_n_per_m\":2000}}]}",
           loads, skin_params, NODES, LENGTH);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

typedef struct stitch {
  double gap;     // m, across the wound at the stitch at the end
  double tension; // N, the thread's at the end (its force model's F0)
  double fx[2];   // N, the loads' x components at the entry and the exit
  double load_max; // N, the largest load the skin was given
  int passed;
  double torn;    // links the skin tore
} stitch;

static stitch run_stitch(const char* loads, double to, const char* skin_params) {
  tx_scenario* s = load_stitch(loads, to, skin_params);
  if (!s) fail_msg("%s", tx_error());
  run(s, 2.0);
  stitch out = {0};
  out.gap = distance(latest_snapshot(s, "skin.x").data, EDGE_L, EDGE_R);
  const tx_force_model* m = (const tx_force_model*)latest(s, "thread.force_model");
  out.tension = sqrt(m->f0[0] * m->f0[0] + m->f0[1] * m->f0[1] + m->f0[2] * m->f0[2]);
  const tx_puncture_load* l = (const tx_puncture_load*)latest(s, "thread.puncture_loads");
  for (int k = 0; k < 2; k++) out.fx[k] = l[k].f[0];
  out.passed = (int)result(s, "thread.punctures_passed");
  out.torn = result(s, "skin.torn_links");
  out.load_max = result(s, "skin.thread_load_max_n");
  assert_int_equal(warnings(s, "skin.bad_load"), 0);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  assert_int_equal(warnings(s, "thread.numerical_fault"), 0);
  tx_scenario_free(s);
  return out;
}

// the grid as this test assumes it, and the wound's gap at rest: 2.5 mm
static void the_stitch_lies_across_the_wound(void** state) {
  (void)state;
  tx_scenario* s = load_stitch("", -0.03, "");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0 / 60);
  const float* x = latest_snapshot(s, "skin.x").data;
  assert_float_equal(x[3 * ENTRY], -0.00375, 1e-6);
  assert_float_equal(x[3 * EXIT], 0.00375, 1e-6);
  assert_float_equal(x[3 * ENTRY + 2], row_z, 1e-6);
  assert_float_equal(distance(x, EDGE_L, EDGE_R), 0.0025, 1e-6);
  tx_scenario_free(s);
}

// Drawn past taut, the stitch draws the edges together; without the loads
// (the control) the wound stays as open as it was, and the thread, held by a
// skin that does not give, is pulled to its clamp. The default skin holds the
// pull (away from the needle's tip it tears at 1000 N/m); with the tip's
// 80 N/m everywhere, as before the two criteria, the same pull tears links
// about the punctures.
static void a_stitch_drawn_tight_closes_the_wound(void** state) {
  (void)state;
  stitch on = run_stitch("thread.puncture_loads", -0.03, ""), off = run_stitch("", -0.03, ""),
         torn = run_stitch("thread.puncture_loads", -0.03, ",\"blunt_rupture_tension_n_per_m\":80");
  print_message("  with the loads: largest %.2f N; at the end tension %.2f N, loads x %.3f and %.3f N, gap %.3f mm, "
                "%g links torn\n", on.load_max, on.tension, on.fx[0], on.fx[1], on.gap * 1e3, on.torn);
  print_message("  without: tension %.2f N, gap %.3f mm (2.500 at rest), %g links torn\n", off.tension, off.gap * 1e3, off.torn);
  print_message("  at the tip's 80 N/m everywhere: largest %.2f N, gap %.3f mm, %g links torn\n", torn.load_max, torn.gap * 1e3,
                torn.torn);
  assert_int_equal(on.passed, 2);
  assert_int_equal(off.passed, 2);
  // at the end the two punctures are still pulled towards each other (x)
  assert_true(on.tension > 0 && on.fx[0] > 0 && on.fx[1] < 0);
  assert_true(on.gap < 0.5 * 0.0025 && on.torn == 0);
  assert_true(on.tension >= 1 && on.tension <= 5); // drawn to the published range of tying forces on skin
  assert_float_equal(off.gap, 0.0025, 5e-5);
  assert_true(off.tension > 9.9 && off.torn == 0); // max_force_n: 10 N
  assert_true(torn.torn > 0);
}

// --- the skin alone ------------------------------------------------------------

static tx_port loads_out, torn_in, hip_out;
static double pair_n, pair_k; // N, N/m: each load's pull and stiffness
static double pair_ramp_s = 0.2; // s, over which the pull rises from 0 to pair_n
static double pair_torn_at;      // N, the pull when the skin was first seen torn (-1: never)
static tx_torn pair_first_torn;  // the skin's count then: links, and those torn beyond the HIP's reach
static double pair_hip_r, pair_hip_at[3]; // m: the skin's HIP (0: none), held still there
static bool bad_rows;

static int pair_configure(tx_setup* s, void** self) {
  *self = NULL;
  loads_out = tx_setup_write(s, &TX_COMPONENT_OF("fixture.loads", tx_puncture_load, 5));
  torn_in = TX_READ_EXPECT(s, "skin.torn", tx_torn);
  hip_out = tx_setup_write(s, &TX_COMPONENT_OF("fixture.hip", tx_pose, 1));
  pair_torn_at = -1;
  return 0;
}

// the entry pulled towards +x and the exit towards -x, ramped in over 0.2 s;
// with bad_rows, three rows that are no triangle points of the skin after them
static void pair_step(tx_ctx* c, void* self) {
  (void)self;
  double f = pair_n * ramp((double)tx_step_index(c) * 1e-3, 0, pair_ramp_s);
  const tx_torn* torn = tx_read(c, torn_in).data;
  if (pair_torn_at < 0 && torn && torn->links > 0) pair_torn_at = f, pair_first_torn = *torn;
  *(tx_pose*)tx_write(c, hip_out) = (tx_pose){{pair_hip_at[0], pair_hip_at[1], pair_hip_at[2]}, {1, 0, 0, 0}};
  tx_puncture_load* l = tx_write(c, loads_out);
  int r = 0;
  if (bad_rows) {
    l[r++] = (tx_puncture_load){{ENTRY, ENTRY + 1, 99999}, {1, 0, 0}, {1, 0, 0}, 0};   // no such particle
    l[r++] = (tx_puncture_load){{ENTRY, ENTRY + 1, ENTRY + SIDE}, {1, 1, 0}, {1, 0, 0}, 0}; // weights summing to 2
    l[r++] = (tx_puncture_load){{ENTRY, ENTRY + 1, ENTRY + SIDE}, {1, 0, 0}, {NAN, 0, 0}, 0};
  }
  l[r++] = (tx_puncture_load){{ENTRY, ENTRY + 1, ENTRY + SIDE}, {1, 0, 0}, {f, 0, 0}, pair_k};
  l[r++] = (tx_puncture_load){{EXIT, EXIT + 1, EXIT + SIDE}, {1, 0, 0}, {-f, 0, 0}, pair_k};
  for (; r < 5; r++) l[r] = (tx_puncture_load){{-1, -1, -1}, {0, 0, 0}, {0, 0, 0}, 0};
}

static const tx_controller_class pair_class = {
    .type = "test.load_pair", .summary = "two loads across a wound", .configure = pair_configure, .step = pair_step};

static tx_scenario* load_pair(const char* skin_params) {
  if (!tx_find_controller(pair_class.type)) assert_int_equal(tx_register_controller(&pair_class), 0);
  char text[1024];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"fixture\",\"type\":\"test.load_pair\",\"rate_hz\":1000},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":60,\"params\":{\"hip_radius_m\":%g,\"pose\":\"fixture.hip\","
           "\"wound_a_m\":[0,0,-0.015],\"wound_b_m\":[0,0,0.015],\"thread_loads\":\"fixture.loads\"%s}}]}",
           pair_hip_r, skin_params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static double pair_gap(double n, double k, uint64_t* bad) {
  pair_n = n, pair_k = k;
  tx_scenario* s = load_pair("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.6);
  double gap = distance(latest_snapshot(s, "skin.x").data, EDGE_L, EDGE_R);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  *bad = warnings(s, "skin.bad_load");
  tx_scenario_free(s);
  return gap;
}

// A pair of loads across the wound closes it in proportion to the pull (the
// membrane in its plane, small strains: linear). Given as a spring (k > 0:
// the pull at the particle's place when set, falling as it moves within the
// step, which the implicit solve takes whole) it settles where the constant
// force (k = 0) does, as it must: at rest the two are the same force. Rows
// that are not the skin's are counted and left out.
static void a_pair_of_loads_closes_the_wound_in_proportion(void** state) {
  (void)state;
  uint64_t bad;
  bad_rows = false;
  double g1 = pair_gap(0.1, 0, &bad), g2 = pair_gap(0.2, 0, &bad), gs = pair_gap(0.2, 1000, &bad);
  double d1 = 0.0025 - g1, d2 = 0.0025 - g2, ds = 0.0025 - gs;
  print_message("  the gap closes by %.4f mm under 0.1 N, %.4f mm under 0.2 N (ratio %.3f); as a 1000 N/m spring of "
                "0.2 N, by %.4f mm\n", d1 * 1e3, d2 * 1e3, d2 / d1, ds * 1e3);
  assert_int_equal(bad, 0);
  assert_true(d1 > 1e-5 && fabs(d2 / d1 - 2) < 0.1);
  assert_true(fabs(ds - d2) < 0.01 * d2);
  bad_rows = true;
  double gb = pair_gap(0.2, 0, &bad);
  assert_true(bad >= 3 * 30); // three rows, every skin step of the last half second
  assert_float_equal(gb, g2, 1e-9);
  bad_rows = false;
  // a load component of another layout, one nobody writes, a radius out of range: refused, named
  assert_refused(load_pair(",\"thread_load_radius_m\":-1"), "thread_load_radius_m");
  tx_scenario* s = load_stitch("hand.pose", -0.03, "");
  assert_refused(s, "hand.pose");
  s = load_stitch("nobody.loads", -0.03, "");
  assert_refused(s, "nobody.loads");
}

// the pull at which the skin first tears (-1: not by up_to N): the pair
// ramped up at 5 N/s; with a HIP (the needle's tip) held hip_y above the
// stitch's entry, or none (0); whether the first tear was counted as a pull's
// (beyond the tip's reach)
static double pull_out(double blunt, double hip_y, double up_to, bool* pulled) {
  pair_n = up_to, pair_k = 0, pair_ramp_s = up_to / 5;
  pair_hip_r = hip_y > 0 ? 0.0005 : 0;
  pair_hip_at[0] = head_x[0], pair_hip_at[1] = hip_y, pair_hip_at[2] = row_z;
  char params[128];
  snprintf(params, sizeof params, ",\"blunt_rupture_tension_n_per_m\":%g", blunt);
  tx_scenario* s = load_pair(params);
  if (!s) fail_msg("%s", tx_error());
  run(s, pair_ramp_s);
  tx_scenario_free(s);
  pair_ramp_s = 0.2, pair_hip_r = 0;
  *pulled = pair_first_torn.pulled == pair_first_torn.links;
  assert_true(pair_first_torn.pulled == 0 || *pulled);
  return pair_torn_at;
}

// The skin's strength against the thread, which only pulls (the tip, which
// cuts, tears it at the 80 N/m of rupture_tension_n_per_m; away from the tip
// blunt_rupture_tension_n_per_m, 1000 N/m, the low end of skin's published
// 10^3 to 10^4 N/m, docs/skin.md). A stitch must hold the pull of tying, 1 to
// 5 N on skin (BJSTR 17(2), 2019), and tear out before the suture breaks: a
// knotted 3-0 polypropylene suture fails at 18.9 N (Naleway et al., J Biomed
// Mater Res B 103:735, 2015). The pull-out: the pair of loads ramped up at
// 5 N/s until the first tear. Then the stitch drawn far past tight (the
// thread to its 10 N clamp, 20 N at each puncture): the skin tears at the
// stitch, and nothing faults. Where the tip's criterion
// holds: with the needle's tip (the HIP) 3 mm above the entry, within its
// reach, the skin there tears as the tip's value says; 3 cm above, not.
static void a_stitch_holds_the_tying_pull_and_tears_out_past_it(void** state) {
  (void)state;
  bool pulled[4];
  const double out = pull_out(1000, 0, 19, &pulled[0]), out_tip = pull_out(80, 0, 5, &pulled[1]),
               tip_near = pull_out(1000, 0.003, 5, &pulled[2]), tip_far = pull_out(1000, 0.03, 19, &pulled[3]);
  stitch hard = run_stitch("thread.puncture_loads", -0.065, "");
  print_message("  the pair tears the skin at %.2f N (at %.2f N with the tip's 80 N/m everywhere); with the tip 3 mm "
                "above the entry at %.2f N, 3 cm above at %.2f N\n", out, out_tip, tip_near, tip_far);
  print_message("  drawn hard: largest %.2f N, tension %.2f N, gap %.3f mm, %g links torn\n", hard.load_max, hard.tension,
                hard.gap * 1e3, hard.torn);
  assert_true(out > 5 && out < 18.9);
  assert_true(out_tip > 0 && out_tip < 5); // what the needle's value alone would give: torn while tying
  assert_true(tip_near > 0 && tip_near < 5);
  assert_float_equal(tip_far, out, 1e-9);
  // counted as the tip's tears near it, as a pull's elsewhere (skin.torn's second column)
  assert_true(pulled[0] && pulled[1] && !pulled[2] && pulled[3]);
  assert_true(hard.torn > 0 && hard.load_max > 18.9);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(the_stitch_lies_across_the_wound),
      cmocka_unit_test(a_stitch_drawn_tight_closes_the_wound),
      cmocka_unit_test(a_pair_of_loads_closes_the_wound_in_proportion),
      cmocka_unit_test(a_stitch_holds_the_tying_pull_and_tears_out_past_it),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
