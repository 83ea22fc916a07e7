// Internal: fitting the voxel tissue and needle to a haptic recording (the
// voxel needle-insertion paper, section 2's "values ... determined
// experimentally", and its Figure 5).
//
// A recording's depth is replayed by a needle going straight down (-y) into
// the top centre of a 5 x 5 x 5 mm block of 10 x 10 x 10 voxels; the model's
// force on the needle is compared with the recorded one at every row, as the
// RMS of the 3-axis difference. Nelder-Mead searches the parameters in
// transformed coordinates (logarithms of the positive ones, logits of the
// bounded ones), so that every trial is valid.
//
//     tx_needle_fit_params p = tx_needle_fit_params_default();
//     tx_needle_fit_result r;
//     tx_needle_fit(&rec, &p, 300, NULL, NULL, &r); // p now holds the best
#ifndef TX_CONTROLLERS_VOXEL_NEEDLE_FIT_H
#define TX_CONTROLLERS_VOXEL_NEEDLE_FIT_H

#include "../../controllers/voxel/needle.h"
#include "../../controllers/voxel/recording.h"

enum { TX_NEEDLE_FIT_PARAMS = 9 };

typedef struct tx_needle_fit_params {
  double spring;        // N/m, k_s of every voxel
  double damping_ratio; // 1, k_d = 2 zeta sqrt(k_s m), in (0, 4)
  double radius;        // m, voxel rest radius, in (0.15, 0.5) of the 0.5 mm spacing
  double mass;          // kg per voxel
  double elasticity;    // 1, e of eq. 5, in (0, 1)
  double damage_shrink; // 1, fraction of the radius a cut takes, in (0, 0.95)
  double rupture_force; // N, the puncture load per voxel (blunt-tip equivalent)
  double cutting_force; // N, the load per voxel once punctured
  double friction;      // 1, Coulomb coefficient of the shaft
} tx_needle_fit_params;

typedef struct tx_needle_fit_result {
  double rms;        // N, of the best parameters
  double peak;       // N, largest recorded force magnitude
  int evaluations;   // simulations run
  double seconds;    // wall time of the search
} tx_needle_fit_result;

// the starting point: the needle-voxel scenario's values
tx_needle_fit_params tx_needle_fit_params_default(void);

// the tissue and needle of a parameter set (the fit's block and an 18-gauge conical needle)
void tx_needle_fit_defs(const tx_needle_fit_params* p, tx_voxel_tissue_def* t, tx_voxel_needle_def* n);

// replays rec with p; f (rec->count x 3, N) receives the model's force; returns the RMS (N) or -1 with tx_error()
double tx_needle_fit_simulate(const tx_needle_fit_params* p, const tx_recording* rec, double* f);

// called after each evaluation with the wall time so far and the best RMS so far
typedef void (*tx_needle_fit_progress)(int evaluation, double seconds, double best_rms, void* user);

// searches from *p for at most max_evals simulations; *p gets the best; false with tx_error() on failure
bool tx_needle_fit(const tx_recording* rec, tx_needle_fit_params* p, int max_evals, tx_needle_fit_progress cb,
                   void* user, tx_needle_fit_result* out);

#endif
