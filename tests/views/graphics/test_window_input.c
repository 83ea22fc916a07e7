// The window's input reaches the model through input.window (not through the
// view, which only reads): what the window sets is published whole as
// window.pointer, and the mouse device, fed by the haptics controller, puts
// the tool there.
#include "model/error.h"
#include "scenarios/loader.h"
#include "views/graphics/window_input.h"

#include <tactus/components.h>

#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

static atomic_bool stop;

// the window's side: inputs whose three coordinates are always (a, 2a, -a)
static void* writer(void* arg) {
  (void)arg;
  for (int k = 0; !atomic_load(&stop); k++) {
    double a = 1e-5 * (k % 10000), p[3] = {a, 2 * a, -a};
    tx_window_input_set(p, (uint32_t)k);
  }
  return NULL;
}

static void never_torn(void** state) {
  (void)state;
  pthread_t t;
  atomic_store(&stop, false);
  tx_window_input_reset();
  double p[3];
  uint32_t buttons;
  assert_false(tx_window_input_get(p, &buttons)); // nothing until the window sets one
  assert_int_equal(pthread_create(&t, NULL, writer, NULL), 0);
  for (int i = 0; i < 200000; i++) {
    if (!tx_window_input_get(p, &buttons)) continue;
    if (p[1] != 2 * p[0] || p[2] != -p[0]) {
      atomic_store(&stop, true);
      pthread_join(t, NULL);
      fail_msg("torn read: %g %g %g", p[0], p[1], p[2]);
    }
  }
  atomic_store(&stop, true);
  pthread_join(t, NULL);
}

// stands in for the window: moves the pointer once, at step 20 (20 ms)
static int hand_configure(tx_setup* s, void** self) {
  (void)s;
  *self = NULL;
  return 0;
}
static void hand_step(tx_ctx* c, void* self) {
  (void)self;
  if (tx_step_index(c) == 20) tx_window_input_set((double[3]){0.05, 0.07, 0.5}, 3); // z beyond reach: clamped
}
static const tx_controller_class hand_class = {
    .type = "test.window_hand", .summary = "sets the window's input once", .configure = hand_configure, .step = hand_step};

static char load_err[1024];

static tx_scenario* load(const char* view) {
  if (!tx_find_controller(hand_class.type)) assert_int_equal(tx_register_controller(&hand_class), 0);
  static const char text[] =
      "{\"name\":\"w\",\"controllers\":[{\"name\":\"hand\",\"type\":\"test.window_hand\",\"rate_hz\":1000},"
      "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"mouse\",\"record\":false}}]}";
  tx_load_options o = {.view = view};
  load_err[0] = 0;
  return tx_scenario_load_text("window.json", text, strlen(text), &o);
}

static void the_mouse_goes_through_the_model(void** state) {
  (void)state;
  // without a window nothing writes window.pointer: the mouse device cannot be loaded
  assert_null(load(NULL));
  assert_non_null(strstr(tx_error(), "window.pointer"));
  // "none" checks the view but adds nothing: no window, no pointer either
  assert_null(load("none"));
  assert_non_null(strstr(tx_error(), "window.pointer"));
}

// with a window: input.window is added, publishes window.pointer once the window has
// input, and the haptics controller's mouse device follows it (the view itself is not
// run here: input.window and the device are what this test is about)
static void the_pointer_moves_the_tool(void** state) {
  (void)state;
  tx_register_builtin();
  const tx_controller_class* in = tx_find_controller("input.window");
  assert_non_null(in);
  assert_false(in->view); // it writes: an ordinary controller, not a view
  // a system with the input, the hand and haptics, as the loader builds it for --view window
  tx_system* s = tx_system_create();
  if (!tx_find_controller(hand_class.type)) assert_int_equal(tx_register_controller(&hand_class), 0);
  json_t* hp = json_pack("{s:s, s:b}", "device", "mouse", "record", 0);
  assert_int_equal(tx_system_add(s, "window_input", "input.window", TX_WINDOW_INPUT_HZ, NULL), 0);
  assert_int_equal(tx_system_add(s, "hand", "test.window_hand", 1000, NULL), 0);
  if (tx_system_add(s, "haptics", "haptics", 1000, hp)) fail_msg("%s: %s", tx_error_key(), tx_error());
  json_decref(hp);
  if (tx_system_finalize(s)) fail_msg("%s: %s", tx_error_key(), tx_error());
  tx_run_options o = {.duration_s = 0.1, .lockstep = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  tx_model* m = tx_system_model(s);
  tx_snapshot p = tx_model_latest(m, tx_model_find(m, "window.pointer"));
  assert_true(p.seq > 0);
  const tx_pointer* ptr = p.data;
  assert_true(ptr->pos[0] == 0.05 && ptr->pos[1] == 0.07 && ptr->pos[2] == TX_POINTER_REACH_M && ptr->buttons == 3);
  const tx_pose* pose = tx_model_latest(m, tx_model_find(m, "device0.pose")).data;
  assert_true(pose->pos[0] == 0.05 && pose->pos[1] == 0.07 && pose->pos[2] == TX_POINTER_REACH_M);
  tx_system_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(never_torn), cmocka_unit_test(the_mouse_goes_through_the_model),
                                     cmocka_unit_test(the_pointer_moves_the_tool)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
