// Timing samples: recorded without allocation, summarised by sorting a copy.
#include "stats.h"

#include <stdlib.h>
#include <string.h>

bool tx_samples_init(tx_samples* s, uint64_t cap) {
  *s = (tx_samples){0};
  s->ns = malloc((cap ? cap : 1) * sizeof *s->ns);
  s->cap = cap ? cap : 1;
  return s->ns != NULL;
}

void tx_samples_free(tx_samples* s) {
  free(s->ns);
  *s = (tx_samples){0};
}

void tx_samples_add(tx_samples* s, int64_t ns) {
  if (!s->ns) return;
  uint32_t v = ns < 0 ? 0 : ns > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)ns;
  s->ns[s->count % s->cap] = v;
  s->count++;
}

static int cmp_u32(const void* a, const void* b) {
  uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
  return (x > y) - (x < y);
}

// nearest-rank percentile of sorted values
static double rank(const uint32_t* v, uint64_t n, double q) {
  uint64_t i = (uint64_t)(q * (double)n + 0.999999);
  if (i < 1) i = 1;
  return v[(i > n ? n : i) - 1];
}

tx_percentiles tx_samples_percentiles(const tx_samples* s) {
  uint64_t n = s->count < s->cap ? s->count : s->cap;
  if (!n || !s->ns) return (tx_percentiles){0};
  uint32_t* v = malloc(n * sizeof *v);
  if (!v) return (tx_percentiles){0};
  memcpy(v, s->ns, n * sizeof *v);
  qsort(v, n, sizeof *v, cmp_u32);
  tx_percentiles p = {rank(v, n, 0.50), rank(v, n, 0.99), v[n - 1]};
  free(v);
  return p;
}

void tx_hist_clear(tx_hist* h) { memset(h, 0, sizeof *h); }

// bucket of a value: exact below TX_HIST_SUB, then TX_HIST_SUB / 2 per octave
static uint32_t bucket_of(uint32_t v) {
  if (v < TX_HIST_SUB) return v;
  int e = (31 - __builtin_clz(v)) - 7; // shift that leaves the top 8 bits, in [128, 255]
  return TX_HIST_SUB + (uint32_t)(e - 1) * (TX_HIST_SUB / 2) + ((v >> e) - TX_HIST_SUB / 2);
}

// the middle of a bucket's range of values
static double bucket_mid(uint32_t b) {
  if (b < TX_HIST_SUB) return b;
  uint32_t e = (b - TX_HIST_SUB) / (TX_HIST_SUB / 2) + 1, sub = (b - TX_HIST_SUB) % (TX_HIST_SUB / 2) + TX_HIST_SUB / 2;
  return (double)((uint64_t)sub << e) + (double)((1ull << e) - 1) / 2;
}

void tx_hist_add(tx_hist* h, int64_t ns) {
  uint32_t v = ns < 0 ? 0 : ns > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)ns;
  h->bucket[bucket_of(v)]++;
  h->count++;
  if (v > h->max) h->max = v;
}

static double hist_rank(const tx_hist* h, double q) {
  uint64_t want = (uint64_t)(q * (double)h->count + 0.999999), seen = 0;
  if (want < 1) want = 1;
  for (uint32_t b = 0; b < TX_HIST_BUCKETS; b++)
    if ((seen += h->bucket[b]) >= want) return bucket_mid(b) < h->max ? bucket_mid(b) : h->max;
  return h->max;
}

tx_percentiles tx_hist_percentiles(const tx_hist* h) {
  if (!h->count) return (tx_percentiles){0};
  return (tx_percentiles){hist_rank(h, 0.50), hist_rank(h, 0.99), h->max};
}
