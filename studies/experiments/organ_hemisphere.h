// Internal: the pieces of the organ-hemisphere check (the LAGB paper's
// Figure 14) that need no physics engine: the hemisphere's tetrahedra at a
// chosen refinement, Hertz's closed form, and Richardson extrapolation.
//
//   tx_hemisphere_mesh m;
//   tx_hemisphere_build(0.02, 6, &m);           // R = 2 cm, 6 cells per radius: 5184 tetrahedra
//   double f = tx_hertz_force(5e3, 0.5, 0.02, 0.002);  // N at d = 2 mm
//   tx_hemisphere_free(&m);
#ifndef TX_STUDIES_EXPERIMENTS_ORGAN_HEMISPHERE_H
#define TX_STUDIES_EXPERIMENTS_ORGAN_HEMISPHERE_H

#include <stdbool.h>

// A solid hemisphere of radius R on the plane y = 0, its pole at (0, R, 0):
// the half cube [-1, 1] x [0, 1] x [-1, 1] cut into 2n x n x 2n cells of side
// 1/n, each split into six tetrahedra around its main diagonal
// (Kuhn's split, conforming between cells), then mapped onto the half ball
// by the cube-to-ball map (Nowell's), which keeps y = 0 on the base and sends
// the cube's faces to the sphere. Refining n by a constant ratio refines
// every element by it, as Richardson extrapolation needs.
typedef struct tx_hemisphere_mesh {
  int n;         // cells per radius
  int nv;        // nodes, (2n+1)^2 (n+1)
  int ne;        // tetrahedra, 24 n^3
  double* v;     // positions (nv x 3), m
  int* e;        // node indices (ne x 4), zero-based, positive volume (TetGen's orientation)
  int pole;      // the node at (0, R, 0)
  bool* base;    // (nv) true on the base y = 0, held fixed in the check
} tx_hemisphere_mesh;

bool tx_hemisphere_build(double radius, int n, tx_hemisphere_mesh* m);
// the same with the cells graded toward the pole, where the indenter
// presses: the cube's coordinates pulled toward x = z = 0 and y = 1 as
// |t|^GRADE (1: uniform); refining n at one grading refines every element alike
bool tx_hemisphere_build_graded(double radius, int n, double grade, tx_hemisphere_mesh* m);
void tx_hemisphere_free(tx_hemisphere_mesh* m);

// Hertz: a rigid flat pressed a depth d into an elastic sphere of radius R
// (or a sphere into a flat), F = (4/3) E / (1 - nu^2) sqrt(R) d^(3/2); for
// nu = 0.5, F = (16/9) E sqrt(R) d^(3/2). Valid for small d / R.
double tx_hertz_force(double young, double nu, double radius, double depth);
// the radius of the contact, a = sqrt(R d)
double tx_hertz_contact_radius(double radius, double depth);

// Richardson: from values on meshes refined by RATIO each time, the observed
// order p = ln((f1 - f2) / (f2 - f3)) / ln(ratio) (f1 the coarsest), NAN when
// the differences do not shrink monotonically
double tx_observed_order(double f1, double f2, double f3, double ratio);
// the extrapolated value f2 + (f2 - f1) / (ratio^p - 1) from a coarse f1 and a fine f2
double tx_richardson(double f1, double f2, double ratio, double order);

#endif
