// Headless renders (OSMesa) through the laparoscope, checked against the
// lighting model and stereo geometry: an organ-coloured plane square to the
// scope is lit by the headlight as the model says at its centre, and still is
// after the scope turns (the light turns with it); with the tissue texture
// its pixels vary about the plain colour's, without it they are uniform; the
// right eye's image is the left's shifted by the disparity that the cameras
// predict for the plane's depth.
#include "model/error.h"
#include "views/graphics/laparoscope.h"
#include "views/graphics/organ_texture.h"
#include "views/graphics/osmesa_target.h"
#include "views/graphics/renderer.h"
#include "views/graphics/stereo_frame.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#define W 240
#define H 180

static const float COLOUR[3] = {0.55f, 0.17f, 0.14f};  // the liver's

typedef struct frame {
  int w, h;
  uint8_t* rgba;  // top row first
} frame;

// a square plane of half size 10 cm, its centre `depth` ahead of the scope's
// tip and square to the shaft, seen in a stereo mode
static frame render(const tx_laparoscope* s, double depth, bool textured, tx_stereo_mode mode, tx_camera* cam_out) {
  tx_view_def d = tx_view_def_default();
  d.width = W, d.height = H;
  d.background[0] = d.background[1] = d.background[2] = 0;
  d.camera.fov_y = 60 * M_PI / 180, d.camera.near_m = 0.005, d.camera.far_m = 1, d.camera.interaxial = 0.004;
  tx_laparoscope_camera(s, &d.camera);
  d.camera.convergence = s->focus;
  tx_headlight(&d.camera, d.light_dir);
  double dir[3], tip[3];
  tx_laparoscope_direction(s, dir);
  tx_laparoscope_tip(s, tip);
  tx_draw_item* it = &d.items[0];
  *it = (tx_draw_item){.kind = TX_DRAW_MESH, .tissue_texture = textured};
  memcpy(it->colour, COLOUR, sizeof COLOUR);
  // the square as a mesh (as the organs are drawn): spanned by the camera's right and up
  double right[3] = {-dir[2], 0, dir[0]}, lr = hypot(right[0], right[2]);
  for (int i = 0; i < 3; i++) right[i] /= lr;
  double up[3] = {right[1] * dir[2] - right[2] * dir[1], right[2] * dir[0] - right[0] * dir[2],
                  right[0] * dir[1] - right[1] * dir[0]};
  static float x[12];
  static const int32_t tri[6] = {0, 1, 2, 0, 2, 3};
  const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int q = 0; q < 4; q++)
    for (int i = 0; i < 3; i++)
      x[3 * q + i] = (float)(tip[i] + depth * dir[i] + 0.1 * (corners[q][0] * right[i] + corners[q][1] * up[i]));
  d.nitems = 1;
  tx_scene sc = {.count = 1};
  sc.items[0] = (tx_scene_item){.item = it, .data = {x, tri}, .rows = {4, 2}};
  frame f;
  tx_stereo_image_size(mode, W, H, &f.w, &f.h);
  tx_osmesa* osm = tx_osmesa_create(f.w, f.h);
  if (!osm) fail_msg("%s", tx_error());
  tx_renderer* r = tx_renderer_create(tx_osmesa_proc);
  if (!r) fail_msg("%s", tx_error());
  tx_renderer_upload(r, &sc);
  tx_stereo_draw(r, &d, &d.camera, mode, 0, W, H);
  tx_renderer_gl(r)->Finish();
  f.rgba = malloc((size_t)f.w * f.h * 4);
  const uint8_t* px = tx_osmesa_pixels(osm);
  for (int y = 0; y < f.h; y++) memcpy(f.rgba + (size_t)y * f.w * 4, px + (size_t)(f.h - 1 - y) * f.w * 4, (size_t)f.w * 4);
  tx_renderer_destroy(r);
  tx_osmesa_destroy(osm);
  if (cam_out) *cam_out = d.camera;
  return f;
}

static const uint8_t* at(const frame* f, int x, int y) { return f->rgba + 4 * ((size_t)y * f->w + x); }

static tx_laparoscope scope(void) {
  tx_laparoscope s;
  const double port[3] = {0, 0.17, -0.10}, target[3] = {0, 0.02, 0.03};
  tx_laparoscope_aim(&s, port, target, 0.06);
  return s;
}

