// tactus/components.h: the layout of every component that crosses controllers.
//
// A controller that writes a component another controller reads makes its
// definition from the layout, and every reader asks for the same layout, so
// the two cannot disagree: the loader refuses a reader whose type or columns
// differ from the writer's (and, with TX_READ_EXPECT, whose units differ).
// One row of a component is one struct; a component of N rows is an array of
// N structs. Nobody indexes another controller's data by number.
//
//     // writer, in configure
//     h->pose = tx_setup_write(s, &TX_COMPONENT_OF("device0.pose", tx_pose, 1));
//     // reader, in configure
//     c->pose = TX_READ_OF(s, "device0.pose", tx_pose);
//     // step
//     const tx_pose* p = tx_read(ctx, c->pose).data;
//     tx_pose* out = tx_write(ctx, h->pose);
//
// Each layout T comes with T_TYPE (element type), T_COLS (values per row,
// checked against sizeof(T) at compile time) and T_UNITS (as the writer
// spells them). Units are SI; frames are the world's (right-handed, Y up).
#ifndef TACTUS_COMPONENTS_H
#define TACTUS_COMPONENTS_H

#include <tactus/haptics.h> // tx_force_model
#include <tactus/model.h>

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#define TX_LAYOUT_ASSERT(T, elem) static_assert(sizeof(T) == T##_COLS * sizeof(elem), #T " is " #T "_COLS values")
#else
#define TX_LAYOUT_ASSERT(T, elem) _Static_assert(sizeof(T) == T##_COLS * sizeof(elem), #T " is " #T "_COLS values")
#endif

// the definition of a component of `rows` rows of layout T, named `name`
#define TX_COMPONENT_OF(name, T, rows) ((tx_component_def){(name), T##_TYPE, (rows), T##_COLS, T##_UNITS})
// a read that the loader checks against layout T (type and columns)
#define TX_READ_OF(s, name, T) tx_setup_read_as((s), (name), T##_TYPE, T##_COLS)
// the same, and the writer's units must be T's
#define TX_READ_EXPECT(s, name, T) tx_setup_read_expect((s), (name), T##_TYPE, T##_COLS, T##_UNITS)

// --- the device and the tool -------------------------------------------------

// DEVICE.pose (1 row), written by haptics, read by collision, physics, views
typedef struct tx_pose {
  double pos[3];  // tool point, m
  double quat[4]; // orientation, unit quaternion (w, x, y, z)
} tx_pose;
#define tx_pose_TYPE TX_F64
#define tx_pose_COLS 7u
#define tx_pose_UNITS "m"
TX_LAYOUT_ASSERT(tx_pose, double);

// DEVICE.velocity (1 row), written by haptics
typedef struct tx_velocity {
  double v[3]; // linear velocity of the tool point, m/s
} tx_velocity;
#define tx_velocity_TYPE TX_F64
#define tx_velocity_COLS 3u
#define tx_velocity_UNITS "m/s"
TX_LAYOUT_ASSERT(tx_velocity, double);

// DEVICE.force (1 row), written by haptics: the force sent, after every safety stage
typedef struct tx_force {
  double f[3]; // N, on the hand
} tx_force;
#define tx_force_TYPE TX_F64
#define tx_force_COLS 3u
#define tx_force_UNITS "N"
TX_LAYOUT_ASSERT(tx_force, double);

// DEVICE.energy (1 row), written by haptics: the passivity observer
typedef struct tx_device_energy {
  double observed;   // J, energy the port has taken in (negative: it gave energy out)
  double dissipated; // J, taken out by the passivity controller's damping
} tx_device_energy;
#define tx_device_energy_TYPE TX_F64
#define tx_device_energy_COLS 2u
#define tx_device_energy_UNITS "J"
TX_LAYOUT_ASSERT(tx_device_energy, double);

// TOOL.force_model (1 row), written by collision, read by haptics; the struct
// is tx_force_model of <tactus/haptics.h>
#define tx_force_model_TYPE TX_F64
#define tx_force_model_COLS TX_FORCE_MODEL_COLS
#define tx_force_model_UNITS TX_FORCE_MODEL_UNITS
TX_LAYOUT_ASSERT(tx_force_model, double);

