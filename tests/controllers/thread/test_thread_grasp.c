// Jaws holding the thread (tx_thread_hold): in ftl the held node is where
// the jaws are, exactly, and the thread behind it follows it at l0; in the
// rod it is pinned, drags the thread and, let go, moves on and falls; bad
// nodes and points are refused; holding never allocates.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/alloc_count.h"
#include "controllers/thread/thread.h"
#include "model/error.h"

#include <math.h>
#include <string.h>

static double dist(const double* a, const double* b) {
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static tx_thread* make(tx_thread_model model, int nodes, double length) {
  tx_thread_def d = tx_thread_def_default();
  d.model = model;
  d.nodes = nodes;
  d.length = length;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  return t;
}

// ftl, 41 nodes of 1 mm along +x from a still head: node 30 is held and
// taken 5 mm back towards the head and 5 mm along +z in 50 steps. It is
// at the jaws at every step; the ten links behind it stay at l0 and follow
// its path (ftl from the held node: node 33, 3 mm behind, is off the line
// by nearly what the path is); the links between the head and it keep l0
// within 0.2 % after the passes from both ends (1e-3 at 2 passes a step). Let go, it follows the thread again.
static void test_ftl_held_node_leads_the_tail(void** state) {
  (void)state;
  tx_thread* t = make(TX_THREAD_FTL, 41, 0.04);
  double l0 = tx_thread_rest_segment(t), tail0[3], worst_at = 0, worst_behind = 0;
  memcpy(tail0, tx_thread_position(t, 40), sizeof tail0);
  assert_false(tx_thread_is_held(t, 30));
  for (int k = 1; k <= 50; k++) {
    double to[3] = {0.03 - 1e-4 * k, 0, 1e-4 * k};
    assert_int_equal(tx_thread_hold(t, 30, to), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    worst_at = fmax(worst_at, dist(tx_thread_position(t, 30), to));
    for (int i = 30; i < 40; i++)
      worst_behind = fmax(worst_behind, fabs(dist(tx_thread_position(t, i), tx_thread_position(t, i + 1)) - l0));
  }
  assert_true(tx_thread_is_held(t, 30));
  double worst_before = 0;
  for (int i = 0; i < 30; i++)
    worst_before = fmax(worst_before, fabs(dist(tx_thread_position(t, i), tx_thread_position(t, i + 1)) - l0));
  const double *tail = tx_thread_position(t, 40), *n33 = tx_thread_position(t, 33);
  print_message("ftl hold: at the jaws %.1e m, links behind %.1e m, before %.1e m; node 33 at z %.2f mm, the tail %.2f mm\n",
                worst_at, worst_behind, worst_before, n33[2] * 1e3, (tail[2] - tail0[2]) * 1e3);
  assert_true(worst_at < 1e-12);
  assert_true(worst_behind < 1e-12);
  assert_true(worst_before < 2e-3 * l0);
  // the held node went 7.1 mm along (-1, 0, 1): 3 mm behind it on that path is z = 2.9 mm
  assert_true(n33[2] > 0.0025 && n33[2] < 0.0031);
  // let go: the head pulls the thread along -x, and the node goes with it
  assert_int_equal(tx_thread_release(t, 30), TX_THREAD_OK);
  assert_false(tx_thread_is_held(t, 30));
  double was[3];
  memcpy(was, tx_thread_position(t, 30), sizeof was);
  for (int k = 1; k <= 50; k++) {
    assert_int_equal(tx_thread_set_head(t, (double[3]){-2e-4 * k, 0, 0}), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  }
  assert_true(dist(tx_thread_position(t, 30), was) > 0.005);
  for (int i = 0; i < 40; i++)
    assert_true(fabs(dist(tx_thread_position(t, i), tx_thread_position(t, i + 1)) - l0) < 1e-12);
  tx_thread_destroy(t);
}

// rod, 21 nodes of 1 mm along +x, gravity on: the tail (node 20) held
// where it lies while the rod settles, then raised 5 mm in 50 steps. The
// held node is at the jaws at every step (pinned), the nodes next to it
// rise with it, and the rod keeps within its stretch cap; let go, the
// bent rod springs it back down.
static void test_rod_held_node_drags_and_lets_go(void** state) {
  (void)state;
  tx_thread* t = make(TX_THREAD_ROD, 21, 0.02);
  double start[3], worst_at = 0;
  memcpy(start, tx_thread_position(t, 20), sizeof start);
  for (int k = 0; k < 200; k++) {
    assert_int_equal(tx_thread_hold(t, 20, start), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  }
  double y18 = tx_thread_position(t, 18)[1];
  for (int k = 1; k <= 50; k++) {
    double to[3] = {start[0], start[1] + 1e-4 * k, start[2]};
    assert_int_equal(tx_thread_hold(t, 20, to), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    worst_at = fmax(worst_at, dist(tx_thread_position(t, 20), to));
  }
  double rise18 = tx_thread_position(t, 18)[1] - y18;
  print_message("rod hold: at the jaws %.1e m, node 18 rose %.2f mm, strain %.3f\n", worst_at, rise18 * 1e3,
                tx_thread_max_strain(t));
  assert_true(worst_at < 1e-12);
  assert_true(rise18 > 0.003);
  assert_true(tx_thread_max_strain(t) <= tx_thread_get_def(t)->max_stretch + 1e-9);
  assert_int_equal(tx_thread_release(t, 20), TX_THREAD_OK);
  assert_false(tx_thread_pin_of(t, 20, (double[3]){0, 0, 0}));
  double y0 = tx_thread_position(t, 20)[1];
  for (int k = 0; k < 150; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  double y1 = tx_thread_position(t, 20)[1];
  print_message("let go: the tail moved %.2f mm in 0.15 s\n", (y1 - y0) * 1e3);
  assert_true(y1 < y0 - 0.003);
  tx_thread_destroy(t);
}

static void test_bad_holds_are_refused(void** state) {
  (void)state;
  tx_thread* t = make(TX_THREAD_FTL, 11, 0.01);
  double p[3] = {0, 0, 0};
  assert_int_equal(tx_thread_hold(t, 0, p), TX_THREAD_BAD); // the head is on its own pose
  assert_non_null(strstr(tx_error(), "hold node 0"));
  assert_int_equal(tx_thread_hold(t, 11, p), TX_THREAD_BAD);
  assert_int_equal(tx_thread_hold(t, 5, (double[3]){NAN, 0, 0}), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "hold"));
  assert_false(tx_thread_is_held(t, 5));
  assert_int_equal(tx_thread_release(t, 12), TX_THREAD_BAD);
  assert_int_equal(tx_thread_release(t, 5), TX_THREAD_OK); // not held: nothing to do
  // a pinned tail held and let go stays pinned
  tx_thread_pin(t, 10, tx_thread_position(t, 10));
  assert_int_equal(tx_thread_hold(t, 10, (double[3]){0.01, 0.001, 0}), TX_THREAD_OK);
  tx_thread_step(t, 1e-3);
  assert_int_equal(tx_thread_release(t, 10), TX_THREAD_OK);
  double pin[3];
  assert_true(tx_thread_pin_of(t, 10, pin));
  tx_thread_destroy(t);
}

static void test_hold_never_allocates(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread* t = make((tx_thread_model)model, 100, 0.1);
    counting = 1;
    for (int k = 0; k < 30; k++) {
      if (k < 20) tx_thread_hold(t, 60, (double[3]){0.06, 0.0002 * k, 0});
      if (k == 20) tx_thread_release(t, 60);
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
      cmocka_unit_test(test_ftl_held_node_leads_the_tail),
      cmocka_unit_test(test_rod_held_node_drags_and_lets_go),
      cmocka_unit_test(test_bad_holds_are_refused),
      cmocka_unit_test(test_hold_never_allocates),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
