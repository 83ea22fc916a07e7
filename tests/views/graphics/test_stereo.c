// Off-axis stereo as pure math: disparity signs, zero parallax on the
// convergence plane, parallel eyes, and the matrices agreeing with projection.
#include "model/error.h"
#include "views/graphics/stereo.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

static tx_camera looking_down_z(void) {
  tx_camera c = tx_camera_default();
  c.eye[0] = 0, c.eye[1] = 0, c.eye[2] = 1;
  c.target[0] = c.target[1] = c.target[2] = 0;
  c.interaxial = 0.065;
  c.convergence = 1.0; // the target's plane
  return c;
}

static double ndc_x(const tx_camera* c, tx_eye e, double x, double y, double z) {
  double p[3] = {x, y, z}, ndc[3];
  assert_true(tx_camera_project(c, e, 4.0 / 3.0, p, ndc));
  return ndc[0];
}

// in front of the convergence plane: crossed disparity, the right eye sees it further left
static void front_point_crossed(void** state) {
  (void)state;
  tx_camera c = looking_down_z();
  for (double z = 0.2; z <= 0.9; z += 0.1) { // 0.1 to 0.8 m from the eyes, plane at 1 m
    double l = ndc_x(&c, TX_EYE_LEFT, 0.01, 0.02, z), r = ndc_x(&c, TX_EYE_RIGHT, 0.01, 0.02, z);
    assert_true(r < l);
    assert_true(l > ndc_x(&c, TX_EYE_MONO, 0.01, 0.02, z)); // each eye on its own side of the mono image
    assert_true(r < ndc_x(&c, TX_EYE_MONO, 0.01, 0.02, z));
  }
}

static void behind_point_uncrossed(void** state) {
  (void)state;
  tx_camera c = looking_down_z();
  for (double z = -0.1; z >= -3; z -= 0.3) {
    double l = ndc_x(&c, TX_EYE_LEFT, -0.02, 0.0, z), r = ndc_x(&c, TX_EYE_RIGHT, -0.02, 0.0, z);
    assert_true(r > l);
  }
}

// on the plane both eyes see a point at the same place, wherever it is in the image
static void plane_zero_parallax(void** state) {
  (void)state;
  tx_camera c = looking_down_z();
  for (double x = -0.3; x <= 0.3; x += 0.1) {
    double l = ndc_x(&c, TX_EYE_LEFT, x, 0.1, 0), r = ndc_x(&c, TX_EYE_RIGHT, x, 0.1, 0);
    assert_true(fabs(l - r) < 1e-12);
  }
  // the disparity, left minus right: interaxial near (1/z - 1/convergence) / half width of the near window
  double z_eye = 0.5, w = 0.01 * tan(0.5 * c.fov_y) * 4.0 / 3.0; // half width at the near plane
  double expect = c.interaxial * c.near_m * (1 / z_eye - 1 / c.convergence) / w;
  double got = ndc_x(&c, TX_EYE_LEFT, 0, 0, 1 - z_eye) - ndc_x(&c, TX_EYE_RIGHT, 0, 0, 1 - z_eye);
  assert_true(fabs(got - expect) < 1e-9);
}

// parallel axes (no toe-in): both views have the same rotation, the eyes differ only by a shift along right
static void parallel_axes_asymmetric_frusta(void** state) {
  (void)state;
  tx_camera c = looking_down_z();
  c.eye[0] = 0.3, c.eye[1] = 0.4, c.eye[2] = 0.8, c.target[1] = 0.05; // an oblique camera
  float vl[16], pl[16], vr[16], pr[16], vm[16], pm[16];
  tx_camera_matrices(&c, TX_EYE_LEFT, 1.5, vl, pl);
  tx_camera_matrices(&c, TX_EYE_RIGHT, 1.5, vr, pr);
  tx_camera_matrices(&c, TX_EYE_MONO, 1.5, vm, pm);
  for (int i = 0; i < 12; i++) assert_true(fabsf(vl[i] - vr[i]) < 1e-6f);
  double el[3], er[3];
  tx_camera_eye_position(&c, TX_EYE_LEFT, el);
  tx_camera_eye_position(&c, TX_EYE_RIGHT, er);
  double sep = sqrt((el[0] - er[0]) * (el[0] - er[0]) + (el[1] - er[1]) * (el[1] - er[1]) + (el[2] - er[2]) * (el[2] - er[2]));
  assert_true(fabs(sep - c.interaxial) < 1e-12);
  // the shear term (column 2, row 0) has opposite signs, and the mono frustum is symmetric
  assert_true(pl[8] > 0 && pr[8] < 0);
  assert_true(fabsf(pl[8] + pr[8]) < 1e-6f);
  assert_true(fabsf(pm[8]) < 1e-7f);
}

// the matrices and tx_camera_project place a point at the same normalised coordinates
static void matrices_match_projection(void** state) {
  (void)state;
  tx_camera c = looking_down_z();
  c.eye[0] = -0.2, c.eye[1] = 0.5, c.target[2] = -0.1;
  const double pts[3][3] = {{0.05, 0.02, 0.01}, {-0.1, 0.1, -0.2}, {0.0, -0.05, 0.3}};
  for (int e = -1; e <= 1; e++)
    for (int k = 0; k < 3; k++) {
      float v[16], p[16];
      tx_camera_matrices(&c, (tx_eye)e, 1.25, v, p);
      double cam[4] = {0, 0, 0, 0}, clip[4] = {0, 0, 0, 0}, w[4] = {pts[k][0], pts[k][1], pts[k][2], 1};
      for (int r = 0; r < 4; r++)
        for (int j = 0; j < 4; j++) cam[r] += v[j * 4 + r] * w[j];
      for (int r = 0; r < 4; r++)
        for (int j = 0; j < 4; j++) clip[r] += p[j * 4 + r] * cam[j];
      double ndc[3];
      assert_true(tx_camera_project(&c, (tx_eye)e, 1.25, pts[k], ndc));
      for (int i = 0; i < 3; i++) assert_true(fabs(clip[i] / clip[3] - ndc[i]) < 1e-5);
    }
}

static void bad_cameras(void** state) {
  (void)state;
  tx_camera c = tx_camera_default();
  assert_int_equal(tx_camera_check(&c), 0);
  tx_camera b = c;
  b.target[0] = b.eye[0], b.target[1] = b.eye[1], b.target[2] = b.eye[2];
  assert_int_equal(tx_camera_check(&b), -1);
  b = c, b.up[0] = 0, b.up[1] = 0.2, b.up[2] = 0.35; // along the viewing direction
  assert_int_equal(tx_camera_check(&b), -1);
  b = c, b.near_m = 0;
  assert_int_equal(tx_camera_check(&b), -1);
  b = c, b.far_m = b.near_m;
  assert_int_equal(tx_camera_check(&b), -1);
  b = c, b.convergence = -1;
  assert_int_equal(tx_camera_check(&b), -1);
  b = c, b.interaxial = NAN;
  assert_int_equal(tx_camera_check(&b), -1);
  b = c, b.eye[1] = INFINITY;
  assert_int_equal(tx_camera_check(&b), -1);
  // a point behind the eye does not project
  double p[3] = {0, 0.4, 0.9}, ndc[3];
  assert_false(tx_camera_project(&c, TX_EYE_MONO, 1, p, ndc));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(front_point_crossed),        cmocka_unit_test(behind_point_uncrossed),
      cmocka_unit_test(plane_zero_parallax),        cmocka_unit_test(parallel_axes_asymmetric_frusta),
      cmocka_unit_test(matrices_match_projection), cmocka_unit_test(bad_cameras),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
