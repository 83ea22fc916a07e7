// replay: a device that plays back a recording (deviceN.bin), one recorded
// tick per haptics tick, with the recorded device's limits. Run in lockstep,
// the same scenario then renders the recorded forces bit for bit. `tactus run`
// without --duration ends the run with the recording; given a longer one, the
// device falls silent after the last record and the watchdog fades the force
// out. A recording cut short (a killed run) replays its whole blocks, with one
// warning; a corrupt or implausible one is refused.
#include "device.h"
#include "recorder.h"

#include "../../model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

struct tx_device {
  tx_record_header header;
  tx_record* records;
  size_t count;
};
// a recording cut short is not refused; the command that names it (tactus
// run) shows tx_record_file.cut_short as a warning: a device prints nothing

static tx_device* open_replay(const char* path, double period_s) {
  tx_device* d = calloc(1, sizeof *d);
  if (!d) return tx_set_error("out of memory"), NULL;
  tx_record_file rf;
  if (tx_record_load(path, &rf)) return free(d), NULL;
  d->header = rf.header, d->records = rf.records, d->count = rf.count;
  double rate = 1.0 / period_s;
  if (fabs(d->header.rate_hz - rate) > 1e-9 * rate) {
    tx_set_error("%s: recorded at %g Hz, replayed at %g Hz: set the haptics rate_hz to match", path,
             d->header.rate_hz, rate);
    free(d->records);
    free(d);
    return NULL;
  }
  return d;
}

static void info_replay(const tx_device* d, tx_device_info* out) { *out = d->header.device; }

static bool read_replay(tx_device* d, double t, tx_device_state* s) {
  double k = round((t - d->records[0].t_s) * d->header.rate_hz);
  bool live = k >= 0 && k < (double)d->count;
  const tx_record* r = &d->records[k < 0 ? 0 : live ? (size_t)k : d->count - 1];
  *s = (tx_device_state){{r->pos[0], r->pos[1], r->pos[2]}, {r->quat[0], r->quat[1], r->quat[2], r->quat[3]},
                         {r->vel[0], r->vel[1], r->vel[2]}, r->grip, (uint32_t)r->buttons, (int64_t)llround(t * 1e9)};
  return live;
}

static void write_replay(tx_device* d, const double force[3]) { (void)d, (void)force; }

static void close_replay(tx_device* d) {
  free(d->records);
  free(d);
}

const tx_device_backend tx_device_replay = {"replay", open_replay, info_replay, read_replay, write_replay, close_replay, NULL, NULL};
