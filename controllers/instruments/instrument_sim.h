// Articulated instruments on ODE: each instrument of a tx_urdf is a root body
// and jaw bodies on hinge joints, in one ODE world with a table plane (the
// rigid scene). Its root follows a device through a virtual coupling (a
// spring-damper); what the hand feels is the coupling's reaction. Its jaws'
// hinge motors follow the device's grip angle within the joint limits. ODE
// contacts: jaw with jaw, instrument with instrument, instrument with the
// table. Built with TX_WITH_ODE (and the readers: TX_WITH_URDFDOM, TX_WITH_ASSIMP).
//
// ODE wants each body's centre of mass at its origin: a link's body is placed
// at the link frame times its inertial origin, and its geoms are offset from
// it to where the URDF puts them in the link frame.
#ifndef TX_CONTROLLERS_INSTRUMENTS_INSTRUMENT_SIM_H
#define TX_CONTROLLERS_INSTRUMENTS_INSTRUMENT_SIM_H

#include "urdf.h"

#include <stdbool.h>

#define TX_INSTRUMENTS_MAX 4 // in one world: up to two per hand, one held, one parked
#define TX_INSTRUMENT_LINKS_MAX 8

// The curved needle: a circular arc of a steel wire, one rigid body. Its
// frame has the circle's centre at its origin and the arc in its x-y plane,
// from the swage end at (radius, 0, 0) counter-clockwise about z to the tip.
typedef struct tx_needle_params {
  bool enabled;
  double radius; // m, of the circle the needle is bent on
  double wire_diameter; // m
  double arc; // rad: 3/8 circle = 0.75 pi, 1/2 circle = pi
  double pos[3], quat[4]; // where its frame starts, in the world
  // held_by >= 0: it starts in that instrument's closed jaws instead (pos and
  // quat are then ignored): the wire across them grasp_distance ahead of the
  // pivot, at grasp_angle along the arc from the swage, the arc in the root's
  // x-y plane curving towards the root's +y; held as a grasp holds it
  int held_by;
  double grasp_distance; // m
  double grasp_angle; // rad
  // foam: it stands in a block of foam, held still at pos until jaws take it:
  // its arc upright in the world's x-y plane, turned so that the point at
  // grasp_angle from the swage lies at pos + (radius, 0, 0) with the wire
  // there along y, across jaws that come along +x (quat is then ignored)
  bool foam;
} tx_needle_params;

// the default: a 3/8-circle reverse-cutting skin needle 19 mm long (the
// common skin-closure size, docs/instruments.md), 0.6 mm wire, lying flat
tx_needle_params tx_needle_defaults(void);

typedef struct tx_instrument_sim_params {
  double coupling_k, coupling_b; // N/m, N s/m: the virtual coupling's spring and damper
  double orient_rate; // 1/s: the root turns towards the device's orientation at this rate x the angle left
  double orient_torque; // N m: with at most this torque
  double max_force; // N: the coupling force is clamped to this (the device's limit)
  double jaw_gain; // 1/s: a jaw motor's speed is gain x its angle error, within the joint's velocity
  double gravity[3]; // m/s^2
  double table_height; // m: the table is the half-space y < table_height
  double friction; // Coulomb coefficient of every contact
  double erp, cfm; // ODE's error reduction and constraint force mixing (cfm: of joints, and the least of contacts)
  // a contact's CFM / dt as a fraction of its normal row's 1/m_eff
  // (tx_instrument_contact_cfm); 0: the world's cfm for every contact
  double contact_relax;
  tx_needle_params needle;
  // where the needle has pierced the skin (pins): a spring-damper holds its
  // arc on each puncture point across the arc, and a friction force of at
  // most pin_friction resists its sliding along the arc
  double pin_stiffness; // N/m, across the arc
  double pin_damping; // N s/m, across the arc
  double pin_friction; // N, along the arc
  double pin_reach; // m: a pin farther than this off the arc holds nothing (the skin there has let go of the needle)

} tx_instrument_sim_params;

