// The udp device backend against a device server, both in this process, on
// loopback: states arrive and forces go back; the round trip at 1 kHz is
// measured; through a lossy relay (loss, reordering, duplicates, garbage,
// replays, forged packets) nothing stale or foreign is used, and once the
// stream stops the safety chain brings the force to zero within 10 ms; bad
// specs and peers that are not ours fail with one clear message.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/haptics/device_server.h"
#include "controllers/haptics/device_udp.h"
#include "controllers/haptics/safety.h"
#include "udp_shim.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

typedef struct server_thread {
  tx_device_server* s;
  atomic_int stop;
  pthread_t thread;
  int rc;
} server_thread;

static void* serve(void* arg) {
  server_thread* st = arg;
  st->rc = tx_device_server_run(st->s, &st->stop);
  if (st->rc) fprintf(stderr, "server: %s\n", tx_error());
  return NULL;
}

// a device server on 127.0.0.1 at listen_port (0: any free port), letting a
// client go after client_timeout_s; peer_port 0 = whoever says hello first
static uint16_t start_server_at(server_thread* st, const char* spec, uint16_t peer_port, uint16_t listen_port,
                                double client_timeout_s) {
  tx_device_server_def def = tx_device_server_def_default();
  def.spec = spec;
  def.listen.sin_port = htons(listen_port);
  def.client_timeout_s = client_timeout_s;
  if (peer_port) {
    def.peer.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    def.peer.sin_port = htons(peer_port);
  }
  st->s = tx_device_server_open(&def);
  if (!st->s) fail_msg("%s", tx_error());
  atomic_init(&st->stop, 0);
  assert_int_equal(pthread_create(&st->thread, NULL, serve, st), 0);
  return tx_device_server_port(st->s);
}

static uint16_t start_server(server_thread* st, const char* spec, uint16_t peer_port) {
  return start_server_at(st, spec, peer_port, 0, tx_device_server_def_default().client_timeout_s);
}

static tx_device_server_stats stop_server(server_thread* st) {
  atomic_store(&st->stop, 1);
  pthread_join(st->thread, NULL);
  assert_int_equal(st->rc, 0);
  tx_device_server_stats stats;
  tx_device_server_get_stats(st->s, &stats);
  tx_device_server_close(st->s);
  return stats;
}

static void open_udp(tx_device_handle* h, uint16_t port) {
  char spec[64];
  snprintf(spec, sizeof spec, "udp:127.0.0.1:%u", port);
  if (tx_device_open(spec, 1e-3, h)) fail_msg("%s", tx_error());
}

// sleep to the next 1 kHz tick. A loop the machine stalled for more than a
// tick resumes from now, as the real-time executor skips missed ticks: a burst
// of catch-up ticks would find nothing new and look like a silent device
static void next_tick(struct timespec* t) {
  t->tv_nsec += 1000000;
  if (t->tv_nsec >= 1000000000) t->tv_nsec -= 1000000000, t->tv_sec++;
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  int64_t behind = (int64_t)(now.tv_sec - t->tv_sec) * 1000000000 + (now.tv_nsec - t->tv_nsec);
  if (behind > 1000000) *t = now;
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, t, NULL);
}

