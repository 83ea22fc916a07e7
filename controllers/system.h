// Internal: a controller system, the instances of one scenario over one model.
//
// The loader adds instances (each is configured at once), finalize resolves
// reads and builds the model, run executes them in real time or lockstep,
// and the report reads the statistics back.
#ifndef TX_CONTROLLERS_SYSTEM_H
#define TX_CONTROLLERS_SYSTEM_H

#include <tactus/stats.h>

#include <tactus/controller.h>

#include <jansson.h>
#include <stdatomic.h>
#include <stdio.h>

#define TX_WARNINGS_MAX 256
// the run lengths the clocks hold (with TX_RATE_MIN_HZ, every tick fits in int64 ns)
#define TX_DURATION_MIN_S 1e-6
#define TX_DURATION_MAX_S 86400.0
// a lockstep trace (tx_run_options.trace) may grow to this; a longer run is refused before it starts
#define TX_TRACE_MAX_BYTES (1024.0 * 1024 * 1024)
#define TX_WARNING_KEY_MAX (2 * TX_NAME_MAX)

typedef struct tx_system tx_system;

typedef struct tx_port_info {
  bool write;
  const char* component;          // name
  const tx_component_def* def;    // schema, after finalize; NULL for an event stream
  int stream;                     // 0: a component; 1: emits the event stream; 2: listens to it
} tx_port_info;

#define TX_STREAM_INFO_READERS 16 // TX_STREAM_READERS_MAX, without tactus/events.h in every file

typedef struct tx_stream_info {
  const char* name;
  const char* writer;       // instance that emits it
  uint32_t capacity;        // events in its ring
  uint64_t sent;            // events emitted, dropped ones included
  uint64_t overflows;       // emits refused because a listener was a whole ring behind
  int nreaders;
  const char* readers[TX_STREAM_INFO_READERS]; // instances that listen
  uint64_t lost[TX_STREAM_INFO_READERS];       // events each listener missed
} tx_stream_info;

typedef struct tx_controller_stats {
  uint64_t steps;      // steps run
  uint64_t missed;     // deadlines missed, skipped ticks included
  double achieved_hz;  // (steps - 1) / (last start - first start)
  tx_percentiles jitter_ns; // |actual period - nominal period|
  tx_percentiles step_ns;   // step time, publishes included
} tx_controller_stats;

typedef struct tx_run_options {
  double duration_s;   // > 0
  bool lockstep;       // one thread, virtual clock
  FILE* trace;         // lockstep: one line per publish, or NULL; a write error stops the run
  const char* trace_name; // the trace's file, named in that error
  bool realtime_priority; // try SCHED_FIFO
  bool pin_threads;       // try CPU pinning
  bool keep_cpus_awake;   // a SCHED_IDLE spinner per CPU, so no CPU halts between ticks
  const char* record_dir; // folder for recordings (tx_record_dir), or NULL for none
  const char* out_dir;    // the run's output folder (views write frames there), or NULL
  // called about every 100 ms from the main thread; returning false stops the run
  bool (*progress)(double elapsed_s, void* user);
  void* progress_user;
} tx_run_options;

typedef struct tx_run_result {
  double duration_s;      // simulated (lockstep) or measured (real time)
  uint64_t trace_hash;    // lockstep: tx_hash of every publish, in order
  bool stopped_early;     // progress returned false
  char scheduler[256];    // how the threads were scheduled, and any fallback
  bool fifo;              // SCHED_FIFO was in effect on every thread
  bool pinned;            // every thread was pinned
  int awake_cpus;         // CPUs kept awake by spinners
  double steal_s;         // CPU time the hypervisor took during the run (all CPUs), -1 if unknown
  bool halted;            // a controller stopped the run (tx_stop_run)
  char halt_reason[512];  // "INSTANCE: reason", when halted
  double halt_t_s;        // simulation time of that request, s
} tx_run_result;

// "an object", "a string", ... for messages about a JSON value of the wrong type
const char* tx_json_kind(const json_t* v);

tx_system* tx_system_create(void);
void tx_system_destroy(tx_system* s); // runs fini for configured instances

// Errors: each call that can fail returns -1 with the message in tx_error()
// and the key it belongs to in tx_error_key() (model/error.h): for add and
// declare a key relative to the instance ("params.work_us", "rate_hz", ""
// for the instance as a whole), for finalize the name of the instance at fault.

// a component that no controller creates itself (from the scenario's "model")
int tx_system_declare(tx_system* s, const tx_component_def* def);
// add and configure one instance; params is borrowed and may be NULL
int tx_system_add(tx_system* s, const char* name, const char* type, double rate_hz, json_t* params);
// run instance i (the last added) on the scenario's thread NAME: 1-31
// characters of a-z 0-9 _ -, shared only by instances of the same rate, and
// never by a haptics instance; the error's key is "thread"
int tx_system_set_thread(tx_system* s, int i, const char* name);
// a class that always runs on a thread of its own (own_thread, or a "haptics" type)
bool tx_class_own_thread(const tx_controller_class* cls);
// resolve reads, check writers, build and commit the model; the error's key names the instance
int tx_system_finalize(tx_system* s);
// run; on failure (an init failed) returns -1 with the message in tx_error()
int tx_system_run(tx_system* s, const tx_run_options* o, tx_run_result* r);

// the registered classes in order of registration; NULL past the last
const tx_controller_class* tx_controller_class_at(int i);

