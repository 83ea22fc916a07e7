// tactus bench: benchmark tables for the spine. Timings are medians and
// percentiles of one run on this machine; they are printed, never asserted.
#include "bench_cloth.h"
#include "bench_dds.h"
#include "bench_hip.h"
#include "bench_instruments.h"
#include "bench_organ_collision.h"
#include "bench_organs.h"
#include "bench_thermal.h"
#include "bench_render.h"
#include "bench_split.h"
#include "bench_suturing.h"
#include "bench_lagb.h"
#include "bench_thread.h"
#include "bench_voxels.h"
#include "../scenarios/command.h"
#include "../scenarios/run.h"

#include <tactus/stats.h>

#include <tactus/events.h>

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <time.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct bench_args {
  const char* out;
  double duration_s; // 0: the bench's own
} bench_args;

void tx_bench_target(const char* what, const char* measured, const char* limit, bool ok) {
  printf("  %-44s %-24s %-12s %s\n", what, measured, limit, ok ? "met" : "MISSED");
}
void tx_bench_target_us(const char* what, double measured_us, double limit_us) {
  char m[64], l[32];
  snprintf(m, sizeof m, "%.1f us", measured_us);
  snprintf(l, sizeof l, "<= %.0f us", limit_us);
  tx_bench_target(what, m, l, measured_us <= limit_us);
}
static int bench_render(const bench_args* a) { return tx_bench_render(a->out, a->duration_s); }
static int bench_render_gui(const bench_args* a) { return tx_bench_render_gui(a->out, a->duration_s); }

json_t* tx_report_controller(json_t* report, const char* name) {
  size_t i;
  json_t* c;
  json_array_foreach(json_object_get(report, "controllers"), i, c) {
    const char* n = json_string_value(json_object_get(c, "name"));
    if (n && strcmp(n, name) == 0) return c;
  }
  return NULL;
}

// a controller that does nothing: what remains is the framework's cost
static int idle_configure(tx_setup* s, void** self) {
  (void)s;
  *self = NULL;
  return 0;
}
static void idle_step(tx_ctx* c, void* self) {
  (void)c;
  (void)self;
}
static const tx_controller_class idle_class = {
    .type = "bench.idle", .summary = "does nothing", .configure = idle_configure, .step = idle_step};

// run a one-controller scenario of bench.idle at rate_hz; returns its statistics
static int run_idle(double rate_hz, const tx_run_options* o, tx_controller_stats* st, tx_run_result* r, double* wall_ns) {
  char text[256];
  snprintf(text, sizeof text,
           "{\"name\":\"overhead\",\"controllers\":[{\"name\":\"idle\",\"type\":\"bench.idle\",\"rate_hz\":%g}]}",
           rate_hz);
  tx_scenario* sc = tx_scenario_load_text("overhead", text, strlen(text), NULL);
  if (!sc) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  int64_t t0 = tx_mono_ns();
  int rc = tx_system_run(sc->system, o, r);
  *wall_ns = (double)(tx_mono_ns() - t0);
  if (rc) fprintf(stderr, "tactus: %s\n", tx_error());
  else *st = tx_system_stats(sc->system, 0);
  tx_scenario_free(sc);
  return rc ? 1 : 0;
}

