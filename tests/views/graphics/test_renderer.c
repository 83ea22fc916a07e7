// Headless renders of known scenes on OSMesa, checked against what geometry
// and the lighting model say: the silhouette of a sphere, the colour of a lit
// sphere at its centre, the eyes' disparity in each stereo layout, meshes
// with bad rows, and PNG files read back.
#include "model/error.h"
#include "views/graphics/osmesa_target.h"
#include "views/graphics/png_writer.h"
#include "views/graphics/renderer.h"
#include "views/graphics/stereo_frame.h"

#include <tactus/components.h>

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#define W 320
#define H 240

typedef struct frame {
  tx_osmesa* osm;
  tx_renderer* r;
  int w, h;     // image, px
  uint8_t* rgba; // copy of the image, top row first
} frame;

static tx_view_def scene_def(void) {
  tx_view_def d = tx_view_def_default();
  d.width = W, d.height = H;
  d.camera.eye[0] = 0, d.camera.eye[1] = 0, d.camera.eye[2] = 1;
  d.camera.target[0] = d.camera.target[1] = d.camera.target[2] = 0;
  d.camera.fov_y = 40 * M_PI / 180;
  d.camera.near_m = 0.1, d.camera.far_m = 10, d.camera.convergence = 1, d.camera.interaxial = 0.06;
  d.background[0] = d.background[1] = d.background[2] = 0;
  d.light_dir[0] = 0, d.light_dir[1] = 0, d.light_dir[2] = -1; // from the camera into the scene
  return d;
}

// render a scene of spheres (x y z r each) in a stereo mode into f
static void render(frame* f, tx_view_def* d, tx_stereo_mode mode, tx_scene* s) {
  tx_stereo_image_size(mode, d->width, d->height, &f->w, &f->h);
  f->osm = tx_osmesa_create(f->w, f->h);
  if (!f->osm) fail_msg("%s", tx_error());
  f->r = tx_renderer_create(tx_osmesa_proc);
  if (!f->r) fail_msg("%s", tx_error());
  tx_renderer_upload(f->r, s);
  tx_stereo_draw(f->r, d, &d->camera, mode, 0, d->width, d->height);
  tx_renderer_gl(f->r)->Finish();
  f->rgba = malloc((size_t)f->w * f->h * 4);
  const uint8_t* px = tx_osmesa_pixels(f->osm);
  for (int y = 0; y < f->h; y++) memcpy(f->rgba + (size_t)y * f->w * 4, px + (size_t)(f->h - 1 - y) * f->w * 4, (size_t)f->w * 4);
}

static void release(frame* f) {
  tx_renderer_destroy(f->r);
  tx_osmesa_destroy(f->osm);
  free(f->rgba);
}

static const uint8_t* at(const frame* f, int x, int y) { return f->rgba + 4 * ((size_t)y * f->w + x); }
static bool lit(const uint8_t* p, int channel) { return channel < 0 ? p[0] + p[1] + p[2] > 24 : p[channel] > 8; }

// centroid x of the lit pixels inside [x0, x1) (channel -1: any)
static double centroid_x(const frame* f, int x0, int x1, int y0, int y1, int channel, int* count) {
  double sum = 0;
  *count = 0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++)
      if (lit(at(f, x, y), channel)) sum += x + 0.5, (*count)++;
  return *count ? sum / *count : NAN;
}

static tx_scene spheres_scene(tx_view_def* d, const float* spheres, uint32_t n, const float colour[3]) {
  d->items[0] = (tx_draw_item){.kind = TX_DRAW_SPHERES, .range = {0, 1}};
  memcpy(d->items[0].colour, colour, 3 * sizeof(float));
  d->nitems = 1;
  tx_scene s = {.count = 1};
  s.items[0] = (tx_scene_item){&d->items[0], {spheres}, {n}};
  return s;
}

