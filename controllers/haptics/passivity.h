// Internal: the passivity observer and controller of one device port, after
// the time-domain passivity approach (Hannaford and Ryu, 2002), and the
// force path of one haptic tick that they sit in.
//
// The observer sums the energy the virtual environment has absorbed through
// the port, E = -sum(F . v) dt, with F the force sent to the device (after
// every safety stage: what the hand really felt) and v its velocity. A
// passive environment keeps E >= 0. The controller, when on, adds just
// enough damping, F -= a v, to bring E back to zero whenever it goes
// negative; the damping is added before the safety chain, so it never
// exceeds the limits, and the observer sees what of it was really sent.
//
// Two references for the controller (the observer's port energy is what a
// run reports either way):
// - port: E as above. A spring pressed in and let go gives back what it
//   stored, so a wall may spend that store on a vibration that never decays.
// - spring: E less the energy U the rendered spring holds at the measured
//   position (tx_spring_energy), plus what the device's own damping b
//   absorbed, b |v|^2 dt per period. Each sampled period of a spring makes
//   k |dx|^2 / 2 that the port sees and b absorbs unseen while k < 2b/T
//   (Colgate's condition); so this energy falls only where the sampling
//   makes more than b takes, and the controller removes just that.
#ifndef TX_CONTROLLERS_HAPTICS_PASSIVITY_H
#define TX_CONTROLLERS_HAPTICS_PASSIVITY_H

#include "safety.h"

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_passivity {
  double energy;        // J absorbed by the environment so far; < 0 means it generated energy
  double min_energy;    // J, the lowest energy observed
  double dissipated;    // J absorbed by the controller's damping over the periods it was held
  uint64_t activations; // ticks on which the controller added damping
} tx_passivity;

// the observer alone: the force sent over the period just measured (N), the
// velocity measured over it (m/s) and its length (s). Non-finite input is
// skipped, so one broken sample cannot poison the energy for the rest of a run.
void tx_passivity_observe(tx_passivity* p, const double sent[3], const double vel[3], double dt);
// the controller on what the observer saw: the damping a (N s/m) that, held
// over the next period at this velocity, absorbs -E; 0 while E >= 0. The
// damping force a |v| asks at most max_force (N): more would only be clamped,
// and a saturated damper one period late pumps energy when v reverses. It
// books nothing: the observer measures what the damping sent really absorbed.
double tx_passivity_damping(tx_passivity* p, const double vel[3], double dt, double max_force);

// the energy (J) a spring of stiffness k (N/m, row-major dF/dx, as in
// tx_force_model) holds while it pushes with force f (N): U = f^T S+ f / 2,
// S+ the pseudo-inverse of S = -(k + k^T) / 2. For a wall -K n n^T at depth d
// that is K d^2 / 2, wherever the model was anchored (x0, f0); directions in
// which k is not a restoring spring hold nothing. 0 for a non-finite k or f.
double tx_spring_energy(const double k[9], const double f[3]);

typedef enum tx_passivity_ref {
  TX_PASSIVITY_REF_PORT = 0, // the energy at the device port alone
  TX_PASSIVITY_REF_SPRING,   // ... less what the rendered spring holds
} tx_passivity_ref;

// The force path of one haptic tick, after rendering, as the `haptics`
// controller runs it and `tactus study haptic-stability` measures it.
typedef struct tx_haptic_path {
  bool control;                // the passivity controller adds damping
  tx_passivity_ref reference;  // what its observer measures against
  tx_safety_limits limits;
  tx_safety safety;
  tx_passivity passivity;
  double held[3];              // N, the force sent last tick, held since
  double damping;              // N s/m, the controller's damping in last tick's force
  double damped_vel[3];        // m/s, the velocity that damping was computed for
  double stored;               // J, spring reference: what the spring held at the last sample
  double reference_energy;     // J, what the controller acts on: passivity.energy, less stored for the spring
  double reference_min;        // J, its lowest
  double device_damping;       // N s/m, spring reference: the device's own b (tx_device_info.damping)
  double absorbed;             // J, spring reference: b |v|^2 dt summed so far
} tx_haptic_path;

// limits as checked by tx_safety_limits_check, the device's own damping
// b >= 0 (N s/m); everything else at rest
void tx_haptic_path_init(tx_haptic_path* p, const tx_safety_limits* limits, bool control, tx_passivity_ref reference,
                         double device_damping);

typedef struct tx_haptic_input {
  double force[3];     // N, what was rendered for this tick
  double stored;       // J, what the rendered spring holds at this sample (tx_spring_energy); spring reference only
  bool mute;           // render zero whatever was asked (the run is stopping): the rate limit makes it a ramp
  double model_age_s;  // s, age of what was rendered
  double silent_s;     // s since the device last answered
} tx_haptic_input;

// one tick of length dt (s) at the device sample (pos m, vel m/s): observe
// the force held over the period just measured (the force about to be
// rendered would make a sampled spring look passive); the controller's
// damping on the reference energy (with the spring reference, the port's
// less what the spring holds now, plus what b absorbed); the safety chain. out (N) is what to send; it is held for the
// next tick's observer. Allocates nothing.
void tx_haptic_tick(tx_haptic_path* p, double dt, const tx_haptic_input* in, const double pos[3], const double vel[3],
                    double out[3]);

#endif
