// Internal: haptic recordings of needle insertions, as CSV (docs/needle.md).
//
//   # any comment lines, before the header only
//   t_s,depth_m,fx_n,fy_n,fz_n,event
//   0.000000,-0.001000000,0,0,0,
//   0.001000,-0.000997000,0,0,0,contact
//
// One row per sample, at 1 kHz or faster (consecutive times at most 1 ms
// apart, strictly increasing). depth_m: the tip below the tissue surface
// along the needle (negative above it). f*_n: the force on the needle, N, in
// a frame whose y axis runs along the needle out of the tissue (insertion
// goes toward -y). event: empty, or contact, puncture, retract, exit.
//
// The reader is strict: any other line is refused with "FILE:LINE: what".
#ifndef TX_CONTROLLERS_VOXEL_RECORDING_H
#define TX_CONTROLLERS_VOXEL_RECORDING_H

#include <stdbool.h>
#include <stddef.h>

typedef enum tx_needle_event {
  TX_EVENT_NONE,
  TX_EVENT_CONTACT,  // the needle first touches the tissue
  TX_EVENT_PUNCTURE, // the first cut of an insertion
  TX_EVENT_RETRACT,  // the needle starts to come out
  TX_EVENT_EXIT,     // the needle has left the tissue
} tx_needle_event;

typedef struct tx_recording_row {
  double t;        // s
  double depth;    // m
  double f[3];     // N, on the needle
  tx_needle_event event;
} tx_recording_row;

typedef struct tx_recording {
  tx_recording_row* rows; // (cap)
  size_t count;           // rows in use
  size_t cap;             // rows allocated
} tx_recording;

#define TX_RECORDING_HEADER "t_s,depth_m,fx_n,fy_n,fz_n,event"
#define TX_RECORDING_MAX_ROWS 10000000

const char* tx_needle_event_name(tx_needle_event e); // "" for none

// room for cap rows; false and tx_error() on no memory
bool tx_recording_alloc(tx_recording* r, size_t cap);
void tx_recording_free(tx_recording* r);
// appends a row; false when full (the row is dropped)
bool tx_recording_push(tx_recording* r, const tx_recording_row* row);

// writes the CSV through a temporary file and a rename (whole or absent);
// false and tx_error() naming the file on failure
bool tx_recording_write(const tx_recording* r, const char* path);

// reads a CSV strictly; false and tx_error() = "FILE:LINE: what" (or
// "FILE: what") on the first problem, r left empty
bool tx_recording_read(tx_recording* r, const char* path);

#endif
