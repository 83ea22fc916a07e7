// Run control: pause, single step, reset and the time scale, in lockstep
// (exact tick counts) and in real time (haptics keeps its rate through a pause).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/haptics/recorder.h"
#include "controllers/system.h"
#include "model/error.h"
#include "scenarios/loader.h"

#include <tactus/components.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

// what each accumulator has counted, for a thread other than its own to read
static _Atomic long mirror[4];

// counts its steps in its own state; init publishes 0 (the initial model)
typedef struct accum {
  tx_port out;
  long count;
  long gain; // added per step
  int slot;
} accum;

static const tx_param_def accum_params[] = {
    {"write", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "the component written (f64 1 x 1)"},
    {"slot", TX_PARAM_INT, "1", 0, 3, 0, NULL, "its mirror"},
    {"gain", TX_PARAM_INT, "1", 1, 100, 1, NULL, "added per step"},
    {"name", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "a text"},
};
static const char* const accum_live[] = {"gain", NULL};

static void accum_tune(tx_ctx* c, void* self, const char* key, double value) {
  (void)c;
  assert_string_equal(key, "gain");
  ((accum*)self)->gain = (long)value;
}

static int accum_configure(tx_setup* s, void** self) {
  accum* a = calloc(1, sizeof *a);
  *self = a;
  a->slot = (int)tx_table_int(s, "slot");
  a->gain = tx_table_int(s, "gain");
  a->out = tx_setup_write(s, &(tx_component_def){tx_table_str(s, "write"), TX_F64, 1, 1, "1"});
  return 0;
}

static void publish(tx_ctx* c, accum* a) {
  *(double*)tx_write(c, a->out) = (double)a->count;
  atomic_store(&mirror[a->slot], a->count);
}

static int accum_init(tx_ctx* c, void* self) {
  publish(c, self);
  return 0;
}

static void accum_step(tx_ctx* c, void* self) {
  accum* a = self;
  a->count += a->gain;
  publish(c, a);
}

static void accum_fini(void* self) { free(self); }

static const tx_controller_class accum_cls = {.type = "test.accum", .summary = "counts its steps",
                                              .configure = accum_configure, .init = accum_init, .step = accum_step,
                                              .fini = accum_fini, .params = accum_params,
                                              .nparams = TX_PARAMS_COUNT(accum_params), .live = accum_live, .tune = accum_tune};
// the same on a haptics thread: live, it steps through a pause and a reset leaves it be
static const tx_controller_class live_cls = {.type = "haptics.accum", .summary = "counts its steps",
                                             .configure = accum_configure, .init = accum_init, .step = accum_step,
                                             .fini = accum_fini, .params = accum_params,
                                             .nparams = TX_PARAMS_COUNT(accum_params), .live = accum_live, .tune = accum_tune};

static void add(tx_system* s, const char* name, const char* type, double rate, const char* write, int slot) {
  char text[128];
  snprintf(text, sizeof text, "{\"write\":\"%s\",\"slot\":%d}", write, slot);
  json_t* p = json_loads(text, 0, NULL);
  assert_int_equal(tx_system_add(s, name, type, rate, p), 0);
  json_decref(p);
}

static double value(tx_system* s, const char* name) {
  tx_model* m = tx_system_model(s);
  return *(const double*)tx_model_latest(m, tx_model_find(m, name)).data;
}

// lockstep, driven from the progress call (the run's own thread): exact counts
typedef struct script {
  tx_system* s;
  int stage;
  double paused_at;
  double phys_before, fast_before;
} script;

