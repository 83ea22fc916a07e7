// views.graphics: a read-only controller that hands snapshots to a rendering thread.
#include "graphics_view.h"

#include "contact_sheet.h"
#include "gui_inspect.h"
#include "png_writer.h"
#include "renderer.h"
#include "stereo_frame.h"
#include "view_def.h"

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/stats.h>

#if TX_WITH_OSMESA
#include "osmesa_target.h"
#endif
#if TX_WITH_GLFW
#include "glfw_window.h"
#include "overlay.h"
#endif

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <semaphore.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define SHEET_THUMBS 24

typedef enum { TARGET_PNG, TARGET_WINDOW } target_kind;

typedef struct view {
  tx_view_def def;
  target_kind target;
  tx_stereo_mode stereo;
  bool wait;                            // lockstep: wait for the renderer instead of dropping a frame
  int render_threads;                   // llvmpipe threads in effect
  tx_port ports[TX_DRAW_MAX][3];        // reads of each item
  char port_names[TX_DRAW_MAX][3][TX_NAME_MAX]; // their components, to share one read between items
  tx_port listens[TX_DRAW_MAX][TX_MARKER_STREAMS]; // markers: the event streams of each item
  tx_marker_list live[TX_DRAW_MAX];     // markers: grasps and knots as the events have left them, every step
  tx_marker_list handed[TX_DRAW_MAX];   // a copy handed to the renderer with the frame
  int nports[TX_DRAW_MAX];
  // handed to the renderer: snapshots held by the step's ports
  tx_scene scene;
  uint64_t seq[TX_DRAW_MAX][3];         // publish numbers, for the overlay's rates
  int64_t frame_sim_ns;                 // simulation time of the frame handed over
  uint64_t frame_index;                 // frames handed over so far
  sem_t go;                             // a frame (or the quit request) is ready
  sem_t idle;                           // the renderer holds no frame: a token the step takes
  sem_t started;                        // the renderer finished its setup
  pthread_t thread;
  bool thread_running;
  bool sems_ready;                      // the semaphores were made (init got that far)
  atomic_bool quit;
  bool setup_failed;
  char setup_error[512];                // the rendering thread's tx_error(), for init
  char finish_error[1024];              // a file of the last frames that cannot be written, for finish
  char frames_dir[4200];
  // the rendering thread's own
  uint64_t rendered, written, dropped;
  uint64_t timed;                       // frames in frame_ns (all but the first, where no warm-up frame was drawn)
  double first_frame_ms;                // ms, the first frame (shader compilation included)
  bool warming;                         // the renderer is on the warm-up frame (init): drawn, not counted or written
  bool warmed;                          // and has drawn it: first_frame_ms is that frame's
  tx_hist frame_ns;                     // render + read-back time of every frame, ns
  tx_hist frame_cpu_ns;                 // CPU time of the rendering thread for each, ns
  double cpu_ms_sum;                    // of the timed frames, for the mean
  tx_result r_frames, r_dropped, r_p50, r_p99, r_threads, r_written, r_first, r_cpu50, r_cpu_mean;
  tx_warning w_write, w_skipped;
  uint64_t skipped_reported;
  tx_ctx* ctx;                          // the step's context, for warnings from the renderer
  bool has_procedure;                   // procedure.step is written: the panels show its text
  tx_port procedure;
  char procedure_text[72];              // handed to the renderer with the frame
} view;

// the layouts of <tactus/components.h> that the renderer draws, by name suffix
#define KIND(suffix, T) {suffix, T##_TYPE, T##_COLS}
static const struct { const char* suffix; tx_type type; uint32_t cols; } kinds[] = {
    KIND(".x", tx_vertex), KIND(".tri", tx_triangle), KIND(".spheres", tx_sphere), KIND(".segments", tx_segment),
    KIND(".pose", tx_pose), KIND(".force", tx_force), KIND(".links", tx_pose), KIND(".held", tx_instrument_held),
    KIND(".force_model", tx_force_model), KIND(".punctures", tx_puncture)};
#undef KIND

