// Simulated impedance-type haptic device: three independent axes, exact
// integration of the linear dynamics over each zero-order-hold period.
#include "sim_device.h"

#include "../range_check.h"

#include "../../model/error.h"

#include <math.h>
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

tx_sim_device_def tx_sim_device_def_default(void) {
  return (tx_sim_device_def){
      .mass = 0.045,
      .damping = 0.3,
      .period = 1e-3,
      .quantum = 2.3e-5,
      .max_force = 3.3,
      .nominal_stiffness = 500,
      .hand_stiffness = 200,
      .hand_damping = 2,
      .workspace_min = {-0.08, -0.06, -0.035},
      .workspace_max = {0.08, 0.06, 0.035},
  };
}

// NULL if lo <= v <= hi (strictly above lo when open_lo) and finite
static int range(const char* name, double v, double lo, bool open_lo, double hi, const char* units) {
  return tx_check_range("sim device", name, v, lo, open_lo, hi, false, units);
}

int tx_sim_device_def_check(const tx_sim_device_def* d) {
  // the ranges span every device of this kind, from a fingertip to an arm; a
  // mass below a gram would make k T / m and b T / m so large that the
  // transition over one period under- and overflows
  if (range("mass", d->mass, 1e-3, false, 100, "kg")) return -1;
  if (range("damping", d->damping, 0, false, 1e3, "N s/m")) return -1;
  if (range("period", d->period, 1e-5, false, 0.1, "s")) return -1;
  if (range("quantum", d->quantum, 0, false, 1e-3, "m")) return -1;
  if (range("max_force", d->max_force, 0, true, 1e3, "N")) return -1;
  if (range("nominal_stiffness", d->nominal_stiffness, 0, true, 1e6, "N/m")) return -1;
  if (range("hand_stiffness", d->hand_stiffness, 0, false, 1e6, "N/m")) return -1;
  if (range("hand_damping", d->hand_damping, 0, false, 1e3, "N s/m")) return -1;
  for (int i = 0; i < 3; i++) {
    if (range("workspace_min", d->workspace_min[i], -10, false, 10, "m")) return -1;
    if (range("workspace_max", d->workspace_max[i], -10, false, 10, "m")) return -1;
    if (!(d->workspace_min[i] < d->workspace_max[i]))
      return tx_check_fail("sim device: workspace_min[%d] = %g m must be below workspace_max[%d] = %g m", i,
                           d->workspace_min[i], i, d->workspace_max[i]);
  }
  return 0;
}

// at most cap - 1 bytes of s into out, each control byte as '?': a message stays one line
static const char* shown(const char* s, size_t len, char* out, size_t cap) {
  if (len >= cap) len = cap - 1;
  for (size_t i = 0; i < len; i++) out[i] = iscntrl((unsigned char)s[i]) ? '?' : s[i];
  out[len] = 0;
  return out;
}

bool tx_sim_device_parse(const char* spec, tx_sim_device_def* d, char* hand, size_t hand_size) {
  struct {
    const char* key;
    double* field;
  } const keys[] = {{"mass", &d->mass},
                    {"damping", &d->damping},
                    {"quantum", &d->quantum},
                    {"max_force", &d->max_force},
                    {"hand_stiffness", &d->hand_stiffness},
                    {"hand_damping", &d->hand_damping},
                    {"hand", NULL}};
  enum { KEYS = sizeof keys / sizeof keys[0] };
  bool seen[KEYS] = {false};
  for (const char* kv = spec; *kv;) {
    size_t len = strcspn(kv, ","), klen = strcspn(kv, "=");
    if (klen > len) klen = len;
    const char* next = kv[len] ? kv + len + 1 : kv + len;
    if (len == 0) { // "a,,b" or a trailing comma: nothing to set
      kv = next;
      continue;
    }
    char key[65]; // as written, for the message
    shown(kv, klen, key, sizeof key);
    if (klen == len) return tx_set_error("%s: expected key=value", key), false;
    size_t k = 0;
    while (k < KEYS && !(strlen(keys[k].key) == klen && strncmp(kv, keys[k].key, klen) == 0)) k++;
    if (k == KEYS)
      return tx_set_error("%s: unknown key (known: mass, damping, quantum, max_force, hand_stiffness, "
                              "hand_damping, hand)", key), false;
    // the second of two values would silently win
    if (seen[k]) return tx_set_error("%s: given twice", keys[k].key), false;
    seen[k] = true;
    const char* value = kv + klen + 1;
    size_t vlen = len - klen - 1;
    if (!keys[k].field) {
      if (vlen == 0) return tx_set_error("hand: expected a scripted motion or a .csv file"), false;
      if (vlen >= hand_size) return tx_set_error("hand: too long"), false;
      memcpy(hand, value, vlen);
      hand[vlen] = 0;
    } else {
      char num[64], text[64];
      if (vlen == 0 || vlen >= sizeof num) return tx_set_error("%s: expected a number", keys[k].key), false;
      memcpy(num, value, vlen);
      num[vlen] = 0;
      shown(num, vlen, text, sizeof text);
      char* end;
      errno = 0;
      double v = strtod(num, &end);
      if (*end || end == num || isspace((unsigned char)num[0]))
        return tx_set_error("%s: expected a number, got '%s'", keys[k].key, text), false;
      if (errno == ERANGE) return tx_set_error("%s: %s is out of range", keys[k].key, text), false;
      *keys[k].field = v;
    }
    kv = next;
  }
  return tx_sim_device_def_check(d) == 0;
}

