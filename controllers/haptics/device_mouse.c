// mouse: a device driven by a window's mouse and keyboard, for people without
// a haptic device. It has no motors: the force it is sent is only shown (the
// window draws deviceN.force). Its input is window.pointer, fed by the
// haptics controller each tick (device_mouse.h).
#include "device.h"

#include "../../model/error.h"
#include "device_mouse.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct tx_device {
  double period;    // s, the haptics tick
  double pos[3];    // m, the latest input (clamped), or the start
  uint32_t buttons; // held, one bit each
  double last[3];   // m, the position read last
  bool have_last;
};

static tx_device* open_mouse(const char* arg, double period_s) {
  if (*arg) return tx_set_error("device 'mouse:%s': takes no options", arg), NULL;
  tx_device* d = calloc(1, sizeof *d);
  if (!d) return tx_set_error("out of memory"), NULL;
  d->period = period_s;
  d->pos[1] = TX_MOUSE_START_Y_M; // above the origin until the window moves it
  return d;
}

static void info_mouse(const tx_device* d, tx_device_info* out) {
  (void)d;
  // nothing is felt; the limits are those of a small desktop device, so that safety behaves as with one
  *out = (tx_device_info){.max_force = 3.3, .max_stiffness = 1000, .damping = 0,
                          .workspace_min = {-TX_POINTER_REACH_M, -TX_POINTER_REACH_M, -TX_POINTER_REACH_M},
                          .workspace_max = {TX_POINTER_REACH_M, TX_POINTER_REACH_M, TX_POINTER_REACH_M}};
}

// the pointer's row of this tick; NULL (never published) keeps the start
static void feed_mouse(tx_device* d, const tx_pointer* in) {
  if (!in) return;
  for (int i = 0; i < 3; i++) {
    double p = in->pos[i];
    d->pos[i] = p < -TX_POINTER_REACH_M ? -TX_POINTER_REACH_M : p > TX_POINTER_REACH_M ? TX_POINTER_REACH_M : p == p ? p : 0;
  }
  d->buttons = in->buttons >= 0 && in->buttons < 4294967296.0 ? (uint32_t)in->buttons : 0;
}

static bool read_mouse(tx_device* d, double t_s, tx_device_state* s) {
  memset(s, 0, sizeof *s);
  s->quat[0] = 1;
  s->t_ns = (int64_t)(t_s * 1e9);
  memcpy(s->pos, d->pos, sizeof s->pos);
  s->buttons = d->buttons;
  if (d->have_last)
    for (int i = 0; i < 3; i++) s->vel[i] = (s->pos[i] - d->last[i]) / d->period;
  memcpy(d->last, s->pos, sizeof d->last);
  d->have_last = true;
  return true; // a mouse is never silent
}

static void write_mouse(tx_device* d, const double force[3]) { (void)d, (void)force; } // no motors

static void close_mouse(tx_device* d) { free(d); }

const tx_device_backend tx_device_mouse = {"mouse",     open_mouse,  info_mouse,     read_mouse, write_mouse,
                                           close_mouse, TX_MOUSE_INPUT, feed_mouse};
