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
#include <cstring>
#include <ctime>
#include <new>

#ifndef GL_BACK
#define GL_BACK 0x0405
#endif
#ifndef GL_DRAW_BUFFER
#define GL_DRAW_BUFFER 0x0C01
#endif

#define GL_FRAMEBUFFER 0x8D40
#define GL_READ_FRAMEBUFFER 0x8CA8
#define GL_DRAW_FRAMEBUFFER 0x8CA9
#define GL_DRAW_FRAMEBUFFER_BINDING 0x8CA6
#define GL_READ_FRAMEBUFFER_BINDING 0x8CAA
#define GL_COLOR_ATTACHMENT0 0x8CE0
#define GL_FRAMEBUFFER_COMPLETE 0x8CD5
#define GL_TEXTURE_2D_ 0x0DE1
#define GL_TEXTURE_BINDING_2D_ 0x8069
#define GL_RGBA8_ 0x8058
#define GL_BGRA_ 0x80E1
#define GL_UNSIGNED_BYTE_ 0x1401
#define GL_COLOR_BUFFER_BIT_ 0x00004000
#define GL_NEAREST_ 0x2600
#define GL_SCISSOR_TEST_ 0x0C11
#define GL_VIEWPORT_ 0x0BA2
#define GL_COLOR_CLEAR_VALUE_ 0x0C22

#define REFRESH_NS 100000000LL // the panels' text and plots are redrawn at 10 Hz without input

// the GL 3.3 entry points the texture and the copies need, from the window's context
struct gl_fns {
  void (*GenFramebuffers)(int, unsigned*);
  void (*DeleteFramebuffers)(int, const unsigned*);
  void (*BindFramebuffer)(unsigned, unsigned);
  void (*FramebufferTexture2D)(unsigned, unsigned, unsigned, unsigned, int);
  unsigned (*CheckFramebufferStatus)(unsigned);
  void (*GenTextures)(int, unsigned*);
  void (*DeleteTextures)(int, const unsigned*);
  void (*BindTexture)(unsigned, unsigned);
  void (*TexImage2D)(unsigned, int, int, int, int, int, unsigned, unsigned, const void*);
  void (*BlitFramebuffer)(int, int, int, int, int, int, int, int, unsigned, unsigned);
  void (*Viewport)(int, int, int, int);
  void (*Scissor)(int, int, int, int);
  void (*ClearColor)(float, float, float, float);
  void (*Clear)(unsigned);
  void (*Enable)(unsigned);
  void (*Disable)(unsigned);
  unsigned char (*IsEnabled)(unsigned);
  void (*GetIntegerv)(unsigned, int*);
  void (*GetFloatv)(unsigned, float*);
};

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
  // The panels are drawn into a texture of one eye's size, rebuilt on input or
  // every REFRESH_NS, and copied into each eye every frame: under a software
  // rasteriser a copy costs a fraction of drawing them (docs/trainer.md, Cost)
  gl_fns gl;
  unsigned fbo, tex;
  int tex_w, tex_h;
  bool dirty;          // input since the last build
  long long built_ns;  // when the texture was last drawn (0: never)
  ImVec4 rects[8];     // the windows' rectangles in it, eye px, top-down (x0, y0, x1, y1)
  int nrects;
  ImVec4 bg;           // their background, cleared into the texture
  bool hovered; // the cursor was over a window at its last move
  tx_pick* pick; // the scenario picker instead of the panels, while set
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
  // opaque: the windows are copied over the scene, and their background is a clear of the texture
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 0;
  g->bg = style.Colors[ImGuiCol_WindowBg];
  style.Colors[ImGuiCol_WindowBg].w = 0;
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
  bool all = true;
