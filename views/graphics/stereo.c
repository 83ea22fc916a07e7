// Off-axis stereo: parallel eyes, asymmetric frusta meeting at the convergence plane.
#include "stereo.h"

#include "../../model/error.h"

#include <math.h>
#include <string.h>

tx_camera tx_camera_default(void) {
  return (tx_camera){.eye = {0, 0.2, 0.35}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov_y = 40 * M_PI / 180,
                     .near_m = 0.01, .far_m = 10, .interaxial = 0.403 / 30, .convergence = 0.403};
}

static void sub(const double a[3], const double b[3], double o[3]) {
  for (int i = 0; i < 3; i++) o[i] = a[i] - b[i];
}
static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross(const double a[3], const double b[3], double o[3]) {
  o[0] = a[1] * b[2] - a[2] * b[1];
  o[1] = a[2] * b[0] - a[0] * b[2];
  o[2] = a[0] * b[1] - a[1] * b[0];
}
static bool normalise(double v[3]) {
  double l = sqrt(dot(v, v));
  if (!(l > 1e-12) || !isfinite(l)) return false;
  for (int i = 0; i < 3; i++) v[i] /= l;
  return true;
}

int tx_camera_check(const tx_camera* c) {
  for (int i = 0; i < 3; i++)
    if (!isfinite(c->eye[i]) || !isfinite(c->target[i]) || !isfinite(c->up[i])) return tx_set_error("eye, target and up must be finite"), -1;
  double f[3], r[3];
  sub(c->target, c->eye, f);
  if (!normalise(f)) return tx_set_error("eye and target must differ"), -1;
  cross(f, c->up, r);
  if (!normalise(r)) return tx_set_error("up must not be parallel to the viewing direction"), -1;
  if (!(c->fov_y > 0 && c->fov_y < M_PI)) return tx_set_error("fov must be in (0, 180) degrees"), -1;
  if (!(c->near_m > 0) || !(c->far_m > c->near_m) || !isfinite(c->far_m)) return tx_set_error("need 0 < near < far"), -1;
  if (!(c->interaxial >= 0) || !isfinite(c->interaxial)) return tx_set_error("interaxial distance must be >= 0"), -1;
  if (!(c->convergence > 0) || !isfinite(c->convergence)) return tx_set_error("convergence distance must be > 0"), -1;
  return 0;
}

// the camera's orthonormal frame: right r, true up u, forward f
static void frame(const tx_camera* c, double r[3], double u[3], double f[3]) {
  sub(c->target, c->eye, f);
  normalise(f);
  cross(f, c->up, r);
  normalise(r);
  cross(r, f, u);
}

void tx_camera_eye_position(const tx_camera* c, tx_eye eye, double out[3]) {
  double r[3], u[3], f[3];
  frame(c, r, u, f);
  double half = 0.5 * c->interaxial * (double)eye;
  for (int i = 0; i < 3; i++) out[i] = c->eye[i] + half * r[i];
}

// the frustum bounds at the near plane: the window on the convergence plane is
// centred on the cyclopean axis, which lies half an interaxial to the side of each eye
static void frustum(const tx_camera* c, tx_eye eye, double aspect, double* l, double* rt, double* b, double* t) {
  *t = c->near_m * tan(0.5 * c->fov_y);
  *b = -*t;
  double hw = *t * aspect, shift = 0.5 * c->interaxial * (double)eye * c->near_m / c->convergence;
  *l = -hw - shift;
  *rt = hw - shift;
}

void tx_camera_matrices(const tx_camera* c, tx_eye eye, double aspect, float view[16], float proj[16]) {
  double r[3], u[3], f[3], e[3];
  frame(c, r, u, f);
  tx_camera_eye_position(c, eye, e);
  // view: rows are r, u, -f; translation moves the eye to the origin
  double v[16] = {r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0, -dot(r, e), -dot(u, e), dot(f, e), 1};
  double l, rt, b, t, n = c->near_m, fa = c->far_m;
  frustum(c, eye, aspect, &l, &rt, &b, &t);
  double p[16] = {0};
  p[0] = 2 * n / (rt - l);
  p[5] = 2 * n / (t - b);
  p[8] = (rt + l) / (rt - l);
  p[9] = (t + b) / (t - b);
  p[10] = -(fa + n) / (fa - n);
  p[11] = -1;
  p[14] = -2 * fa * n / (fa - n);
  for (int i = 0; i < 16; i++) view[i] = (float)v[i], proj[i] = (float)p[i];
}

bool tx_camera_project(const tx_camera* c, tx_eye eye, double aspect, const double p[3], double ndc[3]) {
  double r[3], u[3], f[3], e[3], d[3];
  frame(c, r, u, f);
  tx_camera_eye_position(c, eye, e);
  sub(p, e, d);
  double x = dot(d, r), y = dot(d, u), z = dot(d, f); // z: depth in front of the eye
  if (!(z > 0)) return false;
  double l, rt, b, t;
  frustum(c, eye, aspect, &l, &rt, &b, &t);
  // onto the near plane, then the frustum window to [-1, 1]
  double xn = x * c->near_m / z, yn = y * c->near_m / z;
  ndc[0] = (2 * xn - (rt + l)) / (rt - l);
  ndc[1] = (2 * yn - (t + b)) / (t - b);
  double n = c->near_m, fa = c->far_m;
  ndc[2] = ((fa + n) * z - 2 * fa * n) / ((fa - n) * z);
  return true;
}
