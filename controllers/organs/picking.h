// Internal: grasper picking on tetrahedral soft bodies, as the LAGB paper
// does it: when a grasper's jaws close, the surface triangles between or
// touching them are flagged as picked by that instrument; the nodes that
// carry those triangles move kinematically with the jaws each physics frame
// (their offset in the jaws' frame at the grasp kept), the rest of the body
// follows through its solver; opening the jaws releases them.
//
// Two layers:
//  - tx_picking: the logic on any tx_fem bodies and their drawn surfaces (a
//    surface vertex carried by `per` nodes with weights: 4, embedded in a
//    tetrahedron, as the organs draw theirs; 1, the vertex is a node). No
//    controller API, so a unit test or the band's controller can use it.
//  - tx_pick_ctl: the controller's part (parameters TX_PICK_PARAMS, the
//    jaws' pose reads, the grasp component and the event stream, results),
//    for a physics controller that owns the bodies (physics.organs) and
//    calls four hooks. physics.band uses the first layer alone, since its
//    graspers also take the band's rigid ends.
//
//   tx_picking* p = tx_picking_create(&def, hands);
//   tx_picking_add(p, fem, &surface);                  // each body, at configure
//   tx_event e;                                        // each frame, before the bodies step:
//   if (tx_picking_update(p, h, &jaws, positions, &e)) emit(e);   // per hand
//   tx_fem_step(...);
//   tx_picking_force(p, h, f);                         // after: the bodies' pull on hand h's jaws
#ifndef TX_CONTROLLERS_ORGANS_PICKING_H
#define TX_CONTROLLERS_ORGANS_PICKING_H

#include "bullet/fem.h"

#include <tactus/components.h>
#include <tactus/controller.h>
#include <tactus/events.h>

#include <stdbool.h>
#include <stdint.h>

#define TX_PICK_HANDS_MAX 4   // instruments that may pick at once
#define TX_PICK_BODIES_MAX 8  // bodies one tx_picking picks from

typedef struct tx_pick_def {
  double length;  // m, the jaws reach this far ahead of the pivot along the pose's x
  double reach;   // m, a triangle this close to the jaws' line is between or touching them
  double closed;  // rad, jaws at or below this angle have closed (a grasp, once opened)
  double open;    // rad, jaws at or above this have opened (a release); above closed
  int substeps;   // the jaws' move between updates spread over this many of the bodies' substeps (the band's
                  // parts, stepped one substep at a time: tx_fem_set_kinematic_over); 0: over the next tx_fem_step
} tx_pick_def;

// a drawn surface and what carries it; the arrays are kept, not copied
typedef struct tx_pick_surface {
  int nv, nt;
  const int32_t* tri;   // (nt x 3) rows of the vertices
  int per;              // nodes carrying each vertex, 1 to 4
  const int32_t* node;  // (nv x per) the nodes, rows of the body's positions
  const float* w;       // (nv x per) their weights (summing to 1); NULL: per must be 1
} tx_pick_surface;

typedef struct tx_picking tx_picking;

// NULL with tx_error() on a bad definition or hand count
tx_picking* tx_picking_create(const tx_pick_def* d, int hands);
void tx_picking_destroy(tx_picking* p);
// a body to pick from (fem and s kept; they outlive p); its index, or -1
// with tx_error() (too many bodies, a surface row out of range)
int tx_picking_add(tx_picking* p, tx_fem* fem, const tx_pick_surface* s);

// One physics frame of hand h, before the bodies step: jaws is its pose
// (root frame at the pivot, jaw angle); pos[b] body b's node positions (nodes
// x 3, m) as they are now. Closing jaws (after they were seen open) pick the
// triangles within reach of the segment from the pivot `length` along x; the
// nodes carrying them, not held by another hand, not fixed and not
// kinematic already (bolted to a rigid body, as the band's ends are), become
// kinematic at their place; opened jaws release them. Every held node is then
// set where its offset in the jaws' frame puts it. jaws NULL or not finite:
// nothing changes and what is held stays where it is. Returns true with *e
// filled (kind, source = h, for a grasp the mean point picked and the jaw
// angle) when the jaws grasped or released; a close on nothing, or on
// triangles whose nodes are all held already or fixed, is no event.
// Allocates nothing.
bool tx_picking_update(tx_picking* p, int h, const tx_instrument_pose* jaws, const double* const* pos, tx_event* e);
// hand h lets go of everything (no event); every hand: h = -1
void tx_picking_release(tx_picking* p, int h);

// after the bodies stepped: their force on hand h's jaws, N (the sum of
// tx_fem_kinematic_force over its nodes; zero in the links model)
void tx_picking_force(const tx_picking* p, int h, double f[3]);
int tx_picking_nodes(const tx_picking* p, int h);               // nodes hand h holds
// m, the farthest the last update put one of hand h's nodes from where it was taken
double tx_picking_carried(const tx_picking* p, int h);
int tx_picking_triangles(const tx_picking* p, int h);           // triangles flagged as picked by it
int tx_picking_holder(const tx_picking* p, int body, int node); // the hand holding a node, -1 none
// the hand that picked a triangle of body, -1 none
int tx_picking_triangle_holder(const tx_picking* p, int body, int tri);

// --- the controller's part ------------------------------------------------------

// the parameters, for the class's table (physics.organs)
#define TX_PICK_PARAMS \
  {"grasp", TX_PARAM_STRS, NULL, 0, TX_PICK_HANDS_MAX, 0, NULL, \
   "the graspers that pick: their poses (tx_instrument_pose: instrumentN.pose), hand h the h-th; none: no picking"}, \
  {"grasp_length_m", TX_PARAM_NUM, "m", 0.001, 0.1, 0.02, NULL, \
   "the jaws reach this far ahead of the pivot along the pose's x (the lap grasper's 20 mm)"}, \
  {"grasp_reach_m", TX_PARAM_NUM, "m", 0, 0.02, 0.003, NULL, \
   "closing jaws pick the surface triangles this close to their line (the jaws' half width, 2 mm, and 1 mm)"}, \
  {"grasp_closed_rad", TX_PARAM_NUM, "rad", 0, 1, 0.1, NULL, \
   "jaws at or below this angle between them have closed: a grasp, if they were open since the last"}, \
  {"grasp_open_rad", TX_PARAM_NUM, "rad", 0.001, 3.2, 0.2, NULL, \
   "jaws at or above this have opened: what they held is released (above grasp_closed_rad)"}

typedef struct tx_pick_ctl tx_pick_ctl;

// configure: reads TX_PICK_PARAMS; with grasp poses, reads them, writes
// PREFIX.grasp (tx_organ_grasp, one row per hand) and emits on PREFIX.events;
// results grasps, grasp_releases, grasp_nodes_max, grasp_force_max_n,
// grasp_carried_max_m (the farthest a held node was carried). *out
// NULL when nothing picks. -1 after tx_setup_fail.
int tx_pick_configure(tx_setup* s, const char* prefix, int bodies, tx_fem* const* fem, const tx_pick_surface* surf,
                      tx_pick_ctl** out);
// init: every hand open, nothing held; publishes the rows
void tx_pick_init(tx_ctx* c, tx_pick_ctl* k);
// step, before the bodies step: each hand's jaws; events emitted
void tx_pick_before(tx_ctx* c, tx_pick_ctl* k, const double* const* pos);
// step, after: the bodies' pull on each hand published (zero when !ok: the
// step was undone)
void tx_pick_after(tx_ctx* c, tx_pick_ctl* k, bool ok);
void tx_pick_finish(tx_ctx* c, tx_pick_ctl* k);
void tx_pick_free(tx_pick_ctl* k);

#endif
