// Internal: a laparoscope camera on a pivot, as pure math (no GL).
//
// The scope passes the abdominal wall at a port, which it cannot leave: it
// turns about the port (yaw, pitch) and slides through it (insertion). Its
// camera is at the tip, looking along the shaft (a 0-degree scope), and its
// light comes from the tip too (a headlight along the view).
//
//     tx_laparoscope s;
//     tx_laparoscope_aim(&s, port, target, 0.05);     // 5 cm in, aimed at target
//     tx_laparoscope_move(&s, 0.1, -0.05, 0.01);      // turn 0.1 rad right, 0.05 down, 1 cm deeper
//     tx_laparoscope_camera(&s, &camera);             // eye at the tip, looking along the shaft
#ifndef TX_VIEWS_GRAPHICS_LAPAROSCOPE_H
#define TX_VIEWS_GRAPHICS_LAPAROSCOPE_H

#include "stereo.h"

#define TX_SCOPE_PITCH_MAX 1.4 // rad (80 degrees): the shaft never points straight along the view's up

typedef struct tx_laparoscope {
  double port[3];        // m, the pivot in the abdominal wall
  double yaw, pitch;     // rad: the shaft's direction (cos p sin y, sin p, cos p cos y) into the body
  double insertion;      // m, from the port to the tip
  double insertion_max;  // m, the shaft's length beyond the port
  double focus;          // m, from the tip to the point looked at (the zero-parallax plane)
} tx_laparoscope;

// from a port toward a target, the tip `insertion` beyond the port (at most
// the target's distance less 1 cm); the shaft can go twice the target's distance
void tx_laparoscope_aim(tx_laparoscope* s, const double port[3], const double target[3], double insertion);
// turn about the port and slide through it; pitch within +-TX_SCOPE_PITCH_MAX,
// insertion within [0, insertion_max]
void tx_laparoscope_move(tx_laparoscope* s, double dyaw, double dpitch, double dinsertion);
void tx_laparoscope_direction(const tx_laparoscope* s, double dir[3]);
void tx_laparoscope_tip(const tx_laparoscope* s, double tip[3]);
// the camera's eye at the tip, its target `focus` ahead, up the world's +y
// (anterior, for a supine patient); convergence at the focus; the rest kept
void tx_laparoscope_camera(const tx_laparoscope* s, tx_camera* c);

// a headlight: the light shines from the eye along the view (unit)
void tx_headlight(const tx_camera* c, float light_dir[3]);

// mouse to scope, in the window: radians per pixel dragged, metres per scroll step
#define TX_SCOPE_RAD_PER_PX 0.004
#define TX_SCOPE_M_PER_SCROLL 0.004

#endif