static void states_arrive_and_forces_go_back(void** unused) {
  (void)unused;
  server_thread st;
  uint16_t port = start_server(&st, "scripted:slide-x-over", 0);
  tx_device_handle h;
  open_udp(&h, port);
  assert_ptr_equal(h.backend, &tx_device_udp);
  tx_device_info info; // the scripted device's limits, as its hello gave them
  h.backend->info(h.device, &info);
  assert_true(info.max_force == 3.3 && info.workspace_min[0] == -0.5 && info.workspace_max[2] == 0.5);

  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  int fresh = 0;
  int64_t last_t = -1;
  double last_y = 1;
  for (int k = 0; k < 500; k++) {
    tx_device_state s;
    if (h.backend->read(h.device, k * 1e-3, &s)) {
      fresh++;
      assert_true(s.t_ns > last_t); // never an older state
      // slide-x-over descends from 10 mm to 2 mm in its first second
      assert_true(s.pos[1] <= last_y && s.pos[1] >= 0.002 - 1e-12 && s.pos[1] <= 0.010 + 1e-12);
      assert_true(s.pos[0] == -0.03 && s.quat[0] == 1);
      last_t = s.t_ns, last_y = s.pos[1];
    }
    const double f[3] = {0, 0.5, 0};
    h.backend->write(h.device, f);
    next_tick(&t);
  }
  // stop the stream, then read what is still in flight: the counts then cover
  // every state sent, however long the machine paused this thread meanwhile
  tx_device_server_stats ss = stop_server(&st);
  tx_device_state last;
  h.backend->read(h.device, 0.5, &last);
  tx_device_udp_counts c;
  tx_device_udp_counts_get(h.device, &c);
  tx_device_close(&h);
  print_message("  %d of 500 ticks had a new state; server: %llu states, %llu forces\n", fresh,
                (unsigned long long)ss.states, (unsigned long long)ss.forces);
  // a 1 kHz stream read by a 1 kHz tick in phase with it finds two states on one tick and none on
  // the next, so only the states accepted in all are counted tightly
  assert_true(fresh >= 100);
  assert_true(c.states + 5 >= ss.states && c.forces == 500 && c.send_errors == 0);
  assert_true(c.stale == 0 && c.malformed == 0 && c.foreign == 0 && c.other_session == 0 && c.unexpected == 0);
  assert_true(ss.hellos >= 1 && ss.forces >= 250 && ss.stale == 0 && ss.malformed == 0 && ss.foreign == 0);
}

// pose out, force back, at 1 kHz: the server stamps each state and times the
// first force that answers it on its own clock; the client answers as soon
// as the state is there, so this is the link's round trip
static void round_trip_at_1khz_over_loopback(void** unused) {
  (void)unused;
  server_thread st;
  uint16_t port = start_server(&st, "scripted:pierce-down", 0);
  tx_device_handle h;
  open_udp(&h, port);
  int answered = 0;
  for (int k = 0; k < 2000; k++) {
    tx_device_state s;
    // 500 ms: on a loaded machine the server's thread may wait tens of ms for a CPU
    int64_t give_up = tx_dp_now_ns() + 500000000;
    bool fresh = false;
    while (!(fresh = h.backend->read(h.device, 0, &s)) && tx_dp_now_ns() < give_up) sched_yield();
    if (!fresh) break;
    const double f[3] = {0, 0.1 * s.pos[1], 0};
    h.backend->write(h.device, f);
    answered++;
  }
  tx_device_close(&h);
  tx_device_server_stats ss = stop_server(&st);
  print_message("  round trip over loopback at 1 kHz, %llu samples: p50 %.1f us, p99 %.1f us, max %.1f us "
                "(link only: p50 %.1f us, p99 %.1f us)\n",
                (unsigned long long)ss.round_trips, ss.loop.p50 * 1e-3, ss.loop.p99 * 1e-3, ss.loop.max * 1e-3,
                ss.link.p50 * 1e-3, ss.link.p99 * 1e-3);
  assert_int_equal(answered, 2000);
  assert_true(ss.round_trips >= 1900);
  assert_true(ss.loop.p50 > 0 && ss.loop.p99 >= ss.loop.p50 && ss.link.p99 <= ss.loop.p99 + 1);
  // the target is p99 <= 300 us; the bound here leaves room for a loaded test machine
  assert_true(ss.loop.p99 <= 5e6);
}

typedef struct shim_thread {
  udp_shim shim;
  atomic_int stop;
  pthread_t thread;
} shim_thread;

static void* relay(void* arg) {
  shim_thread* t = arg;
  shim_run(&t->shim, &t->stop);
  return NULL;
}