// the type and width a drawn component must have: by its suffix, and scalars are f32 N x 1
static void schema_of(const tx_draw_item* it, const char* comp, tx_type* type, uint32_t* cols) {
  *type = TX_F32;
  *cols = 1;
  if (*it->scalar && strcmp(comp, it->scalar) == 0) return;
  size_t n = strlen(comp);
  for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
    size_t s = strlen(kinds[k].suffix);
    if (n > s && strcmp(comp + n - s, kinds[k].suffix) == 0) *type = kinds[k].type, *cols = kinds[k].cols;
  }
}

static const tx_param_def params[] = {
    {"view", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "the scenario's \"view\" object (docs/views.md); the loader passes it"},
    {"target", TX_PARAM_STR, NULL, 0, 0, 0, "png", "png (OSMesa frames) or window (GLFW); --view sets it"},
    {"stereo_mode", TX_PARAM_STR, NULL, 0, 0, 0, "mono", "mono, sbs, tb, anaglyph or lr; --stereo sets it"},
    {"wait", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "lockstep: wait for the renderer instead of dropping a frame"},
    {"render_threads", TX_PARAM_INT, "1", -1, 64, -1, NULL, "llvmpipe rasteriser threads (png only); -1: chosen from the CPUs"},
    {"available", TX_PARAM_STRS, NULL, 0, 256, 0, NULL, "the components written in the scenario; the loader passes them"},
};

static int configure(tx_setup* s, void** self) {
  view* v = calloc(1, sizeof *v);
  if (!v) return -1;
  *self = v;
  v->def = tx_view_def_default();
  const char* vj = tx_param_json_text(s, "view");
  const char* target = tx_table_str(s, "target");
  const char* stereo = tx_table_str(s, "stereo_mode");
  v->wait = tx_table_bool(s, "wait");
  int threads = (int)tx_table_int(s, "render_threads");
  const char* avail[256];
  int navail = tx_table_strs(s, "available", avail, 256);
  if (!target || !stereo) return -1;
  if (strcmp(target, "png") == 0) v->target = TARGET_PNG;
  else if (strcmp(target, "window") == 0) v->target = TARGET_WINDOW;
  else return tx_setup_fail(s, "target", "expected \"png\" or \"window\", got \"%s\"", target);
  if (!tx_stereo_mode_from_name(stereo, &v->stereo))
    return tx_setup_fail(s, "stereo_mode", "expected mono, sbs, tb, anaglyph or lr, got \"%s\"", stereo);
  if (vj) {
    if (tx_view_def_from_text(vj, &v->def)) return tx_setup_fail(s, "view", "%s", tx_error());
  }
  if (v->def.nitems == 0 && tx_view_def_auto_draw(&v->def, avail, navail) == 0)
    return tx_setup_fail(s, "view", "nothing to draw: no component follows the naming conventions (docs/views.md)");
#if !TX_WITH_OSMESA
  if (v->target == TARGET_PNG) return tx_setup_fail(s, "target", "this build has no OSMesa (TX_WITH_OSMESA=OFF)");
#else
  // llvmpipe reads this when the first context is made: set it now, before any thread starts
  v->render_threads = tx_osmesa_bound_threads(threads);
#endif
#if !TX_WITH_GLFW
  if (v->target == TARGET_WINDOW) return tx_setup_fail(s, "target", "this build has no GLFW (TX_WITH_GLFW=OFF)");
#else
  // a display that cannot be opened, or lr without quad buffers (a window shows one
  // image; lr's two need GL_BACK_LEFT and GL_BACK_RIGHT), is bad input found at load,
  // before the run has made a folder or a recording
  if (v->target == TARGET_WINDOW) {
    tx_window_lack lack = tx_window_probe(v->stereo == TX_STEREO_LR);
    if (lack == TX_WINDOW_NO_DISPLAY) return tx_setup_fail(s, "target", "--view window: %s", tx_error());
    if (lack == TX_WINDOW_NO_QUAD)
      return tx_setup_fail(s, "stereo_mode", "--stereo lr in a window: %s; use sbs, tb or anaglyph, or --view png for lr files",
                           tx_error());
  }
#endif
  (void)threads;
  // every component an item draws, with the schema it must have
  for (int i = 0; i < v->def.nitems; i++) {
    if (v->def.items[i].kind == TX_DRAW_INSTRUMENT) { // its meshes readable now: bad input at load, not at the first frame
      tx_instrument_mesh* im = tx_instrument_mesh_load(v->def.items[i].urdf);
      if (!im) return tx_setup_fail(s, "view", "draw[%d].urdf: %s", i, tx_error());
      tx_instrument_mesh_free(im);
    }
    char comps[3][TX_NAME_MAX];
    int n = tx_draw_item_components(&v->def.items[i], comps);
    for (int k = 0; k < n; k++) {
      tx_type type;
      uint32_t cols;
      schema_of(&v->def.items[i], comps[k], &type, &cols);
      memcpy(v->port_names[i][k], comps[k], TX_NAME_MAX);
      bool seen = false; // a component two items draw (markers on a drawn skin) is one read
      for (int j = 0; j < i && !seen; j++)
        for (int q = 0; q < v->nports[j] && !seen; q++)
          if (strcmp(v->port_names[j][q], comps[k]) == 0) v->ports[i][k] = v->ports[j][q], seen = true;
      if (!seen) v->ports[i][k] = tx_setup_read_as(s, comps[k], type, cols);
    }
    v->nports[i] = n;
    for (int k = 0; k < v->def.items[i].nevents; k++) v->listens[i][k] = tx_setup_listen(s, v->def.items[i].events[k]);
  }
  // the procedure's current step, for the panels, where something writes it (docs/trainer.md)
  for (int k = 0; k < navail && !v->has_procedure; k++)
    if (strcmp(avail[k], TX_PROCEDURE_COMPONENT) == 0) {
      v->procedure = TX_READ_OF(s, TX_PROCEDURE_COMPONENT, tx_procedure_step);
      v->has_procedure = true;
    }
  v->r_frames = tx_setup_result(s, "frames");
  v->r_written = tx_setup_result(s, "frames_written");
  v->r_dropped = tx_setup_result(s, "frames_dropped");
  v->r_p50 = tx_setup_result(s, "frame_ms_p50");
  v->r_p99 = tx_setup_result(s, "frame_ms_p99");
  v->r_threads = tx_setup_result(s, "render_threads");
  v->r_first = tx_setup_result(s, "first_frame_ms");
  v->r_cpu50 = tx_setup_result(s, "frame_cpu_ms_p50");
  v->r_cpu_mean = tx_setup_result(s, "frame_cpu_ms_mean");
  v->w_write = tx_setup_warning(s, "frame_not_written");
  v->w_skipped = tx_setup_warning(s, "rows_not_drawn");
  return 0;
}

