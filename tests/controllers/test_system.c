// Controller systems: the checks the loader relies on, parameters, warnings.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/system.h"
#include "controllers/system_internal.h"
#include "test_support.h"

#include <math.h>

static json_t* params(const char* text) {
  json_t* p = json_loads(text, 0, NULL);
  assert_non_null(p);
  return p;
}

// add one instance with params text (rc in *rc; the error in tx_error())
static void add(tx_system* s, const char* name, double rate, const char* p, int* rc) {
  json_t* js = p ? params(p) : NULL;
  *rc = tx_system_add(s, name, "test.counter", rate, js);
  json_decref(js);
}

static void rates_out_of_range_are_rejected(void** state) {
  (void)state;
  const double bad[] = {0, -1, 100000.5, 1e9, NAN, INFINITY, 1e-10, 0.0009}; // below 0.001 Hz a period overflows the clocks
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_system* s = tx_system_create();
    int rc;
    add(s, "c", bad[i], NULL, &rc);
    assert_int_equal(rc, -1);
    assert_string_equal(tx_error_key(), "rate_hz");
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
  assert_int_equal(tx_system_finalize(s), -1);
  assert_non_null(strstr(tx_error(), "two writers"));
  tx_system_destroy(s);
}

static void unknown_and_unwritten_reads_are_rejected(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  int rc;
  add(s, "a", 10, "{\"read\":\"nowhere\"}", &rc);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_string_equal(tx_error_key(), "a");
  assert_non_null(strstr(tx_error(), "unknown component 'nowhere'"));
  tx_system_destroy(s);

  // declared in the model, but nobody writes it
  s = tx_system_create();
  assert_int_equal(tx_system_declare(s, &(tx_component_def){"declared", TX_F64, 1, 2, "1"}), 0);
  add(s, "a", 10, "{\"read\":\"declared\"}", &rc);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_non_null(strstr(tx_error(), "no controller writes"));
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
  assert_int_equal(tx_system_add(s, "b", "test.picky", 10, NULL), 0);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_string_equal(tx_error_key(), "b");
  assert_non_null(strstr(tx_error(), "reads 'x' as f64 x 15, but it is written as f64 1x2"));
  tx_system_destroy(s);
}

static void declared_schema_must_match(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  assert_int_equal(tx_system_declare(s, &(tx_component_def){"x", TX_F32, 1, 2, "1"}), 0);
  assert_int_equal(tx_system_declare(s, &(tx_component_def){"x", TX_F32, 1, 2, "1"}), -1);
  int rc;
  add(s, "a", 10, "{\"write\":\"x\"}", &rc); // writes f64, declared f32
  assert_int_equal(tx_system_finalize(s), -1);
  assert_non_null(strstr(tx_error(), "declares"));
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
    add(s, "a", 10, bad[i].params, &rc);
    assert_int_equal(rc, -1);
    assert_string_equal(tx_error_key(), bad[i].key);
    assert_true(strlen(tx_error()) > 0);
    tx_system_destroy(s);
  }
}

