// Internal: the "physics.membrane" controller class (docs/membrane.md), a
// thin membrane of the gastric-banding scene (the pars flaccida of the lesser
// omentum, the phrenogastric ligament at the angle of His): a rectangular
// cloth patch (physics/bullet/cloth.h) attached all round, placed in the
// scene by a centre, a normal and an axis. A cautery hook heats it (2-D
// Pennes on its particles, membrane_heat.h) until particles boil away with
// their triangles; scissors closing across it cut it (tx_cloth_cut); a tool
// that crosses it where it is open counts a pass. Built only with
// TX_WITH_BULLET. Every component is named after the instance (MEMBRANE).
//
// Reads: the hook's pose (param pose, tx_pose) and grip (param grip,
// tx_device_grip), the scissors (param scissors, tx_instrument_pose), the
// tools (param tools, tx_pose each).
// Writes, every step: MEMBRANE.x (tx_vertex, scene frame, m), MEMBRANE.tri
// (tx_triangle, the live triangles; rows in use = their count),
// MEMBRANE.temperature (tx_temperature, K, one per particle), MEMBRANE.state
// (tx_membrane_state).
// Warnings: numerical_fault (the cloth went back to its last good state),
// bad_pose (a non-finite pose, ignored), passed_through_tissue (a tool
// crossed the membrane where it is intact: nothing stops a tool).
// Results: removed, burnt, cut, fallen, passes, opening_m, peak_k,
// damaged_m2, energy_j, boiled_j, active_s, faults, step_p50_ms, step_p99_ms.
#ifndef TX_CONTROLLERS_MEMBRANE_MEMBRANE_CONTROLLER_H
#define TX_CONTROLLERS_MEMBRANE_MEMBRANE_CONTROLLER_H

#include <tactus/controller.h>

#define TX_MEMBRANE_RATE_MIN_HZ 20.0
#define TX_MEMBRANE_RATE_MAX_HZ 1000.0

extern const tx_controller_class tx_physics_membrane;

#endif