// the silhouette's ends along the row through the sphere's centre are where
// the cone of rays tangent to the sphere meets the image plane: tan(theta +- alpha)
static void sphere_silhouette(void** state) {
  (void)state;
  const float white[3] = {1, 1, 1};
  const float xs[2] = {0, 0.2f};
  for (int k = 0; k < 2; k++) {
    tx_view_def d = scene_def();
    float sp[4] = {xs[k], 0, 0, 0.1f};
    tx_scene s = spheres_scene(&d, sp, 1, white);
    frame f = {0};
    render(&f, &d, TX_STEREO_MONO, &s);
    double focal = 0.5 * H / tan(0.5 * d.camera.fov_y); // px
    double theta = atan(xs[k] / 1.0), alpha = asin(0.1 / sqrt(1.0 + xs[k] * xs[k]));
    double left = 0.5 * W + focal * tan(theta - alpha), right = 0.5 * W + focal * tan(theta + alpha);
    int row = H / 2, first = -1, last = -1;
    for (int x = 0; x < W; x++)
      if (lit(at(&f, x, row), -1)) {
        if (first < 0) first = x;
        last = x + 1;
      }
    if (fabs(first - left) > 1.5 || fabs(last - right) > 1.5)
      fail_msg("sphere at x=%g: silhouette [%d, %d] px, expected [%.2f, %.2f]", xs[k], first, last, left, right);
    // and vertically, for the sphere on the axis: the same radius
    if (k == 0) {
      int top = -1, bottom = -1;
      for (int y = 0; y < H; y++)
        if (lit(at(&f, W / 2, y), -1)) {
          if (top < 0) top = y;
          bottom = y + 1;
        }
      assert_true(fabs((bottom - top) - (right - left)) < 2.0);
    }
    release(&f);
  }
}

static float expected_channel(float base, float ndotl, float ndoth) {
  float s = ndoth > 0 ? powf(ndoth, TX_LIGHT_SHININESS) : 0;
  float v = base * (TX_LIGHT_AMBIENT + TX_LIGHT_DIFFUSE * fmaxf(ndotl, 0)) + (ndotl > 0 ? TX_LIGHT_SPECULAR * s : 0);
  return fminf(v, 1) * 255;
}

// at the centre pixel the normal points at the viewer: the lighting model gives the colour
static void lit_sphere_centre_colour(void** state) {
  (void)state;
  const float base[3] = {0.5f, 0.3f, 0.2f};
  const float lights[2][3] = {{0, 0, -1}, {-0.57735f, -0.57735f, -0.57735f}};
  for (int k = 0; k < 2; k++) {
    tx_view_def d = scene_def();
    memcpy(d.light_dir, lights[k], sizeof d.light_dir);
    float sp[4] = {0, 0, 0, 0.2f};
    tx_scene s = spheres_scene(&d, sp, 1, base);
    frame f = {0};
    render(&f, &d, TX_STEREO_MONO, &s);
    // n = (0, 0, 1); l = -light; h = normalize(l + v), v = (0, 0, 1)
    float l[3] = {-lights[k][0], -lights[k][1], -lights[k][2]}, h[3] = {l[0], l[1], l[2] + 1};
    float hn = sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    float ndotl = l[2], ndoth = h[2] / hn;
    // the four pixels around the centre straddle it; average them
    double got[3] = {0, 0, 0};
    for (int y = H / 2 - 1; y <= H / 2; y++)
      for (int x = W / 2 - 1; x <= W / 2; x++)
        for (int c = 0; c < 3; c++) got[c] += at(&f, x, y)[c] / 4.0;
    for (int c = 0; c < 3; c++) {
      float want = expected_channel(base[c], ndotl, ndoth);
      if (fabs(got[c] - want) > 2.5) fail_msg("light %d channel %d: %.1f, expected %.1f", k, c, got[c], want);
    }
    release(&f);
  }
}

