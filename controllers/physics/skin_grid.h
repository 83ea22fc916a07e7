// Internal: the skin's mesh, a regular particle grid. physics.skin builds its
// cloth on it, and the collision tests and benches build synthetic skins on
// it, so both see the same triangles.
//
// nx x nz particles on the plane y = centre[1], particle (ix, iz) at index
// iz nx + ix; cell (cx, cz) holds triangles 2 (cz (nx - 1) + cx) and the one
// after, split along a diagonal that alternates like a checkerboard (no
// preferred direction, so a dent is symmetric), normals towards +y.
//
//     float x[3 * 42 * 42];  int32_t tri[6 * 41 * 41];
//     uint32_t m = tx_skin_grid(42, 42, 0.0025, 0.0025, (double[3]){0, 0, 0}, x, tri);
#ifndef TX_CONTROLLERS_PHYSICS_SKIN_GRID_H
#define TX_CONTROLLERS_PHYSICS_SKIN_GRID_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// x: (nx nz x 3) m, or NULL for the triangles alone; tri: (2 (nx - 1)(nz - 1) x 3);
// spacings hx, hz in m; returns the triangle count (0 when nx or nz < 2)
uint32_t tx_skin_grid(int nx, int nz, double hx, double hz, const double centre[3], float* x, int32_t* tri);

#ifdef __cplusplus
}
#endif
#endif
