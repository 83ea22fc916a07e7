// Internal: fixed-capacity timing samples and their percentiles.
// Samples are stored at init so that recording never allocates; once full,
// the oldest are overwritten.
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

#endif
