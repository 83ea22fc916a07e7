// Cutting the thread: in each model the piece on the head keeps following
// it and the piece behind the cut does not (ftl: it stays where it lies;
// rod: it falls under gravity alone); a cut at the first and the last link,
// a repeated cut and an out-of-range one; the nearest link to a point; and
// stepping a cut thread never allocates.
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

static tx_thread* make(tx_thread_model model, int nodes, double length, const double dir[3]) {
  tx_thread_def d = tx_thread_def_default();
  d.model = model;
  d.nodes = nodes;
  d.length = length;
  memcpy(d.direction, dir, sizeof d.direction);
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  return t;
}

// the head moves 2 cm along +z (across the thread) in 0.2 s
static void pull_head(tx_thread* t, int steps, double from_z) {
  for (int k = 1; k <= steps; k++) {
    assert_int_equal(tx_thread_set_head(t, (double[3]){0, 0, from_z + 1e-4 * k}), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  }
}

// ftl, 41 nodes along +x, cut at link 20: nodes 0..20 follow the head at
// exactly l0, nodes 21..40 do not move at all
static void test_ftl_cut_head_piece_follows_tail_stays(void** state) {
  (void)state;
  tx_thread* t = make(TX_THREAD_FTL, 41, 0.04, (double[3]){1, 0, 0});
  double l0 = tx_thread_rest_segment(t);
  assert_int_equal(tx_thread_cut(t, 20), 1);
  assert_int_equal(tx_thread_head_piece_end(t), 20);
  double before[41][3];
  tx_thread_positions(t, &before[0][0]);
  pull_head(t, 200, 0);
  for (int i = 0; i < 20; i++) {
    const double *a = tx_thread_position(t, i), *b = tx_thread_position(t, i + 1);
    assert_true(fabs(dist(a, b) - l0) < 1e-12);
  }
  // the head's piece moves as a thread of its own length would: a 21-node,
  // 2 cm thread dragged the same way lies on it to rounding
  tx_thread* alone = make(TX_THREAD_FTL, 21, 0.02, (double[3]){1, 0, 0});
  pull_head(alone, 200, 0);
  for (int i = 0; i <= 20; i++) assert_true(dist(tx_thread_position(t, i), tx_thread_position(alone, i)) < 1e-15);
  assert_true(tx_thread_position(t, 20)[2] > 0.001); // and it went aside with the head
  tx_thread_destroy(alone);
  for (int i = 21; i < 41; i++) assert_true(dist(tx_thread_position(t, i), before[i]) < 1e-14);
  // the length is the two pieces', the cut link left out
  assert_true(fabs(tx_thread_current_length(t) - 39 * l0) < 1e-12);
  tx_thread_destroy(t);
}

// the rod hangs straight down from the head; cut at link 20 it drops its
// lower half, which falls freely (no horizontal motion as the head moves
// aside), while the upper half stays on the head within its stretch cap
static void test_rod_cut_tail_falls_head_piece_stays(void** state) {
  (void)state;
  tx_thread* t = make(TX_THREAD_ROD, 41, 0.04, (double[3]){0, -1, 0});
  double l0 = tx_thread_rest_segment(t), f[3];
  for (int k = 0; k < 50; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  tx_thread_head_force(t, f);
  double full = -f[1];
  assert_int_equal(tx_thread_cut(t, 20), 1);
  double before[41][3];
  tx_thread_positions(t, &before[0][0]);
  pull_head(t, 200, 0);
  // the upper piece: attached (every link within the cap), still near the head
  for (int i = 0; i < 20; i++) assert_true(dist(tx_thread_position(t, i), tx_thread_position(t, i + 1)) <= l0 * 1.05 * (1 + 1e-9));
  assert_true(tx_thread_position(t, 20)[1] > -0.021);
  assert_true(tx_thread_position(t, 1)[2] > 0.015); // it went aside with the head
  // the lower piece: fell about g t^2 / 2 (0.196 m in 0.2 s, less the damping), did not go aside
  for (int i = 21; i < 41; i++) {
    double dy = tx_thread_position(t, i)[1] - before[i][1];
    assert_true(dy < -0.15 && dy > -0.2);
    assert_true(fabs(tx_thread_position(t, i)[2] - before[i][2]) < 1e-9);
  }
  // the head holds half the thread now
  tx_thread_head_force(t, f);
  print_message("head force: %.3g N uncut, %.3g N cut\n", full, -f[1]);
  assert_true(full > 0 && -f[1] > 0.3 * full && -f[1] < 0.7 * full);
  tx_thread_destroy(t);
}

// a cut at the first link leaves the head alone: nothing else follows it;
// a cut at the last frees the tail node alone; a repeated cut is a no-op;
// an out-of-range one is refused with the range named
static void test_cut_first_last_repeated_and_bad(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread* t = make((tx_thread_model)model, 21, 0.02, (double[3]){1, 0, 0});
    double before[21][3], f[3];
    tx_thread_positions(t, &before[0][0]);
    assert_int_equal(tx_thread_cut(t, 0), 1);
    assert_int_equal(tx_thread_cut(t, 0), 0); // again: nothing more
    assert_int_equal(tx_thread_cut_count(t), 1);
    assert_int_equal(tx_thread_head_piece_end(t), 0);
    assert_int_equal(tx_thread_cut(t, 19), 1);
    assert_int_equal(tx_thread_cut_count(t), 2);
    assert_int_equal(tx_thread_cut(t, 20), -1);
    assert_non_null(strstr(tx_error(), "[0, 19]"));
    assert_int_equal(tx_thread_cut(t, -1), -1);
    pull_head(t, 100, 0);
    assert_true(fabs(tx_thread_position(t, 0)[2] - 0.01) < 1e-12);
    for (int i = 1; i < 21; i++) {
      for (int a = 0; a < 3; a++) assert_true(isfinite(tx_thread_position(t, i)[a]));
      // neither goes aside with the head; ftl stays put, the rod falls
      assert_true(fabs(tx_thread_position(t, i)[2] - before[i][2]) < 1e-9);
      if (model == TX_THREAD_FTL) assert_true(dist(tx_thread_position(t, i), before[i]) < 1e-14);
      else assert_true(tx_thread_position(t, i)[1] < -0.03);
    }
    tx_thread_head_force(t, f);
    assert_true(f[0] == 0 && f[1] == 0 && f[2] == 0); // the head holds nothing
    tx_thread_destroy(t);
  }
}

// ftl tension after a cut: the head's piece alone, and no pull from a pinned tail
static void test_ftl_tension_of_the_head_piece(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 11;
  d.length = 0.01;
  d.pin_tail = true;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double f[3], K[9];
  pull_head(t, 30, 0); // pulled 3 mm aside: the thread is taut against its pin
  tx_thread_tension(t, 200, 10, f, K);
  assert_true(sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) > 0.01);
  assert_int_equal(tx_thread_cut(t, 5), 1);
  pull_head(t, 10, 0.003);
  tx_thread_tension(t, 200, 10, f, K);
  assert_true(f[0] == 0 && f[1] == 0 && f[2] == 0); // the piece on the head is at its rest length
  tx_thread_destroy(t);
}