// for built-in classes only: params.KEY as JSON (borrowed, marked as used), or NULL
json_t* tx_param_json(tx_setup* s, const char* key);
// a point params.KEY ([x, y, z], m, each within 10 m of the origin; a JSON
// entry of the table) into out, def when absent; -1 after tx_setup_fail
int tx_param_point(tx_setup* s, const char* key, const double def[3], double out[3]);
// tx_output_dir (tactus/controller.h) is the run's tx_run_options.out_dir

// Run control (system_control.c, docs/trainer.md), from any thread, before or
// during a run. Simulated instances (all but haptics and views) step on a
// simulation clock: pause stops it, resume restarts it, the time scale (real
// time only) slows it; haptics and views keep stepping at their full rate,
// haptics rendering the model as the pause left it. Each call that changes
// something is logged in RECORD_DIR/controls.csv during a recorded run; they
// return 0, or -1 with tx_error() when that line could not be written.
#define TX_TIME_SCALE_MIN 0.25
int tx_system_pause(tx_system* s);
int tx_system_resume(tx_system* s);
bool tx_system_paused(const tx_system* s);
// pause, and advance the clock to the next tick of the slowest simulated
// instance: every simulated instance runs each of its ticks up to that one
double tx_system_step_period(const tx_system* s); // s, 0 if nothing is simulated
int tx_system_step(tx_system* s);
// rebuild every simulated instance (fini, configure with its parameters,
// init) on its own thread before its next tick, what it writes restored as
// after its first init. The simulation clock goes on; paused stays paused.
int tx_system_reset(tx_system* s);
uint64_t tx_system_resets(const tx_system* s);      // asked for
uint64_t tx_system_resets_done(const tx_system* s); // carried out by every simulated instance
// x TX_TIME_SCALE_MIN to x1; -1 with tx_error() outside
int tx_system_set_time_scale(tx_system* s, double scale);
double tx_system_time_scale(const tx_system* s);
double tx_system_sim_time(const tx_system* s); // the simulation clock now, s
// Tune: a new value for a live parameter (tx_controller_class.live) of instance i,
// applied by the class's tune on the instance's thread before its next step
// and logged with the time then (tx_system_tune_at, report.json's "tuned").
// -1 with tx_error() for a key the table lacks, one not live, a value outside
// its range (or not whole for an integer, not 0 or 1 for a boolean), or more
// than TX_TUNES_PENDING waiting. A reset restores the scenario's value.
#define TX_TUNES_PENDING 32
#define TX_TUNES_MAX 256 // logged per run; later ones are applied, not logged
int tx_system_tune(tx_system* s, int i, const char* key, double value);
bool tx_param_live(const tx_controller_class* cls, const char* key); // in cls->live
// a parameter as text: a number as the docs write it (the shortest %g that
// reads back, no "+" or leading zeros in the exponent); the table's default
// (md: strings as Markdown code); the value the scenario gave (given: the
// instance's params, tx_system_params; a given text or JSON value longer than
// width cut to it with "...") or the default with "(default)" after it
const char* tx_param_num_text(double x, char* buf, size_t n);
const char* tx_param_default_text(const tx_param_def* d, bool md, char* buf, size_t n);
const char* tx_param_value_text(const tx_param_def* d, json_t* given, int width, char* buf, size_t n);
typedef struct tx_tune_info {
  double t_s;             // simulation time it took effect
  const char* controller; // instance
  const char* key;
  double value;
} tx_tune_info;
int tx_system_tunes(tx_system* s); // logged in the current or last run
tx_tune_info tx_system_tune_at(tx_system* s, int k);

// the system tx_system_run is running now (the last one started), or NULL: for a window's controls
tx_system* tx_system_running(void);
// live, while it runs, from any thread: steps, deadlines missed and the latest jitter of instance i
typedef struct tx_live_stats {
  uint64_t steps, missed;
  int64_t jitter_ns; // |actual - nominal period| of its thread's latest tick
} tx_live_stats;
tx_live_stats tx_system_live(const tx_system* s, int i);

// introspection, valid after finalize
int tx_system_count(const tx_system* s);
const char* tx_system_name(const tx_system* s, int i);
const tx_controller_class* tx_system_class(const tx_system* s, int i);
json_t* tx_system_params(const tx_system* s, int i); // as the scenario gave them (borrowed), may be NULL
double tx_system_rate(const tx_system* s, int i);
// real-time thread of instance i: haptics threads first, then the others fastest first
int tx_system_thread(const tx_system* s, int i);
int tx_system_threads(const tx_system* s);
const char* tx_system_thread_name(const tx_system* s, int t); // the scenario's name, or NULL
bool tx_system_thread_own(const tx_system* s, int t);         // a haptics thread, at the top priority
int tx_system_streams(const tx_system* s);                    // event streams
tx_stream_info tx_system_stream(const tx_system* s, int k);   // after a run: its counts
int tx_system_ports(const tx_system* s, int i);
tx_port_info tx_system_port(const tx_system* s, int i, int p);
tx_controller_stats tx_system_stats(const tx_system* s, int i);
tx_model* tx_system_model(tx_system* s);
// the most bytes a lockstep trace of a run this long can take (every write published every tick)
double tx_system_trace_bytes(const tx_system* s, double duration_s);
int tx_system_warnings(const tx_system* s);
const char* tx_system_warning_key(const tx_system* s, int w);
uint64_t tx_system_warning_count(const tx_system* s, int w);
int tx_system_results(const tx_system* s);
const char* tx_system_result_key(const tx_system* s, int k);
double tx_system_result(const tx_system* s, int k); // NaN if the run did not set it

#endif
