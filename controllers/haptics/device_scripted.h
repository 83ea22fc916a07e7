// Internal: the waypoint reader of the scripted device, on a stream, so that
// a fuzzer can feed it from memory (device_scripted.c describes the format).
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_SCRIPTED_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_SCRIPTED_H

#include "device.h"

#include <stdio.h>

// read waypoints from f (not closed); path names it in "PATH:LINE: message".
// The device it returns is driven through tx_device_scripted's read and close.
tx_device* tx_scripted_read_csv(FILE* f, const char* path, char* err, size_t n);

#endif
