// Internal: a simulated impedance-type haptic device (Phantom Omni / Touch
// class) held by a simulated hand, so closed-loop haptics runs headless.
//
// Each of the three axes moves on its own:
//
//     m x'' + b x' = F + kh (xt - x) + bh (vt - x')
//
// F is the force commanded at the last servo tick, clamped by the device and
// held for one period T (zero-order hold); the hand is a spring-damper (kh,
// bh) pulling toward a target xt that the caller moves each tick. Between
// ticks the force and the target are constant, so the motion over one period
// is integrated exactly (the transition matrix of the linear system is
// computed once at init). The device reports what real hardware reports:
// positions rounded to the encoder quantum, and a velocity by backward
// difference of those positions. There is no Coulomb friction: a real
// device has a little, which hides small limit cycles; without it the
// viscous damping b alone sets what a sampled wall can do.
//
//     tx_sim_device_def d = tx_sim_device_def_default();
//     d.period = 0.25e-3;
//     tx_sim_device dev;
//     if (!tx_sim_device_init(&dev, &d)) puts(tx_error());
//     for (;;) {
//       double f[3];  // computed from dev.state.pos and dev.state.vel
//       tx_sim_device_step(&dev, f, hand_target);  // advances by exactly T
//     }
//
// Nothing here allocates; the device lives in the caller's struct.
#ifndef TX_CONTROLLERS_HAPTICS_SIM_DEVICE_H
#define TX_CONTROLLERS_HAPTICS_SIM_DEVICE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tactus/haptics.h"

typedef struct tx_sim_device_def {
  double mass;              // kg, apparent mass at the tool point, each axis, [0.001, 100]; 0.045: the tip inertia of this class
  double damping;           // N s/m, physical viscous damping b; 0.3: makes 2b/T = 600 N/m at 1 kHz, just above the nominal stiffness
  double period;            // s, servo period T; 1e-3: the 1 kHz servo loop of these devices
  double quantum;           // m, encoder resolution at the tip, 0 = ideal; 2.3e-5: about 1100 dpi
  double max_force;         // N, the device clamps larger commands; 3.3: peak force of this class
  double nominal_stiffness; // N/m, reported as max_stiffness; 500: within 0.4-0.7 N/mm, below 2b/T at 1 kHz
  double hand_stiffness;    // N/m, operator spring toward the target, 0 = free device; 200: a light fingertip grip
  double hand_damping;      // N s/m, operator damping against the target's velocity; 2: a light fingertip grip
  double workspace_min[3];  // m; -0.08, -0.06, -0.035: a 160 x 120 x 70 mm box, as this class
  double workspace_max[3];  // m; 0.08, 0.06, 0.035
} tx_sim_device_def;

typedef struct tx_sim_device {
  tx_sim_device_def def; // as given to init
  double phi[4];         // row-major transition of (x, v) over one period, (1, s; 1/s, 1)
  double gam[2];         // response of (x, v) to a unit held input over one period, (m/N, m/s/N)
  double x[3];           // true position, m
  double v[3];           // true velocity, m/s
  double target[3];      // hand target, m
  double target_vel[3];  // hand target velocity, by difference of targets, m/s
  double q_prev[3];      // position reported at the previous tick, m
  double force[3];       // force held over the last period, after the clamp, N
  double work;           // J, energy the device's motors delivered to the mechanism since reset (exact for ZOH)
  uint64_t ticks;        // periods advanced since reset
  uint64_t clamped;      // ticks whose command exceeded max_force
  uint64_t rejected;     // ticks whose command held NaN or Inf (rendered as zero force)
  tx_device_state state; // what the device reports, sampled at the end of the last step
} tx_sim_device;

// the defaults above
tx_sim_device_def tx_sim_device_def_default(void);

// 0 when every field is finite and in range; otherwise -1 with one line in
// tx_error() naming the field, its value and the allowed range
int tx_sim_device_def_check(const tx_sim_device_def* def);

// the keys of a "sim:" device spec, "key=value,...", over def (the part after
// "sim:"; "" keeps def): mass, damping, quantum, max_force, hand_stiffness,
// hand_damping (numbers in the units above) and hand (the scripted motion the
// hand follows, copied into hand). Each key at most once, and the result must
// pass tx_sim_device_def_check. false with one line naming the key; def and
// hand are then unspecified. Nothing here opens a file.
bool tx_sim_device_parse(const char* spec, tx_sim_device_def* def, char* hand, size_t hand_size);

// checks def and sets the device at rest at the origin, hand target there too;
// on bad input returns false, leaves dev unchanged and sets tx_error()
bool tx_sim_device_init(tx_sim_device* dev, const tx_sim_device_def* def);

// puts the device at pos (m) moving at vel (m/s), either may be NULL for zero;
// the hand target moves to pos, time and counters restart at zero. The
// previous encoder reading is taken as if the device had been moving at vel.
void tx_sim_device_reset(tx_sim_device* dev, const double pos[3], const double vel[3]);

// moves the hand target to target (m) without giving it a velocity: the hand
// is placed there, not swept (the next step with a target differences from it)
void tx_sim_device_place_hand(tx_sim_device* dev, const double target[3]);

// advances by exactly one period T: force (N, the command, may be NULL for
// zero) is clamped to max_force in magnitude and held; hand_target (m) is the
// operator's target for this period, NULL (or a non-finite entry) keeps the
// last one. Then dev->state
// is sampled (quantized position, m; backward-difference velocity, m/s; time, ns).
void tx_sim_device_step(tx_sim_device* dev, const double force[3], const double hand_target[3]);

// max force (N), nominal stiffness (N/m), physical damping (N s/m), workspace (m)
void tx_sim_device_info(const tx_sim_device* dev, tx_device_info* info);

#endif