// --- the haptic interaction point (collision.hip) ----------------------------

// HIP.state (1 row), written by collision.hip, read by view.force_curve
typedef struct tx_hip_state {
  double contacts; // rays in contact this step (a count)
  double pierced;  // 1 while the HIP is through the skin, else 0
  double f[3];     // N, the force of this step's query (eq. 8)
  double depth;    // m, deepest ray penetration
  double resets;   // eq. 8 updates of the anchor so far (a count)
  double skin_t;   // s, simulation time of the skin publish the query used (0: none)
} tx_hip_state;
#define tx_hip_state_TYPE TX_F64
#define tx_hip_state_COLS 8u
#define tx_hip_state_UNITS "1, N, m, s"
TX_LAYOUT_ASSERT(tx_hip_state, double);

// SKIN.contact (1 row), written by physics.skin, read by collision.hip in
// mechanics mode: the skin's reaction on the HIP, from the momentum the
// cloth solver's contact gave the particles over the last physics step, and
// how it changes with the HIP's position there, so that the collision can
// carry it at 4 kHz as F = f + K (c - x), K = -k n n^T
typedef struct tx_skin_contact {
  double f[3];     // N, force of the skin on the HIP, the mean over the last physics step
  double x[3];     // m, the HIP centre f holds at (the end of that step)
  double n[3];     // 1, unit direction of f (0 without contact)
  double k;        // N/m, tangent stiffness along n: d|f|/dw at the contact (0 without contact)
  double depth;    // m, indentation w: how far the contact pushed the skin from rest
  double touching; // 1 when the contact moved the skin in the step, else 0
  double torn;     // links torn so far (a count), as in SKIN.torn
} tx_skin_contact;
#define tx_skin_contact_TYPE TX_F64
#define tx_skin_contact_COLS 13u
#define tx_skin_contact_UNITS "N, m, 1, N/m"
TX_LAYOUT_ASSERT(tx_skin_contact, double);

// *.spheres (N rows), drawn by the graphics view: the HIP, voxels
typedef struct tx_sphere {
  float c[3]; // centre, m
  float r;    // radius, m
} tx_sphere;
#define tx_sphere_TYPE TX_F32
#define tx_sphere_COLS 4u
#define tx_sphere_UNITS "m"
TX_LAYOUT_ASSERT(tx_sphere, float);

// --- surfaces (skin) ---------------------------------------------------------

// SKIN.x (N rows), written by physics, read by collision and views
typedef struct tx_vertex {
  float x[3]; // position, m
} tx_vertex;
#define tx_vertex_TYPE TX_F32
#define tx_vertex_COLS 3u
#define tx_vertex_UNITS "m"
TX_LAYOUT_ASSERT(tx_vertex, float);

// SKIN.tri (M rows, those in use are the live triangles)
typedef struct tx_triangle {
  int32_t v[3]; // indices into SKIN.x, counter-clockwise seen from outside
} tx_triangle;
#define tx_triangle_TYPE TX_I32
#define tx_triangle_COLS 3u
#define tx_triangle_UNITS "1"
TX_LAYOUT_ASSERT(tx_triangle, int32_t);

// SKIN.thickness (1 row)
typedef struct tx_thickness {
  double m; // m, the collision thickness of the surface
} tx_thickness;
#define tx_thickness_TYPE TX_F64
#define tx_thickness_COLS 1u
#define tx_thickness_UNITS "m"
TX_LAYOUT_ASSERT(tx_thickness, double);

// SKIN.torn (1 row)
typedef struct tx_torn {
  int32_t links;   // links torn so far (a count)
  int32_t pulled;  // of them, those torn beyond the HIP's reach: by a pull (a thread, jaws), not the tip's cut
  int32_t pierces; // the HIP's pierces so far: its contact torn through, by the skin's own rule
} tx_torn;
#define tx_torn_TYPE TX_I32
#define tx_torn_COLS 3u
#define tx_torn_UNITS "1"
TX_LAYOUT_ASSERT(tx_torn, int32_t);