// frame the first snapshot's bounding box, seen from the front and above
static void auto_camera(view* v, const tx_renderer* r) {
  double lo[3], hi[3];
  if (!tx_renderer_bounds(r, lo, hi)) return;
  tx_camera* c = &v->def.camera;
  double radius = 0;
  for (int i = 0; i < 3; i++) {
    c->target[i] = 0.5 * (lo[i] + hi[i]);
    radius += 0.25 * (hi[i] - lo[i]) * (hi[i] - lo[i]);
  }
  radius = fmax(sqrt(radius), 0.01);
  double dist = 1.15 * radius / sin(0.5 * c->fov_y), dir[3] = {0, 0.6, 1}, len = sqrt(1.36);
  for (int i = 0; i < 3; i++) c->eye[i] = c->target[i] + dist * dir[i] / len;
  c->up[0] = 0, c->up[1] = 1, c->up[2] = 0;
  if (!v->def.convergence_given) c->convergence = dist;
  if (!v->def.interaxial_given) c->interaxial = c->convergence / 30;
  c->near_m = fmax(dist - 4 * radius, dist * 0.02);
  c->far_m = dist + 6 * radius;
  v->def.auto_camera = false;
}

// the first frame compiles shaders and fills llvmpipe's caches: it is
// reported apart (the warm-up frame drawn before the run, or else the run's first)
static void record_time(view* v, double ms, double cpu_ms) {
  if (v->warming) {
    v->first_frame_ms = ms, v->warmed = true;
    return;
  }
  if (v->rendered++ == 0 && !v->warmed) {
    v->first_frame_ms = ms;
    return;
  }
  tx_hist_add(&v->frame_cpu_ns, llround(cpu_ms * 1e6));
  v->cpu_ms_sum += cpu_ms;
  tx_hist_add(&v->frame_ns, llround(ms * 1e6));
  v->timed++;
}

