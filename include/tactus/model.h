// tactus/model.h: the shared model, a set of named, typed, double-buffered components.
//
// A component is a typed array (rows x cols) with a name and units, such as
// "skin.x" (N x 3 float, m). Each component has exactly one writer. The writer
// fills a back buffer and publishes it with one atomic swap; readers acquire
// the latest published buffer and may hold it until their next acquire.
// Nobody waits and no snapshot is ever torn: every reader owns a hazard slot,
// and the writer only reuses a buffer that is neither the latest nor held.
// A component with R readers therefore keeps R + 2 buffers.
//
//     tx_model* m = tx_model_create();
//     tx_comp x = tx_model_add(m, &(tx_component_def){"skin.x", TX_F32, 1764, 3, "m"});
//     tx_reader r = tx_model_add_reader(m, x);   // one per reading thread
//     tx_model_commit(m);                         // allocates; the schema is now fixed
//     float* back = tx_model_back(m, x);          // writer thread: fill ...
//     tx_model_publish(m, x, sim_ns);             // ... and swap
//     tx_snapshot s = tx_model_acquire(m, r);     // reader thread: s.data, s.seq
//
// Errors, here and in all of tactus: a function that can fail returns -1,
// NULL, false or an invalid id and leaves one line in this thread's
// tx_error(); it never prints and takes no message buffer.
#ifndef TACTUS_MODEL_H
#define TACTUS_MODEL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TX_NAME_MAX 64  // longest component or controller name, with its NUL
#define TX_UNITS_MAX 16 // longest units string, with its NUL
#define TX_READERS_MAX 62 // readers of one component
#define TX_COMPONENT_BYTES_MAX (256u << 20) // payload of one component
#define TX_MODEL_BYTES_MAX (1ull << 30)     // every buffer of a model together

typedef enum tx_type { TX_F32 = 1, TX_F64, TX_I32, TX_U32, TX_U8 } tx_type;

typedef struct tx_component_def {
  const char* name;  // unique, "[a-z0-9_.]+", e.g. "skin.x"
  tx_type type;      // element type
  uint32_t rows;     // rows of capacity, e.g. particles
  uint32_t cols;     // values per row, e.g. 3 for a position
  const char* units; // SI units, e.g. "m", "N", "K"; "1" if dimensionless
} tx_component_def;

typedef struct tx_model tx_model;
typedef struct tx_comp { uint32_t id; } tx_comp;     // 0 is invalid
typedef struct tx_reader { uint32_t id; } tx_reader; // 0 is invalid

typedef struct tx_snapshot {
  const void* data; // rows x cols elements of the component's type
  uint32_t rows;    // rows in use, <= capacity
  uint32_t cols;    // values per row
  uint64_t seq;     // publish number; 0 = never published (all zeros)
  int64_t sim_ns;   // simulation time of the publish, ns
  int64_t mono_ns;  // CLOCK_MONOTONIC at the publish, ns
} tx_snapshot;

// last error message of this thread ("" if none)
const char* tx_error(void);
// bytes of one element of a type; 0 for an unknown type
size_t tx_type_size(tx_type t);
// "f32", "f64", "i32", "u32", "u8"; NULL for an unknown type
const char* tx_type_name(tx_type t);
// the type named by tx_type_name's string, or 0
tx_type tx_type_from_name(const char* name);
// CLOCK_MONOTONIC, ns
int64_t tx_mono_ns(void);
// map a buffer's pages before a real-time loop uses it: writes one zero byte
// per page of p[0, n), so use it on memory that is still all zeros (fresh
// from calloc, or before it is filled). A page fault inside a 1 kHz step is a
// late tick; a buffer touched at init also keeps a long run's memory flat.
void tx_prefault(void* p, size_t n);
// 64-bit FNV-1a-style hash of n bytes by words, continuing from h (start with TX_HASH_SEED)
#define TX_HASH_SEED 1469598103934665603ull
uint64_t tx_hash(uint64_t h, const void* data, size_t n);

// building: single-threaded, before commit
tx_model* tx_model_create(void);
void tx_model_destroy(tx_model* m);
tx_comp tx_model_add(tx_model* m, const tx_component_def* def);
tx_comp tx_model_find(const tx_model* m, const char* name);
tx_reader tx_model_add_reader(tx_model* m, tx_comp c);
bool tx_model_commit(tx_model* m);

// description
uint32_t tx_model_count(const tx_model* m);
tx_comp tx_model_comp(const tx_model* m, uint32_t index); // index < count
const tx_component_def* tx_model_def(const tx_model* m, tx_comp c);
size_t tx_model_bytes(const tx_model* m, tx_comp c); // payload bytes at capacity

// writer side: one thread per component
void* tx_model_back(tx_model* m, tx_comp c);                 // stale contents
void* tx_model_back_copy(tx_model* m, tx_comp c);            // holds the latest publish
void tx_model_set_rows(tx_model* m, tx_comp c, uint32_t rows); // for the next publish
uint64_t tx_model_publish(tx_model* m, tx_comp c, int64_t sim_ns); // returns seq

// the latest publish's number and times, from any thread, with no reader
// slot: lock-free and read-only (the writer never waits; it reads no data).
// All zero before the first publish or for an invalid component.
typedef struct tx_stamp {
  uint64_t seq;    // publish number
  int64_t sim_ns;  // simulation time of the publish, ns
  int64_t mono_ns; // CLOCK_MONOTONIC at the publish, ns
} tx_stamp;
tx_stamp tx_model_stamp(const tx_model* m, tx_comp c);

// reader side: one thread per reader
tx_snapshot tx_model_acquire(tx_model* m, tx_reader r);
tx_snapshot tx_model_latest(tx_model* m, tx_comp c); // writer's own view, no slot needed
void tx_model_release(tx_model* m, tx_reader r);

// Publish hooks: a callback run by tx_model_publish, on the writer's thread,
// right after the new publish became the latest, so that a component can be
// sent on (net.dds) or acted on the moment it is published rather than at the
// next tick of whoever polls it. A hook must be short and must not block: it
// runs inside the writer's step (the haptic thread, for a force model); the
// bridge's hook only posts a semaphore. The table of hooks is fixed memory,
// made with the model (TX_PUBLISH_HOOKS_MAX per model, no allocation after);
// a hook is added before commit or after it, before its component's writer
// runs (a controller's init), and removed by whoever added it (fini). A
// publish finds its hooks lock-free: with none, one atomic load and a branch.
#define TX_PUBLISH_HOOKS_MAX 32
typedef void (*tx_publish_hook)(void* user, tx_comp c, uint64_t seq);
// a hook on c's publishes; returns its id (> 0), or 0 with tx_error() when the table is full
int tx_model_add_hook(tx_model* m, tx_comp c, tx_publish_hook fn, void* user);
// remove a hook; returns once no publish is still running it, so user may be freed after
void tx_model_remove_hook(tx_model* m, int id);

#ifdef __cplusplus
}
#endif
#endif
