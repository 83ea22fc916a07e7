// Internal: the structures behind tx_system, shared by the executors.
#ifndef TX_CONTROLLERS_SYSTEM_INTERNAL_H
#define TX_CONTROLLERS_SYSTEM_INTERNAL_H

#include "system.h"

#include "../model/error.h"

#include <tactus/events.h>

#include <pthread.h>
#include <stdatomic.h>

_Static_assert(TX_STREAM_INFO_READERS == TX_STREAM_READERS_MAX, "tx_stream_info holds every reader");

#define TX_PORTS_MAX 64

typedef enum port_kind { PORT_COMPONENT, PORT_EMIT, PORT_LISTEN } port_kind;

typedef struct port {
  bool write;           // components only: an emit port is not a component write
  char name[TX_NAME_MAX];
  char units[TX_UNITS_MAX];
  tx_component_def def; // writes: the declared schema (name, units point above)
  tx_comp comp;         // after finalize
  tx_reader reader;     // reads: this instance's hazard slot
  tx_type want_type;    // reads: the element type needed, 0 for any
  uint32_t want_cols;   // reads: values per row needed, 0 for any
  char want_units[TX_UNITS_MAX]; // reads: units needed, "" for any
  bool dirty;           // written during the current step
  port_kind kind;       // a component, or an event stream emitted or listened to
  uint32_t capacity;    // emits: the ring's events
  int stream;           // streams: index in tx_system.streams, after finalize
  int listener;         // listens: this instance's reader of the stream
} port;

#define TX_THREAD_NAME_MAX 32 // a scenario's "thread": 1-31 characters of a-z 0-9 _ -

// one event stream of the system, made at finalize
typedef struct sys_stream {
  char name[TX_NAME_MAX];
  int writer;           // instance index
  uint32_t capacity;
  tx_stream* stream;
  int nreaders;
  int readers[TX_STREAM_READERS_MAX]; // instance index of each reader
} sys_stream;

typedef struct instance instance;

struct tx_setup {
  tx_system* sys;
  instance* in;
};

struct tx_ctx {
  tx_system* sys;
  instance* in;
  int64_t sim_ns;  // of the current step
  uint64_t step;   // index of the current step
};

struct instance {
  char name[TX_NAME_MAX];
  const tx_controller_class* cls;
  double rate_hz;
  json_t* params;      // own reference, may be NULL
  json_t* used;        // keys configure asked for
  json_t* strings;     // keeps tx_param_str* results alive
  // first configuration error (tx_setup_fail), kept apart from tx_error(),
  // which later library calls in configure may overwrite
  struct {
    char key[128];
    char message[1024];
  } fault;
  bool failed;
  void* self;
  bool configured;
  port ports[TX_PORTS_MAX];
  int nports;
  int group;          // rate group (lockstep order)
  int thread;         // real-time thread
  char thread_name[TX_THREAD_NAME_MAX]; // from the scenario, "" for none
  tx_setup setup;
  tx_ctx ctx;
  tx_warning bad_port, rows_clamped; // misuse of tx_write / tx_write_rows (context.c)
  tx_hist jitter, step_time; // whole-run statistics in fixed memory
  uint64_t steps, missed;
  int64_t first_start_ns, last_start_ns;
  // run control (system_control.c)
  bool live;          // haptics (own thread) and views: step through a pause, never rebuilt by a reset
  bool dead;          // a reset could not rebuild it: it steps no more
  uint64_t sim_tick;  // simulated instances: the next tick of the simulation clock to run
  int64_t live_ns;    // live instances: the time of their latest step
  uint64_t reset_seen; // the system's reset count this instance has taken up
  _Atomic uint64_t reset_done; // and carried out (rebuilt, restored, init run again)
  void* initial;      // the contents of what it writes, as after init (a reset restores them)
  uint32_t* initial_rows;
  _Atomic uint64_t live_steps, live_missed; // copies for other threads (tx_system_live)
  _Atomic int64_t live_jitter_ns;
  int index;                // in tx_system.inst
  _Atomic int tune_pending; // tunes waiting for it
};

typedef struct tune_entry {
  int inst, param;
  double value, t_s;
} tune_entry;

// The simulation clock behind pause, step and the time scale. `run_ns` is the
// executor's clock (wall time since the run's t0, or lockstep's virtual time);
// the simulation time at run_ns is anchor_sim, plus (run_ns - anchor_wall) x
// scale unless paused. Written under `mutex` by the control calls, read by
// the workers without a lock (a sequence lock: `version` is odd while written).
typedef struct tx_clock {
  pthread_mutex_t mutex;
  pthread_cond_t cond; // lockstep waits here while paused
  _Atomic uint64_t version;
  _Atomic int64_t anchor_wall, anchor_sim;
  _Atomic double scale;
  _Atomic bool paused;
  _Atomic int64_t t0;     // realtime: the run's t0 (monotonic ns); 0 outside a run
  _Atomic int64_t now;    // lockstep: the virtual time of the latest tick
  _Atomic bool lockstep;
  _Atomic bool running;   // between tx_control_start and tx_control_end
  _Atomic uint64_t resets; // resets asked for
  _Atomic uint64_t steps;  // single steps asked for
} tx_clock;

