// Tests of scenarios/loader.c: scenario text and files to a finalized system,
// and every bad input to one line that names the file and the key path.
#include "model/error.h"
#include "scenarios/loader.h"

#include <tactus/config.h>

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#define LABEL "inline.json"
#define WORKER "\"type\":\"rates.worker\""

// one worker "a" at 10 Hz that reads and writes nothing
static const char one_worker[] = "{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10}]}";


static tx_scenario* load_sets(const char* text, const char* const* sets, int nsets, bool plugins) {
  tx_set_error("%s", ""); // a message left must be this load's
  tx_load_options o = {.sets = sets, .nsets = nsets, .allow_plugins = plugins};
  return tx_scenario_load_text(LABEL, text, strlen(text), &o);
}

static tx_scenario* load(const char* text) { return load_sets(text, NULL, 0, false); }

// an error is one line that starts with prefix and holds every further fragment
static void expect_error(const char* prefix, ...) {
  if (strncmp(tx_error(), prefix, strlen(prefix)) != 0) fail_msg("'%s' does not start with '%s'", tx_error(), prefix);
  assert_null(strchr(tx_error(), '\n'));
  va_list ap;
  va_start(ap, prefix);
  for (const char* part; (part = va_arg(ap, const char*));)
    if (!strstr(tx_error(), part)) fail_msg("'%s' does not mention '%s'", tx_error(), part);
  va_end(ap);
}

static void expect_text_error(const char* text, const char* prefix, const char* part) {
  tx_scenario* s = load(text);
  if (s) fail_msg("loaded, expected an error starting with '%s'", prefix);
  expect_error(prefix, part, NULL);
}

static void expect_set_error(const char* text, const char* set, const char* prefix, const char* part) {
  const char* sets[] = {set};
  tx_scenario* s = load_sets(text, sets, 1, false);
  if (s) fail_msg("loaded with --set %s, expected an error", set);
  expect_error(prefix, part, NULL);
}

static int find(const tx_scenario* s, const char* name) {
  for (int i = 0; i < tx_system_count(s->system); i++)
    if (strcmp(tx_system_name(s->system, i), name) == 0) return i;
  fail_msg("no controller '%s'", name);
  return -1;
}

// --- success ---------------------------------------------------------------

static void minimal_scenario_loads_with_defaults(void** state) {
  (void)state;
  tx_scenario* s = load(one_worker);
  assert_non_null(s);
  assert_string_equal(tx_error(), "");
  assert_string_equal(s->name, "t");
  assert_string_equal(s->path, LABEL);
  assert_string_equal(s->description, "");
  assert_true(s->duration_s == 10); // the documented default
  assert_int_equal(tx_system_count(s->system), 1);
  assert_string_equal(tx_system_name(s->system, 0), "a");
  assert_string_equal(tx_system_class(s->system, 0)->type, "rates.worker");
  assert_true(tx_system_rate(s->system, 0) == 10);
  assert_int_equal(tx_system_ports(s->system, 0), 0);
  assert_non_null(tx_system_model(s->system));
  tx_scenario_free(s);
}

