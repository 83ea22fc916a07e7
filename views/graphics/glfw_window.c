// A GLFW window: GL 3.3 core context, quad-buffer stereo when offered, and
// mouse and keyboard input for the `mouse` device (through window_input.h).
#include "glfw_window.h"

#include "../../model/error.h"

#include "laparoscope.h"
#include "window_input.h"
#ifdef TX_HAVE_GUI
#include "gui.h"
#endif

#include "../../controllers/system.h"

#include <tactus/components.h>

#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DRAG_M_PER_PX 0.0004 // tool travel per pixel of mouse drag
#define SCROLL_M 0.002       // per scroll step
#define KEY_M 0.002          // per key press (and repeat)

struct tx_window {
  GLFWwindow* w;
  bool quad;
  double tool[3];    // m, where the input has put the tool
  uint32_t buttons;
  double last_x, last_y; // px, the cursor at the last event
  bool dragging;
  bool turning;      // the right button: the laparoscope
  double scope[3];   // its moves not yet taken: yaw, pitch (rad), insertion (m)
  struct tx_gui* gui; // the trainer's panels, where Dear ImGui is built in
};

static char glfw_error[256];
static bool panels_at_open = true; // tx_window_show_panels

void tx_window_show_panels(bool shown) { panels_at_open = shown; }
static void on_error(int code, const char* text) {
  (void)code;
  snprintf(glfw_error, sizeof glfw_error, "%s", text);
}

static void publish(tx_window* t) { tx_window_input_set(t->tool, t->buttons); }

static void on_button(GLFWwindow* w, int button, int action, int mods) {
  tx_window* t = glfwGetWindowUserPointer(w);
#ifdef TX_HAVE_GUI
  if (t->gui && tx_gui_mouse_button(t->gui, button, action, mods) && action == GLFW_PRESS) return; // a click on a panel
#else
  (void)mods;
#endif
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    t->dragging = action == GLFW_PRESS;
    glfwGetCursorPos(w, &t->last_x, &t->last_y);
  }
  if (button == GLFW_MOUSE_BUTTON_RIGHT) {
    t->turning = action == GLFW_PRESS;
    glfwGetCursorPos(w, &t->last_x, &t->last_y);
  }
}

static void on_cursor(GLFWwindow* w, double x, double y) {
  tx_window* t = glfwGetWindowUserPointer(w);
#ifdef TX_HAVE_GUI
  if (t->gui) tx_gui_cursor(t->gui, x, y);
#endif
  if (t->dragging) {
    t->tool[0] += (x - t->last_x) * DRAG_M_PER_PX;
    t->tool[2] += (y - t->last_y) * DRAG_M_PER_PX; // down the screen is towards the viewer
    publish(t);
  }
  if (t->turning) { // the view follows the hand: drag right to look right, up to look up
    t->scope[0] -= (x - t->last_x) * TX_SCOPE_RAD_PER_PX;
    t->scope[1] -= (y - t->last_y) * TX_SCOPE_RAD_PER_PX;
  }
  t->last_x = x;
  t->last_y = y;
}

static void on_scroll(GLFWwindow* w, double dx, double dy) {
  (void)dx;
  tx_window* t = glfwGetWindowUserPointer(w);
#ifdef TX_HAVE_GUI
  if (t->gui && tx_gui_scroll(t->gui, dx, dy)) return;
#endif
  if (glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS) {
    t->scope[2] += dy * TX_SCOPE_M_PER_SCROLL;
    return;
  }
  t->tool[1] += dy * SCROLL_M;
  publish(t);
}

// the run's controls (controllers/system.h), with or without the panels: true when the key is one
static bool control_key(int key) {
  tx_system* s = tx_system_running();
  if (!s) return false;
  switch (key) { // a line that cannot be logged is no reason to refuse the control
  case GLFW_KEY_P: (void)(tx_system_paused(s) ? tx_system_resume(s) : tx_system_pause(s)); return true;
  case GLFW_KEY_N: (void)tx_system_step(s); return true;
  case GLFW_KEY_R: (void)tx_system_reset(s); return true;
  case GLFW_KEY_LEFT_BRACKET: (void)tx_system_set_time_scale(s, fmax(TX_TIME_SCALE_MIN, tx_system_time_scale(s) / 2)); return true;
  case GLFW_KEY_RIGHT_BRACKET: (void)tx_system_set_time_scale(s, fmin(1, tx_system_time_scale(s) * 2)); return true;
  default: return false;
  }
}

