// Internal: the skin's cloth against closed-form membrane solutions
// (tactus study skin-membrane). A circular membrane of radius a inside the
// square patch (every particle at r >= a clamped), pre-tensioned to T, is
// loaded and run to rest with the solver in its converged range; the
// centre's deflection is compared with the closed form:
//   disc    a force F spread evenly over r < r0:
//           w0 = F (ln(a / r0) + 1/2) / (2 pi T), and w(r0) = F ln(a / r0) / (2 pi T)
//   sag     its own weight, p = rho t g per unit area: w0 = p a^2 / (4 T)
// Both are the small-deflection (linear) solutions of T lap w = -p; the
// loads keep w / a under 1 % so that the stretching the deflection adds to
// T stays under 0.1 %.
//
//     tx_membrane_case k = tx_membrane_case_default(TX_MEMBRANE_DISC);
//     tx_membrane_result r;
//     if (!tx_membrane_run(&k, 0.002, &r)) ... tx_error() ...
#ifndef TX_STUDIES_EXPERIMENTS_SKIN_MEMBRANE_H
#define TX_STUDIES_EXPERIMENTS_SKIN_MEMBRANE_H

#include <stdbool.h>

typedef enum tx_membrane_kind { TX_MEMBRANE_DISC = 0, TX_MEMBRANE_SAG = 1 } tx_membrane_kind;

typedef struct tx_membrane_case {
  tx_membrane_kind kind;
  double radius;      // m, a: the clamp; 0.04
  double tension;     // N/m, T; 100
  double stiffness;   // N/m, k of the stretch and shear links; 2000 (E t = 3000 N/m without bending links)
  double density;     // kg/m^2, rho t; 4.4 (1100 kg/m^3, 4 mm)
  double load;        // N, F of the disc load; 0.02
  double load_radius; // m, r0; 0.005
  double gravity;     // m/s^2, the sag's g; 9.81
  double time;        // s, simulated before the deflection is read; 0.15
  double damping;     // 1/s, the velocity decay that brings it to rest (the rest state does not depend on it); 300
  int implicit;       // 0: XPBD at k w h^2 = 1/4, 4 iterations; 1: the implicit solver at its real-time defaults
} tx_membrane_case;

typedef struct tx_membrane_result {
  double spacing;   // m
  int particles;    // in the patch (the clamped ones included)
  double substep;   // s, the solver's substep: k w h^2 = 1/4 (w: two particles' inverse masses)
  int iterations;   // XPBD iterations per substep
  double measured;  // m, the centre's deflection (down positive)
  double exact;     // m, the closed form
  double error;     // 1, |measured - exact| / exact
  double drift;     // m, how much the centre still moved over the last 10 % of the time
  double tension;   // N/m, the membrane tension the cloth reports at the centre (tx_cloth_membrane_tension)
  double seconds;   // wall time of the run
} tx_membrane_result;

tx_membrane_case tx_membrane_case_default(tx_membrane_kind kind);
// the closed-form centre deflection (m) of the case
double tx_membrane_exact(const tx_membrane_case* k);
// Rupture under a HIP pressing down: a pre-tensioned circular membrane
// (radius 1.5 cm, T = 50 N/m, k = 2000 N/m) tears where its tension averaged
// over rupture_length (2 mm) reaches 150 N/m. The HIP (radius 0.5 mm, skin
// 4 mm thick) comes down at its centre at 2 cm/s; the rupture force is the
// largest contact force before the first tear. Quasi-static: the force does
// not depend on the mass, so the membrane is 100 times denser than skin
// (dynamic relaxation), which makes the converged substep 10 times longer.
typedef struct tx_membrane_rupture {
  double spacing;  // m
  int particles;
  double force;    // N, the rupture force
  double depth;    // m, how far the HIP's centre went below the flat skin by then
  double tension;  // N/m, the membrane tension at the tear (tx_cloth_peak_tension)
  double seconds;  // wall time
} tx_membrane_rupture;

bool tx_membrane_rupture_run(double spacing, tx_membrane_rupture* out);

// The journal paper's gravity test with physical skin: the 10 x 10 cm patch,
// border fixed, no pretension, 1100 kg/m^3, 4 mm, k = 2000 N/m (E t =
// 3100 N/m: E = 0.77 MPa), hanging under 9.81 m/s^2 with the solver
// converged (k w h^2 = 1/4, 4 iterations) and, for comparison, at the
// real-time default; res particles a side.
typedef struct tx_membrane_sag {
  int res;
  double converged;  // m, the centre's sag, converged solver
  double drift;      // m, how much it still moved over the last 10 % of the time
  double realtime;   // m, the centre's sag at the real-time default (1 iteration, 1/600 s substeps)
  double seconds;    // wall time
} tx_membrane_sag;

bool tx_membrane_gravity_run(int res, tx_membrane_sag* out);

// runs the case at this particle spacing (m; it must divide the radius into
// at least 4 cells); false and tx_error() when the cloth cannot be built
bool tx_membrane_run(const tx_membrane_case* k, double spacing, tx_membrane_result* out);

#endif