static void data_flow_through_a_declared_component(void** state) {
  (void)state;
  const char* text = "{\"name\":\"flow\",\"description\":\"two workers\",\"duration_s\":2.5,"
                     "\"model\":[{\"name\":\"t.x\",\"type\":\"f32\",\"rows\":4,\"cols\":3,\"units\":\"m\"}],"
                     "\"controllers\":["
                     "{\"name\":\"src\"," WORKER ",\"rate_hz\":100,\"params\":{\"write\":\"t.x\",\"rows\":4,\"cols\":3,\"units\":\"m\"}},"
                     "{\"name\":\"dst\"," WORKER ",\"rate_hz\":1000,\"params\":{\"reads\":[\"t.x\"],\"work_us\":0}}]}";
  tx_scenario* s = load(text);
  if (!s) fail_msg("%s", tx_error());
  assert_string_equal(s->description, "two workers");
  assert_true(s->duration_s == 2.5);
  assert_int_equal(tx_system_threads(s->system), 2);
  int src = find(s, "src"), dst = find(s, "dst");
  assert_int_equal(tx_system_thread(s->system, dst), 0); // fastest group first
  assert_int_equal(tx_system_thread(s->system, src), 1);
  tx_port_info w = tx_system_port(s->system, src, 0), r = tx_system_port(s->system, dst, 0);
  assert_true(w.write);
  assert_false(r.write);
  assert_string_equal(w.component, "t.x");
  assert_string_equal(r.component, "t.x");
  assert_int_equal(r.def->type, TX_F32);
  assert_int_equal(r.def->rows, 4);
  assert_int_equal(r.def->cols, 3);
  assert_string_equal(r.def->units, "m");
  tx_scenario_free(s);
}

static void rate_at_the_upper_limit_is_accepted(void** state) {
  (void)state;
  tx_scenario* s = load("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":100000}]}");
  if (!s) fail_msg("%s", tx_error());
  assert_true(tx_system_rate(s->system, 0) == TX_RATE_MAX_HZ);
  tx_scenario_free(s);
  s = load("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":0.001}]}");
  if (!s) fail_msg("%s", tx_error());
  tx_scenario_free(s);
}

// --- syntax ----------------------------------------------------------------

static void malformed_json_gives_label_line_column(void** state) {
  (void)state;
  expect_text_error("{\n  \"name\": \"t\",\n  \"controllers\": [\n}", LABEL ":4:1:", "unexpected");
  expect_text_error("", LABEL ":1:0:", "expected");
  expect_text_error("{\"name\": \"t\",}", LABEL ":1:", "");
}

static void duplicate_keys_are_rejected(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\n\"name\":\"u\",\"controllers\":[]}", LABEL ":2:", "duplicate object key");
  // inside params too, where the last value would otherwise win silently
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER
                    ",\"rate_hz\":10,\"params\":{\"work_us\":1,\"work_us\":2}}]}",
                    LABEL ":1:", "duplicate object key");
}

static void top_level_must_be_an_object(void** state) {
  (void)state;
  expect_text_error("[]", LABEL ": ", "expected a JSON object");
}

// --- meaning ---------------------------------------------------------------

static void unknown_top_level_key(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"bogus\":1,\"controllers\":[]}", LABEL ": bogus: ", "unknown key");
}

static void control_characters_from_the_file_stay_out_of_the_message(void** state) {
  (void)state;
  // a key with an escaped newline must not split the one-line message
  expect_text_error("{\"name\":\"t\",\"bo\\ngus\\u001b[2J\":1,\"controllers\":[]}", LABEL ": bo?gus?[2J: ", "unknown key");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\",\"type\":\"x\\ny\",\"rate_hz\":1}]}",
                    LABEL ": controllers[0].type: ", "'x?y'");
  expect_set_error(one_worker, "a.bo\ngus=1", "--set a.bo?gus=1: ", "unknown parameter");
}

static void unknown_controller_key(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"rate\":5}]}",
                    LABEL ": controllers[0].rate: ", "unknown key");
}

