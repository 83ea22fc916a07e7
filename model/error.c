// Per-thread last error message, shared by every module.
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static _Thread_local char last_error[512];

const char* tx_error(void) { return last_error; }

void tx_set_error(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(last_error, sizeof last_error, fmt, ap);
  va_end(ap);
}

void tx_error_prefix(const char* fmt, ...) {
  // the context may be built from tx_error() itself, so format it apart first
  char context[sizeof last_error], was[sizeof last_error];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(context, sizeof context, fmt, ap);
  va_end(ap);
  memcpy(was, last_error, sizeof was);
  size_t n = strlen(context);
  memcpy(last_error, context, n + 1);
  if (*was && n + 2 < sizeof last_error) {
    memcpy(last_error + n, ": ", 3);
    n += 2;
    size_t k = strnlen(was, sizeof last_error - 1 - n);
    memcpy(last_error + n, was, k);
    last_error[n + k] = 0;
  }
}
