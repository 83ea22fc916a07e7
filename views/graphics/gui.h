// Internal: the trainer's GUI in the window, Dear ImGui behind a thin C
// interface (gui_imgui.cpp); the panels themselves are C (gui_panel.c).
// Built when GLFW and libimgui-dev are found (TX_HAVE_GUI). Used only from the
// view's rendering thread, which owns the window and its GL context.
#ifndef TX_VIEWS_GRAPHICS_GUI_H
#define TX_VIEWS_GRAPHICS_GUI_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tx_gui tx_gui;

// with the window's GL context current; NULL with tx_error() when the backends do not start
tx_gui* tx_gui_create(void* glfw_window);
void tx_gui_destroy(tx_gui* g);

// input from the window's callbacks; true when the GUI takes it (the tool does not move)
bool tx_gui_mouse_button(tx_gui* g, int button, int action, int mods);
bool tx_gui_scroll(tx_gui* g, double dx, double dy);
bool tx_gui_key(tx_gui* g, int key, int scancode, int action, int mods);
void tx_gui_char(tx_gui* g, unsigned c);
void tx_gui_cursor(tx_gui* g, double x, double y); // window px
bool tx_gui_wants_mouse(const tx_gui* g);

void tx_gui_set_shown(tx_gui* g, bool shown);
bool tx_gui_shown(const tx_gui* g);

// One frame of panels, drawn over the framebuffer of fb_w x fb_h px, which
// holds tiles_x x tiles_y eyes (sbs 2 x 1, tb 1 x 2): the panels are drawn
// in each eye at the same place, zero disparity; with quad buffers into both
// back buffers. Input is read in the eye under the cursor.
// The panels are laid out and drawn into a texture only on input or at 10 Hz,
// and copied into the eyes every frame.
void tx_gui_frame(tx_gui* g, int fb_w, int fb_h, int tiles_x, int tiles_y, bool quad);

// widgets, for gui_panel.c, between tx_gui_frame's call of tx_gui_panels and its draw
bool tx_gui_begin(const char* title, float x, float y, float w, float h);
void tx_gui_end(void);
bool tx_gui_header(const char* label, bool open);
bool tx_gui_tree_begin(const char* label); // a closed node, indented; tx_gui_tree_end when it returns true
void tx_gui_tree_end(void);
bool tx_gui_button(const char* label);
void tx_gui_same_line(void);
void tx_gui_text(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
bool tx_gui_slider(const char* label, double* v, double min, double max, const char* format);
bool tx_gui_input(const char* label, double* v, const char* format); // true when committed
void tx_gui_plot(const char* label, const float* values, int n, int offset, float height);
bool tx_gui_table_begin(const char* id, int columns);
void tx_gui_table_row(const char* const* cells, int columns);
void tx_gui_table_end(void);

// The scenario picker (tx_window_pick): while set, tx_gui_frame draws it
// instead of the trainer's panels. It lists n scenarios and, when start is
// set, the chosen one and each hand's device: TX_PICK_SCENARIO (the file's
// own), TX_PICK_MOUSE (one hand at most) or TX_PICK_SPEC (a --device spec
// typed into spec). A click on a name or typing part of it chooses; Start or
// Enter starts.
enum { TX_PICK_SCENARIO, TX_PICK_MOUSE, TX_PICK_SPEC };
#define TX_PICK_HANDS 2
typedef struct tx_pick {
  const char* const* names;
  const char* const* about; // one line each
  int n;
  int chosen;
  int device[TX_PICK_HANDS];
  char spec[TX_PICK_HANDS][128];
  bool start;
  char filter[64]; // typed: only the names holding it are listed; Enter starts the chosen one
  bool focused;    // the filter had the keyboard once
} tx_pick;
void tx_gui_set_pick(tx_gui* g, tx_pick* p);

// the panels (gui_panel.c): the run's controls, inspect and tune
void tx_gui_panels(float eye_w, float eye_h);
// a device's position (m) and force (N, or NULL) as the frame drew them, for its plots
// the procedure's current step, as the frame read it; NULL: the run has none
void tx_gui_procedure(const char* text);
void tx_gui_sample(const char* device, double t_s, const double pos[3], const double* force);

#ifdef __cplusplus
}
#endif

#endif
