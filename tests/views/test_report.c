// The run report: a haptics controller's missed deadlines are a warning (a
// stall the hand feels), on the summary's warnings line and in report.json;
// another controller's stay in the table only.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "views/report.h"
#include "tests/controllers/test_support.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

// step 1 sleeps 300 ms: at 5 Hz (ticks 200 ms apart) that is one missed deadline
static int configure(tx_setup* s, void** self) {
  (void)s;
  *self = NULL;
  return 0;
}
static void step(tx_ctx* c, void* self) {
  (void)self;
  if (tx_step_index(c) != 1) return;
  struct timespec ts = {0, 300000000};
  nanosleep(&ts, NULL);
}
static const tx_controller_class stall_haptics = {.type = "haptics.test_stall", .summary = "stalls once",
                                                  .configure = configure, .step = step};
static const tx_controller_class stall_other = {.type = "test.stall", .summary = "stalls once",
                                                .configure = configure, .step = step};

static void haptic_stalls_are_warnings(void** state) {
  (void)state;
  if (!tx_find_controller(stall_haptics.type)) assert_int_equal(tx_register_controller(&stall_haptics), 0);
  if (!tx_find_controller(stall_other.type)) assert_int_equal(tx_register_controller(&stall_other), 0);
  tx_system* s = tx_system_create();
  assert_int_equal(tx_system_add(s, "hand", "haptics.test_stall", 5, NULL), 0);
  assert_int_equal(tx_system_add(s, "physics", "test.stall", 4, NULL), 0);
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = 1.0};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  uint64_t missed = tx_system_stats(s, 0).missed;
  assert_true(missed >= 1);
  assert_true(tx_system_stats(s, 1).missed >= 1);

  json_t* report = tx_report_json(&(tx_report){"t", false, &r, s});
  json_t* warnings = json_object_get(report, "warnings");
  assert_int_equal(json_integer_value(json_object_get(warnings, "hand.missed_deadlines")), (json_int_t)missed);
  assert_null(json_object_get(warnings, "physics.missed_deadlines"));
  // the haptics instance ran on a thread of its own, and the report says so
  json_t* controllers = json_object_get(report, "controllers");
  assert_true(json_is_true(json_object_get(json_array_get(controllers, 0), "own_thread")));
  assert_null(json_object_get(json_array_get(controllers, 1), "own_thread"));
  assert_string_equal(json_string_value(json_object_get(json_array_get(controllers, 0), "thread")), "t0");

  char* text = NULL;
  size_t len = 0;
  FILE* f2 = open_memstream(&text, &len);
  tx_report_print(f2, report);
  fclose(f2);
  char want[64];
  snprintf(want, sizeof want, "hand.missed_deadlines=%llu", (unsigned long long)missed);
  const char* line = strstr(text, "\nwarnings:");
  assert_non_null(line);
  const char* end = strchr(line + 1, '\n');
  assert_non_null(strstr(line, want));
  assert_true(strstr(line, want) < end);
  free(text);
  json_decref(report);
  tx_system_destroy(s);
}

// per stream: events sent, overflows and what each listener lost; loss is a warning
static void streams_are_reported(void** state) {
  (void)state;
  register_test_classes();
  tx_system* s = tx_system_create();
  static const struct { const char* name; double rate; const char* params; } spec[] = {
      {"hand", 1000, "{\"emit\":\"tool0.events\",\"capacity\":16}"},
      {"physics", 20, "{\"listen\":\"tool0.events\"}"},
      {"tool", 1000, "{\"emit\":\"tool1.events\"}"},
      {"cautery", 60, "{\"listen\":\"tool1.events\"}"},
  };
  for (int i = 0; i < 4; i++) {
    json_t* p = json_loads(spec[i].params, 0, NULL);
    assert_int_equal(tx_system_add(s, spec[i].name, "test.events", spec[i].rate, p), 0);
    json_decref(p);
  }
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = 1.0, .lockstep = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  json_t* report = tx_report_json(&(tx_report){"t", true, &r, s});
  json_t* full = json_object_get(json_object_get(report, "streams"), "tool0.events");
  json_t* clean = json_object_get(json_object_get(report, "streams"), "tool1.events");
  assert_non_null(full);
  assert_non_null(clean);
  assert_string_equal(json_string_value(json_object_get(full, "writer")), "hand");
  assert_int_equal(json_integer_value(json_object_get(full, "capacity")), 16);
  assert_int_equal(json_integer_value(json_object_get(full, "sent")), 1000);
  assert_int_equal(json_integer_value(json_object_get(full, "overflows")), 680); // 34 of each 50 between reads
  json_int_t lost = json_integer_value(json_object_get(json_object_get(full, "lost"), "physics"));
  assert_true(lost > 0);
  json_t* warnings = json_object_get(report, "warnings");
  assert_int_equal(json_integer_value(json_object_get(warnings, "tool0.events.overflows")), 680);
  assert_int_equal(json_integer_value(json_object_get(warnings, "tool0.events.lost_by.physics")), lost);
  assert_int_equal(json_integer_value(json_object_get(clean, "sent")), 1000);
  assert_int_equal(json_integer_value(json_object_get(clean, "overflows")), 0);
  assert_int_equal(json_integer_value(json_object_get(json_object_get(clean, "lost"), "cautery")), 0);
  assert_null(json_object_get(warnings, "tool1.events.overflows")); // nothing lost, no warning
  assert_null(json_object_get(warnings, "tool1.events.lost_by.cautery"));
  json_decref(report);
  tx_system_destroy(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(haptic_stalls_are_warnings),
                                     cmocka_unit_test(streams_are_reported)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
