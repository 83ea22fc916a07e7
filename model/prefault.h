// Internal: map a buffer's pages before a real-time loop uses it.
#ifndef TX_MODEL_PREFAULT_H
#define TX_MODEL_PREFAULT_H

#include <stddef.h>

// Writes one zero byte per page of p[0, n) through a volatile pointer, so the
// compiler cannot drop it (a memset after calloc may be). Use on memory that
// is still all zeros: a page fault inside a 1 kHz step is a late tick, and a
// long run's memory then stays flat from its first step.
void tx_prefault(void* p, size_t n);

#endif