#define LOAD(name)                                                                                 \
  all = all && (*reinterpret_cast<void**>(&g->gl.name) = reinterpret_cast<void*>(glfwGetProcAddress("gl" #name)));
  LOAD(GenFramebuffers) LOAD(DeleteFramebuffers) LOAD(BindFramebuffer) LOAD(FramebufferTexture2D)
  LOAD(CheckFramebufferStatus) LOAD(GenTextures) LOAD(DeleteTextures) LOAD(BindTexture) LOAD(TexImage2D)
  LOAD(BlitFramebuffer) LOAD(Viewport) LOAD(Scissor) LOAD(ClearColor) LOAD(Clear) LOAD(Enable) LOAD(Disable)
  LOAD(IsEnabled) LOAD(GetIntegerv) LOAD(GetFloatv)
#undef LOAD
  if (!all) {
    tx_gui_destroy(g);
    return tx_set_error("the GUI's GL context lacks framebuffer objects"), nullptr;
  }
  g->get_integerv = reinterpret_cast<void (*)(unsigned, int*)>(glfwGetProcAddress("glGetIntegerv"));
  return g;
}

void tx_gui_destroy(tx_gui* g) {
  if (!g) return;
  ImGui::SetCurrentContext(g->context);
  if (g->fbo) g->gl.DeleteFramebuffers(1, &g->fbo), g->gl.DeleteTextures(1, &g->tex);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext(g->context);
  delete g;
}

bool tx_gui_mouse_button(tx_gui* g, int button, int action, int mods) {
  if (!g->shown) return false;
  g->dirty = true;
  ImGui_ImplGlfw_MouseButtonCallback(g->window, button, action, mods);
  return ImGui::GetIO().WantCaptureMouse;
}

bool tx_gui_scroll(tx_gui* g, double dx, double dy) {
  if (!g->shown) return false;
  g->dirty = true;
  ImGui_ImplGlfw_ScrollCallback(g->window, dx, dy);
  return ImGui::GetIO().WantCaptureMouse;
}

bool tx_gui_key(tx_gui* g, int key, int scancode, int action, int mods) {
  if (!g->shown) return false;
  g->dirty = true;
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
  if (g->shown) g->dirty = true, ImGui_ImplGlfw_CharCallback(g->window, c);
}

bool tx_gui_wants_mouse(const tx_gui* g) { return g->shown && ImGui::GetIO().WantCaptureMouse; }
void tx_gui_set_shown(tx_gui* g, bool shown) { g->shown = shown, g->dirty = true; }

// a move over a window, or off one, changes what it highlights
void tx_gui_cursor(tx_gui* g, double x, double y) {
  if (!g->shown || !g->tex_w) return;
  float ex = std::fmod((float)x, (float)g->tex_w), ey = std::fmod((float)y, (float)g->tex_h);
  bool over = false;
  for (int k = 0; k < g->nrects && !over; k++)
    over = ex >= g->rects[k].x && ex < g->rects[k].z && ey >= g->rects[k].y && ey < g->rects[k].w;
  if (over || g->hovered) g->dirty = true;
  g->hovered = over;
}
bool tx_gui_shown(const tx_gui* g) { return g->shown; }

static long long mono_ns() {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (long long)t.tv_sec * 1000000000LL + t.tv_nsec;
}

static tx_gui* building; // the GUI whose panels are being laid out, for tx_gui_begin

// the scenario picker: the scenarios, the chosen one's line, each hand's device, Start
static void pick_panel(tx_pick* p, float w, float h) {
  if (!tx_gui_begin("choose a scenario", 8, 8, w - 16, h - 16)) {
    tx_gui_end();
    return;
  }
  if (!p->focused) ImGui::SetKeyboardFocusHere(), p->focused = true;
  bool enter = ImGui::InputText("type to choose", p->filter, sizeof p->filter, ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::TextUnformatted("Scenario");
  int first = -1;
  bool chosen_shown = false;
  for (int i = 0; i < p->n; i++) {
    if (p->filter[0] && !std::strstr(p->names[i], p->filter)) continue;
    if (first < 0) first = i;
    if (ImGui::Selectable(p->names[i], p->chosen == i)) p->chosen = i;
    chosen_shown = chosen_shown || p->chosen == i;
  }
  if (!chosen_shown) p->chosen = first; // typing chooses the first name that holds it
  if (enter && p->chosen >= 0) p->start = true;
  ImGui::Separator();
  if (p->chosen >= 0 && p->chosen < p->n) ImGui::TextWrapped("%s", p->about[p->chosen]);
  ImGui::Separator();
  for (int hand = 0; hand < TX_PICK_HANDS; hand++) {
    ImGui::PushID(hand);
    ImGui::Text("Device for hand %d", hand);
    int was = p->device[hand];
    ImGui::RadioButton("the scenario's", &p->device[hand], TX_PICK_SCENARIO);
    ImGui::SameLine();
    ImGui::RadioButton("mouse", &p->device[hand], TX_PICK_MOUSE);
    ImGui::SameLine();
    ImGui::RadioButton("other:", &p->device[hand], TX_PICK_SPEC);
    if (p->device[hand] == TX_PICK_MOUSE && was != TX_PICK_MOUSE) // one mouse: the other hand gives it up
      for (int o = 0; o < TX_PICK_HANDS; o++)
        if (o != hand && p->device[o] == TX_PICK_MOUSE) p->device[o] = TX_PICK_SCENARIO;
    if (p->device[hand] == TX_PICK_SPEC) ImGui::InputText("--device: sim, udp:HOST:PORT, ...", p->spec[hand], sizeof p->spec[hand]);
    ImGui::PopID();
  }
  if (ImGui::Button("Start") && p->chosen >= 0) p->start = true;
  tx_gui_end();
}

// the texture of one eye's size, made again when the eye's size changes
static bool ensure_target(tx_gui* g, int w, int h) {
  const gl_fns& gl = g->gl;
  if (g->fbo && g->tex_w == w && g->tex_h == h) return true;
  if (!g->fbo) gl.GenFramebuffers(1, &g->fbo), gl.GenTextures(1, &g->tex);
  int bound = 0;
  gl.GetIntegerv(GL_TEXTURE_BINDING_2D_, &bound);
  gl.BindTexture(GL_TEXTURE_2D_, g->tex);
  // BGRA as the window's own buffer, so that the copy is a plain copy
  gl.TexImage2D(GL_TEXTURE_2D_, 0, GL_RGBA8_, w, h, 0, GL_BGRA_, GL_UNSIGNED_BYTE_, nullptr);
  gl.BindTexture(GL_TEXTURE_2D_, (unsigned)bound);
  int draw = 0;
  gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw);
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, g->fbo);
  gl.FramebufferTexture2D(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D_, g->tex, 0);
  bool ok = gl.CheckFramebufferStatus(GL_DRAW_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, (unsigned)draw);
  g->tex_w = w, g->tex_h = h;
  g->built_ns = 0;
  return ok;
}

// the eye's rectangle r (top-down) as GL's bottom-up x0, y0, x1, y1, inside w x h
static void gl_rect(const ImVec4& r, int w, int h, int out[4]) {
  int x0 = (int)std::floor(r.x), y0 = (int)std::floor(r.y), x1 = (int)std::ceil(r.z), y1 = (int)std::ceil(r.w);
  x0 = x0 < 0 ? 0 : x0, y0 = y0 < 0 ? 0 : y0, x1 = x1 > w ? w : x1, y1 = y1 > h ? h : y1;
  out[0] = x0, out[1] = h - y1, out[2] = x1, out[3] = h - y0;
}

// lay the panels out and draw them into the texture: the windows' backgrounds
// as cleared rectangles (a clear is the rasteriser's cheapest fill), the rest by ImGui
static void build(tx_gui* g, int eye_w, int eye_h) {
  const gl_fns& gl = g->gl;
  // the taps the last build saw held are released now; those since wait for this one
  for (int i = 0; i < g->nready; i++)
    ImGui_ImplGlfw_KeyCallback(g->window, g->ready[i].key, g->ready[i].scancode, GLFW_RELEASE, g->ready[i].mods);
  for (int i = 0; i < g->ndeferred; i++) g->ready[i] = g->deferred[i];
  g->nready = g->ndeferred;
  g->ndeferred = 0;
  g->npressed = 0;
  g->dirty = false;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  // one eye's image is the GUI's screen; the cursor acts in the eye it is over
  io.DisplaySize = ImVec2((float)eye_w, (float)eye_h);
  io.DisplayFramebufferScale = ImVec2(1, 1);
  if (io.MousePos.x >= 0 && io.MousePos.y >= 0)
    io.MousePos = ImVec2(std::fmod(io.MousePos.x, (float)eye_w), std::fmod(io.MousePos.y, (float)eye_h));
  ImGui::NewFrame();
  g->nrects = 0;
  building = g;
  if (g->pick) pick_panel(g->pick, (float)eye_w, (float)eye_h);
  else tx_gui_panels((float)eye_w, (float)eye_h);
  building = nullptr;
  ImGui::Render();
  int draw = 0, viewport[4];
  float clear[4];
  gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw);
  gl.GetIntegerv(GL_VIEWPORT_, viewport);
  gl.GetFloatv(GL_COLOR_CLEAR_VALUE_, clear);
  bool scissor = gl.IsEnabled(GL_SCISSOR_TEST_);
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, g->fbo);
  gl.Viewport(0, 0, eye_w, eye_h);
  gl.Enable(GL_SCISSOR_TEST_);
  gl.ClearColor(g->bg.x, g->bg.y, g->bg.z, 1);
  for (int k = 0; k < g->nrects; k++) {
    int r[4];
    gl_rect(g->rects[k], eye_w, eye_h, r);
    gl.Scissor(r[0], r[1], r[2] - r[0], r[3] - r[1]);
    gl.Clear(GL_COLOR_BUFFER_BIT_);
  }
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, (unsigned)draw);
  gl.Viewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  gl.ClearColor(clear[0], clear[1], clear[2], clear[3]);
  (scissor ? gl.Enable : gl.Disable)(GL_SCISSOR_TEST_);
  g->built_ns = mono_ns();
}

