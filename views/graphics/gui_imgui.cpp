// Dear ImGui (libimgui-dev, with its GLFW and OpenGL 3 backends) behind gui.h's
// C interface. The backends' own GL loader opens the same libGL as GLFW; the
// GLFW callbacks stay the window's, which forward to ImGui.
#include "gui.h"

extern "C" {
#include "../../model/error.h"
}

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <new>

#ifndef GL_BACK
#define GL_BACK 0x0405
#endif
#ifndef GL_DRAW_BUFFER
#define GL_DRAW_BUFFER 0x0C01
#endif

struct tx_gui {
  GLFWwindow* window;
  ImGuiContext* context;
  bool shown;
  void (*draw_buffer)(unsigned);
  void (*get_integerv)(unsigned, int*);
  // ImGui 1.86 reads keys as held or not at each frame: a tap shorter than a
  // frame would be lost, so the release of a key pressed since the last frame
  // waits until a frame has seen it held (forwarded before the next frame
  // starts, so the modifiers never change within a frame)
  int pressed[16], npressed;
  struct tap { int key, scancode, mods; } deferred[16], ready[16];
  int ndeferred, nready;
};

extern "C" {

tx_gui* tx_gui_create(void* glfw_window) {
  tx_gui* g = new (std::nothrow) tx_gui();
  if (!g) return tx_set_error("out of memory"), nullptr;
  g->window = static_cast<GLFWwindow*>(glfw_window);
  g->shown = true;
  IMGUI_CHECKVERSION();
  g->context = ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr; // the layout is the code's, not a file's in the working folder
  io.LogFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui::GetStyle().Alpha = 0.92f;
  if (!ImGui_ImplGlfw_InitForOpenGL(g->window, false)) {
    ImGui::DestroyContext(g->context);
    delete g;
    return tx_set_error("the GUI's GLFW backend did not start"), nullptr;
  }
  if (!ImGui_ImplOpenGL3_Init("#version 330 core")) {
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext(g->context);
    delete g;
    return tx_set_error("the GUI's OpenGL 3 backend did not start"), nullptr;
  }
  g->draw_buffer = reinterpret_cast<void (*)(unsigned)>(glfwGetProcAddress("glDrawBuffer"));
  g->get_integerv = reinterpret_cast<void (*)(unsigned, int*)>(glfwGetProcAddress("glGetIntegerv"));
  return g;
}

void tx_gui_destroy(tx_gui* g) {
  if (!g) return;
  ImGui::SetCurrentContext(g->context);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext(g->context);
  delete g;
}

bool tx_gui_mouse_button(tx_gui* g, int button, int action, int mods) {
  if (!g->shown) return false;
  ImGui_ImplGlfw_MouseButtonCallback(g->window, button, action, mods);
  return ImGui::GetIO().WantCaptureMouse;
}

bool tx_gui_scroll(tx_gui* g, double dx, double dy) {
  if (!g->shown) return false;
  ImGui_ImplGlfw_ScrollCallback(g->window, dx, dy);
  return ImGui::GetIO().WantCaptureMouse;
}

bool tx_gui_key(tx_gui* g, int key, int scancode, int action, int mods) {
  if (!g->shown) return false;
  bool tapped = false;
  for (int i = 0; i < g->npressed && !tapped; i++) tapped = g->pressed[i] == key;
  if (action == GLFW_RELEASE && tapped && g->ndeferred < 16) {
    g->deferred[g->ndeferred++] = tx_gui::tap{key, scancode, mods};
    return ImGui::GetIO().WantCaptureKeyboard;
  }
  if (action == GLFW_PRESS && g->npressed < 16) g->pressed[g->npressed++] = key;
  ImGui_ImplGlfw_KeyCallback(g->window, key, scancode, action, mods);
  return ImGui::GetIO().WantCaptureKeyboard;
}

void tx_gui_char(tx_gui* g, unsigned c) {
  if (g->shown) ImGui_ImplGlfw_CharCallback(g->window, c);
}

bool tx_gui_wants_mouse(const tx_gui* g) { return g->shown && ImGui::GetIO().WantCaptureMouse; }
void tx_gui_set_shown(tx_gui* g, bool shown) { g->shown = shown; }
bool tx_gui_shown(const tx_gui* g) { return g->shown; }

void tx_gui_frame(tx_gui* g, int fb_w, int fb_h, int tiles_x, int tiles_y, bool quad) {
  if (!g->shown || fb_w <= 0 || fb_h <= 0) return;
  // the taps the last frame saw held are released now; those since wait for this one
  for (int i = 0; i < g->nready; i++)
    ImGui_ImplGlfw_KeyCallback(g->window, g->ready[i].key, g->ready[i].scancode, GLFW_RELEASE, g->ready[i].mods);
  for (int i = 0; i < g->ndeferred; i++) g->ready[i] = g->deferred[i];
  g->nready = g->ndeferred;
  g->ndeferred = 0;
  g->npressed = 0;
  const float eye_w = (float)fb_w / (float)tiles_x, eye_h = (float)fb_h / (float)tiles_y;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  // one eye's image is the GUI's screen; the cursor acts in the eye it is over
  io.DisplaySize = ImVec2(eye_w, eye_h);
  io.DisplayFramebufferScale = ImVec2(1, 1);
  if (io.MousePos.x >= 0 && io.MousePos.y >= 0)
    io.MousePos = ImVec2(std::fmod(io.MousePos.x, eye_w), std::fmod(io.MousePos.y, eye_h));
  ImGui::NewFrame();
  tx_gui_panels(eye_w, eye_h);
  ImGui::Render();
  ImDrawData* d = ImGui::GetDrawData();
  // the same panels in every eye's tile at the same place: zero disparity
  d->DisplaySize = ImVec2((float)fb_w, (float)fb_h);
  int saved = 0;
  if (quad && g->draw_buffer && g->get_integerv) { // GL_BACK is both back buffers of a quad-buffered context
    g->get_integerv(GL_DRAW_BUFFER, &saved);
    g->draw_buffer(GL_BACK);
  }
  for (int j = 0; j < tiles_y; j++)
    for (int i = 0; i < tiles_x; i++) {
      d->DisplayPos = ImVec2(-(float)i * eye_w, -(float)j * eye_h);
      ImGui_ImplOpenGL3_RenderDrawData(d);
    }
  if (saved) g->draw_buffer((unsigned)saved);
}

bool tx_gui_begin(const char* title, float x, float y, float w, float h) {
  ImGui::SetNextWindowPos(ImVec2(x, y), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(w, h), ImGuiCond_FirstUseEver);
  return ImGui::Begin(title);
}

void tx_gui_end(void) { ImGui::End(); }

bool tx_gui_header(const char* label, bool open) {
  return ImGui::CollapsingHeader(label, open ? ImGuiTreeNodeFlags_DefaultOpen : 0);
}

bool tx_gui_button(const char* label) { return ImGui::Button(label); }
void tx_gui_same_line(void) { ImGui::SameLine(); }

void tx_gui_text(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  ImGui::TextV(fmt, ap);
  va_end(ap);
}

bool tx_gui_slider(const char* label, double* v, double min, double max, const char* format) {
  return ImGui::SliderScalar(label, ImGuiDataType_Double, v, &min, &max, format);
}

bool tx_gui_input(const char* label, double* v, const char* format) {
  ImGui::SetNextItemWidth(110); // room for "instance.key (units)" beside it
  ImGui::InputDouble(label, v, 0, 0, format);
  return ImGui::IsItemDeactivatedAfterEdit();
}

void tx_gui_plot(const char* label, const float* values, int n, int offset, float height) {
  ImGui::PlotLines(label, values, n, offset, nullptr, FLT_MAX, FLT_MAX, ImVec2(0, height));
}

bool tx_gui_table_begin(const char* id, int columns) {
  return ImGui::BeginTable(id, columns, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit);
}

void tx_gui_table_row(const char* const* cells, int columns) {
  ImGui::TableNextRow();
  for (int c = 0; c < columns; c++) {
    ImGui::TableSetColumnIndex(c);
    ImGui::TextUnformatted(cells[c]);
  }
}

void tx_gui_table_end(void) { ImGui::EndTable(); }

} // extern "C"
