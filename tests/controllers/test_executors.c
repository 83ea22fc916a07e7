// Executors: lockstep is deterministic and orders ties slowest first; the
// real-time executor runs every group and moves data between threads.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/system.h"
#include "controllers/system_internal.h"
#include "test_support.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <time.h>

// physics 60 Hz -> collision 4 kHz -> haptics 1 kHz -> graphics 30 Hz, as counters
static tx_system* chain(void) {
  static const struct {
    const char* name;
    double rate;
    const char* params;
  } spec[] = {
      {"physics", 60, "{\"write\":\"skin\",\"read\":\"force\",\"gain\":0.25}"},
      {"collision", 4000, "{\"write\":\"contact\",\"read\":\"skin\"}"},
      {"haptics", 1000, "{\"write\":\"force\",\"read\":\"contact\",\"gain\":-1}"},
      {"graphics", 30, "{\"read\":\"skin\"}"},
  };
  tx_system* s = tx_system_create();
  for (size_t i = 0; i < sizeof spec / sizeof spec[0]; i++) {
    json_t* p = json_loads(spec[i].params, 0, NULL);
    assert_int_equal(tx_system_add(s, spec[i].name, "test.counter", spec[i].rate, p), 0);
    json_decref(p);
  }
  assert_int_equal(tx_system_finalize(s), 0);
  return s;
}

static uint64_t lockstep(tx_system* s, double seconds, FILE* trace) {
  tx_run_options o = {.duration_s = seconds, .lockstep = true, .trace = trace};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  return r.trace_hash;
}

static char* slurp(FILE* f, long* size) {
  fflush(f);
  *size = ftell(f);
  rewind(f);
  char* text = malloc(*size + 1);
  assert_int_equal(fread(text, 1, *size, f), *size);
  return text;
}

static void lockstep_traces_are_bit_identical(void** state) {
  (void)state;
  FILE* t1 = tmpfile();
  FILE* t2 = tmpfile();
  tx_system* a = chain();
  tx_system* b = chain();
  uint64_t h1 = lockstep(a, 1.0, t1), h2 = lockstep(b, 1.0, t2);
  assert_true(h1 == h2);
  long n1, n2;
  char *x1 = slurp(t1, &n1), *x2 = slurp(t2, &n2);
  assert_true(n1 > 1000);
  assert_int_equal(n1, n2);
  assert_memory_equal(x1, x2, n1);
  // a fixed value: a change in scheduling order or arithmetic shows here
  print_message("  trace hash %016llx\n", (unsigned long long)h1);
  assert_true(h1 == 0x0bee6dabef9f10bfull);
  free(x1);
  free(x2);
  fclose(t1);
  fclose(t2);
  tx_system_destroy(a);
  tx_system_destroy(b);
}

static void lockstep_runs_each_rate_exactly(void** state) {
  (void)state;
  tx_system* s = chain();
  lockstep(s, 2.0, NULL);
  const double rates[] = {60, 4000, 1000, 30};
  for (int i = 0; i < 4; i++) {
    tx_controller_stats st = tx_system_stats(s, i);
    assert_int_equal(st.steps, (uint64_t)(rates[i] * 2.0));
    assert_int_equal(st.missed, 0);
    assert_true(st.achieved_hz > rates[i] * 0.999999 && st.achieved_hz < rates[i] * 1.000001);
  }
  tx_system_destroy(s);
}

// at t = 0 every group steps once: the slow writer first, so the fast reader sees it
static void lockstep_ties_go_to_the_slower_group(void** state) {
  (void)state;
  tx_system* s = chain();
  lockstep(s, 0.0001, NULL);
  tx_model* m = tx_system_model(s);
  tx_snapshot skin = tx_model_latest(m, tx_model_find(m, "skin"));
  tx_snapshot contact = tx_model_latest(m, tx_model_find(m, "contact"));
  assert_true(((const double*)skin.data)[0] == 0.25);              // physics step 1: 0.25 x 1
  assert_true(((const double*)contact.data)[0] == 1.0 + 0.5 * 0.25); // collision saw it
  tx_system_destroy(s);
}