// the rates scenario in real time, with the spine's targets
static int bench_rates(const bench_args* a) {
  tx_scenario* sc = tx_load_for_command("rates", NULL, 0, NULL, 0);
  if (!sc) return TX_EXIT_BAD_INPUT;
  printf("bench rates: %g s in real time, four controllers loading both cores\n",
         a->duration_s > 0 ? a->duration_s : sc->duration_s);
  json_t* report = NULL;
  tx_run_config cfg = {.scenario = "rates", .duration_s = a->duration_s, .out = a->out};
  int rc = tx_run_scenario(sc, &cfg, &report);
  tx_scenario_free(sc);
  if (rc) return rc;

  printf("\ntargets:\n");
  bool all = true;
  size_t i;
  json_t* c;
  char measured[64];
  json_array_foreach(json_object_get(report, "controllers"), i, c) {
    double target = json_number_value(json_object_get(c, "target_hz"));
    double achieved = json_number_value(json_object_get(c, "achieved_hz"));
    double error = 100 * fabs(achieved - target) / target;
    char what[96];
    snprintf(what, sizeof what, "%s rate within 1%% of %g Hz", json_string_value(json_object_get(c, "name")), target);
    snprintf(measured, sizeof measured, "%.3f Hz (%.3f%%)", achieved, error);
    tx_bench_target(what, measured, "<= 1%", error <= 1.0);
    all &= error <= 1.0;
  }
  json_t* h = tx_report_controller(report, "haptics");
  if (h) {
    double p99 = json_number_value(json_object_get(json_object_get(h, "jitter_us"), "p99"));
    snprintf(measured, sizeof measured, "%.1f us", p99);
    tx_bench_target("haptics (1 kHz) period jitter p99", measured, "<= 100 us", p99 <= 100);
    double steps = json_number_value(json_object_get(h, "steps")), missed = json_number_value(json_object_get(h, "missed"));
    double pct = 100 * missed / (steps + missed > 0 ? steps + missed : 1);
    snprintf(measured, sizeof measured, "%.0f of %.0f (%.3f%%)", missed, steps + missed, pct);
    tx_bench_target("haptics (1 kHz) missed deadlines", measured, "<= 0.1%", pct <= 0.1);
    all &= p99 <= 100 && pct <= 0.1;
  }
  printf("%s\n", all ? "all targets met" : "some targets MISSED");
  double steal = json_number_value(json_object_get(report, "host_steal_s"));
  double duration = json_number_value(json_object_get(report, "duration_s"));
  json_decref(report);

  // the floor this machine sets: an empty 1 kHz controller alone, same length
  if (!tx_find_controller(idle_class.type)) tx_register_controller(&idle_class);
  tx_run_options alone = {.duration_s = duration, .realtime_priority = true, .pin_threads = true, .keep_cpus_awake = true};
  tx_controller_stats st;
  tx_run_result r;
  double wall;
  if (run_idle(1000, &alone, &st, &r, &wall)) return 1;
  printf("\nthe machine's floor, an empty 1 kHz controller alone for %.0f s:\n", duration);
  printf("  missed %llu of %llu deadlines (%.3f%%), period jitter p50/p99/max %.1f/%.1f/%.1f us\n",
         (unsigned long long)st.missed, (unsigned long long)(st.steps + st.missed),
         100.0 * (double)st.missed / (double)(st.steps + st.missed ? st.steps + st.missed : 1), st.jitter_ns.p50 * 1e-3,
         st.jitter_ns.p99 * 1e-3, st.jitter_ns.max * 1e-3);
  printf("  host steal: %.2f s during the scenario, %.2f s during the empty run\n", steal, r.steal_s);
  return 0;
}

// a 20 Hz listener on its own thread, as physics would take a tool's events
typedef struct listener {
  tx_stream* stream;
  _Atomic bool stop;
  uint64_t taken;
} listener;

static void sleep_until_ns(int64_t ns) {
  struct timespec ts = {ns / 1000000000, ns % 1000000000};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {}
}

static void* listener_main(void* arg) {
  listener* l = arg;
  for (int64_t t = tx_mono_ns();; t += 50000000) {
    bool last = atomic_load(&l->stop); // one more drain after the writer is done
    for (tx_event e; tx_stream_next(l->stream, 0, &e);) l->taken++;
    if (last) return NULL;
    sleep_until_ns(t + 50000000);
  }
}

// a 1 kHz writer's push (tx_emit's cost), each push a millisecond after the last, so
// the ring's lines are as cold as in a real run; a 20 Hz reader drains it on another thread
static int bench_stream_push(tx_percentiles* p, uint64_t* pushes, uint64_t* taken, uint64_t* overflows, bool* fifo_ok) {
  enum { PUSHES = 2000 };
  listener l = {.stream = tx_stream_create("bench.events", 1024)};
  static tx_hist push; // not on the stack
  tx_hist_clear(&push);
  if (!l.stream || tx_stream_add_reader(l.stream) != 0)
    return tx_stream_destroy(l.stream), -1;
  atomic_init(&l.stop, false);
  pthread_t th;
  if (pthread_create(&th, NULL, listener_main, &l) != 0) return tx_stream_destroy(l.stream), -1;
  // the writer as a device thread runs: SCHED_FIFO where granted, restored after
  int policy;
  struct sched_param was, fifo = {.sched_priority = sched_get_priority_max(SCHED_FIFO) - 10};
  pthread_getschedparam(pthread_self(), &policy, &was);
  *fifo_ok = pthread_setschedparam(pthread_self(), SCHED_FIFO, &fifo) == 0;
  int64_t t = tx_mono_ns();
  for (int k = 0; k < PUSHES; k++) {
    t += 1000000;
    sleep_until_ns(t);
    tx_event e = {.kind = TX_EVENT_USER, .sim_ns = k * 1000000LL, .source = (uint32_t)k, .value = {k}};
    int64_t t0 = tx_mono_ns();
    tx_stream_push(l.stream, &e);
    tx_hist_add(&push, tx_mono_ns() - t0);
  }
  if (*fifo_ok) pthread_setschedparam(pthread_self(), policy, &was);
  atomic_store(&l.stop, true);
  pthread_join(th, NULL);
  *p = tx_hist_percentiles(&push);
  *pushes = tx_stream_pushed(l.stream);
  *overflows = tx_stream_overflows(l.stream);
  *taken = l.taken;
  tx_stream_destroy(l.stream);
  return 0;
}

