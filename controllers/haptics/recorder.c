// Full-rate device recording through a lock-free ring and a writer thread.
#include "recorder.h"

#include "device_protocol.h" // tx_dp_crc32: the CRC-32 of zlib, already in the library

#include "../../model/error.h"

#include <tactus/model.h>

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define RING 16384 // records, a power of two: 16 s of backlog at 1 kHz

// one block as written: the CRC covers count, first and the records, which lie contiguous
typedef struct block_buf {
  tx_record_block h;
  tx_record recs[TX_RECORD_BLOCK_MAX];
} block_buf;
_Static_assert(sizeof(tx_record_block) == 16 && offsetof(tx_record_block, count) == 8, "block header layout");
_Static_assert(offsetof(block_buf, recs) == sizeof(tx_record_block), "records follow the block header");
_Static_assert(sizeof(tx_record_header) == 104, "the header of version 1");

struct tx_recorder {
  tx_record ring[RING];
  _Atomic size_t head; // next slot the producer writes
  _Atomic size_t tail; // next slot the consumer reads
  _Atomic bool stop;
  _Atomic int error;   // errno of the first failed write, 0 while all is well
  pthread_t writer;
  FILE* file;
  uint32_t written;    // records in the file so far
  block_buf block;     // the writer's scratch
  char bin[4096], csv[4096];
};

static uint32_t block_crc(const tx_record_block* b, size_t count) {
  return tx_dp_crc32((const uint8_t*)&b->count, 8 + count * sizeof(tx_record));
}

static uint32_t header_crc(const tx_record_header* h) {
  tx_record_header c = *h;
  c.crc = 0;
  return tx_dp_crc32((const uint8_t*)&c, sizeof c);
}

static void failed(tx_recorder* r, int e) {
  int none = 0;
  atomic_compare_exchange_strong(&r->error, &none, e ? e : EIO);
}

// write what the ring holds as blocks and flush it, so that a crash loses at
// most the last drain; after a failed write the records are only consumed
static void drain(tx_recorder* r) {
  size_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  size_t head = atomic_load_explicit(&r->head, memory_order_acquire);
  bool wrote = false;
  while (tail != head) {
    size_t k = head - tail < TX_RECORD_BLOCK_MAX ? head - tail : TX_RECORD_BLOCK_MAX;
    for (size_t i = 0; i < k; i++) r->block.recs[i] = r->ring[(tail + i) % RING];
    tail += k;
    atomic_store_explicit(&r->tail, tail, memory_order_release);
    if (atomic_load(&r->error)) continue;
    memcpy(r->block.h.tag, TX_RECORD_BLOCK_TAG, 4);
    r->block.h.count = (uint32_t)k;
    r->block.h.first = r->written;
    r->block.h.crc = block_crc(&r->block.h, k);
    errno = 0;
    if (fwrite(&r->block, sizeof(tx_record_block) + k * sizeof(tx_record), 1, r->file) != 1) failed(r, errno);
    r->written += (uint32_t)k;
    wrote = true;
  }
  errno = 0;
  if (wrote && !atomic_load(&r->error) && fflush(r->file) != 0) failed(r, errno);
}

static void* writer_main(void* arg) {
  tx_recorder* r = arg;
  struct sched_param none = {0};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &none); // never above the controllers
  pthread_setname_np(pthread_self(), "tx-record");
  while (!atomic_load(&r->stop)) {
    drain(r);
    nanosleep(&(struct timespec){0, 5000000}, NULL);
  }
  drain(r);
  return NULL;
}

tx_recorder* tx_recorder_start(const char* dir, int hand, double rate_hz, const tx_device_info* device) {
  tx_recorder* r = calloc(1, sizeof *r);
  if (!r) return tx_set_error("out of memory for the recorder"), NULL;
  tx_prefault(r->ring, sizeof r->ring); // calloc maps its pages lazily
  snprintf(r->bin, sizeof r->bin, "%s/device%d.bin", dir, hand);
  snprintf(r->csv, sizeof r->csv, "%s/device%d.csv", dir, hand);
  r->file = fopen(r->bin, "wb");
  tx_record_header h = {TX_RECORD_MAGIC, TX_RECORD_VERSION, sizeof(tx_record), rate_hz, (uint32_t)hand, 0, *device};
  h.crc = header_crc(&h);
  // the header reaches the file now: a recording is never left without one
  errno = 0;
  if (!r->file || fwrite(&h, sizeof h, 1, r->file) != 1 || fflush(r->file) != 0) {
    tx_set_error("%s: %s", r->bin, strerror(errno ? errno : EIO));
    if (r->file) fclose(r->file), remove(r->bin);
    free(r);
    return NULL;
  }
  if (pthread_create(&r->writer, NULL, writer_main, r) != 0) {
    tx_set_error("%s: cannot start the writer thread", r->bin);
    fclose(r->file);
    remove(r->bin);
    free(r);
    return NULL;
  }
  return r;
}