static void lossy_link_is_survived(void** unused) {
  (void)unused;
  server_thread st;
  uint16_t server_port = start_server(&st, "scripted:slide-x-over", 0);
  shim_thread sh;
  assert_int_equal(shim_open(&sh.shim, server_port, 12345), 0);
  atomic_init(&sh.stop, 0);
  assert_int_equal(pthread_create(&sh.thread, NULL, relay, &sh), 0);
  tx_device_handle h;
  open_udp(&h, shim_port_of(sh.shim.a)); // the hello gets through 10% loss by being said again

  // the safety chain as the haptics controller runs it, with a device timeout and ramp that sum to 9 ms
  tx_device_info info;
  h.backend->info(h.device, &info);
  tx_safety_limits lim = tx_safety_limits_from_device(&info);
  lim.device_timeout_s = 0.004, lim.ramp_s = 0.005;
  assert_int_equal(tx_safety_limits_check(&lim), 0);
  tx_safety safety;
  tx_safety_init(&safety);

  const int streaming = 1500, after = 60;
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  int fresh = 0, last_fresh = -1, zero_at = -1, fresh_after_stop = 0;
  int64_t last_t = -1;
  double silent = 0, out[3] = {0, 0, 0};
  tx_device_server_stats ss = {0};
  for (int k = 0; k < streaming + after; k++) {
    if (k == streaming) ss = stop_server(&st); // the stream stops here
    tx_device_state s;
    bool got = h.backend->read(h.device, k * 1e-3, &s);
    if (got) {
      fresh++, last_fresh = k;
      if (k > streaming) fresh_after_stop++;
      assert_true(s.t_ns > last_t); // nothing stale is ever used
      assert_true(s.pos[0] != 9);   // nor anything forged
      last_t = s.t_ns;
      silent = 0;
    } else {
      silent += 1e-3;
    }
    const double want[3] = {0, 1, 0};
    tx_safety_apply(&safety, &lim, 1e-3, want, s.pos, 0, silent, out);
    if (k >= streaming && zero_at < 0 && out[0] == 0 && out[1] == 0 && out[2] == 0) zero_at = k;
    h.backend->write(h.device, out);
    next_tick(&t);
  }
  tx_device_udp_counts c;
  tx_device_udp_counts_get(h.device, &c);
  tx_device_close(&h);
  atomic_store(&sh.stop, 1);
  pthread_join(sh.thread, NULL);
  shim_counts* x = &sh.shim.counts;
  print_message("  relay: %llu in, %llu dropped, %llu swapped, %llu duplicated, %llu garbage (%llu replays), "
                "%llu forged\n",
                (unsigned long long)x->in, (unsigned long long)x->dropped, (unsigned long long)x->swapped,
                (unsigned long long)x->duplicated, (unsigned long long)x->garbage, (unsigned long long)x->replayed,
                (unsigned long long)x->forged);
  print_message("  client: %llu of %llu states used, %d of %d ticks fresh; dropped %llu stale, %llu malformed, "
                "%llu foreign; force zero %d ms after the last state\n",
                (unsigned long long)c.states, (unsigned long long)ss.states, fresh, streaming,
                (unsigned long long)c.stale, (unsigned long long)c.malformed,
                (unsigned long long)c.foreign, zero_at - last_fresh);
  shim_close(&sh.shim);
  assert_true(x->dropped > 0 && x->swapped > 0 && x->duplicated > 0 && x->garbage > 0 && x->replayed > 0 &&
              x->forged > 0);
  assert_true(c.states >= ss.states / 2 && fresh >= streaming / 4); // 10% lost, and in-phase ticks as above
  assert_true(c.stale > 0 && c.malformed > 0);
  // what was in flight, then silence: counted, not timed, since a loaded machine may hold the relay's
  // thread back for several ticks before it hands on the last states sent
  assert_true(fresh_after_stop <= 2);
  assert_true(last_fresh >= streaming - 20); // the stream was used up to its stop
  assert_true(zero_at > last_fresh && zero_at - last_fresh <= 10);
}

// the server's side of the same relay: stale, malformed and forged packets counted and dropped
static void server_drops_what_is_not_from_its_peer(void** unused) {
  (void)unused;
  server_thread st;
  uint16_t server_port = start_server(&st, "scripted:pierce-down", 0);
  shim_thread sh;
  assert_int_equal(shim_open(&sh.shim, server_port, 777), 0);
  sh.shim.foreign_every = 16; // more forged forces
  atomic_init(&sh.stop, 0);
  assert_int_equal(pthread_create(&sh.thread, NULL, relay, &sh), 0);
  tx_device_handle h;
  open_udp(&h, shim_port_of(sh.shim.a));
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  for (int k = 0; k < 800; k++) {
    tx_device_state s;
    h.backend->read(h.device, k * 1e-3, &s);
    const double f[3] = {0, 0.2, 0};
    h.backend->write(h.device, f);
    next_tick(&t);
  }
  tx_device_close(&h);
  tx_device_server_stats ss = stop_server(&st);
  atomic_store(&sh.stop, 1);
  pthread_join(sh.thread, NULL);
  shim_close(&sh.shim);
  print_message("  server: %llu forces applied; dropped %llu stale, %llu malformed, %llu foreign\n",
                (unsigned long long)ss.forces, (unsigned long long)ss.stale, (unsigned long long)ss.malformed,
                (unsigned long long)ss.foreign);
  assert_true(ss.forces >= 400 && ss.stale > 0 && ss.malformed > 0 && ss.foreign > 0);
}

