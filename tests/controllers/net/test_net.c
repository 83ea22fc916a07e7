// controllers/net/: the domain's configuration, QoS per kind, packing and the
// checks of received samples; then the bridge itself, two roles of one
// scenario in this process over loopback DDS: a component mirrored with the
// local time of its arrival, events once and in order, foreign and malformed
// samples dropped and counted.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/net/net.h"
#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <tactus/events.h>

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void no_peers_binds_loopback_without_multicast(void** state) {
  (void)state;
  char xml[TX_NET_CONFIG_MAX];
  assert_int_equal(tx_net_config(xml, sizeof xml, NULL, 0), 0);
  assert_non_null(strstr(xml, "<NetworkInterface address=\"127.0.0.1\"/>"));
  assert_non_null(strstr(xml, "<AllowMulticast>false</AllowMulticast>"));
  assert_non_null(strstr(xml, "<Peers><Peer address=\"127.0.0.1\"/></Peers>"));
  const char* peers[] = {"10.0.0.2", "sim-host.local"};
  assert_int_equal(tx_net_config(xml, sizeof xml, peers, 2), 0);
  assert_null(strstr(xml, "address=\"127.0.0.1\"/></Interfaces>"));
  assert_non_null(strstr(xml, "<Peer address=\"10.0.0.2\"/><Peer address=\"sim-host.local\"/>"));
}

static void malformed_peers_are_refused(void** state) {
  (void)state;
  const char* bad[] = {"", "10.0.0.300", "a b", "-x", "host..name", "1.2.3", "x;rm", "<Peer/>"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_false(tx_net_peer_valid(bad[i]));
    assert_true(strlen(tx_error()) > 0);
  }
  const char* good[] = {"127.0.0.1", "192.168.1.20", "sim", "sim-2.lab.example"};
  for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) assert_true(tx_net_peer_valid(good[i]));
  char xml[TX_NET_CONFIG_MAX];
  const char* peers[] = {"10.0.0.2", "10.0.0.256"};
  assert_int_equal(tx_net_config(xml, sizeof xml, peers, 2), -1);
  assert_non_null(strstr(tx_error(), "peers[1]"));
}

static void tags_and_topic_names(void** state) {
  (void)state;
  assert_true(tx_net_session_tag("suturing-skin", 0) != tx_net_session_tag("suturing-skin", 1));
  assert_true(tx_net_session_tag("suturing-skin", 0) != tx_net_session_tag("haptics-wall", 0));
  assert_true(tx_net_session_tag("a", 3) == tx_net_session_tag("a", 3));
  char t[96];
  tx_net_topic_name(t, sizeof t, false, "device0.pose");
  assert_string_equal(t, "tx/c/device0/pose");
  tx_net_topic_name(t, sizeof t, true, "tool0.events");
  assert_string_equal(t, "tx/e/tool0/events");
}

// the QoS table of docs/distributed.md
static void qos_per_kind(void** state) {
  (void)state;
  struct { tx_net_kind kind; dds_reliability_kind_t rel; dds_durability_kind_t dur; dds_history_kind_t hist; int32_t depth; } want[] = {
      {TX_NET_FAST, DDS_RELIABILITY_BEST_EFFORT, DDS_DURABILITY_VOLATILE, DDS_HISTORY_KEEP_LAST, 1},
      {TX_NET_STATE, DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_TRANSIENT_LOCAL, DDS_HISTORY_KEEP_LAST, 1},
      {TX_NET_EVENTS, DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_TRANSIENT_LOCAL, DDS_HISTORY_KEEP_ALL, 0},
  };
  for (size_t i = 0; i < 3; i++) {
    dds_qos_t* q = tx_net_qos(want[i].kind);
    dds_reliability_kind_t rel;
    dds_duration_t blocking;
    dds_durability_kind_t dur;
    dds_history_kind_t hist;
    int32_t depth = -1;
    assert_true(dds_qget_reliability(q, &rel, &blocking));
    assert_true(dds_qget_durability(q, &dur));
    assert_true(dds_qget_history(q, &hist, &depth));
    assert_int_equal(rel, want[i].rel);
    assert_int_equal(dur, want[i].dur);
    assert_int_equal(hist, want[i].hist);
    if (hist == DDS_HISTORY_KEEP_LAST) assert_int_equal(depth, want[i].depth);
    if (want[i].kind == TX_NET_EVENTS) {
      dds_destination_order_kind_t order;
      assert_true(dds_qget_destination_order(q, &order));
      assert_int_equal(order, DDS_DESTINATIONORDER_BY_SOURCE_TIMESTAMP);
    }
    dds_delete_qos(q);
  }
}

