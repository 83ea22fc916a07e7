// Internal: the "physics.skin" controller class, the suturing skin on a
// Bullet soft body (bullet/cloth.h). Built only with TX_WITH_BULLET.
//
// Parameters (SI units; the papers' centimetres are given beside):
//   size_m 0.1 (10 cm), spacing_m 0.0025 (0.25 cm: 42 x 42 particles) or
//   0.001 (0.1 cm: 102 x 102); size / spacing + 1 cells a side, as the
//   journal paper counts them, so the edge is size + spacing; thickness_m 0.004 (0.2 to 0.8 cm), mass_kg,
//   stretch_stiffness and bend_stiffness (N/m, k of eq. 1), damping (1/s),
//   gravity (bool), fixed_border (bool), pretension_n_per_m (N/m),
//   rupture_tension_n_per_m (N/m, 0: never), rupture_length_m (m),
//   iterations, max_substep_s, max_speed (m/s), hip_radius_m 0.0005
//   (0.05 cm; 0: no HIP), pose (the component the HIP follows, default
//   device0.pose, f64 1 x 7); grasp_events (a stream of TX_EVENT_GRASP and
//   TX_EVENT_RELEASE, source = hand h; "": none), grasp_radius_m 0.002 and
//   grasp_hands 2: a grasp holds the free particles within the radius at
//   their offset in instrument<h>.pose's frame until h releases.
// Rate 20 to 120 Hz (60 by default in the scenarios).
//
// Writes, every step: skin.x (f32 N x 3, m), skin.tri (i32 M x 3, the live
// triangles; rows in use = M), skin.thickness (f64 1 x 1, m), skin.torn
// (i32 1 x 1, links broken so far). Warnings: numerical_fault (a step found
// a NaN, an Inf or a blow-up and went back to the last good state),
// bad_pose (a non-finite HIP pose, ignored). Results: torn_links, faults,
// grasps, pierces (tears at the HIP's contact: the skin no longer pushes it),
// freed_particles and freed_pieces (cut off from the patch: frozen, out of
// skin.tri, their rows of skin.x kept).
#ifndef TX_CONTROLLERS_PHYSICS_SKIN_CONTROLLER_H
#define TX_CONTROLLERS_PHYSICS_SKIN_CONTROLLER_H

#include <tactus/controller.h>

#define TX_SKIN_RATE_MIN_HZ 20.0
#define TX_SKIN_RATE_MAX_HZ 120.0

extern const tx_controller_class tx_physics_skin;

#endif