static void bad_specs_fail_with_one_message(void** unused) {
  (void)unused;
  const char* bad[] = {"udp:",
                       "udp:127.0.0.1",
                       "udp:127.0.0.1:0",
                       "udp:127.0.0.1:70000",
                       "udp:device.example:5000",
                       "udp:10.1.2.3:5000",
                       "udp:127.0.0.1:5000,bind=nowhere",
                       "udp:127.0.0.1:5000,bind=127.0.0.1",
                       "udp:127.0.0.1:5000,port=1",
                       "udp:127.0.0.1:5000,bind=127.0.0.1:0,extra"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_device_handle h;
    assert_int_equal(tx_device_open(bad[i], 1e-3, &h), -1);
    assert_null(h.device);
    if (strncmp(tx_error(), "device 'udp:", 12) != 0 || strchr(tx_error(), '\n')) fail_msg("%s: %s", bad[i], tx_error());
  }
  // a port where nothing answers: said within the wait, not hung
  int quiet = shim_socket();
  assert_true(quiet >= 0);
  char spec[64];
  snprintf(spec, sizeof spec, "udp:127.0.0.1:%u", shim_port_of(quiet));
  tx_device_handle h;
  int64_t t0 = tx_dp_now_ns();
  assert_int_equal(tx_device_open(spec, 1e-3, &h), -1);
  double waited = (double)(tx_dp_now_ns() - t0) * 1e-9;
  assert_non_null(strstr(tx_error(), "no hello from the device"));
  assert_true(waited >= TX_DEVICE_UDP_WAIT_S * 0.9 && waited < TX_DEVICE_UDP_WAIT_S + 1);
  close(quiet);
}

// a device opened in another thread, while this one ticks
typedef struct opener {
  uint16_t port;
  tx_device_handle h;
  int rc;
  atomic_int done;
  pthread_t thread;
} opener;

static void* open_in_thread(void* arg) {
  opener* o = arg;
  char spec[64];
  snprintf(spec, sizeof spec, "udp:127.0.0.1:%u", o->port);
  o->rc = tx_device_open(spec, 1e-3, &o->h);
  atomic_store(&o->done, 1);
  return NULL;
}

// tick h at 1 kHz, a force of 1 N each tick, for at least seconds and until o
// (if any) has opened or failed, then join o; the ticks that had a new state
static int tick_until_opened(tx_device_handle* h, opener* o, double seconds) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  int64_t end = tx_dp_now_ns() + (int64_t)(seconds * 1e9);
  int fresh = 0;
  while (tx_dp_now_ns() < end || (o && !atomic_load(&o->done))) {
    tx_device_state s;
    fresh += h->backend->read(h->device, 0, &s);
    const double f[3] = {0, 1, 0};
    h->backend->write(h->device, f);
    next_tick(&t);
  }
  if (o) {
    pthread_join(o->thread, NULL);
    if (o->rc == 0) tx_device_close(&o->h);
  }
  return fresh;
}

// a server answers its one peer: the --peer it was given, or else the first hello
static void a_server_answers_only_its_peer(void** unused) {
  (void)unused;
  int other = shim_socket(); // the configured peer, which says nothing
  server_thread st;
  uint16_t port = start_server(&st, "scripted:pierce-down", shim_port_of(other));
  char spec[64];
  snprintf(spec, sizeof spec, "udp:127.0.0.1:%u", port);
  tx_device_handle h;
  assert_int_equal(tx_device_open(spec, 1e-3, &h), -1);
  tx_device_server_stats ss = stop_server(&st);
  assert_true(ss.foreign > 0 && ss.hellos == 0 && ss.states == 0);
  close(other);

  // without --peer: the first to say hello, while it lives (it ticks here all the
  // while the other one waits its 2 s)
  port = start_server(&st, "scripted:pierce-down", 0);
  tx_device_handle first;
  open_udp(&first, port);
  opener second = {.port = port};
  assert_int_equal(pthread_create(&second.thread, NULL, open_in_thread, &second), 0);
  tick_until_opened(&first, &second, 1.0);
  assert_int_equal(second.rc, -1); // another port: not the peer
  tx_device_close(&first);
  ss = stop_server(&st);
  assert_true(ss.foreign > 0 && ss.hellos >= 1 && ss.clients == 1);
}

