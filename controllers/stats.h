// Internal: timing statistics that never allocate while recording.
//
// tx_samples keeps raw samples in a fixed ring (exact percentiles of the
// newest cap samples; benches). tx_hist counts every sample of a run of any
// length in fixed memory: log-linear buckets, exact below 256 ns and within
// 1/256 (0.4%) above, with the exact maximum (the run's statistics).
#ifndef TX_CONTROLLERS_STATS_H
#define TX_CONTROLLERS_STATS_H

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_samples {
  uint32_t* ns;   // capacity, ns, saturated at UINT32_MAX
  uint64_t cap;
  uint64_t count; // recorded so far, may exceed cap
} tx_samples;

typedef struct tx_percentiles {
  double p50, p99, max; // ns
} tx_percentiles;

bool tx_samples_init(tx_samples* s, uint64_t cap);
void tx_samples_free(tx_samples* s);
void tx_samples_add(tx_samples* s, int64_t ns);
tx_percentiles tx_samples_percentiles(const tx_samples* s); // zeros when empty

#define TX_HIST_SUB 256 // buckets per octave, and the values below it kept exactly
#define TX_HIST_BUCKETS (TX_HIST_SUB + 24 * (TX_HIST_SUB / 2)) // up to UINT32_MAX ns

typedef struct tx_hist {
  uint64_t count;                   // samples recorded
  uint32_t max;                     // ns, exact
  uint64_t bucket[TX_HIST_BUCKETS]; // samples per bucket
} tx_hist;

void tx_hist_clear(tx_hist* h);
void tx_hist_add(tx_hist* h, int64_t ns); // clamped to [0, UINT32_MAX]
// nearest-rank percentiles (bucket midpoints, never above the max); zeros when empty
tx_percentiles tx_hist_percentiles(const tx_hist* h);

#endif