tx_instrument_sim_params tx_instrument_sim_defaults(void);

// the default contact_relax: every contact row regularised by this fraction
// of its own diagonal (the scenario's needle, welded and pinched, needs about
// 1e-5; 2e-6 still let ODE's LCP blow up)
#define TX_CONTACT_RELAX 2e-5

// the CFM of a contact whose normal row's diagonal of ODE's LCP matrix (the
// inverse of the effective mass it pushes on, kg^-1) is inverse_mass, at a
// step of dt: contact_relax x dt x inverse_mass, at least p->cfm
double tx_instrument_contact_cfm(const tx_instrument_sim_params* p, double inverse_mass, double dt);

// one instrument's device this step
typedef struct tx_instrument_input {
  double pos[3], quat[4]; // the tool point's target pose: m, unit (w, x, y, z)
  double vel[3]; // m/s
  double grip; // rad, the angle wanted between the jaws
} tx_instrument_input;

typedef struct tx_instrument_world tx_instrument_world;

// n instruments (at most TX_INSTRUMENTS_MAX), instrument i with its root at
// start[i] (identity orientation), jaws closed. The caller keeps the urdfs
// alive while the world lives. NULL with tx_error() set when ODE cannot be
// started or a description has more than TX_INSTRUMENT_LINKS_MAX links.
// ODE keeps per-thread data: create, step and destroy on one thread (destroy
// frees the calling thread's).
tx_instrument_world* tx_instrument_world_create(const tx_instrument_sim_params* p, const tx_urdf* const* urdfs, int n,
                                                const double (*start)[3]);
void tx_instrument_world_destroy(tx_instrument_world* w);

// one ODE step of dt seconds: couplings, jaw motors, contacts, integration
void tx_instrument_world_step(tx_instrument_world* w, const tx_instrument_input* in, double dt);

// after a step: a link frame's pose in the world (the URDF's link frame, not
// the body's centre of mass), the jaw joint angles, and the coupling force on
// the hand (N, clamped to max_force)
void tx_instrument_world_link(const tx_instrument_world* w, int instrument, int link, double pos[3], double quat[4]);
double tx_instrument_world_joint(const tx_instrument_world* w, int instrument, int joint);
void tx_instrument_world_hand_force(const tx_instrument_world* w, int instrument, double f[3]);
// contacts made in the last step (all pairs), and steps whose state went non-finite (then reset)
int tx_instrument_world_contacts(const tx_instrument_world* w);
int tx_instrument_world_resets(const tx_instrument_world* w);
// steps whose device input was not finite (the coupling then pulls on nothing),
// and the deepest contact of the last step (m)
int tx_instrument_world_bad_inputs(const tx_instrument_world* w);
// Faults: steps whose bodies or inputs were not finite before ODE's step
// (then never stepped) or after it; each puts every body back where it was
// after the last good step, at rest (also counted in resets). Contacts
// dropped for a non-finite point or depth or a normal that is not unit.
int tx_instrument_world_faults(const tx_instrument_world* w);
// Steps ODE gave up inside (one of its assertions, which would end the
// process): left by longjmp, the world is destroyed and rebuilt from the
// description and the last good state, never stepped again; each is also a
// fault (counted in faults and resets)
int tx_instrument_world_rebuilds(const tx_instrument_world* w);
int tx_instrument_world_bad_contacts(const tx_instrument_world* w);
// what an instrument passes through, as owner bits (bit i: instrument i;
// bit TX_INSTRUMENTS_MAX: the needle; the next: the table): after a fault
// each instrument makes no contact with what it overlaps where it was put
// back until they are apart (0 when it overlaps nothing)
unsigned tx_instrument_world_passing_through(const tx_instrument_world* w, int instrument);
double tx_instrument_world_depth(const tx_instrument_world* w);
// Switching instruments. Park: the instrument is put down at pos (identity
// orientation, jaws at their closed stop) and taken out of the world: its
// bodies do not move and its geoms touch nothing, it lets go of the needle
// it held, and its hand force is zero. Take: it is back, its root at pos
// and quat (a device's pose) at rest, so the coupling spring starts
// unstretched. parked: whether it is parked now.
void tx_instrument_world_park(tx_instrument_world* w, int instrument, const double pos[3]);
void tx_instrument_world_take(tx_instrument_world* w, int instrument, const double pos[3], const double quat[4]);
bool tx_instrument_world_parked(const tx_instrument_world* w, int instrument);

