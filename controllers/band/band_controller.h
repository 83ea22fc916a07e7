// Internal: the "physics.band" controller class, the LAGB paper's gastric
// band (band_sim.h): the ring part and the tube part as tetrahedral soft
// bodies on Bullet from assets/lagb/band_*, each end bolted to an ODE rigid
// body, the two parts joined by ODE's double-ball joint, the tube's tip
// latching in the ring's buckle. Built with TX_WITH_BULLET and TX_WITH_ODE.
//
// Writes, every step: band.x (tx_vertex rows: the ring's nodes, then the
// tube's), band.tri (tx_triangle rows: the tetrahedra's boundary faces,
// outward, into band.x), band.state (tx_band_state); the event stream
// band.events (TX_EVENT_LATCH when the band locks). Reads the pose the
// tube's tip follows (param pull, tx_pose) when one is named. Warnings:
// numerical_fault (a NaN, an Inf or a node faster than max_speed: the band
// went back to its last good state), bad_pose. Results: locked (0 or 1),
// joint_error_max (the largest relative error of the joint's length),
// faults, substeps, step_p50_ms, step_p99_ms.
#ifndef TX_CONTROLLERS_BAND_BAND_CONTROLLER_H
#define TX_CONTROLLERS_BAND_BAND_CONTROLLER_H

#include <tactus/controller.h>

#define TX_BAND_RATE_MIN_HZ 10.0
#define TX_BAND_RATE_MAX_HZ 240.0

extern const tx_controller_class tx_physics_band;

#endif