// "thread": a name of a-z 0-9 _ -, at most 31 characters, one rate per name
static void thread_names(void** state) {
  (void)state;
  const char* head = "{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"thread\":";
  static const struct { const char* value; const char* part; } bad[] = {
      {"7", "expected a thread name (a string), got a number"},
      {"null", "got null"},
      {"\"\"", "must be 1-31 characters of a-z 0-9 _ -"},
      {"\"Tissue\"", "'Tissue' must be 1-31"},
      {"\"a b\"", "must be 1-31"},
      {"\"abcdefghijklmnopqrstuvwxyz012345\"", "must be 1-31"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char text[512];
    snprintf(text, sizeof text, "%s%s}]}", head, bad[i].value);
    expect_text_error(text, LABEL ": controllers[0].thread: ", bad[i].part);
  }
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"thread\":\"x\"},"
                    "{\"name\":\"b\"," WORKER ",\"rate_hz\":20,\"thread\":\"x\"}]}",
                    LABEL ": controllers[1].thread: ", "'x' runs a at 10 Hz; b at 20 Hz cannot share it");
  tx_scenario* s = load("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"thread\":\"x\"},"
                        "{\"name\":\"b\"," WORKER ",\"rate_hz\":10},{\"name\":\"c\"," WORKER
                        ",\"rate_hz\":10,\"thread\":\"x\"}]}");
  if (!s) fail_msg("%s", tx_error());
  int a = find(s, "a"), b = find(s, "b"), c = find(s, "c");
  assert_int_equal(tx_system_threads(s->system), 2);
  assert_int_equal(tx_system_thread(s->system, a), tx_system_thread(s->system, c));
  assert_int_not_equal(tx_system_thread(s->system, a), tx_system_thread(s->system, b));
  assert_string_equal(tx_system_thread_name(s->system, tx_system_thread(s->system, a)), "x");
  tx_scenario_free(s);
}

static void missing_or_bad_name_and_controllers(void** state) {
  (void)state;
  expect_text_error("{\"controllers\":[]}", LABEL ": name: ", "a-z 0-9 _ -");
  expect_text_error("{\"name\":\"\",\"controllers\":[]}", LABEL ": name: ", "a-z 0-9 _ -");
  // the name becomes the default output folder: no path in it
  expect_text_error("{\"name\":\"../up\",\"controllers\":[]}", LABEL ": name: ", "a-z 0-9 _ -");
  expect_text_error("{\"name\":\"a/b\",\"controllers\":[]}", LABEL ": name: ", "a-z 0-9 _ -");
  expect_text_error("{\"name\":\"t\"}", LABEL ": controllers: ", "non-empty array");
  expect_text_error("{\"name\":\"t\",\"controllers\":[]}", LABEL ": controllers: ", "non-empty array");
  expect_text_error("{\"name\":\"t\",\"controllers\":[7]}", LABEL ": controllers[0]: ", "expected an object");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"A B\"," WORKER ",\"rate_hz\":1}]}",
                    LABEL ": controllers[0].name: ", "a-z 0-9");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1},"
                    "{\"name\":\"a\"," WORKER ",\"rate_hz\":2}]}",
                    LABEL ": controllers[1].name: ", "already exists");
}

static void unknown_controller_type(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\",\"type\":\"no.such\",\"rate_hz\":1}]}",
                    LABEL ": controllers[0].type: ", "unknown controller type 'no.such'");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\",\"type\":3,\"rate_hz\":1}]}",
                    LABEL ": controllers[0].type: ", "expected a string");
}

static void rate_hz_of_the_wrong_type(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":\"fast\"}]}",
                    LABEL ": controllers[0].rate_hz: ", "got a string");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":true}]}",
                    LABEL ": controllers[0].rate_hz: ", "got a boolean");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER "}]}",
                    LABEL ": controllers[0].rate_hz: ", "got nothing");
}

static void rate_hz_out_of_range(void** state) {
  (void)state;
  // below TX_RATE_MIN_HZ a period no longer fits the int64 ns clocks (1e-10 Hz: 1e19 ns)
  static const char* const rates[] = {"0", "-5", "100001", "100000.5", "1e300", "1e-10", "0.0009", "5e-324"};
  for (size_t i = 0; i < sizeof rates / sizeof rates[0]; i++) {
    char text[256];
    snprintf(text, sizeof text, "{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":%s}]}",
             rates[i]);
    expect_text_error(text, LABEL ": controllers[0].rate_hz: ", "out of range [0.001, 100000]");
  }
}

// the view's rate is checked against the clocks even when nothing draws
static void view_rate_below_the_least(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"view\":{\"rate_hz\":1e-10},\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1}]}",
                    LABEL ": view.rate_hz: ", "below the least rate");
}