static void mat3_mul(const double a[9], const double b[9], double out[9]) {
  double r[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) r[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
  memcpy(out, r, sizeof r);
}

// exp(a) by scaling and squaring with a Taylor series; a is small and well
// conditioned here (a damped oscillator over one period)
static void mat3_exp(const double a[9], double out[9]) {
  double norm = 0;
  for (int i = 0; i < 3; i++) {
    double row = fabs(a[3 * i]) + fabs(a[3 * i + 1]) + fabs(a[3 * i + 2]);
    if (row > norm) norm = row;
  }
  int squarings = 0;
  while (norm > 0.25 && squarings < 60) norm *= 0.5, squarings++;
  double s[9], term[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, sum[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double scale = ldexp(1.0, -squarings);
  for (int i = 0; i < 9; i++) s[i] = a[i] * scale;
  // with |s| <= 1/4 the 18th term is below 1e-26 of the first
  for (int n = 1; n <= 18; n++) {
    mat3_mul(term, s, term);
    for (int i = 0; i < 9; i++) term[i] /= n, sum[i] += term[i];
  }
  for (int k = 0; k < squarings; k++) mat3_mul(sum, sum, sum);
  memcpy(out, sum, sizeof sum);
}

static double quantize(double x, double q) { return q > 0 ? q * floor(x / q + 0.5) : x; }

bool tx_sim_device_init(tx_sim_device* dev, const tx_sim_device_def* def) {
  if (tx_sim_device_def_check(def)) return false;
  // state (x, v, u) with u the held input F + kh xt + bh vt; exp of the
  // augmented matrix gives the transition and the input response at once
  double m = def->mass, T = def->period;
  double a[9] = {0, T, 0, -def->hand_stiffness / m * T, -(def->damping + def->hand_damping) / m * T, T / m, 0, 0, 0};
  double e3[9];
  mat3_exp(a, e3);
  // a passive system's transition has both eigenvalues within the unit circle
  // (Jury: |det| <= 1 and |trace| <= 1 + det); the ranges of the check keep
  // it so, and this makes sure no corner of them steps toward infinity
  double tr = e3[0] + e3[4], det = e3[0] * e3[4] - e3[1] * e3[3];
  bool finite = isfinite(tr) && isfinite(det) && isfinite(e3[2]) && isfinite(e3[5]);
  if (!finite || fabs(det) > 1 + 1e-9 || fabs(tr) > 1 + det + 1e-9) {
    tx_set_error("sim device: mass = %g kg, damping = %g N s/m, hand_stiffness = %g N/m and hand_damping = %g N s/m "
                 "at a period of %g s cannot be integrated stably: raise mass or lower the others",
                 m, def->damping, def->hand_stiffness, def->hand_damping, T);
    return false;
  }
  *dev = (tx_sim_device){.def = *def};
  dev->phi[0] = e3[0], dev->phi[1] = e3[1], dev->phi[2] = e3[3], dev->phi[3] = e3[4];
  dev->gam[0] = e3[2], dev->gam[1] = e3[5];
  tx_sim_device_reset(dev, NULL, NULL);
  return true;
}

void tx_sim_device_reset(tx_sim_device* dev, const double pos[3], const double vel[3]) {
  double T = dev->def.period, q = dev->def.quantum;
  for (int i = 0; i < 3; i++) {
    dev->x[i] = pos ? pos[i] : 0;
    dev->v[i] = vel ? vel[i] : 0;
    dev->target[i] = dev->x[i];
    dev->target_vel[i] = 0;
    dev->force[i] = 0;
    // the encoder reading one period ago, had the device moved at vel
    double before = quantize(dev->x[i] - dev->v[i] * T, q);
    dev->state.pos[i] = quantize(dev->x[i], q);
    dev->state.vel[i] = (dev->state.pos[i] - before) / T;
    dev->q_prev[i] = dev->state.pos[i];
  }
  dev->state.quat[0] = 1, dev->state.quat[1] = dev->state.quat[2] = dev->state.quat[3] = 0;
  dev->state.grip = 0;
  dev->state.buttons = 0;
  dev->state.t_ns = 0;
  dev->work = 0;
  dev->ticks = 0;
  dev->clamped = 0;
  dev->rejected = 0;
}

void tx_sim_device_place_hand(tx_sim_device* dev, const double target[3]) {
  for (int i = 0; i < 3; i++) {
    if (isfinite(target[i])) dev->target[i] = target[i];
    dev->target_vel[i] = 0;
  }
}

void tx_sim_device_step(tx_sim_device* dev, const double force[3], const double hand_target[3]) {
  const tx_sim_device_def* d = &dev->def;
  double T = d->period;
  // the device's own limits: a command it cannot read is dropped, one above max is scaled down
  double f[3] = {0, 0, 0};
  if (force) {
    if (isfinite(force[0]) && isfinite(force[1]) && isfinite(force[2])) {
      f[0] = force[0], f[1] = force[1], f[2] = force[2];
      double n = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
      if (n > d->max_force) {
        double s = d->max_force / n;
        f[0] *= s, f[1] *= s, f[2] *= s;
        dev->clamped++;
      }
    } else {
      dev->rejected++;
    }
  }
  if (hand_target) {
    for (int i = 0; i < 3; i++) {
      double t = isfinite(hand_target[i]) ? hand_target[i] : dev->target[i];
      dev->target_vel[i] = (t - dev->target[i]) / T;
      dev->target[i] = t;
    }
  } else {
    dev->target_vel[0] = dev->target_vel[1] = dev->target_vel[2] = 0;
  }
  // exact motion over one period with everything on the right-hand side held
  for (int i = 0; i < 3; i++) {
    double u = f[i] + d->hand_stiffness * dev->target[i] + d->hand_damping * dev->target_vel[i];
    double x = dev->phi[0] * dev->x[i] + dev->phi[1] * dev->v[i] + dev->gam[0] * u;
    double v = dev->phi[2] * dev->x[i] + dev->phi[3] * dev->v[i] + dev->gam[1] * u;
    dev->work += f[i] * (x - dev->x[i]); // the held force times the distance it moved
    dev->x[i] = x, dev->v[i] = v;
    dev->force[i] = f[i];
  }
  // sample as the device would: quantized position, velocity by difference
  dev->ticks++;
  for (int i = 0; i < 3; i++) {
    double p = quantize(dev->x[i], d->quantum);
    dev->state.vel[i] = (p - dev->q_prev[i]) / T;
    dev->state.pos[i] = p;
    dev->q_prev[i] = p;
  }
  dev->state.t_ns = (int64_t)llround((double)dev->ticks * T * 1e9);
}

void tx_sim_device_info(const tx_sim_device* dev, tx_device_info* info) {
  info->max_force = dev->def.max_force;
  info->max_stiffness = dev->def.nominal_stiffness;
  info->damping = dev->def.damping;
  for (int i = 0; i < 3; i++) {
    info->workspace_min[i] = dev->def.workspace_min[i];
    info->workspace_max[i] = dev->def.workspace_max[i];
  }
}
