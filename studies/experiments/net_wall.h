// Internal: the virtual wall of wall_stability.h with the device on one side
// of a network and the wall on the other, behind `tactus study
// network-haptics`.
//
// The device side runs the simulated device and the haptics controller's
// force path (tx_haptic_tick: passivity observer and controller, safety
// chain). Each servo tick k it sends its encoder reading (x(k), v(k)) to the
// simulation side, which computes the wall,
//
//     F = -K x - B v   (x > 0, else 0),  and the energy its spring holds,
//
// and sends them back. With a one-way network delay d each way, the force
// the device renders at tick k is the one computed from its reading at tick
// k - n, n = round(2 d / T) servo periods (the round trip); before the first
// answers arrive the device renders the force of the wall at rest, -K x_eq.
// With n = 0 this is exactly tx_wall_run's loop (the same arithmetic in the
// same order), so the delay-0 row of the study reproduces haptic-stability's.
//
// The case runs in simulated time: the delay is a delay line of n ticks on
// the device side, exact, where netem's would be in wall time and add the
// jitter of a loaded host. The link itself is a function (tx_wall_link):
// NULL computes the wall in this process; the study also carries every tick
// over Cyclone DDS to a second process and checks it gives the same result
// bit for bit (network_haptics.c).
//
// The exact stability boundary of the delayed loop (tx_net_wall_exact_bound)
// is where the roots of its characteristic polynomial, of degree n + 3, leave
// the unit circle (the Schur-Cohn-Jury test), the measured search is held to it.
#ifndef TX_STUDIES_EXPERIMENTS_NET_WALL_H
#define TX_STUDIES_EXPERIMENTS_NET_WALL_H

#include "wall_stability.h"

// the exact boundary of the delayed loop without quantisation or safety
// limits: the largest K (N/m, to 1e-9 relative) for which every root of the
// characteristic polynomial lies inside the unit circle; 0 if even 1 mN/m
// is unstable; NaN for a bad device or delay (tx_error() set)
double tx_net_wall_exact_bound(const tx_sim_device_def* d, double B, int delay_ticks);

// whether the delayed wall K, B on this device is asymptotically stable (Schur-Cohn-Jury)
bool tx_net_wall_exact_stable(const tx_sim_device* dev, double K, double B, int delay_ticks);

#endif