// a sphere in front of the convergence plane sits further right for the left
// eye than for the right (crossed); behind it, the other way round
static void stereo_layouts_disparity(void** state) {
  (void)state;
  const float white[3] = {1, 1, 1};
  const float zs[2] = {0.5f, -1.5f}; // 0.5 m and 2.5 m from the eyes; the plane is at 1 m
  for (int k = 0; k < 2; k++) {
    bool front = k == 0;
    float sp[4] = {0, 0, zs[k], 0.03f};
    int nl, nr;
    // side by side: left eye in the left half
    tx_view_def d = scene_def();
    tx_scene s = spheres_scene(&d, sp, 1, white);
    frame f = {0};
    render(&f, &d, TX_STEREO_SBS, &s);
    assert_int_equal(f.w, 2 * W);
    double xl = centroid_x(&f, 0, W, 0, H, -1, &nl), xr = centroid_x(&f, W, 2 * W, 0, H, -1, &nr) - W;
    assert_true(nl > 20 && nr > 20);
    if (front ? !(xl > xr + 1) : !(xr > xl + 1)) fail_msg("sbs, z=%g: left %.2f right %.2f", zs[k], xl, xr);
    release(&f);
    // top-bottom: left eye on top
    d = scene_def();
    s = spheres_scene(&d, sp, 1, white);
    render(&f, &d, TX_STEREO_TB, &s);
    assert_int_equal(f.h, 2 * H);
    double tl = centroid_x(&f, 0, W, 0, H, -1, &nl), tr = centroid_x(&f, 0, W, H, 2 * H, -1, &nr);
    assert_true(nl > 20 && nr > 20);
    assert_true(fabs(tl - xl) < 0.6 && fabs(tr - xr) < 0.6); // the same eyes as side by side
    release(&f);
    // anaglyph: the left eye in red, the right in green and blue
    d = scene_def();
    s = spheres_scene(&d, sp, 1, white);
    render(&f, &d, TX_STEREO_ANAGLYPH, &s);
    double al = centroid_x(&f, 0, W, 0, H, 0, &nl), ar = centroid_x(&f, 0, W, 0, H, 2, &nr);
    assert_true(nl > 20 && nr > 20);
    assert_true(fabs(al - xl) < 0.6 && fabs(ar - xr) < 0.6);
    release(&f);
  }
  // on the convergence plane the two eyes agree
  float sp[4] = {0.05f, 0, 0, 0.03f};
  tx_view_def d = scene_def();
  tx_scene s = spheres_scene(&d, sp, 1, white);
  frame f = {0};
  render(&f, &d, TX_STEREO_SBS, &s);
  int nl, nr;
  double xl = centroid_x(&f, 0, W, 0, H, -1, &nl), xr = centroid_x(&f, W, 2 * W, 0, H, -1, &nr) - W;
  assert_true(fabs(xl - xr) < 0.3);
  release(&f);
}

