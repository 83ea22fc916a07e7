// Internal: the tool tip, a sphere, against the closed surfaces of the soft
// organs (docs/lagb.md, "collision.organ"), and the local force model the
// haptics renders from it.
//
// Each organ's surface is a closed triangle mesh wound outwards, held in a
// tx_tri_bvh (tri_bvh.h) built once and refitted at each physics publish.
// The tip (centre c, radius r) is in contact with an organ when its signed
// distance s from the surface (positive outside) is below r; the penetration
// is depth = r - s and the outward direction n runs from the nearest surface
// point p to c (p to c reversed when c is inside), continuous across edges.
//
// The surface is one-sided, as the HIP's skin: a contact begins only from
// outside (0 <= s < r), or when the tip's move since the last query crossed
// a face from its outer side (a hand faster than r per query). While in
// contact only the faces that look the way the contact does (normal . n > 0)
// are searched, so a tip pushed past the middle of a thin organ keeps being
// pushed back out the way it came in, never out the far side. A tip found
// inside an organ it did not enter (it started there, or the organ moved over
// it) gets no force until it is out. A contact ends when s >= r + hold (the
// physics leaves the surface about r from the tool it saw, which may lead
// the hand by a physics period), or when it is deeper than depth_max: the
// organ gave way, and the tip is then inside without having entered.
//
// The force (tx_organ_force): while an organ touches the tip and the
// physics' own reaction (organs.contact, tx_skin_contact) touches too, it is
// carried from where the physics computed it to c with the tangent
// stiffness, as collision.hip's mechanics mode does: F = f - k ((c - x) . m) m,
// K = -k m m^T (m its direction), never a pull. Between physics publishes,
// when the tip meets a surface the physics has not seen it touch yet, it is a
// penalty along each touching organ's normal: F = sum k_pen depth n,
// K = -sum k_pen n n^T. Nothing allocates after tx_organ_* init.
//
//     tx_organ_side side;  tx_organ_side_reset(&side);       // per organ
//     tx_organ_touch t;    tx_organ_tip(&side, &def, &bvh, x, c, &t);
//     tx_organ_force(&t, 1, reaction_or_NULL, k_pen, def.depth_max, c, &out);
#ifndef TX_CONTROLLERS_COLLISION_ORGAN_H
#define TX_CONTROLLERS_COLLISION_ORGAN_H

#include "tri_bvh.h"

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_organ_tip_def {
  double radius;    // m, the tip sphere
  double hold;      // m, a contact lasts while s < radius + hold
  double depth_max; // m, deepest penetration a contact follows; past it the organ gave way
} tx_organ_tip_def;

tx_organ_tip_def tx_organ_tip_def_default(void);
// 0 when every field is valid, else -1 and tx_error() names the field
int tx_organ_tip_def_check(const tx_organ_tip_def* d);

// the point of a surface nearest to c
typedef struct tx_organ_near {
  double p[3];   // m, on the surface
  double s;      // m, signed distance of c: positive outside
  double n[3];   // 1, outward unit direction at p toward c's side (p -> c outside, c -> p inside)
  uint32_t tri;  // triangle id (row of the triangle array)
} tx_organ_near;

// the nearest surface point within rmax of c, over the triangles whose
// outward normal has a positive dot with facing (NULL: every triangle).
// Where triangles are equally near (an edge, a corner) the one whose plane
// c is farthest from decides the side. False when none is that near.
bool tx_organ_nearest(const tx_tri_bvh* b, const float* x, const double c[3], double rmax, const double* facing,
                      tx_organ_near* out);

// one organ's contact with the tip, kept between queries
typedef struct tx_organ_side {
  bool on;          // in contact, entered from outside
  double n[3];      // 1, the contact's outward direction at the last query
  bool deep;        // the centre was inside at the last query in contact
  bool has_prev;    // prev holds the tip's last centre
  double prev[3];   // m
} tx_organ_side;

void tx_organ_side_reset(tx_organ_side* s);

// one query's answer for one organ
typedef struct tx_organ_touch {
  bool on;          // in contact after this query
  bool onset;       // the contact began in this query
  bool gave_way;    // a contact ended deeper than depth_max in this query
  bool inside;      // c is inside the organ without having entered it (no force)
  double depth;     // m, r - s while on (<= 0 within the hold band), else 0
  double n[3];      // 1, outward direction of the contact while on
  double p[3];      // m, nearest surface point while on
} tx_organ_touch;

// the tip at c against one organ (b built or refitted over x); allocates nothing
void tx_organ_tip(tx_organ_side* side, const tx_organ_tip_def* d, tx_tri_bvh* b, const float* x, const double c[3],
                  tx_organ_touch* out);

struct tx_skin_contact; // <tactus/components.h>

typedef enum tx_organ_force_kind {
  TX_ORGAN_FORCE_NONE = 0, // no organ touches the tip (or the reaction would pull)
  TX_ORGAN_FORCE_PENALTY,  // the geometric penetration, k_pen along each normal
  TX_ORGAN_FORCE_REACTION, // the physics' reaction carried to c
} tx_organ_force_kind;

typedef struct tx_organ_force_out {
  double f[3];  // N, on the tool at c
  double k[9];  // N/m, row-major dF/dc
  tx_organ_force_kind kind;
} tx_organ_force_out;

// the force on the tool at c from n organ touches; r: the physics' reaction
// (NULL, or not touching: the penalty with k_pen, N/m)
void tx_organ_force(const tx_organ_touch* t, int n, const struct tx_skin_contact* r, double k_pen, double depth_max,
                    const double c[3], tx_organ_force_out* out);

#endif
