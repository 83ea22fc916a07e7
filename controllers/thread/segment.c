// Closest points of segments and triangles for the thread's contacts.
#include "segment.h"

#include <math.h>

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double clamp01(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

double tx_seg_point_param(const double a[3], const double b[3], const double c[3]) {
  double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  double dd = dot(d, d);
  return dd > 0 ? clamp01(dot(d, e) / dd) : 0;
}

void tx_seg_closest_points(const double p[3], const double p1[3], const double q[3], const double q1[3],
                           tx_seg_closest* out) {
  double v[3], w[3], r[3];
  for (int k = 0; k < 3; k++) {
    v[k] = p1[k] - p[k];
    w[k] = q1[k] - q[k];
    r[k] = p[k] - q[k];
  }
  double vv = dot(v, v), ww = dot(w, w), vw = dot(v, w), vr = dot(v, r), wr = dot(w, r);
  double t, s;
  if (vv <= 0 && ww <= 0) { // two points
    t = s = 0;
  } else if (vv <= 0) { // p p' is a point: its nearest point on q q'
    t = 0;
    s = clamp01(wr / ww);
  } else if (ww <= 0) { // q q' is a point
    s = 0;
    t = clamp01(-vr / vv);
  } else {
    // eqs. 18a, 18b by Cramer's rule; the determinant vv ww - vw^2 is zero
    // for parallel segments, where t = 0 is taken and s follows from it
    double det = vv * ww - vw * vw;
    t = det > 1e-12 * vv * ww ? clamp01((vw * wr - vr * ww) / det) : 0;
    s = (vw * t + wr) / ww;
    // s outside [0, 1]: clamp it and take t again for that end of q q'
    if (s < 0) {
      s = 0;
      t = clamp01(-vr / vv);
    } else if (s > 1) {
      s = 1;
      t = clamp01((vw - vr) / vv);
    }
  }
  out->t = t;
  out->s = s;
  double d2 = 0;
  for (int k = 0; k < 3; k++) {
    out->a[k] = p[k] + t * v[k];
    out->b[k] = q[k] + s * w[k];
    double d = out->b[k] - out->a[k];
    d2 += d * d;
  }
  out->dist = sqrt(d2);
}

void tx_tri_closest_point(const double p[3], const double a[3], const double b[3], const double c[3], double out[3],
                          double bary[3]) {
  // Ericson 5.1.5: the Voronoi region of p among the triangle's vertices, edges and face
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; k++) {
    ab[k] = b[k] - a[k];
    ac[k] = c[k] - a[k];
    ap[k] = p[k] - a[k];
    bp[k] = p[k] - b[k];
    cp[k] = p[k] - c[k];
  }
  double u = 1, v = 0, w = 0;
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (d1 <= 0 && d2 <= 0) {
    u = 1, v = 0, w = 0; // vertex a
  } else if (d3 >= 0 && d4 <= d3) {
    u = 0, v = 1, w = 0; // vertex b
  } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    v = d1 / (d1 - d3), u = 1 - v, w = 0; // edge ab
  } else if (d6 >= 0 && d5 <= d6) {
    u = 0, v = 0, w = 1; // vertex c
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    w = d2 / (d2 - d6), u = 1 - w, v = 0; // edge ac
  } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    w = (d4 - d3) / ((d4 - d3) + (d5 - d6)), v = 1 - w, u = 0; // edge bc
  } else {
    double den = va + vb + vc;
    if (den > 0) {
      v = vb / den, w = vc / den, u = 1 - v - w; // the face
    }
  }
  for (int k = 0; k < 3; k++) out[k] = u * a[k] + v * b[k] + w * c[k];
  if (bary) {
    bary[0] = u;
    bary[1] = v;
    bary[2] = w;
  }
}

int tx_seg_tri_cross(const double o[3], const double e[3], const double a[3], const double b[3], const double c[3],
                     double* t) {
  // Moller-Trumbore on the segment o e
  double d[3], e1[3], e2[3], h[3], s[3], q[3];
  for (int k = 0; k < 3; k++) {
    d[k] = e[k] - o[k];
    e1[k] = b[k] - a[k];
    e2[k] = c[k] - a[k];
    s[k] = o[k] - a[k];
  }
  h[0] = d[1] * e2[2] - d[2] * e2[1];
  h[1] = d[2] * e2[0] - d[0] * e2[2];
  h[2] = d[0] * e2[1] - d[1] * e2[0];
  double det = dot(e1, h);
  if (fabs(det) < 1e-30) return 0;
  double inv = 1 / det, u = dot(s, h) * inv;
  if (u < 0 || u > 1) return 0;
  q[0] = s[1] * e1[2] - s[2] * e1[1];
  q[1] = s[2] * e1[0] - s[0] * e1[2];
  q[2] = s[0] * e1[1] - s[1] * e1[0];
  double v = dot(d, q) * inv;
  if (v < 0 || u + v > 1) return 0;
  double tt = dot(e2, q) * inv;
  if (tt < 0 || tt > 1) return 0;
  *t = tt;
  return 1;
}
