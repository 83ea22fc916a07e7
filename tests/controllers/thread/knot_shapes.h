// The reference set of thread shapes, with the answer each should get: tight
// and loose overhand, square and granny knots (connected sums of two
// trefoils of opposite or of the same hand), and knotless traps: a straight
// thread, two strands touching side by side over 12 cylinders, a loop that
// does not cross itself, a curl (a loop that crosses itself once) and a
// strand laid twice over another (a bigon). Knots are open ("long") knots:
// each trefoil's first end comes in over everything, as the closure of a
// knot would. Nodes are 0.5 mm apart; the thread is 0.5 mm thick.
#ifndef TX_TESTS_THREAD_KNOT_SHAPES_H
#define TX_TESTS_THREAD_KNOT_SHAPES_H

#include "controllers/thread/knot.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#define SHAPE_SPACING 0.0005 // m, between nodes
#define SHAPE_RADIUS 0.00025 // m, of the thread
#define SHAPE_MAX 4000       // nodes
#define SHAPE_PI 3.14159265358979323846

typedef struct shape {
  const char* name;
  bool knot;          // the true answer
  tx_knot_class cls;  // what the classifier should say
  int n;              // nodes
  double* x;          // (n x 3) m
} shape;

typedef struct polyline {
  int n;
  double p[4096][3];
} polyline;

static void pl_add(polyline* l, double x, double y, double z) {
  l->p[l->n][0] = x, l->p[l->n][1] = y, l->p[l->n][2] = z;
  l->n++;
}

// nodes SHAPE_SPACING apart along the polyline (the last node at its end)
static int resample(const polyline* l, double* x) {
  double total = 0;
  for (int i = 1; i < l->n; i++) {
    double d = 0;
    for (int a = 0; a < 3; a++) d += pow(l->p[i][a] - l->p[i - 1][a], 2);
    total += sqrt(d);
  }
  int n = (int)floor(total / SHAPE_SPACING) + 1;
  if (n > SHAPE_MAX) n = SHAPE_MAX;
  int seg = 1;
  double at = 0, seg_start = 0, seg_len = 0;
  {
    double dd = 0;
    for (int a = 0; a < 3; a++) dd += pow(l->p[1][a] - l->p[0][a], 2);
    seg_len = sqrt(dd);
  }
  for (int k = 0; k < n; k++) {
    at = k * SHAPE_SPACING;
    while (at > seg_start + seg_len && seg < l->n - 1) {
      seg_start += seg_len;
      seg++;
      double dd = 0;
      for (int a = 0; a < 3; a++) dd += pow(l->p[seg][a] - l->p[seg - 1][a], 2);
      seg_len = sqrt(dd);
    }
    double f = seg_len > 0 ? (at - seg_start) / seg_len : 0;
    if (f > 1) f = 1;
    for (int a = 0; a < 3; a++) x[3 * k + a] = l->p[seg - 1][a] + f * (l->p[seg][a] - l->p[seg - 1][a]);
  }
  return n;
}

// an open trefoil of size u (m) starting at x0 - 12 u and ending at x0 + 12 u
// on the x axis; hand +1 or -1 (its mirror image)
static void long_trefoil(polyline* l, double u, double x0, int hand) {
  double ts = 0, xs = -1e9;
  for (int k = 0; k < 100000; k++) { // the lobe furthest along +x: where the knot is cut open
    double t = 2 * SHAPE_PI * k / 100000, xv = sin(t) + 2 * sin(2 * t);
    if (xv > xs) xs = xv, ts = t;
  }
  double cut = 0.15;
  double a0 = ts + cut, a1 = ts + 2 * SHAPE_PI - cut;
#define TX(t) (x0 + u * (sin(t) + 2 * sin(2 * (t))))
#define TY(t) (u * (cos(t) - 2 * cos(2 * (t))))
#define TZ(t) (-hand * u * sin(3 * (t)))
  pl_add(l, x0 - 12 * u, 0, 0);
  pl_add(l, x0 - 12 * u, 0, 5 * u); // in over everything
  pl_add(l, TX(a0), TY(a0), 5 * u);
  for (int k = 0; k <= 400; k++) {
    double t = a0 + (a1 - a0) * k / 400;
    pl_add(l, TX(t), TY(t), TZ(t));
  }
  pl_add(l, TX(a1) + 3 * u, TY(a1), TZ(a1));
  pl_add(l, x0 + 12 * u, 0, 0);
#undef TX
#undef TY
#undef TZ
}