bool tx_recorder_push(tx_recorder* r, const tx_record* rec) {
  size_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
  if (head - atomic_load_explicit(&r->tail, memory_order_acquire) == RING) return false;
  r->ring[head % RING] = *rec;
  atomic_store_explicit(&r->head, head + 1, memory_order_release);
  return true;
}

int tx_recorder_error(const tx_recorder* r, const char** file) {
  if (file) *file = r->bin;
  return atomic_load_explicit(&((tx_recorder*)r)->error, memory_order_relaxed);
}

int tx_record_export_csv(const char* bin, const char* csv, tx_record_file* read) {
  tx_record_file rf;
  if (tx_record_load(bin, &rf)) return -1;
  tx_record* recs = rf.records;
  size_t count = rf.count;
  if (read) *read = rf, read->records = NULL;
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s.tmp", csv);
  FILE* f = fopen(tmp, "w");
  if (!f) return free(recs), tx_set_error("%s: %s", tmp, strerror(errno)), -2;
  // %.17g: every double, subnormals included, reads back to the same bits (strtod)
  fprintf(f, "t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n,vx_m_s,vy_m_s,vz_m_s,qw,qx,qy,qz,grip_rad,buttons,"
             "f0x_n,f0y_n,f0z_n,x0x_m,x0y_m,x0z_m,kxx,kxy,kxz,kyx,kyy,kyz,kzx,kzy,kzz\n");
  for (size_t i = 0; i < count; i++) {
    const tx_record* q = &recs[i];
    fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.0f", q->t_s,
            q->pos[0], q->pos[1], q->pos[2], q->force[0], q->force[1], q->force[2], q->vel[0], q->vel[1], q->vel[2],
            q->quat[0], q->quat[1], q->quat[2], q->quat[3], q->grip, q->buttons);
    for (int k = 0; k < 15; k++) fprintf(f, ",%.17g", q->force_model[k]);
    fputc('\n', f);
  }
  free(recs);
  errno = 0;
  bool bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad || rename(tmp, csv) != 0)
    return remove(tmp), tx_set_error("%s: %s", csv, strerror(errno ? errno : EIO)), -2;
  return 0;
}

int tx_recorder_stop(tx_recorder* r) {
  if (!r) return 0;
  atomic_store(&r->stop, true);
  pthread_join(r->writer, NULL);
  errno = 0;
  if (fclose(r->file) != 0) failed(r, errno);
  int e = atomic_load(&r->error), rc = 0;
  if (e) rc = -1, tx_set_error("%s: %s", r->bin, strerror(e));
  if (rc == 0 && tx_record_export_csv(r->bin, r->csv, NULL)) rc = -1;
  free(r);
  return rc;
}

