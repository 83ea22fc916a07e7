// Force rendering: the local model follows the hand, sample-and-hold does not.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/haptics/render.h"

#include <math.h>

// a wall along +y with stiffness 500 N/m: K = -500 n n^T
static tx_force_model wall(void) {
  tx_force_model m = {.f0 = {0, 1.0, 0}, .x0 = {0, -0.002, 0}};
  m.k[4] = -500;
  return m;
}

static void local_model_follows_the_hand(void** state) {
  (void)state;
  tx_force_model m = wall();
  double x[3] = {0.01, -0.003, 0.02}, f[3];
  tx_render_force(&m, TX_RENDER_LOCAL_MODEL, x, f);
  assert_true(fabs(f[1] - 1.5) < 1e-12); // 1 mm deeper: +0.5 N
  assert_true(f[0] == 0 && f[2] == 0);   // tangential motion changes nothing
  x[1] = -0.002;
  tx_render_force(&m, TX_RENDER_LOCAL_MODEL, x, f);
  assert_true(fabs(f[1] - 1.0) < 1e-12);
}

static void sample_and_hold_repeats_f0(void** state) {
  (void)state;
  tx_force_model m = wall();
  double x[3] = {0, -0.010, 0}, f[3];
  tx_render_force(&m, TX_RENDER_SAMPLE_HOLD, x, f);
  assert_true(f[0] == 0 && f[1] == 1.0 && f[2] == 0);
}

static void full_stiffness_matrix(void** state) {
  (void)state;
  tx_force_model m = {0};
  for (int i = 0; i < 9; i++) m.k[i] = i + 1;
  double x[3] = {1, 2, 3}, f[3];
  tx_render_force(&m, TX_RENDER_LOCAL_MODEL, x, f);
  assert_true(f[0] == 14 && f[1] == 32 && f[2] == 50);
}

static void coupling_pulls_device_to_tool(void** state) {
  (void)state;
  double tool_x[3] = {0.01, 0, 0}, tool_v[3] = {0, 0, 0}, x[3] = {0, 0, 0}, v[3] = {0.1, 0, 0}, f[3];
  tx_render_coupling(200, 2, tool_x, tool_v, x, v, f);
  assert_true(fabs(f[0] - (2.0 - 0.2)) < 1e-12);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(local_model_follows_the_hand),
      cmocka_unit_test(sample_and_hold_repeats_f0),
      cmocka_unit_test(full_stiffness_matrix),
      cmocka_unit_test(coupling_pulls_device_to_tool),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
