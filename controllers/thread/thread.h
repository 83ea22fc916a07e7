// Internal: the suture thread, N nodes (spheres of radius r) joined by
// cylinders of rest length l0 = length / (N - 1). Node 0 is the head: it is
// pinned where the caller puts it (the needle's swage end, or a device).
// The tail (node N - 1) is free or pinned; any other node can be pinned too.
//
//   ftl   follow-the-leader (Brown, Latombe and Montgomery 2004; the suturing
//         papers' thread): each node is put at l0 from the one ahead of it,
//         on the line to where it was. Kinematic, and every segment keeps its
//         length exactly. With pinned nodes behind the head it is FABRIK
//         (passes from the head, then back from the last pin, alternated; the
//         last pass is from the head, so lengths stay exact and a pin that
//         is out of reach is missed).
//   rod   XPBD (Macklin et al. 2016) on a mass-spring rod: a distance
//         constraint per segment of compliance l0 / (E A) (A = pi r^2: the
//         axial stiffness E A / l0), and a bending constraint per inner node
//         on the second difference d = x[i-1] - 2 x[i] + x[i+1] (3 linear
//         components; |d| = l0 theta for a small bend theta) of compliance
//         l0^3 / (E I), I = pi r^4 / 4, so that its energy E I theta^2 /
//         (2 l0) is the bending energy of an elastic rod of curvature
//         theta / l0 over a length l0. Gravity along -y, velocity damping,
//         masses from the density. After the iterations of a substep no
//         segment is longer than l0 (1 + max_stretch): a projection along the
//         thread from the head (and back from the last pin) enforces the cap.
//         Each iteration solves all the bends at once, then all the
//         distances at once (a pentadiagonal and a tridiagonal Cholesky,
//         O(N)), so a stiff rod converges in a few iterations where
//         constraint-by-constraint sweeps would need O(N^2). Near two
//         crossing strands a node takes only the part of the bends' move
//         that brings them r / 20 closer, and a substep whose bends would
//         have carried strands through each other gains no more kinetic
//         energy than the bends and gravity released (a tight knot stays
//         tied; docs/thread.md).
//
// Both models share the contacts (step 2 of the thread's issue): self
// contact between cylinders (|AB| < 2 r, segment.h) found through a
// sort and sweep of their boxes, kinematic capsules and spheres, and a triangle mesh (the skin's
// SKIN.x / SKIN.tri arrays). A step is split into substeps short enough
// that the head (and a held node) moves no more than 3 r / 4 in one. With
// capsules or a mesh, and in ftl, every node's move by its last velocity is
// bounded the same way, and a substep in which a free node still moved more
// than 0.9 r is taken again at half the length (down to dt / max_substeps).
// The rod with self contacts alone checks each substep continuously
// instead: its nodes moving in a straight line over it, no two cylinders'
// centrelines may come within half of min(r, their starting distance) (a
// bound from the pairs' relative moves); a substep that fails is taken
// again at half the length, and the next step starts from the substeps
// this one needed. So neither a fast head nor a fast node jumps across a
// contact, while a loop swinging fast as a whole takes one substep. Against
// triangles each node's move in a substep is also tested as a segment
// (continuous), so a node never crosses a triangle whatever its speed.
//
//     tx_thread_def d = tx_thread_def_default();
//     d.model = TX_THREAD_ROD;
//     tx_thread* t = tx_thread_create(&d);        // NULL and tx_error() on bad input
//     tx_thread_set_head(t, (double[3]){0, 0.01, 0});
//     tx_thread_step(t, 0.001);
//     tx_thread_positions(t, x);                  // (N x 3) m
//     tx_thread_destroy(t);
//
// Create allocates everything; step and the getters never allocate. One
// thread of execution at a time per thread.
#ifndef TX_CONTROLLERS_THREAD_THREAD_H
#define TX_CONTROLLERS_THREAD_THREAD_H

#include <stdbool.h>
#include <stdint.h>

#define TX_THREAD_MAX_MESHES 8 // rigid meshes at most

typedef enum tx_thread_model {
  TX_THREAD_FTL = 0, // follow-the-leader, kinematic
  TX_THREAD_ROD = 1, // XPBD rod
} tx_thread_model;

