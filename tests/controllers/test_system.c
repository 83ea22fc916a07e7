// Controller systems: the checks the loader relies on, parameters, warnings.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/system.h"
#include "test_support.h"

#include <math.h>

static json_t* params(const char* text) {
  json_t* p = json_loads(text, 0, NULL);
  assert_non_null(p);
  return p;
}

// add one instance with params text; returns the fault (rc in *rc)
static tx_fault add(tx_system* s, const char* name, double rate, const char* p, int* rc) {
  tx_fault f = {0};
  json_t* js = p ? params(p) : NULL;
  *rc = tx_system_add(s, name, "test.counter", rate, js, &f);
  json_decref(js);
  return f;
}

static void rates_out_of_range_are_rejected(void** state) {
  (void)state;
  const double bad[] = {0, -1, 100000.5, 1e9, NAN, INFINITY, 1e-10, 0.0009}; // below 0.001 Hz a period overflows the clocks
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_system* s = tx_system_create();
    int rc;
    tx_fault f = add(s, "c", bad[i], NULL, &rc);
    assert_int_equal(rc, -1);
    assert_string_equal(f.key, "rate_hz");
    tx_system_destroy(s);
  }
  tx_system* s = tx_system_create();
  int rc;
  add(s, "fastest", TX_RATE_MAX_HZ, NULL, &rc);
  assert_int_equal(rc, 0);
  tx_system_destroy(s);
}

static void two_writers_are_rejected(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  int rc;
  add(s, "a", 10, "{\"write\":\"x\"}", &rc);
  add(s, "b", 20, "{\"write\":\"x\"}", &rc);
  assert_int_equal(rc, 0); // each instance alone is fine
  tx_fault f;
  assert_int_equal(tx_system_finalize(s, &f), -1);
  assert_non_null(strstr(f.message, "two writers"));
  tx_system_destroy(s);
}

static void unknown_and_unwritten_reads_are_rejected(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  int rc;
  add(s, "a", 10, "{\"read\":\"nowhere\"}", &rc);
  tx_fault f;
  assert_int_equal(tx_system_finalize(s, &f), -1);
  assert_string_equal(f.key, "a");
  assert_non_null(strstr(f.message, "unknown component 'nowhere'"));
  tx_system_destroy(s);

  // declared in the model, but nobody writes it
  s = tx_system_create();
  assert_int_equal(tx_system_declare(s, &(tx_component_def){"declared", TX_F64, 1, 2, "1"}, &f), 0);
  add(s, "a", 10, "{\"read\":\"declared\"}", &rc);
  assert_int_equal(tx_system_finalize(s, &f), -1);
  assert_non_null(strstr(f.message, "no controller writes"));
  tx_system_destroy(s);
}

// the counter reads f64 x 2; a reader that needs f64 x 15 is refused that component
static int picky_configure(tx_setup* s, void** self) {
  *self = NULL;
  tx_setup_read_as(s, tx_param_str(s, "read", "x"), TX_F64, 15);
  return 0;
}

static void picky_step(tx_ctx* c, void* self) {}

static void reads_get_the_schema_they_need(void** state) {
  (void)state;
  static const tx_controller_class picky = {.type = "test.picky", .configure = picky_configure, .step = picky_step};
  if (!tx_find_controller("test.picky")) assert_int_equal(tx_register_controller(&picky), 0);
  tx_system* s = tx_system_create();
  int rc;
  add(s, "a", 10, "{\"write\":\"x\"}", &rc);
  tx_fault f;
  assert_int_equal(tx_system_add(s, "b", "test.picky", 10, NULL, &f), 0);
  assert_int_equal(tx_system_finalize(s, &f), -1);
  assert_string_equal(f.key, "b");
  assert_non_null(strstr(f.message, "reads 'x' as f64 x 15, but it is written as f64 1x2"));
  tx_system_destroy(s);
}

static void declared_schema_must_match(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  tx_fault f;
  assert_int_equal(tx_system_declare(s, &(tx_component_def){"x", TX_F32, 1, 2, "1"}, &f), 0);
  assert_int_equal(tx_system_declare(s, &(tx_component_def){"x", TX_F32, 1, 2, "1"}, &f), -1);
  int rc;
  add(s, "a", 10, "{\"write\":\"x\"}", &rc); // writes f64, declared f32
  assert_int_equal(tx_system_finalize(s, &f), -1);
  assert_non_null(strstr(f.message, "declares"));
  tx_system_destroy(s);
}

