// The mouse device: it reads what it is fed from window.pointer (the model),
// clamped to its workspace, and keeps its start until the first input.
#include "model/error.h"
#include "controllers/haptics/device.h"
#include "controllers/haptics/device_mouse.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

static void reads_what_it_is_fed(void** state) {
  (void)state;
  tx_device_handle h;
  assert_int_equal(tx_device_open("mouse", 0.001, &h), 0);
  // its input is a model component of the pointer's layout, fed by the haptics controller
  assert_string_equal(h.backend->input, "window.pointer");
  assert_non_null(h.backend->feed);
  tx_device_state s;
  h.backend->feed(h.device, NULL); // nothing published yet: the start, 2 cm up
  assert_true(h.backend->read(h.device, 0, &s));
  assert_true(s.quat[0] == 1);
  assert_true(s.pos[0] == 0 && s.pos[1] == TX_MOUSE_START_Y_M && s.pos[2] == 0);
  tx_pointer p = {{0.01, 0.03, -0.02}, 1};
  h.backend->feed(h.device, &p);
  assert_true(h.backend->read(h.device, 0.001, &s));
  assert_memory_equal(s.pos, p.pos, sizeof p.pos);
  assert_int_equal(s.buttons, 1);
  tx_pointer q = {{0.02, 0.03, -0.02}, 0};
  h.backend->feed(h.device, &q);
  assert_true(h.backend->read(h.device, 0.002, &s));
  assert_true(fabs(s.vel[0] - 10.0) < 1e-9); // 1 cm in one 1 ms tick
  assert_int_equal(s.buttons, 0);
  h.backend->feed(h.device, NULL); // a tick without a new publish holds the last input
  assert_true(h.backend->read(h.device, 0.003, &s));
  assert_memory_equal(s.pos, q.pos, sizeof q.pos);
  tx_pointer far = {{5, -5, NAN}, -3};
  h.backend->feed(h.device, &far);
  h.backend->read(h.device, 0.004, &s);
  assert_true(s.pos[0] == TX_POINTER_REACH_M && s.pos[1] == -TX_POINTER_REACH_M && s.pos[2] == 0);
  assert_int_equal(s.buttons, 0);
  const double f[3] = {0.5, -1, 2};
  h.backend->write(h.device, f); // no motors: accepted and shown through deviceN.force
  tx_device_close(&h);
  assert_int_equal(tx_device_open("mouse:fast", 0.001, &h), -1);
  assert_non_null(strstr(tx_error(), "mouse:fast"));
}

// the other devices take no input from the model
static void other_devices_have_no_model_input(void** state) {
  (void)state;
  tx_device_handle h;
  assert_int_equal(tx_device_open("sim", 0.001, &h), 0);
  assert_null(h.backend->input);
  tx_device_close(&h);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(reads_what_it_is_fed),
                                     cmocka_unit_test(other_devices_have_no_model_input)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
