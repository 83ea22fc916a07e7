// Internal: a kinematic straight needle in the spherical voxel tissue (the
// voxel needle-insertion paper, eq. 9).
//
// The needle is a cylinder of the gauge's outer radius, from its hub to its
// tip, placed by the device pose every frame. Inside each tissue substep it
// touches the voxels that overlap it, found through the tissue's grid:
//
//   - a touching voxel is moved out of the needle along the contact normal,
//     and its normal velocity answered by eq. 5 with the needle as the body
//     of infinite mass (v_n' = V_n + e (V_n - v_n));
//   - along the shaft, Coulomb friction (coefficient friction) acts against
//     the sliding, at most friction times the normal impulse;
//   - an uncut voxel in front of the tip is pushed along the axis (a bevel
//     tip pushes it along the bevel face's normal). When its load, averaged
//     over load_time, reaches the cutting load (rupture_force for the first
//     cut of an insertion, the puncture, and cutting_force after it, times
//     the tip's sharpness: 1 blunt, sin(tip_angle) conical or bevel), it is cut:
//     fully damaged (its radius shrinks), and from then on parted sideways.
//     A cut voxel is uncut again once its damage has healed.
//
// The force on the needle is the momentum it gave the voxels, over the
// frame, with the sign turned: eq. 9's three terms are kept apart,
//   stiffness: normal loads on the shaft, and on the tip before puncture,
//   friction:  the shaft's tangential loads,
//   cutting:   the tip's loads after puncture (the first cut of an insertion),
// and sum to the force. The energy the needle put into the block is summed
// too, so that a caller can tell a passive block from a blow-up.
//
//     tx_voxel_needle_def nd = tx_voxel_needle_def_default();
//     tx_voxel_needle n;
//     if (!tx_voxel_needle_init(&n, &nd, &tissue)) puts(tx_error());
//     tx_voxel_needle_step(&n, &tissue, tip, quat, 1e-3); // n.force: N on the needle
//     tx_voxel_needle_fini(&n);
//
// Init allocates; step never does.
#ifndef TX_CONTROLLERS_VOXEL_NEEDLE_H
#define TX_CONTROLLERS_VOXEL_NEEDLE_H

#include "tissue.h"

#include <stdbool.h>
#include <stdint.h>

typedef enum tx_needle_tip {
  TX_NEEDLE_CONICAL, // symmetric point: pushes along the axis
  TX_NEEDLE_BEVEL,   // slanted face: pushes along the face normal, so the needle feels a side force
  TX_NEEDLE_BLUNT,   // flat end: the hardest to cut with
} tx_needle_tip;

typedef struct tx_voxel_needle_def {
  int gauge;            // needle gauge (outer diameter from the ISO 9626 table), 10 to 34; 18 (1.27 mm)
  tx_needle_tip tip;    // tip shape; conical
  double tip_angle_deg; // degrees: conical half-angle, or the bevel face's angle to the axis, in (0, 90); 15
  double length;        // m, hub to tip; 0.04
  double friction;      // 1, Coulomb coefficient between the shaft and the voxels, in [0, 10]; 0.3
  double rupture_force; // N, load on one voxel that a blunt tip punctures it with, in (0, 1e4]; 0.2
  double cutting_force; // N, the same once punctured (the crack runs on), in (0, 1e4]; 0.1
  double load_time;     // s, how long a voxel's tip load is averaged before it is compared, in (0, 1]; 0.005
  double axis[3];       // unit direction hub to tip in the device frame; (0, -1, 0): down, Y up
  double side[3];       // unit direction the bevel face looks toward, device frame, normal to axis; (1, 0, 0)
} tx_voxel_needle_def;

typedef struct tx_voxel_needle {
  tx_voxel_needle_def def; // as given to init
  double radius;           // m, outer radius from the gauge
  double cut_scale;        // 1, the tip's sharpness: the share of rupture_force that cuts

  // per voxel (tissue's n), allocated at init
  uint8_t* cut;        // (n) 1 where the needle has cut the voxel and it has not healed
  int32_t* cut_list;   // (n) ids of the cut voxels
  int n_cut;           // entries used in cut_list
  double* load;        // (n) N s, each voxel's tip impulse, decaying with load_time
  double* load_t;      // (n) s, when load was last updated

  // the pose over the current frame (world frame)
  bool placed;        // a pose has been given
  double tip0[3];     // m, tip at the start of the frame
  double tip1[3];     // m, tip at the end of the frame
  double dir[3];      // unit axis, hub to tip
  double side[3];     // unit, the bevel's side, normal to dir
  double vel[3];      // m/s, needle velocity over the frame
  double time;        // s, since init

  // the last frame's results
  double force[3];      // N, on the needle from the tissue (eq. 9's sum)
  double stiffness[3];  // N, eq. 9's stiffness term
  double friction[3];   // N, eq. 9's friction term
  double cutting[3];    // N, eq. 9's cutting term
  double k_axial;       // N/m, spring constants of the uncut voxels held by the tip: the local dF/dx along the axis
  int contacts;         // voxels touched in the frame (all substeps, each voxel once per substep)
  double energy_in;     // J, work the needle has done on the block since init (kinetic + spring)
  bool punctured;       // an insertion has cut a voxel; cleared when the needle touches nothing
  uint64_t cuts;        // voxels cut since init
} tx_voxel_needle;

// the defaults above
tx_voxel_needle_def tx_voxel_needle_def_default(void);

// 0 when every field is valid; otherwise -1 with one line in tx_error() naming the field
int tx_voxel_needle_def_check(const tx_voxel_needle_def* def);

// outer diameter of a gauge, m (ISO 9626 nominal); 0 outside 10 to 34
double tx_needle_gauge_diameter(int gauge);

// parses "conical", "bevel" or "blunt"; false for anything else
bool tx_needle_tip_parse(const char* name, tx_needle_tip* out);
const char* tx_needle_tip_name(tx_needle_tip tip);

// checks def and allocates per-voxel state for tissue t; false and tx_error() on failure
bool tx_voxel_needle_init(tx_voxel_needle* n, const tx_voxel_needle_def* def, const tx_voxel_tissue* t);
void tx_voxel_needle_fini(tx_voxel_needle* n);

// forget the pose, the cuts and the energy (after a tissue reset)
void tx_voxel_needle_reset(tx_voxel_needle* n);

// moves the tip (m, world) with orientation quat (w, x, y, z; normalised
// here) over dt and steps the tissue with it; false (nothing changed,
// tx_error() set) on a non-finite pose or bad dt
bool tx_voxel_needle_step(tx_voxel_needle* n, tx_voxel_tissue* t, const double tip[3], const double quat[4], double dt);

// depth of the tip below the surface where the needle's axis enters the
// block's rest box, m (negative above it); when the axis misses the box,
// minus the tip's distance to it
double tx_voxel_needle_depth(const tx_voxel_needle* n, const tx_voxel_tissue* t);

#endif
