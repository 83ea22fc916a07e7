// Internal: the `mouse` device. A window's mouse and keyboard put the tool
// somewhere; the window's input controller (input.window, views/graphics)
// publishes that as window.pointer (tx_pointer), and the haptics controller
// feeds each tick's row to this backend before it reads the device, so the
// mouse goes through the model like any other input.
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_MOUSE_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_MOUSE_H

#include <tactus/components.h>

#define TX_MOUSE_INPUT "window.pointer" // the component the mouse device reads
#define TX_MOUSE_START_Y_M 0.02         // m, the tool waits this far above the origin until the first input

#endif