static int64_t thread_cpu_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

// ms, NaN before any timed frame
static double frame_ms(const view* v, const tx_hist* h, double q) { return v->timed ? tx_hist_percentile(h, q) * 1e-6 : NAN; }

static void frame_path(const view* v, char* path, size_t n, uint64_t index, const char* eye) {
  snprintf(path, n, "%s/frame_%06llu%s.png", v->frames_dir, (unsigned long long)index, eye);
}

// the rendering thread's setup, shared by both targets
typedef struct render_state {
  tx_renderer* r;
  int img_w, img_h; // px, one image
  uint8_t* left;    // lr: the left image of the latest frame (the right stays in the target)
  tx_contact_sheet sheet;
  bool last_written; // the latest frame is on disk
#if TX_WITH_OSMESA
  tx_osmesa* osm;
#endif
#if TX_WITH_GLFW
  tx_window* win;
  tx_overlay* overlay;
  double rates[TX_DRAW_MAX][3]; // publishes per second of each read, for the overlay
  uint64_t last_seq[TX_DRAW_MAX][3];
  int64_t last_rate_ns;
#endif
} render_state;

static const uint8_t* target_pixels(render_state* rs) {
#if TX_WITH_OSMESA
  if (rs->osm) return tx_osmesa_pixels(rs->osm);
#endif
  (void)rs;
  return NULL;
}

// a frame that cannot be written is counted (frame_not_written) and the run goes on
static void write_frame(view* v, render_state* rs, uint64_t index) {
  char path[4400];
  const uint8_t* px = target_pixels(rs);
  int rc = 0;
  if (v->stereo == TX_STEREO_LR) {
    frame_path(v, path, sizeof path, index, "_left");
    rc = tx_png_write(path, rs->left, rs->img_w, rs->img_h, true);
    frame_path(v, path, sizeof path, index, "_right");
    if (!rc) rc = tx_png_write(path, px, rs->img_w, rs->img_h, true);
  } else {
    frame_path(v, path, sizeof path, index, "");
    rc = tx_png_write(path, px, rs->img_w, rs->img_h, true);
  }
  if (rc) {
    tx_warn(v->ctx, v->w_write);
    return;
  }
  v->written++;
  rs->last_written = true;
}

