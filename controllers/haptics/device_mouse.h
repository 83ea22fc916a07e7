// Internal: the input channel of the `mouse` device. A window's input thread
// sets where the mouse and keyboard put the tool; the haptics thread reads it
// through the `mouse` device backend (device.h) at its own rate. A sequence
// lock over sequentially consistent atomics: the writer never waits, a reader
// retries only while a write is under way. One channel per process (one window).
#ifndef TX_CONTROLLERS_HAPTICS_DEVICE_MOUSE_H
#define TX_CONTROLLERS_HAPTICS_DEVICE_MOUSE_H

#include <stdbool.h>
#include <stdint.h>

#define TX_MOUSE_WORKSPACE_M 0.2 // the tool stays in [-0.2, 0.2] m on each axis

// from the window: the tool point, m (clamped to the workspace), and the buttons held
void tx_mouse_input_set(const double pos[3], uint32_t buttons);
// the latest input; false until a window has set one
bool tx_mouse_input_get(double pos[3], uint32_t* buttons);
// the force last sent to the mouse device, N (for the window's overlay)
void tx_mouse_force_get(double force[3]);
// whether a mouse device is open (the window then drives it)
bool tx_mouse_device_open(void);

#endif