static void parameters_are_checked(void** state) {
  (void)state;
  const struct {
    const char* params;
    const char* key;
  } bad[] = {
      {"{\"gain\":\"high\"}", "params.gain"},  // wrong type
      {"{\"gain\":1e7}", "params.gain"},       // out of range
      {"{\"write\":5}", "params.write"},       // wrong type
      {"{\"gian\":1}", "params.gian"},         // unknown
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_system* s = tx_system_create();
    int rc;
    tx_fault f = add(s, "a", 10, bad[i].params, &rc);
    assert_int_equal(rc, -1);
    assert_string_equal(f.key, bad[i].key);
    assert_true(strlen(f.message) > 0);
    tx_system_destroy(s);
  }
}

static void names_and_types_are_checked(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  tx_fault f;
  assert_int_equal(tx_system_add(s, "Bad Name", "test.counter", 10, NULL, &f), -1);
  assert_string_equal(f.key, "name");
  assert_int_equal(tx_system_add(s, "a", "no.such.type", 10, NULL, &f), -1);
  assert_string_equal(f.key, "type");
  assert_int_equal(tx_system_add(s, "a", "test.counter", 10, NULL, &f), 0);
  assert_int_equal(tx_system_add(s, "a", "test.counter", 10, NULL, &f), -1); // same name twice
  json_t* notobj = json_integer(3);
  assert_int_equal(tx_system_add(s, "b", "test.counter", 10, notobj, &f), -1);
  assert_string_equal(f.key, "params");
  json_decref(notobj);
  tx_system_destroy(s);
  s = tx_system_create();
  assert_int_equal(tx_system_finalize(s, &f), -1); // no controllers
  tx_system_destroy(s);
}

static void registry_rejects_bad_classes(void** state) {
  (void)state;
  assert_int_equal(tx_register_controller(NULL), -1);
  tx_controller_class no_step = {.type = "test.nostep", .configure = counter_configure};
  assert_int_equal(tx_register_controller(&no_step), -1);
  assert_int_equal(tx_register_controller(&test_counter), -1); // taken
  assert_null(tx_find_controller("test.nostep"));
}

static void groups_follow_rates_fastest_first(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  int rc;
  add(s, "slow", 20, NULL, &rc);
  add(s, "fast", 4000, NULL, &rc);
  add(s, "mid", 1000, NULL, &rc);
  add(s, "slow2", 20, NULL, &rc);
  tx_fault f;
  assert_int_equal(tx_system_finalize(s, &f), 0);
  assert_int_equal(tx_system_threads(s), 3);
  assert_int_equal(tx_system_thread(s, 1), 0);
  assert_int_equal(tx_system_thread(s, 2), 1);
  assert_int_equal(tx_system_thread(s, 0), 2);
  assert_int_equal(tx_system_thread(s, 3), 2);
  tx_system_destroy(s);
}

// a reader that expects units: a writer of other units is refused at load,
// and the message names both controllers and both units
static int units_configure(tx_setup* s, void** self) {
  *self = NULL;
  tx_setup_read_expect(s, "x", TX_F64, 2, tx_param_str(s, "units", "m"));
  return 0;
}

static void reads_get_the_units_they_expect(void** state) {
  (void)state;
  static const tx_controller_class cls = {.type = "test.units", .configure = units_configure, .step = picky_step};
  if (!tx_find_controller(cls.type)) assert_int_equal(tx_register_controller(&cls), 0);
  tx_system* s = tx_system_create();
  int rc;
  add(s, "writer", 10, "{\"write\":\"x\"}", &rc); // the counter writes x in "1"
  tx_fault f;
  assert_int_equal(tx_system_add(s, "reader", "test.units", 10, NULL, &f), 0);
  assert_int_equal(tx_system_finalize(s, &f), -1);
  assert_string_equal(f.key, "reader");
  assert_string_equal(f.message, "reader reads 'x' in units \"m\", but writer writes it in \"1\"");
  tx_system_destroy(s);

  // the same units pass
  s = tx_system_create();
  add(s, "writer", 10, "{\"write\":\"x\"}", &rc);
  json_t* p = params("{\"units\":\"1\"}");
  assert_int_equal(tx_system_add(s, "reader", "test.units", 10, p, &f), 0);
  json_decref(p);
  assert_int_equal(tx_system_finalize(s, &f), 0);
  tx_system_destroy(s);
}

