// sim: a simulated impedance-type device held by a simulated hand that
// follows a scripted motion, so closed-loop haptics runs headless.
//
//   sim[:key=value,...]   keys: mass (kg), damping (N s/m), quantum (m),
//                         max_force (N), hand_stiffness (N/m),
//                         hand_damping (N s/m), hand (a scripted motion name
//                         or .csv file, default pierce-down)
// The servo period is the haptics controller's tick. Each write holds the
// force for one period while the hand pulls toward where the motion will be
// at the end of it; the next read reports the device as the encoders see it.
#include "device.h"
#include "sim_device.h"

#include <tactus/model.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct tx_device {
  tx_sim_device sim;
  tx_device_handle hand; // the scripted motion the hand follows
  double t;              // s, time of the device's current state
};

// "key=value" into the definition; a message on failure
static const char* set_key(tx_sim_device_def* d, char* kv, char* hand, size_t hand_size) {
  char* eq = strchr(kv, '=');
  if (!eq) return "expected key=value";
  *eq = 0;
  const char* value = eq + 1;
  if (strcmp(kv, "hand") == 0) {
    if (snprintf(hand, hand_size, "%s", value) >= (int)hand_size) return "hand: too long";
    return NULL;
  }
  struct { const char* key; double* field; } keys[] = {
      {"mass", &d->mass}, {"damping", &d->damping}, {"quantum", &d->quantum}, {"max_force", &d->max_force},
      {"hand_stiffness", &d->hand_stiffness}, {"hand_damping", &d->hand_damping}};
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
    if (strcmp(kv, keys[i].key) != 0) continue;
    char* end;
    errno = 0;
    *keys[i].field = strtod(value, &end);
    return (*value && !*end && !errno) ? NULL : "expected a number";
  }
  return "unknown key (known: mass, damping, quantum, max_force, hand_stiffness, hand_damping, hand)";
}

static tx_device* open_sim(const char* arg, double period_s, char* err, size_t n) {
  tx_sim_device_def def = tx_sim_device_def_default();
  def.period = period_s;
  char hand[512] = "pierce-down", copy[1024];
  if (snprintf(copy, sizeof copy, "%s", arg) >= (int)sizeof copy) return snprintf(err, n, "device 'sim': spec too long"), NULL;
  char* save = NULL;
  for (char* kv = strtok_r(copy, ",", &save); kv; kv = strtok_r(NULL, ",", &save)) {
    char key[64];
    snprintf(key, sizeof key, "%.*s", (int)strcspn(kv, "="), kv);
    const char* problem = set_key(&def, kv, hand, sizeof hand);
    if (problem) return snprintf(err, n, "device 'sim:%s': %s: %s", arg, key, problem), NULL;
  }
  const char* bad = tx_sim_device_def_check(&def);
  if (bad) return snprintf(err, n, "device 'sim:%s': %s", arg, bad), NULL;

  tx_device* d = calloc(1, sizeof *d);
  if (!d) return snprintf(err, n, "out of memory"), NULL;
  char spec[600];
  snprintf(spec, sizeof spec, "scripted:%s", hand);
  if (tx_device_open(spec, period_s, &d->hand, err, n) || !tx_sim_device_init(&d->sim, &def)) {
    if (d->hand.device) snprintf(err, n, "device 'sim:%s': %s", arg, tx_error());
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

const tx_device_backend tx_device_sim = {"sim", open_sim, info_sim, read_sim, write_sim, close_sim};