// ODE's solver messages since start (an LCP it could not finish and recovered
// from); they are counted, not printed
int tx_instrument_ode_messages(void);

// The needle, when enabled. Its frame's pose; the swage end's pose (the
// thread's head: at the swage, the needle frame's orientation) and the tip's
// position. An instrument whose two jaws both touch the needle while they
// close holds it by a fixed joint; it lets go when its jaws open (the grip
// asks for more than they have). held_by: the holding instrument, -1 for none.
// grasps and releases count those events since the world was made.
void tx_instrument_world_needle(const tx_instrument_world* w, double pos[3], double quat[4]);
void tx_instrument_world_needle_swage(const tx_instrument_world* w, double pos[3], double quat[4]);
void tx_instrument_world_needle_tip(const tx_instrument_world* w, double pos[3]);
int tx_instrument_world_needle_held_by(const tx_instrument_world* w);
int tx_instrument_world_needle_grasps(const tx_instrument_world* w);
int tx_instrument_world_needle_releases(const tx_instrument_world* w);
// where the last grasp held it: the mean of the holder's contact points with it
void tx_instrument_world_needle_grasp_point(const tx_instrument_world* w, double p[3]);
// a force (N) on the needle at its swage end during the next step (the thread's pull)
void tx_instrument_world_needle_pull(tx_instrument_world* w, const double f[3]);

// The tip's HIP against the skin: the skin's force on the tip (N), where the
// skin's contact holds it (m), its direction and its tangent stiffness k
// (N/m) along it, as the skin last published them (tx_skin_contact). Each
// step until the next call the tip feels f + k n n^T (x - tip), never a
// pull: the skin's spring about where it held the tip, at the world's rate.
// A zero f lets go of the tip.
void tx_instrument_world_needle_tip_contact(tx_instrument_world* w, const double f[3], const double x[3], const double n[3],
                                            double k);
// the force the skin put on the tip in the last step (N)
void tx_instrument_world_needle_tip_force(const tx_instrument_world* w, double f[3]);

// Punctures: points the needle's arc passes through. Pin a point (world, m):
// its index, or -1 when TX_NEEDLE_PINS_MAX are pinned. Move it where the
// skin carries it. While the point lies within the arc's angles, the arc is
// held on it across the arc (pin_stiffness, pin_damping) and slides along it
// against at most pin_friction; before the tip reaches it it holds nothing,
// and once the swage has passed it (pulled through) it ends for good.
#define TX_NEEDLE_PINS_MAX 16
int tx_instrument_world_needle_pin(tx_instrument_world* w, const double point[3]);
void tx_instrument_world_needle_pin_move(tx_instrument_world* w, int pin, const double point[3]);
int tx_instrument_world_needle_pins(const tx_instrument_world* w);
// whether the needle has been pulled through a pin: its swage passed the
// point, after which that pin holds nothing ever again
bool tx_instrument_world_needle_pin_through(const tx_instrument_world* w, int pin);
// a pin's distance from the arc across it (m), and the arc's angle at the
// point nearest it (rad from the swage; outside [0, arc] when it holds nothing)
double tx_instrument_world_needle_pin_gap(const tx_instrument_world* w, int pin, double* angle);

// the needle's mass (kg) and inertia about its centre of mass, in its frame (ixx ixy ixz iyy iyz izz)
void tx_needle_mass(const tx_needle_params* n, double* mass, double com[3], double inertia[6]);

#endif
