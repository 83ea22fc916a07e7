// Internal: full-rate recording of one device, without ever blocking the
// haptics thread. Each tick the haptics controller pushes one record into a
// lock-free single-producer ring; a low-priority thread drains it into
// DIR/deviceN.bin. When recording ends the binary file is exported as
// DIR/deviceN.csv. A full ring drops the record and counts it: the haptic
// loop never waits for a disk.
//
// deviceN.bin: a tx_record_header (magic "TXREC001", version, record size,
// rate, hand, and the device's info so that a replay applies the same
// limits), then tx_record structs as they are in memory (little-endian IEEE
// doubles on every supported machine).
#ifndef TX_CONTROLLERS_HAPTICS_RECORDER_H
#define TX_CONTROLLERS_HAPTICS_RECORDER_H

#include <tactus/haptics.h>

#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>

#define TX_RECORD_MAGIC "TXREC001"
#define TX_RECORD_VERSION 1

typedef struct tx_record {
  double t_s;             // simulation time of the tick
  double pos[3];          // m
  double quat[4];         // w, x, y, z
  double vel[3];          // m/s
  double grip;            // rad
  double buttons;         // bit field, exact in a double
  double force_model[15]; // F0 (N), x0 (m), K (N/m, row-major) as read this tick
  double force[3];        // N, what was sent to the device
} tx_record;

typedef struct tx_record_header {
  char magic[8];
  uint32_t version;
  uint32_t record_size;
  double rate_hz;
  uint32_t hand;
  uint32_t zero;
  tx_device_info device; // of the recorded device
} tx_record_header;

typedef struct tx_recorder tx_recorder;

// start recording into dir; NULL with a message on failure
tx_recorder* tx_recorder_start(const char* dir, int hand, double rate_hz, const tx_device_info* device, char* err,
                               size_t n);
// from the haptics thread: never blocks; false if the ring was full (dropped)
bool tx_recorder_push(tx_recorder* r, const tx_record* rec);
// drain, close, export the CSV; returns 0 or -1 with a message
int tx_recorder_stop(tx_recorder* r, char* err, size_t n);

// read a recording's header and records (caller frees *records)
int tx_record_load(const char* path, tx_record_header* h, tx_record** records, size_t* count, char* err, size_t n);

#endif