static bool drive(double t, void* user) {
  script* k = user;
  tx_system* s = k->s;
  switch (k->stage) {
  case 0:
    if (t < 0.5) return true;
    assert_int_equal(tx_system_pause(s), 0);
    assert_true(tx_system_paused(s));
    k->paused_at = tx_system_sim_time(s);
    break;
  case 1: // paused: the clock and both counts stand still
    assert_true(fabs(tx_system_sim_time(s) - k->paused_at) < 1e-12);
    k->phys_before = value(s, "phys.x");
    k->fast_before = value(s, "fast.x");
    assert_int_equal(tx_system_step(s), 0); // to the next 10 ms tick of the slowest (100 Hz)
    break;
  case 2: {
    double T = tx_system_sim_time(s);
    assert_true(T > k->paused_at && T <= k->paused_at + 0.01 + 1e-9);
    // a tick at time T runs; every tick from 0 counts 1
    assert_true(value(s, "phys.x") == floor(T * 100 + 1e-9) + 1);
    assert_true(value(s, "fast.x") == floor(T * 1000 + 1e-9) + 1);
    assert_true(value(s, "phys.x") == k->phys_before + 1);
    assert_int_equal(tx_system_reset(s), 0);
    break;
  }
  case 3: // the reset is carried out at once, paused: the initial model
    assert_int_equal(tx_system_resets_done(s), 1);
    assert_true(value(s, "phys.x") == 0);
    assert_true(value(s, "fast.x") == 0);
    assert_int_equal(tx_system_step(s), 0);
    break;
  case 4: // counting again from the start: one 10 ms step is 1 and 10 ticks
    assert_true(value(s, "phys.x") == 1);
    assert_true(value(s, "fast.x") == 10);
    assert_int_equal(tx_system_resume(s), 0);
    assert_false(tx_system_paused(s));
    break;
  default:
    return true;
  }
  k->stage++;
  return true;
}

static void lockstep_pause_step_reset(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  add(s, "physics", "test.accum", 100, "phys.x", 0);
  add(s, "fast", "test.accum", 1000, "fast.x", 1);
  assert_int_equal(tx_system_finalize(s), 0);
  assert_true(fabs(tx_system_step_period(s) - 0.01) < 1e-15);
  script k = {.s = s};
  tx_run_options o = {.duration_s = 1, .lockstep = true, .progress = drive, .progress_user = &k};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_int_equal(k.stage, 5);
  assert_false(r.halted);
  assert_true(r.duration_s == 1);
  // the simulation ran 1 s in all; after the reset the counts restarted at the reset's time
  double reset_at = k.paused_at; // within one step of it
  assert_true(value(s, "phys.x") > (1 - reset_at) * 100 - 3 && value(s, "phys.x") < (1 - reset_at) * 100 + 3);
  tx_system_destroy(s);
}

