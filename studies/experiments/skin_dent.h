// Internal: a synthetic deformation of a skin grid (controllers/physics/skin_grid.h)
// for tests and benchmarks, independent of any physics engine: a smooth dent.
//
//     tx_skin_dent(x, n * n, (double[3]){0, 0, 0}, 0.002, 0.005); // 2 mm deep, 5 mm wide
#ifndef TX_STUDIES_EXPERIMENTS_SKIN_DENT_H
#define TX_STUDIES_EXPERIMENTS_SKIN_DENT_H

#include <stdint.h>

// move every particle down by depth * exp(-d^2 / (2 width^2)), d its distance from
// centre in the x-z plane (depth, width in m)
void tx_skin_dent(float* x, uint32_t count, const double centre[3], double depth, double width);

#endif
