// Internal: the skin patch as a Bullet soft body, behind a C interface.
//
// A rectangular patch in the plane y = center[1] (Y up), res[0] x res[1]
// particles on a regular grid, each cell split into two triangles along an
// alternating diagonal. The links are the springs of the suturing conference
// paper's eq. 1: stretch links along x and z, shear links along both
// diagonals of a cell (8 neighbours for an inner particle, the paper's
// Fig. 2) and bending links two spacings long along x and z. Bullet's
// btSoftBody holds the particles and links; this adapter integrates them.
//
//   solver     implicit (the default): backward Euler on the links, a few
//              Newton steps a substep, each a linear solve by block-Jacobi
//              preconditioned conjugate gradients, matrix-free over the links
//              and warm-started; the SPD part of each link's Hessian (its
//              transverse term clamped at zero under compression). The
//              particles the HIP contact moved are held along the contact's
//              normal in the solve (a Baraff-Witkin filter), and let go where
//              holding them would pull. A link's tension is k (l - l0) at the
//              end of the substep. Or
//              XPBD (Macklin et al. 2016): each link is a distance constraint
//              of compliance 1/k with a Lagrange multiplier accumulated over
//              the iterations of a substep, so the cloth tends to implicit
//              Euler with the true k as iterations grow and substeps shrink
//              (a per-iteration stiffness, as Bullet's own solver has, tends
//              to a rigid link instead). A link's tension is its multiplier
//              over the substep squared. The lattice is a membrane of 2D
//              moduli C11 = 2k + 4 k_bend, C12 = C66 = k (docs/skin.md)
//   pretension the links' rest lengths are shortened so that the flat patch
//              at rest holds an isotropic tension (N/m) against its clamp
//   clamp      the border ring (fixed_border) and, with clamp_radius > 0,
//              every particle at or beyond that distance from the centre
//   load       an external force per particle (tx_cloth_set_load)
//   spring     a zero-length spring per particle to an anchor (tx_cloth_set_spring)
//   pin        grasped particles (tx_cloth_pin): kinematic, moved where the
//              jaws put them across a step, until unpinned
//   rupture    the membrane tension, the largest principal value of the
//              link stresses averaged over a disc of radius rupture_length
//              (a smooth kernel), breaks the most tensed stretch or shear
//              link at a particle where it passes rupture_tension (N/m): a
//              criterion in physical units that does not depend on the
//              spacing. With blunt_rupture_tension set, that holds only
//              within the HIP's reach (a needle's tip cuts), and the skin
//              elsewhere tears at blunt_rupture_tension (a thread's pull). With gravity the tension each link holds once the
//              patch hangs (settle_time) is not counted: the weight alone
//              never tears it. A broken link leaves Bullet, the triangles it
//              bordered (the two of its cell for a diagonal) leave the mesh,
//              so a hole opens; bending links across it go too
//   HIP        a kinematic sphere (the haptic interaction point). Its contact
//              is a point-triangle constraint against every live triangle:
//              the closest point of a triangle within radius + thickness / 2
//              of the centre is projected out to that distance, moving the
//              triangle's three particles by their barycentric weights
//              (inverse mass weighted), before and after each substep's
//              link solve. Bullet's own node-vs-rigid contact tests
//              particles only, and a 0.5 mm sphere slips between particles
//              2.5 mm apart; the face test cannot. A fast HIP is swept in
//              moves of at most half the contact distance, and the side it
//              came from decides which way a triangle is pushed, so it never
//              tunnels through an intact skin.
//   faults     after every substep every particle must be finite, slower than
//              max_speed and within 10 m of the patch (a kinetic energy
//              bound per particle); otherwise the whole patch, its torn
//              links included, goes back to the state after the last good
//              step and the step reports TX_CLOTH_FAULT; the HIP starts the
//              next step where it now is, so the faulty move is not replayed
//
//     tx_cloth_def d = tx_cloth_def_default();
//     tx_cloth* c = tx_cloth_create(&d);          // NULL and tx_error() on bad input
//     tx_cloth_set_hip(c, (double[3]){0, 0.01, 0}, 0.0005);
//     if (tx_cloth_step(c, 1.0 / 60) == TX_CLOTH_FAULT) { ... count a warning ... }
//     tx_cloth_positions(c, x);                    // (n x 3) floats, m
//     int m = tx_cloth_triangles(c, tri);          // live triangles only
//     tx_cloth_destroy(c);
//
// Create allocates everything; step, the getters and the HIP calls never
// allocate. One thread at a time per cloth.
#ifndef TX_CONTROLLERS_PHYSICS_BULLET_CLOTH_H
#define TX_CONTROLLERS_PHYSICS_BULLET_CLOTH_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum tx_cloth_solver {
  TX_CLOTH_IMPLICIT = 0, // backward Euler, Newton and preconditioned CG: the real-time default
  TX_CLOTH_XPBD = 1,     // XPBD: converges only with k w h^2 under about 1 (the refinement path)
} tx_cloth_solver;

