// Internal: closest points of two segments, the test behind every thread
// contact (the suturing conference paper, section 3.3, eqs. 10-18).
//
// Segment one runs from p to p', segment two from q to q'. The paper writes
// v = p - p' and A = p + t v, which for t in [0, 1] leaves the segment; here
// v = p' - p and w = q' - q, so that
//
//   A = p + t v,  B = q + s w,  t, s in [0, 1]                    (eqs. 12, 13)
//
// and A B is perpendicular to both lines where the clamp allows (eqs. 14, 15):
//
//   (v.w) s - (v.v) t = v.(p - q)                                  (eq. 18a)
//   (w.w) s - (v.w) t = w.(p - q)                                  (eq. 18b)
//
// The 2 x 2 system is singular when the segments are parallel (then any t
// with its s is a closest pair: the one nearest t = 0 is taken, so the
// answer is unique) and meaningless when a segment is a point (a zero-length
// segment: the point-segment distance). The unclamped solution is clamped to
// [0, 1] one parameter at a time (Ericson, Real-Time Collision Detection,
// 5.1.9), which gives the true closest pair of the two segments. Contact
// between two cylinders of radius r is |AB| < 2 r (eq. 16).
#ifndef TX_CONTROLLERS_THREAD_SEGMENT_H
#define TX_CONTROLLERS_THREAD_SEGMENT_H

typedef struct tx_seg_closest {
  double t, s;       // parameters of A on p p' and of B on q q', in [0, 1]
  double a[3], b[3]; // m, the points A and B
  double dist;       // m, |AB|
} tx_seg_closest;

// the closest pair of p p' and q q' (either may have zero length)
void tx_seg_closest_points(const double p[3], const double p1[3], const double q[3], const double q1[3],
                           tx_seg_closest* out);

// the parameter in [0, 1] of the point of a b nearest to c (0 for a point segment)
double tx_seg_point_param(const double a[3], const double b[3], const double c[3]);

// the point of triangle (a, b, c) nearest to p, and its barycentric weights
void tx_tri_closest_point(const double p[3], const double a[3], const double b[3], const double c[3], double out[3],
                          double bary[3]);

// where o + t (e - o), t in [0, 1], crosses triangle (a, b, c), either side:
// true and t; false when it misses or runs in the triangle's plane
int tx_seg_tri_cross(const double o[3], const double e[3], const double a[3], const double b[3], const double c[3],
                     double* t);

#endif
