// Internal: the haptics controller class, registered as "haptics".
//
// Parameters: device (a device spec, default "scripted:pierce-down"), hand
// (0 or 1: components device0.* or device1.*), mode ("local" or
// "sample_hold"), force_model (the component to render, f64 1 x 15:
// F0, x0, K row-major; "" for none), passivity_control, and max_force,
// max_force_rate, model_timeout_s, device_timeout_s, ramp_s, which can only
// lower the device's own limits; coupling_tool (a component whose row starts
// x y z, m) with coupling_stiffness (N/m, default 200) and coupling_damping
// (N s/m, default 1) renders a virtual coupling to a simulated tool instead
// of a force model; record (default true) keeps deviceN.bin and
// deviceN.csv, at full rate, in the run's recording folder when it has one.
// Writes deviceN.pose (x y z qw qx qy qz), deviceN.velocity, deviceN.force
// (what was sent) and deviceN.energy (observed and dissipated, J).
#ifndef TX_CONTROLLERS_HAPTICS_CONTROLLER_H
#define TX_CONTROLLERS_HAPTICS_CONTROLLER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_haptics_controller;

#endif
