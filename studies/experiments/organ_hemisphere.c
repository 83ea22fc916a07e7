// The organ-hemisphere check's pieces without physics (see organ_hemisphere.h).
#include "organ_hemisphere.h"

#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void tx_hemisphere_free(tx_hemisphere_mesh* m) {
  free(m->v);
  free(m->e);
  free(m->base);
  *m = (tx_hemisphere_mesh){0};
}

bool tx_hemisphere_build(double radius, int n, tx_hemisphere_mesh* m) {
  return tx_hemisphere_build_graded(radius, n, 1, m);
}

// t in [-1, 1] (or [0, 1]) pulled toward 0: |t|^grade with its sign
static double pull(double t, double grade) { return t < 0 ? -pow(-t, grade) : pow(t, grade); }

bool tx_hemisphere_build_graded(double radius, int n, double grade, tx_hemisphere_mesh* m) {
  *m = (tx_hemisphere_mesh){0};
  if (!(radius > 0 && radius < 10) || n < 1 || n > 64 || !(grade >= 1 && grade <= 3)) {
    tx_set_error("hemisphere: radius %g m, %d cells per radius, grading %g: need 0 < R < 10 m, 1 to 64 cells, "
                 "grading 1 to 3",
                 radius, n, grade);
    return false;
  }
  int nx = 2 * n + 1, ny = n + 1;
  m->n = n;
  m->nv = nx * ny * nx;
  m->ne = 24 * n * n * n;
  m->v = malloc((size_t)m->nv * 3 * sizeof(double));
  m->e = malloc((size_t)m->ne * 4 * sizeof(int));
  m->base = calloc((size_t)m->nv, sizeof(bool));
  if (!m->v || !m->e || !m->base) {
    tx_hemisphere_free(m);
    tx_set_error("hemisphere: out of memory for %d cells per radius", n);
    return false;
  }
  // nodes: the half cube mapped onto the half ball
  for (int k = 0; k < nx; k++)
    for (int j = 0; j < ny; j++)
      for (int i = 0; i < nx; i++) {
        double x = pull(-1 + (double)i / n, grade), y = 1 - pull(1 - (double)j / n, grade);
        double z = pull(-1 + (double)k / n, grade);
        double x2 = x * x, y2 = y * y, z2 = z * z;
        int id = (k * ny + j) * nx + i;
        double* p = m->v + 3 * id;
        p[0] = radius * x * sqrt(fmax(0, 1 - y2 / 2 - z2 / 2 + y2 * z2 / 3));
        p[1] = radius * y * sqrt(fmax(0, 1 - z2 / 2 - x2 / 2 + z2 * x2 / 3));
        p[2] = radius * z * sqrt(fmax(0, 1 - x2 / 2 - y2 / 2 + x2 * y2 / 3));
        m->base[id] = j == 0;
        if (i == n && j == n && k == n) m->pole = id;
      }
  // six tetrahedra per cell: the paths from its corner (0,0,0) to (1,1,1)
  // along the axes in each order; an odd order is turned over to keep the
  // volume positive
  static const int perm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  int* out = m->e;
  for (int k = 0; k < 2 * n; k++)
    for (int j = 0; j < n; j++)
      for (int i = 0; i < 2 * n; i++)
        for (int p = 0; p < 6; p++) {
          int c[3] = {i, j, k}, ids[4];
          for (int s = 0; s < 4; s++) {
            if (s > 0) c[perm[p][s - 1]]++;
            ids[s] = (c[2] * ny + c[1]) * nx + c[0];
          }
          if (p >= 3) {
            int t = ids[1];
            ids[1] = ids[2], ids[2] = t;
          }
          memcpy(out, ids, sizeof ids);
          out += 4;
        }
  return true;
}

double tx_hertz_force(double young, double nu, double radius, double depth) {
  if (depth <= 0) return 0;
  return 4.0 / 3.0 * young / (1 - nu * nu) * sqrt(radius) * pow(depth, 1.5);
}

double tx_hertz_contact_radius(double radius, double depth) { return depth > 0 ? sqrt(radius * depth) : 0; }

double tx_observed_order(double f1, double f2, double f3, double ratio) {
  double d1 = f1 - f2, d2 = f2 - f3;
  if (d1 == 0 || d2 == 0 || (d1 > 0) != (d2 > 0) || fabs(d2) >= fabs(d1) || !(ratio > 1)) return NAN;
  return log(d1 / d2) / log(ratio);
}

double tx_richardson(double f1, double f2, double ratio, double order) {
  return f2 + (f2 - f1) / (pow(ratio, order) - 1);
}
