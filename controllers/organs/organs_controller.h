// Internal: the "physics.organs" controller class, the LAGB organs on Bullet
// (bullet/fem.h): the liver and the stomach as tetrahedral soft bodies from
// assets/lagb, the spleen rigid. Built only with TX_WITH_BULLET.
//
// Modes (mode): "fem", Bullet's FEM deformables (corotated or Neo-Hookean,
// explicit steps; elements thinner than the substep needs are made heavier,
// the added mass reported), or "links", Bullet's classic soft body (edge
// links and volume conservation, solved by iterations).
//
// Writes, every step: liver.x, stomach.x, spleen.x (tx_vertex rows: the drawn
// surface, embedded in the tetrahedra), liver.tri, stomach.tri, spleen.tri
// (tx_triangle rows) and organs.contact (tx_skin_contact: the organs'
// reaction on the tool). Reads the tool's pose (param pose, tx_pose).
// Warnings: numerical_fault (a NaN, an Inf or a node faster than max_speed:
// the organs went back to the last good state), bad_pose. Results: faults,
// step_p50_ms, step_p99_ms, added_mass (fraction), substeps,
// max_displacement_m (the largest node displacement from rest), max_force_n
// (the largest force on the tool).
//
// Grasper picking (picking.h; params grasp, grasp_*): with grasp poses, the
// jaws closing pick the drawn surface between them and carry its nodes;
// writes organs.grasp (tx_organ_grasp, one row per hand), emits
// TX_EVENT_GRASP and TX_EVENT_RELEASE on organs.events (source = the hand).
#ifndef TX_CONTROLLERS_ORGANS_ORGANS_CONTROLLER_H
#define TX_CONTROLLERS_ORGANS_ORGANS_CONTROLLER_H

#include <tactus/controller.h>

#define TX_ORGANS_RATE_MIN_HZ 10.0
#define TX_ORGANS_RATE_MAX_HZ 120.0

extern const tx_controller_class tx_physics_organs;

#endif