// SKIN.rupture (1 row): the rupture criterion over the last physics step, for
// studies that resolve where the skin tore between steps
typedef struct tx_skin_rupture {
  double tension; // N/m, the largest averaged membrane tension the step's rupture checks found
  double broke;   // 1 when a link tore in the step within the HIP's reach, else 0 (a pull's tear: skin.torn)
  double at[3];   // m, the HIP centre where the criterion was first met in the step: between the
                  // substep before the tear and the tear's, linear in the tension (0 when broke is 0)
} tx_skin_rupture;
#define tx_skin_rupture_TYPE TX_F64
#define tx_skin_rupture_COLS 5u
#define tx_skin_rupture_UNITS "N/m, 1, m"
TX_LAYOUT_ASSERT(tx_skin_rupture, double);

// --- the voxel needle (voxel.needle) -----------------------------------------

// needle.segments (1 row per segment), drawn by the graphics view
typedef struct tx_segment {
  float a[3]; // one end (the needle's base), m
  float b[3]; // the other end (the tip), m
  float r;    // radius, m
} tx_segment;
#define tx_segment_TYPE TX_F32
#define tx_segment_COLS 7u
#define tx_segment_UNITS "m"
TX_LAYOUT_ASSERT(tx_segment, float);

// needle.force (1 row): the needle force of eq. 9, and its parts
typedef struct tx_needle_force {
  double total[3];     // N, stiffness + friction + cutting
  double stiffness[3]; // N
  double friction[3];  // N
  double cutting[3];   // N
  double depth;        // m, of the tip below the tissue's surface
} tx_needle_force;
#define tx_needle_force_TYPE TX_F64
#define tx_needle_force_COLS 13u
#define tx_needle_force_UNITS "N, m"
TX_LAYOUT_ASSERT(tx_needle_force, double);

// tissue.damage (N rows, one per voxel)
typedef struct tx_damage {
  float d; // 0 intact .. 1 destroyed
} tx_damage;
#define tx_damage_TYPE TX_F32
#define tx_damage_COLS 1u
#define tx_damage_UNITS "1"
TX_LAYOUT_ASSERT(tx_damage, float);

// window.pointer (1 row), written by input.window (the window's mouse and
// keyboard), read by the haptics controller for the `mouse` device
typedef struct tx_pointer {
  double pos[3];  // m, where the input puts the tool, in [-TX_POINTER_REACH_M, TX_POINTER_REACH_M]
  double buttons; // the buttons held, one bit each (an integer below 2^32)
} tx_pointer;
#define tx_pointer_TYPE TX_F64
#define tx_pointer_COLS 4u
#define tx_pointer_UNITS "m, 1"
#define TX_POINTER_REACH_M 0.2 // m, the pointer's box on each axis
TX_LAYOUT_ASSERT(tx_pointer, double);

// --- for the coming scenarios (suture thread, instruments) -------------------

// THREAD.nodes (N rows, from the needle end): a follow-the-leader thread
typedef struct tx_thread_node {
  double x[3];   // position, m
  double radius; // m, of the thread at this node
} tx_thread_node;
#define tx_thread_node_TYPE TX_F64
#define tx_thread_node_COLS 4u
#define tx_thread_node_UNITS "m"
TX_LAYOUT_ASSERT(tx_thread_node, double);

// THREAD.cut_links (N - 1 rows, link i joins nodes i and i + 1), written by
// physics.thread: how a cut splits the thread. A severed link joins nothing
// (do not draw or collide it); the nodes on either side of it end two
// pieces. Piece 0 holds the head (the needle); each cut along the thread
// starts the next piece. THREAD.segments draws a severed link at radius 0.
typedef struct tx_thread_link {
  double severed; // 1: cut, 0: whole
  double piece;   // the piece this link belongs to: the number of cuts between it and the head
} tx_thread_link;
#define tx_thread_link_TYPE TX_F64
#define tx_thread_link_COLS 2u
#define tx_thread_link_UNITS "1"
TX_LAYOUT_ASSERT(tx_thread_link, double);

