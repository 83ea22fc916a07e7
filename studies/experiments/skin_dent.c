// Synthetic skin deformation: a Gaussian dent.
#include "skin_dent.h"

#include <math.h>
#include <stddef.h>

void tx_skin_dent(float* x, uint32_t count, const double centre[3], double depth, double width) {
  for (uint32_t i = 0; i < count; i++) {
    float* p = x + 3 * (size_t)i;
    double dx = p[0] - centre[0], dz = p[2] - centre[2];
    p[1] -= (float)(depth * exp(-(dx * dx + dz * dz) / (2 * width * width)));
  }
}
