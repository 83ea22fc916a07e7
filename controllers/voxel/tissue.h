// Internal: agent-based spherical voxel tissue (the voxel needle-insertion
// paper, sections 2-4).
//
// A block of spherical voxels on a regular lattice. Each voxel keeps its
// mass, initial and current velocity, elasticity, radius, initial (rest) and
// current position, id and damage. One step of length dt:
//
//   1. Know-Your-Neighbour: each voxel keeps a list of the voxels within
//      reach (contact distance plus a skin), on both voxels' lists. A voxel
//      searches again, alone, through a uniform grid of linked cells (27
//      cells around its own), when it may have moved more than a quarter of
//      the skin since its own last search, counting the motion predicted over
//      this frame; so a block mostly at rest costs nothing to keep listed,
//      and no pair can come into contact without being on the lists.
//   2. Sphere-sphere collision over the frame along straight paths (eq. 2):
//      the time of impact is the smaller root of the quadratic (eq. 3), and
//      pairs whose roots cannot both be positive are culled by the signs of
//      their product and sum (Vieta, eq. 4) before any square root. A hit
//      changes both velocities by eq. 5 with elastic coefficient e; pairs
//      already overlapping and closing are answered at t = 0.
//   3. The parallel spring-damper to the rest position, f = -k_s x - k_d v
//      (eqs. 6, 7), integrated exactly over dt, so any k_s, k_d, mass and dt
//      are stable and a critically damped voxel never overshoots.
//   A step in which some voxel would cross more than an eighth of the skin
//   is split into equal substeps (at most 256), so the lists stay valid.
//   Only awake voxels (displaced or moving) cost anything in 1 to 3: a voxel
//   back within a millionth of its radius of rest, and slow, is put exactly
//   at rest and sleeps until a contact, a tool or a caller moves it.
//   4. Damage recovery: a damaged voxel's radius grows back linearly to its
//      rest radius within recovery_time.
//
//     tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
//     d.count[0] = d.count[1] = d.count[2] = 20;
//     tx_voxel_tissue t;
//     if (!tx_voxel_tissue_init(&t, &d)) puts(tx_error());
//     tx_voxel_tissue_damage(&t, 42, 1.0);  // a needle touched voxel 42
//     tx_voxel_tissue_step(&t, 1e-3);
//     tx_voxel_tissue_fini(&t);
//
// Init allocates everything; step, damage and reset never allocate. Callers
// may write pos, vel and mass between steps, and then wake the voxels they
// wrote (tx_voxel_tissue_wake); the lists follow on the next step. A step
// costs in proportion to the awake voxels, not to the block.
#ifndef TX_CONTROLLERS_VOXEL_TISSUE_H
#define TX_CONTROLLERS_VOXEL_TISSUE_H

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_voxel_tissue_def {
  double block_size[3]; // m, edge lengths of the block along x, y, z; 5e-3: the paper's 5 x 5 x 5 mm sample
  double origin[3];     // m, the block's minimum corner; 0
  int count[3];         // voxels along x, y, z; 10: 1000 voxels, the paper's real-time size
  double mass;          // kg per voxel; 1.25e-7: water density times a 0.5 mm cube
  double elasticity;    // 1, e in eq. 5, in [0, 1]; 0.5
  double spring;        // N/m, k_s of eq. 6; 0.05: a 100 Hz rest oscillation at the default mass
  double damper;        // N s/m, k_d of eq. 7; 1e-4: damping ratio about 0.63 at the default mass
  double radius;        // m, rest radius of every voxel; 0.25e-3: half the default spacing, neighbours touch
  double damage_shrink; // 1, fraction of the radius lost at full damage, in [0, 1); 0.5
  double recovery_time; // s, Delta t for a fully damaged voxel to regain its radius; 0.5
  double skin;          // m, reach of the neighbour lists beyond contact; 0.1e-3: rebuilds are rare at rest
  int max_neighbours;   // capacity of each voxel's neighbour list; 32: a compressed lattice has at most ~26
} tx_voxel_tissue_def;