#if TX_WITH_GLFW
// the overlay over one eye's image of w x h px, repeated in the other eye where
// the eyes tile the frame (sbs, tb); quad's GL_BACK and anaglyph's one image
// already give it to both
static void draw_overlay(view* v, render_state* rs, int w, int h) {
  // publishes per second of each drawn component, over the last half second
  int64_t now = tx_mono_ns();
  double dt = (double)(now - rs->last_rate_ns) * 1e-9;
  if (dt >= 0.5) {
    for (int i = 0; i < v->def.nitems; i++)
      for (int k = 0; k < v->nports[i]; k++) {
        rs->rates[i][k] = rs->last_rate_ns ? (double)(v->seq[i][k] - rs->last_seq[i][k]) / dt : 0;
        rs->last_seq[i][k] = v->seq[i][k];
      }
    rs->last_rate_ns = now;
  }
  const float white[3] = {1, 1, 1}, shade[3] = {0.05f, 0.05f, 0.08f}, bar[3] = {0.95f, 0.8f, 0.1f};
  char line[128];
  int y = 8, lines = 0;
  for (int i = 0; i < v->def.nitems; i++) lines += v->def.items[i].kind != TX_DRAW_PLANE;
  tx_overlay_rect(rs->overlay, 4, 4, 330, 25 * lines + 24, shade);
  snprintf(line, sizeof line, "VIEW %s  T %.2f S", tx_stereo_mode_name(v->stereo), (double)v->frame_sim_ns * 1e-9);
  tx_overlay_text(rs->overlay, 10, y, 2, line, white);
  y += 16;
  for (int i = 0; i < v->def.nitems; i++) {
    const tx_draw_item* it = &v->def.items[i];
    if (it->kind == TX_DRAW_PLANE) continue;
    snprintf(line, sizeof line, "%s %.0f HZ", it->name, rs->rates[i][0]);
    double mag = -1;
    if (it->kind == TX_DRAW_TOOL && v->scene.items[i].rows[0]) // the panels' plots (glfw_window.h)
      tx_window_sample(rs->win, it->name, (double)v->frame_sim_ns * 1e-9, v->scene.items[i].data[0],
                       it->show_force && v->scene.items[i].rows[1] ? v->scene.items[i].data[1] : NULL);
    if (it->kind == TX_DRAW_TOOL && it->show_force && v->scene.items[i].rows[1]) {
      const double* f = v->scene.items[i].data[1];
      mag = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
      size_t len = strlen(line);
      snprintf(line + len, sizeof line - len, "  F %.2f N", mag);
    }
    tx_overlay_text(rs->overlay, 10, y, 2, line, white);
    y += 16;
    if (mag >= 0) { // the force as a bar, 60 px per newton
      tx_overlay_rect(rs->overlay, 10, y, (int)fmin(310, 60 * mag), 5, bar);
      y += 9;
    }
  }
  // GL counts rows from the bottom: tb's left eye is the upper half
  tx_overlay_draw(rs->overlay, 0, v->stereo == TX_STEREO_TB ? h : 0, w, h);
  if (v->stereo == TX_STEREO_SBS) tx_overlay_draw(rs->overlay, w, 0, w, h);
  if (v->stereo == TX_STEREO_TB) tx_overlay_draw(rs->overlay, 0, 0, w, h);
  tx_overlay_clear(rs->overlay);
  // the trainer's panels over it, at zero disparity (glfw_window.h)
  tx_window_procedure(rs->win, v->has_procedure ? v->procedure_text : NULL);
  tx_window_draw_gui(rs->win, v->stereo == TX_STEREO_SBS ? 2 : 1, v->stereo == TX_STEREO_TB ? 2 : 1);
}
#endif

// -1 with the reason in v->setup_error (a library call's tx_error(), or the view's own)
static int setup_failed(view* v, const char* why) {
  snprintf(v->setup_error, sizeof v->setup_error, "%s", why ? why : tx_error());
  return -1;
}

static int setup_target(view* v, render_state* rs) {
  tx_stereo_image_size(v->stereo, v->def.width, v->def.height, &rs->img_w, &rs->img_h);
  if (v->target == TARGET_PNG) {
#if TX_WITH_OSMESA
    if (!(rs->osm = tx_osmesa_create(rs->img_w, rs->img_h))) return setup_failed(v, NULL);
    if (!(rs->r = tx_renderer_create(tx_osmesa_proc))) return setup_failed(v, NULL);
#endif
  } else {
#if TX_WITH_GLFW
    if (!(rs->win = tx_window_open(rs->img_w, rs->img_h, v->stereo != TX_STEREO_MONO))) return setup_failed(v, NULL);
    if (tx_window_is_quad(rs->win)) { // each eye has the whole window
      v->stereo = TX_STEREO_QUAD;
      tx_stereo_image_size(v->stereo, v->def.width, v->def.height, &rs->img_w, &rs->img_h);
      tx_window_resize(rs->win, rs->img_w, rs->img_h);
    }
    if (v->stereo == TX_STEREO_LR) // the probe at load found quad buffers: this window must have them too
      return setup_failed(v, "--stereo lr in a window: the window has no quad-buffered stereo");
    if (!(rs->r = tx_renderer_create(tx_window_proc))) return setup_failed(v, NULL);
    rs->overlay = tx_overlay_create(tx_renderer_gl(rs->r));
#endif
  }
  if (!rs->r) return setup_failed(v, "no graphics target in this build");
  if (v->stereo == TX_STEREO_LR && !(rs->left = malloc((size_t)rs->img_w * rs->img_h * 4)))
    return setup_failed(v, "out of memory");
  if (!tx_contact_sheet_init(&rs->sheet, rs->img_w, rs->img_h, 240, SHEET_THUMBS)) return setup_failed(v, "out of memory");
  return 0;
}