// a reset before a run is nothing: the run starts from the initial model anyway
static void reset_before_run_is_the_start(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  add(s, "physics", "test.accum", 100, "phys.x", 0);
  assert_int_equal(tx_system_finalize(s), 0);
  assert_int_equal(tx_system_reset(s), 0);
  tx_run_options o = {.duration_s = 0.1, .lockstep = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_true(value(s, "phys.x") == 10);
  tx_system_destroy(s);
}

static void time_scale_range(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  add(s, "physics", "test.accum", 100, "phys.x", 0);
  assert_int_equal(tx_system_finalize(s), 0);
  assert_int_equal(tx_system_set_time_scale(s, 0.2), -1);
  assert_non_null(strstr(tx_error(), "time scale 0.2 is out of range [0.25, 1]"));
  assert_int_equal(tx_system_set_time_scale(s, 1.5), -1);
  assert_int_equal(tx_system_set_time_scale(s, NAN), -1);
  assert_int_equal(tx_system_set_time_scale(s, 0.25), 0);
  assert_true(tx_system_time_scale(s) == 0.25);
  tx_system_destroy(s);
}

// a configure that fails at the reset stops the run with the reason, rather than stepping a broken instance
static int fail_on_second;
static int fragile_configure(tx_setup* s, void** self) {
  if (++fail_on_second == 2) return tx_setup_fail(s, "params.write", "the file is gone"), -1;
  return accum_configure(s, self);
}
static const tx_controller_class fragile_cls = {.type = "test.fragile", .summary = "fails its second configure",
                                                .configure = fragile_configure, .init = accum_init,
                                                .step = accum_step, .fini = accum_fini, .params = accum_params,
                                                .nparams = TX_PARAMS_COUNT(accum_params), .live = accum_live, .tune = accum_tune};

static bool reset_at_once(double t, void* user) {
  (void)t;
  tx_system* s = user;
  if (tx_system_resets(s) == 0) assert_int_equal(tx_system_reset(s), 0);
  return true;
}

static void failed_rebuild_stops_the_run(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  add(s, "physics", "test.fragile", 100, "phys.x", 0);
  assert_int_equal(tx_system_finalize(s), 0);
  tx_run_options o = {.duration_s = 1, .lockstep = true, .progress = reset_at_once, .progress_user = s};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_true(r.halted);
  assert_non_null(strstr(r.halt_reason, "physics: reset: configure failed: the file is gone"));
  assert_true(r.halt_t_s < 0.2);
  tx_system_destroy(s);
}

// a live parameter changes from the next step on, and the change is logged with its time
static bool tune_at_half(double t, void* user) {
  tx_system* s = user;
  if (t >= 0.5 && tx_system_tunes(s) == 0 && value(s, "phys.x") == 51) {
    assert_int_equal(tx_system_tune(s, 0, "gain", 10), 0);
  }
  return true;
}

static void tune_live_parameter(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  add(s, "physics", "test.accum", 100, "phys.x", 0);
  assert_int_equal(tx_system_finalize(s), 0);
  // refused: a key the table lacks, one that is not live, out of range, not whole
  assert_int_equal(tx_system_tune(s, 0, "speed", 1), -1);
  assert_non_null(strstr(tx_error(), "physics (test.accum) has no parameter 'speed'"));
  assert_int_equal(tx_system_tune(s, 0, "slot", 1), -1);
  assert_non_null(strstr(tx_error(), "physics.slot cannot change during a run"));
  assert_int_equal(tx_system_tune(s, 0, "gain", 101), -1);
  assert_non_null(strstr(tx_error(), "physics.gain: 101 is out of range [1, 100]"));
  assert_int_equal(tx_system_tune(s, 0, "gain", 2.5), -1);
  assert_int_equal(tx_system_tune(s, 7, "gain", 2), -1);
  tx_run_options o = {.duration_s = 1, .lockstep = true, .progress = tune_at_half, .progress_user = s};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_int_equal(tx_system_tunes(s), 1);
  tx_tune_info t = tx_system_tune_at(s, 0);
  assert_string_equal(t.controller, "physics");
  assert_string_equal(t.key, "gain");
  assert_true(t.value == 10);
  assert_true(fabs(t.t_s - 0.51) < 1e-9); // the tick after the call
  // ticks 0.00-0.50 add 1 (51), 0.51-0.99 add 10 (49 ticks)
  assert_true(value(s, "phys.x") == 51 + 490);
  tx_system_destroy(s);
}

// a class with a live parameter and no tune is refused at registration
static void live_needs_tune(void** state) {
  (void)state;
  static const char* const text_live[] = {"name", NULL}, *const unknown_live[] = {"speed", NULL};
  tx_controller_class bad = accum_cls;
  bad.type = "test.bad_live";
  bad.live = text_live;
  assert_int_equal(tx_register_controller(&bad), -1);
  assert_non_null(strstr(tx_error(), "name: only a number, an integer or a boolean can be live"));
  bad.live = unknown_live;
  assert_int_equal(tx_register_controller(&bad), -1);
  assert_non_null(strstr(tx_error(), "'speed' is not in the parameter table"));
  tx_controller_class untuned = accum_cls;
  untuned.type = "test.untuned";
  untuned.tune = NULL;
  assert_int_equal(tx_register_controller(&untuned), -1);
  assert_non_null(strstr(tx_error(), "gain: live, but the class has no tune"));
}

// real time: the driver is another thread, as a window's would be
typedef struct driver {
  tx_system* s;
  long phys_paused[2], live_paused[2];
  long phys_stepped, phys_reset;
  long phys_scaled, live_scaled;
  uint64_t resets_done;
  int errors;
} driver;

static void sleep_ms(int ms) {
  struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000};
  nanosleep(&ts, NULL);
}