typedef struct tx_voxel_tissue {
  tx_voxel_tissue_def def; // as given to init
  int n;                   // voxel count

  // the voxels (section 2), structure of arrays
  int32_t* id;        // (n) identification, equal to the index
  double* mass;       // (n) kg
  double* elasticity; // (n) 1, e of eq. 5; a pair uses the mean of its two
  double* radius0;    // (n) rest radius, m
  double* radius;     // (n) current radius, m
  double* damage;     // (n) 1, in [0, 1]; 0 = intact
  double* pos0;       // (n x 3) initial (rest) position, m
  double* pos;        // (n x 3) current position, m
  double* vel0;       // (n x 3) initial velocity, m/s (zero: the block starts at rest)
  double* vel;        // (n x 3) current velocity, m/s

  // Know-Your-Neighbour (section 3)
  int32_t* nbr;       // (n x max_neighbours) each voxel's neighbours, by id
  int32_t* nbr_count; // (n) entries used in each list
  double* pos_built;  // (n x 3) each voxel's position at its last search, m
  double reach;       // m, list distance: 2 max radius + skin
  int grid_dims[3];   // cells along x, y, z
  double grid_lo[3];  // m, minimum corner of the grid
  double cell_size[3]; // m, cell edges, each at least reach + skin / 4
  int32_t* cell_head;  // (cells) first voxel filed in each cell, -1 for none
  int32_t* cell_next;  // (n) next voxel in the same cell, -1 at the end
  int32_t* cell_prev;  // (n) previous voxel in the same cell, -1 at the head
  int32_t* cell_of;    // (n) the cell each voxel is filed in (where it last searched)

  // damaged voxels, so that recovery costs only what is damaged
  int32_t* damaged;  // (n) ids of the voxels with damage > 0
  uint8_t* is_damaged; // (n) 1 when listed in damaged
  int n_damaged;     // entries used in damaged

  // awake voxels: those displaced or moving; the rest sit exactly at rest
  int32_t* awake_list; // (n) ids of the awake voxels
  uint8_t* is_awake;   // (n) 1 when listed in awake_list
  int n_awake;         // entries used in awake_list

  // exact spring-damper transition over the last dt for def.mass
  double phi_dt;  // s, dt the transition was computed for (0: none yet)
  double phi[4];  // row-major (x, v) map over phi_dt: (1, s; 1/s, 1)

  // counters
  uint64_t steps;        // steps taken since init or reset
  int substeps;          // frames the last step was split into (fast voxels, at most 256)
  uint64_t rebuilds;     // builds of every list at once (init, reset, tx_voxel_tissue_refresh_neighbours)
  uint64_t refreshes;    // searches of one voxel that had moved
  uint64_t pairs;        // pairs tested in the last step (all substeps)
  uint64_t culled;       // pairs the Vieta test rejected in the last step
  uint64_t contacts;     // collision responses in the last step
  uint64_t overflow;     // neighbours dropped because a list was full (lifetime)
  uint64_t faults;       // voxels found non-finite and put back at rest (lifetime)
} tx_voxel_tissue;

// the defaults above
tx_voxel_tissue_def tx_voxel_tissue_def_default(void);

// 0 when every field is finite and in range; otherwise -1 with one line in
// tx_error() naming the field, its value and the allowed range
int tx_voxel_tissue_def_check(const tx_voxel_tissue_def* def);

// checks def, allocates all storage and puts every voxel at rest on the
// lattice; on bad input or no memory returns false, leaves t unchanged and
// sets tx_error()
bool tx_voxel_tissue_init(tx_voxel_tissue* t, const tx_voxel_tissue_def* def);

// frees the storage; t may then be initialised again
void tx_voxel_tissue_fini(tx_voxel_tissue* t);

// every voxel back to rest, undamaged, counters cleared
void tx_voxel_tissue_reset(tx_voxel_tissue* t);

// advances by dt (s, finite, in (0, 1]); false (state unchanged, tx_error()
// set) otherwise
bool tx_voxel_tissue_step(tx_voxel_tissue* t, double dt);

// the most substeps a step is split into
#define TX_VOXEL_MAX_SUBSTEPS 256

// a tool's part of each substep (substep s of n, length h s), called before
// the lists are checked and the contacts found; it may move voxels, change
// their velocities and damage them
typedef void (*tx_voxel_substep_fn)(tx_voxel_tissue* t, int s, int n, double h, void* user);

// tx_voxel_tissue_step with a tool: at least min_substeps substeps (a fast
// tool asks for more), fn (may be NULL) called at the start of each
bool tx_voxel_tissue_step_with(tx_voxel_tissue* t, double dt, int min_substeps, tx_voxel_substep_fn fn, void* user);

// kinetic plus spring energy of the block, J: sum of m v^2 / 2 + k_s x^2 / 2.
// Collisions (e <= 1) and the damped springs never raise it; only a tool does
double tx_voxel_tissue_energy(const tx_voxel_tissue* t);

// adds amount (1, in (0, 1]) of damage to voxel id, clamped at full damage,
// and shrinks its radius to radius0 (1 - damage_shrink damage); false on a bad
// id or amount (state unchanged, tx_error() set)
bool tx_voxel_tissue_damage(tx_voxel_tissue* t, int id, double amount);

// rebuilds every neighbour list now
void tx_voxel_tissue_refresh_neighbours(tx_voxel_tissue* t);

// marks voxel i as moving, so that the step integrates it (a tool that
// moves a voxel calls it; the step also finds voxels moved between steps)
void tx_voxel_tissue_wake(tx_voxel_tissue* t, int i);

// voxel i searches for its neighbours again from where it is now
void tx_voxel_tissue_refresh_voxel(tx_voxel_tissue* t, int i);

// the grid cell a point is filed under (points outside go to the border cells)
int tx_voxel_tissue_cell_of_point(const tx_voxel_tissue* t, const double p[3]);

// Vieta's cull (eq. 4) for relative position p = p2 - p1 (m), relative
// velocity v = v2 - v1 (m/s) and contact distance r = r1 + r2 (m): true
// when both roots of eq. 3 are positive, the only case in which two apart
// spheres meet later. False for NaN input.
bool tx_voxel_vieta_may_collide(const double p[3], const double v[3], double r);

// time of first contact (eq. 3) in [0, dt] for the same p, v, r; true and
// *t (s) when it lies in the frame. Apart spheres only: touching or
// overlapping ones, receding ones and grazing ones (t1 = t2) give false.
bool tx_voxel_time_of_impact(const double p[3], const double v[3], double r, double dt, double* t);

#endif
