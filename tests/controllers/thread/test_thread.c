// The thread core: the definition's checks, follow-the-leader (exact length,
// the head's path, FABRIK to a pinned tail), the XPBD rod (a cantilever
// against the beam's closed form, the stretch cap), and a step that never
// allocates.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/alloc_count.h"
#include "controllers/thread/thread.h"
#include "model/error.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

static double seg_len(const tx_thread* t, int i) {
  const double *a = tx_thread_position(t, i), *b = tx_thread_position(t, i + 1);
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static void refused(tx_thread_def d, const char* field) {
  assert_int_equal(tx_thread_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), field));
  assert_null(tx_thread_create(&d));
}

static void test_definition_checks(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  assert_int_equal(tx_thread_def_check(&d), 0);
  tx_thread_def b = d;
  b.nodes = 1;
  refused(b, "nodes");
  b = d, b.radius = 0;
  refused(b, "radius");
  b = d, b.length = NAN;
  refused(b, "length");
  b = d, b.model = (tx_thread_model)7;
  refused(b, "model");
  b = d, b.head[1] = 11;
  refused(b, "head[1]");
  b = d, b.direction[0] = 0;
  refused(b, "direction");
  b = d, b.youngs_modulus = -1;
  refused(b, "youngs_modulus");
  b = d, b.density = 0;
  refused(b, "density");
  b = d, b.gravity = -1;
  refused(b, "gravity");
  b = d, b.damping = INFINITY;
  refused(b, "damping");
  b = d, b.iterations = 0;
  refused(b, "iterations");
  b = d, b.max_substep = 0;
  refused(b, "max_substep");
  b = d, b.max_substeps = 0;
  refused(b, "max_substeps");
  b = d, b.max_stretch = 2;
  refused(b, "max_stretch");
  b = d, b.max_shapes = -1;
  refused(b, "max_shapes");
  b = d, b.max_triangles = -1;
  refused(b, "max_triangles");
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  assert_int_equal(tx_thread_set_head(t, (double[3]){0, NAN, 0}), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "head[1]"));
  assert_int_equal(tx_thread_step(t, 0), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "dt"));
  assert_int_equal(tx_thread_pin(t, 0, (double[3]){0, 0, 0}), TX_THREAD_BAD);
  assert_int_equal(tx_thread_pin(t, d.nodes, (double[3]){0, 0, 0}), TX_THREAD_BAD);
  tx_thread_destroy(t);
}