static void* drive_realtime(void* arg) {
  driver* d = arg;
  tx_system* s = d->s;
  sleep_ms(100);
  d->errors += tx_system_pause(s) != 0;
  sleep_ms(20); // a step already under way ends
  d->phys_paused[0] = atomic_load(&mirror[0]);
  d->live_paused[0] = atomic_load(&mirror[1]);
  sleep_ms(150);
  d->phys_paused[1] = atomic_load(&mirror[0]);
  d->live_paused[1] = atomic_load(&mirror[1]);
  d->errors += tx_system_step(s) != 0;
  for (int i = 0; i < 200 && atomic_load(&mirror[0]) == d->phys_paused[1]; i++) sleep_ms(5);
  sleep_ms(20);
  d->phys_stepped = atomic_load(&mirror[0]);
  d->errors += tx_system_reset(s) != 0;
  for (int i = 0; i < 200 && tx_system_resets_done(s) < 1; i++) sleep_ms(5);
  d->resets_done = tx_system_resets_done(s);
  d->phys_reset = atomic_load(&mirror[0]);
  d->errors += tx_system_set_time_scale(s, 0.25) != 0;
  d->errors += tx_system_resume(s) != 0;
  long p0 = atomic_load(&mirror[0]), l0 = atomic_load(&mirror[1]);
  sleep_ms(400);
  d->phys_scaled = atomic_load(&mirror[0]) - p0;
  d->live_scaled = atomic_load(&mirror[1]) - l0;
  d->errors += tx_system_set_time_scale(s, 1) != 0;
  return NULL;
}

static void realtime_haptics_runs_through_a_pause(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  add(s, "physics", "test.accum", 200, "phys.x", 0);
  add(s, "haptics", "haptics.accum", 1000, "hap.x", 1);
  assert_int_equal(tx_system_finalize(s), 0);
  assert_true(fabs(tx_system_step_period(s) - 0.005) < 1e-15); // haptics is never the step
  char dir[] = "/tmp/tx_control_XXXXXX";
  assert_non_null(mkdtemp(dir));
  driver d = {.s = s};
  pthread_t th;
  assert_int_equal(pthread_create(&th, NULL, drive_realtime, &d), 0);
  tx_run_options o = {.duration_s = 0.3, .record_dir = dir};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  pthread_join(th, NULL);
  assert_int_equal(d.errors, 0);
  // paused: physics stands, haptics goes on at its rate (150 ms: about 150 ticks)
  assert_int_equal(d.phys_paused[1], d.phys_paused[0]);
  assert_true(d.live_paused[1] - d.live_paused[0] > 30); // loose: a loaded machine starves threads
  // one step: one 5 ms tick of physics
  assert_int_equal(d.phys_stepped, d.phys_paused[1] + 1);
  // a reset: physics counts from 0 again, haptics does not
  assert_int_equal(d.resets_done, 1);
  assert_int_equal(d.phys_reset, 0);
  // x0.25 for 400 ms: 20 physics steps at 200 Hz (never more than the scale allows), haptics
  // about 400 at its full rate: 20 times as many; at least 5 times on a loaded machine
  assert_true(d.phys_scaled >= 3 && d.phys_scaled <= 28);
  assert_true(d.live_scaled > 5 * d.phys_scaled);
  assert_false(r.halted);
  assert_true(fabs(r.duration_s - 0.3) < 1e-9); // the simulation's time, pauses left out
  // the controls, logged beside the recordings with the simulation time
  char path[64], text[512] = "";
  snprintf(path, sizeof path, "%s/controls.csv", dir);
  FILE* f = fopen(path, "r");
  assert_non_null(f);
  size_t n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[n] = 0;
  assert_non_null(strstr(text, "t_s,action,value\n"));
  const char* order[] = {",pause,", ",step,0.005", ",reset,", ",time_scale,0.25", ",resume,", ",time_scale,1"};
  const char* at = text;
  for (size_t i = 0; i < sizeof order / sizeof *order; i++) {
    const char* hit = strstr(at, order[i]);
    assert_non_null(hit);
    at = hit;
  }
  remove(path);
  rmdir(dir);
  tx_system_destroy(s);
}