#ifdef TX_HAVE_GUI
static void on_char(GLFWwindow* w, unsigned c) {
  tx_window* t = glfwGetWindowUserPointer(w);
  if (t->gui) tx_gui_char(t->gui, c);
}
#endif

static void on_key(GLFWwindow* w, int key, int scancode, int action, int mods) {
  tx_window* t = glfwGetWindowUserPointer(w);
#ifdef TX_HAVE_GUI
  if (t->gui && tx_gui_key(t->gui, key, scancode, action, mods)) return; // typing into a panel
  if (t->gui && key == GLFW_KEY_H && action == GLFW_PRESS) {
    tx_gui_set_shown(t->gui, !tx_gui_shown(t->gui));
    return;
  }
#else
  (void)scancode;
  (void)mods;
#endif
  if (action == GLFW_PRESS && control_key(key)) return;
  if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS) glfwSetWindowShouldClose(w, GLFW_TRUE);
  if (key == GLFW_KEY_SPACE) {
    if (action == GLFW_PRESS) t->buttons |= 1u;
    if (action == GLFW_RELEASE) t->buttons &= ~1u;
  }
  if (action == GLFW_RELEASE) {
    publish(t);
    return;
  }
  switch (key) {
  case GLFW_KEY_LEFT: case GLFW_KEY_A: t->tool[0] -= KEY_M; break;
  case GLFW_KEY_RIGHT: case GLFW_KEY_D: t->tool[0] += KEY_M; break;
  case GLFW_KEY_UP: case GLFW_KEY_W: t->tool[2] -= KEY_M; break;
  case GLFW_KEY_DOWN: case GLFW_KEY_S: t->tool[2] += KEY_M; break;
  case GLFW_KEY_Q: t->tool[1] += KEY_M; break;
  case GLFW_KEY_E: t->tool[1] -= KEY_M; break;
  default: break;
  }
  for (int i = 0; i < 3; i++) t->tool[i] = fmax(-TX_POINTER_REACH_M, fmin(TX_POINTER_REACH_M, t->tool[i]));
  publish(t);
}

static GLFWwindow* make(int width, int height, bool quad, bool visible) {
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_STEREO, quad ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  return glfwCreateWindow(width, height, "tactus", NULL, NULL);
}

tx_window_lack tx_window_probe(bool need_quad) {
  glfwSetErrorCallback(on_error);
  glfw_error[0] = 0;
  if (!glfwInit()) return tx_set_error("cannot open the display (GLFW: %s)", glfw_error), TX_WINDOW_NO_DISPLAY;
  if (!need_quad) return TX_WINDOW_OK;
  // a hidden window with quad buffers, made and closed at once: the answer is the driver's
  GLFWwindow* w = make(16, 16, true, false);
  if (!w) return tx_set_error("the display's GL has no quad-buffered stereo (GLFW: %s)", glfw_error), TX_WINDOW_NO_QUAD;
  glfwDestroyWindow(w);
  return TX_WINDOW_OK;
}

tx_window* tx_window_open(int width, int height, bool want_quad) {
  glfwSetErrorCallback(on_error);
  if (!glfwInit()) return tx_set_error("no window: GLFW: %s", glfw_error), NULL;
  tx_window* t = calloc(1, sizeof *t);
  if (!t) return tx_set_error("out of memory"), NULL;
  // quad buffers where the driver has them; otherwise the chosen mode in a plain window
  if (want_quad && (t->w = make(width, height, true, true))) t->quad = true;
  else t->w = make(width, height, false, true);
  if (!t->w) {
    free(t);
    return tx_set_error("no window: GLFW: %s", glfw_error), NULL;
  }
  glfwMakeContextCurrent(t->w);
  glfwSwapInterval(0); // the view's rate paces frames, not the display
  glfwSetWindowUserPointer(t->w, t);
  glfwSetMouseButtonCallback(t->w, on_button);
  glfwSetCursorPosCallback(t->w, on_cursor);
  glfwSetScrollCallback(t->w, on_scroll);
  glfwSetKeyCallback(t->w, on_key);
#ifdef TX_HAVE_GUI
  glfwSetCharCallback(t->w, on_char);
  if (!(t->gui = tx_gui_create(t->w))) {
    glfwDestroyWindow(t->w);
    free(t);
    return NULL; // tx_error() says why
  }
  tx_gui_set_shown(t->gui, panels_at_open);
#endif
  t->tool[1] = 0.02;
  publish(t);
  return t;
}

