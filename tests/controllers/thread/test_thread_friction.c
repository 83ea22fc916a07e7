// Friction in the rod's contacts with itself (self_friction, Coulomb): a
// limp piece of thread draped across a pinned piece inclined at 20 degrees
// (tan = 0.36) slides down it without friction and holds with a
// coefficient above the slope's tangent, as a block on an inclined plane;
// the coefficient is range-checked.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/thread/thread.h"
#include "model/error.h"

#include <math.h>
#include <string.h>

#define N 42 // nodes 0..20: the pinned piece; link 20 cut; 21..41: the draped piece

// how far (m) the draped piece's middle node goes along the incline in 0.3 s
static double slide(double mu) {
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = N;
  d.length = 0.001 * (N - 1);
  d.bend_factor = 0;
  d.damping = 5;
  d.self_friction = mu;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double th = 20 * 3.14159265358979323846 / 180, u[3] = {cos(th), -sin(th), 0}, x[3 * N];
  for (int i = 0; i <= 20; i++)
    for (int a = 0; a < 3; a++) x[3 * i + a] = u[a] * 0.001 * i;
  // across node 10, along z, 2 r + 1 um above the incline (along its normal)
  double nrm[3] = {sin(th), cos(th), 0}, c[3];
  for (int a = 0; a < 3; a++) c[a] = u[a] * 0.010 + nrm[a] * (2 * d.radius + 1e-6);
  for (int i = 21; i < N; i++) {
    double z = 0.001 * (i - 31) + 0.0005;
    for (int a = 0; a < 3; a++) x[3 * i + a] = c[a] + (a == 2 ? z : 0);
  }
  assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
  assert_int_equal(tx_thread_cut(t, 20), 1);
  for (int i = 1; i <= 20; i++) assert_int_equal(tx_thread_pin(t, i, x + 3 * i), TX_THREAD_OK);
  for (int k = 0; k < 300; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  const double* p = tx_thread_position(t, 31);
  double along = 0;
  for (int a = 0; a < 3; a++) along += (p[a] - c[a]) * u[a];
  tx_thread_destroy(t);
  return along;
}

static void test_friction_holds_on_a_slope(void** state) {
  (void)state;
  double free = slide(0), low = slide(0.2), held = slide(1);
  print_message("along the 20-degree incline in 0.3 s: mu 0: %.2f mm, mu 0.2: %.2f mm, mu 1: %.3f mm\n", free * 1e3,
                low * 1e3, held * 1e3);
  assert_true(free > 0.002);          // slides down (+u is downhill)
  assert_true(low > 0.3 * free);      // below tan 20 = 0.36: still slides
  assert_true(fabs(held) < 0.05 * free); // above it: holds
}

static void test_friction_range(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.self_friction = -0.1;
  assert_int_not_equal(tx_thread_def_check(&d), 0);
  assert_non_null(strstr(tx_error(), "self_friction"));
  d.self_friction = NAN;
  assert_int_not_equal(tx_thread_def_check(&d), 0);
  d.self_friction = 10;
  assert_int_equal(tx_thread_def_check(&d), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_friction_holds_on_a_slope),
      cmocka_unit_test(test_friction_range),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
