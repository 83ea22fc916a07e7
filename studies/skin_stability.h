// Internal: the cases of `tactus study skin-stability`, one run each of the
// skin (physics.skin), the HIP (collision.hip), haptics on a scripted hand
// and a guard that checks every published value, in lockstep.
#ifndef TX_SCENARIOS_STUDIES_SKIN_STABILITY_H
#define TX_SCENARIOS_STUDIES_SKIN_STABILITY_H

#include <stdbool.h>

#define TX_SKIN_STABILITY_CLAMP_N 3.3 // the haptics clamp of every case (the scripted device's own)

typedef struct tx_skin_stability_case {
  const char* name;    // row name, e.g. "stiffness x1e3"
  const char* motion;  // "pierce", "teleport-through", "teleport-in-contact", "fast-through", "fast-sideways"
  double stiffness;    // 1, factor on the default stretch and bend stiffness
  double rate_hz;      // physics.skin rate, 20 to 120
  double substep_s;    // s, physics substep (max_substep_s)
  double thickness_m;  // m
  double max_speed;    // m/s, the skin's blow-up bound (physics.skin max_speed)
} tx_skin_stability_case;

typedef struct tx_skin_stability_row {
  int skin_steps;        // physics steps run
  int faults;            // skin.numerical_fault warnings: detected and put back to the last good state
  int torn;              // links torn at the end
  long nan_values;       // non-finite values the guard saw in skin.x, tool0.force_model or device0.force
  double max_force;      // N, largest |device0.force|
  double max_model_force; // N, largest |F0| of tool0.force_model
  long clamped;          // haptics.force_clamped warnings
  bool ok;               // ran, no NaN anywhere, force within the clamp
  char outcome[16];      // "stable", "recovered" or "FAILED"
  char warnings[256];    // every warning of the run, KEY=COUNT
} tx_skin_stability_row;

// the study's cases, in order
int tx_skin_stability_cases(const tx_skin_stability_case** cases);
// runs one case with its scripted hand written into dir; 0, or -1 (and tx_error())
int tx_skin_stability_run(const tx_skin_stability_case* c, const char* dir, tx_skin_stability_row* row);

#endif
