// Punctures from what the skin publishes (skin.contact, skin.x, skin.tri,
// skin.torn): the tip's HIP tears the skin. A puncture is a tear that the
// skin counts as its HIP's pierce (tx_puncture_skin_pierces: a flap torn as
// it flicks the tip is none), at least `separation` from the last puncture
// (a tear that runs on at the hole is the same puncture), and on the side
// the tip is on:
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
  double torn;       // links torn when last seen
  bool free;         // the tip was clear of the skin since the last puncture (torn flaps cling to it as it comes out)
  bool touched;      // and has touched it since
  double n[3];       // the last direction the skin pushed the tip
  double peak_f, peak_depth; // the largest force since the last puncture (N) and the indentation then (m)
  bool any;
  double last[3]; // the last puncture's point
  int next_side;  // +1: the tip is outside (an entry comes next), -1: inside
  int pierces;    // the skin's count of its HIP's pierces when last seen; -1: not seen yet
  bool pierced;   // it rose, and no puncture has taken that pierce yet
} tx_puncture_tracker;

// a tracker that has seen `torn` links torn already
void tx_puncture_tracker_init(tx_puncture_tracker* t, double separation, double torn);
// the skin's own count of its HIP's pierces (SKIN.torn's third column), given
// before each tx_puncture_update: a tear is a puncture when the count rose,
// however hard the tip pushed (a rule of 0.05 N of push before it missed a
// tip driven a little off its line, which tore through at 0.043 N); the
// first call sets where the count stands
void tx_puncture_skin_pierces(tx_puncture_tracker* t, int pierces);

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

// Where the needle crossed the skin: arc holds narc points along the needle
// from its tip back towards its swage. The patch is the component of the
// particles that the most live triangles join (a flap torn loose, hanging
// by nothing or by itself, is not the patch); scratch (nscratch int32 >= 2
// nx, NULL: every triangle counts as the patch) is its work space. The
// first point back from the tip on the other side of the patch's sheet than
// the tip (the side: the nearest triangle's normal) brackets the crossing
// (with near_to: of the arc's points within `within` of near_to, the
// crossing nearest it, for a hole the needle slides through); a crossing
// within `apart` of one of the ntaken points of taken is another
// puncture's hole and is passed over (an exit torn before the arc has
// crossed the sheet there would otherwise find the entry's);
// on_arc is the crossing, between the two points where the distance to the
// sheet goes through zero, and the result is the patch's triangle nearest
// it (the hole's rim), with the crossing's barycentric coordinates in its
// plane (summing to 1; outside [0, 1], as the hole's centre is off the
// rim) and that point (the crossing projected on the plane); -1 when the arc
// does not cross the sheet.
int tx_puncture_hole(const float* x, int nx, const int32_t* tri, int ntri, const double (*arc)[3], int narc,
                     const double near_to[3], double within, const double (*taken)[3], int ntaken, double apart,
                     int32_t* scratch, int nscratch, double bary[3], double point[3], double on_arc[3]);

// whether the triangle of particles v is still a live triangle (in tri) of
// the patch (as in tx_puncture_hole; scratch NULL: any live one is)
bool tx_puncture_attached(int nx, const int32_t* tri, int ntri, int32_t* scratch, int nscratch, const int32_t v[3]);

// how high p is above the skin's sheet (m; negative: under it): p's height
// less that of the particle nearest it across (in x and z); INFINITY when
// p is not over the patch (outside its particles' x-z bounds)
double tx_height_above_sheet(const float* x, int nx, const double p[3]);

// The same for many points against one publish of the sheet: its particles
// bucketed by x and z once (tx_sheet_grid_build, O(n)), then each point's
// nearest particle across found in the cells around it. Sized once by
// tx_sheet_grid_init (particles), no allocation after; a build with more
// particles than that keeps none (every height INFINITY).
typedef struct tx_sheet_grid {
  int cap;             // particles it has room for (and cells: as many)
  int n;               // particles bucketed by the last build (the finite ones)
  int cols, rows;      // cells
  double lo[2], hi[2]; // m, the particles' x-z bounds
  double cell;         // m, a cell's side
  int32_t* start;      // (cap + 1) where each cell's particles begin in order
  int32_t* cursor;     // (cap) the build's scratch
  int32_t* order;      // (cap) particle numbers, cell by cell
} tx_sheet_grid;
bool tx_sheet_grid_init(tx_sheet_grid* g, int cap);
void tx_sheet_grid_free(tx_sheet_grid* g);
void tx_sheet_grid_build(tx_sheet_grid* g, const float* x, int nx);
// tx_height_above_sheet of p against the particles of the last build
double tx_sheet_height(const tx_sheet_grid* g, const float* x, const double p[3]);

#endif
