// Scissors cutting a thread (cut.h).
#include "cut.h"

#include <math.h>

// the closest points of segments p0 p1 and q0 q1: parameters s, t in [0, 1]
// (Ericson, Real-Time Collision Detection, 5.1.9)
static void closest_segments(const double p0[3], const double p1[3], const double q0[3], const double q1[3], double* s,
                             double* t) {
  double d1[3], d2[3], r[3], a = 0, e = 0, f = 0, c = 0, b = 0;
  for (int k = 0; k < 3; k++) {
    d1[k] = p1[k] - p0[k], d2[k] = q1[k] - q0[k], r[k] = p0[k] - q0[k];
    a += d1[k] * d1[k], e += d2[k] * d2[k], f += d2[k] * r[k], c += d1[k] * r[k], b += d1[k] * d2[k];
  }
  if (a <= 1e-300 && e <= 1e-300) { *s = *t = 0; return; }
  if (a <= 1e-300) { *s = 0, *t = fmin(fmax(f / e, 0), 1); return; }
  if (e <= 1e-300) { *t = 0, *s = fmin(fmax(-c / a, 0), 1); return; }
  double den = a * e - b * b;
  *s = den > 1e-300 ? fmin(fmax((b * f - c * e) / den, 0), 1) : 0;
  *t = (b * *s + f) / e;
  if (*t < 0) *t = 0, *s = fmin(fmax(-c / a, 0), 1);
  else if (*t > 1) *t = 1, *s = fmin(fmax((b - c) / a, 0), 1);
}

int tx_scissors_cut(const double pivot[3], const double dir[3], double length, double reach,
                    const tx_thread_node* nodes, int n, double point[3]) {
  double tip[3];
  for (int k = 0; k < 3; k++) tip[k] = pivot[k] + length * dir[k];
  int best = -1;
  double best_d = INFINITY;
  for (int i = 0; i + 1 < n; i++) {
    const double *a = nodes[i].x, *b = nodes[i + 1].x;
    if (!isfinite(a[0] + a[1] + a[2] + b[0] + b[1] + b[2])) continue;
    double s, t, d2 = 0, q[3];
    closest_segments(pivot, tip, a, b, &s, &t);
    for (int k = 0; k < 3; k++) {
      q[k] = a[k] + t * (b[k] - a[k]);
      double pk = pivot[k] + s * (tip[k] - pivot[k]);
      d2 += (q[k] - pk) * (q[k] - pk);
    }
    double d = sqrt(d2), r = reach + 0.5 * (nodes[i].radius + nodes[i + 1].radius);
    if (s > 0 && d <= r && d < best_d) { // at the pivot itself (s = 0) nothing is between the blades
      best_d = d, best = i;
      for (int k = 0; k < 3; k++) point[k] = q[k];
    }
  }
  return best;
}

int tx_jaws_pinch(const double pivot[3], const double dir[3], double length, double reach, const float* x, int n,
                  double point[3]) {
  int best = -1;
  double best_d = INFINITY;
  for (int i = 0; i < n; i++) {
    double p[3] = {x[3 * i], x[3 * i + 1], x[3 * i + 2]}, s = 0, d2 = 0;
    if (!isfinite(p[0] + p[1] + p[2])) continue;
    for (int k = 0; k < 3; k++) s += (p[k] - pivot[k]) * dir[k];
    if (s <= 0 || s > length) continue; // behind the pivot or past the tips: not between the jaws
    for (int k = 0; k < 3; k++) d2 += (p[k] - pivot[k] - s * dir[k]) * (p[k] - pivot[k] - s * dir[k]);
    if (d2 <= reach * reach && d2 < best_d) best_d = d2, best = i, point[0] = p[0], point[1] = p[1], point[2] = p[2];
  }
  return best;
}

int tx_blades_close(tx_blades* b, double jaw) {
  if (!isfinite(jaw)) return 0;
  if (jaw > b->open) b->armed = 1;
  if (b->armed && jaw < b->closed) {
    b->armed = 0;
    return 1;
  }
  return 0;
}
