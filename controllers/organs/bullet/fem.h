// Internal: a tetrahedral soft body on Bullet, behind a C interface, for the
// organs (liver, stomach) and the organ-hemisphere check.
//
// Two models: Bullet's FEM deformables (its corotated or stable Neo-Hookean
// force on a btSoftBody's tetrahedra, integrated explicitly by symplectic
// Euler here rather than by stepping btDeformableMultiBodyDynamicsWorld, whose
// step also recomputes every tetrahedron's rotation, unused by these forces;
// setImplicit(true) has been seen to diverge at 1-5 ms steps on a small test
// where explicit steps were stable), or Bullet's classic soft body (links along the tetrahedra's edges
// and volume conservation, solved by iterations: the closest open analogue of
// the PhysX soft body of the LAGB paper).
//
//   tx_fem_def d = tx_fem_def_default();
//   tx_fem* b = tx_fem_create(&d, nodes, nv, tets, ne);   // NULL: tx_error() says why
//   tx_fem_fix(b, i);                                       // a node held where it is
//   tx_fem_set_plate(b, y);                                 // a frictionless rigid plate above
//   tx_fem_step(b, 100);
//   double f = tx_fem_plate_force(b);                       // N, pushing the plate up
//   tx_fem_destroy(b);
#ifndef TX_CONTROLLERS_ORGANS_BULLET_FEM_H
#define TX_CONTROLLERS_ORGANS_BULLET_FEM_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum tx_fem_model {
  TX_FEM_COROTATED,   // FEM deformable, corotated linear elasticity
  TX_FEM_NEOHOOKEAN,  // FEM deformable, stable Neo-Hookean (Smith et al. 2018)
  TX_FEM_LINKS,       // classic soft body: edge links and volume conservation
} tx_fem_model;

typedef struct tx_fem_def {
  tx_fem_model model;
  double young;        // Young's modulus, Pa (FEM models)
  double poisson;      // Poisson's ratio, below 0.5 (FEM models)
  double density;      // kg/m^3
  double damping;      // mass-proportional velocity damping, 1/s (moves nothing at rest)
  double dt;           // time step, s; 0: a stable explicit step from the mesh (FEM models)
  bool mass_scaling;   // quasi-static only: thin elements made heavier, so that the step is set by the
                       // median element, not the thinnest (a static answer does not depend on the masses)
  int iterations;      // links: position iterations per step
  double link_stiffness;  // links: Bullet's kLST, 0 to 1
  double volume_stiffness;  // links: Bullet's kVC (volume conservation), >= 0
  double gravity[3];   // m/s^2
  double max_speed;    // m/s: a faster node is a blow-up (tx_fem_step returns false); 0: only NaN and Inf
  bool nodal_pressure; // FEM models: the volume term from each node's J over all its tetrahedra (average nodal
                       // pressure), which keeps linear tetrahedra from locking near nu = 0.5; false: each its own
} tx_fem_def;

tx_fem_def tx_fem_def_default(void);

typedef struct tx_fem tx_fem;

// nodes (nv x 3, m), tets (ne x 4, zero-based, TetGen's orientation)
tx_fem* tx_fem_create(const tx_fem_def* d, const double* nodes, int nv, const int* tets, int ne);
void tx_fem_destroy(tx_fem* b);

void tx_fem_fix(tx_fem* b, int node);
// a rigid frictionless plate whose underside is the plane y = Y: nodes are
// kept at or below it, and what it takes to keep them is its force
void tx_fem_set_plate(tx_fem* b, double y);
// in place of the plate, a rigid frictionless ball (centre c, radius r, m):
// nodes are kept outside it, and tx_fem_plate_force is the upward part of
// what that takes (a node-wise contact, as the plate's; the tool below is
// face-wise). r <= 0: neither ball nor plate.
void tx_fem_set_ball(tx_fem* b, const double c[3], double r);
// rigid frictionless capsules (each 7 numbers: one end of its axis, the
// other, its radius; m) that the nodes are kept out of, node-wise, as the
// ball does; n = 0 removes them. False (nothing changed) for more than
// TX_FEM_CAPSULES_MAX, a radius not above 0 or a value not finite
#define TX_FEM_CAPSULES_MAX 8
bool tx_fem_set_capsules(tx_fem* b, const double* caps, int n);
// false when a position or velocity stopped being finite
bool tx_fem_step(tx_fem* b, int steps);

