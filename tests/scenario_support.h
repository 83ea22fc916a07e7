// Running a loaded scenario in a test and reading what it left: the model's
// latest publishes, the run's results and its warning counts. Include after
// cmocka.h and scenarios/loader.h.
#ifndef TX_TESTS_SCENARIO_SUPPORT_H
#define TX_TESTS_SCENARIO_SUPPORT_H

#include <math.h>
#include <string.h>

// run s in lockstep for the given simulated time; any error fails the test
static inline void run(tx_scenario* s, double seconds) {
  tx_run_options o = {.duration_s = seconds, .lockstep = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s->system, &o, &r), 0);
}

// the latest publish of a component; a name the model lacks fails the test
static inline tx_snapshot latest_snapshot(tx_scenario* s, const char* name) {
  tx_model* m = tx_system_model(s->system);
  tx_comp c = tx_model_find(m, name);
  assert_true(c.id != 0);
  return tx_model_latest(m, c);
}

static inline const double* latest(tx_scenario* s, const char* name) { return latest_snapshot(s, name).data; }

// a load that must be refused: no scenario, and one line naming the key (needle)
static inline void assert_refused(tx_scenario* s, const char* needle) {
  assert_null(s);
  print_message("  %s\n", tx_error());
  assert_non_null(strstr(tx_error(), needle));
  assert_null(strchr(tx_error(), '\n'));
}

// a reported result by its key ("INSTANCE.key")
static inline double result(tx_scenario* s, const char* key) {
  for (int i = 0; i < tx_system_results(s->system); i++)
    if (strcmp(tx_system_result_key(s->system, i), key) == 0) return tx_system_result(s->system, i);
  fail_msg("no result %s", key);
  return NAN;
}

// a warning's count by its key ("INSTANCE.key")
static inline uint64_t warnings(tx_scenario* s, const char* key) {
  for (int w = 0; w < tx_system_warnings(s->system); w++)
    if (strcmp(tx_system_warning_key(s->system, w), key) == 0) return tx_system_warning_count(s->system, w);
  fail_msg("no warning %s", key);
  return 0;
}

#endif