// the lighting model at n.l = n.h = c (the light along the view)
static void expect_lit(const uint8_t* p, double c) {
  for (int k = 0; k < 3; k++) {
    double want = COLOUR[k] * (TX_LIGHT_AMBIENT + TX_LIGHT_DIFFUSE * c) + TX_LIGHT_SPECULAR * pow(c, TX_LIGHT_SHININESS);
    if (fabs(p[k] / 255.0 - fmin(1, want)) > 3 / 255.0) fail_msg("channel %d: %d, want %.1f", k, p[k], 255 * want);
  }
}

static void headlight_follows_the_scope(void** state) {
  (void)state;
  tx_laparoscope s = scope();
  frame f = render(&s, 0.03, false, TX_STEREO_MONO, NULL);
  expect_lit(at(&f, W / 2, H / 2), 1);  // square to the view: full diffuse and highlight
  free(f.rgba);
  // the plane placed square to a turned scope: the same light, for the light turned too
  tx_laparoscope_move(&s, 0.4, -0.2, 0.01);
  f = render(&s, 0.03, false, TX_STEREO_MONO, NULL);
  expect_lit(at(&f, W / 2, H / 2), 1);
  free(f.rgba);
}

static void tissue_texture_on_the_organ(void** state) {
  (void)state;
  tx_laparoscope s = scope();
  frame plain = render(&s, 0.03, false, TX_STEREO_MONO, NULL), tex = render(&s, 0.03, true, TX_STEREO_MONO, NULL);
  // the middle half of the image is all plane
  double sum[2] = {0}, sq[2] = {0};
  int n = 0;
  for (int y = H / 4; y < 3 * H / 4; y++)
    for (int x = W / 4; x < 3 * W / 4; x++, n++)
      for (int k = 0; k < 2; k++) {
        double v = at(k ? &tex : &plain, x, y)[0];
        sum[k] += v, sq[k] += v * v;
      }
  double sd_plain = sqrt(sq[0] / n - pow(sum[0] / n, 2)), sd_tex = sqrt(sq[1] / n - pow(sum[1] / n, 2));
  print_message("red channel sd: plain %.2f, textured %.2f; mean ratio %.3f\n", sd_plain, sd_tex, sum[1] / sum[0]);
  assert_true(sd_plain < 1.5);                       // uniform: a flat plane under a light along the view
  assert_true(sd_tex > 4);                           // textured
  assert_true(fabs(sum[1] / sum[0] - 1) < 0.12);     // about the organ's own colour on average
  free(plain.rgba), free(tex.rgba);
}

static void eyes_differ_by_the_disparity(void** state) {
  (void)state;
  tx_laparoscope s = scope();
  for (int k = 0; k < 2; k++) {
    double depth = k == 0 ? 0.02 : 0.2;  // before and behind the convergence plane (13.8 cm)
    tx_camera cam;
    frame f = render(&s, depth, true, TX_STEREO_SBS, &cam);
    double dir[3], tip[3], p[3], ndc_l[3], ndc_r[3];
    tx_laparoscope_direction(&s, dir);
    tx_laparoscope_tip(&s, tip);
    for (int i = 0; i < 3; i++) p[i] = tip[i] + depth * dir[i];
    assert_true(tx_camera_project(&cam, TX_EYE_LEFT, (double)W / H, p, ndc_l) &&
                tx_camera_project(&cam, TX_EYE_RIGHT, (double)W / H, p, ndc_r));
    double want = (ndc_r[0] - ndc_l[0]) / 2 * W;  // px, right minus left
    // the shift of the right image against the left that matches best (red channel, middle rows)
    int best = 0;
    double best_sad = INFINITY;
    for (int sh = -60; sh <= 60; sh++) {
      double sad = 0;
      for (int y = H / 3; y < 2 * H / 3; y++)
        for (int x = W / 3; x < 2 * W / 3; x++) sad += abs((int)at(&f, x, y)[0] - (int)at(&f, W + x + sh, y)[0]);
      if (sad < best_sad) best_sad = sad, best = sh;
    }
    if (fabs(best - want) > 1) fail_msg("depth %g m: shift %d px, the cameras say %.2f", depth, best, want);
    assert_true(k == 0 ? want < -1 : want > 1);  // crossed in front of the convergence plane, uncrossed behind
    free(f.rgba);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(headlight_follows_the_scope), cmocka_unit_test(tissue_texture_on_the_organ),
                                     cmocka_unit_test(eyes_differ_by_the_disparity)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
