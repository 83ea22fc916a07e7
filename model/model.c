// The shared model: components with one writer and hazard-slot buffers.
//
// Each component keeps readers + 2 buffers. `latest` names the newest publish.
// A reader announces the buffer it is about to read in its hazard slot and
// re-checks `latest`; the writer, after moving `latest` to its back buffer,
// takes as its next back buffer one that is neither latest nor announced.
// With sequentially consistent atomics this is the classic hazard-pointer
// argument: a buffer is never written while a reader may read it.
//
// Publish hooks (tx_model_add_hook) live in a fixed table in the model. A
// component's hook_mask names the slots to call; a call counts itself in its
// slot's `busy` before it checks `armed`, and removal clears `armed` before it
// waits for `busy` to drain: with sequentially consistent atomics either the
// call sees the hook disarmed, or the removal sees the call and waits for it.
#include "error.h"

#include <tactus/model.h>

#include <ctype.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define NO_BUFFER UINT32_MAX
#define CACHE_LINE 64

typedef struct header { // at the start of every buffer
  uint64_t seq;         // publish number
  int64_t sim_ns;       // simulation time, ns
  int64_t mono_ns;      // monotonic time, ns
  uint32_t rows;        // rows in use
} header;

typedef struct hazard { // one per reader, alone on its cache line
  _Alignas(CACHE_LINE) _Atomic uint32_t buffer;
} hazard;

typedef struct component {
  tx_component_def def;          // name and units point into the strings below
  char name[TX_NAME_MAX];
  char units[TX_UNITS_MAX];
  size_t bytes;                  // payload bytes at capacity
  size_t stride;                 // bytes per buffer, header included
  uint32_t readers;              // hazard slots
  uint32_t buffers;              // readers + 2
  unsigned char* memory;         // buffers x stride, cache-line aligned
  void* allocation;              // what memory was carved from
  hazard* hazards;               // readers
  _Alignas(CACHE_LINE) _Atomic uint32_t latest;
  _Alignas(CACHE_LINE) uint32_t back; // writer-private from here on
  uint32_t next_rows;
  uint64_t seq;
  _Atomic uint32_t hook_mask;    // publish hooks to call: bit i is hooks[i]
  // tx_model_stamp's copy of the latest header: a sequence lock, odd while the writer changes it
  _Alignas(CACHE_LINE) _Atomic uint64_t stamp_version;
  _Atomic uint64_t stamp_seq;
  _Atomic int64_t stamp_sim_ns, stamp_mono_ns;
} component;

_Static_assert(TX_PUBLISH_HOOKS_MAX <= 32, "a component's hook mask is 32 bits");

typedef struct hook {
  tx_publish_hook fn; // written before armed is set, read after it is seen
  void* user;
  _Atomic uint32_t comp; // the component id it was added for
  _Atomic bool armed;
  _Atomic uint32_t busy; // calls under way
  bool used;             // under hook_lock
} hook;

typedef struct reader_slot {
  uint32_t comp;  // component index
  uint32_t slot;  // hazard index within it
} reader_slot;

struct tx_model {
  component** comps; // count
  uint32_t count;
  reader_slot* readers; // reader_count
  uint32_t reader_count;
  bool committed;
  atomic_flag hook_lock; // adding and removing hooks; never taken by a publish
  hook hooks[TX_PUBLISH_HOOKS_MAX];
};

static size_t header_size(void) { return (sizeof(header) + CACHE_LINE - 1) / CACHE_LINE * CACHE_LINE; }

size_t tx_type_size(tx_type t) {
  switch (t) {
  case TX_F32: case TX_I32: case TX_U32: return 4;
  case TX_F64: return 8;
  case TX_U8: return 1;
  }
  return 0;
}

static const char* const type_names[] = {NULL, "f32", "f64", "i32", "u32", "u8"};

const char* tx_type_name(tx_type t) {
  return (t >= TX_F32 && t <= TX_U8) ? type_names[t] : NULL;
}

tx_type tx_type_from_name(const char* name) {
  for (int t = TX_F32; name && t <= TX_U8; t++)
    if (strcmp(name, type_names[t]) == 0) return (tx_type)t;
  return (tx_type)0;
}

static bool valid_name(const char* s) {
  if (!s || !*s || strlen(s) >= TX_NAME_MAX) return false;
  for (; *s; s++)
    if (!(islower((unsigned char)*s) || isdigit((unsigned char)*s) || *s == '_' || *s == '.')) return false;
  return true;
}

