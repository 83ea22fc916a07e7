// Internal: the scripted probe of the `lagb-organs` scenario ("lagb.probe"):
// it writes a tool pose (param pose, default device0.pose) that presses and
// slides on the liver, then on the stomach, of assets/lagb, and holds still
// after 6.5 s. Waypoints are in lagb_probe.c.
#ifndef TX_SCENARIOS_LAGB_ORGANS_LAGB_PROBE_H
#define TX_SCENARIOS_LAGB_ORGANS_LAGB_PROBE_H

#include <tactus/controller.h>

extern const tx_controller_class tx_lagb_probe;

// the probe's pose at t seconds (position m, then the identity quaternion)
void tx_lagb_probe_at(double t, double pose[7]);

#endif
