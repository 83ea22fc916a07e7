// Internal: the "collision.wall" controller class. Parameters: stiffness
// (N/m), height_m, pose (component read, default device0.pose), force_model
// (component written, default tool0.force_model, f64 1 x 15: F0, x0, K).
#ifndef TX_CONTROLLERS_COLLISION_WALL_H
#define TX_CONTROLLERS_COLLISION_WALL_H

#include <tactus/controller.h>

extern const tx_controller_class tx_collision_wall;

#endif