// issue 11, row 7: once a client is gone (nothing heard for the client
// timeout), the next one that says hello is served, and its forces ramp from
// zero; the first, gone quiet without a word, could not hold the device
static void a_new_client_is_served_once_the_old_one_is_gone(void** unused) {
  (void)unused;
  server_thread st;
  const double timeout = 0.3;
  uint16_t port = start_server_at(&st, "scripted:pierce-down", 0, 0, timeout);
  tx_device_handle first, second;
  open_udp(&first, port);
  tick_until_opened(&first, NULL, 0.3); // forces of 1 N
  tx_device_close(&first);
  int64_t t0 = tx_dp_now_ns();
  open_udp(&second, port); // waits out the client timeout within its 2 s
  double waited = (double)(tx_dp_now_ns() - t0) * 1e-9;
  tick_until_opened(&second, NULL, 0.3);
  tx_device_udp_counts c;
  tx_device_udp_counts_get(second.device, &c);
  tx_device_close(&second);
  tx_device_server_stats ss = stop_server(&st);
  print_message("  second client served %.3f s after the first left; server: %llu clients, %llu let go, %llu forces "
                "ramped\n",
                waited, (unsigned long long)ss.clients, (unsigned long long)ss.clients_gone,
                (unsigned long long)ss.ramped);
  assert_true(waited >= timeout * 0.5 && waited < TX_DEVICE_UDP_WAIT_S);
  assert_true(c.states >= 100);
  assert_true(ss.clients == 2 && ss.clients_gone >= 1);
  // each client's first forces after its hello are scaled down: 5 ms of a 1 kHz stream, less the handshake
  assert_true(ss.ramped >= 4 && ss.ramped <= 20);
}

// issue 11, row 8: a server that stops is lost, one that comes back in its
// place is rejoined (the client says hello again while it waits); one that
// comes back with other limits is not
static void a_lost_device_is_rejoined(void** unused) {
  (void)unused;
  server_thread st;
  uint16_t port = start_server(&st, "scripted:pierce-down", 0);
  tx_device_handle h;
  open_udp(&h, port);
  tx_device_udp_counts c;
  tick_until_opened(&h, NULL, 0.3);
  stop_server(&st);
  tick_until_opened(&h, NULL, 0.3);
  tx_device_udp_counts_get(h.device, &c);
  assert_true(c.losses == 1 && c.returns == 0);
  // a server of another device on the same port: not taken on
  start_server_at(&st, "sim", 0, port, 1);
  int fresh = tick_until_opened(&h, NULL, 0.3);
  tx_device_udp_counts_get(h.device, &c);
  stop_server(&st);
  assert_int_equal(fresh, 0);
  assert_true(c.other_device >= 1 && c.returns == 0 && c.rejoins == 0);
  // the same device again: rejoined, and states flow
  start_server_at(&st, "scripted:pierce-down", 0, port, 1);
  int64_t t0 = tx_dp_now_ns();
  fresh = tick_until_opened(&h, NULL, 0.5);
  tx_device_udp_counts_get(h.device, &c);
  tx_device_close(&h);
  tx_device_server_stats ss = stop_server(&st);
  print_message("  rejoined: %d fresh ticks in the 0.5 s after the restart (%.3f s); %llu losses, %llu returns\n", fresh,
                (double)(tx_dp_now_ns() - t0) * 1e-9, (unsigned long long)c.losses, (unsigned long long)c.returns);
  assert_true(c.losses == 1 && c.returns == 1 && c.rejoins == 1);
  assert_true(fresh >= 100);
  assert_true(ss.clients == 1 && ss.forces >= 200);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(states_arrive_and_forces_go_back),
      cmocka_unit_test(round_trip_at_1khz_over_loopback),
      cmocka_unit_test(lossy_link_is_survived),
      cmocka_unit_test(server_drops_what_is_not_from_its_peer),
      cmocka_unit_test(bad_specs_fail_with_one_message),
      cmocka_unit_test(a_server_answers_only_its_peer),
      cmocka_unit_test(a_new_client_is_served_once_the_old_one_is_gone),
      cmocka_unit_test(a_lost_device_is_rejoined),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
