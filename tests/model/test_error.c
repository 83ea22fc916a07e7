// tx_error: one message per thread, and tx_error_prefix adds where it failed
// in front of it without reading the buffer it writes.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/model.h>

#include "model/error.h"

#include <pthread.h>
#include <string.h>

static void a_prefix_goes_in_front(void** state) {
  (void)state;
  tx_set_error("bad header");
  tx_error_prefix("%s line %d", "a.csv", 3);
  assert_string_equal(tx_error(), "a.csv line 3: bad header");
  tx_error_prefix("%s", tx_error()); // its own text as the context: no overlap fault
  assert_string_equal(tx_error(), "a.csv line 3: bad header: a.csv line 3: bad header");
}

static void a_prefix_on_no_message_is_the_context_alone(void** state) {
  (void)state;
  tx_set_error("%s", "");
  tx_error_prefix("scene.json");
  assert_string_equal(tx_error(), "scene.json");
}

static void a_long_message_is_cut_not_overrun(void** state) {
  (void)state;
  char big[2000];
  memset(big, 'x', sizeof big - 1);
  big[sizeof big - 1] = 0;
  tx_set_error("%s", big);
  tx_error_prefix("%s", big);
  assert_int_equal(strlen(tx_error()), 1023);
}

static void a_key_travels_with_its_message(void** state) {
  (void)state;
  tx_set_error_at("params.gain", "%g is out of range", 11.0);
  assert_string_equal(tx_error_key(), "params.gain");
  assert_string_equal(tx_error(), "11 is out of range");
  tx_error_prefix("scene.json"); // context keeps the key
  assert_string_equal(tx_error_key(), "params.gain");
  tx_set_error_at(tx_error_key(), "%s", tx_error()); // built from itself
  assert_string_equal(tx_error_key(), "params.gain");
  assert_string_equal(tx_error(), "scene.json: 11 is out of range");
  tx_set_error("%s, again", tx_error()); // no overlap fault either
  assert_string_equal(tx_error(), "scene.json: 11 is out of range, again");
  tx_set_error("plain");
  assert_string_equal(tx_error_key(), ""); // a keyless error clears it
  tx_set_error_at(NULL, "whole");
  assert_string_equal(tx_error_key(), "");
}

static void* other_thread(void* arg) {
  (void)arg;
  tx_set_error("other");
  return NULL;
}

static void each_thread_has_its_own(void** state) {
  (void)state;
  tx_set_error("mine");
  pthread_t t;
  assert_int_equal(pthread_create(&t, NULL, other_thread, NULL), 0);
  pthread_join(t, NULL);
  assert_string_equal(tx_error(), "mine");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_prefix_goes_in_front),
      cmocka_unit_test(a_prefix_on_no_message_is_the_context_alone),
      cmocka_unit_test(a_long_message_is_cut_not_overrun),
      cmocka_unit_test(a_key_travels_with_its_message),
      cmocka_unit_test(each_thread_has_its_own),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