static void received_samples_are_checked(void** state) {
  (void)state;
  double pose[7] = {1, 2, 3, 1, 0, 0, 0};
  tx_snapshot snap = {.data = pose, .rows = 1, .cols = 7, .seq = 5, .sim_ns = 123, .mono_ns = 456};
  tx_component_def def = {"device0.pose", TX_F64, 1, 7, "m"};
  uint64_t tag = tx_net_session_tag("s", 0);
  tx_net_Snapshot s;
  tx_net_pack(&s, tag, "device0.pose", TX_F64, &snap);
  assert_int_equal(s.data._length, 7 * sizeof(double));
  assert_int_equal(s.sim_ns, 123);
  assert_int_equal(s.mono_ns, 456); // the writer's publish, not the send
  assert_int_equal(tx_net_check(&s, tag, &def), 0);
  assert_int_equal(tx_net_check(&s, tag + 1, &def), 1); // another session
  tx_net_Snapshot bad = s;
  strcpy(bad.name, "device1.pose");
  assert_int_equal(tx_net_check(&bad, tag, &def), 2);
  bad = s, bad.type = TX_F32;
  assert_int_equal(tx_net_check(&bad, tag, &def), 2);
  bad = s, bad.cols = 3;
  assert_int_equal(tx_net_check(&bad, tag, &def), 2);
  bad = s, bad.rows = 2; // beyond the capacity, and the length disagrees
  assert_int_equal(tx_net_check(&bad, tag, &def), 2);
  bad = s, bad.data._length = 8;
  assert_int_equal(tx_net_check(&bad, tag, &def), 2);
  memset(bad.name, 'x', sizeof bad.name); // no terminator
  assert_int_equal(tx_net_check(&bad, tag, &def), 2);

  tx_event e = {.seq = 9, .sim_ns = 77, .kind = TX_EVENT_PUNCTURE, .source = 4, .value = {1, 2, 3, 4, 5}};
  tx_net_Event ev;
  tx_net_pack_event(&ev, tag, "skin.events", &e);
  assert_int_equal(tx_net_check_event(&ev, tag, "skin.events"), 0);
  assert_int_equal(tx_net_check_event(&ev, tag ^ 1, "skin.events"), 1);
  assert_int_equal(tx_net_check_event(&ev, tag, "tool0.events"), 2);
  tx_event back;
  tx_net_unpack_event(&ev, &back);
  assert_int_equal(back.seq, 9);
  assert_int_equal(back.sim_ns, 77);
  assert_int_equal(back.kind, TX_EVENT_PUNCTURE);
  assert_int_equal(back.source, 4);
  assert_memory_equal(back.value, e.value, sizeof e.value);
}

// ---- the bridge: a writer role and a reader role of one scenario, in this process

typedef struct src {
  tx_port out, ev;
} src;
static int src_configure(tx_setup* s, void** self) {
  src* c = calloc(1, sizeof *c);
  *self = c;
  c->out = tx_setup_write(s, &(tx_component_def){"t.val", TX_F64, 4, 3, "m"});
  c->ev = tx_setup_emit(s, "t.ev", 1024);
  return 0;
}
static void src_step(tx_ctx* ctx, void* self) {
  src* c = self;
  double* v = tx_write(ctx, c->out);
  for (int i = 0; i < 12; i++) v[i] = (double)tx_step_index(ctx) + 0.25 * i;
  tx_write_rows(ctx, c->out, 2 + (uint32_t)(tx_step_index(ctx) % 3));
  tx_emit(ctx, c->ev, &(tx_event){.kind = TX_EVENT_USER, .source = 7, .value = {(double)tx_step_index(ctx)}});
}

static struct {
  uint64_t seen, events, out_of_order, last;
  bool consistent;      // every mirrored snapshot is whole: its rows and values agree with one step
  uint64_t stale;       // mirrored snapshots whose local time of arrival is over 20 ms before the read
} got;
typedef struct dst {
  tx_port in, ev;
  uint64_t last_seq;
} dst;
static int dst_configure(tx_setup* s, void** self) {
  dst* c = calloc(1, sizeof *c);
  *self = c;
  c->in = tx_setup_read_as(s, "t.val", TX_F64, 3);
  c->ev = tx_setup_listen(s, "t.ev");
  return 0;
}
static void dst_step(tx_ctx* ctx, void* self) {
  dst* c = self;
  tx_snapshot s = tx_read(ctx, c->in);
  if (s.seq && s.seq != c->last_seq) {
    c->last_seq = s.seq;
    const double* v = s.data;
    uint64_t k = (uint64_t)v[0];
    got.seen++;
    if (s.rows != 2 + k % 3 || v[s.rows * 3 - 1] != (double)k + 0.25 * (s.rows * 3 - 1)) got.consistent = false;
    // stamped with the local time of arrival: fresh while the writer runs (every 2 ms)
    if (tx_sim_ns(ctx) - s.sim_ns > 20000000) got.stale++;
  }
  for (tx_event e; tx_next_event(ctx, c->ev, &e);) {
    if (e.kind != TX_EVENT_USER || e.source != 7 || (got.events && e.value[0] != (double)got.last + 1)) got.out_of_order++;
    got.last = (uint64_t)e.value[0];
    got.events++;
  }
}

