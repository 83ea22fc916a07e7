// Passivity observer and controller for one impedance-type device port.
#include "passivity.h"

#include <math.h>

double tx_passivity_tick(tx_passivity* p, double force[3], const double vel[3], double dt, bool control) {
  double power = force[0] * vel[0] + force[1] * vel[1] + force[2] * vel[2]; // into the hand
  double energy = p->energy - power * dt;
  double v2 = vel[0] * vel[0] + vel[1] * vel[1] + vel[2] * vel[2];
  double alpha = 0;
  // a damping force -alpha v absorbs alpha |v|^2 dt: just enough to reach zero
  if (control && energy < 0 && v2 > 1e-12 && dt > 0) {
    alpha = -energy / (v2 * dt);
    for (int i = 0; i < 3; i++) force[i] -= alpha * vel[i];
    p->dissipated += -energy;
    p->activations++;
    energy = 0;
  }
  p->energy = energy;
  if (energy < p->min_energy) p->min_energy = energy;
  return alpha;
}

void tx_passivity_observe(tx_passivity* p, const double sent[3], const double vel[3], double dt) {
  double power = sent[0] * vel[0] + sent[1] * vel[1] + sent[2] * vel[2]; // into the hand
  double energy = p->energy - power * dt;
  if (!isfinite(energy)) return;
  p->energy = energy;
  if (energy < p->min_energy) p->min_energy = energy;
}

double tx_passivity_damping(tx_passivity* p, const double vel[3], double dt, double max_force) {
  double v2 = vel[0] * vel[0] + vel[1] * vel[1] + vel[2] * vel[2];
  if (!(p->energy < 0 && v2 > 1e-12 && dt > 0 && isfinite(v2))) return 0;
  p->activations++;
  return fmin(-p->energy / (v2 * dt), max_force / sqrt(v2));
}