// A kinematic frictionless sphere (the tool) against the tetrahedra's
// boundary: a face it overlaps is pushed out along the sphere's normal, the
// push shared by the face's nodes by their barycentric weights, at most a
// tenth of r a step; the momentum this takes is its force. A face the
// centre is behind is pushed back only if the centre was in front of it at
// the last call (it went through); a face a removal laid open inside the
// sphere is left until the sphere has left it. r <= 0: no tool.
void tx_fem_set_tool(tx_fem* b, const double c[3], double r);
typedef struct tx_fem_tool_info {
  double f[3];    // N, the body's force on the tool, averaged over the last tx_fem_step
  double depth;   // m, how far the sphere reaches past the boundary as it lay before the tool touched it
  int faces;      // boundary faces it touched in the last step
} tx_fem_tool_info;
void tx_fem_tool(const tx_fem* b, tx_fem_tool_info* out);
// Kinematic nodes, moved by what holds them (a grasper's jaws, a rigid body
// the soft part is bolted to) instead of by the body. tx_fem_set_kinematic
// makes node massless and moves it to p over the next tx_fem_step, in equal
// parts each substep, its velocity the move's; it stays there until the next
// call. tx_fem_release gives it its mass back, keeping the velocity it had.
// Its neighbours follow through the solver. Out-of-range nodes, nodes fixed
// by tx_fem_fix and non-finite p are ignored.
void tx_fem_set_kinematic(tx_fem* b, int node, const double p[3]);
// the same move spread over the next `substeps` substeps, whichever
// tx_fem_step calls take them (a body stepped one substep at a time beside
// another solver: the band's parts); substeps <= 1: tx_fem_set_kinematic
void tx_fem_set_kinematic_over(tx_fem* b, int node, const double p[3], int substeps);
void tx_fem_release(tx_fem* b, int node);
bool tx_fem_is_kinematic(const tx_fem* b, int node);
// FEM models: the body's elastic force on a kinematic node, N, averaged over
// the last tx_fem_step (minus the load on what holds it). Links model: false
// (its position iterations carry no force), f zero.
bool tx_fem_kinematic_force(const tx_fem* b, int node, double f[3]);

// Removal (tissue vaporised by cautery): tetrahedron t stops acting. Its
// elastic force goes, its mass leaves its four nodes, and a node left in no
// live tetrahedron leaves the solve (massless, not stepped, where it was;
// a kinematic one is released). The boundary the tool meets is updated: the
// removed tetrahedron's faces that were boundary go, its faces shared with a
// live neighbour become boundary, turned outward from that neighbour.
// Links model: the links of edges no live tetrahedron has any more go.
// No allocation (sized at tx_fem_create). false: t out of range or already
// removed; nothing changes. Removing the last tetrahedron is refused too
// (false): a body always has one.
bool tx_fem_remove_tet(tx_fem* b, int t);
bool tx_fem_tet_live(const tx_fem* b, int t);
int tx_fem_tet_count(const tx_fem* b);       // tetrahedra as created
int tx_fem_live_tet_count(const tx_fem* b);  // not removed
const int* tx_fem_tets(const tx_fem* b);     // (tx_fem_tet_count x 4) the tetrahedra as created
bool tx_fem_node_live(const tx_fem* b, int node);  // in a live tetrahedron
// the tetrahedron's signed volume now, m^3 (positive: as created; 0 for a removed one)
double tx_fem_tet_volume(const tx_fem* b, int t);
// the live tetrahedra's boundary: *faces rows of 3 node numbers, outward
// (right-hand rule); valid until the next tx_fem_remove_tet
const int* tx_fem_hull(const tx_fem* b, int* faces);
// the check on that boundary, which tx_fem_remove_tet keeps up a face at a
// time: true when it equals, as a set of faces, the live tetrahedra's found
// afresh (the faces of exactly one live tetrahedron). Allocates: for tests
// and the removal study, not for a step.
bool tx_fem_hull_is_live_boundary(const tx_fem* b);

// the state (positions, velocities) kept aside, and brought back
void tx_fem_save(tx_fem* b);
void tx_fem_restore(tx_fem* b);

int tx_fem_node_count(const tx_fem* b);
double tx_fem_added_mass(const tx_fem* b);  // mass scaling's added mass over the true mass (0 without)
double tx_fem_dt(const tx_fem* b);          // s, the step in use
double tx_fem_plate_force(const tx_fem* b); // N, upward on the plate or ball, averaged over the last tx_fem_step's steps
double tx_fem_kinetic(const tx_fem* b);     // J
int tx_fem_plate_contacts(const tx_fem* b); // nodes on the plate or ball
void tx_fem_positions(const tx_fem* b, double* out);  // (nv x 3), m

#ifdef __cplusplus
}
#endif

#endif