// test.ramp: a force model whose F0 grows with the steps since its init, so that a reset shows in
// what haptics records (F0 back to 0)
typedef struct ramp {
  tx_port out;
  long count;
} ramp;

static int ramp_configure(tx_setup* s, void** self) {
  ramp* r = calloc(1, sizeof *r);
  *self = r;
  r->out = tx_setup_write(s, &TX_COMPONENT_OF("tool0.force_model", tx_force_model, 1));
  return 0;
}

static void ramp_publish(tx_ctx* c, ramp* r) {
  tx_force_model* m = tx_write(c, r->out);
  memset(m, 0, sizeof *m);
  m->f0[1] = 0.01 * (double)r->count;
}

static int ramp_init(tx_ctx* c, void* self) {
  ramp_publish(c, self);
  return 0;
}

static void ramp_step(tx_ctx* c, void* self) {
  ramp* r = self;
  r->count++;
  ramp_publish(c, r);
}

static const tx_controller_class ramp_cls = {.type = "test.ramp", .summary = "a force model that grows",
                                             .configure = ramp_configure, .init = ramp_init, .step = ramp_step,
                                             .fini = accum_fini};

// the session: a reset at 0.3 s from the run's own thread
static bool reset_once(double t, void* user) {
  int* done = user;
  if (t >= 0.3 && !*done) *done = 1, assert_int_equal(tx_system_reset(tx_system_running()), 0);
  return true;
}

// a lockstep run of the ramp at 100 Hz and haptics at 1 kHz from DEVICE, recorded into dir
static void session(const char* device, const char* dir, bool reset) {
  tx_system* s = tx_system_create();
  assert_int_equal(tx_system_add(s, "ramp", "test.ramp", 100, NULL), 0);
  char text[512];
  snprintf(text, sizeof text, "{\"device\":\"%s\",\"force_model\":\"tool0.force_model\"}", device);
  json_t* p = json_loads(text, 0, NULL);
  int rc = tx_system_add(s, "haptics", "haptics", 1000, p);
  if (rc) fprintf(stderr, "%s\n", tx_error());
  assert_int_equal(rc, 0);
  json_decref(p);
  assert_int_equal(tx_system_finalize(s), 0);
  int done = 0;
  tx_run_options o = {.duration_s = 0.6, .lockstep = true, .record_dir = dir, .progress = reset ? reset_once : NULL,
                      .progress_user = &done};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  assert_false(r.halted);
  tx_system_destroy(s);
}

static tx_record_file load(const char* dir) {
  char path[128];
  snprintf(path, sizeof path, "%s/device0.bin", dir);
  tx_record_file f;
  assert_int_equal(tx_record_load(path, &f), 0);
  return f;
}

static void clean(const char* dir) {
  const char* files[] = {"device0.bin", "device0.csv", "controls.csv"};
  char path[128];
  for (size_t i = 0; i < 3; i++) snprintf(path, sizeof path, "%s/%s", dir, files[i]), remove(path);
  rmdir(dir);
}

