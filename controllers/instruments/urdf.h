// Instrument descriptions: a URDF read with urdfdom (urdf_adapter.cpp) into
// plain C structs. Built with TX_WITH_URDFDOM. Poses are a position (m) and a
// unit quaternion (w, x, y, z) in the parent frame.
#ifndef TX_CONTROLLERS_INSTRUMENTS_URDF_H
#define TX_CONTROLLERS_INSTRUMENTS_URDF_H

#include <stdbool.h>

#define TX_URDF_NAME_MAX 64
#define TX_URDF_SHAPES_MAX 8 // collision primitives per link
#define TX_URDF_PATH_MAX 1024

typedef enum { TX_URDF_BOX, TX_URDF_CYLINDER, TX_URDF_SPHERE } tx_urdf_shape_kind;

typedef struct tx_urdf_pose {
  double p[3], q[4];
} tx_urdf_pose;

// a collision primitive: box size[0..2] (full lengths); cylinder radius
// size[0] and length size[1] along its frame's z; sphere radius size[0]
typedef struct tx_urdf_shape {
  char name[TX_URDF_NAME_MAX];
  tx_urdf_shape_kind kind;
  double size[3];
  tx_urdf_pose pose; // in the link frame
} tx_urdf_shape;

typedef struct tx_urdf_link {
  char name[TX_URDF_NAME_MAX];
  double mass; // kg, > 0
  tx_urdf_pose com; // the <inertial> origin: the centre of mass and the inertia's axes
  double inertia[6]; // ixx ixy ixz iyy iyz izz about com (kg m^2), positive definite
  char mesh[TX_URDF_PATH_MAX]; // the visual mesh, resolved against the URDF's folder; "" for none
  tx_urdf_pose mesh_pose;
  double mesh_scale[3];
  tx_urdf_shape shapes[TX_URDF_SHAPES_MAX];
  int nshapes;
} tx_urdf_link;

typedef struct tx_urdf_joint {
  char name[TX_URDF_NAME_MAX];
  bool fixed; // else revolute
  int parent, child; // link indices
  tx_urdf_pose origin; // child frame at angle 0, in the parent frame
  double axis[3]; // unit, in the joint frame
  double lower, upper, effort, velocity; // rad, rad, N m, rad/s
} tx_urdf_joint;

typedef struct tx_urdf {
  char name[TX_URDF_NAME_MAX];
  tx_urdf_link* links; // links[0] is the root
  tx_urdf_joint* joints; // a joint's parent comes before its child in links
  int nlinks, njoints;
} tx_urdf;

// Reads and checks PATH. NULL, with one line "PATH: ..." in tx_error() naming
// the element (or the XML line), for: a malformed file, a joint that is not
// revolute or fixed, a revolute joint with no <limit> or lower > upper, a link
// with no <inertial>, a mass or principal inertia that is not positive, a
// collision shape that is not a positive box, cylinder or sphere, and a mesh
// given by a package:// URI. Meshes are only named here (tx_instrument_load
// reads them).
tx_urdf* tx_urdf_load(const char* path);
void tx_urdf_free(tx_urdf* u);
int tx_urdf_link_index(const tx_urdf* u, const char* name); // -1 if none

#endif