typedef struct tx_thread_def {
  int nodes;             // N, in [2, 100000]; 64
  double radius;         // m, r, in (0, 0.01]; 0.00025 (a 0.5 mm thread)
  double length;         // m, rest length head to tail, in (0, 10]; 0.2
  tx_thread_model model; // TX_THREAD_FTL or TX_THREAD_ROD; TX_THREAD_FTL
  double head[3];        // m, the head at creation, each in [-10, 10]; 0
  double direction[3];   // the thread lies straight from the head this way at creation (normalised); (1, 0, 0)
  bool pin_tail;         // the tail stays where it was created (or tx_thread_pin puts it); false
  bool self_collision;   // cylinders of the thread push each other apart; true
  bool slack;            // ftl: a node follows only when pulled, so a segment may be shorter than
                         // l0, never longer (a string on a table); false: every segment at l0
  double youngs_modulus; // Pa, E, in (0, 1e16]; 2e9 (monofilament nylon, 2 GPa; the top is x5e6, for stability studies)
  double bend_factor;    // the bending stiffness is bend_factor E I, in [0, 1]; 1 (0: a perfectly flexible
                         // thread, the catenary's chain; braided threads bend more easily than their E says)
  double density;        // kg/m^3, in (0, 1e5]; 1140 (nylon)
  double gravity;        // m/s^2, along -y, in [0, 100]; 9.81
  double damping;        // 1/s, decay rate of node velocities, in [0, 1e4]; 1
  int iterations;        // rod: direct XPBD solves per substep; ftl with pins: FABRIK passes; in [1, 1000]; 2
  double max_substep;    // s, the step is split into substeps no longer than this, in [1e-7, 0.1]; 1e-3
  int max_substeps;      // at most this many substeps per step, in [1, 10000]; 64
  double max_stretch;    // the stretch cap: (l - l0) / l0 of a segment, in [0, 1]; 0.05
  int max_shapes;        // room for capsules and spheres, in [0, 4096]; 16
  int max_triangles;     // room for mesh triangles, in [0, 10000000]; 0: no mesh
  int max_meshes;        // rigid meshes (tx_thread_set_rigid_mesh), in [0, TX_THREAD_MAX_MESHES]; 0
  int max_mesh_triangles; // room for each rigid mesh's triangles, in [0, 10000000]; 0
  int max_punctures;     // room for puncture points, in [0, 1024]; 16
  double puncture_friction; // N, in [0, 100]: the force along the thread a puncture holds it with
                            // before it slides (and drags with while sliding); 0
  double puncture_capture;  // m, in (0, 0.1]: the head has passed a puncture once the thread behind
                            // it (not the head's end) comes this near it; 0.001
  double self_friction;   // rod: Coulomb coefficient of the thread's contacts with itself, in [0, 10]; 0
                          // (position-based: a contact's sliding across it is undone up to this times
                          // the depth pushed out in that solve)
} tx_thread_def;

// a kinematic capsule: the points within radius of segment a b (a sphere when a == b)
typedef struct tx_thread_capsule {
  double a[3], b[3]; // m
  double radius;     // m
} tx_thread_capsule;

typedef struct tx_thread tx_thread;

typedef enum tx_thread_status {
  TX_THREAD_OK = 0,    // stepped
  TX_THREAD_FAULT = 1, // a node went non-finite: put back to the state before the step
  TX_THREAD_BAD = 2,   // bad argument: nothing done, tx_error() set
} tx_thread_status;

// the defaults above
tx_thread_def tx_thread_def_default(void);

// 0 when every field is finite and in range; otherwise -1, and tx_error()
// names the field, its value and the range
int tx_thread_def_check(const tx_thread_def* def);

// the thread straight from def.head along def.direction, at rest; NULL (and
// tx_error()) on bad input or no memory
tx_thread* tx_thread_create(const tx_thread_def* def);
void tx_thread_destroy(tx_thread* t);

const tx_thread_def* tx_thread_get_def(const tx_thread* t);
double tx_thread_rest_segment(const tx_thread* t); // l0, m

// the head's target: the next step moves it in a straight line from where it
// was to here (each coordinate finite, in [-10, 10] m)
tx_thread_status tx_thread_set_head(tx_thread* t, const double pos[3]);
// pins node i (0 < i < N) at pos; tx_thread_unpin frees it (not the head)
tx_thread_status tx_thread_pin(tx_thread* t, int i, const double pos[3]);
tx_thread_status tx_thread_unpin(tx_thread* t, int i);
// grasping: node i (0 < i < N) held by jaws at pos (each coordinate
// finite, in [-10, 10] m). The first call holds it where it is; each call
// sets where the next step takes it, in a straight line over the step's
// substeps (as the head), so a step holds it at pos. A held node is pinned:
// in the rod it has no inverse mass (the constraints pull on the jaws, not
// it); in ftl it is where it is held,
// exactly, the thread behind it (towards the tail) follows it, and the part
// between the head and it is solved from both ends (passes from the head
// and back from it, the last from the head). tx_thread_release lets it go
// (a node pinned before the grasp stays pinned); tx_thread_pin and
// tx_thread_unpin end a hold too.
tx_thread_status tx_thread_hold(tx_thread* t, int i, const double pos[3]);
tx_thread_status tx_thread_release(tx_thread* t, int i);
bool tx_thread_is_held(const tx_thread* t, int i);
// puts every node at x (N x 3, m) at rest (zero velocity); the head and the
// pins move there too. For reference shapes and tests.
tx_thread_status tx_thread_set_positions(tx_thread* t, const double* x);

