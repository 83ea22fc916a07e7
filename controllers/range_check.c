// Range checks of definition structs.
#include "range_check.h"

#include "../model/error.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

int tx_check_range(const char* owner, const char* name, double v, double lo, bool open_lo, double hi, bool open_hi,
                   const char* units) {
  if (isfinite(v) && (open_lo ? v > lo : v >= lo) && (open_hi ? v < hi : v <= hi)) return 0;
  tx_set_error("%s: %s = %g %s, must be finite and in %s%g, %g%s", owner, name, v, units, open_lo ? "(" : "[", lo, hi,
               open_hi ? ")" : "]");
  return -1;
}

int tx_check_count(const char* owner, const char* name, long long v, long long lo, long long hi) {
  if (v >= lo && v <= hi) return 0;
  tx_set_error("%s: %s = %lld, must be in [%lld, %lld]", owner, name, v, lo, hi);
  return -1;
}

int tx_check_fail(const char* fmt, ...) {
  char message[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(message, sizeof message, fmt, ap);
  va_end(ap);
  tx_set_error("%s", message);
  return -1;
}
