// Synthetic skin: a flat particle grid and a Gaussian dent.
#include "skin_grid.h"

#include <math.h>
#include <stddef.h>

uint32_t tx_skin_grid(uint32_t n, double spacing, float* x, int32_t* tri) {
  double half = 0.5 * spacing * (n - 1);
  for (uint32_t i = 0; i < n; i++)
    for (uint32_t j = 0; j < n; j++) {
      float* p = x + 3 * ((size_t)i * n + j);
      p[0] = (float)(j * spacing - half);
      p[1] = 0.0f;
      p[2] = (float)(i * spacing - half);
    }
  uint32_t m = 0;
  // two triangles per cell, wound so their normals point up (+y)
  for (uint32_t i = 0; i + 1 < n; i++)
    for (uint32_t j = 0; j + 1 < n; j++) {
      int32_t a = (int32_t)(i * n + j), b = a + 1, c = a + (int32_t)n, d = c + 1;
      int32_t* t = tri + 3 * (size_t)m;
      t[0] = a, t[1] = c, t[2] = b;
      t[3] = b, t[4] = c, t[5] = d;
      m += 2;
    }
  return m;
}

void tx_skin_dent(float* x, uint32_t count, const double centre[3], double depth, double width) {
  for (uint32_t i = 0; i < count; i++) {
    float* p = x + 3 * (size_t)i;
    double dx = p[0] - centre[0], dz = p[2] - centre[2];
    p[1] -= (float)(depth * exp(-(dx * dx + dz * dz) / (2 * width * width)));
  }
}