// a controller that misuses the write calls, as a plugin might: "how" picks the mistake
typedef struct misuse {
  tx_port out, in;
  int how;
} misuse;

static int misuse_configure(tx_setup* s, void** self) {
  misuse* m = calloc(1, sizeof *m);
  *self = m;
  m->how = (int)tx_param_int(s, "how", 0, 0, 3);
  m->out = tx_setup_write(s, &(tx_component_def){"rows", TX_F64, 4, 1, "1"});
  m->in = tx_setup_read(s, "x");
  return 0;
}

static void misuse_step(tx_ctx* c, void* self) {
  misuse* m = self;
  if (tx_step_index(c) < 3) return; // fine at first
  double* p = NULL;
  switch (m->how) {
  case 0: p = tx_write(c, m->in); break;             // its read port
  case 1: p = tx_write(c, (tx_port){42}); break;     // never declared
  case 2: p = tx_write_copy(c, (tx_port){0}); break; // the invalid port
  case 3: tx_write(c, m->out), tx_write_rows(c, m->out, 5); return; // one row beyond the four it declared
  }
  if (p) p[0] = 1; // never: a bad port gives NULL
}

static void misuse_fini(void* self) { free(self); }

static void misused_writes_stop_the_run(void** state) {
  (void)state;
  static const tx_controller_class cls = {.type = "test.misuse", .configure = misuse_configure, .step = misuse_step,
                                          .fini = misuse_fini};
  if (!tx_find_controller(cls.type)) assert_int_equal(tx_register_controller(&cls), 0);
  const char* want[] = {
      "plugin: tx_write on port 2 ('x'), which it declared as a read, not a write",
      "plugin: tx_write on port 42, which it never declared (it has 2 ports)",
      "plugin: tx_write_copy on port 0, which it never declared (it has 2 ports)",
      "plugin: tx_write_rows(5) on 'rows', beyond its capacity of 4 rows",
  };
  for (int how = 0; how < 4; how++) {
    for (int lock = 1; lock >= 0; lock--) {
      tx_system* s = tx_system_create();
      int rc;
      add(s, "writer", 100, "{\"write\":\"x\"}", &rc);
      char text[32];
      snprintf(text, sizeof text, "{\"how\":%d}", how);
      json_t* p = params(text);
      tx_fault f;
      assert_int_equal(tx_system_add(s, "plugin", "test.misuse", 100, p, &f), 0);
      json_decref(p);
      assert_int_equal(tx_system_finalize(s, &f), 0);
      tx_run_options o = {.duration_s = 2, .lockstep = lock};
      tx_run_result r;
      char err[256];
      assert_int_equal(tx_system_run(s, &o, &r, err, sizeof err), 0);
      assert_true(r.halted);
      assert_string_equal(r.halt_reason, want[how]);
      // step 3 is at 30 ms; in real time a late tick may be skipped, never an early one taken
      assert_true(lock ? fabs(r.halt_t_s - 0.03) < 1e-9 : r.halt_t_s > 0.03 - 1e-9);
      uint64_t bad = 0, clamped = 0;
      for (int w = 0; w < tx_system_warnings(s); w++) {
        if (strcmp(tx_system_warning_key(s, w), "plugin.bad_port") == 0) bad = tx_system_warning_count(s, w);
        if (strcmp(tx_system_warning_key(s, w), "plugin.rows_clamped") == 0) clamped = tx_system_warning_count(s, w);
      }
      assert_true(how == 3 ? (bad == 0 && clamped >= 1) : (bad >= 1 && clamped == 0));
      if (how == 3) { // still clamped, so no reader looks past the buffer
        tx_model* m = tx_system_model(s);
        assert_int_equal(tx_model_latest(m, tx_model_find(m, "rows")).rows, 4);
      }
      tx_system_destroy(s);
    }
  }
}

int main(void) {
  register_test_classes();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(rates_out_of_range_are_rejected),
      cmocka_unit_test(two_writers_are_rejected),
      cmocka_unit_test(unknown_and_unwritten_reads_are_rejected),
      cmocka_unit_test(declared_schema_must_match),
      cmocka_unit_test(reads_get_the_schema_they_need),
      cmocka_unit_test(reads_get_the_units_they_expect),
      cmocka_unit_test(misused_writes_stop_the_run),
      cmocka_unit_test(parameters_are_checked),
      cmocka_unit_test(names_and_types_are_checked),
      cmocka_unit_test(registry_rejects_bad_classes),
      cmocka_unit_test(groups_follow_rates_fastest_first),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