static void two_writers_of_one_component(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":["
                    "{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"write\":\"t.x\"}},"
                    "{\"name\":\"b\"," WORKER ",\"rate_hz\":20,\"params\":{\"write\":\"t.x\"}}]}",
                    LABEL ": controllers[1]: ", "'t.x' has two writers: a and b");
}

static void declared_component_that_nobody_writes(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"model\":[{\"name\":\"t.x\",\"type\":\"f32\",\"rows\":1,\"cols\":3}],"
                    "\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"reads\":[\"t.x\"]}}]}",
                    LABEL ": controllers[0]: ", "no controller writes");
  // declared, read by nobody and written by nobody: still an error, at the model
  expect_text_error("{\"name\":\"t\",\"model\":[{\"name\":\"t.x\",\"type\":\"f32\",\"rows\":1}],"
                    "\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10}]}",
                    LABEL ": ", "'t.x' has no writer");
}

static void read_of_an_unknown_component(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER
                    ",\"rate_hz\":10,\"params\":{\"reads\":[\"t.nope\"]}}]}",
                    LABEL ": controllers[0]: ", "unknown component 't.nope'");
}

static void declared_schema_must_match_the_writer(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"model\":[{\"name\":\"t.x\",\"type\":\"f32\",\"rows\":5,\"cols\":3,\"units\":\"m\"}],"
                    "\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,"
                    "\"params\":{\"write\":\"t.x\",\"rows\":4,\"cols\":3,\"units\":\"m\"}}]}",
                    LABEL ": controllers[0]: ", "the model declares");
  expect_text_error("{\"name\":\"t\",\"model\":[{\"name\":\"t.x\",\"type\":\"f16\",\"rows\":1}],"
                    "\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10}]}",
                    LABEL ": model[0].type: ", "f32");
  expect_text_error("{\"name\":\"t\",\"model\":[{\"name\":\"t.x\",\"type\":\"f32\",\"rows\":0}],"
                    "\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10}]}",
                    LABEL ": model[0].rows: ", "integer");
}

static void unknown_parameter(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"bogus\":1}}]}",
                    LABEL ": controllers[0].params.bogus: ", "unknown parameter for rates.worker");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":[]}]}",
                    LABEL ": controllers[0].params: ", "expected an object");
}

static void parameter_out_of_range_or_of_the_wrong_type(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"work_us\":2e6}}]}",
                    LABEL ": controllers[0].params.work_us: ", "out of range [0, 1e+06]");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"work_us\":-1}}]}",
                    LABEL ": controllers[0].params.work_us: ", "out of range");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"work_us\":\"x\"}}]}",
                    LABEL ": controllers[0].params.work_us: ", "expected a number");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"rows\":1.5}}]}",
                    LABEL ": controllers[0].params.rows: ", "expected an integer");
  expect_text_error("{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"reads\":[1]}}]}",
                    LABEL ": controllers[0].params.reads: ", "expected a string");
}

static void duration_out_of_range(void** state) {
  (void)state;
  expect_text_error("{\"name\":\"t\",\"duration_s\":0,\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1}]}",
                    LABEL ": duration_s: ", "[1e-06, 86400]");
  expect_text_error("{\"name\":\"t\",\"duration_s\":\"long\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1}]}",
                    LABEL ": duration_s: ", "[1e-06, 86400]");
  expect_text_error("{\"name\":\"t\",\"duration_s\":1e-300,\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1}]}",
                    LABEL ": duration_s: ", "[1e-06, 86400]");
}