static void realtime_runs_every_group_and_moves_data(void** state) {
  (void)state;
  tx_system* s = chain();
  tx_run_options o = {.duration_s = 0.5, .realtime_priority = true, .pin_threads = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  print_message("  %s\n", r.scheduler);
  assert_true(strlen(r.scheduler) > 0);
  for (int i = 0; i < tx_system_count(s); i++) {
    tx_controller_stats st = tx_system_stats(s, i);
    print_message("  %-10s %6llu steps %5llu missed %9.2f Hz\n", tx_system_name(s, i), (unsigned long long)st.steps,
                  (unsigned long long)st.missed, st.achieved_hz);
    assert_true(st.steps > 0);
  }
  tx_model* m = tx_system_model(s);
  tx_snapshot force = tx_model_latest(m, tx_model_find(m, "force"));
  assert_true(force.seq > 0);
  assert_true(((const double*)force.data)[0] != 0); // haptics read collision's contact
  tx_system_destroy(s);
}

// step 1 sleeps sleep_ms: a controlled overrun
typedef struct sleeper {
  double sleep_ms;
} sleeper;

static int sleeper_configure(tx_setup* s, void** self) {
  sleeper* z = calloc(1, sizeof *z);
  *self = z;
  z->sleep_ms = tx_param_num(s, "sleep_ms", 0, 0, 1000);
  return 0;
}

static void sleeper_step(tx_ctx* c, void* self) {
  sleeper* z = self;
  if (tx_step_index(c) != 1) return;
  int64_t ns = (int64_t)(z->sleep_ms * 1e6);
  struct timespec ts = {ns / 1000000000, ns % 1000000000};
  nanosleep(&ts, NULL);
}

// 5 Hz for 1 s: ticks at 0, 200, 400, 600 and 800 ms; step 1 starts at 200 ms
static void overrun(double sleep_ms, uint64_t want_steps, uint64_t want_missed) {
  static tx_controller_class cls = {.type = "test.sleeper", .summary = "sleeps once", .configure = sleeper_configure,
                                    .step = sleeper_step, .fini = counter_fini};
  if (!tx_find_controller(cls.type)) assert_int_equal(tx_register_controller(&cls), 0);
  tx_system* s = tx_system_create();
  json_t* p = json_pack("{s:f}", "sleep_ms", sleep_ms);
  assert_int_equal(tx_system_add(s, "z", "test.sleeper", 5, p), 0);
  json_decref(p);
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = 1.0};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  tx_controller_stats st = tx_system_stats(s, 0);
  print_message("  sleep %g ms: %llu steps, %llu missed\n", sleep_ms, (unsigned long long)st.steps,
                (unsigned long long)st.missed);
  assert_int_equal(st.steps, want_steps);
  assert_int_equal(st.missed, want_missed);
  tx_system_destroy(s);
}

// ends at 500 ms, inside tick 2's period (400-600): tick 2 runs late, nothing is skipped
static void a_late_tick_still_runs_in_its_period(void** state) {
  (void)state;
  overrun(300, 5, 1);
}

// ends at 700 ms: tick 2's period is over, so it is skipped; tick 3 runs late
static void a_tick_whose_period_is_over_is_skipped(void** state) {
  (void)state;
  overrun(500, 4, 2);
}

static int failing_init(tx_ctx* c, void* self) { return -1; }

