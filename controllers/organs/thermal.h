// Internal: heat in a tetrahedral organ (docs/lagb.md, "Cautery"). A
// temperature field T (K) on the nodes of linear tetrahedra, Pennes' bioheat
// equation
//   rho c dT/dt = div(k grad T) - w_b rho_b c_b (T - T_a) + Q
// with a lumped (diagonal) mass and explicit Euler steps: on the organs'
// meshes the stable step is seconds (diffusion is slow: k / (rho c) is about
// 1.4e-7 m^2/s), far above a 100 Hz step, so no solve is needed; a step
// longer than the bound is split into substeps within it. Thermal damage
// Omega = integral of A exp(-Ea / (R T)) dt (Arrhenius) per node. Needs no
// optional library. Nothing here allocates after tx_thermal_create.
#ifndef TX_CONTROLLERS_ORGANS_THERMAL_H
#define TX_CONTROLLERS_ORGANS_THERMAL_H

#include <stdbool.h>

#define TX_GAS_CONSTANT 8.314462618 // J/(mol K)
#define TX_BODY_TEMPERATURE_K 310.15
#define TX_VAPORISATION_K 373.15

// a tissue's thermal properties; perfusion is the Pennes coefficient
// w_b rho_b c_b, W/(m^3 K) (tx_perfusion_coefficient)
typedef struct tx_tissue {
  double k;          // W/(m K)
  double rho;        // kg/m^3
  double c;          // J/(kg K)
  double perfusion;  // W/(m^3 K)
  double t_arterial; // K, the blood's and the tissue's at rest
} tx_tissue;

// w_b rho_b c_b from a perfusion in ml of blood per minute and kg of tissue
// (the IT'IS database's "heat transfer rate") and the tissue's density; the
// blood is IT'IS's: 1050 kg/m^3, 3617 J/(kg K)
double tx_perfusion_coefficient(double ml_min_kg, double tissue_rho);

// IT'IS tissue properties database (docs/lagb.md)
tx_tissue tx_tissue_liver(void);
tx_tissue tx_tissue_stomach(void);

// Arrhenius damage rate A exp(-Ea / (R T)), 1/s
typedef struct tx_arrhenius {
  double a;  // 1/s
  double ea; // J/mol
} tx_arrhenius;
tx_arrhenius tx_arrhenius_liver(void); // A = 7.39e39 1/s, Ea = 2.577e5 J/mol
double tx_arrhenius_rate(const tx_arrhenius* d, double t_k);

typedef struct tx_thermal tx_thermal;

// x: nodes (n x 3, m), tet: (ntet x 4) node numbers; dt: the step, s. Every
// node starts at t_arterial. NULL (tx_error says why) for a degenerate or
// inverted tetrahedron, a node out of range, a bad tissue or step.
tx_thermal* tx_thermal_create(const double* x, int n, const int* tet, int ntet, const tx_tissue* t,
                              const tx_arrhenius* d, double dt);
void tx_thermal_destroy(tx_thermal* h);

// hold a node at t_arterial (a boundary far from the heat)
void tx_thermal_fix(tx_thermal* h, int node);

// the largest stable explicit step (Gershgorin's bound on the lumped
// system's largest eigenvalue, times 0.9), s; the substeps of one step
double tx_thermal_stable_dt(const tx_thermal* h);
int tx_thermal_substeps(const tx_thermal* h);

// the heat source until the next call: power watts around c with a Gaussian
// fall-off exp(-r^2 / (2 radius^2)), weighted by the nodes' volumes and
// normalised so that the nodes get `power` in all (the whole power where
// the Gaussian is narrower than the elements). power 0: none.
void tx_thermal_source(tx_thermal* h, const double c[3], double radius, double power);

// a ceiling: no node rises above t_cap (K; 0: none). Tissue boils there
// (water's latent heat holds it): the heat past it is counted as
// tx_thermal_boiled, J, and the node as reached (tx_thermal_reached)
void tx_thermal_cap(tx_thermal* h, double t_cap);
double tx_thermal_boiled(const tx_thermal* h);
const bool* tx_thermal_reached(const tx_thermal* h); // one per node: reached the cap since the reset