// publish then acquire a 10404 x 3 float component, as the physics-to-collision hand-over does
static int bench_model(const bench_args* a) {
  (void)a;
  enum { ROWS = 10404, COLS = 3, ITER = 20000 };
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &(tx_component_def){"bench.x", TX_F32, ROWS, COLS, "m"});
  tx_reader r = tx_model_add_reader(m, c);
  tx_model_add_reader(m, c); // a second reader holds an older buffer, as graphics would
  if (!c.id || !r.id || !tx_model_commit(m)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  float* source = malloc(sizeof(float) * ROWS * COLS);
  static tx_hist swap, full; // not on the stack
  tx_hist_clear(&swap);
  tx_hist_clear(&full);
  if (!source) return fprintf(stderr, "tactus: out of memory\n"), 1;
  for (int i = 0; i < ROWS * COLS; i++) source[i] = (float)i;
  volatile float sink = 0;
  for (int k = 0; k < ITER; k++) {
    source[k % (ROWS * COLS)] += 1.0f;
    int64_t t0 = tx_mono_ns();
    memcpy(tx_model_back(m, c), source, sizeof(float) * ROWS * COLS);
    int64_t t1 = tx_mono_ns();
    tx_model_publish(m, c, k);
    tx_snapshot s = tx_model_acquire(m, r);
    sink += ((const float*)s.data)[k % (ROWS * COLS)];
    int64_t t2 = tx_mono_ns();
    tx_hist_add(&swap, t2 - t1);
    tx_hist_add(&full, t2 - t0);
  }
  tx_percentiles ps = tx_hist_percentiles(&swap), pf = tx_hist_percentiles(&full);
  printf("bench model: %d publishes of a %dx%d f32 component (%.0f KiB), 2 readers\n\n", ITER, ROWS, COLS,
         ROWS * COLS * 4 / 1024.0);
  printf("  %-40s %10s %10s %10s\n", "operation", "p50 us", "p99 us", "max us");
  printf("  %-40s %10.2f %10.2f %10.2f\n", "publish + acquire", ps.p50 * 1e-3, ps.p99 * 1e-3, ps.max * 1e-3);
  printf("  %-40s %10.2f %10.2f %10.2f\n", "fill 122 KiB + publish + acquire", pf.p50 * 1e-3, pf.p99 * 1e-3, pf.max * 1e-3);
  tx_percentiles pe;
  uint64_t pushes = 0, taken = 0, overflows = 0;
  bool fifo_ok = false;
  if (bench_stream_push(&pe, &pushes, &taken, &overflows, &fifo_ok)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  printf("  %-40s %10.2f %10.2f %10.2f\n", "event push, 1 kHz writer, 20 Hz reader", pe.p50 * 1e-3, pe.p99 * 1e-3,
         pe.max * 1e-3);
  printf("  (%llu events sent, %llu taken, %llu overflows; writer %s)\n", (unsigned long long)pushes,
         (unsigned long long)taken, (unsigned long long)overflows, fifo_ok ? "SCHED_FIFO" : "SCHED_OTHER: FIFO refused");
  printf("\ntargets:\n");
  char measured[64];
  snprintf(measured, sizeof measured, "%.2f us (with the fill)", pf.p99 * 1e-3);
  tx_bench_target("publish + acquire 10404x3 f32, p99", measured, "<= 20 us", pf.p99 * 1e-3 <= 20);
  snprintf(measured, sizeof measured, "%.3f us", pe.p99 * 1e-3);
  tx_bench_target("event push of a 1 kHz writer, p99", measured, "<= 1 us", pe.p99 * 1e-3 <= 1 && taken == pushes);
  if (sink == -1.0f) printf("(unreachable: keeps the reads)\n");
  free(source);
  tx_model_destroy(m);
  return 0;
}

static int bench_overhead(const bench_args* a) {
  (void)a;
  if (!tx_find_controller(idle_class.type)) tx_register_controller(&idle_class);
  // lockstep at the highest allowed rate: the executor loop and nothing else
  const double lock_hz = TX_RATE_MAX_HZ, lock_s = 10, rt_hz = 10000, rt_s = 3;
  tx_controller_stats ls, rs;
  tx_run_result r;
  double lock_wall, rt_wall;
  tx_run_options lock = {.duration_s = lock_s, .lockstep = true};
  tx_run_options rt = {.duration_s = rt_s, .realtime_priority = true, .pin_threads = true, .keep_cpus_awake = true};
  if (run_idle(lock_hz, &lock, &ls, &r, &lock_wall) || run_idle(rt_hz, &rt, &rs, &r, &rt_wall)) return 1;
  double per_step = lock_wall / (double)ls.steps;

  printf("bench overhead: an empty controller\n\n");
  printf("  %-58s %9s %9s %9s\n", "measure", "p50 us", "p99 us", "max us");
  printf("  %-58s %9.3f %9s %9s\n", "lockstep 100 kHz, 10 s: wall time per step, whole loop", per_step * 1e-3, "-", "-");
  printf("  %-58s %9.3f %9.3f %9.3f\n", "lockstep 100 kHz: step call + publish + bookkeeping", ls.step_ns.p50 * 1e-3,
         ls.step_ns.p99 * 1e-3, ls.step_ns.max * 1e-3);
  printf("  %-58s %9.3f %9.3f %9.3f\n", "real time 10 kHz, 3 s: step call + publish + bookkeeping",
         rs.step_ns.p50 * 1e-3, rs.step_ns.p99 * 1e-3, rs.step_ns.max * 1e-3);
  printf("  %-58s %9.3f %9.3f %9.3f\n", "real time 10 kHz: period jitter", rs.jitter_ns.p50 * 1e-3,
         rs.jitter_ns.p99 * 1e-3, rs.jitter_ns.max * 1e-3);
  printf("  real time 10 kHz: %.2f Hz achieved, %llu of %llu deadlines missed; %s\n", rs.achieved_hz,
         (unsigned long long)rs.missed, (unsigned long long)(rs.steps + rs.missed), r.scheduler);
  printf("\ntargets:\n");
  char measured[64];
  snprintf(measured, sizeof measured, "%.3f us", per_step * 1e-3);
  tx_bench_target("framework overhead of an empty step", measured, "<= 5 us", per_step * 1e-3 <= 5);
  return 0;
}

// a wall at 60 Hz rendered by haptics at haptics_hz, with or without the rates scenario's load beside it
static tx_scenario* haptics_scenario(double haptics_hz, bool loaded) {
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"bench-haptics\",\"controllers\":["
           "{\"name\":\"wall\",\"type\":\"collision.wall\",\"rate_hz\":60},"
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":%g,"
           "\"params\":{\"device\":\"scripted:pierce-down\",\"force_model\":\"tool0.force_model\"}}%s]}",
           haptics_hz,
           loaded ? ",{\"name\":\"physics\",\"type\":\"rates.worker\",\"rate_hz\":20,\"params\":{\"work_us\":10000}},"
                    "{\"name\":\"collision\",\"type\":\"rates.worker\",\"rate_hz\":4000,\"params\":{\"work_us\":50}},"
                    "{\"name\":\"graphics\",\"type\":\"rates.worker\",\"rate_hz\":30,\"params\":{\"work_us\":5000}}"
                  : "");
  tx_scenario* sc = tx_scenario_load_text("bench-haptics", text, strlen(text), NULL);
  if (!sc) fprintf(stderr, "tactus: %s\n", tx_error());
  return sc;
}

