// A tight stitch closes the wound: physics.thread's pull at its punctures
// (thread.puncture_loads) on physics.skin's particles (thread_loads). A
// fixture stands for the needle: it drives the thread's head down through
// one edge of a 3 cm wound, under it and up through the other edge, then
// over the wound and along it, as a throw drawn tight; the thread's tail is
// pinned 3 mm above the wound's middle, where a knot would sit (a hairpin
// start shape keeps the thread slack until the pull). The gap across the
// wound at the stitch is read from the skin at the end, with the loads and,
// as a control, without them.
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
#define ROW 20                        // z = -1.25 mm: the stitch's row
#define ENTRY (ROW * SIDE + 19)       // x = -3.75 mm: a 3.75 mm bite on the -x edge
#define EXIT (ROW * SIDE + 22)        // x = +3.75 mm: and on the +x edge
#define EDGE_L (ROW * SIDE + 20)      // x = -1.25 mm and +1.25 mm: the wound's edges there (the cut at x = 0)
#define EDGE_R (ROW * SIDE + 21)
#define NODES 21
#define LENGTH 0.04

static tx_port head_out, punct_out, shape_out;
static double head_x[2] = {FIRST + 19 * SPACING, FIRST + 22 * SPACING}, row_z = FIRST + ROW * SPACING;
static double pull_to; // m, the head's x at the end of the pull // m, the head's height at the end of the pull

static int fixture_configure(tx_setup* s, void** self) {
  *self = NULL;
  head_out = tx_setup_write(s, &TX_COMPONENT_OF("hand.pose", tx_pose, 1));
  punct_out = tx_setup_write(s, &TX_COMPONENT_OF("needle.punctures", tx_puncture, 3));
  shape_out = tx_setup_write(s, &TX_COMPONENT_OF("fixture.shape", tx_thread_node, NODES));
  return 0;
}

static double ramp(double t, double t0, double t1) { return fmin(1, fmax(0, (t - t0) / (t1 - t0))); }

// the start shape: from the head up, across to the wound's middle and down to
// 3 mm above it (the knot's place, where the tail is pinned), sampled a link apart
static void hairpin(double out[NODES][3]) {
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
    out[i][0] = corner[leg][0] + f * (corner[leg + 1][0] - corner[leg][0]);
    out[i][1] = corner[leg][1] + f * (corner[leg + 1][1] - corner[leg][1]);
    out[i][2] = row_z;
  }
}

static void fixture_step(tx_ctx* c, void* self) {
  (void)self;
  double t = (double)tx_step_index(c) * 1e-3;
  // down through the entry, under the wound, up through the exit, over to the
  // entry's side, then the pull along -x, as a throw drawn tight over the wound
  double down = ramp(t, 0, 0.3), across = ramp(t, 0.3, 0.6), up = ramp(t, 0.6, 0.9), over = ramp(t, 0.9, 1.2),
         pull = ramp(t, 1.2, 2.4);
  double x = head_x[0] + across * (head_x[1] - head_x[0]) + over * (-0.01 - head_x[1]) + pull * (pull_to + 0.01);
  double y = 0.01 - 0.013 * down + 0.013 * up - 0.006 * pull;
  *(tx_pose*)tx_write(c, head_out) = (tx_pose){{x, y, row_z + 0.001 * over}, {1, 0, 0, 0}};
  tx_puncture* p = tx_write(c, punct_out);
  p[0] = (tx_puncture){{ENTRY, ENTRY + 1, ENTRY + SIDE}, {1, 0, 0}, 1};
  p[1] = (tx_puncture){{EXIT, EXIT + 1, EXIT + SIDE}, {1, 0, 0}, -1};
  p[2] = (tx_puncture){{-1, -1, -1}, {0, 0, 0}, 0};
  tx_thread_node* n = tx_write(c, shape_out);
  double shape[NODES][3];
  hairpin(shape);
  for (int i = 0; i < NODES; i++) n[i] = (tx_thread_node){{shape[i][0], shape[i][1], shape[i][2]}, 0.00025};
}

static const tx_controller_class fixture_class = {
    .type = "test.stitch", .summary = "a needle's path through a wound", .configure = fixture_configure, .step = fixture_step};

