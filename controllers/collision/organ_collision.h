// Internal: the "collision.organ" controller class: the tool tip (a sphere)
// against the latest surfaces of the soft organs (see organ.h), and the local
// force model for the haptics controller. Parameters: organs (the names,
// default liver and stomach: reads ORGAN.x, ORGAN.tri), pose (read, default
// device0.pose), contact (read, default organs.contact: the organs' reaction,
// tx_skin_contact; "" for the penalty alone), force_model (written, default
// tool0.force_model), radius_m, hold_m, depth_max_m, stiffness.
#ifndef TX_CONTROLLERS_COLLISION_ORGAN_COLLISION_H
#define TX_CONTROLLERS_COLLISION_ORGAN_COLLISION_H

#include <tactus/controller.h>

extern const tx_controller_class tx_collision_organ;

#endif