// the rigid shapes for the next steps (copied; n in [0, max_shapes])
tx_thread_status tx_thread_set_capsules(tx_thread* t, const tx_thread_capsule* caps, int n);
// the triangle mesh for the next steps: x (nx x 3) and tri (ntri x 3) as the
// skin's SKIN.x (tx_vertex) and SKIN.tri (tx_triangle) rows. Both arrays are
// read during tx_thread_step and must stay valid until the next call; the
// BVH is rebuilt when the triangles change and refitted otherwise. thickness
// (m, in [0, 0.02]): the surface's collision thickness. ntri = 0 removes it.
tx_thread_status tx_thread_set_mesh(tx_thread* t, const float* x, uint32_t nx, const int32_t* tri, uint32_t ntri,
                                    double thickness);

// rigid mesh k (k in [0, max_meshes)) for the next steps: x (nx x 3) and
// tri (ntri x 3) as tx_vertex and tx_triangle rows (an instrument's or an
// organ's surface, kinematic: it moves between steps), read during
// tx_thread_step as the skin's. The thread keeps r off its triangles, with
// the skin's contacts (continuous for the nodes, the edges kept on their
// side) and no thickness; no puncture and no knot fixing. ntri = 0 removes it.
tx_thread_status tx_thread_set_rigid_mesh(tx_thread* t, int k, const float* x, uint32_t nx, const int32_t* tri,
                                          uint32_t ntri);

// cutting: severs link seg (node seg to seg + 1, in [0, N - 2]). The piece
// that holds the head stays on it; the piece behind the cut has a free end
// there (rod: it falls and moves on its own; ftl: it stays where it lies, a
// chain that follows its cut end, which nothing pulls). A severed link has
// no distance, no bend across it and no contacts; the two new ends carry
// half a link's mass less. Returns 1 when cut now, 0 when it was already
// cut, -1 (tx_error()) when seg is out of range. Never allocates.
int tx_thread_cut(tx_thread* t, int seg);
// the link (not severed) nearest p, m, and its point nearest p in at (may be
// NULL); -1 when every link is severed
int tx_thread_nearest_link(const tx_thread* t, const double p[3], double at[3]);
// per link (N - 1 entries): 1 when it was cut
const uint8_t* tx_thread_severed(const tx_thread* t);
int tx_thread_cut_count(const tx_thread* t); // links severed so far
// the head's piece is nodes 0..this (N - 1 when uncut): its lowest cut link
int tx_thread_head_piece_end(const tx_thread* t);

// punctures: the points (n x 3, m, in order) the thread passes through,
// for the next steps (copied; n in [0, max_punctures]). Once the head has
// gone through point k (after points 0..k-1: the thread behind the head,
// not its end, within puncture_capture of it), the thread runs through it:
// it slides through and never leaves it sideways (a free tail can be pulled
// out through it: tx_thread_punctures_out) (ftl: the link that holds it is put
// through it; rod: a sliding constraint on the polyline that sticks until
// the thread's two sides are stretched apart by more than puncture_friction
// / E A and half max_stretch, then slides; a link on a pinned node turns
// about it through the point, without friction). The
// skin's contacts are left out near a passed puncture. Points move between
// steps (a skin that moves); a shorter list forgets those past its end.
// side (n, or NULL: not said): which way the needle went through each (+1:
// in, -1: out, 0: not said; tx_puncture's side): the strand from an entry
// to the exit passed after it is a bite, inside the tissue, and has no skin
// contact either (the sheet is the skin's mid-surface, not a floor it runs under)
tx_thread_status tx_thread_set_punctures(tx_thread* t, const double* p, const double* side, int n);
int tx_thread_punctures_passed(const tx_thread* t); // how many the head has passed (the thread runs through those after the first tx_thread_punctures_out)
// the material coordinate (m from the head, at rest) of the thread's point
// at passed puncture k; -1 when k is not passed or pulled out of. It grows as the thread is pulled through.
double tx_thread_puncture_arc(const tx_thread* t, int k);
// the passed punctures the thread slid on through in the last step (a
// puncture it was pulled out of in it counts)
int tx_thread_punctures_slid(const tx_thread* t);
// the first this many passed punctures the thread was pulled out of: its
// free tail drawn through to its end, it runs through them no more (their
// arcs -1, no load on the skin there)
int tx_thread_punctures_out(const tx_thread* t);

