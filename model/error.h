// Internal: set the message that tx_error() returns.
#ifndef TX_MODEL_ERROR_H
#define TX_MODEL_ERROR_H

void tx_set_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

#endif