// GLFW stays initialised for the rest of the process: terminating it unloads
// the GL driver, whose process-wide state then can no longer be told apart
void tx_window_close(tx_window* t) {
  if (!t) return;
#ifdef TX_HAVE_GUI
  tx_gui_destroy(t->gui); // with its GL objects, while the context is current
#endif
  glfwDestroyWindow(t->w);
  free(t);
}

bool tx_window_is_quad(const tx_window* t) { return t->quad; }
tx_gl_proc tx_window_proc(const char* name) { return (tx_gl_proc)glfwGetProcAddress(name); }
void tx_window_framebuffer(const tx_window* t, int* width, int* height) { glfwGetFramebufferSize(t->w, width, height); }
void tx_window_set_title(tx_window* t, const char* title) { glfwSetWindowTitle(t->w, title); }
void tx_window_resize(tx_window* t, int width, int height) { glfwSetWindowSize(t->w, width, height); }

void tx_window_draw_gui(tx_window* t, int tiles_x, int tiles_y) {
#ifdef TX_HAVE_GUI
  int fw, fh;
  glfwGetFramebufferSize(t->w, &fw, &fh);
  if (t->gui) tx_gui_frame(t->gui, fw, fh, t->quad ? 1 : tiles_x, t->quad ? 1 : tiles_y, t->quad);
#else
  (void)t, (void)tiles_x, (void)tiles_y;
#endif
}

void tx_window_sample(tx_window* t, const char* device, double t_s, const double pos[3], const double* force) {
#ifdef TX_HAVE_GUI
  if (t->gui) tx_gui_sample(device, t_s, pos, force);
#else
  (void)t, (void)device, (void)t_s, (void)pos, (void)force;
#endif
}

void tx_window_procedure(tx_window* t, const char* text) {
#ifdef TX_HAVE_GUI
  if (t->gui) tx_gui_procedure(text);
#else
  (void)t, (void)text;
#endif
}

bool tx_window_present(tx_window* t) {
  glfwSwapBuffers(t->w);
  glfwPollEvents();
  return !glfwWindowShouldClose(t->w);
}

int tx_window_pick(const char* const* names, const char* const* about, int n, char devices[2][128]) {
  devices[0][0] = devices[1][0] = 0;
#ifdef TX_HAVE_GUI
  tx_window* t = tx_window_open(640, 480, false);
  if (!t) return -2;
  glfwSetWindowTitle(t->w, "tactus: choose a scenario");
  void (*clear_color)(float, float, float, float) = (void (*)(float, float, float, float))glfwGetProcAddress("glClearColor");
  void (*clear)(unsigned) = (void (*)(unsigned))glfwGetProcAddress("glClear");
  tx_pick pick = {.names = names, .about = about, .n = n, .chosen = n > 0 ? 0 : -1};
  tx_gui_set_pick(t->gui, &pick);
  while (!pick.start && !glfwWindowShouldClose(t->w)) {
    glfwWaitEventsTimeout(0.05); // nothing moves here but what the hand does
    clear_color(0.1f, 0.1f, 0.12f, 1);
    clear(0x00004000); // GL_COLOR_BUFFER_BIT
    tx_window_draw_gui(t, 1, 1);
    glfwSwapBuffers(t->w);
  }
  tx_gui_set_pick(t->gui, NULL);
  bool started = pick.start;
  tx_window_close(t);
  tx_window_input_reset(); // the picker's clicks are not the run's input
  for (int h = 0; h < TX_PICK_HANDS && h < 2; h++)
    snprintf(devices[h], 128, "%s", pick.device[h] == TX_PICK_MOUSE ? "mouse" : pick.device[h] == TX_PICK_SPEC ? pick.spec[h] : "");
  return started ? pick.chosen : -1;
#else
  (void)names, (void)about, (void)n;
  return tx_set_error("the scenario picker needs Dear ImGui (libimgui-dev)"), -2;
#endif
}

void tx_window_take_scope(tx_window* t, double move[3]) {
  for (int i = 0; i < 3; i++) move[i] = t->scope[i], t->scope[i] = 0;
}