tx_model* tx_model_create(void) {
  tx_model* m = calloc(1, sizeof(tx_model));
  if (m) atomic_flag_clear(&m->hook_lock);
  return m;
}

void tx_model_destroy(tx_model* m) {
  if (!m) return;
  for (uint32_t i = 0; i < m->count; i++) {
    free(m->comps[i]->allocation);
    free(m->comps[i]->hazards);
    free(m->comps[i]);
  }
  free(m->comps);
  free(m->readers);
  free(m);
}

static component* get(const tx_model* m, tx_comp c) {
  return (m && c.id >= 1 && c.id <= m->count) ? m->comps[c.id - 1] : NULL;
}

tx_comp tx_model_find(const tx_model* m, const char* name) {
  for (uint32_t i = 0; m && name && i < m->count; i++)
    if (strcmp(m->comps[i]->name, name) == 0) return (tx_comp){i + 1};
  return (tx_comp){0};
}

tx_comp tx_model_add(tx_model* m, const tx_component_def* def) {
  const tx_comp none = {0};
  if (!m || !def) return tx_set_error("no model or definition"), none;
  if (m->committed) return tx_set_error("%s: the model is already committed", def->name ? def->name : "?"), none;
  if (!valid_name(def->name))
    return tx_set_error("component name '%s' must be 1-%d characters of a-z 0-9 _ .", def->name ? def->name : "",
                        TX_NAME_MAX - 1), none;
  if (tx_model_find(m, def->name).id) return tx_set_error("%s: component already exists", def->name), none;
  if (!tx_type_size(def->type)) return tx_set_error("%s: unknown element type %d", def->name, (int)def->type), none;
  if (def->rows == 0 || def->cols == 0) return tx_set_error("%s: rows and cols must be at least 1", def->name), none;
  uint64_t bytes = (uint64_t)def->rows * def->cols * tx_type_size(def->type);
  if (bytes > TX_COMPONENT_BYTES_MAX)
    return tx_set_error("%s: %ux%u %s is %llu MiB, more than the %u MiB a component may hold", def->name, def->rows,
                        def->cols, tx_type_name(def->type), (unsigned long long)(bytes >> 20), TX_COMPONENT_BYTES_MAX >> 20), none;
  const char* units = def->units ? def->units : "1";
  if (strlen(units) >= TX_UNITS_MAX) return tx_set_error("%s: units '%s' too long", def->name, units), none;

  component** grown = realloc(m->comps, (m->count + 1) * sizeof *grown);
  component* c = aligned_alloc(CACHE_LINE, sizeof *c); // it holds cache-line aligned atomics
  if (c) memset(c, 0, sizeof *c);
  if (!grown || !c) {
    if (grown) m->comps = grown;
    free(c);
    return tx_set_error("%s: out of memory", def->name), none;
  }
  m->comps = grown;
  strcpy(c->name, def->name);
  strcpy(c->units, units);
  c->def = *def;
  c->def.name = c->name;
  c->def.units = c->units;
  c->bytes = (size_t)bytes;
  m->comps[m->count++] = c;
  return (tx_comp){m->count};
}

tx_reader tx_model_add_reader(tx_model* m, tx_comp id) {
  component* c = get(m, id);
  if (!c) return tx_set_error("no such component"), (tx_reader){0};
  if (m->committed) return tx_set_error("%s: the model is already committed", c->name), (tx_reader){0};
  if (c->readers == TX_READERS_MAX) return tx_set_error("%s: more than %d readers", c->name, TX_READERS_MAX), (tx_reader){0};
  reader_slot* grown = realloc(m->readers, (m->reader_count + 1) * sizeof *grown);
  if (!grown) return tx_set_error("%s: out of memory", c->name), (tx_reader){0};
  m->readers = grown;
  m->readers[m->reader_count++] = (reader_slot){id.id - 1, c->readers++};
  return (tx_reader){m->reader_count};
}

static header* buffer_header(const component* c, uint32_t b) { return (header*)(c->memory + (size_t)b * c->stride); }
static void* buffer_data(const component* c, uint32_t b) { return c->memory + (size_t)b * c->stride + header_size(); }