typedef enum tx_cloth_reading {
  TX_CLOTH_BALANCE = 0, // implicit: the patch's momentum balance (the default)
  TX_CLOTH_HELD = 1,    // the held particles' own imbalance (XPBD always reads this)
} tx_cloth_reading;

typedef struct tx_cloth_def {
  double size[2];           // m, edge lengths along x and z; 0.1 (the papers' 10 x 10 cm patch)
  int res[2];               // particles along x and z, in [2, 1024]; 42 (0.25 cm spacing: 1764 particles)
  double center[3];         // m, centre of the patch; 0 (mid-plane y = 0)
  double thickness;         // m, in [0, 0.02]; 0.004 (the papers' 0.4 cm); only the contact uses it
  double mass;              // kg, the whole patch, spread evenly; 0.044 (10 x 10 x 0.4 cm at 1100 kg/m^3)
  double stretch_stiffness; // N/m, k of eq. 1 for stretch and shear links, in (0, 1e9]; 2000 (E t along x
                            // and z is C11 - C12^2 / C11, C11 = 2 k + 4 k_bend, C12 = k: 3100 N/m, E = 0.77 MPa
                            // at 4 mm; docs/skin.md)
  double bend_stiffness;    // N/m, k of the bending links, in [0, 1e9]; 20
  double damping;           // 1/s, decay rate of particle velocities (b of eq. 1 per unit mass), in [0, 1e4]; 5
  double gravity;           // m/s^2, along -y, in [0, 100]; 0 (9.81 with gravity on)
  bool fixed_border;        // the outer ring of particles cannot move; true
  double clamp_radius;      // m, particles this far or further from the centre (in the plane) cannot move
                            // either, in [0, 10]; 0: none (a circular membrane inside the square)
  double pretension;        // N/m, isotropic tension of the flat patch at rest, in [0, (3 k + 4 k_bend) / 2]; 0
  double rupture_tension;   // N/m, membrane tension that tears, in [0, 1e7]; 80; 0: never, anywhere. With
                            // blunt_rupture_tension, only within the HIP's reach (the tip cuts)
  double blunt_rupture_tension; // N/m, the same away from the HIP (a thread or jaws only pull), in [0, 1e7];
                                // 0: rupture_tension everywhere
  double rupture_length;    // m, radius over which the tension is averaged, in [1e-4, 0.05]; 0.002
  int solver;               // tx_cloth_solver; TX_CLOTH_IMPLICIT
  int iterations;           // XPBD iterations per substep, in [1, 200]; 1
  int newton_steps;         // implicit: most Newton steps per substep, in [1, 20]; 2 (they stop once the
                            // gradient is a tenth of the first's)
  int cg_iterations;        // implicit: most conjugate-gradient iterations per Newton step, in [1, 10000]; 100
  double cg_tolerance;      // implicit: the CG stops at this residual over the right-hand side's, in [1e-12, 1]; 1e-2
  int coarse_block;         // implicit: 0, the CG preconditioned by block Jacobi; else, plus a coarse level of one
                            // particle per coarse_block x coarse_block block (two-level), in [2, 64]; 0
  double max_substep;       // s, a step is split into substeps of at most this, in [1e-6, 0.1]; 1/60
  double max_speed;         // m/s, a faster particle is a blow-up, in (0, 1e4]; 100
  double settle_time;       // s, with gravity the patch first hangs this long without rupture, in [0, 10]; 1
  int reading;              // tx_cloth_reading, how the implicit solver reads the force on the HIP; TX_CLOTH_BALANCE
} tx_cloth_def;

typedef struct tx_cloth tx_cloth;

typedef enum tx_cloth_status {
  TX_CLOTH_OK = 0,    // stepped
  TX_CLOTH_FAULT = 1, // non-finite or blown up: put back to the last good state
  TX_CLOTH_BAD = 2,   // bad argument: nothing done, tx_error() set
} tx_cloth_status;

// the defaults above
tx_cloth_def tx_cloth_def_default(void);

// 0 when every field is finite and in range; otherwise -1, and tx_error()
// names the field, its value and the range
int tx_cloth_def_check(const tx_cloth_def* def);