// the overlay uses the renderer's GL entry points, and both need their context
static void teardown(render_state* rs) {
#if TX_WITH_GLFW
  tx_overlay_destroy(rs->overlay);
#endif
  tx_renderer_destroy(rs->r);
#if TX_WITH_GLFW
  if (rs->win) tx_window_close(rs->win);
#endif
#if TX_WITH_OSMESA
  tx_osmesa_destroy(rs->osm);
#endif
  free(rs->left);
  tx_contact_sheet_free(&rs->sheet);
}

// the laparoscope, moved by the window's mouse, places the camera; a
// headlight shines along the view
static void view_hooks(view* v, render_state* rs) {
  tx_view_def* d = &v->def;
  if (d->scope) {
#if TX_WITH_GLFW
    double move[3];
    if (rs->win) tx_window_take_scope(rs->win, move), tx_laparoscope_move(&d->laparoscope, move[0], move[1], move[2]);
#else
    (void)rs;
#endif
    tx_laparoscope_camera(&d->laparoscope, &d->camera);
  }
  if (d->headlight) tx_headlight(&d->camera, d->light_dir);
}

// one frame: draw every pass, read back, and write it when its turn comes
static void render_frame(view* v, render_state* rs) {
  int64_t t0 = tx_mono_ns(), c0 = thread_cpu_ns();
  tx_renderer_upload(rs->r, &v->scene);
  if (v->def.auto_camera) auto_camera(v, rs->r);
  view_hooks(v, rs);
  const tx_gl* gl = tx_renderer_gl(rs->r);
  int w = v->def.width, h = v->def.height;
#if TX_WITH_GLFW
  if (rs->win) {
    int fw, fh;
    tx_window_framebuffer(rs->win, &fw, &fh);
    // the window may have been resized: keep each eye's share of it
    if (v->stereo == TX_STEREO_SBS) fw /= 2;
    if (v->stereo == TX_STEREO_TB) fh /= 2;
    if (fw > 0 && fh > 0) w = fw, h = fh;
  }
#endif
  for (int pass = 0; pass < tx_stereo_passes(v->stereo); pass++) {
    tx_stereo_draw(rs->r, &v->def, &v->def.camera, v->stereo, pass, w, h);
    if (pass == 0 && v->stereo == TX_STEREO_LR) {
      gl->Finish();
      memcpy(rs->left, target_pixels(rs), (size_t)rs->img_w * rs->img_h * 4);
    }
  }
  uint64_t index = v->frame_index - 1;
  rs->last_written = false;
#if TX_WITH_GLFW
  if (rs->win) {
    draw_overlay(v, rs, w, h);
    if (!tx_window_present(rs->win)) kill(getpid(), SIGINT); // closing the window ends the run, report and all
    record_time(v, (double)(tx_mono_ns() - t0) * 1e-6, (double)(thread_cpu_ns() - c0) * 1e-6);
    v->warming = false;
    return;
  }
#endif
  gl->Finish();
  record_time(v, (double)(tx_mono_ns() - t0) * 1e-6, (double)(thread_cpu_ns() - c0) * 1e-6);
  if (v->warming) {
    v->warming = false;
    return;
  }
  if (index % (uint64_t)v->def.frame_every == 0) {
    write_frame(v, rs, index);
    tx_contact_sheet_add(&rs->sheet, v->stereo == TX_STEREO_LR ? rs->left : target_pixels(rs), rs->img_w, rs->img_h, false);
  }
}