bool tx_model_commit(tx_model* m) {
  if (!m) return tx_set_error("no model"), false;
  if (m->committed) return true;
  uint64_t total = 0;
  for (uint32_t i = 0; i < m->count; i++) {
    component* c = m->comps[i];
    c->buffers = c->readers + 2;
    c->stride = header_size() + (c->bytes + CACHE_LINE - 1) / CACHE_LINE * CACHE_LINE;
    total += (uint64_t)c->stride * c->buffers;
  }
  if (total > TX_MODEL_BYTES_MAX)
    return tx_set_error("the model's buffers would take %llu MiB, more than %llu MiB", (unsigned long long)(total >> 20),
                        (unsigned long long)(TX_MODEL_BYTES_MAX >> 20)), false;
  for (uint32_t i = 0; i < m->count; i++) {
    component* c = m->comps[i];
    // calloc leaves large zeroed blocks untouched until used; align by hand
    c->allocation = calloc(1, c->stride * c->buffers + CACHE_LINE);
    c->memory = (unsigned char*)(((uintptr_t)c->allocation + CACHE_LINE - 1) / CACHE_LINE * CACHE_LINE);
    c->hazards = c->readers ? aligned_alloc(CACHE_LINE, sizeof(hazard) * c->readers) : NULL;
    if (!c->allocation || (c->readers && !c->hazards)) return tx_set_error("%s: out of memory", c->name), false;
    for (uint32_t r = 0; r < c->readers; r++) atomic_init(&c->hazards[r].buffer, NO_BUFFER);
    for (uint32_t b = 0; b < c->buffers; b++) buffer_header(c, b)->rows = c->def.rows;
    atomic_init(&c->latest, 0);
    c->back = 1;
    c->next_rows = c->def.rows;
  }
  m->committed = true;
  return true;
}

uint32_t tx_model_count(const tx_model* m) { return m ? m->count : 0; }
tx_comp tx_model_comp(const tx_model* m, uint32_t index) {
  return (m && index < m->count) ? (tx_comp){index + 1} : (tx_comp){0};
}
const tx_component_def* tx_model_def(const tx_model* m, tx_comp id) {
  component* c = get(m, id);
  return c ? &c->def : NULL;
}
size_t tx_model_bytes(const tx_model* m, tx_comp id) {
  component* c = get(m, id);
  return c ? c->bytes : 0;
}

void* tx_model_back(tx_model* m, tx_comp id) {
  component* c = get(m, id);
  return c && c->memory ? buffer_data(c, c->back) : NULL;
}

void* tx_model_back_copy(tx_model* m, tx_comp id) {
  component* c = get(m, id);
  if (!c || !c->memory) return NULL;
  // only this thread moves `latest`, and it never writes the latest buffer
  uint32_t latest = atomic_load_explicit(&c->latest, memory_order_relaxed);
  memcpy(buffer_data(c, c->back), buffer_data(c, latest), c->bytes);
  c->next_rows = buffer_header(c, latest)->rows;
  return buffer_data(c, c->back);
}

void tx_model_set_rows(tx_model* m, tx_comp id, uint32_t rows) {
  component* c = get(m, id);
  if (c) c->next_rows = rows < c->def.rows ? rows : c->def.rows;
}

uint64_t tx_model_publish(tx_model* m, tx_comp id, int64_t sim_ns) {
  component* c = get(m, id);
  if (!c || !c->memory) return 0;
  header* h = buffer_header(c, c->back);
  *h = (header){++c->seq, sim_ns, tx_mono_ns(), c->next_rows};
  uint32_t published = c->back;
  atomic_store(&c->latest, published);
  uint64_t v = atomic_load_explicit(&c->stamp_version, memory_order_relaxed);
  atomic_store_explicit(&c->stamp_version, v + 1, memory_order_relaxed);
  atomic_thread_fence(memory_order_release); // the odd version is seen before any field changes
  atomic_store_explicit(&c->stamp_seq, h->seq, memory_order_relaxed);
  atomic_store_explicit(&c->stamp_sim_ns, h->sim_ns, memory_order_relaxed);
  atomic_store_explicit(&c->stamp_mono_ns, h->mono_ns, memory_order_relaxed);
  atomic_store_explicit(&c->stamp_version, v + 2, memory_order_release);
  // next back buffer: neither latest nor announced by a reader. Each hazard is
  // read once: re-reading per candidate would let one reader that moves its
  // slot during the scan block several buffers, and leave none free.
  // With R readers, R + 2 buffers and one value per slot, one is always free.
  bool held[TX_READERS_MAX + 2] = {false};
  for (uint32_t r = 0; r < c->readers; r++) {
    uint32_t b = atomic_load(&c->hazards[r].buffer);
    if (b < c->buffers) held[b] = true;
  }
  held[published] = true;
  uint32_t b = 0;
  while (held[b]) b++;
  c->back = b;
  uint64_t seq = c->seq;
  for (uint32_t mask = atomic_load_explicit(&c->hook_mask, memory_order_acquire); mask; mask &= mask - 1) {
    hook* k = &m->hooks[__builtin_ctz(mask)];
    atomic_fetch_add(&k->busy, 1);
    // a mask read before a removal may name a slot since given to another component
    if (atomic_load(&k->armed) && atomic_load_explicit(&k->comp, memory_order_relaxed) == id.id) k->fn(k->user, id, seq);
    atomic_fetch_sub_explicit(&k->busy, 1, memory_order_release);
  }
  return seq;
}

