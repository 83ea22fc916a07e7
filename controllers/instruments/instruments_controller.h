// Internal: the "physics.instruments" controller class: up to two instruments
// (URDF descriptions, assets/instruments/) on ODE, instrument N held by
// deviceN through a virtual coupling. docs/instruments.md.
#ifndef TX_CONTROLLERS_INSTRUMENTS_INSTRUMENTS_CONTROLLER_H
#define TX_CONTROLLERS_INSTRUMENTS_INSTRUMENTS_CONTROLLER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_physics_instruments;

#endif