static void names_and_types_are_checked(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  assert_int_equal(tx_system_add(s, "Bad Name", "test.counter", 10, NULL), -1);
  assert_string_equal(tx_error_key(), "name");
  assert_int_equal(tx_system_add(s, "a", "no.such.type", 10, NULL), -1);
  assert_string_equal(tx_error_key(), "type");
  assert_int_equal(tx_system_add(s, "a", "test.counter", 10, NULL), 0);
  assert_int_equal(tx_system_add(s, "a", "test.counter", 10, NULL), -1); // same name twice
  json_t* notobj = json_integer(3);
  assert_int_equal(tx_system_add(s, "b", "test.counter", 10, notobj), -1);
  assert_string_equal(tx_error_key(), "params");
  json_decref(notobj);
  tx_system_destroy(s);
  s = tx_system_create();
  assert_int_equal(tx_system_finalize(s), -1); // no controllers
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
  assert_int_equal(tx_system_finalize(s), 0);
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
  assert_int_equal(tx_system_add(s, "reader", "test.units", 10, NULL), 0);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_string_equal(tx_error_key(), "reader");
  assert_string_equal(tx_error(), "reader reads 'x' in units \"m\", but writer writes it in \"1\"");
  tx_system_destroy(s);

  // the same units pass
  s = tx_system_create();
  add(s, "writer", 10, "{\"write\":\"x\"}", &rc);
  json_t* p = params("{\"units\":\"1\"}");
  assert_int_equal(tx_system_add(s, "reader", "test.units", 10, p), 0);
  json_decref(p);
  assert_int_equal(tx_system_finalize(s), 0);
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
      assert_int_equal(tx_system_add(s, "plugin", "test.misuse", 100, p), 0);
      json_decref(p);
      assert_int_equal(tx_system_finalize(s), 0);
      tx_run_options o = {.duration_s = 2, .lockstep = lock};
      tx_run_result r;
      assert_int_equal(tx_system_run(s, &o, &r), 0);
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

static void add_as(tx_system* s, const char* name, const char* type, double rate, const char* p, int* rc) {
  json_t* js = p ? params(p) : NULL;
  *rc = tx_system_add(s, name, type, rate, js);
  json_decref(js);
}

// haptics instances run alone and first, whatever their rate; the rest share by rate
static void haptics_never_shares_a_thread(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  int rc;
  add(s, "tissue", 1000, NULL, &rc);                       // 0
  add_as(s, "hap", "haptics.test", 1000, NULL, &rc);       // 1
  add(s, "physics", 60, NULL, &rc);                        // 2
  add_as(s, "hap2", "test.alone", 1000, NULL, &rc);        // 3: by the class flag
  add(s, "collision", 1000, NULL, &rc);                    // 4
  add_as(s, "slowhap", "haptics.test", 10, NULL, &rc);     // 5: even at 10 Hz
  assert_int_equal(rc, 0);
  assert_int_equal(tx_system_finalize(s), 0);
  assert_int_equal(tx_system_threads(s), 5);
  // own threads first, in rate then scenario order
  assert_int_equal(tx_system_thread(s, 1), 0);
  assert_int_equal(tx_system_thread(s, 3), 1);
  assert_int_equal(tx_system_thread(s, 5), 2);
  for (int t = 0; t < 3; t++) assert_true(tx_system_thread_own(s, t));
  assert_int_equal(tx_system_thread(s, 0), 3); // tissue and collision: one 1 kHz thread
  assert_int_equal(tx_system_thread(s, 4), 3);
  assert_int_equal(tx_system_thread(s, 2), 4);
  assert_false(tx_system_thread_own(s, 3));
  assert_null(tx_system_thread_name(s, 3));
  // priority below haptics ranks by rate: 1 kHz, then 60 Hz
  assert_int_equal(s->threads[3].rank, 0);
  assert_int_equal(s->threads[4].rank, 1);
  tx_system_destroy(s);
}

static int set_thread(tx_system* s, const char* name) {
  return tx_system_set_thread(s, tx_system_count(s) - 1, name);
}

// a scenario's thread: shared by its instances of one rate, never by two rates or a haptics instance
static void named_threads(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  int rc;
  add(s, "tissue", 1000, NULL, &rc);
  assert_int_equal(set_thread(s, "tissue"), 0);
  add(s, "tissue2", 1000, NULL, &rc);
  assert_int_equal(set_thread(s, "tissue"), 0);
  add(s, "other", 1000, NULL, &rc); // no name: its own rate thread
  add(s, "slow", 20, NULL, &rc);
  assert_int_equal(set_thread(s, "tissue"), -1); // another rate
  assert_string_equal(tx_error_key(), "thread");
  assert_non_null(strstr(tx_error(), "'tissue' runs tissue at 1000 Hz; slow at 20 Hz cannot share it"));
  add_as(s, "hap", "haptics.test", 1000, NULL, &rc);
  assert_int_equal(set_thread(s, "tissue"), -1);
  assert_non_null(strstr(tx_error(), "runs alone"));
  assert_int_equal(set_thread(s, "device"), 0); // a name alone is fine
  static const char* const bad[] = {"", "Tissue", "a b", "a.b", "a/b", "0123456789012345678901234567890x"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(set_thread(s, bad[i]), -1);
    assert_string_equal(tx_error_key(), "thread");
    assert_non_null(strstr(tx_error(), "1-31 characters of a-z 0-9 _ -"));
  }
  assert_int_equal(set_thread(s, "abcdefghijklmnopqrstuvwxyz01234"), 0); // 31 characters
  assert_int_equal(tx_system_finalize(s), 0);
  assert_int_equal(tx_system_threads(s), 4); // hap; tissue+tissue2; other; slow
  assert_int_equal(tx_system_thread(s, 4), 0);
  assert_int_equal(tx_system_thread(s, 0), tx_system_thread(s, 1));
  assert_int_not_equal(tx_system_thread(s, 0), tx_system_thread(s, 2));
  assert_string_equal(tx_system_thread_name(s, tx_system_thread(s, 0)), "tissue");
  assert_null(tx_system_thread_name(s, tx_system_thread(s, 2)));
  // threads of one rate share a priority; the 20 Hz one is next below
  assert_int_equal(s->threads[tx_system_thread(s, 0)].rank, 0);
  assert_int_equal(s->threads[tx_system_thread(s, 2)].rank, 0);
  assert_int_equal(s->threads[tx_system_thread(s, 3)].rank, 1);
  tx_system_destroy(s);
}

static tx_system* events_system(const char* writer, const char* reader, const char* reader2) {
  tx_system* s = tx_system_create();
  int rc;
  add_as(s, "writer", "test.events", 1000, writer, &rc);
  assert_int_equal(rc, 0);
  if (reader) add_as(s, "reader", "test.events", 20, reader, &rc), assert_int_equal(rc, 0);
  if (reader2) add_as(s, "reader2", "test.events", 60, reader2, &rc), assert_int_equal(rc, 0);
  return s;
}

static void event_streams_are_checked(void** state) {
  (void)state;
  int rc;
  // two writers
  tx_system* s = events_system("{\"emit\":\"tool0.events\"}", "{\"emit\":\"tool0.events\"}", NULL);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_string_equal(tx_error_key(), "reader");
  assert_string_equal(tx_error(), "event stream 'tool0.events' has two writers: writer and reader");
  tx_system_destroy(s);
  // a listen that nobody emits
  s = events_system("{\"emit\":\"tool0.events\"}", "{\"listen\":\"tool1.events\"}", NULL);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_string_equal(tx_error_key(), "reader");
  assert_string_equal(tx_error(), "listens to event stream 'tool1.events', which no controller emits");
  tx_system_destroy(s);
  // a stream is not a component: a read of it has no writer
  s = events_system("{\"emit\":\"tool0.events\"}", NULL, NULL);
  add(s, "c", 10, "{\"read\":\"tool0.events\"}", &rc);
  assert_int_equal(tx_system_finalize(s), -1);
  assert_non_null(strstr(tx_error(), "reads unknown component 'tool0.events'"));
  tx_system_destroy(s);
  // capacities and names
  static const char* const bad[] = {"{\"emit\":\"e\",\"capacity\":3}", "{\"emit\":\"e\",\"capacity\":0}",
                                    "{\"emit\":\"e\",\"capacity\":1}", "{\"emit\":\"e\",\"capacity\":2097152}",
                                    "{\"emit\":\"Bad name\"}", "{\"listen\":\"\"}"};
  static const char* const why[] = {"capacity 3 is not a power of two in [2, 1048576]", "capacity 0", "capacity 1",
                                    "capacity 2097152", "bad component name 'Bad name'", "bad component name ''"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    s = tx_system_create();
    add_as(s, "w", "test.events", 100, bad[i], &rc);
    assert_int_equal(rc, -1);
    if (!strstr(tx_error(), why[i])) fail_msg("'%s' does not mention '%s'", tx_error(), why[i]);
    tx_system_destroy(s);
  }
  // at most TX_STREAM_READERS_MAX listeners
  s = events_system("{\"emit\":\"e\"}", NULL, NULL);
  for (int i = 0; i <= TX_STREAM_READERS_MAX; i++) {
    char name[16];
    snprintf(name, sizeof name, "r%d", i);
    add_as(s, name, "test.events", 10, "{\"listen\":\"e\"}", &rc);
  }
  assert_int_equal(tx_system_finalize(s), -1);
  assert_string_equal(tx_error_key(), "r16");
  assert_non_null(strstr(tx_error(), "more than 16 listeners"));
  tx_system_destroy(s);
}

static tx_stream_info run_events(tx_system* s, bool lock, double seconds) {
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = seconds, .lockstep = lock};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_false(r.halted);
  assert_int_equal(tx_system_streams(s), 1);
  return tx_system_stream(s, 0);
}

