// Internal: full-rate recording of one device, without ever blocking the
// haptics thread. Each tick the haptics controller pushes one record into a
// lock-free single-producer ring; a low-priority thread drains it into
// DIR/deviceN.bin every 5 ms and flushes what it drained, so that a run that
// crashes or is killed leaves every record up to its last 5 ms on disk. When
// recording ends the binary file is exported as DIR/deviceN.csv. A full ring
// drops the record and counts it: the haptic loop never waits for a disk. A
// write that fails (a full disk) is kept as an errno that the haptics thread
// polls, so that the run stops at once rather than at its end.
//
// deviceN.bin, version 2: a tx_record_header (magic "TXREC001", version,
// record size, rate, hand, the CRC-32 of the header, and the device's info so
// that a replay applies the same limits), then blocks of records: a
// tx_record_block then `count` tx_record structs as they are in memory
// (little-endian IEEE doubles on every supported machine). Each block carries
// the CRC-32 of its count, first index and records. Version 1 (no CRCs, the
// records straight after the header) is still read.
#ifndef TX_CONTROLLERS_HAPTICS_RECORDER_H
#define TX_CONTROLLERS_HAPTICS_RECORDER_H

#include <tactus/haptics.h>

#include <stdatomic.h>
#include <stddef.h>
#include <stdio.h>

#define TX_RECORD_MAGIC "TXREC001"
#define TX_RECORD_VERSION 2
#define TX_RECORD_BLOCK_TAG "TXBK"
#define TX_RECORD_BLOCK_MAX 256 // records in one block at most

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
  uint32_t crc;          // version 2: CRC-32 of this header with crc = 0; version 1: 0
  tx_device_info device; // of the recorded device
} tx_record_header;

typedef struct tx_record_block {
  char tag[4];    // "TXBK"
  uint32_t crc;   // CRC-32 of the bytes from count to the end of the block's records
  uint32_t count; // records that follow, 1..TX_RECORD_BLOCK_MAX
  uint32_t first; // index in the recording of the first of them
} tx_record_block;

typedef struct tx_recorder tx_recorder;

// Errors: NULL or -1 with one line in tx_error() (tactus/model.h).

// start recording into dir; NULL on failure
tx_recorder* tx_recorder_start(const char* dir, int hand, double rate_hz, const tx_device_info* device);
// from the haptics thread: never blocks; false if the ring was full (dropped)
bool tx_recorder_push(tx_recorder* r, const tx_record* rec);
// from the haptics thread: 0, or the errno of the first failed write (the
// recording is then broken and the run should stop); *file is the .bin path
int tx_recorder_error(const tx_recorder* r, const char** file);
// drain, close, export the CSV; returns 0 or -1
int tx_recorder_stop(tx_recorder* r);

// a recording as read. A file cut short (a killed run) is not an error: it
// gives its whole blocks, and cut_short says where it ends (data the caller
// may show as a warning; the reader prints nothing).
typedef struct tx_record_file {
  tx_record_header header;
  tx_record* records;   // count records; the caller frees them (NULL after an error)
  size_t count;
  char cut_short[512];  // "" when whole; else one line naming the file and where it ends
} tx_record_file;

// read a recording; a corrupt block or an implausible value is an error
// naming the file, the block and the record
int tx_record_load(const char* path, tx_record_file* out);
// the same on the bytes of a recording in memory; name is used in messages
int tx_record_parse(const void* data, size_t size, const char* name, tx_record_file* out);
// write a recording's CSV (aside, then renamed when whole): 0; -1 when the
// recording cannot be read, -2 when the CSV cannot be written; read, when not
// NULL, receives what was read (header, count, cut_short; records NULL)
int tx_record_export_csv(const char* bin, const char* csv, tx_record_file* read);

#endif