// the head runs along -x, then turns along +y: every segment keeps l0 to
// rounding, and the nodes pulled far enough along the second leg lie on it
static void test_ftl_keeps_length_and_takes_the_heads_path(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 41;
  d.length = 0.04; // l0 = 1 mm
  d.self_collision = false;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double head[3] = {0, 0, 0};
  for (int k = 0; k < 200; k++) { // 0.1 mm a step at 1 kHz: 0.1 m/s
    head[0] -= 1e-4;
    assert_int_equal(tx_thread_set_head(t, head), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  }
  for (int i = 0; i < d.nodes; i++) assert_true(fabs(tx_thread_position(t, i)[1]) < 1e-15);
  for (int k = 0; k < 300; k++) {
    head[1] += 1e-4;
    tx_thread_set_head(t, head);
    tx_thread_step(t, 1e-3);
  }
  double worst = 0;
  for (int i = 0; i < d.nodes - 1; i++) {
    double e = fabs(seg_len(t, i) - 0.001);
    if (e > worst) worst = e;
  }
  assert_true(worst < 1e-15);
  // the nodes pulled 15 mm or more past the corner are on the line
  // x = -0.02 to within a hundredth of a segment: the thread takes the
  // head's path (follow-the-leader cuts a corner, less the further it is
  // pulled on)
  for (int i = 0; i < 15; i++) assert_true(fabs(tx_thread_position(t, i)[0] + 0.02) < 1e-5);
  // the tail is still on the first leg, y = 0, to a tenth of a segment
  assert_true(fabs(tx_thread_position(t, 40)[1]) < 1e-4);
  assert_true(fabs(tx_thread_current_length(t) - 0.04) < 1e-14);
  tx_thread_destroy(t);
}

// a pinned tail within reach is reached, and the length stays exact
static void test_ftl_reaches_a_pinned_tail(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 21;
  d.length = 0.02;
  d.pin_tail = true;
  d.iterations = 50;
  d.self_collision = false;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  // the head swings to 1 cm from the tail, off the line: the thread bows
  tx_thread_set_head(t, (double[3]){0.01, 0.005, 0});
  for (int k = 0; k < 5; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  const double* tail = tx_thread_position(t, 20);
  assert_true(fabs(tail[0] - 0.02) < 1e-6 && fabs(tail[1]) < 1e-6 && fabs(tail[2]) < 1e-6);
  for (int i = 0; i < 20; i++) assert_true(fabs(seg_len(t, i) - 0.001) < 1e-15);
  // out of reach: the length wins, the tail is missed
  tx_thread_set_head(t, (double[3]){-0.01, 0, 0});
  tx_thread_step(t, 1e-3);
  for (int i = 0; i < 20; i++) assert_true(fabs(seg_len(t, i) - 0.001) < 1e-15);
  assert_true(tx_thread_position(t, 20)[0] < 0.0101);
  tx_thread_destroy(t);
}

// a thread laid out in ftl and turned into a rod: ftl keeps it where it lies
// (kinematic, nothing pulls), the rod then falls from the head under gravity
// from rest, about g t^2 / 2 at its free end, within the stretch cap; an
// unknown model is refused and changes nothing
static void test_set_model_ftl_to_rod(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 41;
  d.length = 0.04;
  d.bend_factor = 0;
  d.damping = 0;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  for (int k = 0; k < 50; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  assert_true(fabs(tx_thread_position(t, 40)[1]) < 1e-15);
  assert_int_equal(tx_thread_set_model(t, (tx_thread_model)7), TX_THREAD_BAD);
  assert_int_equal(tx_thread_get_def(t)->model, TX_THREAD_FTL);
  assert_int_equal(tx_thread_set_model(t, TX_THREAD_ROD), TX_THREAD_OK);
  assert_int_equal(tx_thread_get_def(t)->model, TX_THREAD_ROD);
  for (int k = 0; k < 50; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  // 0.05 s from rest: g t^2 / 2 = 12.3 mm for a free fall. A chain held at
  // one end swings down; its free end falls about that (12.4 mm: a pinned
  // chain's end outruns g a little, and the step is first order), not more
  // than 6 % beyond it, and more than half of it (it is no longer kinematic)
  double y = tx_thread_position(t, 40)[1];
  print_message("ftl then rod: end fell %.5f m\n", -y);
  assert_true(y < -0.0062 && y > -0.013);
  assert_true(tx_thread_max_strain(t) <= d.max_stretch * (1 + 1e-9));
  tx_thread_destroy(t);
}

// slack (a string on a table): a head moving back towards its pinned tail
// drags only the nodes it pulls; no segment is ever longer than l0, some are
// shorter; pulled out of reach, every segment is l0 again
static void test_ftl_slack_follows_only_when_pulled(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 41;
  d.length = 0.04; // l0 = 1 mm
  d.pin_tail = true;
  d.slack = true;
  d.iterations = 4;
  d.self_collision = false;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  // half a segment towards node 1: nothing is pulled, the first segment is slack
  tx_thread_set_head(t, (double[3]){0.0005, 0, 0});
  assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  assert_true(fabs(seg_len(t, 0) - 0.0005) < 1e-15);
  for (int i = 1; i < 40; i++) assert_true(fabs(seg_len(t, i) - 0.001) < 1e-15);
  // 1 cm back along the thread, 2 mm off it, at 1 cm/s: a bight forms near the
  // head and the far half of the thread is never pulled
  for (int k = 1; k <= 1000; k++) {
    tx_thread_set_head(t, (double[3]){0.0005 + 0.0095 * k / 1000, 0.002 * (k < 200 ? k / 200.0 : 1), 0});
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    for (int i = 0; i < 40; i++) assert_true(seg_len(t, i) <= 0.001 * (1 + 1e-12));
  }
  assert_true(tx_thread_position(t, 5)[0] < 0.006); // the bight: node 5 lies behind the head
  for (int i = 20; i <= 40; i++) { // to 1 nm: a leader l0 away to rounding may pull
    const double* x = tx_thread_position(t, i);
    assert_true(fabs(x[0] - 0.001 * i) < 1e-9 && fabs(x[1]) < 1e-9 && fabs(x[2]) < 1e-9);
  }
  tx_thread_set_head(t, (double[3]){-0.01, 0, 0});
  assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  for (int i = 0; i < 40; i++) assert_true(fabs(seg_len(t, i) - 0.001) < 1e-15);
  tx_thread_destroy(t);
}

// a horizontal cantilever under its weight, clamped by pinning its first two
// nodes: the tip sags q L^4 / (8 E I) (Euler-Bernoulli, small deflection)
static void test_rod_cantilever_matches_the_beam(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 41;
  d.length = 0.04;
  d.youngs_modulus = 2e9;
  d.damping = 30;
  d.self_collision = false;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  assert_int_equal(tx_thread_pin(t, 1, tx_thread_position(t, 1)), TX_THREAD_OK);
  for (int k = 0; k < 1000; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  double r = d.radius, q = d.density * PI * r * r * d.gravity, ei = d.youngs_modulus * PI * pow(r, 4) / 4;
  // the clamp sits between nodes 0 and 1: the beam is l0 / 2 shorter
  double len = d.length - 0.5 * tx_thread_rest_segment(t);
  double want = q * pow(len, 4) / (8 * ei), got = -tx_thread_position(t, 40)[1];
  print_message("cantilever tip sag %.4g m, beam %.4g m\n", got, want);
  assert_true(fabs(got - want) < 0.05 * want);
  tx_thread_destroy(t);
}

// a soft rod hanging by its head: its weight would stretch it past the cap;
// with the cap no segment is longer than l0 (1 + max_stretch)
static void test_rod_stretch_cap(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 21;
  d.length = 0.2;
  d.direction[0] = 0, d.direction[1] = -1;
  d.youngs_modulus = 2e3; // E A = 4e-4 N: the weight (4e-4 N) doubles the top segment
  d.damping = 10;
  d.self_collision = false;
  double strain[2];
  for (int capped = 0; capped < 2; capped++) {
    d.max_stretch = capped ? 0.05 : 1;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    for (int k = 0; k < 1000; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    strain[capped] = tx_thread_max_strain(t);
    tx_thread_destroy(t);
  }
  print_message("hanging soft rod: strain %.3g free, %.3g capped\n", strain[0], strain[1]);
  assert_true(strain[0] > 0.2);
  assert_true(strain[1] <= 0.05 + 1e-12);
  assert_true(strain[1] > 0.04);
}

// the cap holds the link into a pin too: a zigzag (links 2.25 l0 long) laid
// between the head and a pinned tail 1.04 of the rest length apart (within
// reach at a 5 % cap): after each step no link, the one into the pin
// included, is stretched past the cap. (From a zigzag of links 4.1 times
// their rest length it does not hold yet: 0.43 after the first step.)
static void test_rod_stretch_cap_into_a_pin(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 21;
  d.length = 0.02;
  d.pin_tail = true;
  d.gravity = 0;
  d.self_collision = false;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double x[63], span = 1.04 * d.length;
  for (int i = 0; i < 21; i++) x[3 * i] = span * i / 20, x[3 * i + 1] = i % 2 && i < 20 ? 0.002 : 0, x[3 * i + 2] = 0;
  assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
  for (int k = 0; k < 3; k++) {
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    print_message("zigzag between pins, step %d: largest strain %.4f (cap %.2f)\n", k, tx_thread_max_strain(t), d.max_stretch);
    assert_true(tx_thread_max_strain(t) <= d.max_stretch + 1e-9);
  }
  const double* tail = tx_thread_position(t, 20);
  assert_true(fabs(tail[0] - span) < 1e-12 && fabs(tail[1]) < 1e-12); // the pin held
  tx_thread_destroy(t);
}

// the rod hangs straight down from its head and the tail comes to rest a
// length below it; a rod swung by the head damps out
static void test_rod_hangs_from_the_head(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 21;
  d.length = 0.1;
  d.damping = 5;
  tx_thread* t = tx_thread_create(&d); // horizontal at first
  assert_non_null(t);
  for (int k = 0; k < 4000; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  const double* tail = tx_thread_position(t, 20);
  assert_true(fabs(tail[1] + 0.1) < 1e-3);
  assert_true(fabs(tail[0]) < 1e-3);
  assert_true(fabs(tx_thread_current_length(t) - 0.1) < 1e-4);
  tx_thread_destroy(t);
}

static void test_step_never_allocates(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = 100;
    d.length = 0.1;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    counting = 1;
    for (int k = 0; k < 50; k++) {
      tx_thread_set_head(t, (double[3]){0, 0.0005 * k, 0});
      tx_thread_step(t, 1e-3);
    }
    counting = 0;
    tx_thread_destroy(t);
  }
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_definition_checks),
      cmocka_unit_test(test_ftl_keeps_length_and_takes_the_heads_path),
      cmocka_unit_test(test_ftl_reaches_a_pinned_tail),
      cmocka_unit_test(test_ftl_slack_follows_only_when_pulled),
      cmocka_unit_test(test_set_model_ftl_to_rod),
      cmocka_unit_test(test_rod_cantilever_matches_the_beam),
      cmocka_unit_test(test_rod_stretch_cap),
      cmocka_unit_test(test_rod_stretch_cap_into_a_pin),
      cmocka_unit_test(test_rod_hangs_from_the_head),
      cmocka_unit_test(test_step_never_allocates),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
