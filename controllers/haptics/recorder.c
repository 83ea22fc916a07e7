// Full-rate device recording through a lock-free ring and a writer thread.
#include "recorder.h"

#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define RING 16384 // records, a power of two: 16 s of backlog at 1 kHz

struct tx_recorder {
  tx_record ring[RING];
  _Atomic size_t head; // next slot the producer writes
  _Atomic size_t tail; // next slot the consumer reads
  _Atomic bool stop;
  pthread_t writer;
  FILE* file;
  int io_error;        // errno of the first failed write, read after join
  char bin[4096], csv[4096];
};

static void drain(tx_recorder* r) {
  size_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  size_t head = atomic_load_explicit(&r->head, memory_order_acquire);
  for (; tail != head; tail++)
    if (fwrite(&r->ring[tail % RING], sizeof(tx_record), 1, r->file) != 1 && !r->io_error) r->io_error = errno ? errno : EIO;
  atomic_store_explicit(&r->tail, tail, memory_order_release);
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

tx_recorder* tx_recorder_start(const char* dir, int hand, double rate_hz, const tx_device_info* device, char* err,
                               size_t n) {
  tx_recorder* r = calloc(1, sizeof *r);
  if (!r) return snprintf(err, n, "out of memory for the recorder"), NULL;
  snprintf(r->bin, sizeof r->bin, "%s/device%d.bin", dir, hand);
  snprintf(r->csv, sizeof r->csv, "%s/device%d.csv", dir, hand);
  r->file = fopen(r->bin, "wb");
  tx_record_header h = {TX_RECORD_MAGIC, TX_RECORD_VERSION, sizeof(tx_record), rate_hz, (uint32_t)hand, 0, *device};
  if (!r->file || fwrite(&h, sizeof h, 1, r->file) != 1) {
    snprintf(err, n, "%s: %s", r->bin, strerror(errno));
    if (r->file) fclose(r->file);
    free(r);
    return NULL;
  }
  if (pthread_create(&r->writer, NULL, writer_main, r) != 0) {
    snprintf(err, n, "%s: cannot start the writer thread", r->bin);
    fclose(r->file);
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

// the CSV beside the binary file: written aside, renamed when whole
static int export_csv(tx_recorder* r, char* err, size_t n) {
  tx_record_header h;
  tx_record* recs;
  size_t count;
  if (tx_record_load(r->bin, &h, &recs, &count, err, n)) return -1;
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s.tmp", r->csv);
  FILE* f = fopen(tmp, "w");
  if (!f) return free(recs), snprintf(err, n, "%s: %s", tmp, strerror(errno)), -1;
  fprintf(f, "t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n,vx_m_s,vy_m_s,vz_m_s,qw,qx,qy,qz,grip_rad,buttons,"
             "f0x_n,f0y_n,f0z_n,x0x_m,x0y_m,x0z_m,kxx,kxy,kxz,kyx,kyy,kyz,kzx,kzy,kzz\n");
  for (size_t i = 0; i < count; i++) {
    const tx_record* q = &recs[i];
    fprintf(f, "%.9f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.0f", q->t_s,
            q->pos[0], q->pos[1], q->pos[2], q->force[0], q->force[1], q->force[2], q->vel[0], q->vel[1], q->vel[2],
            q->quat[0], q->quat[1], q->quat[2], q->quat[3], q->grip, q->buttons);
    for (int k = 0; k < 15; k++) fprintf(f, ",%.17g", q->force_model[k]);
    fputc('\n', f);
  }
  free(recs);
  if (fclose(f) != 0 || rename(tmp, r->csv) != 0) return remove(tmp), snprintf(err, n, "%s: %s", r->csv, strerror(errno)), -1;
  return 0;
}

int tx_recorder_stop(tx_recorder* r, char* err, size_t n) {
  if (!r) return 0;
  atomic_store(&r->stop, true);
  pthread_join(r->writer, NULL);
  int rc = 0;
  if (fclose(r->file) != 0 || r->io_error)
    rc = -1, snprintf(err, n, "%s: %s", r->bin, strerror(r->io_error ? r->io_error : errno));
  if (rc == 0) rc = export_csv(r, err, n);
  free(r);
  return rc;
}

int tx_record_load(const char* path, tx_record_header* h, tx_record** records, size_t* count, char* err, size_t n) {
  *records = NULL;
  *count = 0;
  FILE* f = fopen(path, "rb");
  if (!f) return snprintf(err, n, "%s: %s", path, strerror(errno)), -1;
  const char* problem = NULL;
  if (fread(h, sizeof *h, 1, f) != 1 || memcmp(h->magic, TX_RECORD_MAGIC, 8) != 0) problem = "not a tactus recording";
  else if (h->version != TX_RECORD_VERSION) problem = "recording version is not 1";
  else if (h->record_size != sizeof(tx_record)) problem = "record size does not match this build";
  else if (!(h->rate_hz > 0 && h->rate_hz <= 100000)) problem = "rate out of range";
  long start = ftell(f);
  if (!problem && (fseek(f, 0, SEEK_END) != 0 || ftell(f) < start)) problem = "cannot be read to its end";
  long bytes = problem ? 0 : ftell(f) - start;
  if (!problem && bytes % (long)sizeof(tx_record) != 0) problem = "ends in the middle of a record";
  size_t total = problem ? 0 : (size_t)bytes / sizeof(tx_record);
  if (!problem && total == 0) problem = "holds no records";
  if (!problem && !(*records = malloc(total * sizeof(tx_record)))) problem = "out of memory";
  if (!problem && (fseek(f, start, SEEK_SET) != 0 || fread(*records, sizeof(tx_record), total, f) != total))
    problem = "cannot be read";
  fclose(f);
  if (problem) {
    free(*records);
    *records = NULL;
    return snprintf(err, n, "%s: %s", path, problem), -1;
  }
  *count = total;
  return 0;
}