static void a_failing_init_stops_the_run_cleanly(void** state) {
  (void)state;
  static tx_controller_class bad = {.type = "test.badinit", .summary = "fails init", .configure = counter_configure,
                                    .init = failing_init, .step = counter_step, .fini = counter_fini,
                                    .params = counter_params, .nparams = TX_PARAMS_COUNT(counter_params)};
  if (!tx_find_controller(bad.type)) assert_int_equal(tx_register_controller(&bad), 0);
  for (int lock = 0; lock < 2; lock++) {
    tx_system* s = tx_system_create();
    assert_int_equal(tx_system_add(s, "good", "test.counter", 100, NULL), 0);
    assert_int_equal(tx_system_add(s, "bad", "test.badinit", 50, NULL), 0);
    assert_int_equal(tx_system_finalize(s), 0);
    tx_run_options o = {.duration_s = 0.2, .lockstep = lock};
    tx_run_result r;
    assert_int_equal(tx_system_run(s, &o, &r), -1);
    assert_non_null(strstr(tx_error(), "bad"));
    tx_system_destroy(s);
  }
}

static void bad_durations_are_refused(void** state) {
  (void)state;
  tx_system* s = chain();
  const double bad[] = {0, -1, 86401, NAN, 1e-9, INFINITY};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_run_options o = {.duration_s = bad[i], .lockstep = true};
    tx_run_result r;
    assert_int_equal(tx_system_run(s, &o, &r), -1);
  }
  tx_system_destroy(s);
}

// a controller's tx_stop_run ends the run at once, in either executor, with its reason
static void a_controller_can_stop_the_run(void** state) {
  (void)state;
  for (int lock = 1; lock >= 0; lock--) {
    tx_system* s = tx_system_create();
    json_t* p = json_loads("{\"write\":\"a\",\"stop_at\":20}", 0, NULL);
    assert_int_equal(tx_system_add(s, "stopper", "test.counter", 1000, p), 0);
    json_decref(p);
    p = json_loads("{\"write\":\"b\"}", 0, NULL);
    assert_int_equal(tx_system_add(s, "other", "test.counter", 100, p), 0);
    json_decref(p);
    assert_int_equal(tx_system_finalize(s), 0);
    tx_run_options o = {.duration_s = 5, .lockstep = lock};
    tx_run_result r;
    int64_t t0 = tx_mono_ns();
    assert_int_equal(tx_system_run(s, &o, &r), 0);
    assert_true(r.halted);
    assert_string_equal(r.halt_reason, "stopper: disk full");
    // lockstep: exactly at step 20 (t = 20 ms), and no step after it. In real
    // time a late tick may be skipped, so step 20 may come at a later tick
    if (lock) assert_true(fabs(r.halt_t_s - 0.020) < 1e-9);
    else assert_true(r.halt_t_s >= 0.020 - 1e-9 && r.halt_t_s < 2);
    assert_int_equal(tx_system_stats(s, 0).steps, 21);
    if (!lock) assert_true(tx_mono_ns() - t0 < 3000000000); // not the whole 5 s
    tx_system_destroy(s);
  }
}

// a period past the int64 ns clocks saturates ("never") instead of wrapping to
// INT64_MIN, which made a 1e-10 Hz run spin forever; the slowest allowed rate
// holds every tick of the longest run with a wide margin
static void ticks_saturate_and_the_limits_fit(void** state) {
  (void)state;
  assert_true(tx_tick_ns(1e-10, 1) == INT64_MAX);
  assert_true(tx_tick_ns(1e-10, UINT64_MAX) == INT64_MAX);
  assert_true(tx_tick_ns(1, UINT64_MAX) == INT64_MAX);
  assert_true(tx_tick_ns(1e-10, 0) == 0);
  uint64_t last = (uint64_t)ceil(TX_DURATION_MAX_S * TX_RATE_MIN_HZ) + 1;
  assert_true(tx_tick_ns(TX_RATE_MIN_HZ, last) > 0 && tx_tick_ns(TX_RATE_MIN_HZ, last) < INT64_MAX / 1000);
  assert_true(tx_tick_ns(TX_RATE_MAX_HZ, (uint64_t)(TX_DURATION_MAX_S * TX_RATE_MAX_HZ)) == (int64_t)(TX_DURATION_MAX_S * 1e9));
  // the longest run at the slowest rate: one tick each 1000 s, 0 to 86000 s
  tx_system* s = tx_system_create();
  json_t* p = json_loads("{\"write\":\"a\"}", 0, NULL);
  assert_int_equal(tx_system_add(s, "slow", "test.counter", TX_RATE_MIN_HZ, p), 0);
  json_decref(p);
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = TX_DURATION_MAX_S, .lockstep = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_int_equal(tx_system_stats(s, 0).steps, 87);
  tx_system_destroy(s);
  // and one below it is refused
  s = tx_system_create();
  assert_int_equal(tx_system_add(s, "slower", "test.counter", TX_RATE_MIN_HZ / 2, NULL), -1);
  assert_string_equal(tx_error_key(), "rate_hz");
  tx_system_destroy(s);
}

