// Touching pages ahead of a real-time loop. A volatile write per page: the
// compiler may drop a memset that follows calloc, leaving the pages unmapped.
#include <tactus/model.h>

#include <unistd.h>

void tx_prefault(void* p, size_t n) {
  if (!p || !n) return;
  long page = sysconf(_SC_PAGESIZE);
  size_t step = page > 0 ? (size_t)page : 4096;
  volatile unsigned char* b = p;
  for (size_t i = 0; i < n; i += step) b[i] = 0;
  b[n - 1] = 0;
}
