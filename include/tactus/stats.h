// tactus/stats.h: percentiles of a run's timings, in fixed memory.
//
// A tx_hist counts every sample of a run of any length without allocating:
// log-linear buckets, exact below 256 and within 1/256 (0.4%) above, with the
// exact maximum. Controllers, views and benches all take their p50/p99 from
// it, so every percentile in a report follows one rule (nearest rank).
//
//     static tx_hist h;            // about 26 kB: keep it off the stack
//     tx_hist_clear(&h);
//     tx_hist_add(&h, step_ns);    // lock-free for one writer, no allocation
//     tx_percentiles p = tx_hist_percentiles(&h);
#ifndef TACTUS_STATS_H
#define TACTUS_STATS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TX_HIST_SUB 256 // buckets per octave, and the values below it kept exactly
#define TX_HIST_BUCKETS (TX_HIST_SUB + 24 * (TX_HIST_SUB / 2)) // up to UINT32_MAX

typedef struct tx_hist {
  uint64_t count;                   // samples recorded
  uint32_t max;                     // exact
  uint64_t bucket[TX_HIST_BUCKETS]; // samples per bucket
} tx_hist;

typedef struct tx_percentiles {
  double p50, p99, max; // in the samples' unit (ns for timings)
} tx_percentiles;

void tx_hist_clear(tx_hist* h);
void tx_hist_add(tx_hist* h, int64_t v); // clamped to [0, UINT32_MAX]
// nearest-rank percentile q in [0, 1] (a bucket's midpoint, never above the max); 0 when empty
double tx_hist_percentile(const tx_hist* h, double q);
// p50, p99 and max; zeros when empty
tx_percentiles tx_hist_percentiles(const tx_hist* h);

#ifdef __cplusplus
}
#endif
#endif
