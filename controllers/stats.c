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