// the last frame of the run, and the contact sheet; a file that cannot be
// written is kept in finish_error, for finish to stop the run with
static void finish_frames(view* v, render_state* rs) {
  char path[4400];
  if (v->rendered == 0) return;
#if TX_WITH_GLFW
  if (rs->win) { // a screenshot of the last frame: drawn once more and read from the back buffer
    const tx_gl* gl = tx_renderer_gl(rs->r);
    int fw, fh;
    tx_window_framebuffer(rs->win, &fw, &fh);
    int w = v->stereo == TX_STEREO_SBS ? fw / 2 : fw, h = v->stereo == TX_STEREO_TB ? fh / 2 : fh;
    uint8_t* px = malloc((size_t)fw * fh * 4);
    if (px && w > 0 && h > 0) {
      tx_stereo_draw(rs->r, &v->def, &v->def.camera, v->stereo, 0, w, h);
      draw_overlay(v, rs, w, h);
      gl->ReadBuffer(v->stereo == TX_STEREO_QUAD ? GL_BACK_LEFT : GL_BACK);
      gl->PixelStorei(GL_PACK_ALIGNMENT, 1);
      gl->ReadPixels(0, 0, fw, fh, GL_RGBA, GL_UNSIGNED_BYTE, px);
      snprintf(path, sizeof path, "%s/window.png", v->frames_dir);
      if (tx_png_write(path, px, fw, fh, true)) snprintf(v->finish_error, sizeof v->finish_error, "%s", tx_error());
      else v->written++;
    }
    free(px);
    return;
  }
#endif
  uint64_t last = v->frame_index - 1;
  if (!rs->last_written) {
    write_frame(v, rs, last);
    tx_contact_sheet_add(&rs->sheet, v->stereo == TX_STEREO_LR ? rs->left : target_pixels(rs), rs->img_w, rs->img_h, true);
  }
  snprintf(path, sizeof path, "%s/contact_sheet.png", v->frames_dir);
  if (tx_contact_sheet_write(&rs->sheet, path, 6)) snprintf(v->finish_error, sizeof v->finish_error, "%s", tx_error());
}

static void* render_main(void* arg) {
  view* v = arg;
  render_state rs = {0};
  if (setup_target(v, &rs)) {
    v->setup_failed = true;
    teardown(&rs);
    sem_post(&v->started);
    return NULL;
  }
  sem_post(&v->started);
  for (;;) {
    while (sem_wait(&v->go) != 0 && errno == EINTR) {}
    if (atomic_load(&v->quit)) break;
    render_frame(v, &rs);
    sem_post(&v->idle);
  }
  finish_frames(v, &rs);
  uint64_t skipped = tx_renderer_skipped(rs.r);
  for (; v->skipped_reported < skipped; v->skipped_reported++) tx_warn(v->ctx, v->w_skipped);
  teardown(&rs);
  return NULL;
}

// the rendering thread runs at normal priority, off the last CPU of the set,
// where the scheduler pins its fastest group (haptics)
static int start_thread(view* v) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  pthread_attr_setschedpolicy(&attr, SCHED_OTHER);
  struct sched_param sp = {0};
  pthread_attr_setschedparam(&attr, &sp);
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 1) {
    int last = -1;
    for (int c = 0; c < CPU_SETSIZE; c++)
      if (CPU_ISSET(c, &set)) last = c;
    CPU_ZERO(&set);
    cpu_set_t all;
    sched_getaffinity(0, sizeof all, &all);
    for (int c = 0; c < last; c++)
      if (CPU_ISSET(c, &all)) CPU_SET(c, &set);
    pthread_attr_setaffinity_np(&attr, sizeof set, &set);
  }
  int rc = pthread_create(&v->thread, &attr, render_main, v);
  pthread_attr_destroy(&attr);
  return rc;
}

// the scene as the model holds it now, handed to the idle renderer (the
// snapshots it read before may be released now)
static void take_scene(tx_ctx* c, view* v) {
  v->scene.count = 0;
  for (int i = 0; i < v->def.nitems; i++) {
    tx_scene_item* si = &v->scene.items[v->scene.count++];
    si->item = &v->def.items[i];
    for (int k = 0; k < v->nports[i]; k++) {
      tx_snapshot s = tx_read(c, v->ports[i][k]);
      si->data[k] = s.data;
      si->rows[k] = s.seq ? s.rows : 0; // never published: nothing to draw
      v->seq[i][k] = s.seq;
    }
    v->scene.markers[i] = NULL;
    if (v->def.items[i].nevents) {
      v->handed[i] = v->live[i];
      v->scene.markers[i] = &v->handed[i];
    }
  }
  if (v->has_procedure) {
    tx_snapshot p = tx_read(c, v->procedure);
    tx_procedure_text(&p, v->procedure_text, sizeof v->procedure_text);
  }
  v->frame_sim_ns = tx_sim_ns(c);
}

