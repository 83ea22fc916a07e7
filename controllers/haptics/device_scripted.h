// Internal: the waypoint reader of the scripted device, on a stream, so that
// a fuzzer can feed it from memory (device_scripted.c describes the format).
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_SCRIPTED_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_SCRIPTED_H

#include "device.h"

#include <stdio.h>

// read waypoints from f (not closed); path names it in "PATH:LINE: message".
// The device it returns is driven through tx_device_scripted's read and close.
tx_device* tx_scripted_read_csv(FILE* f, const char* path);

// a named hand motion: waypoints t, x, y, z (s, m), the tool moving in straight
// lines between them. One table holds every motion that a scenario
// (`scripted:NAME`) or a study drives.
typedef struct tx_hand_motion {
  const char* name;
  int count;
  double t_pos[12][4];
} tx_hand_motion;
// the motion of that name, or NULL
const tx_hand_motion* tx_hand_motion_find(const char* name);

#endif
