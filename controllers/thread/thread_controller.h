// Internal: the "physics.thread" controller class: the suture thread
// (thread.h) with its head on a pose component, publishing its nodes, the
// tension at the head as a force model, and knot events (docs/thread.md).
#ifndef TX_CONTROLLERS_THREAD_THREAD_CONTROLLER_H
#define TX_CONTROLLERS_THREAD_THREAD_CONTROLLER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_physics_thread;

#endif