// a quad facing the camera: lit flat; a triangle with an index past the vertices is skipped and counted
static void mesh_and_bad_rows(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  const float x[12] = {-0.2f, -0.2f, 0, 0.2f, -0.2f, 0, 0.2f, 0.2f, 0, -0.2f, 0.2f, 0};
  const int32_t tri[9] = {0, 1, 2, 0, 2, 3, 0, 2, 7};
  const float sp[8] = {0, 0, 0.3f, NAN, 0.1f, 0.1f, 0.1f, 0.05f}; // a NaN sphere is skipped, the other drawn
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_MESH, .colour = {0.4f, 0.6f, 0.8f}};
  d.items[1] = (tx_draw_item){.kind = TX_DRAW_SPHERES, .colour = {1, 0, 0}};
  d.nitems = 2;
  tx_scene s = {.count = 2};
  s.items[0] = (tx_scene_item){&d.items[0], {x, tri}, {4, 3}};
  s.items[1] = (tx_scene_item){&d.items[1], {sp}, {2}};
  frame f = {0};
  render(&f, &d, TX_STEREO_MONO, &s);
  assert_int_equal(tx_renderer_skipped(f.r), 2);
  const uint8_t* p = at(&f, W / 2 - 40, H / 2 + 30); // on the quad, away from the sphere
  for (int c = 0; c < 3; c++) {
    float want = expected_channel(d.items[0].colour[c], 1, 1);
    if (fabs(p[c] - want) > 2.5) fail_msg("quad channel %d: %d, expected %.1f", c, p[c], want);
  }
  double lo[3], hi[3];
  assert_true(tx_renderer_bounds(f.r, lo, hi));
  assert_true(fabs(lo[0] + 0.2) < 1e-6 && fabs(hi[0] - 0.2) < 1e-6);
  release(&f);
  // the skin texture: a skin tone, red over green over blue, and not flat
  d = scene_def();
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_MESH, .skin_texture = true};
  d.nitems = 1;
  s.count = 1;
  s.items[0].rows[1] = 2;
  render(&f, &d, TX_STEREO_MONO, &s);
  double sum[3] = {0, 0, 0}, lo_r = 255, hi_r = 0;
  int n = 0;
  for (int y = H / 2 - 30; y < H / 2 + 30; y++)
    for (int xx = W / 2 - 30; xx < W / 2 + 30; xx++, n++) {
      const uint8_t* q = at(&f, xx, y);
      for (int c = 0; c < 3; c++) sum[c] += q[c];
      lo_r = fmin(lo_r, q[0]), hi_r = fmax(hi_r, q[0]);
    }
  assert_true(sum[0] > sum[1] && sum[1] > sum[2]);
  assert_true(hi_r - lo_r > 10);
  release(&f);
}

// a quad coloured by a scalar per vertex (colour_by on a mesh, an organ's
// temperature): cold blue on the left, hot red on the right, the map's green
// between, smooth across each triangle; and the frame as a PNG read back the same
static void mesh_coloured_by_scalar(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  const float x[12] = {-0.2f, -0.2f, 0, 0.2f, -0.2f, 0, 0.2f, 0.2f, 0, -0.2f, 0.2f, 0};
  const int32_t tri[6] = {0, 1, 2, 0, 2, 3};
  const float t[4] = {310.15f, 373.15f, 373.15f, 310.15f}; // K, left cold, right boiling
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_MESH, .colour = {0.5f, 0.5f, 0.5f}, .range = {310.15f, 373.15f}};
  snprintf(d.items[0].scalar, sizeof d.items[0].scalar, "quad.temperature");
  d.nitems = 1;
  tx_scene s = {.count = 1};
  s.items[0] = (tx_scene_item){&d.items[0], {x, tri, t}, {4, 2, 4}};
  frame f = {0};
  render(&f, &d, TX_STEREO_MONO, &s);
  assert_int_equal(tx_renderer_skipped(f.r), 0);
  // the quad spans x in about [W/2 - 70, W/2 + 70]: sample near its ends and its middle
  const uint8_t *cold = at(&f, W / 2 - 60, H / 2), *hot = at(&f, W / 2 + 60, H / 2), *mid = at(&f, W / 2, H / 2 + 20);
  print_message("  cold (%d, %d, %d), middle (%d, %d, %d), hot (%d, %d, %d)\n", cold[0], cold[1], cold[2], mid[0], mid[1],
                mid[2], hot[0], hot[1], hot[2]);
  assert_true(cold[2] > 2 * cold[0] && cold[2] > 100);  // blue
  assert_true(hot[0] > 2 * hot[2] && hot[0] > 100);     // red
  assert_true(mid[1] > mid[0] && mid[1] > mid[2]);      // green between: interpolated, not one colour a triangle
  // the same frame through a PNG
  char path[] = "/tmp/tx_temp_png_XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  assert_int_equal(tx_png_write(path, f.rgba, f.w, f.h, false), 0);
  uint8_t* back;
  int w, h;
  assert_int_equal(tx_png_read(path, &back, &w, &h), 0);
  assert_int_equal(w, W), assert_int_equal(h, H);
  assert_memory_equal(back + 4 * ((size_t)(H / 2) * W + W / 2 + 60), hot, 3);
  free(back);
  remove(path);
  release(&f);
  // a scalar with other rows than the vertices (not yet published right): the plain colour, counted
  s.items[0].rows[2] = 3;
  render(&f, &d, TX_STEREO_MONO, &s);
  assert_int_equal(tx_renderer_skipped(f.r), 1);
  const uint8_t* p = at(&f, W / 2 + 60, H / 2);
  assert_true(abs(p[0] - p[2]) < 4); // grey
  release(&f);
}