static void plugins_rejected_when_not_allowed(void** state) {
  (void)state;
  const char* text = "{\"name\":\"t\",\"plugins\":[\"libexample.so\"],\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1}]}";
  assert_null(load_sets(text, NULL, 0, false));
  expect_error(LABEL ": plugins[0]: ", "not allowed", NULL);
  // and with no options at all, as the fuzzer and the benches pass
  tx_set_error("%s", ""); // a message left must be this load's
  assert_null(tx_scenario_load_text(LABEL, text, strlen(text), NULL));
  expect_error(LABEL ": plugins[0]: ", "not allowed", NULL);
  expect_text_error("{\"name\":\"t\",\"plugins\":\"x.so\",\"controllers\":[]}", LABEL ": plugins: ", "array");
}

// --- --set -----------------------------------------------------------------

static void set_overrides_are_applied(void** state) {
  (void)state;
  const char* text = "{\"name\":\"t\",\"controllers\":["
                     "{\"name\":\"a\"," WORKER ",\"rate_hz\":10,\"params\":{\"write\":\"t.x\",\"rows\":2,\"cols\":3}},"
                     "{\"name\":\"b\"," WORKER ",\"rate_hz\":10,\"params\":{\"reads\":[\"t.x\"]}}]}";
  const char* sets[] = {"a.rate_hz=50", "a.rows=7", "a.units=N", "b.work_us=0", "duration_s=0.25"};
  tx_scenario* s = load_sets(text, sets, 5, false);
  if (!s) fail_msg("%s", tx_error());
  int a = find(s, "a"), b = find(s, "b");
  assert_true(tx_system_rate(s->system, a) == 50);
  assert_true(tx_system_rate(s->system, b) == 10);
  assert_true(s->duration_s == 0.25);
  tx_port_info r = tx_system_port(s->system, b, 0);
  assert_int_equal(r.def->rows, 7);
  assert_int_equal(r.def->cols, 3);
  assert_string_equal(r.def->units, "N"); // a bare word is a string

  // and the run sees the new rate: 50 Hz for 0.25 s of virtual time
  tx_run_options o = {.duration_s = s->duration_s, .lockstep = true};
  tx_run_result res;
  assert_int_equal(tx_system_run(s->system, &o, &res), 0);
  assert_int_equal(tx_system_stats(s->system, a).steps, 13); // ticks at 0, 20, ..., 240 ms
  assert_int_equal(tx_system_stats(s->system, b).steps, 3);  // ticks at 0, 100, 200 ms
  tx_scenario_free(s);
}

static void set_adds_params_to_a_controller_without_any(void** state) {
  (void)state;
  const char* sets[] = {"a.work_us=5", "a.reads=[]"};
  tx_scenario* s = load_sets(one_worker, sets, 2, false);
  if (!s) fail_msg("%s", tx_error());
  tx_scenario_free(s);
}

static void set_the_last_one_wins(void** state) {
  (void)state;
  const char* sets[] = {"a.rate_hz=0", "a.rate_hz=25"};
  tx_scenario* s = load_sets(one_worker, sets, 2, false);
  if (!s) fail_msg("%s", tx_error());
  assert_true(tx_system_rate(s->system, 0) == 25);
  tx_scenario_free(s);
}

static void set_error_names_the_set_in_effect(void** state) {
  (void)state;
  // two --sets of one key: the value that fails is the last one, and so is the message
  const char* sets[] = {"a.rate_hz=25", "a.rate_hz=0"};
  assert_null(load_sets(one_worker, sets, 2, false));
  expect_error("--set a.rate_hz=0: ", "out of range", NULL);
  const char* params[] = {"a.work_us=0", "a.work_us=-1"};
  assert_null(load_sets(one_worker, params, 2, false));
  expect_error("--set a.work_us=-1: ", "out of range", NULL);
}

static void set_of_an_unknown_controller(void** state) {
  (void)state;
  expect_set_error(one_worker, "nobody.work_us=1", "--set nobody.work_us=1: ", "no controller named 'nobody'");
}

static void set_of_an_unknown_parameter(void** state) {
  (void)state;
  expect_set_error(one_worker, "a.bogus=1", "--set a.bogus=1: ", "unknown parameter");
  expect_set_error(one_worker, "bogus=1", "--set bogus=1: ", "unknown key");
}

