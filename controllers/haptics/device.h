// Internal: haptic device backends, chosen by a spec such as "sim",
// "scripted:pierce-down" or "scripted:path/to/waypoints.csv".
//
// A haptics tick reads the device's state, renders a force and writes it;
// the device holds that force until the next write (zero-order hold).
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_H

#include <tactus/components.h>
#include <tactus/haptics.h>

#include <stddef.h>

typedef struct tx_device tx_device;

typedef struct tx_device_backend {
  const char* scheme; // the spec up to the first ':'
  // open with the rest of the spec; period_s is the haptics tick. NULL and a
  // one-line message in tx_error() on failure
  tx_device* (*open)(const char* arg, double period_s);
  void (*info)(const tx_device* d, tx_device_info* out);
  // the state at time t_s from the start; false if the device had nothing new
  bool (*read)(tx_device* d, double t_s, tx_device_state* out);
  void (*write)(tx_device* d, const double force[3]); // N, held until the next write
  void (*close)(tx_device* d);
  // optional, for a device whose input is in the model (the mouse): the
  // component the haptics controller reads for it, and each tick, before
  // read, that component's row (NULL until it is first published)
  const char* input;
  void (*feed)(tx_device* d, const tx_pointer* input);
} tx_device_backend;

typedef struct tx_device_handle {
  const tx_device_backend* backend;
  tx_device* device;
} tx_device_handle;

// open a spec; returns -1 with the message in tx_error() naming the spec when it is bad
int tx_device_open(const char* spec, double period_s, tx_device_handle* h);
void tx_device_close(tx_device_handle* h);

extern const tx_device_backend tx_device_scripted;
extern const tx_device_backend tx_device_replay;
extern const tx_device_backend tx_device_sim;
extern const tx_device_backend tx_device_udp;
extern const tx_device_backend tx_device_mouse; // driven by a window, through window.pointer (device_mouse.h)
extern const tx_device_backend tx_device_dds;   // across Cyclone DDS, in DDS builds (controllers/net/device_dds.h)

#endif