// INSTRUMENT.capsules, NEEDLE.capsules (N rows): rigid shapes the thread
// keeps out of (instrument jaws, the needle), read by physics.thread
typedef struct tx_capsule {
  double a[3], b[3]; // m, the ends of the axis (a == b: a sphere)
  double radius;     // m
} tx_capsule;
#define tx_capsule_TYPE TX_F64
#define tx_capsule_COLS 7u
#define tx_capsule_UNITS "m"
TX_LAYOUT_ASSERT(tx_capsule, double);

// INSTRUMENT.pose (1 row): a pose and the angle of its jaws
typedef struct tx_instrument_pose {
  double pos[3];  // tool point (between the jaws), m
  double quat[4]; // orientation, unit quaternion (w, x, y, z)
  double jaw;     // rad, opening angle of the jaws (0: closed)
} tx_instrument_pose;
#define tx_instrument_pose_TYPE TX_F64
#define tx_instrument_pose_COLS 8u
#define tx_instrument_pose_UNITS "m, 1, rad"
TX_LAYOUT_ASSERT(tx_instrument_pose, double);

// DEVICE.grip (1 row), written by haptics, read by physics.instruments: what
// the hand does with the instrument's handle
typedef struct tx_device_grip {
  double grip;    // rad, the gripper angle (tx_device_state.grip): the angle wanted between the jaws
  double buttons; // the device's buttons, one bit each, as a number
} tx_device_grip;
#define tx_device_grip_TYPE TX_F64
#define tx_device_grip_COLS 2u
#define tx_device_grip_UNITS "rad, 1"
TX_LAYOUT_ASSERT(tx_device_grip, double);

// NAME.punctures (N rows, in the order the needle made them), written by
// physics.instruments, read by physics.thread: where the thread must pass
// through the skin. Each point moves with its skin triangle, named by its
// three particles (rows of skin.x, which never renumber: skin.tri is packed
// and a tear renumbers the rows after it); rows past the last puncture have
// v[0] = -1.
typedef struct tx_puncture {
  double v[3];    // rows of skin.x: the pierced triangle's corners (integers); v[0] = -1: no puncture in this row
  double bary[3]; // barycentric coordinates of the point, in the order of v (they sum to 1)
  double side;    // +1: the needle entered here, -1: it came out here
} tx_puncture;
#define tx_puncture_TYPE TX_F64
#define tx_puncture_COLS 7u
#define tx_puncture_UNITS "1"
TX_LAYOUT_ASSERT(tx_puncture, double);

// THREAD.puncture_loads (max_punctures + 1 rows), written by physics.thread,
// read by physics.skin (thread_loads): the force of the thread on the skin
// at each puncture it runs through, in the puncture list's order, on the
// same triangle point; rows past the last have v[0] = -1. A tight stitch
// pulls its two punctures towards each other: the wound's edges close.
typedef struct tx_puncture_load {
  double v[3];    // rows of skin.x, as tx_puncture's (integers); v[0] = -1: none in this row
  double bary[3]; // barycentric coordinates of the point, in the order of v
  double f[3];    // N: the thread's pull on the skin there
  double k;       // N/m: how fast the pull falls as the skin there moves along it (the thread gives)
} tx_puncture_load;
#define tx_puncture_load_TYPE TX_F64
#define tx_puncture_load_COLS 10u
#define tx_puncture_load_UNITS "1, 1, N, N/m"
TX_LAYOUT_ASSERT(tx_puncture_load, double);

