// tactus/controller.h: controllers, the only things that change the model.
//
// A controller class is a set of callbacks registered under a type name. A
// scenario makes instances of it, each with a name, a rate and parameters.
//
//   configure  reads its parameters and declares what it writes and reads;
//              it runs once, on the loading thread, before the model exists
//   init       runs once, on the controller's own thread, before the first step
//   step       runs at the controller's rate; what it wrote with tx_write() is
//              published when step returns (the "swap buffer" step)
//   finish     optional: runs once after a run's last step, on the same thread;
//              it may block (flush a recording), the run is over
//   fini       frees what configure and init made
//
// A class with .view = true is a view: it reads the model and never writes
// it. The loader refuses a view that declares a write, naming the controller.
//
// No step may allocate, lock or block: the haptic thread shares nothing that
// waits. Parameters are declared in the class's table (key, kind, units,
// range, default, meaning); configure reads them with tx_table_*, which take
// the default and range from the table, so `tactus describe` and the docs
// list them without running configure. Parameter errors are sticky: the
// readers return the default after the first error, and the loader reports
// "params.KEY: message" for the first one. A parameter in the scenario that
// the table lacks is an error too, naming the valid keys.
//
//     static const tx_param_def params[] = {
//       {"gain", TX_PARAM_NUM, "1", 0.0, 10.0, 1.0, NULL, "counts this much per step"},
//     };
//     static int configure(tx_setup* s, void** self) {
//       counter* c = calloc(1, sizeof *c);
//       c->gain = tx_table_num(s, "gain");
//       c->out = tx_setup_write(s, &(tx_component_def){"demo.count", TX_F64, 1, 1, "1"});
//       *self = c;
//       return 0;
//     }
//     const tx_controller_class demo = {.type = "demo.counter", .configure = configure, .step = step,
//                                       .params = params, .nparams = TX_PARAMS_COUNT(params)};
//
// Errors: a controller never prints. configure fails with tx_setup_fail (the
// loader names the file and key, exit 2); at run time tx_warn counts what was
// recovered, and tx_stop_run ends the run for what cannot be (in init the run
// fails with that reason; in a step or finish the report is still written and
// the run exits 1 naming it). The library calls below return -1, NULL or an
// invalid id with one line in tx_error() (tactus/model.h).
//
// Plugins: a shared library named in a scenario's "plugins" exports
// TX_PLUGIN_ENTRY, which calls tx_register_controller for each class.
#ifndef TACTUS_CONTROLLER_H
#define TACTUS_CONTROLLER_H

#include <tactus/model.h>