static int init(tx_ctx* c, void* self) {
  view* v = self;
  v->ctx = c;
  const char* out = tx_output_dir(c);
  if (!out) out = ".";
  snprintf(v->frames_dir, sizeof v->frames_dir, "%s/frames", out);
  if (mkdir(v->frames_dir, 0755) != 0 && errno != EEXIST) {
    tx_stop_run(c, "%s: %s", v->frames_dir, strerror(errno));
    return -1;
  }
  sem_init(&v->go, 0, 0);
  sem_init(&v->idle, 0, 1);
  sem_init(&v->started, 0, 0);
  v->sems_ready = true;
  if (start_thread(v) != 0) {
    tx_stop_run(c, "cannot start the rendering thread");
    return -1;
  }
  v->thread_running = true;
  while (sem_wait(&v->started) != 0 && errno == EINTR) {}
  if (v->setup_failed) {
    pthread_join(v->thread, NULL);
    v->thread_running = false;
    tx_stop_run(c, "%s", v->setup_error);
    return -1;
  }
  // a warm-up frame of the scene as the controllers' init left it, before the
  // clock starts: llvmpipe compiles its shaders and the meshes are uploaded
  // (about 120 ms in lagb), which would otherwise stall the run's first frames
  while (sem_wait(&v->idle) != 0 && errno == EINTR) {}
  take_scene(c, v);
  v->warming = true;
  sem_post(&v->go);
  while (sem_wait(&v->idle) != 0 && errno == EINTR) {}
  sem_post(&v->idle);
  return 0;
}

static void step(tx_ctx* c, void* self) {
  view* v = self;
  // events every tick, a dropped frame's too: the stream keeps them only until its readers take them
  for (int i = 0; i < v->def.nitems; i++)
    for (int k = 0; k < v->def.items[i].nevents; k++)
      for (tx_event e; tx_next_event(c, v->listens[i][k], &e);) tx_marker_take(&v->live[i], &e);
  if (v->wait) {
    while (sem_wait(&v->idle) != 0 && errno == EINTR) {}
  } else if (sem_trywait(&v->idle) != 0) {
    v->dropped++; // the renderer is still on the last frame: this tick gives none
    return;
  }
  take_scene(c, v);
  v->frame_index++;
  sem_post(&v->go);
}


static void stop_thread(view* v) {
  if (!v->thread_running) return;
  while (sem_wait(&v->idle) != 0 && errno == EINTR) {} // the frame in hand is finished
  atomic_store(&v->quit, true);
  sem_post(&v->go);
  pthread_join(v->thread, NULL);
  v->thread_running = false;
}

static void finish(tx_ctx* c, void* self) {
  view* v = self;
  v->ctx = c;
  stop_thread(v);
  if (*v->finish_error) tx_stop_run(c, "%s", v->finish_error); // the run exits 1, naming the file
  tx_set_result(c, v->r_frames, (double)v->rendered);
  tx_set_result(c, v->r_written, (double)v->written);
  tx_set_result(c, v->r_dropped, (double)v->dropped);
  tx_set_result(c, v->r_p50, frame_ms(v, &v->frame_ns, 0.5));
  tx_set_result(c, v->r_p99, frame_ms(v, &v->frame_ns, 0.99));
  tx_set_result(c, v->r_cpu50, frame_ms(v, &v->frame_cpu_ns, 0.5));
  tx_set_result(c, v->r_cpu_mean, v->timed ? v->cpu_ms_sum / (double)v->timed : NAN);
  tx_set_result(c, v->r_threads, v->target == TARGET_PNG ? v->render_threads : NAN);
  tx_set_result(c, v->r_first, v->rendered ? v->first_frame_ms : NAN);
}

static void fini(void* self) {
  view* v = self;
  if (!v) return;
  stop_thread(v);
  if (v->sems_ready) {
    sem_destroy(&v->go);
    sem_destroy(&v->idle);
    sem_destroy(&v->started);
  }
  free(v);
}

const tx_controller_class tx_graphics_view = {
    .type = "views.graphics",
    .summary = "draws meshes, spheres, segments and tools from the model: PNG frames (OSMesa) or a window (GLFW), mono or stereo",
    .configure = configure,
    .init = init,
    .step = step,
    .fini = fini,
    .finish = finish,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
    .view = true,
};