static shape make_shape(const char* name, bool knot, tx_knot_class cls, const polyline* l) {
  shape s = {name, knot, cls, 0, malloc(sizeof(double) * 3 * SHAPE_MAX)};
  if (s.x) s.n = resample(l, s.x);
  return s;
}

// the whole set; returns how many (at most 16)
static int knot_shapes(shape* out) {
  static polyline l;
  int k = 0;
  double tight = 0.00035, loose = 0.002;
  l.n = 0, long_trefoil(&l, tight, 0, 1);
  out[k++] = make_shape("overhand, tight", true, TX_KNOT_TREFOIL, &l);
  l.n = 0, long_trefoil(&l, loose, 0, 1);
  out[k++] = make_shape("overhand, loose", true, TX_KNOT_TREFOIL, &l);
  l.n = 0, long_trefoil(&l, tight, 0, 1), long_trefoil(&l, tight, 24 * tight, -1);
  out[k++] = make_shape("square, tight", true, TX_KNOT_SQUARE, &l);
  l.n = 0, long_trefoil(&l, tight, 0, 1), long_trefoil(&l, tight, 24 * tight, 1);
  out[k++] = make_shape("granny, tight", true, TX_KNOT_GRANNY, &l);
  l.n = 0, long_trefoil(&l, loose, 0, -1), long_trefoil(&l, loose, 24 * loose, 1);
  out[k++] = make_shape("square, loose", true, TX_KNOT_SQUARE, &l);
  l.n = 0, long_trefoil(&l, loose, 0, -1), long_trefoil(&l, loose, 24 * loose, -1);
  out[k++] = make_shape("granny, loose", true, TX_KNOT_GRANNY, &l);
  // straight
  l.n = 0, pl_add(&l, 0, 0, 0), pl_add(&l, 0.02, 0, 0);
  out[k++] = make_shape("straight", false, TX_KNOT_UNKNOT, &l);
  // two strands side by side, 0.45 mm apart (touching: 2 r = 0.5 mm) over 6 mm
  // (12 cylinders), joined by a wide turn: contact without a knot
  l.n = 0;
  pl_add(&l, 0, 0, 0), pl_add(&l, 0.02, 0, 0);
  for (int i = 1; i <= 20; i++) pl_add(&l, 0.02 + 0.003 * sin(SHAPE_PI * i / 20), 0.003 - 0.003 * cos(SHAPE_PI * i / 20), 0);
  pl_add(&l, 0.013, 0.00045, 0), pl_add(&l, 0.007, 0.00045, 0), pl_add(&l, 0, 0.006, 0);
  out[k++] = make_shape("parallel strands touching", false, TX_KNOT_UNKNOT, &l);
  // a loop that almost closes, 2 mm between its ends, in a plane
  l.n = 0;
  for (int i = 0; i <= 100; i++) {
    double a = 0.2 + (2 * SHAPE_PI - 0.4) * i / 100;
    pl_add(&l, 0.005 * cos(a), 0.005 * sin(a), 0);
  }
  out[k++] = make_shape("loop, no crossing", false, TX_KNOT_UNKNOT, &l);
  // a curl: the thread loops round and crosses itself once, 2 mm over
  l.n = 0;
  pl_add(&l, -0.01, 0, 0);
  for (int i = 0; i <= 100; i++) {
    double a = -SHAPE_PI / 2 + 2 * SHAPE_PI * i / 100;
    pl_add(&l, 0.004 * cos(a), 0.004 + 0.004 * sin(a), 0.002 * i / 100);
  }
  pl_add(&l, 0.01, 0, 0.002);
  out[k++] = make_shape("curl (one crossing)", false, TX_KNOT_UNKNOT, &l);
  // a bigon: the thread comes back and lies twice over its own first part
  l.n = 0;
  pl_add(&l, 0, 0, 0), pl_add(&l, 0.015, 0, 0), pl_add(&l, 0.015, -0.005, 0.001), pl_add(&l, 0.01, -0.005, 0.001);
  pl_add(&l, 0.01, 0.005, 0.001), pl_add(&l, 0.005, 0.005, 0.001), pl_add(&l, 0.005, -0.005, 0.001);
  pl_add(&l, 0, -0.005, 0.001);
  out[k++] = make_shape("bigon (laid over twice)", false, TX_KNOT_UNKNOT, &l);
  return k;
}

static void free_shapes(shape* s, int n) {
  for (int i = 0; i < n; i++) free(s[i].x);
}

#endif
