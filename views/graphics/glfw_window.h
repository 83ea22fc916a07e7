// Internal: a live GLFW window for a graphics view (X11, where DISPLAY is set).
// Quad-buffered stereo is asked for when wanted and used when the context
// offers it. Mouse and keyboard move the tool of a `--device mouse` device:
//   drag with the left button   x and z (in the horizontal plane)
//   scroll wheel, Q / E         y (up, down)
//   arrow keys, W A S D         x and z in steps
//   space                       button 0 (held)
// and, where the view has a laparoscope (laparoscope.h), move it about its port:
//   drag with the right button  turn it (yaw, pitch)
//   Ctrl + scroll wheel         slide it in and out
//   Esc or closing the window   ends the run (as Ctrl-C does)
//   P, N, R                     pause or resume, single step, reset (controllers/system.h)
//   [ and ]                     halve, double the time scale (x0.25 to x1)
//   H                           hides or shows the panels (where built with Dear ImGui, gui.h)
// GLFW is used from the view's rendering thread, after the probe at load.
#ifndef TX_VIEWS_GRAPHICS_GLFW_WINDOW_H
#define TX_VIEWS_GRAPHICS_GLFW_WINDOW_H

#include "gl.h"

#include <stdbool.h>
#include <stddef.h>

typedef struct tx_window tx_window;

typedef enum tx_window_lack { TX_WINDOW_OK, TX_WINDOW_NO_DISPLAY, TX_WINDOW_NO_QUAD } tx_window_lack;
// at load time, before the run writes anything: whether the display opens and,
// with need_quad, offers a quad-buffered GL context; the reason in tx_error() when not.
// GLFW stays initialised, as after tx_window_open.
tx_window_lack tx_window_probe(bool need_quad);
// whether windows opened from now on show the trainer's panels (default true;
// `tactus bench render` measures their cost against a window without them)
void tx_window_show_panels(bool shown);
// NULL with a one-line message in tx_error() when no window can be made
tx_window* tx_window_open(int width, int height, bool want_quad);
void tx_window_close(tx_window* w);
bool tx_window_is_quad(const tx_window* w);
tx_gl_proc tx_window_proc(const char* name);
void tx_window_framebuffer(const tx_window* w, int* width, int* height);
void tx_window_set_title(tx_window* w, const char* title);
void tx_window_resize(tx_window* w, int width, int height);
// the panels over the frame drawn, in each of tiles_x x tiles_y eyes (nothing without Dear ImGui)
void tx_window_draw_gui(tx_window* w, int tiles_x, int tiles_y);
// a drawn device's position (m) and force (N, or NULL), for the panels' plots
// the procedure's current step for the panels (NULL: no procedure in this run)
void tx_window_procedure(tx_window* t, const char* text);
void tx_window_sample(tx_window* w, const char* device, double t_s, const double pos[3], const double* force);
// show the frame and handle input; false once the window asked to close
bool tx_window_present(tx_window* w);

// The scenario picker, in a window of its own (tactus run --view window with
// no scenario): names and one line about each; the index chosen, with each
// hand's device in devices[h] as a --device spec ("mouse", "sim", ...; ""
// for the scenario's own); -1 when the window was closed, -2 with tx_error()
// when it does not open (or the build has no Dear ImGui).
int tx_window_pick(const char* const* names, const char* const* about, int n, char devices[2][128]);
// the laparoscope's moves since the last call: yaw, pitch (rad), insertion (m)
void tx_window_take_scope(tx_window* w, double move[3]);

#endif