static const tx_controller_class test_classes[] = {
    {.type = "t.src", .summary = "test writer", .configure = src_configure, .step = src_step, .fini = free},
    {.type = "t.dst", .summary = "test reader", .configure = dst_configure, .step = dst_step, .fini = free},
};

static const char* scenario_text_at(int domain, double net_hz, int poll_us) {
  static char text[1024];
  snprintf(text, sizeof text,
           "{\"name\": \"net-test-%d\", \"roles\": {\"a\": [\"src\"], \"b\": [\"dst\"]},"
           " \"net\": {\"domain\": %d, \"rate_hz\": %g, \"poll_us\": %d, \"state\": [\"t.val\"], \"streams\": [\"t.ev\"]},"
           " \"controllers\": [{\"name\": \"src\", \"type\": \"t.src\", \"rate_hz\": 500},"
           " {\"name\": \"dst\", \"type\": \"t.dst\", \"rate_hz\": 1000}]}",
           (int)getpid(), domain, net_hz, poll_us);
  return text;
}
static const char* scenario_text(int domain) { return scenario_text_at(domain, 2000, 100); }

typedef struct runner {
  tx_scenario* sc;
  double seconds;
  int rc;
} runner;
static void* run_thread(void* arg) {
  runner* r = arg;
  tx_run_options o = {.duration_s = r->seconds};
  tx_run_result res;
  r->rc = tx_system_run(r->sc->system, &o, &res);
  return NULL;
}

static void roles_build_the_bridge(void** state) {
  (void)state;
  for (size_t i = 0; i < 2; i++)
    if (!tx_find_controller(test_classes[i].type)) tx_register_controller(&test_classes[i]);
  const char* text = scenario_text(150);
  tx_load_options oa = {.role = "a"}, ob = {.role = "b"};
  tx_scenario* a = tx_scenario_load_text("t.json", text, strlen(text), &oa);
  assert_non_null(a);
  assert_int_equal(tx_system_count(a->system), 2); // src and the bridge
  assert_string_equal(tx_system_name(a->system, 1), "net");
  tx_scenario* b = tx_scenario_load_text("t.json", text, strlen(text), &ob);
  assert_non_null(b);
  assert_int_equal(tx_system_count(b->system), 2);
  // the mirror has the writer's schema
  tx_comp c = tx_model_find(tx_system_model(b->system), "t.val");
  assert_true(c.id != 0);
  const tx_component_def* d = tx_model_def(tx_system_model(b->system), c);
  assert_int_equal(d->type, TX_F64);
  assert_int_equal(d->rows, 4);
  assert_int_equal(d->cols, 3);
  assert_string_equal(d->units, "m");
  json_t* p = tx_system_params(b->system, 1);
  assert_int_equal(json_array_size(json_object_get(p, "receive")), 1);
  assert_int_equal(json_integer_value(json_object_get(json_array_get(json_object_get(p, "receive_streams"), 0), "capacity")), 1024);
  tx_scenario_free(a);
  tx_scenario_free(b);
}

