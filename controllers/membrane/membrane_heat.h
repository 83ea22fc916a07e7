// Internal: heat in a thin membrane (physics.membrane, docs/membrane.md):
// Pennes' bioheat equation in two dimensions on the particle grid of a
// rectangular patch (nx x nz particles, spacing s, thickness t), lumped and
// explicit:
//   C_i dT_i/dt = sum_j G_ij (T_j - T_i) - P_i (T_i - T_a) + q_i
//   C_i = rho c t A_i   (A_i: s^2 inside, s^2 / 2 on an edge, s^2 / 4 at a corner)
//   P_i = w_b rho_b c_b t A_i
//   G_ij = (k t / 2) x (live triangles beside the grid edge i-j, 0 to 2)
// The 5-point stencil of a finite-volume grid: each of the two triangles
// beside an edge holds half of the face between the particles' cells, so a
// cut or a hole stops the conduction across it, and an edge of the patch
// conducts half as much as an inner one. Damage: Omega_i = integral of
// A exp(-Ea / (R T_i)) dt (Arrhenius, thermal.h). Boiling: no particle rises
// above vaporisation_k; one that reaches it is vaporised: out of the solve
// (its edges conduct no more), published at T_a, taking no heat. The border
// ring is held at T_a (the membrane's attachment to perfused organs) or
// insulated. Needs no optional library; nothing allocates after create.
//
//     tx_membrane_heat* h = tx_membrane_heat_create(&def);
//     tx_membrane_heat_source(h, x, tip, radius, power);   // or h->q[i] = ...
//     int boiled = tx_membrane_heat_step(h, dt);           // h->boiled_now[0 .. boiled)
//     tx_membrane_heat_edges(h, tri, m);                   // after triangles left the mesh
#ifndef TX_CONTROLLERS_MEMBRANE_MEMBRANE_HEAT_H
#define TX_CONTROLLERS_MEMBRANE_MEMBRANE_HEAT_H

#include "../organs/thermal.h" // tx_tissue, tx_arrhenius

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_membrane_heat_def {
  int nx, nz;            // particles along local x and z, each in [2, 1024]
  double spacing;        // m, s
  double thickness;      // m, t
  tx_tissue tissue;      // k, rho, c, perfusion (W/(m^3 K)), t_arterial (T_a)
  tx_arrhenius damage;   // A, Ea
  double vaporisation_k; // K, above t_arterial
  bool insulated;        // the border ring: insulated (true) or held at T_a (false)
} tx_membrane_heat_def;

typedef struct tx_membrane_heat {
  tx_membrane_heat_def def;
  int n;              // particles, nx nz, row by row along x (i = ix + nx iz)
  double* t;          // (n) K
  double* omega;      // (n) Arrhenius damage integral, 1
  double* area;       // (n) m^2, A_i
  double* cap;        // (n) J/K, C_i
  double* perf;       // (n) W/K, P_i
  double* q;          // (n) W, the source over the next step (the caller's, or tx_membrane_heat_source)
  uint8_t* ex;        // ((nx - 1) nz) live triangles beside edge (ix, iz)-(ix + 1, iz)
  uint8_t* ez;        // (nx (nz - 1)) beside edge (ix, iz)-(ix, iz + 1)
  uint8_t* gone;      // (n) 1: vaporised
  uint8_t* held;      // (n) 1: held at T_a (the border, unless insulated)
  int32_t* boiled_now;// (n) the particles the last step vaporised
  double* next;       // (n) scratch: the substep's new temperatures
  double dt_max;      // s, 0.9 x the Gershgorin bound of the explicit step, all edges live
  double energy;      // J, deposited by q so far
  double boiled;      // J, carried off by boiling: the heat past the cap and the particle's own above T_a
  double peak;        // K, the hottest particle in the last step (a boiling one counts at the cap)
  int substeps;       // substeps of the last step
} tx_membrane_heat;

// NULL (tx_error says why) on bad input or no memory; every particle at
// T_a, every edge live (both triangles of a cell)
tx_membrane_heat* tx_membrane_heat_create(const tx_membrane_heat_def* def);
void tx_membrane_heat_destroy(tx_membrane_heat* h);

// the live triangles (m x 3 particle indices) set which edges conduct: an
// edge along x or z counts each live triangle that has it
void tx_membrane_heat_edges(tx_membrane_heat* h, const int32_t* tri, int m);

// whether particle i is still tissue: not vaporised and on a conducting edge
bool tx_membrane_heat_live(const tx_membrane_heat* h, int i);

// power (W) spread as exp(-r^2 / (2 radius^2)) A_i over the live particles
// around tip (r from each particle's position x, n x 3 floats, the same
// frame as tip), normalised to the whole power; zeroes q first. Returns
// the power placed (0 when no live particle has a weight)
double tx_membrane_heat_source(tx_membrane_heat* h, const float* x, const double tip[3], double radius, double power);

// advances by dt (s, > 0) in ceil(dt / dt_max) substeps with the source q;
// returns how many particles it vaporised (listed in boiled_now)
int tx_membrane_heat_step(tx_membrane_heat* h, double dt);

// J: sum of C_i (T_i - T_a) over the particles in the solve
double tx_membrane_heat_content(const tx_membrane_heat* h);
// m^2: the area of the particles whose Omega is 1 or more
double tx_membrane_heat_damaged(const tx_membrane_heat* h);

#endif
