// The device across DDS (controllers/net/device_dds.c): the ramp rule, the
// spec, and a server and a client in one process on loopback: forces
// applied, a lost simulation's force at zero within 10 ms and one that comes
// back taken up (ramped in), foreign and malformed samples dropped, a lost
// server reported and taken again when it comes back, and one of other
// limits never used.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/net/device_dds.h"
#include "controllers/net/net.h"
#include "model/error.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static void the_ramp_rule(void** state) {
  (void)state;
  const double T = 0.003, R = 0.005;
  assert_true(tx_device_dds_scale(0, 1, T, R) == 1);
  assert_true(tx_device_dds_scale(T, 1, T, R) == 1);
  assert_true(fabs(tx_device_dds_scale(T + R / 2, 1, T, R) - 0.5) < 1e-12);
  assert_true(tx_device_dds_scale(T + R, 1, T, R) == 0);
  assert_true(tx_device_dds_scale(1, 1, T, R) == 0);
  // taken up: from zero, over the ramp
  assert_true(tx_device_dds_scale(0, 0, T, R) == 0);
  assert_true(fabs(tx_device_dds_scale(0, R / 2, T, R) - 0.5) < 1e-12);
  assert_true(tx_device_dds_scale(0, R, T, R) == 1);
  // no ramp: a step
  assert_true(tx_device_dds_scale(T * 1.01, 0, T, 0) == 0);
  assert_true(tx_device_dds_scale(T, 0, T, 0) == 1);
  // at 1 kHz, ticks 1 ms apart after the tick that took the last force: zero from 8 ms on
  for (int k = 0; k <= 12; k++) {
    double s = tx_device_dds_scale(k * 1e-3, 1, T, R);
    if (k <= 3) assert_true(s == 1);
    if (k >= 8) assert_true(s == 0);
    if (k > 3 && k < 8) assert_true(s > 0 && s < 1);
  }
}

static void the_spec(void** state) {
  (void)state;
  tx_device_dds_spec sp;
  assert_true(tx_device_dds_parse("5", &sp));
  assert_int_equal(sp.domain, 5);
  assert_string_equal(sp.name, "device0");
  assert_int_equal(sp.npeers, 0);
  assert_true(tx_device_dds_parse("232:arm_1,peer=10.0.0.2,peer=sim-host", &sp));
  assert_int_equal(sp.domain, 232);
  assert_string_equal(sp.name, "arm_1");
  assert_int_equal(sp.npeers, 2);
  assert_string_equal(sp.peers[0], "10.0.0.2");
  assert_string_equal(sp.peers[1], "sim-host");
  const char* bad[] = {"", "x", "233", "-1", "5:", "5:Bad", "5:a-b", "1234567", "5:0123456789012345678901234567890123",
                       "5:a,peer=10.0.0.300", "5:a,peer=", "5:a,bind=1", "5,peer=a..b",
                       "5,peer=a,peer=a,peer=a,peer=a,peer=a,peer=a,peer=a,peer=a,peer=a"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_false(tx_device_dds_parse(bad[i], &sp));
    assert_true(strlen(tx_error()) > 0);
  }
  tx_device_handle h;
  assert_int_equal(tx_device_open("dds:999", 1e-3, &h), -1);
  assert_non_null(strstr(tx_error(), "dds:999"));
}

typedef struct server_run {
  tx_device_dds_server* s;
  atomic_int stop;
  pthread_t thread;
} server_run;

static void* serve(void* arg) {
  server_run* r = arg;
  tx_device_dds_server_run(r->s, &r->stop);
  return NULL;
}

static void start(server_run* r, int domain, const char* spec) {
  tx_device_dds_server_def def = tx_device_dds_server_def_default();
  char dds[32];
  snprintf(dds, sizeof dds, "%d:t", domain);
  def.dds = dds;
  def.spec = spec;
  r->s = tx_device_dds_server_open(&def);
  assert_non_null(r->s);
  atomic_store(&r->stop, 0);
  assert_int_equal(pthread_create(&r->thread, NULL, serve, r), 0);
}

static void stop(server_run* r) {
  atomic_store(&r->stop, 1);
  pthread_join(r->thread, NULL);
  tx_device_dds_server_close(r->s);
  r->s = NULL;
}

static void sleep_ms(double ms) {
  struct timespec ts = {0, (long)(ms * 1e6)};
  nanosleep(&ts, NULL);
}

// the client as a haptics tick would run it: read, then write
static int ticks(tx_device_handle* h, int n, double fx, int* fresh) {
  for (int i = 0; i < n; i++) {
    tx_device_state st;
    if (h->backend->read(h->device, i * 1e-3, &st)) (*fresh)++;
    if (fx >= 0) h->backend->write(h->device, (double[3]){fx, 0, 0});
    sleep_ms(1);
  }
  return *fresh;
}

