// Event streams: every reader sees every event once and in order; a full ring
// refuses and counts; bad input is refused. Then a 4 kHz writer and a 20 Hz
// reader for 10 s of real time, once with room and once overflowing: nothing
// is lost, duplicated or reordered, and every loss is counted.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <tactus/events.h>

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>
#include <time.h>

static void two_readers_see_every_event_in_order(void** state) {
  (void)state;
  tx_stream* s = tx_stream_create("tool0.events", 8);
  assert_non_null(s);
  int a = tx_stream_add_reader(s), b = tx_stream_add_reader(s);
  assert_int_equal(a, 0);
  assert_int_equal(b, 1);
  for (int i = 1; i <= 3; i++)
    assert_int_equal(tx_stream_push(s, &(tx_event){.kind = TX_EVENT_GRASP, .source = 10 + i, .sim_ns = i}), i);
  tx_event e;
  for (int r = 0; r < 2; r++) {
    for (int i = 1; i <= 3; i++) {
      assert_true(tx_stream_next(s, r, &e));
      assert_int_equal(e.seq, i);
      assert_int_equal(e.source, 10 + i);
      assert_int_equal(e.kind, TX_EVENT_GRASP);
    }
    assert_false(tx_stream_next(s, r, &e));
    assert_int_equal(tx_stream_lost(s, r), 0);
  }
  tx_stream_destroy(s);
}

static void a_full_ring_refuses_and_counts(void** state) {
  (void)state;
  tx_stream* s = tx_stream_create("cuts", 8);
  int fast = tx_stream_add_reader(s), slow = tx_stream_add_reader(s);
  tx_event e;
  for (int i = 1; i <= 10; i++) {
    uint64_t seq = tx_stream_push(s, &(tx_event){.kind = TX_EVENT_CUT, .value = {i}});
    assert_int_equal(seq, i <= 8 ? i : 0); // the ring holds 8; 9 and 10 are refused
    while (tx_stream_next(s, fast, &e)) {} // one reader keeping up does not make room
  }
  assert_int_equal(tx_stream_overflows(s), 2);
  for (int i = 1; i <= 8; i++) assert_true(tx_stream_next(s, slow, &e) && e.seq == (uint64_t)i);
  // room again: the next events carry seq 11 and 12, and both readers count the gap of two
  assert_int_equal(tx_stream_push(s, &(tx_event){.kind = TX_EVENT_CUT}), 11);
  assert_int_equal(tx_stream_push(s, &(tx_event){.kind = TX_EVENT_CUT}), 12);
  for (int r = 0; r < 2; r++) {
    assert_true(tx_stream_next(s, r, &e) && e.seq == 11);
    assert_true(tx_stream_next(s, r, &e) && e.seq == 12);
    assert_int_equal(tx_stream_lost(s, r), 2);
  }
  assert_int_equal(tx_stream_pushed(s), 12);
  tx_stream_destroy(s);
}

static void bad_input_is_refused(void** state) {
  (void)state;
  assert_null(tx_stream_create("x", 3));
  assert_non_null(strstr(tx_error(), "power of two"));
  assert_null(tx_stream_create("x", 1));
  assert_null(tx_stream_create("x", TX_STREAM_CAPACITY_MAX * 2));
  assert_null(tx_stream_create("", 8));
  assert_null(tx_stream_create(NULL, 8));
  tx_stream* s = tx_stream_create("x", 2);
  for (int i = 0; i < TX_STREAM_READERS_MAX; i++) assert_int_equal(tx_stream_add_reader(s), i);
  assert_int_equal(tx_stream_add_reader(s), -1);
  tx_stream_destroy(s);
  s = tx_stream_create("x", 2);
  tx_stream_push(s, &(tx_event){0});
  assert_int_equal(tx_stream_add_reader(s), -1); // after the first push
  assert_non_null(strstr(tx_error(), "before the first push"));
  tx_event e;
  assert_false(tx_stream_next(s, 0, &e)); // no such reader
  assert_false(tx_stream_next(s, -1, &e));
  tx_stream_destroy(s);
}

// ---- threads: a 4 kHz writer, a 20 Hz reader, 10 s

