// The published needle-force model form, and reference curves from it.
#include "insertion_model.h"

#include "../range_check.h"

#include "../../model/error.h"

#include <math.h>
#include <string.h>

tx_insertion_model tx_insertion_model_default(void) {
  return (tx_insertion_model){.a1 = 50, .a2 = 1e5, .puncture_depth = 2e-3, .cutting = 0.2, .friction = 25};
}

tx_insertion_motion tx_insertion_motion_default(void) {
  return (tx_insertion_motion){.start_depth = -1e-3, .max_depth = 4e-3, .speed = 3e-3, .wait = 0.2, .rate = 1000};
}

int tx_insertion_model_check(const tx_insertion_model* m) {
  if (tx_check_range("insertion model", "a1", m->a1, -1e6, false, 1e6, false, "N/m")) return -1;
  if (tx_check_range("insertion model", "a2", m->a2, -1e9, false, 1e9, false, "N/m^2")) return -1;
  if (tx_check_range("insertion model", "puncture_depth", m->puncture_depth, 0, true, 1, false, "m")) return -1;
  if (tx_check_range("insertion model", "cutting", m->cutting, 0, false, 1e3, false, "N")) return -1;
  if (tx_check_range("insertion model", "friction", m->friction, 0, false, 1e6, false, "N/m")) return -1;
  return 0;
}

int tx_insertion_motion_check(const tx_insertion_motion* m) {
  if (tx_check_range("insertion motion", "start_depth", m->start_depth, -1, false, 0, true, "m")) return -1;
  if (tx_check_range("insertion motion", "max_depth", m->max_depth, 0, true, 1, false, "m")) return -1;
  if (tx_check_range("insertion motion", "speed", m->speed, 1e-6, false, 10, false, "m/s")) return -1;
  if (tx_check_range("insertion motion", "wait", m->wait, 0, false, 60, false, "s")) return -1;
  if (tx_check_range("insertion motion", "rate", m->rate, 1000, false, 1e5, false, "Hz")) return -1;
  double rows = (2 * (m->max_depth - m->start_depth) / m->speed + 2 * m->wait) * m->rate;
  if (rows > TX_RECORDING_MAX_ROWS) return tx_check_fail("insertion motion: %.0f rows, more than %d", rows, TX_RECORDING_MAX_ROWS);
  return 0;
}

double tx_insertion_force(const tx_insertion_model* m, double z, int dir, bool punctured) {
  if (z <= 0) return 0;
  if (!punctured) return m->a1 * z + m->a2 * z * z;
  if (dir > 0) return m->cutting + m->friction * z;
  if (dir < 0) return -m->friction * z;
  return 0;
}

bool tx_insertion_generate(const tx_insertion_model* m, const tx_insertion_motion* mo, tx_recording* out) {
  memset(out, 0, sizeof *out);
  if (tx_insertion_model_check(m) || tx_insertion_motion_check(mo)) return false;
  const double travel = (mo->max_depth - mo->start_depth) / mo->speed;
  const double t_in = mo->wait, t_turn = t_in + travel, t_out = t_turn + travel, t_end = t_out + mo->wait;
  const size_t rows = (size_t)floor(t_end * mo->rate + 1e-9) + 1;
  if (!tx_recording_alloc(out, rows)) return false;
  bool punctured = false, inside = false;
  int last_dir = 0;
  for (size_t k = 0; k < rows; k++) {
    double t = (double)k / mo->rate, z;
    int dir;
    if (t < t_in) z = mo->start_depth, dir = 0;
    else if (t < t_turn) z = mo->start_depth + mo->speed * (t - t_in), dir = 1;
    else if (t < t_out) z = mo->max_depth - mo->speed * (t - t_turn), dir = -1;
    else z = mo->start_depth, dir = 0;
    tx_recording_row r = {t, z, {0, 0, 0}, TX_EVENT_NONE};
    if (dir > 0 && !punctured && z >= m->puncture_depth) punctured = true, r.event = TX_EVENT_PUNCTURE;
    if (z > 0 && !inside) inside = true, r.event = TX_EVENT_CONTACT;
    else if (z <= 0 && inside) inside = false, punctured = false, r.event = TX_EVENT_EXIT;
    else if (dir < 0 && last_dir > 0) r.event = TX_EVENT_RETRACT;
    r.f[1] = tx_insertion_force(m, z, dir, punctured);
    last_dir = dir;
    tx_recording_push(out, &r);
  }
  return true;
}