typedef struct tx_clock_state {
  int64_t anchor_wall, anchor_sim;
  double scale;
  bool paused;
} tx_clock_state;

typedef struct group {
  double rate_hz;
  int* members; // instance indices, in scenario order
  int count;
  bool own;     // threads: a haptics thread, at the top priority
  int rank;     // threads: 0 for the fastest rate among the threads that are not own
  const char* name; // threads: the scenario's name, or NULL
} group;

struct tx_system {
  instance** inst;
  int count;
  tx_component_def* declared; // from the scenario's "model"
  char (*declared_names)[TX_NAME_MAX];
  char (*declared_units)[TX_UNITS_MAX];
  int ndeclared;
  tx_model* model;
  group* groups; // instances of equal rate, fastest first: lockstep's order
  int ngroups;
  group* threads; // real-time threads: own threads first, then fastest first
  int nthreads;
  sys_stream* streams;
  int nstreams;
  char result_keys[TX_WARNINGS_MAX][TX_WARNING_KEY_MAX];
  double result_values[TX_WARNINGS_MAX]; // NaN until set
  int nresults;
  char warning_keys[TX_WARNINGS_MAX][TX_WARNING_KEY_MAX];
  _Atomic uint64_t warning_counts[TX_WARNINGS_MAX];
  int nwarnings;
  const char* record_dir; // of the current run, or NULL
  const char* out_dir;    // of the current run, or NULL
  bool tracing;        // lockstep: hash every publish
  FILE* trace;         // and write it here, if not NULL
  const char* trace_name; // that file, for a write error
  uint64_t trace_hash; // tx_hash over every publish, in order
  _Atomic int halt_claim;  // 0 until a controller asks to stop the run
  _Atomic bool halt;       // set once halt_reason is written
  char halt_reason[512];   // the first tx_stop_run reason
  int64_t halt_sim_ns;     // simulation time of that request
  tx_clock clock;          // pause, step, reset, time scale (system_control.c)
  uint64_t clock_resets_seen; // lockstep: the resets carried out
  tune_entry tunes_pending[TX_TUNES_PENDING]; // under clock.mutex
  int ntunes_pending;
  tune_entry tunes[TX_TUNES_MAX]; // applied, under clock.mutex
  int ntunes;
};

// true once a controller asked to stop the run (tx_stop_run)
static inline bool tx_system_halted(tx_system* s) { return atomic_load_explicit(&s->halt, memory_order_acquire); }

// nominal start of tick k of a group, ns from the run's start
int64_t tx_tick_ns(double rate_hz, uint64_t k);
// allocate the statistics of every instance for a run of this length
bool tx_system_prepare_stats(tx_system* s, double duration_s);
// run one instance's step at sim_ns and publish what it wrote; returns its duration
int64_t tx_instance_step(tx_system* s, instance* in, int64_t sim_ns);
// run init of one instance; 0 or -1 with err filled
int tx_instance_init(tx_system* s, instance* in); // -1 with tx_error()
// after the last step of a run
void tx_instance_finish(instance* in);

// run control (system_control.c)
void tx_clock_init(tx_clock* c);
void tx_clock_destroy(tx_clock* c);
tx_clock_state tx_clock_read(tx_clock* c);
// the simulation time at the executor's time run_ns
int64_t tx_clock_sim(const tx_clock_state* st, int64_t run_ns);
// before a run's first tick: mark live instances, set every clock anchor to 0
void tx_control_start(tx_system* s, bool lockstep);
void tx_control_end(tx_system* s);
// after init, on the instance's thread: keep what it wrote, for a reset; false: out of memory
bool tx_control_keep_initial(tx_system* s, instance* in);
// on the instance's thread, between its steps: carry out a reset asked for (rebuild the instance,
// restore what it writes, run init again); simulation time sim_ns
void tx_control_apply_reset(tx_system* s, instance* in, int64_t sim_ns);
// on the instance's thread, before a step: apply the tunes waiting for it (never blocks: a
// busy lock leaves them for the next tick)
void tx_control_apply_tunes(tx_system* s, instance* in, int64_t sim_ns);
// publish what an instance wrote (context.c)
void tx_instance_publish(tx_system* s, instance* in, int64_t sim_ns);

int tx_run_realtime(tx_system* s, const tx_run_options* o, tx_run_result* r);
int tx_run_lockstep(tx_system* s, const tx_run_options* o, tx_run_result* r);

#endif