// every step sleeps 20 ms
static void slow_step(tx_ctx* c, void* self) {
  (void)c, (void)self;
  struct timespec ts = {0, 20000000};
  nanosleep(&ts, NULL);
}

static int progress_calls;
static bool stop_at_once(double elapsed_s, void* user) {
  (void)elapsed_s, (void)user;
  progress_calls++;
  return false;
}

// a stop request is heard within about 100 ms of wall time, however slowly the
// virtual clock moves: 100 ms of simulated time here is 2 s of steps
static void lockstep_hears_a_stop_on_wall_time(void** state) {
  (void)state;
  static tx_controller_class cls = {.type = "test.slow", .summary = "sleeps 20 ms a step", .configure = sleeper_configure,
                                    .step = slow_step, .fini = counter_fini};
  if (!tx_find_controller(cls.type)) assert_int_equal(tx_register_controller(&cls), 0);
  tx_system* s = tx_system_create();
  assert_int_equal(tx_system_add(s, "slow", "test.slow", 1000, NULL), 0);
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = 10, .lockstep = true, .progress = stop_at_once};
  tx_run_result r;
  progress_calls = 0;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_true(r.stopped_early);
  assert_int_equal(progress_calls, 1);
  uint64_t steps = tx_system_stats(s, 0).steps;
  print_message("  stopped after %llu steps, at t = %g s\n", (unsigned long long)steps, r.duration_s);
  assert_true(steps >= 1 && steps <= 20); // about 5; 100 if only simulated time counted
  // the report's duration is the simulated time reached, not the whole run
  assert_true(fabs(r.duration_s - (double)(steps - 1) * 1e-3) < 1e-9);
  tx_system_destroy(s);
}

// a trace that cannot be written (a full disk) stops a lockstep run at once,
// naming the file and the reason, rather than after the whole duration
static void a_trace_write_error_stops_the_run(void** state) {
  (void)state;
  FILE* full = fopen("/dev/full", "w");
  if (!full) skip();
  tx_system* s = chain();
  tx_run_options o = {.duration_s = 10, .lockstep = true, .trace = full, .trace_name = "out/trace.csv"};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_true(r.halted);
  char want[256];
  snprintf(want, sizeof want, "out/trace.csv: %s", strerror(ENOSPC));
  assert_string_equal(r.halt_reason, want);
  print_message("  halted at t = %g s: %s\n", r.halt_t_s, r.halt_reason);
  assert_true(r.halt_t_s < 0.5);
  assert_true(tx_system_stats(s, 1).steps < 2000); // collision, 4 kHz: not the 40000 of 10 s
  fclose(full);
  tx_system_destroy(s);
}

static int finishes;
static void count_finish(tx_ctx* c, void* self) {
  (void)c, (void)self;
  finishes++;
}

