// Event streams: a single-writer ring with one tail per reader.
//
// The writer fills slot head % capacity, then publishes head + 1 with a release
// store; a reader acquires head, copies its slot, then releases its own tail.
// The writer acquires every tail before it reuses a slot, so a slot is never
// written while a reader may still copy it. Each tail sits on its own cache
// line, so readers never contend with each other.
//
// A push touches two cache lines, the writer's and the slot (a 1 kHz push
// comes after a millisecond of sleep, so any line may be cold): head shares
// the writer's line, since readers look at it only at their own slower rate;
// the writer keeps the smallest tail it last saw and reads the readers' lines
// only when that bound says the ring may be full; and it prefetches the next
// slot. The stream, its tails and its ring are one block on huge pages where
// the system grants them (2 MiB a stream at least): after a millisecond of
// other work the TLB is cold too, and a page walk under a hypervisor costs
// more than the misses themselves; on one huge page the push takes one walk.
#include "error.h"

#include <tactus/events.h>

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#define CACHE_LINE 64
#define HUGE_PAGE (2u << 20)

typedef struct tail {
  _Alignas(CACHE_LINE) _Atomic uint64_t next; // next event this reader takes
  uint64_t last_seq;                          // reader-private: seq of its last event
  uint64_t lost;                              // reader-private, read after the run
} tail;

struct tx_stream {
  // the writer's line: everything a push reads or writes but the slot
  _Alignas(CACHE_LINE) uint64_t seq; // the last seq handed out
  uint64_t min_tail;                 // a lower bound of every reader's tail
  _Atomic uint64_t overflows;        // pushes refused (read by others after the run)
  tx_event* ring;                    // capacity
  tail* tails;                       // TX_STREAM_READERS_MAX
  uint32_t mask;                     // capacity - 1
  int readers;
  _Atomic uint64_t head;             // events published
  _Alignas(CACHE_LINE) char name[TX_NAME_MAX];
};

tx_stream* tx_stream_create(const char* name, uint32_t capacity) {
  if (!name || !*name || strlen(name) >= TX_NAME_MAX) return tx_set_error("stream name: empty or too long"), NULL;
  if (capacity < 2 || capacity > TX_STREAM_CAPACITY_MAX || (capacity & (capacity - 1)))
    return tx_set_error("%s: capacity %u is not a power of two in [2, %u]", name, capacity, TX_STREAM_CAPACITY_MAX), NULL;
  // one block: the stream, the tails, the ring, in whole huge pages
  size_t tails_at = sizeof(tx_stream), ring_at = tails_at + TX_STREAM_READERS_MAX * sizeof(tail);
  size_t bytes = (ring_at + (size_t)capacity * sizeof(tx_event) + HUGE_PAGE - 1) / HUGE_PAGE * HUGE_PAGE;
  char* block = aligned_alloc(HUGE_PAGE, bytes);
  if (!block) return tx_set_error("%s: out of memory", name), NULL;
  madvise(block, bytes, MADV_HUGEPAGE); // a hint: without huge pages the stream still works
  memset(block, 0, bytes);              // touched now, not in a 1 kHz push
  tx_stream* s = (tx_stream*)block;
  tx_event* ring = (tx_event*)(block + ring_at);
  tail* tails = (tail*)(block + tails_at);
  strcpy(s->name, name);
  s->mask = capacity - 1;
  s->ring = ring;
  s->tails = tails;
  return s;
}

void tx_stream_destroy(tx_stream* s) {
  free(s); // the whole block
}

const char* tx_stream_name(const tx_stream* s) { return s->name; }

int tx_stream_add_reader(tx_stream* s) {
  if (atomic_load(&s->head) || s->seq) return tx_set_error("%s: a reader must be added before the first push", s->name), -1;
  if (s->readers == TX_STREAM_READERS_MAX)
    return tx_set_error("%s: more than %d readers", s->name, TX_STREAM_READERS_MAX), -1;
  return s->readers++;
}

// the smallest tail now; each acquire orders the slot reuse after that reader's copy
static uint64_t min_tail(tx_stream* s) {
  uint64_t m = atomic_load_explicit(&s->head, memory_order_relaxed);
  for (int r = 0; r < s->readers; r++) {
    uint64_t t = atomic_load_explicit(&s->tails[r].next, memory_order_acquire);
    if (t < m) m = t;
  }
  return m;
}

uint64_t tx_stream_push(tx_stream* s, const tx_event* e) {
  uint64_t head = atomic_load_explicit(&s->head, memory_order_relaxed), seq = ++s->seq; // only this thread stores head
  // tails only grow, so a ring with room by the old bound has room now
  if (head - s->min_tail > s->mask && head - (s->min_tail = min_tail(s)) > s->mask) {
    atomic_store_explicit(&s->overflows, atomic_load_explicit(&s->overflows, memory_order_relaxed) + 1,
                          memory_order_relaxed); // one writer: no read-modify-write needed
    return 0;
  }
  tx_event* slot = &s->ring[head & s->mask];
  *slot = *e;
  slot->seq = seq;
  atomic_store_explicit(&s->head, head + 1, memory_order_release);
  __builtin_prefetch(&s->ring[(head + 1) & s->mask], 1); // the next push's slot, fetched while the writer goes on
  return seq;
}

bool tx_stream_next(tx_stream* s, int reader, tx_event* out) {
  if (reader < 0 || reader >= s->readers) return false;
  tail* t = &s->tails[reader];
  uint64_t next = atomic_load_explicit(&t->next, memory_order_relaxed); // only this reader stores it
  if (next == atomic_load_explicit(&s->head, memory_order_acquire)) return false;
  *out = s->ring[next & s->mask];
  atomic_store_explicit(&t->next, next + 1, memory_order_release);
  t->lost += out->seq - t->last_seq - 1; // dropped pushes used their seq numbers
  t->last_seq = out->seq;
  return true;
}

uint64_t tx_stream_pushed(const tx_stream* s) { return s->seq; }
uint64_t tx_stream_overflows(const tx_stream* s) { return atomic_load(&((tx_stream*)s)->overflows); }
uint64_t tx_stream_lost(const tx_stream* s, int reader) {
  return reader >= 0 && reader < s->readers ? s->tails[reader].lost : 0;
}
