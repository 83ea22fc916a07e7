// input.window: the window's latest mouse and keyboard input, published as
// window.pointer (see window_input.h for why a view does not write it).
#include "window_input.h"

#include <tactus/components.h>

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

// the channel: a sequence lock (odd while written) over atomic words
static _Atomic uint64_t seq;
static _Atomic uint64_t pos_bits[3], buttons_bits;
static atomic_bool have_input;

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

void tx_window_input_set(const double pos[3], uint32_t buttons) {
  // sequentially consistent throughout: a reader that sees any of these
  // stores sees the odd count before it, so it retries
  uint64_t s = atomic_load(&seq);
  atomic_store(&seq, s + 1);
  for (int i = 0; i < 3; i++) {
    double p = pos[i] < -TX_POINTER_REACH_M ? -TX_POINTER_REACH_M : pos[i] > TX_POINTER_REACH_M ? TX_POINTER_REACH_M : pos[i];
    atomic_store(&pos_bits[i], bits(p == p ? p : 0));
  }
  atomic_store(&buttons_bits, buttons);
  atomic_store(&seq, s + 2);
  atomic_store(&have_input, true);
}

bool tx_window_input_get(double pos[3], uint32_t* buttons) {
  if (!atomic_load(&have_input)) return false;
  for (;;) {
    uint64_t s0 = atomic_load(&seq);
    for (int i = 0; i < 3; i++) pos[i] = value(atomic_load(&pos_bits[i]));
    *buttons = (uint32_t)atomic_load(&buttons_bits);
    if (!(s0 & 1) && atomic_load(&seq) == s0) return true;
  }
}

void tx_window_input_reset(void) { atomic_store(&have_input, false); }

typedef struct input {
  tx_port pointer;
} input;

static int configure(tx_setup* s, void** self) {
  input* in = calloc(1, sizeof *in);
  if (!in) return -1;
  *self = in;
  in->pointer = tx_setup_write(s, &TX_COMPONENT_OF("window.pointer", tx_pointer, 1));
  return 0;
}

static int init(tx_ctx* c, void* self) {
  (void)c, (void)self;
  tx_window_input_reset(); // what an earlier run's window left is not this run's input
  return 0;
}

// nothing is published until the window has had input: a reader then sees
// seq 0 and keeps its own starting point
static void step(tx_ctx* c, void* self) {
  input* in = self;
  double pos[3];
  uint32_t buttons;
  if (!tx_window_input_get(pos, &buttons)) return;
  tx_pointer* p = tx_write(c, in->pointer);
  memcpy(p->pos, pos, sizeof p->pos);
  p->buttons = buttons;
}

static void fini(void* self) { free(self); }

static const tx_param_def no_params[1]; // an empty table: it takes no parameter

const tx_controller_class tx_window_input = {
    .type = "input.window",
    .summary = "the window's mouse and keyboard as window.pointer, for the mouse device (added with --view window)",
    .configure = configure,
    .init = init,
    .step = step,
    .fini = fini,
    .params = no_params,
    .nparams = 0,
};