// a run whose init failed never started: no controller's finish runs (it would
// flush an empty recording), in either executor
static void no_finish_after_a_failed_init(void** state) {
  (void)state;
  static tx_controller_class fin = {.type = "test.finisher", .summary = "counts finish", .configure = counter_configure,
                                    .step = counter_step, .finish = count_finish, .fini = counter_fini,
                                    .params = counter_params, .nparams = TX_PARAMS_COUNT(counter_params)};
  static tx_controller_class bad = {.type = "test.badinit2", .summary = "fails init", .configure = counter_configure,
                                    .init = failing_init, .step = counter_step, .fini = counter_fini,
                                    .params = counter_params, .nparams = TX_PARAMS_COUNT(counter_params)};
  if (!tx_find_controller(fin.type)) assert_int_equal(tx_register_controller(&fin), 0);
  if (!tx_find_controller(bad.type)) assert_int_equal(tx_register_controller(&bad), 0);
  for (int lock = 0; lock < 2; lock++) {
    tx_system* s = tx_system_create();
    assert_int_equal(tx_system_add(s, "good", "test.finisher", 1000, NULL), 0);
    assert_int_equal(tx_system_add(s, "bad", "test.badinit2", 50, NULL), 0);
    assert_int_equal(tx_system_finalize(s), 0);
    tx_run_options o = {.duration_s = 0.2, .lockstep = lock};
    tx_run_result r;
    finishes = 0;
    assert_int_equal(tx_system_run(s, &o, &r), -1);
    assert_int_equal(finishes, 0);
    assert_int_equal(tx_system_stats(s, 0).steps, 0);
    tx_system_destroy(s);
  }
}

static tx_system* events_chain(int per_step) {
  tx_system* s = tx_system_create();
  char text[96];
  snprintf(text, sizeof text, "{\"emit\":\"tool0.events\",\"per_step\":%d}", per_step);
  json_t* w = json_loads(text, 0, NULL);
  json_t* r = json_loads("{\"listen\":\"tool0.events\"}", 0, NULL);
  json_t* c = json_loads("{\"write\":\"x\"}", 0, NULL);
  assert_int_equal(tx_system_add(s, "writer", "test.events", 1000, w), 0);
  assert_int_equal(tx_system_add(s, "reader", "test.events", 20, r), 0);
  assert_int_equal(tx_system_add(s, "count", "test.counter", 100, c), 0);
  json_decref(w), json_decref(r), json_decref(c);
  assert_int_equal(tx_system_finalize(s), 0);
  return s;
}

// the hash covers events: the same events give the same hash, other events another
static void lockstep_hash_covers_events(void** state) {
  (void)state;
  FILE* t = tmpfile();
  tx_system *a = events_chain(1), *b = events_chain(1), *c = events_chain(2), *none = events_chain(0);
  uint64_t ha = lockstep(a, 0.5, t), hb = lockstep(b, 0.5, NULL), hc = lockstep(c, 0.5, NULL), h0 = lockstep(none, 0.5, NULL);
  print_message("  hashes %016llx %016llx %016llx\n", (unsigned long long)ha, (unsigned long long)hc,
                (unsigned long long)h0);
  assert_true(ha == hb);
  assert_true(ha != hc);
  assert_true(ha != h0);
  assert_true(hc != h0);
  long n;
  char* text = slurp(t, &n);
  // each event is a trace line: "sim_ns,instance,stream,seq,event,hash"
  assert_non_null(strstr(text, "\n0,writer,tool0.events,1,event,"));
  assert_non_null(strstr(text, "\n499000000,writer,tool0.events,500,event,"));
  free(text);
  fclose(t);
  tx_system_destroy(a), tx_system_destroy(b), tx_system_destroy(c), tx_system_destroy(none);
}

