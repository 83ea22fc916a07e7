// Internal: the one way library code reports an error.
//
// A function that can fail returns -1, NULL, false or an invalid id and leaves
// one line in this thread's tx_error() (tactus/model.h) with tx_set_error. A
// caller that knows more (the file, the flag) adds it with tx_error_prefix.
// A configuration error that belongs to a key ("params.gain", "thread") is set
// with tx_set_error_at, so the loader can name the key in its own way.
#ifndef TX_MODEL_ERROR_H
#define TX_MODEL_ERROR_H

#include <tactus/model.h> // tx_error()

// the message, and no key
void tx_set_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// the message and the key it belongs to ("" or NULL: the whole object)
void tx_set_error_at(const char* key, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
// the key of this thread's last error, "" when it has none
const char* tx_error_key(void);
// puts "CONTEXT: " before the message already there, as a caller adds where it
// failed: tx_error_prefix("%s", path) turns "bad header" into "PATH: bad header";
// the key is kept
void tx_error_prefix(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