// advances by dt (s, in (0, 1])
// changes the model from the next step on, the nodes where they are and at
// rest (e.g. a knot formed in ftl and pulled tight as a rod); TX_THREAD_BAD
// on an unknown model
tx_thread_status tx_thread_set_model(tx_thread* t, tx_thread_model model);
tx_thread_status tx_thread_step(tx_thread* t, double dt);

int tx_thread_node_count(const tx_thread* t);
// out: (N x 3) positions, m
void tx_thread_positions(const tx_thread* t, double* out);
const double* tx_thread_position(const tx_thread* t, int i); // node i, m
// the sum of the segment lengths (severed links left out), m
double tx_thread_current_length(const tx_thread* t);
// the largest (l - l0) / l0 over the segments (severed links left out)
double tx_thread_max_strain(const tx_thread* t);

// a knot's fixing: when a node of cylinders first..last (a knot's, from
// the knot rules) is within limit (m, in [0, 1]) of the mesh, those
// cylinders' nodes are pinned where they are (immobilised) and it returns 1;
// 0 when none is that near (or there is no mesh); -1 (tx_error()) on a bad range
int tx_thread_fix_near_mesh(tx_thread* t, int first, int last, double limit);

// contacts of the last step
typedef struct tx_thread_contacts {
  int self_pairs;  // cylinder pairs closer than 2 r (found and pushed apart)
  int shape_hits;  // node or cylinder contacts with capsules
  int mesh_hits;   // node contacts with triangles
  int substeps;    // substeps the step took
  int broad_pairs; // cylinder pairs the broadphase proposed (the broadphase's work)
  int retries;     // substeps taken again shorter because a node moved more than r
} tx_thread_contacts;
void tx_thread_last_contacts(const tx_thread* t, tx_thread_contacts* out);
// per cylinder (N - 1 entries): 1 when it touched another cylinder of the
// thread in the last step (the input of the knot rules)
const uint8_t* tx_thread_colliding(const tx_thread* t);
// rod: the force (N) the constraints put on the head in the last substep,
// the distance's pull and the first bend's (zero in ftl)
void tx_thread_head_force(const tx_thread* t, double out[3]);
// the tension at the head as a force model (step B of the conference
// paper): ftl: (length - rest length) x stiffness (N/m) of the head's piece
// (the whole thread when uncut) along the sum of its segments (from the head
// towards its end), the length running on from the tail to its pin when the
// tail is pinned and the thread uncut, K = -stiffness d d^T, plus
// puncture_friction for each puncture it slid through in the last step,
// towards the first; rod: the
// constraints' force on the head (tx_thread_head_force) plus the same
// friction, K = 0. f (N) is
// clamped to max_force (N) and never NaN.
void tx_thread_tension(const tx_thread* t, double stiffness, double max_force, double f[3], double K[9]);
// the force (N) of the thread on the skin at each passed puncture k, into
// f[3k..3k+2], and its stiffness (N/m) into k_out[k]: the thread's tension T
// pulls the point along it both ways, T (u_head + u_tail), u the unit
// vectors from the point to the thread's first nodes at least one and a half
// links away on either side. T is the tension the hand feels (the magnitude
// of tx_thread_tension's force with the same stiffness and clamp), the same
// all along as through frictionless punctures. The pull falls as the point
// moves along it by the strand's stiffness (ftl: stiffness; rod: E A over the
// head's piece) times |u_head + u_tail|^2. A puncture on a piece the head no
// longer pulls (past a cut), or with no thread beyond it towards the tail
// (its end has slid out), loads nothing. Returns the number of passed punctures.
int tx_thread_puncture_loads(const tx_thread* t, double stiffness, double max_force, double* f, double* k_out);
// where node i is pinned: false when it is free
bool tx_thread_pin_of(const tx_thread* t, int i, double out[3]);
// steps that faulted and were put back
int tx_thread_faults(const tx_thread* t);

#endif
