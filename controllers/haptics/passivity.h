// Internal: the passivity observer and controller of one device port, after
// the time-domain passivity approach (Hannaford and Ryu, 2002).
//
// The observer sums the energy the virtual environment has absorbed through
// the port, E = -sum(F . v) dt, with F the force sent to the device (after
// every safety stage: what the hand really felt) and v its velocity. A
// passive environment keeps E >= 0. The controller, when on, adds just
// enough damping, F -= a v, to bring E back to zero whenever it goes
// negative; the damping is added before the safety chain, so it never
// exceeds the limits, and the observer sees what of it was really sent.
#ifndef TX_CONTROLLERS_HAPTICS_PASSIVITY_H
#define TX_CONTROLLERS_HAPTICS_PASSIVITY_H

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_passivity {
  double energy;        // J absorbed by the environment so far; < 0 means it generated energy
  double min_energy;    // J, the lowest energy observed
  double dissipated;    // J absorbed by the controller's damping over the periods it was held
  uint64_t activations; // ticks on which the controller added damping
} tx_passivity;

// observer and controller in one, booking the damping's energy when it is
// commanded: only for a port where nothing changes the force after it (the
// stability study); the haptics controller uses the two calls below.
// Observe one period: the force held over it (N), the device velocity
// measured over it (m/s) and its length (s). Pair them so: the force about
// to be rendered with the last velocity would make a sampled spring look
// passive. With control on, returns the damping a (N s/m) to subtract, as
// a v, from the next force so that the energy stays >= 0 (force is changed
// in place too, for callers that render what they observed).
double tx_passivity_tick(tx_passivity* p, double force[3], const double vel[3], double dt, bool control);

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

#endif
