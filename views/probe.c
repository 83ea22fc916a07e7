// view.probe: samples any components into memory taken at configure and
// writes them as one CSV once the run is over (probe.h).
#include "probe.h"

#include "aside.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { PROBE_MAX = 16, HEAD = 4 }; // components; a record's head: t, component, seq, rows

typedef struct probe {
  tx_port port[PROBE_MAX];
  int n;
  double every, from, until; // s
  double next;               // s: the next sample is due then
  char file[64];
  double* vals;              // records: t, component, seq, rows, then rows x cols values
  uint64_t cap, used;        // doubles
  uint64_t samples;
  bool full;
  tx_warning w_full;
  tx_result r_samples;
} probe;

static const tx_param_def params[] = {
    {"components", TX_PARAM_STRS, NULL, 0, PROBE_MAX, 0, NULL, "the components sampled, of any type (e.g. thread.nodes, needle.pose)"},
    {"every_s", TX_PARAM_NUM, "s", 0, 1e6, 0.1, NULL, "time between two samples; 0: every step of the probe"},
    {"from_s", TX_PARAM_NUM, "s", 0, 1e9, 0, NULL, "the first sample is taken at this time"},
    {"until_s", TX_PARAM_NUM, "s", 0, 1e9, 1e9, NULL, "no sample after this time"},
    {"file", TX_PARAM_STR, NULL, 0, 0, 0, "probe", "base name of OUT/FILE.csv"},
    {"max_values", TX_PARAM_INT, "1", 1, 1000000000, 1000000, NULL, "values kept (8 bytes each), allocated at configure; the probe stops, with a warning, when they are used up"},
};

static int configure(tx_setup* s, void** self) {
  probe* p = calloc(1, sizeof *p);
  if (!p) return -1;
  *self = p;
  const char* names[PROBE_MAX];
  p->n = tx_table_strs(s, "components", names, PROBE_MAX);
  p->every = tx_table_num(s, "every_s");
  p->from = tx_table_num(s, "from_s");
  p->until = tx_table_num(s, "until_s");
  p->cap = (uint64_t)tx_table_int(s, "max_values");
  const char* file = tx_table_str(s, "file");
  if (!file || p->n < 0) return -1;
  if (p->n == 0) return tx_setup_fail(s, "components", "expected at least one component");
  if (p->until < p->from) return tx_setup_fail(s, "until_s", "%g s is before from_s (%g s)", p->until, p->from);
  size_t len = strlen(file);
  if (len == 0 || len >= sizeof p->file || strspn(file, "abcdefghijklmnopqrstuvwxyz0123456789_-") != len)
    return tx_setup_fail(s, "file", "expected a base name of letters, digits, _ and - (at most 63), got \"%s\"", file);
  memcpy(p->file, file, len + 1);
  for (int k = 0; k < p->n; k++) p->port[k] = tx_setup_read(s, names[k]);
  p->vals = malloc(sizeof(double) * p->cap);
  if (!p->vals) return tx_setup_fail(s, "max_values", "%llu values do not fit in memory", (unsigned long long)p->cap);
  p->next = p->from;
  p->w_full = tx_setup_warning(s, "probe_full");
  p->r_samples = tx_setup_result(s, "samples");
  return 0;
}

static int init(tx_ctx* c, void* self) {
  probe* p = self;
  tx_prefault(p->vals, sizeof(double) * p->cap); // no page fault beside a 1 kHz thread
  return 0;
}

static double value_at(const void* data, tx_type type, uint64_t i) {
  switch (type) {
  case TX_F32: return ((const float*)data)[i];
  case TX_F64: return ((const double*)data)[i];
  case TX_I32: return ((const int32_t*)data)[i];
  case TX_U32: return ((const uint32_t*)data)[i];
  case TX_U8: return ((const uint8_t*)data)[i];
  }
  return NAN;
}

static void step(tx_ctx* c, void* self) {
  probe* p = self;
  double t = tx_sim_ns(c) * 1e-9;
  // a half step early counts as due: the probe's own ticks need not land on every_s exactly
  if (p->full || t > p->until || t < p->next - 0.5 / tx_rate(c)) return;
  p->next = fmax(p->next + p->every, t);
  for (int k = 0; k < p->n; k++) {
    tx_snapshot s = tx_read(c, p->port[k]);
    if (s.seq == 0) continue; // never published yet: nothing to keep
    const tx_component_def* d = tx_port_schema(c, p->port[k]);
    uint64_t need = HEAD + (uint64_t)s.rows * s.cols;
    if (p->used + need > p->cap) { // nothing half kept: the sample ends here
      p->full = true;
      tx_warn(c, p->w_full);
      return;
    }
    double* r = p->vals + p->used;
    r[0] = t, r[1] = k, r[2] = (double)s.seq, r[3] = s.rows;
    for (uint64_t i = 0; i < (uint64_t)s.rows * s.cols; i++) r[HEAD + i] = value_at(s.data, d->type, i);
    p->used += need;
  }
  p->samples++;
}

static void finish(tx_ctx* c, void* self) {
  probe* p = self;
  tx_set_result(c, p->r_samples, (double)p->samples);
  const char* dir = tx_output_dir(c);
  if (!dir) return;
  char name[80];
  snprintf(name, sizeof name, "%s.csv", p->file);
  tx_aside a;
  if (!tx_aside_open(c, &a, dir, name)) return;
  FILE* f = a.f;
  uint32_t most = 0;
  for (int k = 0; k < p->n; k++) {
    const tx_component_def* d = tx_port_schema(c, p->port[k]);
    fprintf(f, "# %s: %s, %u values a row, %s\n", d->name, tx_type_name(d->type), d->cols, d->units);
    if (d->cols > most) most = d->cols;
  }
  fprintf(f, "t_s,component,seq,row");
  for (uint32_t j = 0; j < most; j++) fprintf(f, ",v%u", j);
  fputc('\n', f);
  for (uint64_t at = 0; at < p->used;) {
    const double* r = p->vals + at;
    const tx_component_def* d = tx_port_schema(c, p->port[(int)r[1]]);
    uint32_t rows = (uint32_t)r[3];
    for (uint32_t i = 0; i < rows; i++) {
      fprintf(f, "%.6f,%s,%.0f,%u", r[0], d->name, r[2], i);
      for (uint32_t j = 0; j < d->cols; j++) fprintf(f, ",%.9g", r[HEAD + (uint64_t)i * d->cols + j]);
      fputc('\n', f);
    }
    at += HEAD + (uint64_t)rows * d->cols;
  }
  tx_aside_commit(c, &a);
}

static void fini(void* self) {
  probe* p = self;
  if (!p) return;
  free(p->vals);
  free(p);
}

const tx_controller_class tx_view_probe = {
    .type = "view.probe",
    .summary = "samples any components (every_s, from_s to until_s) and writes them to OUT/FILE.csv",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
    .view = true,
};
