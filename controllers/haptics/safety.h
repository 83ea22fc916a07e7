// Internal: the force safety chain, the one place every force passes through
// on its way to a device. Each tick, in this order:
//   1. NaN/Inf guard: a non-finite force or position renders zero (counted)
//   2. clamp: |F| <= max_force
//   3. force rate: |F(k) - F(k-1)| <= max_force_rate * dt, an impulse limit
//   4. watchdog: a stale force model or a silent device ramps the force to
//      zero within ramp_s (<= 10 ms), and back up once both are fresh
//   5. workspace: outside the device's box no force pushes further out
// Stages 1, 2, 4 and 5 shape the target; the rate limit is applied to what
// leaves, against what left last tick, so no later stage can make a jump.
// The output is a convex mix of the last output and a clamped target, so it
// is finite and within the clamp whatever comes in.
#ifndef TX_CONTROLLERS_HAPTICS_SAFETY_H
#define TX_CONTROLLERS_HAPTICS_SAFETY_H

#include <tactus/haptics.h>

typedef struct tx_safety_limits {
  double max_force;          // N
  double max_force_rate;     // N/s; at least max_force / ramp_s, so a ramp is never slowed
  double model_timeout_s;    // s, a force model older than this is stale
  double device_timeout_s;   // s, a device silent for longer than this is lost
  double ramp_s;             // s, (0, 0.01]: time to ramp to zero
  double workspace_min[3];   // m
  double workspace_max[3];   // m
} tx_safety_limits;

typedef struct tx_safety_counts {
  uint64_t non_finite;   // ticks with a NaN or Inf in the force or position
  uint64_t clamped;      // ticks whose force was above max_force
  uint64_t rate_limited; // ticks whose change was above the impulse limit
  uint64_t watchdog;     // ticks with a stale model or a silent device
  uint64_t workspace;    // ticks outside the workspace with an outward force
} tx_safety_counts;

typedef struct tx_safety {
  double last[3]; // N, what left last tick
  double gain;    // watchdog gain in [0, 1]
  tx_safety_counts counts;
} tx_safety;

// limits from a device: its max force, a 5 ms ramp, 50 ms model and 4 ms device timeouts,
// so that a device gone silent feels no force 9 ms after its last sample
tx_safety_limits tx_safety_limits_from_device(const tx_device_info* info);
// 0 when every field is finite and consistent, else -1 with what is wrong in tx_error() ("max_force: ...")
int tx_safety_limits_check(const tx_safety_limits* l);
// the tighter of each limit, so that a scenario can only lower a device's limits
tx_safety_limits tx_safety_limits_lower(const tx_safety_limits* device, const tx_safety_limits* wanted);

void tx_safety_init(tx_safety* s);
// one tick of length dt (s): force in (N), device position (m), the ages (s)
// of the force model and of the last device sample; out is what may be sent
void tx_safety_apply(tx_safety* s, const tx_safety_limits* l, double dt, const double in[3], const double pos[3],
                     double model_age_s, double device_silent_s, double out[3]);

#endif