// physics.instruments writes, for instrument N (held by deviceN):
//   INSTRUMENT.pose (1 row, tx_instrument_pose): the root link frame (the
//     pivot of the jaws) and the angle between the jaws, rad
//   INSTRUMENT.links (one row per URDF link, root first, tx_pose): each link frame
//   INSTRUMENT.force_model (1 row, tx_force_model): the virtual coupling as the
//     hand feels it, for the haptics controller to render (docs/instruments.md)
//   INSTRUMENT.held (1 row, tx_instrument_held): which of the hand's
//     instruments (handN) it is, for a view to draw the right meshes
// and, with the needle: needle.pose, needle.swage (tx_pose: its frame, its
// swage end for the thread's head), needle.tip (tx_pose: the tip, the skin's
// HIP when physics.skin's pose names it), needle.punctures (tx_puncture) and
// needle.segments (tx_segment: the arc as chords, for a view)
typedef struct tx_instrument_held {
  double index; // in handN's list, from 0 (0 without handN)
} tx_instrument_held;
#define tx_instrument_held_TYPE TX_F64
#define tx_instrument_held_COLS 1u
#define tx_instrument_held_UNITS "1"
TX_LAYOUT_ASSERT(tx_instrument_held, double);

// --- gastric banding: the organs ---------------------------------------------

// physics.organs writes, for each soft organ ORGAN (liver, stomach), its
// surface, which collision.organ reads at up to 4 kHz:
//   ORGAN.x (N rows, tx_vertex): the surface vertices, m
//   ORGAN.tri (M rows, tx_triangle): the surface triangles, outward by the
//     right-hand rule, rows into ORGAN.x
//   ORGAN.surface_node (as many rows as ORGAN.x, tx_surface_node): the tetrahedral
//     node each row is, or -1 for a vertex of the drawn surface. An organ
//     that has lost tetrahedra (cautery's removal, docs/lagb.md) is drawn by
//     its live tetrahedra's boundary, one row a node; until then by the
//     drawn surface embedded in them, every row -1
// and, like SKIN.contact for the skin, the organs' reaction on the tool:
//   organs.contact (1 row, tx_skin_contact): force, where it holds, its
//     direction, the tangent stiffness k along it, the indentation

// PREFIX.grasp (one row per grasping hand, in the order of the controller's
// `grasp` list), written by a soft body's physics that graspers pick from
// (physics.organs: organs.grasp; controllers/organs/picking.h): what the
// picked tissue does to the jaws. Apart from organs.contact, which is the
// tool sphere's one-sided push with a stiffness along its normal: a grasp
// pulls any way, and each hand has its own.
typedef struct tx_organ_grasp {
  double f[3];      // N, the tissue's force on the jaws, averaged over the last physics step (0: holding nothing)
  double x[3];      // m, the jaws' pivot that step
  double nodes;     // nodes held
  double triangles; // surface triangles flagged as picked by these jaws
} tx_organ_grasp;
#define tx_organ_grasp_TYPE TX_F64
#define tx_organ_grasp_COLS 8u
#define tx_organ_grasp_UNITS "N, m, 1"
TX_LAYOUT_ASSERT(tx_organ_grasp, double);
typedef struct tx_surface_node {
  int32_t node; // the tetrahedral node (its number in the organ's .node file), -1: a vertex of the drawn surface
} tx_surface_node;
#define tx_surface_node_TYPE TX_I32
#define tx_surface_node_COLS 1u
#define tx_surface_node_UNITS "1"
TX_LAYOUT_ASSERT(tx_surface_node, int32_t);

// --- gastric banding: the organs' temperature (physics.cautery) --------------

// physics.cautery writes, for each soft organ ORGAN, one row per row of
// ORGAN.x (its drawn surface vertices, interpolated from the tetrahedra's
// nodes):
//   ORGAN.temperature (tx_temperature): K
//   ORGAN.damage (tx_organ_damage): the Arrhenius integral Omega (1: the
//     tissue is coagulated)
typedef struct tx_temperature {
  float t; // K
} tx_temperature;
#define tx_temperature_TYPE TX_F32
#define tx_temperature_COLS 1u
#define tx_temperature_UNITS "K"
TX_LAYOUT_ASSERT(tx_temperature, float);

