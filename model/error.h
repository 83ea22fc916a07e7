// Internal: set the message that tx_error() returns.
#ifndef TX_MODEL_ERROR_H
#define TX_MODEL_ERROR_H

void tx_set_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// puts "CONTEXT: " before the message already there, as a caller adds where it
// failed: tx_error_prefix("%s", path) turns "bad header" into "PATH: bad header"
void tx_error_prefix(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
