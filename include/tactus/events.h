// tactus/events.h: event streams, for what must not be lost between rates.
//
// A component holds only its latest value: a grasp sent at 1 kHz and read by
// 60 Hz physics would be overwritten before it is read. An event stream keeps
// every event until each of its readers has taken it. One thread writes, any
// number of readers (each one thread) read; every reader sees every event once
// and in order. Nothing locks or waits: a push is a copy and a release store.
//
// A stream has a fixed capacity. When its slowest reader is a full ring
// behind, a push is refused and counted (tx_stream_overflows); the event's
// sequence number is still used, so each reader sees the gap and counts what
// it lost (tx_stream_lost). Loss is never silent.
//
//     tx_stream* s = tx_stream_create("tool0.events", 1024);   // a power of two
//     int physics = tx_stream_add_reader(s);                   // before the first push
//     tx_stream_push(s, &(tx_event){.kind = TX_EVENT_GRASP, .sim_ns = t});   // writer thread
//     for (tx_event e; tx_stream_next(s, physics, &e);) ...   // reader thread
//
// Functions that can fail return 0, -1 or NULL and leave a message in tx_error().
#ifndef TACTUS_EVENTS_H
#define TACTUS_EVENTS_H

#include <tactus/model.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TX_STREAM_READERS_MAX 16      // readers of one stream
#define TX_STREAM_CAPACITY_MAX (1u << 20) // events in one stream's ring

// what happened; a stream's writer documents which kinds it sends and what
// source and value mean for each
typedef enum tx_event_kind {
  TX_EVENT_GRASP = 1, // jaws closed on something: source = instrument, payload .grasp
  TX_EVENT_RELEASE,   // jaws opened: source = instrument
  TX_EVENT_PUNCTURE,  // a surface was pierced: source = surface element (for the skin: its skin.tri row at that publish), payload .puncture
  TX_EVENT_CUT,       // something was cut: source = element (thread segment, link), payload .cut
  TX_EVENT_BURN,      // tissue vaporised: source = tetrahedron (its row of ORGAN.ele), payload .burn
  TX_EVENT_KNOT,      // a knot formed or was fixed: source = knot index
  TX_EVENT_STEP,      // a procedure step began or ended: source = step index, value[0] = its tx_step_status
  TX_EVENT_LATCH = 20, // the gastric band locked: source = 0, value[0..2] = the buckle's opening, m
  TX_EVENT_USER = 1000 // kinds of plugins start here
} tx_event_kind;

// the payloads of the kinds that carry more than a source; each is read and
// written through the tx_event union below, never by position in value[]
typedef struct tx_grasp_payload { // TX_EVENT_GRASP, source = instrument
  double point[3]; // m, the contact point between the jaws, world frame
  double jaw;      // rad, the jaws' opening angle when they closed on it
  double force;    // N, grip force at the grasp (0 when the instrument cannot tell)
} tx_grasp_payload;
typedef struct tx_puncture_payload { // TX_EVENT_PUNCTURE, source = surface element
  double point[3]; // m, where the surface was pierced, world frame
  double force;    // N, the axial force that pierced it
  double depth;    // m, the tip's depth below the surface at the puncture
} tx_puncture_payload;

typedef struct tx_cut_payload { // TX_EVENT_CUT, source = thread segment (node i to i + 1) or link
  double point[3]; // m, where the blades closed, world frame
} tx_cut_payload;
typedef struct tx_burn_payload { // TX_EVENT_BURN, source = tetrahedron of the organ's .ele (physics.organs' numbering)
  double organ;    // which organ: 0 the liver, 1 the stomach (physics.organs' order), a whole number
  double fraction; // of its volume that had reached the vaporisation temperature when it was sent
  double point[3]; // m, its centroid at rest
} tx_burn_payload;
typedef struct tx_event {
  uint64_t seq;     // set by the push: 1, 2, ... per stream; a gap means events were lost
  int64_t sim_ns;   // simulation time of the step that sent it, ns
  uint32_t kind;    // a tx_event_kind
  uint32_t source;  // which instrument, node, element or step (per kind)
  union {           // payload (per kind), SI units
    double value[5];             // kinds without a payload struct (e.g. TX_EVENT_BURN: value[0] = K)
    tx_grasp_payload grasp;      // TX_EVENT_GRASP
    tx_puncture_payload puncture; // TX_EVENT_PUNCTURE
    tx_cut_payload cut;           // TX_EVENT_CUT
    tx_burn_payload burn;         // TX_EVENT_BURN
  };
} tx_event;
#ifdef __cplusplus
static_assert(sizeof(tx_event) == 64, "one event is one cache line");
static_assert(sizeof(tx_grasp_payload) <= 5 * sizeof(double), "a grasp fits in an event");
static_assert(sizeof(tx_puncture_payload) <= 5 * sizeof(double), "a puncture fits in an event");
static_assert(sizeof(tx_cut_payload) <= 5 * sizeof(double), "a cut fits in an event");
static_assert(sizeof(tx_burn_payload) <= 5 * sizeof(double), "a burn fits in an event");
#else
_Static_assert(sizeof(tx_event) == 64, "one event is one cache line");
_Static_assert(sizeof(tx_grasp_payload) <= 5 * sizeof(double), "a grasp fits in an event");
_Static_assert(sizeof(tx_puncture_payload) <= 5 * sizeof(double), "a puncture fits in an event");
_Static_assert(sizeof(tx_cut_payload) <= 5 * sizeof(double), "a cut fits in an event");
_Static_assert(sizeof(tx_burn_payload) <= 5 * sizeof(double), "a burn fits in an event");
#endif

typedef struct tx_stream tx_stream;

// capacity: a power of two in [2, TX_STREAM_CAPACITY_MAX]; NULL on bad input
tx_stream* tx_stream_create(const char* name, uint32_t capacity);
void tx_stream_destroy(tx_stream* s);
const char* tx_stream_name(const tx_stream* s);
// a new reader, before the first push; its index, or -1
int tx_stream_add_reader(tx_stream* s);

// writer: copy e in (its seq is assigned); returns the seq, or 0 when the
// slowest reader is a whole ring behind (the event is dropped and counted)
uint64_t tx_stream_push(tx_stream* s, const tx_event* e);
// reader: take the next event; false when there is none
bool tx_stream_next(tx_stream* s, int reader, tx_event* out);

uint64_t tx_stream_pushed(const tx_stream* s);            // events sent, dropped ones included
uint64_t tx_stream_overflows(const tx_stream* s);         // pushes refused because the ring was full
uint64_t tx_stream_lost(const tx_stream* s, int reader);  // gaps this reader has seen so far

#ifdef __cplusplus
}
#endif
#endif