#ifdef __cplusplus
extern "C" {
#endif

// 2: tx_controller_class gained its parameter table (params, nparams) and
// own_thread, so a
// plugin built against version 1 would be read past its end: it must refuse
// 3: tx_stop_run takes a printf format
#define TX_API_VERSION 3
#define TX_RATE_MAX_HZ 100000.0 // no controller runs faster
// no controller runs slower: one period is 1000 s, so every tick of the longest
// run (86400 s) is a few 1e13 ns, far inside the int64 ns of the clocks
#define TX_RATE_MIN_HZ 0.001
#define TX_PLUGIN_ENTRY tx_plugin_register // int tx_plugin_register(int api_version)

typedef struct tx_setup tx_setup; // configure-time view of one instance
typedef struct tx_ctx tx_ctx;     // run-time view of one instance
typedef struct tx_port { uint16_t id; } tx_port;       // a declared read or write; 0 is invalid
typedef struct tx_warning { uint16_t id; } tx_warning; // a counted warning; 0 is invalid
typedef struct tx_result { uint16_t id; } tx_result;   // a number the run reports; 0 is invalid
struct tx_event; // tactus/events.h, which a controller that sends or takes events includes

// One parameter of a controller class. Ranges are inclusive. A number whose
// default configure works out (from the device, say) gives def_str as the text
// that describes it and reads as NaN when the scenario leaves it out.
typedef enum tx_param_kind {
  TX_PARAM_NUM = 1, // double, in [min, max]
  TX_PARAM_INT,     // integer, in [min, max]
  TX_PARAM_BOOL,    // true or false; def_num 0 or 1
  TX_PARAM_STR,     // a string; def_str (NULL: none)
  TX_PARAM_STRS,    // a list of at most max strings; empty by default
  TX_PARAM_JSON,    // any JSON, read by built-in classes (tx_param_json)
} tx_param_kind;

typedef struct tx_param_def {
  const char* key;     // as in the scenario's "params"
  tx_param_kind kind;
  const char* units;   // e.g. "N/m", "1" for none; NULL for strings and booleans
  double min, max;     // NUM and INT: the range; STRS: max is the most entries
  double def_num;      // NUM, INT, BOOL: the default
  const char* def_str; // STR: the default (NULL: none); NUM: text for a computed default
  const char* meaning; // one line for `tactus describe` and the docs
} tx_param_def;

#define TX_PARAMS_COUNT(table) ((int)(sizeof(table) / sizeof((table)[0])))

typedef struct tx_controller_class {
  const char* type;    // registry name, e.g. "rates.synthetic"
  const char* summary; // one line for `tactus describe`
  int (*configure)(tx_setup* s, void** self); // 0 on success
  int (*init)(tx_ctx* c, void* self);         // optional; 0 on success
  void (*step)(tx_ctx* c, void* self);
  void (*fini)(void* self);                   // optional
  void (*finish)(tx_ctx* c, void* self);      // optional
  // the parameter table; a class without one (NULL) reads with tx_param_*
  // alone, and `tactus describe` says it has no parameter table
  const tx_param_def* params;
  int nparams;
  // runs on a thread of its own at the top priority, whatever the rates of the
  // others (a device loop: no other step may delay it). Classes whose type
  // starts with "haptics" always do.
  bool own_thread;
  // a view only reads the model (plots, graphics, recordings): the loader
  // refuses a view that declares a write with tx_setup_write
  bool view;
  // the table's keys that may change while the run goes (numbers, integers,
  // booleans), NULL-terminated, or NULL for none; tune applies a new value
  // (within the table's range) on the instance's own thread between two steps
  const char* const* live;
  void (*tune)(tx_ctx* c, void* self, const char* key, double value);
} tx_controller_class;

// registry; returns 0, or -1 for a bad class (a bad parameter table
// included: see tx_error()) or a taken type name
int tx_register_controller(const tx_controller_class* cls);
const tx_controller_class* tx_find_controller(const char* type);

// configure: identity
const char* tx_setup_name(const tx_setup* s); // instance name from the scenario
double tx_setup_rate(const tx_setup* s);      // Hz
// the rate when it is in lo..hi Hz; otherwise fails configure ("TYPE runs at LO to HI Hz, not R") and returns 0
double tx_setup_rate_in(tx_setup* s, double lo, double hi);

// configure: model access. A written component is created with def's schema
// (def->name may be freed after the call). A read resolves once every
// instance is configured.
tx_port tx_setup_write(tx_setup* s, const tx_component_def* def);
tx_port tx_setup_read(tx_setup* s, const char* component);
// a read that needs this element type and this many values per row (0: any);
// the loader rejects a writer of another schema
tx_port tx_setup_read_as(tx_setup* s, const char* component, tx_type type, uint32_t cols);
// the same, and in these units (as the writer spells them, e.g. "N, m, N/m";
// NULL for any): the loader rejects a writer of other units, naming both
tx_port tx_setup_read_expect(tx_setup* s, const char* component, tx_type type, uint32_t cols, const char* units);
tx_warning tx_setup_warning(tx_setup* s, const char* key); // reported as "INSTANCE.key"
tx_result tx_setup_result(tx_setup* s, const char* key);   // reported as "INSTANCE.key"; put the units in the key

// configure: event streams (tactus/events.h), for what must not be lost
// between rates. A stream has one writer, which declares it with its capacity
// (a power of two in [2, TX_STREAM_CAPACITY_MAX]); any number of instances
// (at most TX_STREAM_READERS_MAX) listen, each seeing every event once and in
// order. The loader rejects two writers, or a listen that no one emits.
tx_port tx_setup_emit(tx_setup* s, const char* stream, uint32_t capacity);
tx_port tx_setup_listen(tx_setup* s, const char* stream);

// configure: parameters through the class's table: the default and range come
// from there. Asking for a key the table lacks, or as another kind, is a
// programming error reported at configure. tx_table_strs fills at most
// the table's max entries of out.
double tx_table_num(tx_setup* s, const char* key);
int64_t tx_table_int(tx_setup* s, const char* key);
bool tx_table_bool(tx_setup* s, const char* key);
const char* tx_table_str(tx_setup* s, const char* key); // valid until fini
int tx_table_strs(tx_setup* s, const char* key, const char** out, int max);
// the entry for key in this class's table, or NULL
const tx_param_def* tx_param_find(const tx_controller_class* cls, const char* key);

// configure: parameters without a table (older classes). Range checks are
// inclusive. In a class with a table the key must be there, and the default
// and range given here must equal the table's.
double tx_param_num(tx_setup* s, const char* key, double def, double min, double max);
int64_t tx_param_int(tx_setup* s, const char* key, int64_t def, int64_t min, int64_t max);
bool tx_param_bool(tx_setup* s, const char* key, bool def);
const char* tx_param_str(tx_setup* s, const char* key, const char* def); // valid until fini
// a list of strings; returns how many (<= max) and fills out (valid until fini)
int tx_param_strs(tx_setup* s, const char* key, const char** out, int max);
// a parameter of any kind (an object, a list, ...) as compact JSON text, for a
// controller that parses a structured parameter itself; valid until fini;
// NULL when absent (or after an error)
const char* tx_param_json_text(tx_setup* s, const char* key);
// flag an error at params.KEY (or at the instance when key is NULL); returns -1
int tx_setup_fail(tx_setup* s, const char* key, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

// run time, from init and step
tx_snapshot tx_read(tx_ctx* c, tx_port p);           // latest publish; held until the next tx_read
// tx_write and tx_write_copy return NULL for a port this instance did not
// declare with tx_setup_write; tx_write_rows keeps at most the declared rows.
// Either misuse counts the warning "INSTANCE.bad_port" or
// "INSTANCE.rows_clamped" and stops the run, naming the instance and the port.
void* tx_write(tx_ctx* c, tx_port p);                // back buffer, published after step
void* tx_write_copy(tx_ctx* c, tx_port p);           // same, starting from the latest publish
void tx_write_rows(tx_ctx* c, tx_port p, uint32_t rows); // rows in use for this publish
// the schema (name, element type, rows, cols, units) of a component this
// instance declared, a read or a write, for one that reads any type (a
// probe); NULL for a port it did not declare
const tx_component_def* tx_port_schema(tx_ctx* c, tx_port p);
int64_t tx_sim_ns(const tx_ctx* c);                  // simulation time of this step, ns
uint64_t tx_step_index(const tx_ctx* c);             // 0 for the first step
double tx_rate(const tx_ctx* c);                     // Hz
void tx_warn(tx_ctx* c, tx_warning w);               // count one occurrence, lock-free
const char* tx_record_dir(const tx_ctx* c);          // where this run keeps recordings, or NULL
const char* tx_output_dir(const tx_ctx* c);          // where this run writes its outputs (frames, plots), or NULL
void tx_set_result(tx_ctx* c, tx_result r, double value); // the last value set is reported (set it in finish)
// end the run at once for a fault the controller cannot recover from (a full
// disk, a lost file); every thread stops at its next tick, finish still runs,
// and the report names the first reason given, printf-style ("%s: cannot be
// written", path). Lock-free, no allocation; callable from any thread and from
// init (the run then fails with this reason) or finish (the run still ends
// with its report, and exits 1 naming the reason).
void tx_stop_run(tx_ctx* c, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
// send an event (its seq and sim_ns are set here); returns its seq, or 0 when
// the slowest listener is a whole ring behind: then it is dropped and counted
// in the report. Lock-free, no allocation: safe at 1 kHz.
uint64_t tx_emit(tx_ctx* c, tx_port p, const struct tx_event* e);
// take the next event of a listened stream; false when there is none
bool tx_next_event(tx_ctx* c, tx_port p, struct tx_event* out);

#ifdef __cplusplus
}
#endif
#endif