// builds the patch at rest, flat; NULL (and tx_error()) on bad input or no memory
tx_cloth* tx_cloth_create(const tx_cloth_def* def);
void tx_cloth_destroy(tx_cloth* c);

const tx_cloth_def* tx_cloth_get_def(const tx_cloth* c);
int tx_cloth_particle_count(const tx_cloth* c);  // res[0] res[1]
int tx_cloth_triangle_count(const tx_cloth* c);  // 2 (res[0] - 1)(res[1] - 1), live or not
int tx_cloth_link_count(const tx_cloth* c);      // links in Bullet now (stretch, shear, bending)

// the HIP: centre (m) and radius (m, in [0, 0.1]; 0 removes it). The next
// step moves it in a straight line from where it was to here.
tx_cloth_status tx_cloth_set_hip(tx_cloth* c, const double pos[3], double radius);

// advances by dt (s, in (0, 1]) in ceil(dt / max_substep) substeps
tx_cloth_status tx_cloth_step(tx_cloth* c, double dt);

// out: (n x 3) positions, m; true when every one is finite (the copy checks them)
bool tx_cloth_positions(const tx_cloth* c, float* out);
// out: (triangle_count x 3) room; fills the live triangles (vertex indices,
// normals towards +y at rest) and returns how many; the list is compacted
// again only after links broke or came back
int tx_cloth_triangles(tx_cloth* c, int32_t* out);
// stretch and shear links broken so far
int tx_cloth_torn(const tx_cloth* c);
// of them, those torn beyond the HIP's reach: by a pull (a thread, jaws), not the tip
int tx_cloth_torn_pulled(const tx_cloth* c);
// force of the skin on the HIP at the end of the last step (N), along the
// contact's normal, never a pull; zero without contact. TX_CLOTH_HELD: the
// links' pull (k (l - l0) each) and the weight, less the m a, of the particles
// the contact holds. TX_CLOTH_BALANCE (implicit only): the whole patch's
// momentum balance, the links' pull on its kinematic particles (border, clamp,
// pins) less the free particles' backward Euler inertia M (x - y) / h^2
void tx_cloth_contact_force(const tx_cloth* c, double out[3]);
// the contact over the last step, what the skin's reaction on the HIP is
typedef struct tx_cloth_contact_info {
  double f[3];  // N, force of the skin on the HIP, as tx_cloth_contact_force
  double x[3];  // m, the HIP centre at the end of that step: where f holds
  double depth; // m, indentation: the largest distance from rest of a particle the contact moved in the step
  int moves;    // particle moves the contact made in the step
  int held;     // particles the contact holds at the end of the step (0: no contact)
} tx_cloth_contact_info;
void tx_cloth_contact(const tx_cloth* c, tx_cloth_contact_info* out);
// the largest strain (length - rest) / rest of a stretch or shear link now
// (the rest length is shorter than the spacing under pretension)
double tx_cloth_max_strain(const tx_cloth* c);
// an external force (N) on particle i from the next step on, until set
// again (zero removes it); TX_CLOTH_BAD for a bad index or a non-finite force
tx_cloth_status tx_cloth_set_load(tx_cloth* c, int i, const double f[3]);
// a zero-length spring of k N/m from particle i to anchor (m) from the next
// step on, until set again (k = 0 removes it): the force k (anchor - x)
// follows the particle within the step, so the implicit solver takes a
// stiff pull stably where a constant load, fixed for the whole step, would
// overshoot (XPBD adds it as a force at each substep's start, stable only
// while k h^2 / m is small); the HIP's balance reading counts it as an
// external force.
// TX_CLOTH_BAD for a bad index, k outside [0, 1e9] or a point not finite
tx_cloth_status tx_cloth_set_spring(tx_cloth* c, int i, const double anchor[3], double k);
// grasped particles (the forceps' jaws hold them): a pinned particle is
// kinematic, moved in a straight line from where it is to x (m) across the
// next step's substeps and held there until pinned again elsewhere or
// unpinned; the links, the HIP and gravity do not move it. TX_CLOTH_BAD
// (tx_error() set) for a bad index, a non-finite or far x, or a particle the
// patch holds fixed (border, clamp). Unpin gives it back its mass; false when
// it was not pinned
tx_cloth_status tx_cloth_pin(tx_cloth* c, int i, const double x[3]);
bool tx_cloth_unpin(tx_cloth* c, int i);
int tx_cloth_pinned(const tx_cloth* c); // particles pinned now
// link ids run from 0 to the count at creation (tx_cloth_link_total); a
// broken link keeps its id. Its two particles; false for a bad id
int tx_cloth_link_total(const tx_cloth* c);
bool tx_cloth_link_ends(const tx_cloth* c, int link, int32_t ends[2]);
// the link's tension over the last substep (N, > 0 stretched): implicit,
// k (l - l0) at its end; XPBD, its multiplier / substep^2, the force the
// solver applied; 0 once broken
double tx_cloth_link_tension(const tx_cloth* c, int link);
// the membrane tension at particle i now (N/m): the largest principal value
// of the link stresses averaged over rupture_length, as rupture sees it
// (with gravity: beyond the hanging state)
double tx_cloth_membrane_tension(const tx_cloth* c, int i);
// the largest membrane tension found by the rupture checks of the last step
// (N/m): at the particle whose own links carry the most in each substep, and
// at every particle whose links could reach rupture_tension; 0 without rupture
double tx_cloth_peak_tension(const tx_cloth* c);
// whether the last step tore a link within the HIP's reach (a tear by a pull
// elsewhere, tx_cloth_torn_pulled, does not count); if so, at = the HIP
// centre where the rupture criterion was first met in it: between the
// substep before the tear and the tear's, linear in the peak membrane
// tension of their checks
bool tx_cloth_broke_at(const tx_cloth* c, double at[3]);
// faults found and recovered so far
int tx_cloth_faults(const tx_cloth* c);
// A cut through the skin (a wound, made before a run): every stretch and
// shear link whose particles at rest lie on either side of the segment a-b
// (in x-z, Y up) goes, with the triangles it borders and the bending links
// across it, as a tear would take them, but not counted as torn. Returns the
// links cut (0: the segment crosses none)
int tx_cloth_cut(tx_cloth* c, const double a[3], const double b[3]);
// A particle gone (boiled away by a cautery): every stretch, shear and
// bending link at particle i goes, with the triangles they border, as
// tx_cloth_cut takes them (not counted as torn), and the particle is frozen
// where it is as a freed one (tx_cloth_freed; not counted as a piece).
// Returns the links removed (0: a bad index, or none left)
int tx_cloth_remove_particle(tx_cloth* c, int i);
// the pierce: a link torn where the HIP holds the skin is its puncture; from
// then on the contact ignores the hole's rim (the particles then within the
// contact distance plus two of the longest links of the HIP) and the skin
// does not push the HIP, until it is clear of the rim: no rim triangle within
// the contact distance, and beyond the rim's radius from where it went
// through or back out on the side it came from. Whether the HIP is pierced
// now, and the pierces so far
bool tx_cloth_pierced(const tx_cloth* c);
int tx_cloth_pierces(const tx_cloth* c);
// pieces cut off by tears (no path of links to a fixed or pinned particle)
// are freed: frozen where they were cut off, without links or triangles,
// their indices kept. Whether particle i is freed; the particles and the
// pieces freed so far. A patch without a fixed particle frees nothing
bool tx_cloth_freed(const tx_cloth* c, int i);
int tx_cloth_freed_count(const tx_cloth* c);
int tx_cloth_pieces_freed(const tx_cloth* c);
// implicit solver, the last step: CG iterations summed over its Newton steps and
// substeps, and the largest relative residual a Newton step ended with (0: XPBD)
typedef struct tx_cloth_solve_info {
  int cg_iterations;
  double residual;
  int released; // held particles let go because holding them would pull
  int newton;   // Newton steps taken
} tx_cloth_solve_info;
void tx_cloth_solve_stats(const tx_cloth* c, tx_cloth_solve_info* out);
// the substep (s) at which k w h^2 = kwh2 for links of stiffness k (N/m) between
// particles of mass m (kg), w = 2 / m: XPBD reaches the links' true stiffness for
// kwh2 up to about 1/4 with a few iterations (docs/skin.md)
double tx_cloth_converged_substep(double stiffness, double particle_mass, double kwh2);

// the state after the last good step: saved by every good step, and put
// back by a fault or by restore
void tx_cloth_save(tx_cloth* c);
void tx_cloth_restore(tx_cloth* c);

// overwrite one particle's position (m) and velocity (m/s), unchecked, so
// tests can inject a fault; false for a bad index
bool tx_cloth_poke(tx_cloth* c, int i, const double x[3], const double v[3]);
// one particle's position (m) as doubles, for tests; NaN for a bad index
void tx_cloth_particle(const tx_cloth* c, int i, double out[3]);

#ifdef __cplusplus
}
#endif
#endif
