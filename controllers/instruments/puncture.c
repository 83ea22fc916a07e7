// Punctures from the skin's publishes (puncture.h).
#include "puncture.h"

#include <math.h>
#include <string.h>

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// the point of triangle abc nearest p, as barycentric coordinates (Ericson,
// Real-Time Collision Detection, 5.1.5: by the Voronoi regions of the corners and edges)
static void closest_bary(const double a[3], const double b[3], const double c[3], const double p[3], double w[3]) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k], bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) { w[0] = 1, w[1] = w[2] = 0; return; }
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) { w[1] = 1, w[0] = w[2] = 0; return; }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    w[0] = 1 - v, w[1] = v, w[2] = 0;
    return;
  }
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) { w[2] = 1, w[0] = w[1] = 0; return; }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double u = d2 / (d2 - d6);
    w[0] = 1 - u, w[2] = u, w[1] = 0;
    return;
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    double u = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w[1] = 1 - u, w[2] = u, w[0] = 0;
    return;
  }
  double den = 1 / (va + vb + vc);
  w[1] = vb * den, w[2] = vc * den, w[0] = 1 - w[1] - w[2];
}

static void corner(const float* x, int32_t i, double o[3]) {
  for (int k = 0; k < 3; k++) o[k] = x[3 * i + k];
}

int tx_nearest_triangle(const float* x, int nx, const int32_t* tri, int ntri, const double p[3], double bary[3],
                        double point[3]) {
  int best = -1;
  double best_d2 = INFINITY;
  for (int t = 0; t < ntri; t++) {
    const int32_t* v = tri + 3 * t;
    if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= nx || v[1] >= nx || v[2] >= nx) continue;
    double a[3], b[3], c[3], w[3], q[3], d2 = 0;
    corner(x, v[0], a), corner(x, v[1], b), corner(x, v[2], c);
    closest_bary(a, b, c, p, w);
    for (int k = 0; k < 3; k++) q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k], d2 += (q[k] - p[k]) * (q[k] - p[k]);
    if (d2 < best_d2) {
      best_d2 = d2, best = t;
      memcpy(bary, w, sizeof w);
      memcpy(point, q, sizeof q);
    }
  }
  return best;
}

void tx_puncture_tracker_init(tx_puncture_tracker* t, double separation, double min_force, double torn) {
  memset(t, 0, sizeof *t);
  t->separation = separation;
  t->min_force = min_force;
  t->torn = torn;
  t->next_side = 1;
  t->free = true;
}

bool tx_puncture_update(tx_puncture_tracker* t, const tx_skin_contact* c, const float* x, int nx, const int32_t* tri,
                        int ntri, tx_puncture_found* out) {
  double fn = sqrt(dot(c->f, c->f));
  bool touching = c->touching > 0 && fn > 0 && isfinite(fn);
  if (!touching) t->free = true; // the tip is clear of the skin: the next touch can make a puncture
  if (touching && t->free) {
    t->touched = true;
    memcpy(t->n, c->n, sizeof t->n);
    if (fn > t->peak_f) t->peak_f = fn, t->peak_depth = c->depth;
  }
  bool tore = c->torn > t->torn;
  if (isfinite(c->torn)) t->torn = c->torn;
  if (!tore || !t->touched || t->peak_f < t->min_force) return false;
  double bary[3], point[3];
  int row = tx_nearest_triangle(x, nx, tri, ntri, c->x, bary, point);
  if (row < 0) return false;
  if (t->any) {
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (point[k] - t->last[k]) * (point[k] - t->last[k]);
    if (d2 < t->separation * t->separation) { // the tear runs on at the last hole: the same puncture
      t->touched = false;
      t->peak_f = t->peak_depth = 0;
      return false;
    }
  }
  const int32_t* v = tri + 3 * row;
  double a[3], b[3], cc[3], ab[3], ac[3];
  corner(x, v[0], a), corner(x, v[1], b), corner(x, v[2], cc);
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = cc[k] - a[k];
  double normal[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
  int side = dot(t->n, normal) >= 0 ? 1 : -1;
  if (side != t->next_side) { // through one membrane the tip goes in, then out: this tear is at the hole it made
    t->touched = false;
    t->peak_f = t->peak_depth = 0;
    return false;
  }
  t->next_side = -side;
  *out = (tx_puncture_found){.row = {.v = {v[0], v[1], v[2]}, .bary = {bary[0], bary[1], bary[2]}, .side = side},
                             .verts = {v[0], v[1], v[2]},
                             .triangle = row,
                             .point = {point[0], point[1], point[2]},
                             .force = t->peak_f,
                             .depth = t->peak_depth};
  t->any = true;
  memcpy(t->last, point, sizeof point);
  t->touched = false;
  t->free = false;
  t->peak_f = t->peak_depth = 0;
  return true;
}
