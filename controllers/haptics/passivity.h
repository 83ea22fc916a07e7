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

// observe one tick: the force about to be rendered (N), the device velocity
// (m/s) and the tick length (s). With control on, force is changed in place
// so that the energy stays >= 0. Returns the damping added, N s/m.
double tx_passivity_tick(tx_passivity* p, double force[3], const double vel[3], double dt, bool control);

#endif
