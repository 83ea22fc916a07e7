// A laparoscope on a pivot (see laparoscope.h).
#include "laparoscope.h"

#include <math.h>

void tx_laparoscope_direction(const tx_laparoscope* s, double dir[3]) {
  dir[0] = cos(s->pitch) * sin(s->yaw);
  dir[1] = sin(s->pitch);
  dir[2] = cos(s->pitch) * cos(s->yaw);
}

void tx_laparoscope_tip(const tx_laparoscope* s, double tip[3]) {
  double d[3];
  tx_laparoscope_direction(s, d);
  for (int i = 0; i < 3; i++) tip[i] = s->port[i] + s->insertion * d[i];
}

void tx_laparoscope_move(tx_laparoscope* s, double dyaw, double dpitch, double dinsertion) {
  s->yaw = remainder(s->yaw + dyaw, 2 * M_PI);
  s->pitch = fmax(-TX_SCOPE_PITCH_MAX, fmin(TX_SCOPE_PITCH_MAX, s->pitch + dpitch));
  s->insertion = fmax(0, fmin(s->insertion_max, s->insertion + dinsertion));
}

void tx_laparoscope_aim(tx_laparoscope* s, const double port[3], const double target[3], double insertion) {
  double d[3], len = 0;
  for (int i = 0; i < 3; i++) s->port[i] = port[i], d[i] = target[i] - port[i], len += d[i] * d[i];
  len = sqrt(len);
  s->yaw = len > 0 ? atan2(d[0], d[2]) : 0;
  s->pitch = len > 0 ? asin(fmax(-1, fmin(1, d[1] / len))) : 0;
  s->insertion_max = 2 * len;
  s->insertion = 0, s->focus = fmax(0.01, len - insertion);
  tx_laparoscope_move(s, 0, 0, fmin(insertion, fmax(0, len - 0.01)));
}

void tx_laparoscope_camera(const tx_laparoscope* s, tx_camera* c) {
  double d[3];
  tx_laparoscope_direction(s, d);
  tx_laparoscope_tip(s, c->eye);
  for (int i = 0; i < 3; i++) c->target[i] = c->eye[i] + s->focus * d[i];
  c->up[0] = 0, c->up[1] = 1, c->up[2] = 0;
  c->convergence = s->focus;
}

void tx_headlight(const tx_camera* c, float light_dir[3]) {
  double f[3], l = 0;
  for (int i = 0; i < 3; i++) f[i] = c->target[i] - c->eye[i], l += f[i] * f[i];
  for (int i = 0; i < 3; i++) light_dir[i] = (float)(f[i] / sqrt(l));
}
