// Internal: the passivity observer and controller of one device port, after
// the time-domain passivity approach (Hannaford and Ryu, 2002).
//
// The observer sums the energy the virtual environment has absorbed through
// the port, E = -sum(F . v) dt, with F the force rendered on the device and v
// its velocity. A passive environment keeps E >= 0. The controller, when on,
// adds just enough damping, F -= a v, to bring E back to zero whenever it
// would go negative.
#ifndef TX_CONTROLLERS_HAPTICS_PASSIVITY_H
#define TX_CONTROLLERS_HAPTICS_PASSIVITY_H

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_passivity {
  double energy;        // J absorbed by the environment so far; < 0 means it generated energy
  double min_energy;    // J, the lowest energy observed
  double dissipated;    // J removed by the controller
  uint64_t activations; // ticks on which the controller added damping
} tx_passivity;

// observe one period: the force held over it (N), the device velocity
// measured over it (m/s) and its length (s). Pair them so: the force about
// to be rendered with the last velocity would make a sampled spring look
// passive. With control on, returns the damping a (N s/m) to subtract, as
// a v, from the next force so that the energy stays >= 0 (force is changed
// in place too, for callers that render what they observed).
double tx_passivity_tick(tx_passivity* p, double force[3], const double vel[3], double dt, bool control);

#endif
