// replay: a device that plays back a recording (deviceN.bin), one recorded
// tick per haptics tick, with the recorded device's limits. Run in lockstep,
// the same scenario then renders the recorded forces bit for bit. `tactus run`
// without --duration ends the run with the recording; given a longer one, the
// device falls silent after the last record and the watchdog fades the force
// out. A recording cut short (a killed run) replays its whole blocks, with one
// warning; a corrupt or implausible one is refused. The reset lines of the
// session's controls.csv, beside the recording, are honoured: when the replay
// reaches a reset's time it resets the run (tx_system_reset), as the trainer
// did, so that a replayed session with a reset reproduces the original
// (docs/trainer.md): in --lockstep bit for bit but for the haptics tick at
// the reset's time.
#include "device.h"
#include "recorder.h"

#include "../system.h"

#include "../../model/error.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RESETS_MAX 4096 // reset lines honoured in one recording

struct tx_device {
  tx_record_header header;
  tx_record* records;
  size_t count;
  double* resets; // s, the reset lines' times in controls.csv, in order
  int nresets, next;
};

// the reset lines of DIR/controls.csv, where DIR holds the recording; a missing file is none.
// 0, or -1 with the file, line and what is wrong in tx_error()
static int load_resets(tx_device* d, const char* bin) {
  char path[4200];
  const char* slash = strrchr(bin, '/');
  int dirlen = slash ? (int)(slash - bin) : 1;
  if (snprintf(path, sizeof path, "%.*s/controls.csv", dirlen, slash ? bin : ".") >= (int)sizeof path)
    return tx_set_error("%s: path too long", bin), -1;
  FILE* f = fopen(path, "r");
  if (!f) return errno == ENOENT ? 0 : (tx_set_error("%s: %s", path, strerror(errno)), -1);
  char line[512];
  int n = 0;
  double last = -INFINITY;
  while (fgets(line, sizeof line, f)) {
    n++;
    if (n == 1 && strncmp(line, "t_s,action,value", 16) == 0) continue;
    char action[256];
    double t;
    if (sscanf(line, "%lf,%255[^,]", &t, action) != 2 || !isfinite(t) || t < 0) {
      fclose(f);
      return tx_set_error("%s: line %d: expected t_s,action,value", path, n), -1;
    }
    if (strcmp(action, "reset") != 0) continue; // pauses, steps, the time scale, tunes: not replayed
    if (t < last || d->nresets == RESETS_MAX) {
      fclose(f);
      return tx_set_error("%s: line %d: %s", path, n, t < last ? "a reset before the one above it" : "too many resets"), -1;
    }
    if (!d->resets && !(d->resets = malloc(RESETS_MAX * sizeof *d->resets))) {
      fclose(f);
      return tx_set_error("out of memory"), -1;
    }
    d->resets[d->nresets++] = last = t;
  }
  fclose(f);
  return 0;
}
// a recording cut short is not refused; the command that names it (tactus
// run) shows tx_record_file.cut_short as a warning: a device prints nothing

static tx_device* open_replay(const char* path, double period_s) {
  tx_device* d = calloc(1, sizeof *d);
  if (!d) return tx_set_error("out of memory"), NULL;
  tx_record_file rf;
  if (tx_record_load(path, &rf)) return free(d), NULL;
  d->header = rf.header, d->records = rf.records, d->count = rf.count;
  if (load_resets(d, path)) {
    free(d->records);
    free(d->resets);
    free(d);
    return NULL;
  }
  double rate = 1.0 / period_s;
  if (fabs(d->header.rate_hz - rate) > 1e-9 * rate) {
    tx_set_error("%s: recorded at %g Hz, replayed at %g Hz: set the haptics rate_hz to match", path,
             d->header.rate_hz, rate);
    free(d->records);
    free(d->resets);
    free(d);
    return NULL;
  }
  return d;
}

static void info_replay(const tx_device* d, tx_device_info* out) { *out = d->header.device; }

static bool read_replay(tx_device* d, double t, tx_device_state* s) {
  // a reset logged at t_r (to the log's ns) is asked for at the tick at t_r, the last of the ticks at
  // that time (the fastest group runs last), so every simulated controller is rebuilt before its next
  // tick, as in the session; only this tick still reads the model from before it. None at the start.
  for (; t > 0 && d->next < d->nresets && t >= d->resets[d->next] - 1e-9; d->next++) {
    tx_system* sys = tx_system_running();
    if (sys) (void)tx_system_reset(sys);
  }
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
  free(d->resets);
  free(d);
}

const tx_device_backend tx_device_replay = {"replay", open_replay, info_replay, read_replay, write_replay, close_replay, NULL, NULL};