// ImGui needs a frame for each change of its input: a click, a key, a drag in progress, typing
static bool wants_build(const tx_gui* g) {
  if (g->dirty || g->ndeferred || g->nready || !g->built_ns || mono_ns() - g->built_ns >= REFRESH_NS) return true;
  const ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsAnyItemActive() || io.WantTextInput) return true;
  for (bool down : io.MouseDown)
    if (down) return true;
  return false;
}

void tx_gui_frame(tx_gui* g, int fb_w, int fb_h, int tiles_x, int tiles_y, bool quad) {
  if (!g->shown || fb_w <= 0 || fb_h <= 0) return;
  const gl_fns& gl = g->gl;
  const int eye_w = fb_w / tiles_x, eye_h = fb_h / tiles_y;
  if (!ensure_target(g, eye_w, eye_h)) return;
  if (wants_build(g)) build(g, eye_w, eye_h);
  // the same panels in every eye's tile at the same place: zero disparity
  int saved = 0, read = 0;
  if (quad && g->draw_buffer && g->get_integerv) { // GL_BACK is both back buffers of a quad-buffered context
    g->get_integerv(GL_DRAW_BUFFER, &saved);
    g->draw_buffer(GL_BACK);
  }
  gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read);
  bool scissor = gl.IsEnabled(GL_SCISSOR_TEST_);
  gl.Disable(GL_SCISSOR_TEST_); // a copy is clipped by the scissor
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, g->fbo);
  for (int j = 0; j < tiles_y; j++)
    for (int i = 0; i < tiles_x; i++)
      for (int k = 0; k < g->nrects; k++) {
        int r[4];
        gl_rect(g->rects[k], eye_w, eye_h, r);
        // GL counts rows from the bottom: the top row of tiles is the highest
        const int dx = i * eye_w, dy = (tiles_y - 1 - j) * eye_h;
        gl.BlitFramebuffer(r[0], r[1], r[2], r[3], r[0] + dx, r[1] + dy, r[2] + dx, r[3] + dy, GL_COLOR_BUFFER_BIT_,
                           GL_NEAREST_);
      }
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, (unsigned)read);
  if (scissor) gl.Enable(GL_SCISSOR_TEST_);
  if (saved) g->draw_buffer((unsigned)saved);
}

void tx_gui_set_pick(tx_gui* g, tx_pick* p) { g->pick = p, g->dirty = true; }

bool tx_gui_begin(const char* title, float x, float y, float w, float h) {
  ImGui::SetNextWindowPos(ImVec2(x, y), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(w, h), ImGuiCond_FirstUseEver);
  return ImGui::Begin(title);
}

// the window's rectangle is copied into the eyes: kept as it ends, when its size is known
void tx_gui_end(void) {
  if (building && building->nrects < 8) {
    ImVec2 p = ImGui::GetWindowPos(), z = ImGui::GetWindowSize();
    building->rects[building->nrects++] = ImVec4(p.x, p.y, p.x + z.x, p.y + z.y);
  }
  ImGui::End();
}

bool tx_gui_header(const char* label, bool open) {
  return ImGui::CollapsingHeader(label, open ? ImGuiTreeNodeFlags_DefaultOpen : 0);
}

bool tx_gui_tree_begin(const char* label) { return ImGui::TreeNode(label); }
void tx_gui_tree_end(void) { ImGui::TreePop(); }

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