static void colour_map_and_png(void** state) {
  (void)state;
  float a[3], b[3], m[3];
  tx_colour_map(0, a);
  tx_colour_map(1, b);
  tx_colour_map(NAN, m);
  assert_true(a[2] > a[0] && b[0] > b[2]); // cold blue, hot red
  assert_memory_equal(a, m, sizeof a);
  // write bottom-up, read back top-down
  uint8_t img[4 * 3 * 2];
  for (int i = 0; i < 24; i++) img[i] = (uint8_t)(i * 10);
  for (int i = 3; i < 24; i += 4) img[i] = 255;
  char path[] = "/tmp/tx_png_XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  assert_int_equal(tx_png_write(path, img, 3, 2, true), 0);
  uint8_t* back;
  int w, h;
  assert_int_equal(tx_png_read(path, &back, &w, &h), 0);
  assert_int_equal(w, 3);
  assert_int_equal(h, 2);
  assert_memory_equal(back, img + 12, 12); // the bottom row of the buffer is the file's top row
  assert_memory_equal(back + 12, img, 12);
  free(back);
  remove(path);
  assert_int_equal(tx_png_write("/nonexistent/dir/x.png", img, 3, 2, true), -1);
  assert_non_null(strstr(tx_error(), "/nonexistent/dir/x.png"));
}

// impostor depth: a small near sphere (red on the map) is drawn over a big far
// one (blue) whatever the order; a sphere beyond the cut plane is not drawn
static void sphere_depth_and_cut(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  const float sp[12] = {0, 0, 0.3f, 0.05f, 0, 0, 0, 0.2f, 0.28f, 0, 0, 0.08f};
  const float scalar[3] = {1, 0, 1};
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_SPHERES, .range = {0, 1}, .scalar = "s", .has_cut = true,
                              .cut = {0.25f, 0, 0, 1, 0, 0}};
  d.nitems = 1;
  tx_scene s = {.count = 1};
  s.items[0] = (tx_scene_item){&d.items[0], {sp, scalar}, {3, 3}};
  frame f = {0};
  render(&f, &d, TX_STEREO_MONO, &s);
  const uint8_t* c = at(&f, W / 2, H / 2);
  if (!(c[0] > 2 * c[2])) fail_msg("centre (%d, %d, %d): the near red sphere should hide the far blue one", c[0], c[1], c[2]);
  const uint8_t* b = at(&f, W / 2 + 30, H / 2); // on the big sphere, off the small one
  if (!(b[2] > 2 * b[0])) fail_msg("(%d, %d, %d): expected the blue sphere", b[0], b[1], b[2]);
  // the cut sphere's centre projects to x = 0.28 / (1 tan 20 deg) of the half width
  int cx = (int)(W / 2 + 0.28 / tan(20 * M_PI / 180) * (H / 2));
  const uint8_t* g = at(&f, cx, H / 2);
  if (lit(g, -1)) fail_msg("(%d, %d, %d) at x = %d: the sphere beyond the cut is drawn", g[0], g[1], g[2], cx);
  assert_int_equal(tx_renderer_skipped(f.r), 0); // cut away is not an error
  release(&f);
}