// a replayed session with a reset reproduces the original: the force model haptics read each tick, bit for bit
static void replay_honours_reset_lines(void** state) {
  (void)state;
  char a[] = "/tmp/tx_replay_a_XXXXXX", b[] = "/tmp/tx_replay_b_XXXXXX";
  assert_non_null(mkdtemp(a));
  assert_non_null(mkdtemp(b));
  session("scripted:pierce-down", a, true);
  char spec[64];
  snprintf(spec, sizeof spec, "replay:%s/device0.bin", a);
  session(spec, b, false);
  tx_record_file orig = load(a), again = load(b);
  assert_int_equal(again.count, orig.count);
  size_t drops = 0, differ = 0, at = 0;
  for (size_t k = 0; k < orig.count; k++) {
    bool same = memcmp(orig.records[k].force_model, again.records[k].force_model, sizeof orig.records[k].force_model) == 0;
    if (!same) differ++, at = k;
    drops += k && orig.records[k].force_model[1] < orig.records[k - 1].force_model[1];
  }
  assert_int_equal(drops, 1); // the original's reset is in the records: F0 fell once, at 0.3 s
  // every tick the same but the one at the reset's time, which still read the model from before it
  assert_true(differ <= 1);
  if (differ) assert_true(fabs(orig.records[at].t_s - 0.3) < 1e-9);
  // the replay logged its own reset, at the original's time
  char path[128], text[256] = "";
  snprintf(path, sizeof path, "%s/controls.csv", b);
  FILE* f = fopen(path, "r");
  assert_non_null(f);
  text[fread(text, 1, sizeof text - 1, f)] = 0;
  fclose(f);
  assert_non_null(strstr(text, "0.300000000,reset,0"));
  free(again.records);
  // without the reset lines the replay does not reproduce it
  snprintf(path, sizeof path, "%s/controls.csv", a);
  remove(path);
  clean(b);
  strcpy(b, "/tmp/tx_replay_b_XXXXXX");
  assert_non_null(mkdtemp(b));
  session(spec, b, false);
  again = load(b);
  differ = 0;
  for (size_t k = 0; k < orig.count && k < again.count; k++)
    differ += memcmp(orig.records[k].force_model, again.records[k].force_model, sizeof orig.records[k].force_model) != 0;
  assert_true(differ > 200);
  free(orig.records);
  free(again.records);
  clean(a);
  clean(b);
}

// a controls.csv that cannot be read as one is refused with its line, before the run
static void replay_refuses_bad_controls(void** state) {
  (void)state;
  char a[] = "/tmp/tx_replay_c_XXXXXX";
  assert_non_null(mkdtemp(a));
  session("scripted:pierce-down", a, false);
  char path[128], spec[64];
  snprintf(path, sizeof path, "%s/controls.csv", a);
  FILE* f = fopen(path, "w");
  fputs("t_s,action,value\n0.5,reset,0\n0.2,reset,0\n", f);
  fclose(f);
  snprintf(spec, sizeof spec, "replay:%s/device0.bin", a);
  char text[256];
  snprintf(text, sizeof text, "{\"device\":\"%s\",\"force_model\":\"tool0.force_model\"}", spec);
  const char* bad[][2] = {{"t_s,action,value\n0.5,reset,0\n0.2,reset,0\n", "controls.csv: line 3: a reset before the one above it"},
                          {"t_s,action,value\nsoon,reset,0\n", "controls.csv: line 2: expected t_s,action,value"}};
  for (int i = 0; i < 2; i++) {
    f = fopen(path, "w");
    fputs(bad[i][0], f);
    fclose(f);
    tx_system* s = tx_system_create();
    json_t* p = json_loads(text, 0, NULL);
    assert_int_equal(tx_system_add(s, "haptics", "haptics", 1000, p), -1);
    assert_non_null(strstr(tx_error(), bad[i][1]));
    json_decref(p);
    tx_system_destroy(s);
  }
  clean(a);
}

int main(void) {
  tx_register_controller(&accum_cls);
  tx_register_controller(&live_cls);
  tx_register_controller(&fragile_cls);
  tx_register_controller(&ramp_cls);
  tx_register_builtin(); // haptics and its replay device
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(lockstep_pause_step_reset),
      cmocka_unit_test(reset_before_run_is_the_start),
      cmocka_unit_test(time_scale_range),
      cmocka_unit_test(failed_rebuild_stops_the_run),
      cmocka_unit_test(tune_live_parameter),
      cmocka_unit_test(live_needs_tune),
      cmocka_unit_test(realtime_haptics_runs_through_a_pause),
      cmocka_unit_test(replay_honours_reset_lines),
      cmocka_unit_test(replay_refuses_bad_controls),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
