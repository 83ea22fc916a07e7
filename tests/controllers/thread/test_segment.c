// Closest points of two segments (eqs. 10-18) against hand-computed answers
// for the skew, parallel, collinear, clamped and zero-length cases, and
// against a convex minimisation on random pairs; the triangle's closest point
// in each Voronoi region; a segment's crossing of a triangle.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/thread/segment.h"

#include <math.h>
#include <stdlib.h>

#define P(...) ((const double[3]){__VA_ARGS__})

static void expect(const double p[3], const double p1[3], const double q[3], const double q1[3], double t, double s,
                   double dist) {
  tx_seg_closest c;
  tx_seg_closest_points(p, p1, q, q1, &c);
  assert_true(fabs(c.t - t) < 1e-12);
  assert_true(fabs(c.s - s) < 1e-12);
  assert_true(fabs(c.dist - dist) < 1e-12);
  for (int a = 0; a < 3; a++) {
    assert_true(fabs(c.a[a] - (p[a] + t * (p1[a] - p[a]))) < 1e-12);
    assert_true(fabs(c.b[a] - (q[a] + s * (q1[a] - q[a]))) < 1e-12);
  }
  // swapping the segments swaps the answer (the distance at least: a
  // parallel pair has many closest pairs)
  tx_seg_closest r;
  tx_seg_closest_points(q, q1, p, p1, &r);
  assert_true(fabs(r.dist - dist) < 1e-12);
}

static void test_hand_computed_cases(void** state) {
  (void)state;
  // skew and perpendicular, closest at both middles (eqs. 18a, 18b inside [0, 1])
  expect(P(-1, 0, 0), P(1, 0, 0), P(0, -1, 1), P(0, 1, 1), 0.5, 0.5, 1);
  // crossing: distance 0
  expect(P(-1, 0, 0), P(1, 0, 0), P(0, -1, 0), P(0, 1, 0), 0.5, 0.5, 0);
  // T: the unclamped t is past the end of p p'; clamped to 1
  expect(P(0, 0, 0), P(1, 0, 0), P(2, -1, 0), P(2, 1, 0), 1, 0.5, 1);
  // both clamped: the nearest ends
  expect(P(0, 0, 0), P(1, 0, 0), P(2, 1, 0), P(2, 3, 0), 1, 0, sqrt(2));
  // parallel and overlapping: singular system, t = 0 taken, s clamped, t again
  expect(P(0, 0, 0), P(2, 0, 0), P(1, 1, 0), P(3, 1, 0), 0.5, 0, 1);
  // parallel, disjoint along the axis
  expect(P(0, 0, 0), P(1, 0, 0), P(2, 1, 0), P(3, 1, 0), 1, 0, sqrt(2));
  // antiparallel collinear, end to end
  expect(P(0, 0, 0), P(1, 0, 0), P(3, 0, 0), P(2, 0, 0), 1, 1, 1);
  // collinear and overlapping: touching, distance 0
  tx_seg_closest c;
  tx_seg_closest_points(P(0, 0, 0), P(2, 0, 0), P(1, 0, 0), P(3, 0, 0), &c);
  assert_true(c.dist < 1e-15);
  // zero-length p p': the point's foot on q q'
  expect(P(0.5, 1, 0), P(0.5, 1, 0), P(0, 0, 0), P(1, 0, 0), 0, 0.5, 1);
  // zero-length q q' beyond the end of p p'
  expect(P(0, 0, 0), P(1, 0, 0), P(3, 0, 4), P(3, 0, 4), 1, 0, sqrt(4 + 16));
  // both points
  expect(P(1, 2, 3), P(1, 2, 3), P(1, 2, 5), P(1, 2, 5), 0, 0, 2);
  // nearly parallel (determinant ~1e-14 of vv ww): still the true distance
  tx_seg_closest_points(P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(1, 1 + 1e-9, 0), &c);
  assert_true(fabs(c.dist - 1) < 1e-9);
  // the paper's contact test, |AB| < 2 r: two cylinders of r = 0.25 mm 0.4 mm apart touch
  tx_seg_closest_points(P(0, 0, 0), P(0.003, 0, 0), P(0.0015, 0.0004, -0.001), P(0.0015, 0.0004, 0.002), &c);
  assert_true(c.dist < 2 * 0.00025);
  assert_true(fabs(c.dist - 0.0004) < 1e-15);
}

static double frand(void) { return rand() / (double)RAND_MAX * 2 - 1; }

