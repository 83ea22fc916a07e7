// Internal: what a graphics view draws and from where, read from a scenario's
// "view" object (docs/views.md). No GL here: the loader checks a "view" even in
// a build without graphics.
//
//     tx_view_def d = tx_view_def_default();
//     char key[128], msg[256];
//     if (tx_view_def_from_json(json, &d, key, sizeof key, msg, sizeof msg)) error at "view.KEY: MSG"
//
// Drawn components follow the model's naming conventions:
//   mesh NAME      NAME.x (f32 N x 3, m) and NAME.tri (i32 M x 3, vertex indices)
//   spheres NAME   NAME.spheres (f32 N x 4: x y z radius, m), optional scalar NAME.Q (f32 N x 1)
//   segments NAME  NAME.segments (f32 N x 7: x0 y0 z0 x1 y1 z1 radius, m)
//   tool NAME      NAME.pose (f64 1 x 7: x y z m, qw qx qy qz), optional NAME.force (f64 1 x 3, N)
//   plane          a fixed square (no component): point, normal and size in the view itself
//   instrument NAME  NAME.links (f64 N x 7: each URDF link's frame) and NAME.held (f64 1 x 1: which of
//                  the entry's "urdf" list the hand holds), drawn from the URDFs' visual meshes
//   markers        a puncture list P.punctures (f64 N x 7, tx_puncture) placed on SKIN.x: a small
//                  sphere where each puncture is, on the triangle it pierced; and the live grasps
//                  and knots of event streams (tx_marker_take), knots on THREAD.spheres
#ifndef TX_VIEWS_GRAPHICS_VIEW_DEF_H
#define TX_VIEWS_GRAPHICS_VIEW_DEF_H

#include "laparoscope.h"
#include "stereo.h"

#include <tactus/events.h>
#include <tactus/model.h>

#include <jansson.h>
#include <stdbool.h>
#include <stddef.h>

#define TX_DRAW_MAX 16     // draw entries of one view
#define TX_VIEW_SIDE_MAX 4096 // px, largest width or height of one eye

#define TX_DRAW_URDF_MAX 512     // the instruments named by one instrument entry, as text
#define TX_DRAW_INSTRUMENT_LINKS 8 // links of one drawn instrument
#define TX_MARKER_STREAMS 4        // event streams of one markers entry
#define TX_MARKERS_MAX 64          // live grasps and knots of one markers entry

typedef enum tx_draw_kind {
  TX_DRAW_MESH = 1,
  TX_DRAW_SPHERES,
  TX_DRAW_SEGMENTS,
  TX_DRAW_TOOL,
  TX_DRAW_PLANE,
  TX_DRAW_INSTRUMENT,
  TX_DRAW_MARKERS
} tx_draw_kind;

typedef struct tx_draw_item {
  tx_draw_kind kind;
  char name[TX_NAME_MAX];   // component prefix ("skin" for skin.x and skin.tri); "" for a plane; markers: the puncture list
  char skin[TX_NAME_MAX];   // markers: the mesh prefix the punctures' rows index (SKIN.x)
  char events[TX_MARKER_STREAMS][TX_NAME_MAX]; // markers: the event streams listened to
  int nevents;
  char thread[TX_NAME_MAX]; // markers: the prefix of THREAD.spheres, whose nodes a knot names; "" for none
  char scalar[TX_NAME_MAX]; // colour-map component, e.g. "tissue.damage" (f32 N x 1); "" for a plain colour
  float colour[3];          // 1, linear RGB in [0, 1]
  float range[2];           // scalar values mapped to the ends of the colour map
  bool skin_texture;        // meshes: the procedural skin texture instead of the plain colour
  bool tissue_texture;      // meshes: the colour modulated by the procedural tissue texture (organ_texture.h)
  bool show_force;          // tools: a line along NAME.force
  float radius;             // m, tools: radius of the HIP sphere; markers: of each marker
  float force_scale;        // m/N, tools: length of the force line per newton
  char proxy[TX_NAME_MAX];  // tools: a force model (tx_force_model) whose x0 is drawn as the proxy; "" for none
  float plane[7];           // planes: point (m), unit normal, half size (m)
  bool has_cut;             // spheres: a cutaway plane is given
  float cut[6];             // spheres: point (m) and unit normal of the cutaway; centres on the normal's side are not drawn
  char urdf[TX_DRAW_URDF_MAX]; // instruments: the hand's instruments, names in assets/instruments or .urdf paths, by spaces
} tx_draw_item;

typedef struct tx_view_def {
  tx_camera camera;       // cyclopean camera and the stereo geometry
  bool auto_camera;       // no "camera" given: frame the first snapshot's bounding box
  bool interaxial_given;  // stereo.interaxial_m was given; else it is the convergence distance / 30
  bool convergence_given; // stereo.convergence_m was given; else the eye-target distance
  int width, height;      // px, one eye's image
  int frame_every;        // png: write every Nth rendered frame (and the last)
  float background[3];    // 1, linear RGB
  float light_dir[3];     // 1, direction the light shines from (towards the scene), unit
  bool headlight;         // the light shines along the view, from the eye (set each frame)
  bool scope;             // the camera is a laparoscope's on a pivot (the window's mouse moves it)
  tx_laparoscope laparoscope;
  tx_draw_item items[TX_DRAW_MAX];
  int nitems;
} tx_view_def;

tx_view_def tx_view_def_default(void);
// read a "view" object (rate_hz is the caller's); 0, or -1 with "KEY: message"
// in tx_error() (KEY relative to the view; none for the whole view) and KEY
// alone in tx_error_key() (model/error.h)
int tx_view_def_from_json(const json_t* view, tx_view_def* d);
// the same from the object's JSON text (tx_param_json_text)
int tx_view_def_from_text(const char* text, tx_view_def* d);
// draw entries for every component that follows the naming conventions, from the names written in a model
int tx_view_def_auto_draw(tx_view_def* d, const char* const* written, int count);
// a grasp or knot marker: grasps at their point until their hand's release,
// knots on the thread's nodes first..last (where the thread is now)
typedef struct tx_marker {
  uint32_t kind;   // TX_EVENT_GRASP or TX_EVENT_KNOT
  uint32_t source; // the grasp's hand; the knot's index
  float p[3];      // m, grasps: the grasp point
  uint32_t first, last; // knots: the thread's cylinders (node i to i + 1), as physics.thread's event names them
} tx_marker;
typedef struct tx_marker_list {
  tx_marker m[TX_MARKERS_MAX];
  uint32_t n;
  uint64_t dropped; // markers refused with the list full
} tx_marker_list;
// one event into the live list: a grasp added, its hand's grasps removed on
// a release, a knot added; other kinds and bad payloads ignored
void tx_marker_take(tx_marker_list* l, const tx_event* e);

// the components an item reads, in order; returns how many (at most 3)
int tx_draw_item_components(const tx_draw_item* it, char out[3][TX_NAME_MAX]);

#endif
