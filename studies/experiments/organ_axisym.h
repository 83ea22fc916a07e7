// Internal: the organ-hemisphere check's converged continuum reference. The
// hemisphere with a fixed base pressed at its pole by a rigid frictionless
// flat or sphere is axisymmetric, so the continuum (small-strain linear elasticity, the
// model the organs' FEM discretises) is solved here in the (r, z) half plane
// with biquadratic (9-node) elements, which neither lock at nu = 0.45 nor
// need many elements across the contact, a banded Cholesky factorisation, and
// the contact as a linear complementarity problem on the top surface's
// nodes, solved exactly. No physics engine: this is the reference the
// study's 3-D meshes are measured against.
//
//   tx_axisym* a = tx_axisym_create(0.02, 5e3, 0.45, 32, 2);  // R, E, nu, elements per side, grading
//   double f;
//   tx_axisym_indent(a, 0.002, 0, &f);                        // N at d = 2 mm under a flat
//   tx_axisym_destroy(a);
#ifndef TX_STUDIES_EXPERIMENTS_ORGAN_AXISYM_H
#define TX_STUDIES_EXPERIMENTS_ORGAN_AXISYM_H

#include <stdbool.h>

typedef struct tx_axisym tx_axisym;

// The quarter disc r, z >= 0, r^2 + z^2 <= R^2 (the hemisphere's meridian
// half plane) as the image of the unit square (s, t) under the 2-D cube-to-ball
// map r = R s sqrt(1 - t^2/2), z = R t sqrt(1 - s^2/2), cut into n x n
// 9-node elements, s and t graded toward the pole (0, 1) as s^GRADE and
// 1 - (1 - t)^GRADE, so that refining n refines every element by the same
// ratio and the coarse nodes are among the fine ones. Base z = 0 fixed, u_r = 0
// on the axis. Factorises the stiffness and the top surface's compliance to
// the flat (r <= 0.6 R). NULL and tx_error() on bad arguments or memory.
tx_axisym* tx_axisym_create(double radius, double young, double nu, int n, double grade);
void tx_axisym_destroy(tx_axisym* a);
// the indenter lowered a depth d below the pole: a rigid frictionless flat
// (indenter 0) or a sphere of that radius (m, a tool's tip) on the axis; the
// force it takes (N), the complementarity problem (gap >= 0, pressure >= 0, one of them zero at every
// node) solved by Murty's least-index principal pivoting; false and
// tx_error() if it does not end or the contact reaches past the nodes kept
bool tx_axisym_indent(tx_axisym* a, double depth, double indenter, double* force);
// after tx_axisym_indent: the nodes in contact, and the outer surface's
// vertical displacement (m) at the point phi radians from the pole (0 to pi/2,
// linear between the surface's nodes)
int tx_axisym_contact_nodes(const tx_axisym* a);
double tx_axisym_surface_uz(const tx_axisym* a, double phi);
int tx_axisym_dofs(const tx_axisym* a);

// Banded symmetric positive definite solve, the factorisation in place:
// A holds row i's entries A(i, i - kd .. i) at A[i (kd + 1) + (j - i + kd)]
// (entries before column 0 unused). False when not positive definite.
bool tx_band_cholesky(double* a, int n, int kd);
void tx_band_solve(const double* l, int n, int kd, double* b);

#endif
