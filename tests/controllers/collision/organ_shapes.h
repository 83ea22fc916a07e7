// Closed surfaces whose nearest points and normals are known, for the tests of
// collision.organ: a geodesic sphere (an icosahedron subdivided, its vertices on
// the sphere) and a thin box. Both wound outwards (counter-clockwise seen from
// outside), as the organs' surfaces are.
#ifndef TX_TESTS_ORGAN_SHAPES_H
#define TX_TESTS_ORGAN_SHAPES_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct shape {
  float* x;      // 3 nx
  int32_t* tri;  // 3 ntri
  uint32_t nx, ntri;
} shape;

static inline void shape_free(shape* s) {
  free(s->x);
  free(s->tri);
  memset(s, 0, sizeof *s);
}

// the unit-sphere point halfway between vertices a and b, found or added (exact
// equality: (a + b) / 2 is the same either way round)
static inline int32_t ico_mid(double* v, uint32_t* nv, int32_t a, int32_t b) {
  double m[3];
  for (int k = 0; k < 3; k++) m[k] = 0.5 * (v[3 * a + k] + v[3 * b + k]);
  double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  for (int k = 0; k < 3; k++) m[k] /= l;
  for (uint32_t i = 0; i < *nv; i++)
    if (v[3 * i] == m[0] && v[3 * i + 1] == m[1] && v[3 * i + 2] == m[2]) return (int32_t)i;
  memcpy(v + 3 * *nv, m, sizeof m);
  return (int32_t)(*nv)++;
}

// a sphere of radius r about o, the icosahedron subdivided `level` times: 20 4^level triangles
static inline shape ico_sphere(int level, double r, const double o[3]) {
  const double p = (1 + sqrt(5.0)) / 2;
  const double base[12][3] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                              {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  const int32_t faces[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  uint32_t ntri = 20, maxv = 12;
  for (int l = 0; l < level; l++) maxv += 3 * ntri / 2, ntri *= 4;
  double* v = malloc(sizeof(double) * 3 * maxv);
  int32_t* t = malloc(sizeof(int32_t) * 3 * ntri);
  int32_t* u = malloc(sizeof(int32_t) * 3 * ntri);
  uint32_t nv = 12, nt = 20;
  for (int i = 0; i < 12; i++) {
    double l = sqrt(base[i][0] * base[i][0] + base[i][1] * base[i][1] + base[i][2] * base[i][2]);
    for (int k = 0; k < 3; k++) v[3 * i + k] = base[i][k] / l;
  }
  memcpy(t, faces, sizeof faces);
  for (int l = 0; l < level; l++) {
    for (uint32_t f = 0; f < nt; f++) {
      int32_t a = t[3 * f], b = t[3 * f + 1], c = t[3 * f + 2];
      int32_t ab = ico_mid(v, &nv, a, b), bc = ico_mid(v, &nv, b, c), ca = ico_mid(v, &nv, c, a);
      int32_t q[12] = {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca};
      memcpy(u + 12 * f, q, sizeof q);
    }
    nt *= 4;
    int32_t* w = t;
    t = u, u = w;
  }
  shape s = {malloc(sizeof(float) * 3 * nv), t, nv, nt};
  for (uint32_t i = 0; i < 3 * nv; i++) s.x[i] = (float)(o[i % 3] + r * v[i]);
  free(v);
  free(u);
  return s;
}

// the box [lo, hi], two triangles a face, outward
static inline shape box(const double lo[3], const double hi[3]) {
  static const int32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  shape s = {malloc(sizeof(float) * 24), malloc(sizeof(int32_t) * 36), 8, 12};
  for (int i = 0; i < 8; i++) { // corner i: bit 0 x, bit 1 y, bit 2 z
    s.x[3 * i] = (float)(i & 1 ? hi[0] : lo[0]);
    s.x[3 * i + 1] = (float)(i & 2 ? hi[1] : lo[1]);
    s.x[3 * i + 2] = (float)(i & 4 ? hi[2] : lo[2]);
  }
  for (int f = 0; f < 6; f++) {
    int32_t t[6] = {q[f][0], q[f][1], q[f][2], q[f][0], q[f][2], q[f][3]};
    memcpy(s.tri + 6 * f, t, sizeof t);
  }
  return s;
}

// the signed volume (positive when wound outwards)
static inline double shape_volume(const shape* s) {
  double v = 0;
  for (uint32_t f = 0; f < s->ntri; f++) {
    const float *a = s->x + 3 * s->tri[3 * f], *b = s->x + 3 * s->tri[3 * f + 1], *c = s->x + 3 * s->tri[3 * f + 2];
    v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) - a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
          a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6;
  }
  return v;
}

#endif
