// Run statistics in fixed memory: a log-linear histogram.
#include <tactus/stats.h>

#include <string.h>

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

void tx_hist_add(tx_hist* h, int64_t v) {
  uint32_t u = v < 0 ? 0 : v > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)v;
  h->bucket[bucket_of(u)]++;
  h->count++;
  if (u > h->max) h->max = u;
}

double tx_hist_percentile(const tx_hist* h, double q) {
  if (!h->count) return 0;
  // nearest rank: the smallest value with at least q n samples at or below it
  uint64_t want = (uint64_t)(q * (double)h->count + 0.999999), seen = 0;
  if (want < 1) want = 1;
  for (uint32_t b = 0; b < TX_HIST_BUCKETS; b++)
    if ((seen += h->bucket[b]) >= want) return bucket_mid(b) < h->max ? bucket_mid(b) : h->max;
  return h->max;
}

tx_percentiles tx_hist_percentiles(const tx_hist* h) {
  if (!h->count) return (tx_percentiles){0};
  return (tx_percentiles){tx_hist_percentile(h, 0.50), tx_hist_percentile(h, 0.99), h->max};
}
