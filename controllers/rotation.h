// Internal: rotations shared by controllers: a unit quaternion (w, x, y, z),
// as tx_pose and tx_instrument_pose carry it, applied to a vector, and a
// rotation matrix from angles in degrees about x, then y, then z.
#ifndef TX_CONTROLLERS_ROTATION_H
#define TX_CONTROLLERS_ROTATION_H

#include <math.h>
#include <stdbool.h>

// v rotated by q, or by its inverse (q unit)
static inline void tx_quat_rotate(const double q[4], bool inverse, const double v[3], double out[3]) {
  const double w = q[0], x = inverse ? -q[1] : q[1], y = inverse ? -q[2] : q[2], z = inverse ? -q[3] : q[3];
  const double t0 = 2 * (y * v[2] - z * v[1]), t1 = 2 * (z * v[0] - x * v[2]), t2 = 2 * (x * v[1] - y * v[0]);
  out[0] = v[0] + w * t0 + (y * t2 - z * t1);
  out[1] = v[1] + w * t1 + (z * t0 - x * t2);
  out[2] = v[2] + w * t2 + (x * t1 - y * t0);
}

// R = Rz(deg[2]) Ry(deg[1]) Rx(deg[0]): x' = R x turns about x first
static inline void tx_rotation_from_degrees(const double deg[3], double r[3][3]) {
  const double k = M_PI / 180;
  const double cx = cos(deg[0] * k), sx = sin(deg[0] * k), cy = cos(deg[1] * k), sy = sin(deg[1] * k);
  const double cz = cos(deg[2] * k), sz = sin(deg[2] * k);
  r[0][0] = cz * cy, r[0][1] = cz * sy * sx - sz * cx, r[0][2] = cz * sy * cx + sz * sx;
  r[1][0] = sz * cy, r[1][1] = sz * sy * sx + cz * cx, r[1][2] = sz * sy * cx - cz * sx;
  r[2][0] = -sy, r[2][1] = cy * sx, r[2][2] = cy * cx;
}

#endif
