// tactus/haptics.h: what haptic devices and the force pipeline exchange.
//
// The collision controllers publish a local force model: a force F0 at the
// tool position x0 and a 3x3 stiffness K (dF/dx). The haptics controller
// renders F = F0 + K (x - x0) at the device rate, far above the rate of the
// physics behind it, then passes F through the safety chain before it reaches
// the device. Units are SI; frames are the world's (right-handed, Y up).
#ifndef TACTUS_HAPTICS_H
#define TACTUS_HAPTICS_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tx_device_state {
  double pos[3];    // tool point, m
  double quat[4];   // orientation, unit quaternion (w, x, y, z)
  double vel[3];    // linear velocity, m/s
  double grip;      // gripper angle, rad
  uint32_t buttons; // one bit per button
  int64_t t_ns;     // when the device sampled it, ns
} tx_device_state;

typedef struct tx_device_info {
  double max_force;        // N, the most the device can output
  double max_stiffness;    // N/m, nominal largest stable stiffness
  double damping;          // N s/m, the device's own physical damping b
  double workspace_min[3]; // m, box the tool point can reach
  double workspace_max[3]; // m
} tx_device_info;

// F = f0 + k (x - x0): published by collision, rendered by haptics. The
// component is f64, 1 x TX_FORCE_MODEL_COLS, in units TX_FORCE_MODEL_UNITS;
// the haptics controller reads it with tx_setup_read_expect, so a writer of
// another layout or other units is refused when the scenario is loaded.
typedef struct tx_force_model {
  double f0[3]; // N, the force at x0
  double x0[3]; // m, where f0 was computed
  double k[9];  // N/m, row-major dF/dx; a spring wall with normal n is -k n n^T
} tx_force_model;
#define TX_FORCE_MODEL_COLS 15
#define TX_FORCE_MODEL_UNITS "N, m, N/m"
#ifdef __cplusplus
static_assert(sizeof(tx_force_model) == TX_FORCE_MODEL_COLS * sizeof(double), "tx_force_model is 15 doubles");
#else
_Static_assert(sizeof(tx_force_model) == TX_FORCE_MODEL_COLS * sizeof(double), "tx_force_model is 15 doubles");
#endif

#ifdef __cplusplus
}
#endif
#endif
