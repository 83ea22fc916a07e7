// Internal: the "voxel.needle" controller class: the spherical voxel block
// and the needle in it, stepped together at the haptic rate (the paper's
// haptic frame of collision, response and springs at 1 kHz). See
// docs/needle.md for its parameters and the components it publishes.
#ifndef TX_CONTROLLERS_VOXEL_NEEDLE_CONTROLLER_H
#define TX_CONTROLLERS_VOXEL_NEEDLE_CONTROLLER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_voxel_needle_controller;

#endif
