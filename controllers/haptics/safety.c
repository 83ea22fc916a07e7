// The force safety chain; see safety.h for the order and why.
#include "safety.h"

#include "../../model/error.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

tx_safety_limits tx_safety_limits_from_device(const tx_device_info* info) {
  tx_safety_limits l = {
      .max_force = info->max_force,
      .ramp_s = 0.005,
      .model_timeout_s = 0.050, // three physics frames at 60 Hz
      .device_timeout_s = 0.004, // 4 lost samples at 1 kHz: with the ramp, zero within 10 ms of silence
  };
  l.max_force_rate = l.max_force / l.ramp_s * 2; // twice what a full ramp needs
  for (int i = 0; i < 3; i++) {
    l.workspace_min[i] = info->workspace_min[i];
    l.workspace_max[i] = info->workspace_max[i];
  }
  return l;
}

int tx_safety_limits_check(const tx_safety_limits* l) {
  if (!(isfinite(l->max_force) && l->max_force > 0)) return tx_set_error("max_force: must be a positive number of newtons"), -1;
  if (!(isfinite(l->ramp_s) && l->ramp_s > 0 && l->ramp_s <= 0.010)) return tx_set_error("ramp_s: must be in (0, 0.01] s"), -1;
  if (!(isfinite(l->max_force_rate) && l->max_force_rate * l->ramp_s >= l->max_force * (1 - 1e-12)))
    return tx_set_error("max_force_rate: must be at least max_force / ramp_s, or the ramp to zero would be slowed"), -1;
  if (!(isfinite(l->model_timeout_s) && l->model_timeout_s > 0)) return tx_set_error("model_timeout_s: must be positive"), -1;
  if (!(isfinite(l->device_timeout_s) && l->device_timeout_s > 0)) return tx_set_error("device_timeout_s: must be positive"), -1;
  for (int i = 0; i < 3; i++)
    if (!(isfinite(l->workspace_min[i]) && isfinite(l->workspace_max[i]) && l->workspace_min[i] < l->workspace_max[i]))
      return tx_set_error("workspace: each min must be a number below its max"), -1;
  return 0;
}

tx_safety_limits tx_safety_limits_lower(const tx_safety_limits* d, const tx_safety_limits* w) {
  tx_safety_limits l = *d;
  l.max_force = fmin(d->max_force, w->max_force);
  l.max_force_rate = fmin(d->max_force_rate, w->max_force_rate);
  l.model_timeout_s = fmin(d->model_timeout_s, w->model_timeout_s);
  l.device_timeout_s = fmin(d->device_timeout_s, w->device_timeout_s);
  l.ramp_s = fmin(d->ramp_s, w->ramp_s);
  for (int i = 0; i < 3; i++) {
    l.workspace_min[i] = fmax(d->workspace_min[i], w->workspace_min[i]);
    l.workspace_max[i] = fmin(d->workspace_max[i], w->workspace_max[i]);
  }
  return l;
}

void tx_safety_init(tx_safety* s) { *s = (tx_safety){.gain = 1}; }

// |v| without overflow for huge components or underflow for tiny ones
static double norm(const double v[3]) {
  double m = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
  if (m == 0 || !isfinite(m)) return m;
  double a = v[0] / m, b = v[1] / m, c = v[2] / m;
  return m * sqrt(a * a + b * b + c * c);
}

// scale v so that |v| <= limit, keeping its direction; true if it had to
static bool clamp_norm(double v[3], double limit) {
  double n = norm(v);
  if (n <= limit) return false;
  double scale = limit / n * (1 - 4 * DBL_EPSILON); // strictly inside after rounding
  for (int i = 0; i < 3; i++) v[i] *= scale;
  return true;
}

void tx_safety_apply(tx_safety* s, const tx_safety_limits* l, double dt, const double in[3], const double pos[3],
                     double model_age_s, double device_silent_s, double out[3]) {
  if (!(isfinite(dt) && dt > 0)) dt = 0; // no time, no change
  double target[3] = {in[0], in[1], in[2]};

  // 1. non-finite force or position: render nothing
  bool finite = true;
  for (int i = 0; i < 3; i++) finite = finite && isfinite(in[i]) && isfinite(pos[i]);
  if (!finite) {
    s->counts.non_finite++;
    target[0] = target[1] = target[2] = 0;
  }

  // 2. clamp the magnitude, keeping the direction
  if (clamp_norm(target, l->max_force)) s->counts.clamped++;

  // 4. watchdog: fade out while the model is stale or the device silent, fade back in after
  bool fresh = model_age_s <= l->model_timeout_s && device_silent_s <= l->device_timeout_s; // NaN ages are stale
  if (!fresh) s->counts.watchdog++;
  double step = dt / l->ramp_s;
  s->gain = fresh ? fmin(1, s->gain + step) : fmax(0, s->gain - step);
  if (s->gain < 1e-9) s->gain = 0; // n steps of 1/n reach zero, not 1e-16
  for (int i = 0; i < 3; i++) target[i] *= s->gain;

  // 5. workspace: outside the box, drop components that push further out
  bool outward = false;
  for (int i = 0; finite && i < 3; i++) {
    if ((pos[i] < l->workspace_min[i] && target[i] < 0) || (pos[i] > l->workspace_max[i] && target[i] > 0)) {
      target[i] = 0;
      outward = true;
    }
  }
  if (outward) s->counts.workspace++;

  // 3. impulse limit on what leaves, against what left last tick
  double delta[3] = {target[0] - s->last[0], target[1] - s->last[1], target[2] - s->last[2]};
  if (clamp_norm(delta, l->max_force_rate * dt)) s->counts.rate_limited++;
  for (int i = 0; i < 3; i++) out[i] = s->last[i] + delta[i];
  // a convex mix of two forces within the clamp is within it, but for rounding
  clamp_norm(out, l->max_force);
  for (int i = 0; i < 3; i++) s->last[i] = out[i];
}
