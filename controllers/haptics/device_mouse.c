// mouse: a device driven by a window's mouse and keyboard, for people without
// a haptic device. It has no motors: the force it is sent is only shown.
#include "device.h"
#include "device_mouse.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// the channel: a sequence lock (odd while written) over relaxed atomic words
static _Atomic uint64_t seq;
static _Atomic uint64_t pos_bits[3], buttons_bits, force_bits[3];
static atomic_bool have_input, device_open;

static uint64_t bits(double x) {
  uint64_t b;
  memcpy(&b, &x, sizeof b);
  return b;
}
static double value(uint64_t b) {
  double x;
  memcpy(&x, &b, sizeof x);
  return x;
}

void tx_mouse_input_set(const double pos[3], uint32_t buttons) {
  // sequentially consistent throughout: a reader that sees any of these
  // stores sees the odd count before it, so it retries
  uint64_t s = atomic_load(&seq);
  atomic_store(&seq, s + 1);
  for (int i = 0; i < 3; i++) {
    double p = pos[i] < -TX_MOUSE_WORKSPACE_M ? -TX_MOUSE_WORKSPACE_M : pos[i] > TX_MOUSE_WORKSPACE_M ? TX_MOUSE_WORKSPACE_M : pos[i];
    atomic_store(&pos_bits[i], bits(p == p ? p : 0));
  }
  atomic_store(&buttons_bits, buttons);
  atomic_store(&seq, s + 2);
  atomic_store(&have_input, true);
}

bool tx_mouse_input_get(double pos[3], uint32_t* buttons) {
  if (!atomic_load(&have_input)) return false;
  for (;;) {
    uint64_t s0 = atomic_load(&seq);
    for (int i = 0; i < 3; i++) pos[i] = value(atomic_load(&pos_bits[i]));
    *buttons = (uint32_t)atomic_load(&buttons_bits);
    if (!(s0 & 1) && atomic_load(&seq) == s0) return true;
  }
}

void tx_mouse_force_get(double force[3]) {
  for (int i = 0; i < 3; i++) force[i] = value(atomic_load_explicit(&force_bits[i], memory_order_relaxed));
}

bool tx_mouse_device_open(void) { return atomic_load(&device_open); }

struct tx_device {
  double period;   // s, the haptics tick
  double last[3];  // m, the position read last
  bool have_last;
};

static tx_device* open_mouse(const char* arg, double period_s, char* err, size_t n) {
  if (*arg) return snprintf(err, n, "device 'mouse:%s': takes no options", arg), NULL;
  if (atomic_exchange(&device_open, true)) return snprintf(err, n, "device 'mouse': only one per run"), NULL;
  tx_device* d = calloc(1, sizeof *d);
  if (!d) {
    atomic_store(&device_open, false);
    return snprintf(err, n, "out of memory"), NULL;
  }
  d->period = period_s;
  return d;
}

static void info_mouse(const tx_device* d, tx_device_info* out) {
  (void)d;
  // nothing is felt; the limits are those of a small desktop device, so that safety behaves as with one
  *out = (tx_device_info){.max_force = 3.3, .max_stiffness = 1000, .damping = 0,
                          .workspace_min = {-TX_MOUSE_WORKSPACE_M, -TX_MOUSE_WORKSPACE_M, -TX_MOUSE_WORKSPACE_M},
                          .workspace_max = {TX_MOUSE_WORKSPACE_M, TX_MOUSE_WORKSPACE_M, TX_MOUSE_WORKSPACE_M}};
}

static bool read_mouse(tx_device* d, double t_s, tx_device_state* s) {
  memset(s, 0, sizeof *s);
  s->quat[0] = 1;
  s->t_ns = (int64_t)(t_s * 1e9);
  s->pos[1] = 0.02; // above the origin until the window moves it
  uint32_t buttons = 0;
  tx_mouse_input_get(s->pos, &buttons);
  s->buttons = buttons;
  if (d->have_last)
    for (int i = 0; i < 3; i++) s->vel[i] = (s->pos[i] - d->last[i]) / d->period;
  memcpy(d->last, s->pos, sizeof d->last);
  d->have_last = true;
  return true; // a mouse is never silent
}

static void write_mouse(tx_device* d, const double force[3]) {
  (void)d;
  for (int i = 0; i < 3; i++) atomic_store_explicit(&force_bits[i], bits(force[i]), memory_order_relaxed);
}

static void close_mouse(tx_device* d) {
  free(d);
  atomic_store(&device_open, false);
}

const tx_device_backend tx_device_mouse = {"mouse", open_mouse, info_mouse, read_mouse, write_mouse, close_mouse};
