// Internal: the "collision.hip" controller class, the suturing papers'
// simplified ray-casting method (see hip.h) against the published skin.
// Parameters: radius_m, rays (26 or 98), alpha (N/m), k, slide_max_m,
// pierce_range_m, hold_m, join (anchor or own). Components: pose (read,
// default device0.pose), skin (the mesh NAME: reads NAME.x, NAME.tri,
// NAME.thickness; default "skin"), force_model (written, default
// tool0.force_model: F0, x0, K), state (written, default hip0.state, f64
// 1 x 8: contacts, pierced, F (3, N), depth (m), eq. 8 updates, simulation
// time of the skin publish in use (s)), spheres (written, default
// hip0.spheres: x y z r, for views).
#ifndef TX_CONTROLLERS_COLLISION_HIP_COLLISION_H
#define TX_CONTROLLERS_COLLISION_HIP_COLLISION_H

#include <tactus/controller.h>

extern const tx_controller_class tx_collision_hip;

#endif
