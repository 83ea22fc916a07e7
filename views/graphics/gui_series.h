// Internal: the scrolling series behind the window's device plots: the last
// TX_SERIES_LEN samples of each device's force and position, one per frame
// drawn. Fixed memory, no allocation; used from the view's rendering thread only.
#ifndef TX_VIEWS_GRAPHICS_GUI_SERIES_H
#define TX_VIEWS_GRAPHICS_GUI_SERIES_H

#include <stdbool.h>

#define TX_SERIES_LEN 240  // 8 s at the view's 30 Hz
#define TX_SERIES_DEVICES 4 // devices plotted

typedef struct tx_series {
  char name[32];          // the device ("device0")
  float force[TX_SERIES_LEN]; // |F|, N
  float fxyz[3];          // the latest force, N
  float pos[3][TX_SERIES_LEN]; // x y z, mm
  double last_t;          // s, of the latest sample
  int next, count;        // ring: the slot written next, samples held
  bool has_force;
} tx_series;

typedef struct tx_series_set {
  tx_series dev[TX_SERIES_DEVICES];
  int count;
} tx_series_set;

// one sample of device NAME at simulation time t_s (pos in m, force in N or
// NULL when the view does not read it); a sample at a time not after the
// last one is the same frame drawn again (a screenshot) and is dropped.
// false when NAME is a device past the first TX_SERIES_DEVICES.
bool tx_series_push(tx_series_set* s, const char* name, double t_s, const double pos[3], const double* force);
// the oldest sample's index in the ring, for a plot that scrolls
static inline int tx_series_offset(const tx_series* d) { return d->count < TX_SERIES_LEN ? 0 : d->next; }

#endif