typedef struct run {
  tx_stream* s;
  int reader;
  _Atomic bool done;
  uint64_t pushed, refused;                // writer
  uint64_t seen, bad_order, bad_payload;   // reader
} run;

static void sleep_until(struct timespec* t, long step_ns) {
  t->tv_nsec += step_ns;
  while (t->tv_nsec >= 1000000000) t->tv_nsec -= 1000000000, t->tv_sec++;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, t, NULL) == EINTR) {}
}

static void* writer(void* arg) {
  run* r = arg;
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  for (uint64_t i = 1; i <= 40000; i++) { // 10 s at 4 kHz
    // the payload repeats the seq the push will hand out, so the reader can check it
    uint64_t seq = tx_stream_push(r->s, &(tx_event){.kind = TX_EVENT_PUNCTURE, .value = {(double)i, -(double)i}});
    if (seq) r->pushed++;
    else r->refused++;
    sleep_until(&t, 250000);
  }
  atomic_store(&r->done, true);
  return NULL;
}

static void drain(run* r, uint64_t* last) {
  for (tx_event e; tx_stream_next(r->s, r->reader, &e);) {
    r->seen++;
    if (e.seq <= *last) r->bad_order++; // duplicated or reordered
    if (e.value[0] != (double)e.seq || e.value[1] != -(double)e.seq) r->bad_payload++;
    *last = e.seq;
  }
}

static void* reader(void* arg) {
  run* r = arg;
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  uint64_t last = 0;
  while (!atomic_load(&r->done)) {
    drain(r, &last);
    sleep_until(&t, 50000000); // 20 Hz
  }
  drain(r, &last);
  return NULL;
}

static void writer_4khz_reader_20hz_for_10_s(void** state) {
  (void)state;
  // 200 events arrive between two reads: 4096 holds them, 64 overflows
  // (4096: a reader that a loaded machine holds back 1 s still loses nothing)
  run roomy = {.s = tx_stream_create("roomy", 4096)}, tight = {.s = tx_stream_create("tight", 64)};
  run* runs[2] = {&roomy, &tight};
  pthread_t th[4];
  for (int k = 0; k < 2; k++) {
    runs[k]->reader = tx_stream_add_reader(runs[k]->s);
    assert_int_equal(pthread_create(&th[2 * k], NULL, reader, runs[k]), 0);
    assert_int_equal(pthread_create(&th[2 * k + 1], NULL, writer, runs[k]), 0);
  }
  for (int k = 0; k < 4; k++) pthread_join(th[k], NULL);
  for (int k = 0; k < 2; k++) {
    run* r = runs[k];
    print_message("  %s: %llu sent, %llu refused, %llu seen, %llu lost\n", tx_stream_name(r->s),
                  (unsigned long long)r->pushed, (unsigned long long)r->refused, (unsigned long long)r->seen,
                  (unsigned long long)tx_stream_lost(r->s, r->reader));
    assert_int_equal(r->pushed + r->refused, 40000);
    assert_int_equal(r->seen, r->pushed); // every accepted event, once
    assert_int_equal(r->bad_order, 0);
    assert_int_equal(r->bad_payload, 0);
    assert_int_equal(tx_stream_overflows(r->s), r->refused);
  }
  assert_int_equal(roomy.refused, 0);
  assert_true(tight.refused > 20000); // about 136 of every 200 are refused
  // one more event after the run (the reader drained the ring): its gap shows
  // the refusals after the last accepted one too, so every loss is counted
  for (int k = 0; k < 2; k++) {
    run* r = runs[k];
    assert_int_equal(tx_stream_push(r->s, &(tx_event){.kind = TX_EVENT_STEP}), 40001);
    tx_event e;
    assert_true(tx_stream_next(r->s, r->reader, &e) && e.seq == 40001);
    assert_int_equal(tx_stream_lost(r->s, r->reader), r->refused);
  }
  tx_stream_destroy(roomy.s);
  tx_stream_destroy(tight.s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(two_readers_see_every_event_in_order),
      cmocka_unit_test(a_full_ring_refuses_and_counts),
      cmocka_unit_test(bad_input_is_refused),
      cmocka_unit_test(writer_4khz_reader_20hz_for_10_s),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