static eventer* self_of(tx_system* s, int i) { return s->inst[i]->self; }

// 1 kHz writer, 20 Hz and 60 Hz readers: each sees every event once and in order
static void events_reach_every_listener_in_lockstep(void** state) {
  (void)state;
  tx_system* s = events_system("{\"emit\":\"tool0.events\"}", "{\"listen\":\"tool0.events\"}",
                               "{\"listen\":\"tool0.events\"}");
  for (int run = 0; run < 2; run++) { // a second run starts with empty streams
    tx_stream_info st = run_events(s, true, 1.0);
    assert_string_equal(st.name, "tool0.events");
    assert_string_equal(st.writer, "writer");
    assert_int_equal(st.capacity, 1024);
    assert_int_equal(st.sent, 1000);
    assert_int_equal(st.overflows, 0);
    assert_int_equal(st.nreaders, 2);
    assert_string_equal(st.readers[0], "reader");
    assert_string_equal(st.readers[1], "reader2");
    assert_int_equal(st.lost[0], 0);
    assert_int_equal(st.lost[1], 0);
    // the 20 Hz reader's last step is at 950 ms, before the writer's tick there
    assert_int_equal(self_of(s, 1)->received, 950);
    assert_int_equal(self_of(s, 1)->last_seq, 950);
    assert_int_equal(self_of(s, 2)->received, 984); // 60 Hz: last step at 983.3 ms
    for (int i = 1; i <= 2; i++) {
      assert_int_equal(self_of(s, i)->gaps, 0);
      assert_int_equal(self_of(s, i)->out_of_order, 0);
    }
  }
  tx_system_destroy(s);
}

