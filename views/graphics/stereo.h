// Internal: cameras and off-axis stereo, as pure math (no GL).
//
// Both eyes look along the same direction as the cyclopean camera (parallel
// axes, never toe-in); each is moved half the interaxial distance along the
// camera's right vector, and its frustum is sheared (asymmetric) so that the
// two frusta meet on the convergence plane. A point on that plane has zero
// parallax, a point in front of it crossed parallax (it is drawn further left
// for the right eye than for the left eye), a point behind it uncrossed.
//
//     tx_camera c = tx_camera_default();
//     float view[16], proj[16];  // column-major, as GL takes them
//     tx_camera_matrices(&c, TX_EYE_LEFT, 640.0 / 480.0, view, proj);
//     double ndc[3];
//     tx_camera_project(&c, TX_EYE_RIGHT, 640.0 / 480.0, point, ndc);
#ifndef TX_VIEWS_GRAPHICS_STEREO_H
#define TX_VIEWS_GRAPHICS_STEREO_H

#include <stdbool.h>

typedef enum tx_eye { TX_EYE_LEFT = -1, TX_EYE_MONO = 0, TX_EYE_RIGHT = 1 } tx_eye;

typedef struct tx_camera {
  double eye[3];      // m, the cyclopean eye (midway between the two eyes)
  double target[3];   // m, the point looked at
  double up[3];       // 1, up direction (need not be unit or orthogonal)
  double fov_y;       // rad, vertical field of view, in (0, pi)
  double near_m;      // m, near clip plane distance, > 0
  double far_m;       // m, far clip plane distance, > near_m
  double interaxial;  // m, distance between the left and right eye, >= 0
  double convergence; // m, distance from the eye to the zero-parallax plane, > 0
} tx_camera;

// eye at (0, 0.2, 0.35) m looking at the origin, 40 degrees, converging at the target, eyes 1/30 of that apart
tx_camera tx_camera_default(void);
// 0, or -1 with what is wrong with the camera in tx_error()
int tx_camera_check(const tx_camera* c);
// view and projection matrices (column-major) of one eye for a viewport of this width/height
void tx_camera_matrices(const tx_camera* c, tx_eye eye, double aspect, float view[16], float proj[16]);
// a world point to normalised device coordinates of one eye; false if it is behind the eye
bool tx_camera_project(const tx_camera* c, tx_eye eye, double aspect, const double p[3], double ndc[3]);
// the position of one eye, m
void tx_camera_eye_position(const tx_camera* c, tx_eye eye, double out[3]);

#endif
