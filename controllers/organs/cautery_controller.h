// Internal: the "physics.cautery" controller class, the LAGB paper's
// electrosurgery by temperature (docs/lagb.md, "Cautery"): heat on the
// liver's and the stomach's tetrahedra (thermal.h) from a hook whose tip
// follows a pose while a device button is held. Built only with
// TX_WITH_BULLET (it reads physics.organs' surfaces).
//
// Reads: the pose (param pose, tx_pose) and its grip (param grip,
// tx_device_grip: the button's bit), ORGAN.x (tx_vertex, physics.organs'
// surfaces: where the organs have moved the tissue the tip touches).
// Writes, every step: ORGAN.temperature (tx_temperature, K) and ORGAN.damage
// (tx_organ_damage, Omega), one row per row of ORGAN.x.
// Warnings: bad_pose (not finite), bad_surface (ORGAN.x of other rows).
// Results: ORGAN_peak_k, ORGAN_damaged_m3 (Omega > 1), ORGAN_boiled_m3
// (reached the vaporisation temperature), energy_j (deposited), boiled_j
// (taken by boiling), active_s (heating), substeps, step_p50_ms, step_p99_ms.
#ifndef TX_CONTROLLERS_ORGANS_CAUTERY_CONTROLLER_H
#define TX_CONTROLLERS_ORGANS_CAUTERY_CONTROLLER_H

#include <tactus/controller.h>

#define TX_CAUTERY_RATE_MIN_HZ 100.0
#define TX_CAUTERY_RATE_MAX_HZ 1000.0

extern const tx_controller_class tx_physics_cautery;

#endif