// a cut thread: a segment of radius 0 is a gap, not drawn and not counted
// as a bad row; the segments on either side of it are drawn (two tubes)
static void segments_with_a_gap(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  const float sg[21] = {-0.2f, 0, 0, -0.05f, 0, 0, 0.02f, -0.05f, 0, 0, 0.05f, 0, 0, 0, 0.05f, 0, 0, 0.2f, 0, 0, 0.02f};
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_SEGMENTS, .colour = {1, 1, 0}};
  d.nitems = 1;
  tx_scene s = {.count = 1};
  s.items[0] = (tx_scene_item){&d.items[0], {sg}, {3}};
  frame f = {0};
  render(&f, &d, TX_STEREO_MONO, &s);
  assert_int_equal(tx_renderer_skipped(f.r), 0);
  int off = (int)(0.12 / tan(20 * M_PI / 180) * (H / 2)); // x = +-0.12 m on the image
  assert_true(lit(at(&f, W / 2 - off, H / 2), -1) && lit(at(&f, W / 2 + off, H / 2), -1));
  assert_false(lit(at(&f, W / 2, H / 2), -1)); // the gap
  release(&f);
}

// the proxy: a cyan sphere where the force model's force vanishes along F0 while it holds a contact
// (a wall's spring, K = -300 n n^T, pushing F0 = 15 N up at x0 0.05 m below its surface: the proxy is
// on the surface, x0 + F0 / 300), none for a model of zeros
static void tool_proxy_at_x0(void** state) {
  (void)state;
  for (int contact = 0; contact < 2; contact++) {
    tx_view_def d = scene_def();
    d.items[0] = (tx_draw_item){.kind = TX_DRAW_TOOL, .colour = {1, 0, 0}, .radius = 0.02f, .proxy = "tool0.force_model"};
    d.nitems = 1;
    const tx_pose pose = {{-0.2, 0, 0}, {1, 0, 0, 0}};
    tx_force_model fm = {{0}, {0.2, -0.05, 0}, {0}};
    if (contact) fm.k[4] = -300, fm.f0[1] = 15;
    tx_scene s = {.count = 1};
    s.items[0] = (tx_scene_item){&d.items[0], {&pose, &fm}, {1, 1}};
    frame f = {0};
    render(&f, &d, TX_STEREO_MONO, &s);
    int x = (int)(W / 2 + 0.2 / tan(20 * M_PI / 180) * (H / 2)); // the proxy (0.2, 0, 0) on the image
    const uint8_t* p = at(&f, x, H / 2);
    if (contact && !(p[1] > 2 * p[0] + 8 && p[2] > 2 * p[0] + 8)) fail_msg("(%d, %d, %d) at the surface: no cyan proxy", p[0], p[1], p[2]);
    if (!contact && lit(p, -1)) fail_msg("(%d, %d, %d): a proxy without a contact", p[0], p[1], p[2]);
    // not at x0 itself, 0.05 m (16 px) below it
    const uint8_t* q = at(&f, x, H / 2 + (int)(0.05 / tan(20 * M_PI / 180) * (H / 2)));
    if (lit(q, -1)) fail_msg("(%d, %d, %d) at x0: the proxy is drawn at x0, not on the surface", q[0], q[1], q[2]);
    const uint8_t* t = at(&f, (int)(W / 2 - 0.2 / tan(20 * M_PI / 180) * (H / 2)), H / 2);
    assert_true(t[0] > 2 * t[2]); // the device's own (red) sphere, either way
    release(&f);
  }
}

// px right of (or above) the image centre of a point at distance 1 m in the view's plane
static int px_of(double m) { return (int)lround(m / tan(20 * M_PI / 180) * (H / 2)); }
static bool yellow(const uint8_t* p) { return p[0] > 3 * p[2] + 8 && p[1] > 3 * p[2] + 8; }

