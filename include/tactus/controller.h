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
// waits. Parameter errors are sticky: tx_param_* return the default after the
// first error, and the loader reports "params.KEY: message" for the first one.
// A parameter in the scenario that configure never asked for is an error too.
//
//     static int configure(tx_setup* s, void** self) {
//       counter* c = calloc(1, sizeof *c);
//       c->gain = tx_param_num(s, "gain", 1.0, 0.0, 10.0);
//       c->out = tx_setup_write(s, &(tx_component_def){"demo.count", TX_F64, 1, 1, "1"});
//       *self = c;
//       return 0;
//     }
//
// Plugins: a shared library named in a scenario's "plugins" exports
// TX_PLUGIN_ENTRY, which calls tx_register_controller for each class.
#ifndef TACTUS_CONTROLLER_H
#define TACTUS_CONTROLLER_H

#include <tactus/model.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TX_API_VERSION 1
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

typedef struct tx_controller_class {
  const char* type;    // registry name, e.g. "rates.synthetic"
  const char* summary; // one line for `tactus describe`
  int (*configure)(tx_setup* s, void** self); // 0 on success
  int (*init)(tx_ctx* c, void* self);         // optional; 0 on success
  void (*step)(tx_ctx* c, void* self);
  void (*fini)(void* self);                   // optional
  void (*finish)(tx_ctx* c, void* self);      // optional
  // a view only reads the model (plots, graphics, recordings): the loader
  // refuses a view that declares a write with tx_setup_write
  bool view;
} tx_controller_class;

// registry; returns 0, or -1 for a bad class or a taken type name
int tx_register_controller(const tx_controller_class* cls);
const tx_controller_class* tx_find_controller(const char* type);

// configure: identity
const char* tx_setup_name(const tx_setup* s); // instance name from the scenario
double tx_setup_rate(const tx_setup* s);      // Hz

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

// configure: parameters. Range checks are inclusive.
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
int64_t tx_sim_ns(const tx_ctx* c);                  // simulation time of this step, ns
uint64_t tx_step_index(const tx_ctx* c);             // 0 for the first step
double tx_rate(const tx_ctx* c);                     // Hz
void tx_warn(tx_ctx* c, tx_warning w);               // count one occurrence, lock-free
const char* tx_record_dir(const tx_ctx* c);          // where this run keeps recordings, or NULL
const char* tx_output_dir(const tx_ctx* c);          // where this run writes its outputs (frames, plots), or NULL
void tx_set_result(tx_ctx* c, tx_result r, double value); // the last value set is reported (set it in finish)
// end the run at once for a fault the controller cannot recover from (a full
// disk, a lost file); every thread stops at its next tick, finish still runs,
// and the report names the first reason given. Lock-free; callable from any thread.
void tx_stop_run(tx_ctx* c, const char* reason);

#ifdef __cplusplus
}
#endif
#endif