static void set_out_of_range(void** state) {
  (void)state;
  expect_set_error(one_worker, "a.rate_hz=0", "--set a.rate_hz=0: ", "out of range [0.001, 100000]");
  expect_set_error(one_worker, "a.rate_hz=1e-10", "--set a.rate_hz=1e-10: ", "out of range [0.001, 100000]");
  expect_set_error(one_worker, "a.rate_hz=100001", "--set a.rate_hz=100001: ", "out of range");
  expect_set_error(one_worker, "a.rate_hz=fast", "--set a.rate_hz=fast: ", "expected a number");
  expect_set_error(one_worker, "a.work_us=-1", "--set a.work_us=-1: ", "out of range");
  expect_set_error(one_worker, "duration_s=0", "--set duration_s=0: ", "[1e-06, 86400]");
  expect_set_error(one_worker, "duration_s=abc", "--set duration_s=abc: ", "[1e-06, 86400]");
  // a number past a double's range is named as such, not as "a string"
  expect_set_error(one_worker, "a.work_us=1e999", "--set a.work_us=1e999: ", "out of range");
  expect_set_error(one_worker, "a.work_us=-1e400", "--set a.work_us=-1e400: ", "out of range");
}

// a bad component name is named, with the --set that gave it, not blamed on a reader
static void set_of_a_bad_component_name(void** state) {
  (void)state;
  expect_set_error(one_worker, "a.write=Bad Name!", "--set a.write=Bad Name!: ", "bad component name 'Bad Name!'");
  expect_set_error(one_worker, "a.reads=[\"ok.x\", \"UP\"]", "--set a.reads=[\"ok.x\", \"UP\"]: ", "bad component name 'UP'");
}

static void set_malformed(void** state) {
  (void)state;
  expect_set_error(one_worker, "a.work_us", "--set a.work_us: ", "KEY=VALUE");
  expect_set_error(one_worker, "=1", "--set =1: ", "KEY=VALUE");
  expect_set_error(one_worker, "a.=1", "--set a.=1: ", "CONTROLLER.PARAM");
}

static void set_names_only_the_controller_it_changed(void** state) {
  (void)state;
  // the --set is fine; the file's own error at another controller is reported as the file's
  const char* text = "{\"name\":\"t\",\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":10},"
                     "{\"name\":\"b\"," WORKER ",\"rate_hz\":0}]}";
  expect_set_error(text, "a.rate_hz=20", LABEL ": controllers[1].rate_hz: ", "out of range");
}

// --- files -----------------------------------------------------------------

static char dir[64];

static int make_dir(void** state) {
  (void)state;
  snprintf(dir, sizeof dir, "/tmp/tx_test_loader.XXXXXX");
  return mkdtemp(dir) ? 0 : -1;
}

static int remove_dir(void** state) {
  (void)state;
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  return system(cmd) == 0 ? 0 : -1;
}

