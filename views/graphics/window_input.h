// Internal: the window's mouse and keyboard, into the model.
//
// A view only reads, so the window (the graphics view's rendering thread,
// where GLFW delivers events) does not write the model itself: it leaves
// its latest input in a channel, and input.window, an ordinary controller of
// this folder, takes it at its own rate and publishes it as window.pointer
// (tx_pointer). The `mouse` device backend reads that component through the
// haptics controller, as any other device reads its hardware.
//
// The channel is a sequence lock over sequentially consistent atomics: the
// window never waits, a reader retries only while a write is under way.
#ifndef TX_VIEWS_GRAPHICS_WINDOW_INPUT_H
#define TX_VIEWS_GRAPHICS_WINDOW_INPUT_H

#include <tactus/controller.h>

#include <stdbool.h>
#include <stdint.h>

#define TX_WINDOW_INPUT_HZ 250.0 // input.window's rate: above any display's event rate

// from the window: the tool point (m, clamped to TX_POINTER_REACH_M) and the buttons held
void tx_window_input_set(const double pos[3], uint32_t buttons);
// the latest input; false until the window has set one
bool tx_window_input_get(double pos[3], uint32_t* buttons);
// forget any input (a new run starts without one)
void tx_window_input_reset(void);

// "input.window": writes window.pointer from the channel
extern const tx_controller_class tx_window_input;

#endif
