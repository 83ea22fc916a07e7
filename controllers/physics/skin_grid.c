// The skin's grid: particles and triangles.
#include "skin_grid.h"

#include <stddef.h>

uint32_t tx_skin_grid(int nx, int nz, double hx, double hz, const double centre[3], float* x, int32_t* tri) {
  if (nx < 2 || nz < 2) return 0;
  if (x)
    for (int iz = 0; iz < nz; iz++)
      for (int ix = 0; ix < nx; ix++) {
        float* p = x + 3 * ((size_t)iz * (size_t)nx + (size_t)ix);
        p[0] = (float)(centre[0] + (ix - 0.5 * (nx - 1)) * hx);
        p[1] = (float)centre[1];
        p[2] = (float)(centre[2] + (iz - 0.5 * (nz - 1)) * hz);
      }
  for (int cz = 0; cz + 1 < nz; cz++)
    for (int cx = 0; cx + 1 < nx; cx++) {
      int32_t a = cz * nx + cx, b = a + 1, c = a + nx, d = c + 1;
      int32_t* t = tri + 6 * ((size_t)cz * (size_t)(nx - 1) + (size_t)cx);
      if (((cx + cz) & 1) == 0) { // diagonal a-d
        t[0] = a, t[1] = d, t[2] = b;
        t[3] = a, t[4] = c, t[5] = d;
      } else { // diagonal b-c
        t[0] = a, t[1] = c, t[2] = b;
        t[3] = b, t[4] = c, t[5] = d;
      }
    }
  return 2u * (uint32_t)(nx - 1) * (uint32_t)(nz - 1);
}