typedef struct tx_organ_damage {
  float omega; // 1
} tx_organ_damage;
#define tx_organ_damage_TYPE TX_F32
#define tx_organ_damage_COLS 1u
#define tx_organ_damage_UNITS "1"
TX_LAYOUT_ASSERT(tx_organ_damage, float);

// --- gastric banding: the band (physics.band) ---------------------------------

// physics.band writes the band's two parts as one surface, for views and
// collision:
//   band.x (N rows, tx_vertex): the ring part's nodes, then the tube part's, m
//   band.tri (M rows, tx_triangle): their tetrahedra's boundary faces,
//     outward by the right-hand rule, rows into band.x
// its state:
//   band.state (1 row, tx_band_state)
// and, on the event stream band.events, TX_EVENT_LATCH when it locks.
typedef struct tx_band_state {
  double locked;        // 1: the tube's tip has latched in the buckle (it stays so), 0: not yet
  double joint_length;  // m, the distance joint's length now
  double joint_error;   // its relative error: length over the joint's length, minus 1
  double tip_to_buckle; // m, from the tube's tip to the centre of the buckle's opening
} tx_band_state;
#define tx_band_state_TYPE TX_F64
#define tx_band_state_COLS 4u
#define tx_band_state_UNITS "1"
TX_LAYOUT_ASSERT(tx_band_state, double);

// cautery.tissue (one row per organ: the liver, then the stomach), written by
// physics.cautery: the tissue its heat has damaged and boiled so far
typedef struct tx_tissue_damage {
  double damaged_m3; // m^3, the volume where the Arrhenius Omega is over 1
  double boiled_m3;  // m^3, the volume that reached the vaporisation temperature
  double peak_k;     // K, the hottest drawn vertex so far
} tx_tissue_damage;
#define tx_tissue_damage_TYPE TX_F64
#define tx_tissue_damage_COLS 3u
#define tx_tissue_damage_UNITS "m^3, m^3, K"
TX_LAYOUT_ASSERT(tx_tissue_damage, double);

// band.centre (rows), written by physics.band: the band's centre line as one
// open loop, from the ring's head (the buckle) round to its tail, then the
// tube from its head to its tip (each row the middle of a cross-section), m
// (tx_vertex rows)

// --- gastric banding: a membrane (physics.membrane) --------------------------

// physics.membrane writes a thin membrane (the pars flaccida, the
// phrenogastric ligament at the angle of His) under its own name MEMBRANE:
//   MEMBRANE.x (N rows, tx_vertex): its particles, m
//   MEMBRANE.tri (M rows, tx_triangle): its live triangles (burnt or cut ones gone)
//   MEMBRANE.temperature (N rows, tx_temperature): each particle's, K
//   MEMBRANE.state (1 row, tx_membrane_state)
typedef struct tx_membrane_state {
  double opening_m;  // m, the largest hole's longest extent across the membrane at rest; 0: intact
  double removed;    // triangles removed so far (burnt or cut)
  double burnt;      // of them, removed because a corner boiled
  double cut;        // of them, cut by the scissors
  double passes;     // times a tool passed through a hole (crossed the membrane where it is open)
  double peak_k;     // K, the hottest particle now
  double damaged_m2; // m^2, the area where the Arrhenius Omega is over 1
} tx_membrane_state;
#define tx_membrane_state_TYPE TX_F64
#define tx_membrane_state_COLS 7u
#define tx_membrane_state_UNITS "m, 1, K, m^2"
TX_LAYOUT_ASSERT(tx_membrane_state, double);

// --- the procedure ------------------------------------------------------------

// procedure.step (1 row), written by whatever runs a procedure, read by the
// window's panels (docs/trainer.md): the current step as one line of text,
// NUL-terminated, e.g. "3/7 pass the needle through the far edge"
typedef struct tx_procedure_step {
  char text[64];
} tx_procedure_step;
#define tx_procedure_step_TYPE TX_U8
#define tx_procedure_step_COLS 64u
#define tx_procedure_step_UNITS "1"
TX_LAYOUT_ASSERT(tx_procedure_step, uint8_t);

