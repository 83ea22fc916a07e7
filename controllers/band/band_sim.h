// Internal: the gastric band of the LAGB paper (section 2.3) as two soft
// parts on Bullet (../organs/bullet/fem.h) and four rigid bodies on ODE.
//
// The ring part (almost inextensible, highly damped, a curved rest shape)
// and the tube part (elastic, highly deformable) are two tetrahedral FEM
// bodies with their own materials. Each end of each part is bolted to an
// ODE rigid body: its end nodes are kinematic, carried by the body's pose,
// and the body is loaded by their reaction (tx_fem_kinematic_force). The
// ring's tail body and the tube's head body are joined by ODE's double-ball
// joint (a distance joint: the paper's PhysX NxDistanceJoint); the ring's
// head body is the buckle, the tube's tip body the end that is threaded
// through it. Soft and rigid bodies advance together, substep by substep.
//
// When the tube's tip passes through the buckle's opening (a disc beyond
// the ring's head, across its tangent) in the insertion direction, the band
// latches: a fixed joint holds the tip to the buckle from then on.
//
//   tx_band_def d = tx_band_def_default();
//   tx_band* b = tx_band_create(&d, "assets/lagb");  // NULL: tx_error() says why
//   tx_band_set_force(b, TX_BAND_BUCKLE, f);          // a pull on a body
//   tx_band_step(b);                                    // false: a NaN (tx_band_restore)
//   double e = tx_band_joint_length(b) / tx_band_joint_rest(b) - 1;
//   tx_band_destroy(b);
#ifndef TX_CONTROLLERS_BAND_BAND_SIM_H
#define TX_CONTROLLERS_BAND_BAND_SIM_H

#include <stdbool.h>
#include <stdint.h>

enum { TX_BAND_RING, TX_BAND_TUBE, TX_BAND_PARTS };

// the rigid bodies
enum {
  TX_BAND_RING_TAIL, // the ring's tail, one end of the distance joint
  TX_BAND_TUBE_HEAD, // the tube's start, the joint's other end
  TX_BAND_BUCKLE,    // the ring's head
  TX_BAND_TUBE_TIP,  // the tube's free end, threaded through the buckle
  TX_BAND_BODIES
};

#define TX_BAND_OBSTACLES_MAX 8

typedef struct tx_band_material {
  double young;    // Pa
  double poisson;  // 1
  double density;  // kg/m^3
  double damping;  // 1/s, decay rate of the nodes' velocities
} tx_band_material;

typedef struct tx_band_def {
  tx_band_material part[TX_BAND_PARTS];
  double body_mass;      // kg, each rigid body
  double step;           // s, what tx_band_step advances
  double max_substep;    // s, the substep at most (the step is split into equal substeps); 0: the FEM's
                         // stable explicit step, with its safety factor 0.3 (the default,
                         // 2.5e-5, is stable on the committed assets; 4e-5 is not)
  double buckle_offset;  // m, the opening's centre beyond the ring's head along its tangent
  double buckle_radius;  // m, the opening's radius
  double gravity[3];     // m/s^2
  double max_speed;      // m/s, a faster node is a fault
  double erp, cfm;       // ODE's error reduction and constraint force mixing
  double origin[3];      // m, where the assets' origin goes in the scene; 0
  double rotation[3][3]; // the assets' axes in the scene (a rotation, rows: x' = R x); identity
  int obstacles;         // rigid capsules the band's nodes are kept out of (the oesophagus, the cardia); 0
  double obstacle[TX_BAND_OBSTACLES_MAX][7]; // each: its axis's two ends and its radius, m
} tx_band_def;

tx_band_def tx_band_def_default(void);

typedef struct tx_band tx_band;

// DIR/band_ring.node/.ele and DIR/band_tube.node/.ele (tactus-band-assets)
tx_band* tx_band_create(const tx_band_def* d, const char* dir);
void tx_band_destroy(tx_band* b);

// a constant force on a body (N, world frame) until changed
void tx_band_set_force(tx_band* b, int body, const double f[3]);
// the body carried kinematically to p (m) over the next tx_band_step, its
// orientation kept; tx_band_free gives it back to the dynamics
void tx_band_drive(tx_band* b, int body, const double p[3]);
void tx_band_free(tx_band* b, int body);

// advances def.step in substeps; false when a node or body stopped being
// finite or a node went faster than max_speed (the state is then unusable:
// tx_band_restore)
bool tx_band_step(tx_band* b);
void tx_band_save(tx_band* b);
void tx_band_restore(tx_band* b);

double tx_band_joint_length(const tx_band* b);  // m, between the joint's anchors now
double tx_band_joint_rest(const tx_band* b);    // m, the joint's length
bool tx_band_locked(const tx_band* b);
int tx_band_substeps(const tx_band* b);         // per tx_band_step
double tx_band_substep(const tx_band* b);       // s
void tx_band_body_position(const tx_band* b, int body, double p[3]);
// the buckle's opening now: its centre and its axis, the insertion direction
void tx_band_buckle(const tx_band* b, double c[3], double axis[3]);

// the parts' nodes and their tetrahedra's boundary faces, outward
int tx_band_nodes(const tx_band* b, int part);
int tx_band_faces(const tx_band* b, int part);
void tx_band_positions(const tx_band* b, int part, double* out);  // (nodes x 3) m
const int32_t* tx_band_face_nodes(const tx_band* b, int part);   // (faces x 3)
const double* tx_band_rest(const tx_band* b, int part);          // (nodes x 3) m, as loaded
// the part's soft body, for what holds its nodes besides the band's own
// bodies (a grasper's picking: tx_fem_set_kinematic_over, spread over
// tx_band_substeps, since each tx_band_step steps the parts one substep at a time)
struct tx_fem* tx_band_fem(tx_band* b, int part);
// the part's cross-sections along its centre line (tactus-band-assets writes
// the nodes section by section, from the end marked 1); 0 when the nodes do
// not come so. The middle of section k of the positions pos (nodes x 3)
int tx_band_sections(const tx_band* b, int part);
void tx_band_section_centre(const tx_band* b, int part, int k, const double* pos, double c[3]);

#endif
