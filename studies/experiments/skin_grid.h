// Internal: synthetic skin meshes for tests and benchmarks, independent of any
// physics engine: an n x n particle grid on the plane y = 0, centred on the
// origin, two triangles per cell, optionally pressed in by a smooth dent.
//
//     float x[3 * n * n];  int32_t tri[6 * (n - 1) * (n - 1)];
//     uint32_t m = tx_skin_grid(n, 0.001, x, tri);        // 1 mm spacing
//     tx_skin_dent(x, n * n, (double[3]){0, 0, 0}, 0.002, 0.005); // 2 mm deep, 5 mm wide
#ifndef TX_CONTROLLERS_COLLISION_SKIN_GRID_H
#define TX_CONTROLLERS_COLLISION_SKIN_GRID_H

#include <stdint.h>

// fill x (n*n x 3, m) and tri (2 (n-1)^2 x 3); returns the triangle count
uint32_t tx_skin_grid(uint32_t n, double spacing, float* x, int32_t* tri);
// move every particle down by depth * exp(-d^2 / (2 width^2)), d its distance from
// centre in the x-z plane (depth, width in m)
void tx_skin_dent(float* x, uint32_t count, const double centre[3], double depth, double width);

#endif