// in real time too, a 20 Hz listener takes every event of a 1 kHz writer once and in order
static void realtime_events_arrive_whole(void** state) {
  (void)state;
  tx_system* s = events_chain(1);
  tx_run_options o = {.duration_s = 0.5};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  tx_stream_info st = tx_system_stream(s, 0);
  eventer *w = s->inst[0]->self, *rd = s->inst[1]->self;
  print_message("  sent %llu, received %llu\n", (unsigned long long)st.sent, (unsigned long long)rd->received);
  assert_int_equal(st.sent, w->sent);
  assert_true(st.sent > 0);
  assert_int_equal(st.overflows, 0);
  assert_int_equal(st.lost[0], 0);
  assert_int_equal(rd->gaps, 0);
  assert_int_equal(rd->out_of_order, 0);
  assert_int_equal(rd->received, rd->last_seq);
  assert_true(rd->received + 100 >= st.sent); // at most the 50 ms after its last step unread, with slack
  tx_system_destroy(s);
}

// sleeps sleep_ms every step: a physics step that never fits its period
static void hog_step(tx_ctx* c, void* self) {
  (void)c;
  int64_t ns = (int64_t)(((sleeper*)self)->sleep_ms * 1e6);
  struct timespec ts = {ns / 1000000000, ns % 1000000000};
  nanosleep(&ts, NULL);
}

// a haptics instance beside an overrunning one of the same rate: separate
// threads, so haptics keeps its rate while the other's overruns are counted
static void haptics_keeps_its_rate_beside_an_overrun(void** state) {
  (void)state;
  static tx_controller_class hog = {.type = "test.hog", .summary = "overruns every step", .configure = sleeper_configure,
                                    .step = hog_step, .fini = counter_fini};
  if (!tx_find_controller(hog.type)) assert_int_equal(tx_register_controller(&hog), 0);
  tx_system* s = tx_system_create();
  json_t* p = json_pack("{s:f}", "sleep_ms", 3.0);
  json_t* hp = json_loads("{\"write\":\"force\"}", 0, NULL);
  assert_int_equal(tx_system_add(s, "tissue", "test.hog", 1000, p), 0);
  assert_int_equal(tx_system_add(s, "haptics", "haptics.test", 1000, hp), 0);
  json_decref(p), json_decref(hp);
  assert_int_equal(tx_system_finalize(s), 0);
  assert_int_not_equal(tx_system_thread(s, 0), tx_system_thread(s, 1));
  tx_run_options o = {.duration_s = 1.0, .realtime_priority = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  tx_controller_stats tissue = tx_system_stats(s, 0), hap = tx_system_stats(s, 1);
  print_message("  %s\n  tissue %llu steps %llu missed; haptics %llu steps %llu missed\n", r.scheduler,
                (unsigned long long)tissue.steps, (unsigned long long)tissue.missed, (unsigned long long)hap.steps,
                (unsigned long long)hap.missed);
  assert_true(tissue.missed > 500); // 3 ms steps in 1 ms periods: most ticks missed, and said so
  assert_true(hap.steps >= 950);    // one thread, it would have been about 250
  assert_true(hap.missed < 50);
  tx_system_destroy(s);
}

int main(void) {
  register_test_classes();
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(lockstep_traces_are_bit_identical),
      cmocka_unit_test(lockstep_runs_each_rate_exactly),
      cmocka_unit_test(lockstep_ties_go_to_the_slower_group),
      cmocka_unit_test(realtime_runs_every_group_and_moves_data),
      cmocka_unit_test(a_late_tick_still_runs_in_its_period),
      cmocka_unit_test(a_tick_whose_period_is_over_is_skipped),
      cmocka_unit_test(a_failing_init_stops_the_run_cleanly),
      cmocka_unit_test(bad_durations_are_refused),
      cmocka_unit_test(a_controller_can_stop_the_run),
      cmocka_unit_test(ticks_saturate_and_the_limits_fit),
      cmocka_unit_test(lockstep_hears_a_stop_on_wall_time),
      cmocka_unit_test(a_trace_write_error_stops_the_run),
      cmocka_unit_test(no_finish_after_a_failed_init),
      cmocka_unit_test(lockstep_hash_covers_events),
      cmocka_unit_test(realtime_events_arrive_whole),
      cmocka_unit_test(haptics_keeps_its_rate_beside_an_overrun),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