int tx_record_load(const char* path, tx_record_file* out) {
  memset(out, 0, sizeof *out);
  FILE* f = fopen(path, "rb");
  if (!f) return tx_set_error("%s: %s", path, strerror(errno)), -1;
  unsigned char* data = NULL;
  long size = -1;
  if (fseek(f, 0, SEEK_END) == 0 && (size = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
      (data = malloc(size ? (size_t)size : 1)) && fread(data, 1, (size_t)size, f) == (size_t)size) {
    fclose(f);
    int rc = tx_record_parse(data, (size_t)size, path, out);
    free(data);
    return rc;
  }
  fclose(f);
  free(data);
  return tx_set_error("%s: %s", path, data || size < 0 ? "cannot be read" : "out of memory"), -1;
}

// NULL when the device's limits are finite and sane
static const char* device_problem(const tx_device_info* d) {
  if (!(d->max_force >= 1e-6 && d->max_force <= 1e4)) return "its max_force is not in [1e-6, 1e4] N";
  if (!(isfinite(d->max_stiffness) && d->max_stiffness >= 0 && d->max_stiffness <= 1e9)) return "its max_stiffness is not in [0, 1e9] N/m";
  if (!(isfinite(d->damping) && d->damping >= 0 && d->damping <= 1e6)) return "its damping is not in [0, 1e6] N s/m";
  for (int i = 0; i < 3; i++)
    if (!(fabs(d->workspace_min[i]) <= 10 && fabs(d->workspace_max[i]) <= 10 && d->workspace_min[i] < d->workspace_max[i]))
      return "its workspace is not a box within 10 m";
  return NULL;
}

static bool all_finite(const double* v, int k, double bound) {
  for (int i = 0; i < k; i++)
    if (!(fabs(v[i]) <= bound)) return false; // NaN fails too
  return true;
}

// what a device could have sent and the safety chain let out; NULL when plausible.
// The force model is what a controller published and is kept as it was read.
static const char* record_problem(const tx_record* r, const tx_record* prev, const tx_record_header* h) {
  if (!(r->t_s >= 0 && r->t_s <= 1e7)) return "time is not in [0, 1e7] s";
  if (prev && !(r->t_s > prev->t_s)) return "time does not increase";
  if (!all_finite(r->pos, 3, 10)) return "a position is not finite or beyond 10 m";
  double q2 = 0;
  for (int i = 0; i < 4; i++) q2 += r->quat[i] * r->quat[i];
  if (!(fabs(q2 - 1) <= 1e-6)) return "the orientation is not a unit quaternion"; // as the device protocol checks
  if (!all_finite(r->vel, 3, 1000)) return "a velocity is not finite or beyond 1000 m/s";
  if (!(fabs(r->grip) <= 100)) return "the grip is not finite or beyond 100 rad";
  if (!(r->buttons >= 0 && r->buttons <= 4294967295.0 && r->buttons == floor(r->buttons))) return "the buttons are not a 32-bit field";
  double f = hypot(hypot(r->force[0], r->force[1]), r->force[2]); // no square to underflow or overflow
  if (!(f <= h->device.max_force * (1 + 1e-9))) return "the force sent is not finite or above the device's max_force";
  return NULL;
}

int tx_record_parse(const void* bytes, size_t size, const char* name, tx_record_file* out) {
  const unsigned char* data = bytes;
  memset(out, 0, sizeof *out);
  tx_record_header* h = &out->header;
  if (size < 8 || memcmp(data, TX_RECORD_MAGIC, 8) != 0) return tx_set_error("%s: not a tactus recording", name), -1;
  if (size < sizeof *h) return tx_set_error("%s: cut short in its header", name), -1;
  memcpy(h, data, sizeof *h);
  const char* problem = NULL;
  if (h->version != 1 && h->version != 2) problem = "its version is neither 1 nor 2 (made by another tactus?)";
  else if (h->version == 2 && h->crc != header_crc(h)) problem = "header checksum mismatch (the file is corrupt)";
  else if (h->record_size != sizeof(tx_record)) problem = "record size does not match this build";
  else if (!(h->rate_hz > 0 && h->rate_hz <= 100000)) problem = "rate out of range";
  else if (h->hand > 1) problem = "hand is neither 0 nor 1";
  if (problem) return tx_set_error("%s: %s", name, problem), -1;
  if ((problem = device_problem(&h->device))) return tx_set_error("%s: recorded device: %s", name, problem), -1;

  size_t off = sizeof *h, most = (size - off) / sizeof(tx_record), total = 0, blk = 0;
  tx_record* recs = malloc((most ? most : 1) * sizeof *recs);
  if (!recs) return tx_set_error("%s: out of memory", name), -1;
  while (off < size) {
    size_t k;
    if (h->version == 1) { // records straight after the header
      k = (size - off) / sizeof(tx_record);
      if (k == 0) {
        snprintf(out->cut_short, sizeof out->cut_short, "%s: ends in the middle of a record (a run that did not finish?): using its %zu whole records",
                 name, total);
        break;
      }
      memcpy(recs + total, data + off, k * sizeof(tx_record));
      off += k * sizeof(tx_record);
    } else {
      tx_record_block b;
      if (size - off < sizeof b) {
        snprintf(out->cut_short, sizeof out->cut_short, "%s: cut short in block %zu at byte %zu (a run that did not finish?): using the %zu records before it",
                 name, blk, off, total);
        break;
      }
      memcpy(&b, data + off, sizeof b);
      if (memcmp(b.tag, TX_RECORD_BLOCK_TAG, 4) != 0 || b.count == 0 || b.count > TX_RECORD_BLOCK_MAX || b.first != total) {
        tx_set_error("%s: block %zu at byte %zu: not a block of records %zu on (the file is corrupt)", name, blk, off,
                 total);
        goto bad;
      }
      k = b.count;
      if (size - off - sizeof b < k * sizeof(tx_record)) {
        snprintf(out->cut_short, sizeof out->cut_short, "%s: cut short in block %zu at byte %zu (a run that did not finish?): using the %zu records before it",
                 name, blk, off, total);
        break;
      }
      uint32_t crc = tx_dp_crc32(data + off + 8, 8 + k * sizeof(tx_record));
      if (crc != b.crc) {
        tx_set_error("%s: block %zu (records %zu to %zu, at byte %zu): checksum mismatch (the file is corrupt)", name,
                 blk, total, total + k - 1, off);
        goto bad;
      }
      memcpy(recs + total, data + off + sizeof b, k * sizeof(tx_record));
      off += sizeof b + k * sizeof(tx_record);
    }
    for (size_t i = total; i < total + k; i++)
      if ((problem = record_problem(&recs[i], i ? &recs[i - 1] : NULL, h))) {
        if (h->version == 1) tx_set_error("%s: record %zu: %s", name, i, problem);
        else tx_set_error("%s: record %zu (block %zu): %s", name, i, blk, problem);
        goto bad;
      }
    total += k;
    blk++;
  }
  if (total == 0) {
    tx_set_error("%s: holds no records", name);
    goto bad;
  }
  out->records = recs;
  out->count = total;
  return 0;
bad:
  out->cut_short[0] = 0;
  free(recs);
  return -1;
}