// the haptics controller of a scenario run in real time for seconds
static int run_haptics(double hz, bool loaded, double seconds, tx_controller_stats* st, tx_run_result* r) {
  tx_scenario* sc = haptics_scenario(hz, loaded);
  if (!sc) return 1;
  tx_run_options o = {.duration_s = seconds, .realtime_priority = true, .pin_threads = true, .keep_cpus_awake = true};
  int rc = tx_system_run(sc->system, &o, r);
  if (rc) fprintf(stderr, "tactus: %s\n", tx_error());
  for (int i = 0; rc == 0 && i < tx_system_count(sc->system); i++)
    if (strcmp(tx_system_name(sc->system, i), "haptics") == 0) *st = tx_system_stats(sc->system, i);
  tx_scenario_free(sc);
  return rc ? 1 : 0;
}

static int bench_haptics(const bench_args* a) {
  const double seconds = a->duration_s > 0 ? a->duration_s : 10;
  tx_controller_stats idle1k, loaded1k, idle10k;
  tx_run_result r1, r2, r3;
  printf("bench haptics: a wall at 60 Hz rendered by the haptics controller, %g s per case, in real time\n\n", seconds);
  if (run_haptics(1000, false, seconds, &idle1k, &r1) || run_haptics(1000, true, seconds, &loaded1k, &r2) ||
      run_haptics(10000, false, seconds, &idle10k, &r3))
    return 1;
  printf("  %-34s %9s %9s %9s %9s %9s %9s %10s %8s\n", "case", "Hz", "tick p50", "tick p99", "jit p50", "jit p99",
         "jit max", "missed", "steal s");
  const struct {
    const char* name;
    const tx_controller_stats* st;
    const tx_run_result* r;
  } rows[] = {{"1 kHz, nothing else running", &idle1k, &r1},
              {"1 kHz, rates load on both cores", &loaded1k, &r2},
              {"10 kHz, nothing else running", &idle10k, &r3}};
  for (int i = 0; i < 3; i++) {
    const tx_controller_stats* st = rows[i].st;
    char missed[32];
    snprintf(missed, sizeof missed, "%.3f%%", 100.0 * (double)st->missed / (double)(st->steps + st->missed));
    printf("  %-34s %9.1f %9.2f %9.2f %9.1f %9.1f %9.1f %10s %8.2f\n", rows[i].name, st->achieved_hz,
           st->step_ns.p50 * 1e-3, st->step_ns.p99 * 1e-3, st->jitter_ns.p50 * 1e-3, st->jitter_ns.p99 * 1e-3,
           st->jitter_ns.max * 1e-3, missed, rows[i].r->steal_s);
  }
  printf("  (tick and jitter in us; a tick is the device read, rendering, passivity, safety, write and publishes)\n");
  printf("\ntargets:\n");
  char measured[64];
  snprintf(measured, sizeof measured, "%.2f us", loaded1k.step_ns.p99 * 1e-3);
  tx_bench_target("one haptics tick, p99 (loaded)", measured, "<= 20 us", loaded1k.step_ns.p99 * 1e-3 <= 20);
  double pct = 100.0 * (double)loaded1k.missed / (double)(loaded1k.steps + loaded1k.missed);
  snprintf(measured, sizeof measured, "%.3f%%", pct);
  tx_bench_target("1 kHz with both cores loaded, missed", measured, "<= 0.1%", pct <= 0.1);
  snprintf(measured, sizeof measured, "%.1f Hz, p99 %.1f us", idle10k.achieved_hz, idle10k.jitter_ns.p99 * 1e-3);
  tx_bench_target("10 kHz reachable, jitter p99", measured, "<= 50 us",
               idle10k.achieved_hz > 9900 && idle10k.jitter_ns.p99 * 1e-3 <= 50);
  return 0;
}

