// Punctures from what the skin publishes (skin.contact, skin.x, skin.tri):
// the tip's HIP tears the skin. A puncture is the first tear after the tip,
// clear of the skin since the last puncture (torn flaps cling to it as it
// comes out), pushed on it with at least `min_force` (a flap flicking the tip
// is no puncture), at least `separation` from the last puncture (a tear that
// runs on at the hole is the same puncture), and on the side the tip is on:
// through one membrane it goes in, then out, in, out. Its place is the point of the
// live triangles nearest the HIP centre that tore them (the hole's rim), and
// its side is where the tip came from: +1 from the triangles' normal side (the
// skin's outside: an entry), -1 from behind (an exit). Pure C, no ODE.
#ifndef TX_CONTROLLERS_INSTRUMENTS_PUNCTURE_H
#define TX_CONTROLLERS_INSTRUMENTS_PUNCTURE_H

#include <tactus/components.h>

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_puncture_tracker {
  double separation; // m: the least distance between two punctures
  double min_force;  // N: the tip must have pushed the skin this hard before a tear is its puncture
  double torn;       // links torn when last seen
  bool free;         // the tip was clear of the skin since the last puncture
  bool touched;      // and has touched it since
  double n[3];       // the last direction the skin pushed the tip
  double peak_f, peak_depth; // the largest force since the last puncture (N) and the indentation then (m)
  bool any;
  double last[3]; // the last puncture's point
  int next_side;  // +1: the tip is outside (an entry comes next), -1: inside
} tx_puncture_tracker;

// a tracker that has seen `torn` links torn already
void tx_puncture_tracker_init(tx_puncture_tracker* t, double separation, double min_force, double torn);

// what a puncture found: the row, its vertices, the point and the force
typedef struct tx_puncture_found {
  tx_puncture row;     // the triangle's particles (rows of skin.x), barycentric coordinates, side
  int32_t verts[3];    // the same particles, as integers: they carry the point
  int triangle;        // its row of skin.tri at this publish (renumbered by the next tear)
  double point[3];     // m
  double force, depth; // the largest force on the tip before the tear (N), and the skin's indentation then (m)
} tx_puncture_found;

// one publish of the skin (x: nx particles, tri: ntri live triangles): true
// when it makes a puncture, then *out says where. A tear without a triangle
// left, or with indices outside skin.x, is no puncture (counted as seen).
bool tx_puncture_update(tx_puncture_tracker* t, const tx_skin_contact* c, const float* x, int nx, const int32_t* tri,
                        int ntri, tx_puncture_found* out);

// the point of the triangles nearest p: its row (-1 when none), its
// barycentric coordinates and the point; rows with indices outside [0, nx) are skipped
int tx_nearest_triangle(const float* x, int nx, const int32_t* tri, int ntri, const double p[3], double bary[3],
                        double point[3]);

#endif