static tx_scenario* load(const char* loads, double top) {
  if (!tx_find_controller(fixture_class.type)) assert_int_equal(tx_register_controller(&fixture_class), 0);
  pull_to = top;
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"fixture\",\"type\":\"test.stitch\",\"rate_hz\":1000},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":60,\"params\":{\"hip_radius_m\":0,"
           "\"wound_a_m\":[0,0,-0.015],\"wound_b_m\":[0,0,0.015],\"thread_loads\":\"%s\",\"thread_load_radius_m\":0.004}},"
           "{\"name\":\"thread\",\"type\":\"physics.thread\",\"rate_hz\":1000,\"params\":{\"head\":\"hand.pose\","
           "\"nodes\":%d,\"length_m\":%g,\"pin_tail\":true,\"start_shape\":\"fixture.shape\",\"skin\":\"skin\","
           "\"punctures\":\"needle.punctures\",\"tension_n_per_m\":200}}]}",
           loads, NODES, LENGTH);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static double distance(const float* x, int i, int j) {
  double d = 0;
  for (int a = 0; a < 3; a++) d += pow((double)x[3 * i + a] - x[3 * j + a], 2);
  return sqrt(d);
}

typedef struct stitch {
  double gap;        // m, across the wound at the stitch at the end
  double tension;    // N, the thread's at the end (its force model's F0)
  double fx[2];      // N, the loads' x components at the entry and the exit
  double fy[2];      // N, and their y components
  int passed;
  double torn;       // links the skin tore
} stitch;

static stitch run_stitch(const char* loads, double top) {
  tx_scenario* s = load(loads, top);
  if (!s) fail_msg("%s", tx_error());
  run(s, 2.5);
  stitch out = {0};
  const float* x = latest_snapshot(s, "skin.x").data;
  out.gap = distance(x, EDGE_L, EDGE_R);
  const tx_force_model* m = (const tx_force_model*)latest(s, "thread.force_model");
  out.tension = sqrt(m->f0[0] * m->f0[0] + m->f0[1] * m->f0[1] + m->f0[2] * m->f0[2]);
  const tx_puncture_load* l = (const tx_puncture_load*)latest(s, "thread.puncture_loads");
  for (int k = 0; k < 2; k++) out.fx[k] = l[k].f[0], out.fy[k] = l[k].f[1];
  out.passed = (int)result(s, "thread.punctures_passed");
  out.torn = result(s, "skin.torn_links");
  assert_int_equal(warnings(s, "skin.bad_load"), 0);
  assert_int_equal(warnings(s, "skin.numerical_fault"), 0);
  assert_int_equal(warnings(s, "thread.numerical_fault"), 0);
  tx_scenario_free(s);
  return out;
}

// the grid as this test assumes it, and the wound's gap at rest: 2.5 mm
static void the_stitch_lies_across_the_wound(void** state) {
  (void)state;
  tx_scenario* s = load("", 0.01);
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.0 / 60);
  const float* x = latest_snapshot(s, "skin.x").data;
  assert_float_equal(x[3 * ENTRY], -0.00375, 1e-6);
  assert_float_equal(x[3 * EXIT], 0.00375, 1e-6);
  assert_float_equal(x[3 * ENTRY + 2], row_z, 1e-6);
  assert_float_equal(distance(x, EDGE_L, EDGE_R), 0.0025, 1e-6);
  tx_scenario_free(s);
}

// pulled tight, the stitch draws the edges together; without the loads
// (the control) the wound stays open as wide as it was
static void a_tight_stitch_closes_the_wound(void** state) {
  (void)state;
  stitch on = run_stitch("thread.puncture_loads", -0.033), off = run_stitch("", -0.033);
  print_message("  with the loads: tension %.2f N, entry (%.2f, %.2f) N, exit (%.2f, %.2f) N, gap %.3f mm, %g links torn\n",
                on.tension, on.fx[0], on.fy[0], on.fx[1], on.fy[1], on.gap * 1e3, on.torn);
  print_message("  without: tension %.2f N, gap %.3f mm (2.500 at rest), %g links torn\n", off.tension, off.gap * 1e3, off.torn);
  assert_int_equal(on.passed, 2);
  assert_int_equal(off.passed, 2);
  // the two punctures pulled towards each other across the wound (x), equal
  // and opposite: the stitch's pull across the wound is its own
  assert_true(on.fx[0] > 0.5 && on.fx[1] < -0.5);
  assert_true(fabs(on.fx[0] + on.fx[1]) <= 0.05 * on.fx[0]);
  assert_true(on.gap < 0.7 * 0.0025);
  assert_float_equal(off.gap, 0.0025, 5e-5);
  assert_true(off.torn == 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(the_stitch_lies_across_the_wound),
      cmocka_unit_test(a_tight_stitch_closes_the_wound),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