static void test_nearest_link(void** state) {
  (void)state;
  tx_thread* t = make(TX_THREAD_FTL, 11, 0.01, (double[3]){1, 0, 0});
  double at[3];
  assert_int_equal(tx_thread_nearest_link(t, (double[3]){0.0035, 0.002, 0}, at), 3);
  assert_true(fabs(at[0] - 0.0035) < 1e-15 && at[1] == 0 && at[2] == 0);
  assert_int_equal(tx_thread_nearest_link(t, (double[3]){-1, 0, 0}, NULL), 0);
  assert_int_equal(tx_thread_cut(t, 3), 1);
  int k = tx_thread_nearest_link(t, (double[3]){0.0035, 0.002, 0}, at);
  assert_true(k == 2 || k == 4); // the cut link is no longer there
  for (int i = 0; i < 10; i++) tx_thread_cut(t, i);
  assert_int_equal(tx_thread_nearest_link(t, (double[3]){0, 0, 0}, NULL), -1);
  tx_thread_destroy(t);
}

static void test_cut_and_step_never_allocate(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread* t = make((tx_thread_model)model, 100, 0.1, (double[3]){1, 0, 0});
    counting = 1;
    for (int k = 0; k < 30; k++) {
      if (k == 10) tx_thread_cut(t, 50);
      if (k == 20) tx_thread_cut(t, tx_thread_nearest_link(t, (double[3]){0.02, 0, 0}, NULL));
      tx_thread_set_head(t, (double[3]){0, 0.0005 * k, 0});
      tx_thread_step(t, 1e-3);
    }
    counting = 0;
    assert_int_equal(tx_thread_cut_count(t), 2);
    tx_thread_destroy(t);
  }
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_ftl_cut_head_piece_follows_tail_stays),
      cmocka_unit_test(test_rod_cut_tail_falls_head_piece_stays),
      cmocka_unit_test(test_cut_first_last_repeated_and_bad),
      cmocka_unit_test(test_ftl_tension_of_the_head_piece),
      cmocka_unit_test(test_nearest_link),
      cmocka_unit_test(test_cut_and_step_never_allocate),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