// a ring of 16 behind a 20 Hz reader: pushes are refused and counted, the reader counts the gaps
static void a_full_stream_is_counted(void** state) {
  (void)state;
  tx_system* s = events_system("{\"emit\":\"e\",\"capacity\":16}", "{\"listen\":\"e\"}", NULL);
  tx_stream_info st = run_events(s, true, 1.0);
  eventer *w = self_of(s, 0), *r = self_of(s, 1);
  assert_int_equal(st.sent, 1000);
  assert_int_equal(st.overflows, 20 * 34); // 16 of each 50 between reads get through
  assert_int_equal(w->dropped, st.overflows); // tx_emit said so each time
  assert_int_equal(st.lost[0], r->gaps);
  assert_true(r->gaps > 0);
  assert_int_equal(r->out_of_order, 0);
  assert_int_equal(r->received + r->gaps, r->last_seq); // every seq up to the last: taken or counted lost
  assert_int_equal(r->received, 19 * 16);  // reads at 50 ms .. 950 ms, a full ring each
  tx_system_destroy(s);
}

// tx_emit on a listen port, tx_next_event on an emit port: counted, and the run stops
static void misused_events_stop_the_run(void** state) {
  (void)state;
  static const char* const want[] = {"writer: tx_next_event on port 1, which it did not declare with tx_setup_listen",
                                     "writer: tx_emit on port 1, which it did not declare with tx_setup_emit"};
  tx_system* s = tx_system_create();
  int rc;
  add_as(s, "writer", "test.events", 100, "{\"emit\":\"e\"}", &rc);
  add_as(s, "reader", "test.events", 100, "{\"listen\":\"e\"}", &rc);
  assert_int_equal(tx_system_finalize(s), 0);
  for (int which = 0; which < 2; which++) {
    // swap the ports: the writer now listens on its emit port, or the reader emits on its listen port
    eventer* e = self_of(s, which);
    tx_port good_in = e->in, good_out = e->out;
    if (which == 0) e->in = e->out;
    else e->out = e->in;
    tx_run_options o = {.duration_s = 0.5, .lockstep = true};
    tx_run_result r;
    assert_int_equal(tx_system_run(s, &o, &r), 0);
    assert_true(r.halted);
    const char* expect = which == 0 ? want[0] : "reader: tx_emit on port 1, which it did not declare with tx_setup_emit";
    assert_string_equal(r.halt_reason, expect);
    e->in = good_in, e->out = good_out;
  }
  tx_system_destroy(s);
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
      cmocka_unit_test(haptics_never_shares_a_thread),
      cmocka_unit_test(named_threads),
      cmocka_unit_test(event_streams_are_checked),
      cmocka_unit_test(events_reach_every_listener_in_lockstep),
      cmocka_unit_test(a_full_stream_is_counted),
      cmocka_unit_test(misused_events_stop_the_run),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