static int bench_voxels(const bench_args* a) { return tx_bench_voxels(a->duration_s); }
static int bench_cloth(const bench_args* a) { return tx_bench_cloth(a->duration_s); }
static int bench_organs(const bench_args* a) { return tx_bench_organs(a->duration_s); }
static int bench_thermal(const bench_args* a) { return tx_bench_thermal(a->duration_s); }
static int bench_instruments(const bench_args* a) { return tx_bench_instruments(a->duration_s); }
static int bench_thread(const bench_args* a) { return tx_bench_thread(a->duration_s); }
static int bench_organ_collision(const bench_args* a) { return tx_bench_organ_collision(a->duration_s); }

// the bridges' sender threads poll every 50 us (net.poll_us); the echoing sim runs at the HIP's 4 kHz
static int bench_dds(const bench_args* a) { return tx_bench_dds(a->duration_s, 1000, 4000, 0, true); }
static int bench_split_session(const bench_args* a) { return tx_bench_split_session(a->out, a->duration_s); }
static int bench_suturing(const bench_args* a) { return tx_bench_suturing(a->out, a->duration_s); }
static int bench_lagb(const bench_args* a) { return tx_bench_lagb(a->out, a->duration_s); }

static int bench_hip(const bench_args* a) {
  (void)a;
  return tx_bench_hip();
}

