// Internal: the "physics.instruments" controller class: up to two instruments
// (URDF descriptions, assets/instruments/) on ODE, instrument N held by
// deviceN through a virtual coupling. docs/instruments.md.
#ifndef TX_CONTROLLERS_INSTRUMENTS_INSTRUMENTS_CONTROLLER_H
#define TX_CONTROLLERS_INSTRUMENTS_INSTRUMENTS_CONTROLLER_H

#include <tactus/controller.h>
#include <tactus/events.h>

extern const tx_controller_class tx_physics_instruments;

// on instruments.events when a hand switches instruments: source = the hand
// (N of deviceN), value[0] = the index in its list (handN) of the one it
// took, value[1] = of the one it put down
#define TX_EVENT_INSTRUMENT_SWITCH (TX_EVENT_USER + 1)

#endif