// the distance from A(t) to q q' is convex in t: a ternary search finds the minimum
static double reference(const double p[3], const double p1[3], const double q[3], const double q1[3]) {
  double lo = 0, hi = 1;
  double best = INFINITY;
  for (int it = 0; it < 200; it++) {
    double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3, f[2];
    for (int k = 0; k < 2; k++) {
      double tt = k ? m2 : m1, a[3];
      for (int j = 0; j < 3; j++) a[j] = p[j] + tt * (p1[j] - p[j]);
      double s = tx_seg_point_param(q, q1, a), d = 0;
      for (int j = 0; j < 3; j++) {
        double e = q[j] + s * (q1[j] - q[j]) - a[j];
        d += e * e;
      }
      f[k] = sqrt(d);
      if (f[k] < best) best = f[k];
    }
    if (f[0] < f[1])
      hi = m2;
    else
      lo = m1;
  }
  return best;
}

static void test_random_pairs_match_a_minimisation(void** state) {
  (void)state;
  srand(11);
  for (int k = 0; k < 2000; k++) {
    double p[3], p1[3], q[3], q1[3];
    for (int a = 0; a < 3; a++) {
      p[a] = frand(), p1[a] = frand(), q[a] = frand(), q1[a] = frand();
    }
    if (k % 4 == 1) // parallel
      for (int a = 0; a < 3; a++) q1[a] = q[a] + 0.7 * (p1[a] - p[a]);
    if (k % 4 == 2) // a point
      for (int a = 0; a < 3; a++) q1[a] = q[a];
    tx_seg_closest c;
    tx_seg_closest_points(p, p1, q, q1, &c);
    assert_true(c.t >= 0 && c.t <= 1 && c.s >= 0 && c.s <= 1);
    assert_true(fabs(c.dist - reference(p, p1, q, q1)) < 1e-9);
  }
}

static void test_triangle_closest_point_regions(void** state) {
  (void)state;
  const double* a = P(0, 0, 0);
  const double* b = P(1, 0, 0);
  const double* c = P(0, 1, 0);
  struct {
    double p[3], want[3];
  } cases[] = {
      {{0.2, 0.2, 0.5}, {0.2, 0.2, 0}},  // face
      {{-1, -1, 0}, {0, 0, 0}},          // vertex a
      {{2, -0.5, 1}, {1, 0, 0}},         // vertex b
      {{-0.5, 2, 0}, {0, 1, 0}},         // vertex c
      {{0.5, -1, 0}, {0.5, 0, 0}},       // edge ab
      {{-1, 0.5, 0}, {0, 0.5, 0}},       // edge ac
      {{1, 1, -2}, {0.5, 0.5, 0}},       // edge bc
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    double out[3], bary[3];
    tx_tri_closest_point(cases[k].p, a, b, c, out, bary);
    for (int j = 0; j < 3; j++) {
      assert_true(fabs(out[j] - cases[k].want[j]) < 1e-12);
      assert_true(fabs(bary[0] * a[j] + bary[1] * b[j] + bary[2] * c[j] - out[j]) < 1e-12);
    }
  }
}

static void test_segment_crosses_triangle(void** state) {
  (void)state;
  const double* a = P(0, 0, 0);
  const double* b = P(1, 0, 0);
  const double* c = P(0, 1, 0);
  double t = -1;
  assert_true(tx_seg_tri_cross(P(0.25, 0.25, 1), P(0.25, 0.25, -3), a, b, c, &t));
  assert_true(fabs(t - 0.25) < 1e-12);
  // from below too
  assert_true(tx_seg_tri_cross(P(0.25, 0.25, -1), P(0.25, 0.25, 1), a, b, c, &t));
  assert_true(fabs(t - 0.5) < 1e-12);
  // stops short, passes beside, runs in the plane
  assert_false(tx_seg_tri_cross(P(0.25, 0.25, 1), P(0.25, 0.25, 0.1), a, b, c, &t));
  assert_false(tx_seg_tri_cross(P(0.8, 0.8, 1), P(0.8, 0.8, -1), a, b, c, &t));
  assert_false(tx_seg_tri_cross(P(-1, 0.2, 0), P(2, 0.2, 0), a, b, c, &t));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_hand_computed_cases),
      cmocka_unit_test(test_random_pairs_match_a_minimisation),
      cmocka_unit_test(test_triangle_closest_point_regions),
      cmocka_unit_test(test_segment_crosses_triangle),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