static const struct {
  const char* name;
  int (*run)(const bench_args*);
  const char* what;
} benches[] = {
    {"rates", bench_rates, "the rates scenario for 10 s in real time: rates, jitter, missed deadlines"},
    {"model", bench_model, "publish + acquire of a 10404x3 f32 component; an event push at 1 kHz"},
    {"overhead", bench_overhead, "framework cost of an empty controller step"},
    {"haptics", bench_haptics, "haptics tick cost, 1 kHz under load, 10 kHz idle"},
    {"voxels", bench_voxels, "needle in 250 to 100000 voxels: haptic Hz beside the voxel paper's Table 1"},
    {"render", bench_render, "graphics view frame times, mono and 2x640x480 stereo, beside 1 kHz haptics"},
    {"render-gui", bench_render_gui, "the trainer's panels in a 640x480 window: their cost per frame, and haptics' rate beside them (render's last tables)"},
    {"cloth", bench_cloth, "skin physics step at 10404 particles with rupture; overhead vs a bare Bullet loop"},
    {"hip", bench_hip, "collision.hip query (98 rays) on 10404 and 102400 particles, and the refit"},
    {"organ-collision", bench_organ_collision, "collision.organ query against the committed liver and stomach, and the refit"},
    {"instruments", bench_instruments, "one 1 kHz ODE step of two articulated instruments and the needle"},
    {"organs", bench_organs, "physics.organs step, liver and stomach (5793 tetrahedra), fem and links, against 30 Hz"},
    {"thermal", bench_thermal, "the cautery's bioheat step on the liver and stomach at 100 Hz, surfaces included, against 2 ms"},
    {"thread", bench_thread, "suture thread step, ftl and rod, 100 and 1000 nodes with self collision"},
    {"dds", bench_dds, "two processes over loopback (net.dds): pose -> sim -> force round trip, a 10404x3 mesh at 60 Hz"},
    {"suturing", bench_suturing, "the suturing scenario in real time beside an empty 1 kHz controller: rates, missed deadlines; lockstep time"},
    {"lagb", bench_lagb, "gastric banding in real time with no view, mono and stereo: physics, haptics and frame rates against their targets"},
    {"split-session", bench_split_session, "suturing-skin in one, two and three processes, alternated in 5 rounds: haptics' missed deadlines"},
};

int tx_cmd_bench(int argc, char** argv) {
  static const struct option longs[] = {
      {"out", required_argument, 0, 'o'}, {"duration", required_argument, 0, 'd'}, {"help", no_argument, 0, 'h'},
      {"force", no_argument, 0, 'F'},     {0, 0, 0, 0}};
  bench_args a = {0};
  bool force = false;
  optind = 1;
  opterr = 0;
  for (int c; (c = getopt_long(argc, argv, "", longs, NULL)) != -1;) {
    if (c == 'o') a.out = optarg;
    else if (c == 'F') force = true;
    else if (c == 'd') {
      if (!tx_parse_num(optarg, 0.1, 3600, &a.duration_s)) return tx_bad_input("--duration %s: expected seconds in [0.1, 3600]", optarg);
    } else if (c == 'h') {
      optind = argc + 1; // --help: list the benchmarks; reading on would pass the end of argv
      break;
    } else if (optopt && strncmp(argv[optind - 1], "--", 2) != 0) // inside a group of short options
      return tx_bad_input("bench: unknown option '-%c'", optopt);
    else return tx_bad_input("bench: unknown or incomplete option '%s'", argv[optind - 1]);
  }
  if (optind != argc - 1) {
    printf("usage: tactus bench NAME [--out DIR [--force]] [--duration S]\n\n");
    for (size_t i = 0; i < sizeof benches / sizeof benches[0]; i++) printf("  %-11s %s\n", benches[i].name, benches[i].what);
    if (optind == argc + 1) return 0; // --help
    return tx_bad_input("bench: expected one NAME from the list above");
  }
  for (size_t i = 0; i < sizeof benches / sizeof benches[0]; i++) {
    if (strcmp(argv[optind], benches[i].name) != 0) continue;
    if (tx_out_check(a.out, force)) return TX_EXIT_BAD_INPUT; // a used --out is refused, as by run
    return benches[i].run(&a);
  }
  return tx_bad_input("bench %s: unknown benchmark (tactus bench lists them)", argv[optind]);
}
