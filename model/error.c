// Per-thread last error message and its key, shared by every module.
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

// room for the valid keys of a large parameter table, with the file in front
static _Thread_local char last_error[1024];
static _Thread_local char last_key[128];

const char* tx_error(void) { return last_error; }
const char* tx_error_key(void) { return last_key; }

// the message may be built from tx_error(), the key from tx_error_key(): both are formatted apart first
static void set(const char* key, const char* fmt, va_list ap) {
  char message[sizeof last_error], k[sizeof last_key];
  vsnprintf(message, sizeof message, fmt, ap);
  snprintf(k, sizeof k, "%s", key ? key : "");
  memcpy(last_key, k, sizeof last_key);
  memcpy(last_error, message, sizeof last_error);
}

void tx_set_error(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  set(NULL, fmt, ap);
  va_end(ap);
}

void tx_set_error_at(const char* key, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  set(key, fmt, ap);
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