// PREFIX.steps (one row per step, in the procedure's order), written by a
// procedure controller (procedure.suture): each step's progress, read by the
// scorecard (view.scorecard) in this process or an instructor's
typedef enum tx_step_status {
  TX_STEP_NOT_REACHED = 0,
  TX_STEP_UNDER_WAY = 1,
  TX_STEP_DONE = 2,
  TX_STEP_SKIPPED = 3, // a later step was done first
} tx_step_status;
typedef struct tx_procedure_step_state {
  double status;    // a tx_step_status
  double t_start_s; // s, simulation time it began; NaN: not reached
  double t_end_s;   // s, when it was done or skipped; NaN: not yet
} tx_procedure_step_state;
#define tx_procedure_step_state_TYPE TX_F64
#define tx_procedure_step_state_COLS 3u
#define tx_procedure_step_state_UNITS "1, s, s"
TX_LAYOUT_ASSERT(tx_procedure_step_state, double);

// PREFIX.suture (1 row), written by procedure.suture: the measures of its
// scorecard (docs/suturing.md gives each one's rule and source)
typedef struct tx_suture_measures {
  double bite_entry_m;   // m, the stitch's entry from the wound line; NaN: none yet
  double bite_exit_m;    // m, its exit from the wound line, on the other edge; NaN: none yet
  double punctures;      // punctures made
  double knots;          // knots found (the papers' rule)
  double knots_fixed;    // knots fixed at the skin
  double peak_tension_n; // N, the thread's largest tension at the needle
  double path_m[2];      // m, the path of each hand's tool point
  double wound_gap_before_m; // m, across the wound at the stitch, the skin as the run found it; NaN: no skin read
  double wound_gap_after_m;  // m, the same on the latest skin
  double tissue_force_max_n; // N, the largest force of the skin on the needle's tip (SKIN.contact)
  double tears;              // links the skin tore (SKIN.contact's count), the wound's cut not counted
  double tears_pulled;       // of them, those a pull tore (the thread's, the jaws'), away from the needle's tip (SKIN.torn)
} tx_suture_measures;
#define tx_suture_measures_TYPE TX_F64
#define tx_suture_measures_COLS 13u
#define tx_suture_measures_UNITS "m, 1, N"
TX_LAYOUT_ASSERT(tx_suture_measures, double);

// PREFIX.step_paths (one row per step), written by procedure.lagb: how far
// each hand's tool point travelled while the step was under way
typedef struct tx_step_path {
  double path_m[2]; // m, hand 0, hand 1
} tx_step_path;
#define tx_step_path_TYPE TX_F64
#define tx_step_path_COLS 2u
#define tx_step_path_UNITS "m"
TX_LAYOUT_ASSERT(tx_step_path, double);

// PREFIX.lagb (1 row), written by procedure.lagb: the measures of its
// scorecard (docs/lagb.md, "The procedure")
typedef struct tx_lagb_measures {
  double path_m[2];           // m, the path of each hand's tool point over the run
  double liver_force_max_n;   // N, the largest pull of the liver on a grasper holding it
  double stomach_force_max_n; // N, the same for the stomach
  double damage_outside_m3;   // m^3, organ tissue (liver, stomach: not the target) with Omega over 1; NaN: no cautery read
  double locked;              // 1: the band is locked
  double encircles;           // 1: the band's loop goes round the stomach's axis (linking number +-1)
  double linking;             // the linking number of the band's loop, closed at the buckle, with the axis
  double band_from_gej_m;     // m, the band's centre from the gastro-oesophageal junction along the axis (+: toward the stomach)
  double band_off_axis_m;     // m, the band's centre from the axis
} tx_lagb_measures;
#define tx_lagb_measures_TYPE TX_F64
#define tx_lagb_measures_COLS 10u
#define tx_lagb_measures_UNITS "m, N, m^3, 1"
TX_LAYOUT_ASSERT(tx_lagb_measures, double);

#ifdef __cplusplus
}
#endif
#endif