static void write_file(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static void files_load_and_errors_name_the_path(void** state) {
  (void)state;
  char good[128], bad[128], prefix[160];
  snprintf(good, sizeof good, "%s/good.json", dir);
  snprintf(bad, sizeof bad, "%s/bad.json", dir);
  write_file(good, one_worker);
  write_file(bad, "{\n\"name\": \"t\",\n\"controllers\": [ {\"name\": \"a\" \"type\": 1} ]\n}\n");

  tx_load_options o = {.allow_plugins = false};
  tx_scenario* s = tx_scenario_load(good, &o);
  if (!s) fail_msg("%s", tx_error());
  assert_string_equal(s->path, good);
  tx_scenario_free(s);

  assert_null(tx_scenario_load(bad, &o));
  snprintf(prefix, sizeof prefix, "%s:3:", bad);
  expect_error(prefix, NULL);

  char missing[128];
  snprintf(missing, sizeof missing, "%s/missing.json", dir);
  assert_null(tx_scenario_load(missing, &o));
  snprintf(prefix, sizeof prefix, "%s: ", missing);
  expect_error(prefix, "No such file", NULL);

  assert_null(tx_scenario_load(dir, &o));
  snprintf(prefix, sizeof prefix, "%s: ", dir);
  expect_error(prefix, "not a regular file", NULL);

  // a meaning error names the file, not a label
  char unknown[128];
  snprintf(unknown, sizeof unknown, "%s/unknown.json", dir);
  write_file(unknown, "{\"name\":\"t\",\"controllers\":[{\"name\":\"a\",\"type\":\"no.such\",\"rate_hz\":1}]}");
  assert_null(tx_scenario_load(unknown, &o));
  snprintf(prefix, sizeof prefix, "%s: controllers[0].type: ", unknown);
  expect_error(prefix, "no.such", NULL);
}

static void plugin_paths_resolve_beside_the_file(void** state) {
  (void)state;
  char path[128], prefix[160], beside[160];
  snprintf(path, sizeof path, "%s/with_plugin.json", dir);
  write_file(path, "{\"name\":\"t\",\"plugins\":[\"libnone.so\"],\"controllers\":[{\"name\":\"a\"," WORKER ",\"rate_hz\":1}]}");
  tx_load_options o = {.allow_plugins = true};
  assert_null(tx_scenario_load(path, &o));
  snprintf(prefix, sizeof prefix, "%s: plugins[0]: ", path);
  snprintf(beside, sizeof beside, "%s/libnone.so", dir);
  expect_error(prefix, beside, "No such file", NULL);

  // a file that is there but no shared library
  write_file(beside, "not an ELF file");
  assert_null(tx_scenario_load(path, &o));
  expect_error(prefix, "libnone.so", NULL);
}

static void the_shipped_rates_scenario_loads(void** state) {
  (void)state;
  char path[512];
  assert_int_equal(tx_scenario_locate("rates", path, sizeof path), 0);
  assert_string_equal(path, TX_SCENARIO_DIR "/rates/rates.json");
  tx_scenario* s = tx_scenario_load(path, NULL);
  if (!s) fail_msg("%s", tx_error());
  assert_string_equal(s->name, "rates");
  assert_int_equal(tx_system_count(s->system), 4);
  assert_int_equal(tx_system_threads(s->system), 4);
  assert_true(tx_system_rate(s->system, find(s, "collision")) == 4000);
  tx_scenario_free(s);
}

// --device: the i-th goes to the i-th haptics controller; "scenario" keeps
// that hand's device from the file (the picker's choice for a hand it leaves
// alone); one more than the hands is refused
static void devices_per_hand(void** state) {
  (void)state;
  static const char text[] =
      "{\"name\":\"t\",\"controllers\":["
      "{\"name\":\"wall0\",\"type\":\"collision.wall\",\"rate_hz\":100},"
      "{\"name\":\"wall1\",\"type\":\"collision.wall\",\"rate_hz\":100,\"params\":{\"pose\":\"device1.pose\","
      "\"force_model\":\"tool1.force_model\"}},"
      "{\"name\":\"h0\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:pierce-down\"}},"
      "{\"name\":\"h1\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:pierce-down\",\"hand\":1,"
      "\"force_model\":\"tool1.force_model\"}}]}";
  const char* const chosen[] = {"scenario", "sim"};
  tx_load_options o = {.devices = chosen, .ndevices = 2};
  tx_scenario* s = tx_scenario_load_text(LABEL, text, strlen(text), &o);
  if (!s) fail_msg("%s", tx_error());
  assert_string_equal(json_string_value(json_object_get(tx_system_params(s->system, 2), "device")), "scripted:pierce-down");
  assert_string_equal(json_string_value(json_object_get(tx_system_params(s->system, 3), "device")), "sim");
  tx_scenario_free(s);
  const char* const kept[] = {"scenario", "scenario"};
  o = (tx_load_options){.devices = kept, .ndevices = 2};
  s = tx_scenario_load_text(LABEL, text, strlen(text), &o);
  if (!s) fail_msg("%s", tx_error()); // both kept: the file as it is
  assert_string_equal(json_string_value(json_object_get(tx_system_params(s->system, 3), "device")), "scripted:pierce-down");
  tx_scenario_free(s);
  static const char one_hand[] = "{\"name\":\"t\",\"controllers\":["
                                 "{\"name\":\"wall0\",\"type\":\"collision.wall\",\"rate_hz\":100},"
                                 "{\"name\":\"h0\",\"type\":\"haptics\",\"rate_hz\":1000}]}";
  o = (tx_load_options){.devices = chosen, .ndevices = 2};
  assert_null(tx_scenario_load_text(LABEL, one_hand, strlen(one_hand), &o));
  expect_error("--device sim: " LABEL " has 1 haptics controller, so it takes at most 1 --device", NULL);
}

static void locate_unknown_names_and_missing_files(void** state) {
  (void)state;
  char path[512];
  assert_int_not_equal(tx_scenario_locate("no_such_scenario", path, sizeof path), 0);
  expect_error("no_such_scenario: ", "unknown scenario", NULL);
  assert_int_not_equal(tx_scenario_locate("/nonexistent/x.json", path, sizeof path), 0);
  expect_error("/nonexistent/x.json: ", "No such file", NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(minimal_scenario_loads_with_defaults),
      cmocka_unit_test(devices_per_hand),
      cmocka_unit_test(data_flow_through_a_declared_component),
      cmocka_unit_test(rate_at_the_upper_limit_is_accepted),
      cmocka_unit_test(malformed_json_gives_label_line_column),
      cmocka_unit_test(duplicate_keys_are_rejected),
      cmocka_unit_test(top_level_must_be_an_object),
      cmocka_unit_test(unknown_top_level_key),
      cmocka_unit_test(control_characters_from_the_file_stay_out_of_the_message),
      cmocka_unit_test(unknown_controller_key),
      cmocka_unit_test(thread_names),
      cmocka_unit_test(missing_or_bad_name_and_controllers),
      cmocka_unit_test(unknown_controller_type),
      cmocka_unit_test(rate_hz_of_the_wrong_type),
      cmocka_unit_test(rate_hz_out_of_range),
      cmocka_unit_test(two_writers_of_one_component),
      cmocka_unit_test(declared_component_that_nobody_writes),
      cmocka_unit_test(read_of_an_unknown_component),
      cmocka_unit_test(declared_schema_must_match_the_writer),
      cmocka_unit_test(unknown_parameter),
      cmocka_unit_test(parameter_out_of_range_or_of_the_wrong_type),
      cmocka_unit_test(duration_out_of_range),
      cmocka_unit_test(plugins_rejected_when_not_allowed),
      cmocka_unit_test(set_overrides_are_applied),
      cmocka_unit_test(set_adds_params_to_a_controller_without_any),
      cmocka_unit_test(set_the_last_one_wins),
      cmocka_unit_test(set_error_names_the_set_in_effect),
      cmocka_unit_test(set_of_an_unknown_controller),
      cmocka_unit_test(set_of_an_unknown_parameter),
      cmocka_unit_test(set_out_of_range),
      cmocka_unit_test(set_of_a_bad_component_name),
      cmocka_unit_test(view_rate_below_the_least),
      cmocka_unit_test(set_malformed),
      cmocka_unit_test(set_names_only_the_controller_it_changed),
      cmocka_unit_test_setup_teardown(files_load_and_errors_name_the_path, make_dir, remove_dir),
      cmocka_unit_test_setup_teardown(plugin_paths_resolve_beside_the_file, make_dir, remove_dir),
      cmocka_unit_test(the_shipped_rates_scenario_loads),
      cmocka_unit_test(locate_unknown_names_and_missing_files),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
