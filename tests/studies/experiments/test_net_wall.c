// The virtual wall across a network (net_wall.c): with no delay it is
// wall_stability.c's loop bit for bit; the exact boundary of the delayed loop
// (Schur-Cohn on its characteristic polynomial) agrees with tx_wall_exact_bound
// at no delay and with the simulation at every delay; a link sees every tick
// once and in order, and its answer is rendered exactly n ticks later.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "studies/experiments/net_wall.h"
#include "tactus/model.h"

#include <math.h>
#include <string.h>

// every field, bit for bit (a memcmp of the struct would compare its padding)
static void assert_same(const tx_wall_result* a, const tx_wall_result* b) {
  assert_int_equal(a->stable, b->stable);
  const double da[] = {a->energy_start, a->energy_end, a->growth_rate, a->depth_rest, a->depth_max, a->outside_s, a->observed_min};
  const double db[] = {b->energy_start, b->energy_end, b->growth_rate, b->depth_rest, b->depth_max, b->outside_s, b->observed_min};
  assert_memory_equal(da, db, sizeof da);
  assert_int_equal(a->control_ticks, b->control_ticks);
  assert_int_equal(a->clamped_ticks, b->clamped_ticks);
  assert_int_equal(a->rate_limited_ticks, b->rate_limited_ticks);
}

static tx_wall_case one_khz(void) {
  tx_wall_case c = tx_wall_case_default();
  c.device.period = 1e-3;
  return c;
}

static void no_delay_is_the_local_wall_bit_for_bit(void** state) {
  (void)state;
  tx_wall_case c = one_khz();
  const double ks[] = {200, 590, 610, 900};
  const tx_wall_pc pcs[] = {TX_WALL_PC_OFF, TX_WALL_PC_PORT, TX_WALL_PC_SPRING};
  for (size_t i = 0; i < 4; i++)
    for (size_t j = 0; j < 3; j++) {
      c.stiffness = ks[i];
      c.passivity = pcs[j];
      tx_wall_result a, b;
      assert_true(tx_wall_run(&c, &a));
      assert_true(tx_wall_run_delayed(&c, 0, NULL, &b));
      assert_same(&a, &b);
    }
}

static void the_exact_bound_without_delay_is_wall_stabilitys(void** state) {
  (void)state;
  tx_wall_case c = one_khz();
  const double dampings[] = {0, 0.15, -0.15};
  for (int i = 0; i < 3; i++) {
    double a = tx_wall_exact_bound(&c.device, dampings[i]), b = tx_net_wall_exact_bound(&c.device, dampings[i], 0);
    assert_true(a > 0);
    assert_true(fabs(b / a - 1) < 1e-6);
  }
}

// the measured boundary against the exact one, and the exact one falling with the delay
static void the_simulation_finds_the_exact_boundary_at_each_delay(void** state) {
  (void)state;
  tx_wall_case c = one_khz();
  const int ticks[] = {0, 2, 10, 40};
  double last = INFINITY;
  for (int i = 0; i < 4; i++) {
    double exact = tx_net_wall_exact_bound(&c.device, 0, ticks[i]);
    tx_wall_search s = tx_wall_largest_stable_delayed(&c, ticks[i], 1, 1e6, 0.01);
    print_message("round trip %2d ms: exact %7.1f N/m, measured %7.1f N/m\n", ticks[i], exact, s.k);
    assert_false(s.lo_unstable);
    assert_false(s.hi_stable);
    assert_true(fabs(s.k / exact - 1) < 0.05);
    assert_true(exact < last);
    last = exact;
  }
  // a round trip of 2 periods at 1 kHz: well below the 600 N/m of no delay
  assert_true(tx_net_wall_exact_bound(&c.device, 0, 2) < 200);
}

// a link that answers with the wall one tick too soft would be seen; this one
// checks the ticks and answers exactly, so the result is the local one
typedef struct tally {
  uint64_t next;
  int out_of_order;
} tally;
static int counting(void* user, uint64_t k, double K, double B, double x, double v, double* force, double* stored) {
  tally* t = user;
  if (k != t->next++) t->out_of_order++;
  tx_wall_force(K, B, x, v, force, stored);
  return 0;
}
static int failing(void* user, uint64_t k, double K, double B, double x, double v, double* force, double* stored) {
  (void)user, (void)K, (void)B, (void)x, (void)v, (void)force, (void)stored;
  if (k < 5) {
    *force = 0, *stored = 0;
    return 0;
  }
  tx_set_error("the link broke");
  return -1;
}

static void a_link_carries_every_tick_in_order(void** state) {
  (void)state;
  tx_wall_case c = one_khz();
  c.stiffness = 25;
  c.passivity = TX_WALL_PC_PORT;
  tally t = {0};
  tx_wall_link link = {counting, &t};
  tx_wall_result here, there;
  assert_true(tx_wall_run_delayed(&c, 10, NULL, &here));
  assert_true(tx_wall_run_delayed(&c, 10, &link, &there));
  assert_int_equal(t.next, 10000);
  assert_int_equal(t.out_of_order, 0);
  assert_same(&here, &there);
  // the delay is really there: another delay gives another result
  tx_wall_result other;
  assert_true(tx_wall_run_delayed(&c, 12, NULL, &other));
  assert_true(memcmp(&here.energy_end, &other.energy_end, sizeof(double)) != 0);
  tx_wall_link broken = {failing, NULL};
  assert_false(tx_wall_run_delayed(&c, 10, &broken, &there));
  assert_string_equal(tx_error(), "the link broke");
}

static void bad_delays_are_refused(void** state) {
  (void)state;
  tx_wall_case c = one_khz();
  tx_wall_result r;
  assert_false(tx_wall_run_delayed(&c, -1, NULL, &r));
  assert_non_null(strstr(tx_error(), "delay"));
  assert_false(tx_wall_run_delayed(&c, TX_WALL_DELAY_MAX + 1, NULL, &r));
  assert_true(isnan(tx_net_wall_exact_bound(&c.device, 0, -1)));
  c.stiffness = -1;
  assert_false(tx_wall_run_delayed(&c, 0, NULL, &r));
  assert_non_null(strstr(tx_error(), "stiffness"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(no_delay_is_the_local_wall_bit_for_bit),
      cmocka_unit_test(the_exact_bound_without_delay_is_wall_stabilitys),
      cmocka_unit_test(the_simulation_finds_the_exact_boundary_at_each_delay),
      cmocka_unit_test(a_link_carries_every_tick_in_order),
      cmocka_unit_test(bad_delays_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