// the force rod starts on the HIP sphere: a force shorter than the radius is
// still seen; along the shaft it starts past the shaft's end
static void force_arrow_outside_the_tool(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_TOOL, .colour = {1, 0, 0}, .radius = 0.05f, .show_force = true, .force_scale = 0.01f};
  d.nitems = 1;
  // sideways, 4 N: 40 mm, inside the 50 mm sphere had it started at the HIP
  const tx_pose pose = {{0, 0, 0}, {1, 0, 0, 0}};
  tx_force f = {{4, 0, 0}};
  tx_scene s = {.count = 1};
  s.items[0] = (tx_scene_item){&d.items[0], {&pose, &f}, {1, 1}};
  frame fr = {0};
  render(&fr, &d, TX_STEREO_MONO, &s);
  const uint8_t* p = at(&fr, W / 2 + px_of(0.07), H / 2);
  if (!yellow(p)) fail_msg("(%d, %d, %d) 70 mm right of the HIP: no force rod outside the sphere", p[0], p[1], p[2]);
  p = at(&fr, W / 2 + px_of(0.1), H / 2);
  if (lit(p, -1)) fail_msg("(%d, %d, %d) at 100 mm: the rod is longer than 4 N x 10 mm/N past the sphere", p[0], p[1], p[2]);
  release(&fr);
  // along the shaft (+Y, 16 r = 0.32 m from a HIP at y = -0.2): from the shaft's end, 0.12, to 0.16
  d.items[0].radius = 0.02f;
  const tx_pose low = {{0, -0.2, 0}, {1, 0, 0, 0}};
  f = (tx_force){{0, 4, 0}};
  s.items[0] = (tx_scene_item){&d.items[0], {&low, &f}, {1, 1}};
  render(&fr, &d, TX_STEREO_MONO, &s);
  p = at(&fr, W / 2, H / 2 - px_of(0.14));
  if (!yellow(p)) fail_msg("(%d, %d, %d) past the shaft's end: no force rod", p[0], p[1], p[2]);
  for (double y = -0.17; y < 0.1; y += 0.03) {
    p = at(&fr, W / 2, H / 2 - px_of(y));
    if (yellow(p)) fail_msg("(%d, %d, %d) at y = %g: the rod runs along the shaft", p[0], p[1], p[2], y);
  }
  release(&fr);
  // the start itself: on the sphere for a force across the shaft, at the HIP for none
  float start[3];
  const float c0[3] = {1, 2, 3}, shaft[3] = {0, 0.32f, 0};
  tx_force_arrow_start(c0, shaft, 0.02f, (const double[3]){0, 0, -5}, start);
  assert_float_equal(start[2], 3 - 0.02f, 1e-6);
  tx_force_arrow_start(c0, shaft, 0.02f, (const double[3]){0, -5, 0}, start); // away from the shaft
  assert_float_equal(start[1], 2 - 0.02f, 1e-6);
  tx_force_arrow_start(c0, shaft, 0.02f, (const double[3]){0, 0, 0}, start);
  assert_float_equal(start[0], 1, 0), assert_float_equal(start[1], 2, 0), assert_float_equal(start[2], 3, 0);
}

