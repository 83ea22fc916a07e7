// Internal: the checks of definition structs (a simulated device, a voxel
// block, ...): a value must be finite and inside a range. Each returns 0 when
// the value passes, or -1 with one line in tx_error() naming the owner, the
// field, the value and the range.
#ifndef TX_CONTROLLERS_RANGE_CHECK_H
#define TX_CONTROLLERS_RANGE_CHECK_H

#include <stdbool.h>

// v finite and in lo..hi, each end open or closed:
// "OWNER: NAME = V UNITS, must be finite and in [LO, HI]"
int tx_check_range(const char* owner, const char* name, double v, double lo, bool open_lo, double hi, bool open_hi,
                   const char* units);
// a whole number in [lo, hi]: "OWNER: NAME = V, must be in [LO, HI]"
int tx_check_count(const char* owner, const char* name, long long v, long long lo, long long hi);
// any other rule, printf-style: sets tx_error() and returns -1
int tx_check_fail(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
