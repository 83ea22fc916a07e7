// Internal: the needle-in-voxels stability cases (issue: stiff springs, e =
// 1, tiny masses, a fast needle, overlapping voxels). Each case replays a
// straight insertion into the needle-fit block with one thing pushed to an
// extreme, with the guard on, and reports what it saw: whether any force or
// state was ever non-finite after the guard, the energy against its bound,
// and the steps the guard detected and undid.
#ifndef TX_CONTROLLERS_VOXEL_NEEDLE_STABILITY_H
#define TX_CONTROLLERS_VOXEL_NEEDLE_STABILITY_H

#include <stdbool.h>
#include <stdint.h>

enum { TX_NEEDLE_STABILITY_CASES = 6 };

typedef struct tx_needle_stability_result {
  const char* name;        // short name of the case
  const char* what;        // what is pushed to the extreme
  int steps;               // frames of 1 ms
  uint64_t nan_out;        // frames whose force left the guard non-finite (must be 0)
  uint64_t nan_state;      // voxels non-finite at the end (must be 0)
  double energy_max;       // J, most the block held after the guard
  double energy_bound;     // J, twice the most net work the needle did, plus the floor
  bool bounded;            // energy_max <= energy_bound
  uint64_t recoveries;     // frames the guard detected and undid
  uint64_t recovered_nan;  // of them, with a non-finite force or energy
  uint64_t voxel_faults;   // voxels found non-finite and put back at rest by the tissue
  double peak_force;       // N, largest force magnitude after the guard
  int max_substeps;        // most substeps a frame took
  uint64_t cuts;           // voxels the needle cut
  double seconds;          // wall time
} tx_needle_stability_result;

// runs case k (0 to TX_NEEDLE_STABILITY_CASES - 1) for duration_s (<= 0: the
// whole insertion); false and tx_error() when it could not be set up
bool tx_needle_stability_run(int k, double duration_s, tx_needle_stability_result* out);

#endif
