// The mouse device: what a window sets is what the haptics thread reads,
// whole (never x of one input with y of another), clamped to the workspace.
#include "controllers/haptics/device.h"
#include "controllers/haptics/device_mouse.h"

#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

static void reads_what_the_window_sets(void** state) {
  (void)state;
  tx_device_handle h;
  char err[256];
  assert_int_equal(tx_device_open("mouse", 0.001, &h, err, sizeof err), 0);
  assert_true(tx_mouse_device_open());
  tx_device_handle second;
  assert_int_equal(tx_device_open("mouse", 0.001, &second, err, sizeof err), -1); // one window, one mouse
  assert_non_null(strstr(err, "only one"));
  tx_device_state s;
  assert_true(h.backend->read(h.device, 0, &s));
  assert_true(s.quat[0] == 1);
  const double p[3] = {0.01, 0.03, -0.02};
  tx_mouse_input_set(p, 1);
  assert_true(h.backend->read(h.device, 0.001, &s));
  assert_memory_equal(s.pos, p, sizeof p);
  assert_int_equal(s.buttons, 1);
  const double q[3] = {0.02, 0.03, -0.02};
  tx_mouse_input_set(q, 0);
  assert_true(h.backend->read(h.device, 0.002, &s));
  assert_true(fabs(s.vel[0] - 10.0) < 1e-9); // 1 cm in one 1 ms tick
  const double far[3] = {5, -5, NAN};
  tx_mouse_input_set(far, 0);
  h.backend->read(h.device, 0.003, &s);
  assert_true(s.pos[0] == TX_MOUSE_WORKSPACE_M && s.pos[1] == -TX_MOUSE_WORKSPACE_M && s.pos[2] == 0);
  const double f[3] = {0.5, -1, 2};
  h.backend->write(h.device, f);
  double back[3];
  tx_mouse_force_get(back);
  assert_memory_equal(back, f, sizeof f);
  tx_device_close(&h);
  assert_false(tx_mouse_device_open());
  assert_int_equal(tx_device_open("mouse:fast", 0.001, &h, err, sizeof err), -1);
  assert_non_null(strstr(err, "mouse:fast"));
}

static atomic_bool stop;

// the window's side: inputs whose three coordinates are always (a, 2a, -a)
static void* writer(void* arg) {
  (void)arg;
  for (int k = 0; !atomic_load(&stop); k++) {
    double a = 1e-5 * (k % 10000), p[3] = {a, 2 * a, -a};
    tx_mouse_input_set(p, (uint32_t)k);
  }
  return NULL;
}

static void never_torn(void** state) {
  (void)state;
  pthread_t t;
  atomic_store(&stop, false);
  const double zero[3] = {0, 0, 0}; // the input the last test left is not of the writer's form
  tx_mouse_input_set(zero, 0);
  assert_int_equal(pthread_create(&t, NULL, writer, NULL), 0);
  double p[3];
  uint32_t buttons;
  for (int i = 0; i < 200000; i++) {
    if (!tx_mouse_input_get(p, &buttons)) continue;
    if (p[1] != 2 * p[0] || p[2] != -p[0]) {
      atomic_store(&stop, true);
      pthread_join(t, NULL);
      fail_msg("torn read: %g %g %g", p[0], p[1], p[2]);
    }
  }
  atomic_store(&stop, true);
  pthread_join(t, NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(reads_what_the_window_sets), cmocka_unit_test(never_torn)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
