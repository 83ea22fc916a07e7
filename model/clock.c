// Monotonic time, the one clock every timestamp in a run comes from.
#include <tactus/model.h>

#include <time.h>

int64_t tx_mono_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}