static void a_session_on_loopback(void** state) {
  (void)state;
  // the client ticks as a haptics thread would: at SCHED_FIFO where allowed,
  // else a late tick is a gap in its forces, which the server must treat as a loss
  struct sched_param sp = {.sched_priority = sched_get_priority_max(SCHED_FIFO) - 10};
  bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
  int domain = 190 + (int)(getpid() % 40);
  server_run r;
  start(&r, domain, "sim");
  char spec[32];
  snprintf(spec, sizeof spec, "dds:%d:t", domain);
  tx_device_handle h;
  assert_int_equal(tx_device_open(spec, 1e-3, &h), 0);
  tx_device_info info;
  h.backend->info(h.device, &info);
  assert_true(info.max_force > 0);

  // forces applied, ramped in from zero
  int fresh = 0;
  ticks(&h, 300, 0.5, &fresh);
  assert_true(fresh > 100);
  tx_device_dds_server_stats st;
  tx_device_dds_server_get_stats(r.s, &st);
  assert_true(st.forces > 100);
  if (fifo) assert_true(fabs(st.last_force[0] - 0.5) < 1e-12);
  uint64_t timeouts = st.timeouts, resumes = st.resumes;

  // the simulation falls silent: zero within 10 ms of its last force
  sleep_ms(60);
  tx_device_dds_server_get_stats(r.s, &st);
  print_message("lost simulation: force zero %.2f ms after its last force (%s, %llu late ticks)\n", st.zero_after_s * 1e3,
                st.fifo ? "SCHED_FIFO" : "SCHED_OTHER", (unsigned long long)st.late_ticks);
  assert_int_equal(st.timeouts, timeouts + 1);
  assert_true(st.last_force[0] == 0);
  assert_true(st.zero_after_s > 0.007);
  if (st.fifo) assert_true(st.zero_after_s <= 0.0101);
  else assert_true(st.zero_after_s <= 0.05); // a loaded machine without real-time priority: still bounded

  // and comes back: taken up, ramped in again
  ticks(&h, 100, 0.5, &fresh);
  tx_device_dds_server_get_stats(r.s, &st);
  assert_true(st.resumes >= resumes + 1);
  if (fifo) assert_true(fabs(st.last_force[0] - 0.5) < 1e-12);
  else assert_true(st.last_force[0] > 0 && st.last_force[0] <= 0.5);

  // a foreign and two malformed forces (a wrong size, a NaN): dropped, counted, never applied
  dds_entity_t pp = tx_net_participant(domain, NULL, 0);
  assert_true(pp > 0);
  dds_qos_t* q = tx_net_qos(TX_NET_FAST);
  dds_entity_t topic = dds_create_topic(pp, &tx_net_Snapshot_desc, "tx/d/t/force", q, NULL);
  dds_entity_t w = dds_create_writer(pp, topic, q, NULL);
  dds_delete_qos(q);
  assert_true(w > 0);
  sleep_ms(300); // discovery
  double big[4] = {9, 0, 0, 0}, nan_force[4] = {NAN, 0, 0, 0}, wide[6] = {9};
  tx_net_Snapshot s;
  tx_net_pack(&s, tx_net_session_tag("device/other", domain), "device.force", TX_F64,
              &(tx_snapshot){.data = big, .rows = 1, .cols = 4, .seq = 1});
  assert_int_equal(dds_write(w, &s), 0);
  sleep_ms(5);
  tx_net_pack(&s, tx_net_session_tag("device/t", domain), "device.force", TX_F64,
              &(tx_snapshot){.data = wide, .rows = 1, .cols = 6, .seq = 2});
  assert_int_equal(dds_write(w, &s), 0);
  sleep_ms(5);
  tx_net_pack(&s, tx_net_session_tag("device/t", domain), "device.force", TX_F64,
              &(tx_snapshot){.data = nan_force, .rows = 1, .cols = 4, .seq = 3});
  assert_int_equal(dds_write(w, &s), 0);
  sleep_ms(30);
  dds_delete(pp);
  tx_device_dds_server_get_stats(r.s, &st);
  assert_int_equal(st.foreign, 1);
  assert_int_equal(st.malformed, 2);
  assert_true(st.last_force[0] == 0); // the client is silent: nothing forged was taken up

  // the server goes away: the client reports nothing new, then the device lost
  stop(&r);
  int before = fresh;
  ticks(&h, 150, 0, &fresh);
  tx_device_dds_counts c;
  tx_device_dds_counts_get(h.device, &c);
  assert_true(fresh - before <= 2);
  assert_int_equal(c.losses, 1);
  // one of other limits answers: not used
  start(&r, domain, "sim:max_force=2");
  before = fresh;
  ticks(&h, 300, 0, &fresh);
  tx_device_dds_counts_get(h.device, &c);
  assert_int_equal(fresh, before);
  assert_true(c.other_device > 0);
  assert_int_equal(c.returns, 0);
  stop(&r);
  // the same device again: taken
  start(&r, domain, "sim");
  ticks(&h, 300, 0.25, &fresh);
  tx_device_dds_counts_get(h.device, &c);
  assert_true(fresh > before + 50);
  assert_int_equal(c.returns, 1);
  tx_device_dds_server_get_stats(r.s, &st);
  if (fifo) assert_true(fabs(st.last_force[0] - 0.25) < 1e-12);
  else assert_true(st.last_force[0] > 0 && st.last_force[0] <= 0.25);
  tx_device_close(&h);
  stop(&r);
  sp.sched_priority = 0;
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(the_ramp_rule),
      cmocka_unit_test(the_spec),
      cmocka_unit_test(a_session_on_loopback),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
