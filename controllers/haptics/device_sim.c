// sim: a simulated impedance-type device held by a simulated hand that
// follows a scripted motion, so closed-loop haptics runs headless.
//
//   sim[:key=value,...]   keys: mass (kg), damping (N s/m), quantum (m),
//                         max_force (N), hand_stiffness (N/m),
//                         hand_damping (N s/m), hand (a scripted motion name
//                         or .csv file, default pierce-down); each key at
//                         most once, each value in the range that keeps the
//                         integration finite (tx_sim_device_def_check)
// The servo period is the haptics controller's tick. Each write holds the
// force for one period while the hand pulls toward where the motion will be
// at the end of it; the next read reports the device as the encoders see it.
#include "device.h"

#include "../../model/error.h"
#include "sim_device.h"

#include <tactus/model.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct tx_device {
  tx_sim_device sim;
  tx_device_handle hand; // the scripted motion the hand follows
  double t;              // s, time of the device's current state
};

static tx_device* open_sim(const char* arg, double period_s) {
  tx_sim_device_def def = tx_sim_device_def_default();
  def.period = period_s;
  char hand[512] = "pierce-down";
  if (!tx_sim_device_parse(arg, &def, hand, sizeof hand))
    return tx_error_prefix("device 'sim:%s'", arg), NULL;

  tx_device* d = calloc(1, sizeof *d);
  if (!d) return tx_set_error("out of memory"), NULL;
  char spec[600];
  snprintf(spec, sizeof spec, "scripted:%s", hand);
  if (tx_device_open(spec, period_s, &d->hand) || !tx_sim_device_init(&d->sim, &def)) {
    if (d->hand.device) tx_error_prefix("device 'sim:%s'", arg);
    else tx_error_prefix("device 'sim:%s': hand", arg);
    tx_device_close(&d->hand);
    free(d);
    return NULL;
  }
  // the device starts at rest where the hand starts
  tx_device_state start;
  d->hand.backend->read(d->hand.device, 0, &start);
  tx_sim_device_reset(&d->sim, start.pos, NULL);
  return d;
}

static void info_sim(const tx_device* d, tx_device_info* out) { tx_sim_device_info(&d->sim, out); }

static bool read_sim(tx_device* d, double t, tx_device_state* s) {
  (void)t; // the device's time advances with each write, one period at a time
  *s = d->sim.state;
  return true;
}

static void write_sim(tx_device* d, const double force[3]) {
  tx_device_state target;
  d->t += d->sim.def.period;
  d->hand.backend->read(d->hand.device, d->t, &target);
  tx_sim_device_step(&d->sim, force, target.pos);
}

static void close_sim(tx_device* d) {
  tx_device_close(&d->hand);
  free(d);
}

const tx_device_backend tx_device_sim = {"sim", open_sim, info_sim, read_sim, write_sim, close_sim, NULL, NULL};