// a band, K (0, the default: none): each substep steps only the nodes off
// T_a by more than band_k, those heated, and their neighbours; the rest keep
// their temperature (each within band_k of T_a, so the field is off by at
// most about band_k there) and their damage past the resting tissue's. The
// cost follows the heated region, not the organ. tx_thermal_stepped: the
// nodes the last substep stepped.
void tx_thermal_band(tx_thermal* h, double band_k);
int tx_thermal_stepped(const tx_thermal* h);

// one step dt: temperature, then damage at the substep's start temperature
void tx_thermal_step(tx_thermal* h);

// every node back to t_arterial, no damage, no source
void tx_thermal_reset(tx_thermal* h);

// tissue removed (vaporised): the tetrahedron of nodes t (4) leaves the
// solve. Its conductances, volume, heat capacity and perfusion go; a node
// in no live tetrahedron any more takes no heat and holds T_a; the substeps
// grow if a node's stable step shrank. false (nothing changes): a node out
// of range or already out, a flat tetrahedron. No allocation.
bool tx_thermal_remove(tx_thermal* h, const int t[4]);
bool tx_thermal_node_live(const tx_thermal* h, int node);
const double* tx_thermal_positions(const tx_thermal* h); // (n x 3) m, as created

int tx_thermal_nodes(const tx_thermal* h);
const double* tx_thermal_temperature(const tx_thermal* h); // K, one per node
double* tx_thermal_temperature_mut(tx_thermal* h);         // to set an initial field
// Omega, one per node, past the resting tissue's own: add tx_thermal_damage_rest
const double* tx_thermal_damage(const tx_thermal* h);
// A exp(-Ea / (R T_a)) times the time stepped: the damage of tissue at rest
// (2.9e-4 1/s for liver at 37 C: 1 after about an hour)
double tx_thermal_damage_rest(const tx_thermal* h);
const double* tx_thermal_volume(const tx_thermal* h);      // m^3, each node's lumped share
double tx_thermal_energy(const tx_thermal* h);             // J deposited by the source so far

// the point in tetrahedron `e` nearest to p in barycentric terms: w (4) the
// weights at p (negative outside); false for a degenerate tetrahedron
bool tx_tet_barycentric(const double* x, const int* tet, int e, const double p[3], double w[4]);

// one level of regular ("red") refinement: each tetrahedron into 8, new
// nodes at the edges' midpoints (the octahedron cut along its shortest
// diagonal); the children of tetrahedron e are 8 e .. 8 e + 7, the old nodes
// keep their numbers. malloc'd *x2, *tet2; false and tx_error() on memory
bool tx_tet_refine(const double* x, int n, const int* tet, int ntet, double** x2, int* n2, int** tet2, int* ntet2);

// the tetrahedron of (x, tet) each of np points lies in, or nearest to by
// its least negative barycentric weight (a surface drawn a fraction of an
// element off the tetrahedra's hull): out_tet (np x 4) its nodes, out_w
// (np x 4) the weights, so that a nodal field f reads sum w f[tet] there
// out_e (np, may be NULL): the tetrahedron's number
void tx_thermal_embed(const double* x, const int* tet, int ntet, const float* points, int np, int* out_tet, float* out_w,
                      int* out_e);
// the same, the point's tetrahedron e of a coarser mesh known: among e's
// children in the once refined (x, tet) (tx_tet_refine); returns the child
int tx_thermal_embed_child(const double* x, const int* tet, int e, const float* point, int* out_tet, float* out_w);

// a mesh refined `levels` times (tx_tet_refine) and np points embedded in
// it (as tx_thermal_embed, in O(np (ntet + 8 levels)), not O(np ntet 8^levels)):
// malloc'd *xf, *tetf; out_tet, out_w (np x 4); false and tx_error() on memory
bool tx_thermal_refine_embed(const double* x, int n, const int* tet, int ntet, int levels, const float* points, int np,
                             double** xf, int* nf, int** tetf, int* ntetf, int* out_tet, float* out_w);

// TetGen's BASE.node (3-D, zero-based) and BASE.ele (4 nodes): malloc'd x
// (n x 3) and tet (ntet x 4); false and tx_error() (naming the file) else
bool tx_tetgen_read(const char* base, double** x, int* n, int** tet, int* ntet);

// a triangle OBJ (v and f lines; /vt/vn ignored): malloc'd x (nv x 3), tri
// (nt x 3, zero-based); false and tx_error() (naming the file) else
bool tx_obj_read(const char* path, float** x, int* nv, int** tri, int* nt);

#endif
