// Tests of the view flag (controllers/system.c): a class marked as a view may
// read the model, and one that declares a write is refused at load, in one
// line that names the scenario file, the controller and the component.
#include "scenarios/loader.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

// a source the views read
static int source_configure(tx_setup* s, void** self) {
  *self = NULL;
  tx_setup_write(s, &(tx_component_def){"src.value", TX_F64, 1, 1, "1"});
  return 0;
}
static void nothing(tx_ctx* c, void* self) { (void)c, (void)self; }

// a view that reads, as a view must; and one that also writes (param "write")
static int view_configure(tx_setup* s, void** self) {
  *self = NULL;
  bool write = tx_param_bool(s, "write", false);
  tx_setup_read(s, "src.value");
  if (write) tx_setup_write(s, &(tx_component_def){"view.out", TX_F64, 1, 1, "1"});
  return 0;
}

static const tx_controller_class source_class = {
    .type = "test_views.source", .summary = "writes src.value", .configure = source_configure, .step = nothing};
static const tx_controller_class view_class = {.type = "test_views.view",
                                               .summary = "reads src.value; writes view.out if asked",
                                               .configure = view_configure,
                                               .step = nothing,
                                               .view = true};
// the same callbacks without the flag: an ordinary controller may write
static const tx_controller_class plain_class = {
    .type = "test_views.plain", .summary = "as test_views.view, not a view", .configure = view_configure, .step = nothing};

static int setup(void** state) {
  (void)state;
  tx_register_builtin();
  if (!tx_find_controller(source_class.type)) {
    assert_int_equal(tx_register_controller(&source_class), 0);
    assert_int_equal(tx_register_controller(&view_class), 0);
    assert_int_equal(tx_register_controller(&plain_class), 0);
  }
  return 0;
}

static tx_scenario* load(const char* type, bool write) {
  char text[512];
  snprintf(text, sizeof text,
           "{\"name\":\"v\",\"controllers\":[{\"name\":\"src\",\"type\":\"test_views.source\",\"rate_hz\":10},"
           "{\"name\":\"plot\",\"type\":\"%s\",\"rate_hz\":10,\"params\":{\"write\":%s}}]}",
           type, write ? "true" : "false");
  tx_load_options o = {0};
  return tx_scenario_load_text("views.json", text, strlen(text), &o);
}

static void a_view_that_only_reads_loads(void** state) {
  (void)state;
  tx_scenario* s = load("test_views.view", false);
  if (!s) fail_msg("%s", tx_error());
  tx_scenario_free(s);
}

static void a_view_that_writes_is_refused_in_one_line(void** state) {
  (void)state;
  tx_scenario* s = load("test_views.view", true);
  if (s) fail_msg("a view that writes view.out was loaded");
  print_message("%s\n", tx_error());
  assert_null(strchr(tx_error(), '\n'));
  const char* parts[] = {"views.json", "plot", "test_views.view", "is a view", "view.out"};
  for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++)
    if (!strstr(tx_error(), parts[i])) fail_msg("'%s' does not mention '%s'", tx_error(), parts[i]);
}

static void an_ordinary_controller_may_write(void** state) {
  (void)state;
  tx_scenario* s = load("test_views.plain", true);
  if (!s) fail_msg("%s", tx_error());
  tx_scenario_free(s);
}

// a structured parameter reaches a view as JSON text through the public API
static char seen_text[256];
static bool seen_absent;
static int text_configure(tx_setup* s, void** self) {
  *self = NULL;
  const char* t = tx_param_json_text(s, "view");
  snprintf(seen_text, sizeof seen_text, "%s", t ? t : "(null)");
  seen_absent = tx_param_json_text(s, "absent") == NULL;
  return 0;
}
static const tx_controller_class text_class = {
    .type = "test_views.text", .summary = "keeps params.view as text", .configure = text_configure, .step = nothing, .view = true};

static void a_structured_parameter_comes_as_json_text(void** state) {
  (void)state;
  if (!tx_find_controller(text_class.type)) assert_int_equal(tx_register_controller(&text_class), 0);
  const char* text = "{\"name\":\"t\",\"controllers\":[{\"name\":\"v\",\"type\":\"test_views.text\",\"rate_hz\":10,"
                     "\"params\":{\"view\":{\"width\":640,\"eye\":[0.1,-2.5e-3,1]}}}]}";
  tx_load_options o = {0};
  tx_scenario* sc = tx_scenario_load_text("text.json", text, strlen(text), &o);
  if (!sc) fail_msg("%s", tx_error());
  tx_scenario_free(sc);
  // every number as it was (17 digits), and the key counts as used (no "unknown parameter")
  assert_string_equal(seen_text, "{\"width\":640,\"eye\":[0.10000000000000001,-0.0025000000000000001,1]}");
  assert_true(seen_absent);
}

// the built-in views say that they are views
static void the_builtin_views_are_views(void** state) {
  (void)state;
  const tx_controller_class* fc = tx_find_controller("view.force_curve");
  assert_non_null(fc);
  assert_true(fc->view);
  const tx_controller_class* g = tx_find_controller("views.graphics");
  if (g) assert_true(g->view); // only in builds with a renderer
  assert_false(tx_find_controller("haptics")->view);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(a_view_that_only_reads_loads),
      cmocka_unit_test(a_view_that_writes_is_refused_in_one_line),
      cmocka_unit_test(an_ordinary_controller_may_write),
      cmocka_unit_test(a_structured_parameter_comes_as_json_text),
      cmocka_unit_test(the_builtin_views_are_views),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
