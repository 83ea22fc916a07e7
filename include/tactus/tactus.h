// tactus/tactus.h: everything a controller or a plugin needs.
//
// tactus is an extended Model-View-Controller framework for haptic surgical
// simulation. The model (tactus/model.h) is a set of double-buffered
// components; controllers (tactus/controller.h) change it, each on a thread
// at its own rate; views only read it (tactus/haptics.h: the force model a
// controller publishes for the haptics controller to render on a device;
// tactus/components.h: the layout of every component that crosses controllers).
// See docs/architecture.md.
#ifndef TACTUS_H
#define TACTUS_H

#include <tactus/components.h>
#include <tactus/controller.h>
#include <tactus/haptics.h>
#include <tactus/model.h>
#include <tactus/stats.h>

#define TX_VERSION "0.1.0"

#endif