static void a_session_in_one_process(void** state) {
  (void)state;
  for (size_t i = 0; i < 2; i++)
    if (!tx_find_controller(test_classes[i].type)) tx_register_controller(&test_classes[i]);
  int domain = 150 + (int)(getpid() % 50);
  const char* text = scenario_text(domain);
  tx_load_options oa = {.role = "a"}, ob = {.role = "b"};
  tx_scenario* a = tx_scenario_load_text("t.json", text, strlen(text), &oa);
  tx_scenario* b = tx_scenario_load_text("t.json", text, strlen(text), &ob);
  assert_non_null(a);
  assert_non_null(b);
  memset(&got, 0, sizeof got);
  got.consistent = true;

  // a foreign sample (another session's tag) and a malformed one on the mirror's topic
  dds_entity_t pp = tx_net_participant(domain, NULL, 0);
  assert_true(pp > 0);
  dds_qos_t* q = tx_net_qos(TX_NET_STATE);
  dds_entity_t topic = dds_create_topic(pp, &tx_net_Snapshot_desc, "tx/c/t/val", q, NULL);
  dds_entity_t w = dds_create_writer(pp, topic, q, NULL);
  dds_delete_qos(q);
  assert_true(w > 0);

  runner rb = {b, 1.6, 0}, ra = {a, 1.0, 0};
  pthread_t tb, ta;
  pthread_create(&tb, NULL, run_thread, &rb);
  usleep(200000); // the reader up first
  pthread_create(&ta, NULL, run_thread, &ra);
  usleep(500000);
  double foreign[12] = {0}, wide[12] = {0};
  tx_snapshot fs = {.data = foreign, .rows = 2, .cols = 3, .seq = 1};
  tx_net_Snapshot s;
  tx_net_pack(&s, tx_net_session_tag("another", domain), "t.val", TX_F64, &fs);
  assert_int_equal(dds_write(w, &s), 0);
  tx_snapshot ws = {.data = wide, .rows = 2, .cols = 6, .seq = 1}; // 6 columns: not the mirror's schema
  char name[64];
  snprintf(name, sizeof name, "net-test-%d", (int)getpid());
  tx_net_pack(&s, tx_net_session_tag(name, domain), "t.val", TX_F64, &ws);
  assert_int_equal(dds_write(w, &s), 0);
  pthread_join(ta, NULL);
  pthread_join(tb, NULL);
  dds_delete(pp);
  assert_int_equal(ra.rc, 0);
  assert_int_equal(rb.rc, 0);

  // 500 publishes in 1 s, reliable: the reader at 1 kHz sees most of them, each whole
  assert_true(got.seen > 100);
  assert_true(got.consistent);
  assert_true(got.stale * 10 < got.seen);
  // the writer's process ended at about 1.2 s of the reader's 1.6: the mirror's age shows it
  int64_t last = latest_snapshot(b, "t.val").sim_ns;
  assert_true(last > 900000000 && last < 1400000000);
  // events: every one, once and in order (reliable, keep all)
  assert_int_equal(got.events, (uint64_t)result(a, "net.events_sent"));
  assert_true(got.events >= 300);
  assert_int_equal(got.out_of_order, 0);
  assert_int_equal(warnings(b, "net.events_lost"), 0);
  assert_int_equal(warnings(b, "net.foreign_samples"), 1);
  assert_int_equal(warnings(b, "net.malformed_samples"), 1);
  assert_true(result(b, "net.t.val.latency_p99_us") > 0);
  tx_scenario_free(a);
  tx_scenario_free(b);
}

// sending on publish (poll_us 0, the default): the bridges step at 4 Hz, so
// sending from the step would carry 4 of the writer's 500 publishes a second,
// each up to 250 ms late; the publish hook sends every one at once. The
// bridge's finish, after its last tick (0.75 s), ends its counts and hooks
static void sends_on_publish_not_on_its_tick(void** state) {
  (void)state;
  for (size_t i = 0; i < 2; i++)
    if (!tx_find_controller(test_classes[i].type)) tx_register_controller(&test_classes[i]);
  int domain = 200 + (int)(getpid() % 30);
  const char* text = scenario_text_at(domain, 4, 0);
  tx_load_options oa = {.role = "a"}, ob = {.role = "b"};
  tx_scenario* a = tx_scenario_load_text("t.json", text, strlen(text), &oa);
  tx_scenario* b = tx_scenario_load_text("t.json", text, strlen(text), &ob);
  assert_non_null(a);
  assert_non_null(b);
  memset(&got, 0, sizeof got);
  got.consistent = true;
  runner rb = {b, 1.4, 0}, ra = {a, 1.0, 0};
  pthread_t tb, ta;
  pthread_create(&tb, NULL, run_thread, &rb);
  usleep(200000);
  pthread_create(&ta, NULL, run_thread, &ra);
  pthread_join(ta, NULL);
  pthread_join(tb, NULL);
  assert_int_equal(ra.rc, 0);
  assert_int_equal(rb.rc, 0);
  double sent = result(a, "net.samples_sent");
  assert_true(sent >= 300 && sent <= 400); // every publish up to 0.75 s (init's and 375 steps), none twice
  assert_true(got.seen > 250);              // the reader, at 1 kHz, sees most of them
  assert_true(got.consistent);
  // publish -> mirrored, one host: far below the bridge's 500 ms tick (loose, for a loaded machine)
  assert_true(result(b, "net.t.val.latency_p50_us") > 0);
  assert_true(result(b, "net.t.val.latency_p50_us") < 20000);
  tx_scenario_free(a);
  tx_scenario_free(b);
}

int main(void) {
  tx_register_builtin();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(no_peers_binds_loopback_without_multicast),
      cmocka_unit_test(malformed_peers_are_refused),
      cmocka_unit_test(tags_and_topic_names),
      cmocka_unit_test(qos_per_kind),
      cmocka_unit_test(received_samples_are_checked),
      cmocka_unit_test(roles_build_the_bridge),
      cmocka_unit_test(a_session_in_one_process),
      cmocka_unit_test(sends_on_publish_not_on_its_tick),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
