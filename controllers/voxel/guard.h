// Internal: the numerical guard of a needle in voxel tissue. It keeps a
// checkpoint of the block every few steps, and after each step checks that
// the force is finite and that the block holds no more energy than the
// needle put into it (collisions with e <= 1 and the damped springs only take
// energy away; a factor of two covers the position shift of eq. 5's
// response). A step that fails is undone back to the checkpoint, counted,
// and its force replaced by zero, so that a blow-up never reaches a device.
//
//     tx_voxel_guard g;
//     tx_voxel_guard_init(&g, &tissue, 100);
//     tx_voxel_needle_step(&needle, &tissue, tip, quat, dt);
//     if (tx_voxel_guard_check(&g, &tissue, &needle)) { /* recovered */ }
#ifndef TX_CONTROLLERS_VOXEL_GUARD_H
#define TX_CONTROLLERS_VOXEL_GUARD_H

#include "needle.h"

typedef struct tx_voxel_guard {
  int n;             // voxels
  int every;         // steps between checkpoints
  uint64_t steps;    // steps checked
  // the checkpoint holds only what is not at rest: the awake voxels' state
  // and the damaged voxels' damage, so that taking it costs what is moving
  int32_t* awake;    // (n) ids of the voxels awake at the checkpoint
  int n_awake;       // entries used in awake
  double* pos;       // (n x 3) their positions, m
  double* vel;       // (n x 3) their velocities, m/s
  int32_t* damaged;  // (n) ids of the voxels damaged at the checkpoint
  int n_damaged;     // entries used in damaged
  double* damage;    // (n) their damage, 1
  double energy_in;  // J, the needle's work at the checkpoint
  double energy_max; // J, the most the block has held
  uint64_t recoveries; // steps undone
  uint64_t non_finite; // of them, with a non-finite force or energy
} tx_voxel_guard;

// allocates the checkpoint (taken now); false and tx_error() on no memory
bool tx_voxel_guard_init(tx_voxel_guard* g, const tx_voxel_tissue* t, int every);
void tx_voxel_guard_fini(tx_voxel_guard* g);

// checks the step just taken; true when it was undone
bool tx_voxel_guard_check(tx_voxel_guard* g, tx_voxel_tissue* t, tx_voxel_needle* nd);

#endif