// punctures as markers on the skin, where their barycentric coordinates put them
static void puncture_markers(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_MARKERS, .name = "needle.punctures", .skin = "skin", .colour = {0.9f, 0.15f, 0.85f},
                              .radius = 0.01f};
  d.nitems = 1;
  const float x[4 * 3] = {0, 0, 0, 0.2f, 0, 0, 0, 0.2f, 0, -0.2f, 0, 0};
  const tx_puncture pu[4] = {
      {{0, 1, 2}, {0.5, 0.5, 0}, 1},   // (0.1, 0, 0)
      {{0, 2, 3}, {0, 0.5, 0.5}, -1},  // (-0.1, 0.1, 0)
      {{0, 1, 7}, {0.2, 0.4, 0.4}, 1}, // a row past the skin's: skipped, counted
      {{-1, 0, 0}, {0}, 0},           // past the list's end: nothing
  };
  tx_scene s = {.count = 1};
  s.items[0] = (tx_scene_item){&d.items[0], {pu, x}, {4, 4}};
  frame fr = {0};
  render(&fr, &d, TX_STEREO_MONO, &s);
  const int spots[2][2] = {{W / 2 + px_of(0.1), H / 2}, {W / 2 - px_of(0.1), H / 2 - px_of(0.1)}};
  for (int k = 0; k < 2; k++) {
    const uint8_t* p = at(&fr, spots[k][0], spots[k][1]);
    if (!(p[0] > 2 * p[1] + 8 && p[2] > 2 * p[1] + 8)) fail_msg("(%d, %d, %d): no magenta marker at puncture %d", p[0], p[1], p[2], k);
  }
  const uint8_t* p = at(&fr, W / 2, H / 2); // the skin's first corner: no marker there
  if (lit(p, -1)) fail_msg("(%d, %d, %d) at the triangle's corner", p[0], p[1], p[2]);
  assert_int_equal(tx_renderer_skipped(fr.r), 1);
  release(&fr);
}

// a grasp at its point (green), a knot at the mean of its cylinders' nodes (orange);
// a knot past the thread's nodes is skipped and counted
static void grasp_and_knot_markers(void** state) {
  (void)state;
  tx_view_def d = scene_def();
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_MARKERS, .thread = "thread", .nevents = 1, .radius = 0.01f};
  d.nitems = 1;
  const tx_sphere nodes[4] = {{{0, -0.1f, 0}, 0.001f}, {{0, 0.1f, 0}, 0.001f}, {{0.2f, 0.1f, 0}, 0.001f}, {{0.2f, -0.1f, 0}, 0.001f}};
  const tx_marker_list m = {.n = 3,
                            .m = {{.kind = TX_EVENT_GRASP, .p = {-0.1f, 0, 0}},
                                  {.kind = TX_EVENT_KNOT, .first = 0, .last = 2}, // nodes 0..3: (0.1, 0, 0)
                                  {.kind = TX_EVENT_KNOT, .first = 2, .last = 3}}};  // node 4 is past the thread
  tx_scene s = {.count = 1, .markers = {&m}};
  s.items[0] = (tx_scene_item){&d.items[0], {nodes}, {4}};
  frame fr = {0};
  render(&fr, &d, TX_STEREO_MONO, &s);
  const uint8_t* p = at(&fr, W / 2 - px_of(0.1), H / 2);
  if (!(p[1] > 2 * p[0] + 8 && p[1] > 2 * p[2] + 8)) fail_msg("(%d, %d, %d): no green grasp marker", p[0], p[1], p[2]);
  p = at(&fr, W / 2 + px_of(0.1), H / 2);
  if (!(p[0] > 3 * p[2] + 8 && p[1] > p[2] + 8 && p[0] > p[1] + 16)) fail_msg("(%d, %d, %d): no orange knot marker", p[0], p[1], p[2]);
  p = at(&fr, W / 2, H / 2 - px_of(0.1)); // a node itself: nothing there but its own (undrawn) sphere
  if (lit(p, -1)) fail_msg("(%d, %d, %d) at a node", p[0], p[1], p[2]);
  assert_int_equal(tx_renderer_skipped(fr.r), 1);
  release(&fr);
}

int main(void) {
  tx_osmesa_bound_threads(-1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(sphere_silhouette),        cmocka_unit_test(lit_sphere_centre_colour),
      cmocka_unit_test(stereo_layouts_disparity), cmocka_unit_test(mesh_and_bad_rows),
      cmocka_unit_test(mesh_coloured_by_scalar),  cmocka_unit_test(colour_map_and_png),       cmocka_unit_test(sphere_depth_and_cut),
      cmocka_unit_test(segments_with_a_gap),      cmocka_unit_test(tool_proxy_at_x0),
      cmocka_unit_test(force_arrow_outside_the_tool), cmocka_unit_test(puncture_markers),
      cmocka_unit_test(grasp_and_knot_markers),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
