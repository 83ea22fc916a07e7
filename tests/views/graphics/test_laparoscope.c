// The laparoscope on its pivot, as geometry says: the port stays on the
// shaft whatever the moves, the eye at the tip insertion metres from it,
// pitch and insertion kept in range; the view's "laparoscope" and
// "headlight" and the tissue texture read from a scenario's view, bad ones
// named; the tissue texture's factor about 1 on average, varied, and
// tileable.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "views/graphics/laparoscope.h"
#include "views/graphics/view_def.h"

#include <tactus/config.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#if TX_WITH_OSMESA
#include "views/graphics/organ_texture.h"
#endif

static double dist(const double a[3], const double b[3]) {
  return sqrt(pow(a[0] - b[0], 2) + pow(a[1] - b[1], 2) + pow(a[2] - b[2], 2));
}

// the distance of p from the line through a along unit u
static double off_line(const double p[3], const double a[3], const double u[3]) {
  double d[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]}, t = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
  return sqrt(fmax(0, d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - t * t));
}

static void pivot_keeps_the_port(void** state) {
  (void)state;
  const double port[3] = {0, 0.17, -0.10}, target[3] = {0, 0.02, 0.03};
  tx_laparoscope s;
  tx_laparoscope_aim(&s, port, target, 0.05);
  tx_camera c = tx_camera_default();
  tx_laparoscope_camera(&s, &c);
  // aimed: the eye on the port-target line, 5 cm in; the target straight ahead
  double u[3], l = dist(port, target);
  for (int i = 0; i < 3; i++) u[i] = (target[i] - port[i]) / l;
  assert_true(off_line(c.eye, port, u) < 1e-8 && fabs(dist(c.eye, port) - 0.05) < 1e-12);
  assert_true(dist(c.target, target) < 1e-12);
  srand(3);
  for (int k = 0; k < 200; k++) {
    double m[3] = {(rand() / (double)RAND_MAX - 0.5) * 0.6, (rand() / (double)RAND_MAX - 0.5) * 0.6,
                   (rand() / (double)RAND_MAX - 0.5) * 0.04};
    tx_laparoscope_move(&s, m[0], m[1], m[2]);
    tx_laparoscope_camera(&s, &c);
    double dir[3], f[3], lf = dist(c.target, c.eye);
    tx_laparoscope_direction(&s, dir);
    for (int i = 0; i < 3; i++) f[i] = (c.target[i] - c.eye[i]) / lf;
    // the port stays on the shaft (the line of sight through the eye), insertion metres behind the eye
    assert_true(off_line(port, c.eye, f) < 1e-8); // 10 nm: the square root of rounding
    assert_true(fabs(dist(c.eye, port) - s.insertion) < 1e-12);
    for (int i = 0; i < 3; i++) assert_true(fabs(c.eye[i] - (port[i] + s.insertion * dir[i])) < 1e-12);
    assert_true(fabs(s.pitch) <= TX_SCOPE_PITCH_MAX && s.insertion >= 0 && s.insertion <= s.insertion_max);
    assert_int_equal(tx_camera_check(&c), 0);
  }
  // yaw turns about the vertical through the port: the eye's height is kept
  tx_laparoscope_aim(&s, port, target, 0.05);
  tx_laparoscope_camera(&s, &c);
  double y0 = c.eye[1];
  tx_laparoscope_move(&s, 0.7, 0, 0);
  tx_laparoscope_camera(&s, &c);
  assert_true(fabs(c.eye[1] - y0) < 1e-12);
  // insertion slides along the shaft and stops at its ends; pitch stops short of vertical
  tx_laparoscope_move(&s, 0, 0, -1);
  assert_true(s.insertion == 0);
  tx_laparoscope_move(&s, 0, 0, 10);
  assert_true(s.insertion == s.insertion_max);
  tx_laparoscope_move(&s, 0, -5, 0);
  assert_true(s.pitch == -TX_SCOPE_PITCH_MAX);
}

static int parse(const char* text, tx_view_def* d) {
  *d = tx_view_def_default();
  return tx_view_def_from_text(text, d);
}

static void view_reads_the_scope(void** state) {
  (void)state;
  tx_view_def d;
  assert_int_equal(parse("{\"camera\": {\"eye\": [0, 1, 0], \"target\": [0, 0.02, 0.03]}, \"light\": \"headlight\","
                         " \"laparoscope\": {\"port\": [0, 0.17, -0.10], \"insertion_m\": 0.04},"
                         " \"draw\": [{\"mesh\": \"liver\", \"colour\": [0.5, 0.2, 0.1], \"texture\": \"tissue\"}]}",
                         &d),
                   0);
  assert_true(d.scope && d.headlight && d.items[0].tissue_texture && !d.items[0].skin_texture);
  const double port[3] = {0, 0.17, -0.10};
  assert_true(fabs(dist(d.camera.eye, port) - 0.04) < 1e-12);  // the eye is the tip, not the camera's "eye"
  assert_true(fabs(d.camera.convergence - dist(d.camera.eye, d.camera.target)) < 1e-12);
  // bad ones, named
  const char* bad[][2] = {
      {"{\"laparoscope\": {\"port\": [0, 0.17, -0.10]}}", "laparoscope"},
      {"{\"camera\": {\"target\": [0, 0, 0]}, \"laparoscope\": {}}", "laparoscope.port"},
      {"{\"camera\": {\"target\": [0, 0, 0]}, \"laparoscope\": {\"port\": [0, 0.1, 0], \"insertion_m\": 0.2}}",
       "laparoscope.insertion_m"},
      {"{\"camera\": {\"target\": [0, 0, 0]}, \"laparoscope\": {\"port\": [0, 0.1, 0], \"roll\": 1}}", "laparoscope.roll"},
      {"{\"light\": \"sun\"}", "light"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_int_equal(parse(bad[i][0], &d), -1);
    assert_string_equal(tx_error_key(), bad[i][1]);
  }
}

#if TX_WITH_OSMESA
static void tissue_texture_about_one_varied_tileable(void** state) {
  (void)state;
  enum { S = 256 };
  uint8_t* t = malloc(S * S * 3);
  tx_tissue_texture(t, S);
  double sum = 0, sq = 0, seam = 0, inner = 0;
  for (int y = 0; y < S; y++)
    for (int x = 0; x < S; x++) {
      double f = TX_TISSUE_LO + TX_TISSUE_SPAN * t[3 * (y * S + x) + 1] / 255.0;
      sum += f, sq += f * f;
      // across the wrap (x = S-1 to 0) against across any other column pair
      double g = TX_TISSUE_LO + TX_TISSUE_SPAN * t[3 * (y * S + (x + 1) % S) + 1] / 255.0;
      if (x == S - 1) seam += fabs(g - f);
      if (x == S / 2) inner += fabs(g - f);
    }
  double mean = sum / (S * S), sd = sqrt(sq / (S * S) - mean * mean);
  assert_true(fabs(mean - 1) < 0.08);  // the colour keeps its tone on average
  assert_true(sd > 0.05 && sd < 0.3);  // visibly textured, not noise
  assert_true(seam < 3 * inner + 1);   // no seam where it repeats
  free(t);
}
#endif

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(pivot_keeps_the_port),
      cmocka_unit_test(view_reads_the_scope),
#if TX_WITH_OSMESA
      cmocka_unit_test(tissue_texture_about_one_varied_tileable),
#endif
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
