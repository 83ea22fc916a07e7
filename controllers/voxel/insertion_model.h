// Internal: the published needle-force model form ("Force modeling for
// needle insertion into soft tissue", IEEE TBME 2004), used to
// generate reference insertion curves. Along the needle, with z the tip's
// depth below the surface:
//
//   before puncture:  f = a1 z + a2 z^2                    (stiffness)
//   after puncture:   f = cutting + friction z             (inserting)
//                     f = -friction z                      (retracting)
//
// f resists the motion: positive pushes the needle out of the tissue. The
// friction of the published model depends on the velocity (a Karnopp
// model); at the constant speed of a scripted insertion it is a force per
// length of shaft in the tissue, which is the form kept here. The parameter
// values are ours, chosen for a 5 mm block; they are not measured.
#ifndef TX_CONTROLLERS_VOXEL_INSERTION_MODEL_H
#define TX_CONTROLLERS_VOXEL_INSERTION_MODEL_H

#include "recording.h"

typedef struct tx_insertion_model {
  double a1;             // N/m, linear stiffness coefficient; 50 (0.05 N/mm)
  double a2;             // N/m^2, quadratic stiffness coefficient; 1e5 (0.1 N/mm^2)
  double puncture_depth; // m, depth at which the surface ruptures; 2e-3
  double cutting;        // N, constant cutting force while inserting after puncture; 0.2
  double friction;       // N/m, friction per metre of shaft in the tissue; 25 (0.025 N/mm)
} tx_insertion_model;

typedef struct tx_insertion_motion {
  double start_depth; // m, where the tip starts (negative: above the surface); -1e-3
  double max_depth;   // m, the deepest point; 4e-3
  double speed;       // m/s, in and out; 3e-3
  double wait;        // s, still before going in and after coming out; 0.2
  double rate;        // Hz, samples per second, >= 1000; 1000
} tx_insertion_motion;

tx_insertion_model tx_insertion_model_default(void);
tx_insertion_motion tx_insertion_motion_default(void);

// 0 when valid; otherwise -1 with one line in tx_error() naming the field
int tx_insertion_model_check(const tx_insertion_model* m);
int tx_insertion_motion_check(const tx_insertion_motion* m);

// the force resisting the needle (N, positive out of the tissue) at depth z
// (m) moving into the tissue (dir > 0), out of it (dir < 0) or not (0)
double tx_insertion_force(const tx_insertion_model* m, double z, int dir, bool punctured);

// samples the motion in and out, with events; false and tx_error() on bad
// input or no memory (out is then empty)
bool tx_insertion_generate(const tx_insertion_model* m, const tx_insertion_motion* mo, tx_recording* out);

#endif
