// rates.worker: a synthetic controller that computes for a set time per step and
// passes checksummed data through the model, to measure the scheduler and to
// catch torn snapshots under real load.
//
// It reads any number of f32 components and writes at most one. Every payload
// ends with a checksum of the values before it; a reader that finds a
// mismatch counts a "torn_reads" warning. What it writes depends on what it
// read, so data really flows around the scenario.
#include "rates_worker.h"

#include <stdlib.h>
#include <string.h>

#define READS_MAX 8

typedef struct worker {
  double work_ns;            // time to compute per step
  tx_port reads[READS_MAX];
  uint64_t last_seq[READS_MAX];
  int nreads;
  tx_port out;               // 0 when it writes nothing
  size_t out_values;         // rows x cols
  double input;              // folded from the latest reads
  tx_warning torn;
} worker;

// compute for about ns. Timed on the monotonic clock (vDSO, no system call):
// a thread-CPU clock would cost a system call per check and drown the work.
static void burn(double ns) {
  if (ns <= 0) return;
  const int64_t until = tx_mono_ns() + (int64_t)ns;
  volatile double sink = 1.0;
  do {
    for (int i = 0; i < 256; i++) sink = sink * 1.0000001 + 1e-9;
  } while (tx_mono_ns() < until);
}

static uint32_t checksum(const float* v, size_t n) {
  uint64_t h = tx_hash(TX_HASH_SEED, v, n * sizeof *v);
  return (uint32_t)(h ^ (h >> 32));
}

bool tx_rates_payload_intact(const float* v, size_t values) {
  uint32_t stored;
  memcpy(&stored, &v[values - 1], sizeof stored);
  return stored == checksum(v, values - 1);
}

void tx_rates_payload_fill(float* v, size_t values, double base) {
  for (size_t i = 0; i + 1 < values; i++) v[i] = (float)(base + 1e-3 * (double)(i % 1000));
  uint32_t sum = checksum(v, values - 1);
  memcpy(&v[values - 1], &sum, sizeof sum);
}

static const tx_param_def params[] = {
    {"work_us", TX_PARAM_NUM, "us", 0, 1e6, 0, NULL, "busy computation per step"},
    {"reads", TX_PARAM_STRS, NULL, 0, READS_MAX, 0, NULL, "f32 components read; each payload's checksum is checked"},
    {"write", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "the f32 component written with a checksummed payload; none by default"},
    {"rows", TX_PARAM_INT, "1", 1, 1 << 24, 1, NULL, "rows of the component written"},
    {"cols", TX_PARAM_INT, "1", 1, 64, 3, NULL, "values per row of the component written"},
    {"units", TX_PARAM_STR, NULL, 0, 0, 0, "1", "units of the component written"},
};

static int configure(tx_setup* s, void** self) {
  worker* w = calloc(1, sizeof *w);
  if (!w) return -1;
  *self = w;
  w->work_ns = 1e3 * tx_table_num(s, "work_us");
  const char* reads[READS_MAX];
  w->nreads = tx_table_strs(s, "reads", reads, READS_MAX);
  for (int i = 0; i < w->nreads; i++) w->reads[i] = tx_setup_read_as(s, reads[i], TX_F32, 0);
  const char* out = tx_table_str(s, "write");
  int64_t rows = tx_table_int(s, "rows");
  int64_t cols = tx_table_int(s, "cols");
  const char* units = tx_table_str(s, "units");
  if (out) {
    if (rows * cols < 2) return tx_setup_fail(s, "rows", "a payload needs at least 2 values (one is the checksum)");
    w->out = tx_setup_write(s, &(tx_component_def){out, TX_F32, (uint32_t)rows, (uint32_t)cols, units});
    w->out_values = (size_t)(rows * cols);
  }
  w->torn = tx_setup_warning(s, "torn_reads");
  return 0;
}

static int init(tx_ctx* c, void* self) {
  worker* w = self;
  if (w->out.id) tx_rates_payload_fill(tx_write(c, w->out), w->out_values, 0);
  return 0;
}

static void step(tx_ctx* c, void* self) {
  worker* w = self;
  for (int i = 0; i < w->nreads; i++) {
    tx_snapshot snap = tx_read(c, w->reads[i]);
    if (snap.seq == w->last_seq[i] || snap.seq == 0) continue; // verify each publish once
    w->last_seq[i] = snap.seq;
    size_t values = (size_t)snap.rows * snap.cols;
    if (values >= 2 && !tx_rates_payload_intact(snap.data, values)) tx_warn(c, w->torn);
    w->input = 0.5 * w->input + ((const float*)snap.data)[0];
  }
  burn(w->work_ns);
  if (w->out.id) tx_rates_payload_fill(tx_write(c, w->out), w->out_values, 1e-3 * (double)tx_step_index(c) + w->input);
}

static void fini(void* self) { free(self); }

const tx_controller_class tx_rates_worker = {
    .type = "rates.worker",
    .summary = "computes for work_us per step; passes checksummed f32 payloads from 'reads' to 'write'",
    .configure = configure,
    .init = init,
    .step = step,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