static void hook_lock(tx_model* m) {
  while (atomic_flag_test_and_set_explicit(&m->hook_lock, memory_order_acquire)) sched_yield();
}
static void hook_unlock(tx_model* m) { atomic_flag_clear_explicit(&m->hook_lock, memory_order_release); }

int tx_model_add_hook(tx_model* m, tx_comp id, tx_publish_hook fn, void* user) {
  component* c = get(m, id);
  if (!c || !fn) return tx_set_error("a publish hook needs a component and a function"), 0;
  hook_lock(m);
  int i = 0;
  while (i < TX_PUBLISH_HOOKS_MAX && m->hooks[i].used) i++;
  if (i == TX_PUBLISH_HOOKS_MAX) {
    hook_unlock(m);
    return tx_set_error("%s: more than %d publish hooks in one model", c->name, TX_PUBLISH_HOOKS_MAX), 0;
  }
  hook* h = &m->hooks[i];
  h->used = true;
  h->fn = fn;
  h->user = user;
  atomic_store(&h->comp, id.id);
  atomic_store(&h->armed, true);
  atomic_fetch_or(&c->hook_mask, 1u << i);
  hook_unlock(m);
  return i + 1;
}

void tx_model_remove_hook(tx_model* m, int id) {
  if (!m || id < 1 || id > TX_PUBLISH_HOOKS_MAX) return;
  hook* h = &m->hooks[id - 1];
  hook_lock(m);
  if (!h->used) return hook_unlock(m);
  component* c = get(m, (tx_comp){atomic_load(&h->comp)});
  if (c) atomic_fetch_and(&c->hook_mask, ~(1u << (id - 1)));
  atomic_store(&h->armed, false);
  while (atomic_load(&h->busy)) sched_yield(); // a call under way ends first
  h->used = false;
  hook_unlock(m);
}

static tx_snapshot snapshot_of(const component* c, uint32_t b) {
  const header* h = buffer_header(c, b);
  return (tx_snapshot){buffer_data(c, b), h->rows, c->def.cols, h->seq, h->sim_ns, h->mono_ns};
}

tx_stamp tx_model_stamp(const tx_model* m, tx_comp id) {
  component* w = get(m, id); // its stamp atomics are only loaded here
  if (!w) return (tx_stamp){0};
  for (;;) { // retried only while a publish is between its two version stores
    uint64_t v = atomic_load_explicit(&w->stamp_version, memory_order_acquire);
    tx_stamp t = {atomic_load_explicit(&w->stamp_seq, memory_order_relaxed),
                  atomic_load_explicit(&w->stamp_sim_ns, memory_order_relaxed),
                  atomic_load_explicit(&w->stamp_mono_ns, memory_order_relaxed)};
    atomic_thread_fence(memory_order_acquire); // the fields are read before the version again
    if (!(v & 1) && atomic_load_explicit(&w->stamp_version, memory_order_relaxed) == v) return t;
  }
}

tx_snapshot tx_model_acquire(tx_model* m, tx_reader r) {
  if (!m || r.id < 1 || r.id > m->reader_count || !m->committed) return (tx_snapshot){0};
  component* c = m->comps[m->readers[r.id - 1].comp];
  _Atomic uint32_t* slot = &c->hazards[m->readers[r.id - 1].slot].buffer;
  uint32_t b = atomic_load(&c->latest);
  for (;;) { // announce, then confirm it is still the latest
    atomic_store(slot, b);
    uint32_t again = atomic_load(&c->latest);
    if (again == b) break;
    b = again;
  }
  return snapshot_of(c, b);
}

tx_snapshot tx_model_latest(tx_model* m, tx_comp id) {
  component* c = get(m, id);
  if (!c || !c->memory) return (tx_snapshot){0};
  return snapshot_of(c, atomic_load_explicit(&c->latest, memory_order_relaxed));
}

void tx_model_release(tx_model* m, tx_reader r) {
  if (!m || r.id < 1 || r.id > m->reader_count || !m->committed) return;
  component* c = m->comps[m->readers[r.id - 1].comp];
  atomic_store(&c->hazards[m->readers[r.id - 1].slot].buffer, NO_BUFFER);
}
