// The instruments' ODE world (instrument_sim.h).
#include "instrument_sim.h"

#include "../../model/error.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <ode/ode.h>
#include <stdlib.h>
#include <string.h>

#define MAX_CONTACTS 8 // per geom pair
#define TX_JAW_STOP_GUARD 0.02 // rad
#define TX_NEEDLE_RELEASE_RAD 0.01 // a jaw this much wider than when it took the needle has let it go
#define STEEL_DENSITY 7900.0 // kg/m^3
// rad/s: ODE caps every body's spin at this (a radian a step at 1 kHz, far
// beyond a hand's), so no finite velocity from the solver turns a body's
// quaternion past what one step's integration can follow
#define TX_MAX_ANGULAR_SPEED 1000.0

typedef struct instrument {
  const tx_urdf* urdf;
  dBodyID body[TX_INSTRUMENT_LINKS_MAX];
  dJointID joint[TX_INSTRUMENT_LINKS_MAX]; // joint j of the URDF
  dJointID orient; // the angular motor of the root
  double hand_force[3];
  double start[3], start_q[4]; // where place() puts the root
  bool parked; // out of the world (tx_instrument_world_park)
  double target[TX_INSTRUMENT_LINKS_MAX]; // the jaw motors' target angles this step
  bool touch[TX_INSTRUMENT_LINKS_MAX]; // links that touched the needle this step
  double touch_sum[3]; // the needle's contact points with it this step, summed
  int touch_n;
  bool was_on; // both jaws were on the needle the step before: a grasp is the step they come on
  // what it overlapped where a fault put it back (owner bits, see owner()):
  // it passes through them without contact until they are apart
  unsigned ghost, ghost_now;
} instrument;

// a body's state, for going back to the last good step
typedef struct body_state {
  dReal pos[3], quat[4], vel[3], avel[3];
} body_state;
#define TX_WORLD_BODIES_MAX (TX_INSTRUMENTS_MAX * TX_INSTRUMENT_LINKS_MAX + 1)

#define NEEDLE_SEGMENTS 8 // capsules along the arc
#define NEEDLE_MASS_POINTS 512 // for its mass properties

struct tx_instrument_world {
  tx_instrument_sim_params p;
  dWorldID world;
  dSpaceID space;
  dJointGroupID contacts;
  instrument ins[TX_INSTRUMENTS_MAX];
  int n, ncontacts, resets, bad_inputs;
  dBodyID needle; // NULL without a needle
  double needle_com[3]; // in the needle frame
  dJointID hold; // the needle's fixed joint to its holder, or NULL
  dJointID foam; // its fixed joint to the world while it stands in foam, or NULL
  int held_by, grasps, releases;
  double grasp_point[3]; // the mean contact point of the last grasp
  double hold_angle[TX_INSTRUMENT_LINKS_MAX]; // the holder's jaw angles when it took the needle
  double pull[3]; // N at the swage, this step
  double tip_f[3], tip_x[3], tip_n[3], tip_k; // the skin's contact on the tip (tx_instrument_world_needle_tip_contact)
  double tip_force[3]; // what it put on the tip in the last step
  double pin[TX_NEEDLE_PINS_MAX][3]; // puncture points, world
  bool pin_through[TX_NEEDLE_PINS_MAX]; // the swage has passed it: the needle has left that hole for good
  int npins;
  double needle_mass;
  double depth; // deepest contact of the last step, m
  double dt; // the step being taken (s), for the contacts' softness
  // every body after the last step whose state and inputs were all finite
  dBodyID bodies[TX_WORLD_BODIES_MAX];
  body_state good[TX_WORLD_BODIES_MAX];
  int nbodies, faults, bad_contacts;
  int rebuilds; // steps ODE gave up inside (world_rebuild)
  // the world's own threading (ODE's self-threaded one): a step left by
  // longjmp leaves its job in it, so it is abandoned with that world
  dThreadingImplementationID threading;
};

static void save_good(tx_instrument_world* w);
static bool make_world(tx_instrument_world* w);
static void restore_good(tx_instrument_world* w);
static void enable(instrument* in, bool on);
static char needle_tag; // the needle's geoms carry its address

// ODE prints its solver's messages (an LCP it could not finish, then
// recovered) to stderr; they are counted instead
static atomic_int ode_messages;
static void count_message(int num, const char* msg, va_list ap) {
  (void)num, (void)msg, (void)ap;
  ode_messages++;
}
int tx_instrument_ode_messages(void) { return ode_messages; }

// ODE's internal checks (dDebug, and dError) end the process after their
// handler returns. Inside a step this thread's handler leaves the step by
// longjmp instead: ODE's state is then undefined, so the world is never
// stepped again but destroyed and rebuilt (world_rebuild). Outside a step
// the handler returns and ODE aborts, as it would without it.
static _Thread_local jmp_buf* ode_escape;
static void leave_step(int num, const char* msg, va_list ap) {
  (void)num, (void)msg, (void)ap;
  jmp_buf* j = ode_escape;
  ode_escape = NULL;
  if (j) longjmp(*j, 1);
}

tx_needle_params tx_needle_defaults(void) {
  // 19 mm along the arc over 3/8 of a circle: radius 19 mm / (0.75 pi)
  return (tx_needle_params){.enabled = false,
                            .radius = 0.019 / (0.75 * M_PI),
                            .wire_diameter = 0.0006,
                            .arc = 0.75 * M_PI,
                            .pos = {0.03, -0.05 + 0.0003, 0},
                            .quat = {M_SQRT1_2, -M_SQRT1_2, 0, 0}, // arc plane flat on the table, normal up
                            .held_by = -1,
                            .grasp_distance = 0.03,
                            .grasp_angle = 0.2};
}

tx_instrument_sim_params tx_instrument_sim_defaults(void) {
  return (tx_instrument_sim_params){.needle = tx_needle_defaults(),.coupling_k = 200,
                                    .coupling_b = 1,
                                    .orient_rate = 50,
                                    .orient_torque = 0.2,
                                    .max_force = 3.3,
                                    .jaw_gain = 40,
                                    .gravity = {0, -9.81, 0},
                                    .table_height = -0.05,
                                    .friction = 0.5,
                                    .erp = 0.2,
                                    .cfm = 1e-7,
                                    .contact_relax = TX_CONTACT_RELAX,
                                    .pin_stiffness = 200,
                                    .pin_damping = 0.1,
                                    .pin_friction = 0.02,
                                    .pin_reach = 0.005};
}

// ---- poses: position and unit quaternion (w, x, y, z)

static void qmul(const double a[4], const double b[4], double o[4]) {
  double r[4] = {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                 a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                 a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                 a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
  memcpy(o, r, sizeof r);
}
static void qrot(const double q[4], const double v[3], double o[3]) {
  double t[3] = {2 * (q[2] * v[2] - q[3] * v[1]), 2 * (q[3] * v[0] - q[1] * v[2]), 2 * (q[1] * v[1] - q[2] * v[0])};
  double r[3] = {v[0] + q[0] * t[0] + q[2] * t[2] - q[3] * t[1], v[1] + q[0] * t[1] + q[3] * t[0] - q[1] * t[2],
                 v[2] + q[0] * t[2] + q[1] * t[1] - q[2] * t[0]};
  memcpy(o, r, sizeof r);
}
// a * b for poses (p, q)
static void compose(const double pa[3], const double qa[4], const double pb[3], const double qb[4], double po[3],
                    double qo[4]) {
  double r[3];
  qrot(qa, pb, r);
  for (int k = 0; k < 3; k++) po[k] = pa[k] + r[k];
  qmul(qa, qb, qo);
}

// ---- contacts

// The normal row's diagonal of ODE's LCP matrix, J M^-1 J^T: 1/m + (r x n)^T
// I^-1 (r x n) summed over the contact's bodies (r from each centre of mass
// to the point, I in the world): the inverse of the effective mass the
// contact pushes on (kg^-1)
static double inverse_mass_along(dBodyID b, const dReal pos[3], const dReal n[3]) {
  if (!b) return 0;
  dMass m;
  dBodyGetMass(b, &m);
  const dReal* c = dBodyGetPosition(b);
  const dReal* R = dBodyGetRotation(b); // rows of 4: world = R body
  double r[3] = {pos[0] - c[0], pos[1] - c[1], pos[2] - c[2]};
  double rn[3] = {r[1] * n[2] - r[2] * n[1], r[2] * n[0] - r[0] * n[2], r[0] * n[1] - r[1] * n[0]}, v[3];
  for (int i = 0; i < 3; i++) v[i] = R[i] * rn[0] + R[4 + i] * rn[1] + R[8 + i] * rn[2]; // R^T (r x n): in the body
  // solve I x = v (I symmetric positive definite, body frame) by its adjugate
  const dReal* I = m.I;
  double a = I[0], b2 = I[1], c2 = I[2], d = I[5], e = I[6], f = I[10];
  double A = d * f - e * e, B = c2 * e - b2 * f, C = b2 * e - c2 * d, det = a * A + b2 * B + c2 * C;
  double x[3] = {(A * v[0] + B * v[1] + C * v[2]) / det, (B * v[0] + (a * f - c2 * c2) * v[1] + (b2 * c2 - a * e) * v[2]) / det,
                 (C * v[0] + (b2 * c2 - a * e) * v[1] + (a * d - b2 * b2) * v[2]) / det};
  return 1 / m.mass + v[0] * x[0] + v[1] * x[1] + v[2] * x[2];
}

// A contact's CFM: contact_relax x dt x its row's diagonal (above), or the
// world's CFM if that is softer. CFM / dt is what ODE adds to that diagonal,
// so every contact row is regularised by the same fraction of itself, which
// bounds the LCP's conditioning whatever the masses: a 42 mg needle welded
// to one instrument and pinched by another's jaws is otherwise an all but
// singular LCP (ODE's Dantzig solver aborts the process in dxLDLTRemove, or
// returns infinite velocities). The contact is then a spring k = erp m_eff /
// (relax dt^2) with damping (1 - erp) m_eff / (relax dt): the same natural
// frequency for every contact, sqrt(erp / relax) / dt, far above the step's
// (docs/instruments.md, "Contacts").
double tx_instrument_contact_cfm(const tx_instrument_sim_params* p, double inverse_mass, double dt) {
  double cfm = p->contact_relax * dt * inverse_mass;
  return isfinite(cfm) && cfm > p->cfm ? cfm : p->cfm;
}

// a geom's owner as a bit: instrument i is bit i, the needle the next, the
// static scene (the table) the last
static unsigned owner(const tx_instrument_world* w, dGeomID g) {
  void* d = dGeomGetData(g);
  if (d == &needle_tag) return 1u << TX_INSTRUMENTS_MAX;
  if (!dGeomGetBody(g) || !d) return 1u << (TX_INSTRUMENTS_MAX + 1);
  return 1u << ((const instrument*)d - w->ins);
}

// a contact ODE can take: finite point, unit normal, finite depth (a
// degenerate geom pair can give a zero normal, whose friction directions
// are then NaN)
static bool contact_ok(const dContactGeom* g) {
  double nn = g->normal[0] * g->normal[0] + g->normal[1] * g->normal[1] + g->normal[2] * g->normal[2];
  return isfinite(g->pos[0] + g->pos[1] + g->pos[2]) && isfinite(g->depth) && nn > 0.25 && nn < 4;
}

static void near(void* data, dGeomID a, dGeomID b) {
  tx_instrument_world* w = data;
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  if (!ba && !bb) return;
  // an instrument put back by a fault across another body passes through
  // it until they are apart: pushed out at once by 2 mm-deep contacts (a
  // welded needle pinched between two blades) is the LCP that ODE's solver
  // turns into NaN velocities, and ODE then aborts the process (dxNormalize4)
  {
    instrument* ia = dGeomGetData(a) != &needle_tag && ba ? dGeomGetData(a) : NULL;
    instrument* ib = dGeomGetData(b) != &needle_tag && bb ? dGeomGetData(b) : NULL;
    unsigned oa = owner(w, a), ob = owner(w, b);
    instrument* g = ia && (ia->ghost & ob) ? ia : ib && (ib->ghost & oa) ? ib : NULL;
    if (g) {
      dContactGeom one;
      if (dCollide(a, b, 1, &one, sizeof one) > 0) g->ghost_now |= g == ia ? ob : oa;
      return;
    }
  }
  // the links of one instrument do not touch each other: a jaw and its root
  // overlap at the pivot by design, and two jaws at their closed stop lie
  // face to face at zero depth, where a box-box test has no separating
  // direction to push along; the stop (lower limit 0) is where they meet
  if (ba && bb && dGeomGetData(a) == dGeomGetData(b)) return;
  // which instrument touches the needle (a held needle still touches its
  // holder's jaws: they stay closed on the wire, not through it)
  instrument* other = dGeomGetData(a) == &needle_tag ? dGeomGetData(b) : dGeomGetData(b) == &needle_tag ? dGeomGetData(a) : NULL;
  dBodyID other_body = dGeomGetData(a) == &needle_tag ? bb : ba;
  dContactGeom cg[MAX_CONTACTS];
  int n = dCollide(a, b, MAX_CONTACTS, cg, sizeof cg[0]), kept = 0;
  for (int i = 0; i < n; i++)
    if (contact_ok(&cg[i])) cg[kept++] = cg[i];
    else w->bad_contacts++;
  n = kept;
  for (int i = 0; i < n; i++) {
    dContact c = {0};
    c.geom = cg[i];
    // friction bounded by mu x the normal force, so touching faces at zero depth hold nothing
    c.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
    c.surface.mu = w->p.friction;
    c.surface.soft_erp = w->p.erp;
    double d = inverse_mass_along(ba, cg[i].pos, cg[i].normal) + inverse_mass_along(bb, cg[i].pos, cg[i].normal);
    c.surface.soft_cfm = tx_instrument_contact_cfm(&w->p, d, w->dt);
    dJointID j = dJointCreateContact(w->world, w->contacts, &c);
    dJointAttach(j, ba, bb);
    w->ncontacts++;
    w->depth = fmax(w->depth, cg[i].depth);
  }
  if (n > 0 && other)
    for (int l = 0; l < other->urdf->nlinks; l++)
      if (other->body[l] == other_body) other->touch[l] = true;
  for (int i = 0; other && i < n; i++, other->touch_n++)
    for (int k = 0; k < 3; k++) other->touch_sum[k] += cg[i].pos[k];
}

// ---- building

static void place(tx_instrument_world* w, instrument* in) {
  const tx_urdf* u = in->urdf;
  double lp[TX_INSTRUMENT_LINKS_MAX][3], lq[TX_INSTRUMENT_LINKS_MAX][4];
  memcpy(lp[0], in->start, sizeof lp[0]);
  memcpy(lq[0], in->start_q, sizeof lq[0]);
  for (int j = 0; j < u->njoints; j++) { // a joint's parent comes first (urdf.h)
    const tx_urdf_joint* jt = &u->joints[j];
    compose(lp[jt->parent], lq[jt->parent], jt->origin.p, jt->origin.q, lp[jt->child], lq[jt->child]);
  }
  for (int l = 0; l < u->nlinks; l++) {
    const tx_urdf_link* link = &u->links[l];
    double bp[3], bq[4];
    compose(lp[l], lq[l], link->com.p, link->com.q, bp, bq);
    dBodyID b = in->body[l];
    dBodySetPosition(b, bp[0], bp[1], bp[2]);
    dQuaternion q = {bq[0], bq[1], bq[2], bq[3]};
    dBodySetQuaternion(b, q);
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
  }
}

static bool build(tx_instrument_world* w, instrument* in) {
  const tx_urdf* u = in->urdf;
  for (int l = 0; l < u->nlinks; l++) {
    const tx_urdf_link* link = &u->links[l];
    dBodyID b = in->body[l] = dBodyCreate(w->world);
    dMass m;
    // the inertia is about the centre of mass in the inertial frame, which is the body's frame
    dMassSetParameters(&m, link->mass, 0, 0, 0, link->inertia[0], link->inertia[3], link->inertia[5], link->inertia[1],
                       link->inertia[2], link->inertia[4]);
    if (!dMassCheck(&m)) return tx_set_error("%s: link '%s': ODE refuses its mass", u->name, link->name), false;
    dBodySetMass(b, &m);
  }
  place(w, in);
  // geoms: where the URDF puts them in the link frame, offset from the body
  for (int l = 0; l < u->nlinks; l++) {
    const tx_urdf_link* link = &u->links[l];
    const dReal* bp = dBodyGetPosition(in->body[l]);
    const dReal* bq = dBodyGetQuaternion(in->body[l]);
    // the link frame from the body: body * com^-1
    double cq[4] = {link->com.q[0], -link->com.q[1], -link->com.q[2], -link->com.q[3]};
    double q[4] = {bq[0], bq[1], bq[2], bq[3]}, lq[4], lp[3], r[3];
    qmul(q, cq, lq);
    qrot(lq, link->com.p, r);
    for (int k = 0; k < 3; k++) lp[k] = bp[k] - r[k];
    for (int s = 0; s < link->nshapes; s++) {
      const tx_urdf_shape* sh = &link->shapes[s];
      // a long cylinder is a capsule of the same length: ODE's cylinder
      // against cylinder gives one contact point, on which two shafts roll
      double rad = sh->size[0], len = sh->size[1];
      dGeomID g = sh->kind == TX_URDF_BOX ? dCreateBox(w->space, sh->size[0], sh->size[1], sh->size[2])
                  : sh->kind == TX_URDF_CYLINDER && len > 4 * rad ? dCreateCapsule(w->space, rad, len - 2 * rad)
                  : sh->kind == TX_URDF_CYLINDER               ? dCreateCylinder(w->space, rad, len)
                                                               : dCreateSphere(w->space, rad);
      double gp[3], gq[4];
      compose(lp, lq, sh->pose.p, sh->pose.q, gp, gq);
      dGeomSetBody(g, in->body[l]);
      dGeomSetData(g, in); // which instrument it belongs to
      dGeomSetOffsetWorldPosition(g, gp[0], gp[1], gp[2]);
      dQuaternion dq = {gq[0], gq[1], gq[2], gq[3]};
      dGeomSetOffsetWorldQuaternion(g, dq);
    }
  }
  in->orient = dJointCreateAMotor(w->world, 0);
  dJointAttach(in->orient, in->body[0], 0);
  dJointSetAMotorMode(in->orient, dAMotorUser);
  dJointSetAMotorNumAxes(in->orient, 3);
  for (int k = 0; k < 3; k++) { // world axes
    dJointSetAMotorAxis(in->orient, k, 0, k == 0, k == 1, k == 2);
    dJointSetAMotorParam(in->orient, dParamFMax + k * dParamGroup, w->p.orient_torque);
  }
  // hinges at the jaw pivots, zero angle = as built (closed)
  for (int j = 0; j < u->njoints; j++) {
    const tx_urdf_joint* jt = &u->joints[j];
    dBodyID child = in->body[jt->child], parent = in->body[jt->parent];
    if (jt->fixed) {
      in->joint[j] = dJointCreateFixed(w->world, 0);
      dJointAttach(in->joint[j], child, parent);
      dJointSetFixed(in->joint[j]);
      continue;
    }
    // the joint frame in the world: the child's link frame at angle 0
    double pp[3], pq[4], jp[3], jq[4], axis[3];
    const dReal* bp = dBodyGetPosition(parent);
    const dReal* bq = dBodyGetQuaternion(parent);
    const tx_urdf_link* pl = &u->links[jt->parent];
    double q[4] = {bq[0], bq[1], bq[2], bq[3]}, cq[4] = {pl->com.q[0], -pl->com.q[1], -pl->com.q[2], -pl->com.q[3]}, r[3];
    qmul(q, cq, pq);
    qrot(pq, pl->com.p, r);
    for (int k = 0; k < 3; k++) pp[k] = bp[k] - r[k];
    compose(pp, pq, jt->origin.p, jt->origin.q, jp, jq);
    qrot(jq, jt->axis, axis);
    dJointID h = in->joint[j] = dJointCreateHinge(w->world, 0);
    // body 1 is the child: the angle is the child's turn about the axis
    dJointAttach(h, child, parent);
    dJointSetHingeAnchor(h, jp[0], jp[1], jp[2]);
    dJointSetHingeAxis(h, axis[0], axis[1], axis[2]);
    // The motor's target stays inside [lower, upper]; ODE's stops sit a
    // guard outside it, for what pushes harder than the motor. At a stop ODE
    // drives a motor pulling away with a fudged torque applied directly,
    // which flings a jaw of a gram; never starting at a stop avoids it.
    dJointSetHingeParam(h, dParamLoStop, jt->lower - TX_JAW_STOP_GUARD);
    dJointSetHingeParam(h, dParamHiStop, jt->upper + TX_JAW_STOP_GUARD);
    dJointSetHingeParam(h, dParamFMax, jt->effort);
    dJointSetHingeParam(h, dParamVel, 0);
  }
  return true;
}

void tx_needle_mass(const tx_needle_params* n, double* mass, double com[3], double inertia[6]) {
  // a thin wire: point masses along the arc (midpoint rule), then about their centre
  double a = n->wire_diameter / 2, m = STEEL_DENSITY * M_PI * a * a * n->radius * n->arc, dm = m / NEEDLE_MASS_POINTS;
  double c[3] = {0}, I[6] = {0};
  for (int k = 0; k < NEEDLE_MASS_POINTS; k++) {
    double phi = (k + 0.5) * n->arc / NEEDLE_MASS_POINTS;
    c[0] += dm * n->radius * cos(phi) / m, c[1] += dm * n->radius * sin(phi) / m;
  }
  for (int k = 0; k < NEEDLE_MASS_POINTS; k++) {
    double phi = (k + 0.5) * n->arc / NEEDLE_MASS_POINTS;
    double x = n->radius * cos(phi) - c[0], y = n->radius * sin(phi) - c[1];
    I[0] += dm * y * y, I[1] -= dm * x * y, I[3] += dm * x * x, I[5] += dm * (x * x + y * y);
  }
  // the wire's own section, so that no axis has zero inertia: a rod's m a^2 / 4 across, m a^2 / 2 along
  I[0] += m * a * a / 4, I[3] += m * a * a / 4, I[5] += m * a * a / 4;
  *mass = m;
  memcpy(com, c, sizeof c);
  memcpy(inertia, I, sizeof I);
}

static void needle_place(tx_instrument_world* w) {
  const tx_needle_params* n = &w->p.needle;
  double bp[3], q[4] = {1, 0, 0, 0};
  compose(n->pos, n->quat, w->needle_com, q, bp, q);
  dBodySetPosition(w->needle, bp[0], bp[1], bp[2]);
  dQuaternion dq = {q[0], q[1], q[2], q[3]};
  dBodySetQuaternion(w->needle, dq);
  dBodySetLinearVel(w->needle, 0, 0, 0);
  dBodySetAngularVel(w->needle, 0, 0, 0);
}

static void needle_build(tx_instrument_world* w) {
  const tx_needle_params* n = &w->p.needle;
  double m, I[6];
  tx_needle_mass(n, &m, w->needle_com, I);
  w->needle_mass = m;
  w->needle = dBodyCreate(w->world);
  dMass dm;
  dMassSetParameters(&dm, m, 0, 0, 0, I[0], I[3], I[5], I[1], I[2], I[4]);
  dBodySetMass(w->needle, &dm);
  needle_place(w);
  for (int k = 0; k < NEEDLE_SEGMENTS; k++) { // a capsule on each chord of the arc
    double p0 = k * n->arc / NEEDLE_SEGMENTS, p1 = (k + 1) * n->arc / NEEDLE_SEGMENTS;
    double a[3] = {n->radius * cos(p0), n->radius * sin(p0), 0}, b[3] = {n->radius * cos(p1), n->radius * sin(p1), 0};
    double mid[3] = {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, 0}, u[3] = {b[0] - a[0], b[1] - a[1], 0};
    double len = sqrt(u[0] * u[0] + u[1] * u[1]);
    u[0] /= len, u[1] /= len;
    // the capsule's z onto the chord u (in the arc plane, never -z): q = (1 + z.u, z x u) normalised
    double sq[4] = {1, -u[1], u[0], 0}, qn = sqrt(1 + u[0] * u[0] + u[1] * u[1]);
    for (int k2 = 0; k2 < 4; k2++) sq[k2] /= qn;
    double gp[3], gq[4];
    compose(n->pos, n->quat, mid, sq, gp, gq);
    dGeomID g = dCreateCapsule(w->space, n->wire_diameter / 2, len);
    dGeomSetBody(g, w->needle);
    dGeomSetData(g, &needle_tag);
    dGeomSetOffsetWorldPosition(g, gp[0], gp[1], gp[2]);
    dQuaternion dq = {gq[0], gq[1], gq[2], gq[3]};
    dGeomSetOffsetWorldQuaternion(g, dq);
  }
}

tx_instrument_world* tx_instrument_world_create(const tx_instrument_sim_params* p, const tx_urdf* const* urdfs, int n,
                                                const double (*start)[3]) {
  if (n < 0 || n > TX_INSTRUMENTS_MAX) return tx_set_error("at most %d instruments", TX_INSTRUMENTS_MAX), NULL;
  for (int i = 0; i < n; i++)
    if (urdfs[i]->nlinks > TX_INSTRUMENT_LINKS_MAX)
      return tx_set_error("%s: more than %d links", urdfs[i]->name, TX_INSTRUMENT_LINKS_MAX), NULL;
  if (!dInitODE2(0) || !dAllocateODEDataForThread(dAllocateMaskAll))
    return tx_set_error("ODE cannot be started"), NULL;
  dSetMessageHandler(count_message);
  dSetDebugHandler(leave_step);
  dSetErrorHandler(leave_step);
  tx_instrument_world* w = calloc(1, sizeof *w);
  if (!w) {
    dCloseODE();
    return tx_set_error("out of memory"), NULL;
  }
  w->p = *p;
  w->n = n;
  w->held_by = -1;
  tx_needle_params* nd = &w->p.needle;
  if (nd->enabled && nd->held_by >= n) {
    tx_instrument_world_destroy(w);
    return tx_set_error("the needle is held by instrument %d of %d", nd->held_by, n), NULL;
  }
  if (nd->enabled && nd->held_by >= 0) { // in the jaws: the arc's point at grasp_angle on the root's x axis
    double phi = nd->grasp_angle;
    const double* s = start[nd->held_by];
    nd->pos[0] = s[0] + nd->grasp_distance - nd->radius, nd->pos[1] = s[1], nd->pos[2] = s[2];
    nd->quat[0] = cos(-phi / 2), nd->quat[1] = nd->quat[2] = 0, nd->quat[3] = sin(-phi / 2);
  }
  if (nd->enabled && nd->foam && nd->held_by < 0) {
    nd->quat[0] = cos(-nd->grasp_angle / 2), nd->quat[1] = nd->quat[2] = 0, nd->quat[3] = sin(-nd->grasp_angle / 2);
  }
  for (int i = 0; i < n; i++) {
    w->ins[i].urdf = urdfs[i];
    memcpy(w->ins[i].start, start[i], sizeof w->ins[i].start);
    w->ins[i].start_q[0] = 1;
  }
  if (!make_world(w)) {
    tx_instrument_world_destroy(w);
    return NULL;
  }
  if (nd->enabled && nd->foam && nd->held_by < 0) { // the foam holds it where it stands
    w->foam = dJointCreateFixed(w->world, 0);
    dJointAttach(w->foam, w->needle, 0);
    dJointSetFixed(w->foam);
  }
  if (nd->enabled && nd->held_by >= 0) { // held as a grasp holds it, the jaws on the wire (not counted as a grasp)
    instrument* in = &w->ins[nd->held_by];
    w->hold = dJointCreateFixed(w->world, 0);
    dJointAttach(w->hold, w->needle, in->body[0]);
    dJointSetFixed(w->hold);
    w->held_by = nd->held_by;
    in->was_on = true;
    for (int j = 0; j < in->urdf->njoints; j++)
      w->hold_angle[j] = in->urdf->joints[j].fixed ? 0 : asin(fmin(1, nd->wire_diameter / 2 / nd->grasp_distance));
  }
  save_good(w);
  return w;
}

// the ODE world from the description: the table, the needle where its
// parameters put it, each instrument built at its start (its hinges' zero
// there), and the list of bodies; false with tx_error() set
static bool make_world(tx_instrument_world* w) {
  const tx_instrument_sim_params* p = &w->p;
  w->world = dWorldCreate();
  w->threading = dThreadingAllocateSelfThreadedImplementation();
  if (!w->threading) return tx_set_error("ODE cannot make a world"), false;
  dWorldSetStepThreadingImplementation(w->world, dThreadingImplementationGetFunctions(w->threading), w->threading);
  w->space = dSimpleSpaceCreate(0); // a dozen geoms: every pair is cheaper than a hash
  w->contacts = dJointGroupCreate(0);
  dWorldSetGravity(w->world, p->gravity[0], p->gravity[1], p->gravity[2]);
  dWorldSetERP(w->world, p->erp);
  dWorldSetCFM(w->world, p->cfm);
  dCreatePlane(w->space, 0, 1, 0, p->table_height);
  w->needle = NULL;
  if (p->needle.enabled) needle_build(w);
  for (int i = 0; i < w->n; i++)
    if (!build(w, &w->ins[i])) return false;
  w->nbodies = 0;
  for (int i = 0; i < w->n; i++)
    for (int l = 0; l < w->ins[i].urdf->nlinks; l++) w->bodies[w->nbodies++] = w->ins[i].body[l];
  if (w->needle) w->bodies[w->nbodies++] = w->needle;
  for (int b = 0; b < w->nbodies; b++) dBodySetMaxAngularSpeed(w->bodies[b], TX_MAX_ANGULAR_SPEED);
  return true;
}

static void free_world(tx_instrument_world* w) {
  if (w->contacts) dJointGroupDestroy(w->contacts);
  if (w->space) dSpaceDestroy(w->space); // and its geoms
  if (w->world) dWorldDestroy(w->world); // and its bodies and joints
  if (w->threading) dThreadingFreeImplementation(w->threading);
  w->contacts = NULL, w->space = NULL, w->world = NULL, w->threading = NULL;
}

// ODE gave up inside a step (an assertion, left by longjmp): its world is in
// an undefined state and is never stepped again. A new one is built from the
// description, every body put where the last good step left it, at rest,
// with the needle's hold (or its foam) as it was and the parked instruments
// out of it; then as for any fault (restore_good): each instrument passes
// through what it overlaps there until they are apart. What ODE allocated
// inside the step it left is not freed (it cannot be reached).
static void world_rebuild(tx_instrument_world* w) {
  bool foam = w->foam != NULL, hold = w->hold != NULL;
  // its threading still holds the job of the step left: freeing it asserts (ODE
  // would abort), so it is left as it is, a few hundred bytes lost per rebuild
  w->threading = NULL;
  free_world(w);
  w->foam = w->hold = NULL;
  if (!make_world(w)) return; // it was built from the same description once: cannot fail
  for (int b = 0; b < w->nbodies; b++) {
    const body_state* g = &w->good[b];
    dBodySetPosition(w->bodies[b], g->pos[0], g->pos[1], g->pos[2]);
    dBodySetQuaternion(w->bodies[b], g->quat);
  }
  if (foam) {
    w->foam = dJointCreateFixed(w->world, 0);
    dJointAttach(w->foam, w->needle, 0);
    dJointSetFixed(w->foam);
  }
  if (hold) {
    w->hold = dJointCreateFixed(w->world, 0);
    dJointAttach(w->hold, w->needle, w->ins[w->held_by].body[0]);
    dJointSetFixed(w->hold);
  }
  for (int i = 0; i < w->n; i++)
    if (w->ins[i].parked) enable(&w->ins[i], false);
  w->rebuilds++;
  restore_good(w);
}

void tx_instrument_world_destroy(tx_instrument_world* w) {
  if (!w) return;
  free_world(w);
  free(w);
  dCleanupODEAllDataForThread(); // this thread's ODE data (it may not be the one that made the world)
  dCloseODE();
}

void tx_instrument_world_link(const tx_instrument_world* w, int i, int l, double pos[3], double quat[4]) {
  const tx_urdf_link* link = &w->ins[i].urdf->links[l];
  const dReal* bp = dBodyGetPosition(w->ins[i].body[l]);
  const dReal* bq = dBodyGetQuaternion(w->ins[i].body[l]);
  double q[4] = {bq[0], bq[1], bq[2], bq[3]}, cq[4] = {link->com.q[0], -link->com.q[1], -link->com.q[2], -link->com.q[3]};
  double r[3];
  qmul(q, cq, quat);
  qrot(quat, link->com.p, r);
  for (int k = 0; k < 3; k++) pos[k] = bp[k] - r[k];
}

double tx_instrument_world_joint(const tx_instrument_world* w, int i, int j) {
  const instrument* in = &w->ins[i];
  return in->urdf->joints[j].fixed ? 0 : dJointGetHingeAngle(in->joint[j]);
}

void tx_instrument_world_hand_force(const tx_instrument_world* w, int i, double f[3]) {
  memcpy(f, w->ins[i].hand_force, 3 * sizeof *f);
}
int tx_instrument_world_contacts(const tx_instrument_world* w) { return w->ncontacts; }
int tx_instrument_world_resets(const tx_instrument_world* w) { return w->resets; }
int tx_instrument_world_bad_inputs(const tx_instrument_world* w) { return w->bad_inputs; }
int tx_instrument_world_faults(const tx_instrument_world* w) { return w->faults; }
int tx_instrument_world_rebuilds(const tx_instrument_world* w) { return w->rebuilds; }
int tx_instrument_world_bad_contacts(const tx_instrument_world* w) { return w->bad_contacts; }
unsigned tx_instrument_world_passing_through(const tx_instrument_world* w, int i) { return w->ins[i].ghost; }
double tx_instrument_world_depth(const tx_instrument_world* w) { return w->depth; }

static bool finite_input(const tx_instrument_input* d) {
  for (int k = 0; k < 3; k++)
    if (!isfinite(d->pos[k]) || !isfinite(d->vel[k])) return false;
  for (int k = 0; k < 4; k++)
    if (!isfinite(d->quat[k])) return false;
  return true; // a grip that is not finite closes the jaws (drive_jaws)
}

static void couple(tx_instrument_world* w, instrument* in, const tx_instrument_input* d) {
  if (!finite_input(d)) { // a device gone wrong pulls on nothing: the instrument stays where it is
    memset(in->hand_force, 0, sizeof in->hand_force);
    for (int k = 0; k < 3; k++) dJointSetAMotorParam(in->orient, dParamVel + k * dParamGroup, 0);
    w->bad_inputs++;
    return;
  }
  double x[3], q[4];
  tx_instrument_world_link(w, (int)(in - w->ins), 0, x, q);
  dVector3 v;
  dBodyGetPointVel(in->body[0], x[0], x[1], x[2], v);
  double f[3], n2 = 0;
  for (int k = 0; k < 3; k++) {
    f[k] = w->p.coupling_k * (d->pos[k] - x[k]) + w->p.coupling_b * (d->vel[k] - v[k]);
    n2 += f[k] * f[k];
  }
  double n = sqrt(n2);
  if (n > w->p.max_force) // the hand cannot push harder than the device can push back
    for (int k = 0; k < 3; k++) f[k] *= w->p.max_force / n;
  dBodyAddForceAtPos(in->body[0], f[0], f[1], f[2], x[0], x[1], x[2]);
  for (int k = 0; k < 3; k++) in->hand_force[k] = -f[k];
  // orientation: the angular motor turns the root towards the device's
  // orientation at orient_rate x the angle left, with at most orient_torque.
  // A motor is solved with the step (implicitly): an explicit torque spring
  // is unstable about a 5 mm shaft's axis, whose inertia is 1e-7 kg m^2.
  double qc[4] = {q[0], -q[1], -q[2], -q[3]}, e[4];
  qmul(d->quat, qc, e);
  double s = e[0] < 0 ? -1 : 1, vn = sqrt(e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
  double angle = isfinite(vn) ? 2 * atan2(vn, s * e[0]) : 0;
  for (int k = 0; k < 3; k++) {
    double omega = vn > 1e-12 && isfinite(vn) ? w->p.orient_rate * angle * s * e[k + 1] / vn : 0;
    dJointSetAMotorParam(in->orient, dParamVel + k * dParamGroup, omega);
  }
}

static void drive_jaws(tx_instrument_world* w, instrument* in, double grip) {
  int revolute = 0;
  for (int j = 0; j < in->urdf->njoints; j++) revolute += !in->urdf->joints[j].fixed;
  for (int j = 0; j < in->urdf->njoints; j++) {
    const tx_urdf_joint* jt = &in->urdf->joints[j];
    if (jt->fixed) continue;
    // the grip is the angle between the jaws: each of two opens by half of it
    double target = isfinite(grip) ? grip / (revolute > 1 ? 2 : 1) : jt->lower;
    target = fmin(fmax(target, jt->lower), jt->upper);
    in->target[j] = target;
    double speed = w->p.jaw_gain * (target - dJointGetHingeAngle(in->joint[j]));
    dJointSetHingeParam(in->joint[j], dParamVel, fmin(fmax(speed, -jt->velocity), jt->velocity));
  }
}

// jaws closing (or holding): no jaw's target above its angle
static bool closing(const instrument* in) {
  for (int j = 0; j < in->urdf->njoints; j++)
    if (!in->urdf->joints[j].fixed && in->target[j] > dJointGetHingeAngle(in->joint[j]) + 1e-3) return false;
  return true;
}
// the holder's jaws opened: one is TX_NEEDLE_RELEASE_RAD wider than when it took the needle
static bool opened(const tx_instrument_world* w, const instrument* in) {
  for (int j = 0; j < in->urdf->njoints; j++)
    if (!in->urdf->joints[j].fixed && dJointGetHingeAngle(in->joint[j]) > w->hold_angle[j] + TX_NEEDLE_RELEASE_RAD)
      return true;
  return false;
}

static void needle_grasp(tx_instrument_world* w) {
  if (w->held_by >= 0 && opened(w, &w->ins[w->held_by])) {
    dJointDestroy(w->hold);
    w->hold = NULL;
    w->held_by = -1;
    w->releases++;
  }
  // another instrument closing on a held needle takes it over (a handover):
  // one holder at a time, so the needle never binds two hands together
  for (int i = 0; i < w->n; i++) {
    instrument* in = &w->ins[i];
    // jaws passing through the wire (put back across it) have not come on it:
    // counted as on, they must leave it and close on it again to take it
    if (in->ghost & (1u << TX_INSTRUMENTS_MAX)) {
      in->was_on = true;
      continue;
    }
    int jaws = 0, touching = 0;
    for (int j = 0; j < in->urdf->njoints; j++)
      if (!in->urdf->joints[j].fixed) jaws++, touching += in->touch[in->urdf->joints[j].child];
    bool on = jaws >= 2 && touching == jaws, came_on = on && !in->was_on;
    in->was_on = on;
    if (i == w->held_by || !came_on || !closing(in)) continue;
    if (w->hold) dJointDestroy(w->hold); // handed over: no release event, the needle stays held
    if (w->foam) dJointDestroy(w->foam), w->foam = NULL; // taken out of the foam
    w->hold = dJointCreateFixed(w->world, 0);
    dJointAttach(w->hold, w->needle, in->body[0]);
    dJointSetFixed(w->hold);
    w->held_by = i;
    w->grasps++;
    for (int j = 0; j < in->urdf->njoints; j++)
      w->hold_angle[j] = in->urdf->joints[j].fixed ? 0 : dJointGetHingeAngle(in->joint[j]);
    for (int k = 0; k < 3; k++) w->grasp_point[k] = in->touch_sum[k] / in->touch_n;
  }
}

// the skin's force on the tip: f + k n n^T (x - tip) about where the skin
// held it, never a pull. Explicit at the world's step, so k is capped where
// it would be unstable on what the tip moves (the needle alone, or its holder's root too)
static void tip_push(tx_instrument_world* w, double dt) {
  memset(w->tip_force, 0, sizeof w->tip_force);
  double f0n = w->tip_f[0] * w->tip_n[0] + w->tip_f[1] * w->tip_n[1] + w->tip_f[2] * w->tip_n[2];
  if (!(f0n > 0)) return;
  double tip[3], m = w->needle_mass;
  tx_instrument_world_needle_tip(w, tip);
  if (w->held_by >= 0) {
    dMass hm;
    dBodyGetMass(w->ins[w->held_by].body[0], &hm);
    m += hm.mass;
  }
  double k = fmin(w->tip_k, m / (dt * dt));
  double d = 0;
  for (int c = 0; c < 3; c++) d += w->tip_n[c] * (w->tip_x[c] - tip[c]);
  // along n the force is |f0| + k d, never below zero; across n it stays f0's
  double along = fmax(0, f0n + k * d);
  for (int c = 0; c < 3; c++) w->tip_force[c] = w->tip_f[c] + (along - f0n) * w->tip_n[c];
  dBodyAddForceAtPos(w->needle, w->tip_force[0], w->tip_force[1], w->tip_force[2], tip[0], tip[1], tip[2]);
}

// a pin in the needle frame: the arc's angle nearest it, that point, the
// arc's tangent there, and the pin's offset from the arc across it
static double pin_locate(const tx_instrument_world* w, int i, double c[3], double t[3], double e[3]) {
  double o[3], q[4], d[3], r[3];
  tx_instrument_world_needle(w, o, q);
  for (int k = 0; k < 3; k++) d[k] = w->pin[i][k] - o[k];
  double qc[4] = {q[0], -q[1], -q[2], -q[3]};
  qrot(qc, d, r);
  double R = w->p.needle.radius, arc = w->p.needle.arc;
  double phi = atan2(r[1], r[0]);
  if (phi < -(2 * M_PI - arc) / 2) phi += 2 * M_PI; // the gap's middle splits the angles
  double cn[3] = {R * cos(phi), R * sin(phi), 0}, tn[3] = {-sin(phi), cos(phi), 0}, en[3];
  double along = 0;
  for (int k = 0; k < 3; k++) en[k] = r[k] - cn[k], along += en[k] * tn[k];
  for (int k = 0; k < 3; k++) en[k] -= along * tn[k];
  double cw[3];
  qrot(q, cn, cw);
  for (int k = 0; k < 3; k++) c[k] = o[k] + cw[k];
  qrot(q, tn, t);
  qrot(q, en, e);
  return phi;
}

// the arc held on a pin: one contact joint at the arc's nearest point, its
// normal towards the pin across the arc, as deep as the pin is off the arc.
// Its soft ERP and CFM make it the spring-damper (k, c) solved with the step
// (the needle alone weighs 40 mg: an explicit 200 N/m spring at 1 kHz would
// be unstable on it); its friction rows, without ODE's Approx1, are bounded by
// pin_friction in newtons whatever the normal force: the sliding along the arc
static void pin_hold(tx_instrument_world* w, int i, double dt) {
  double c[3], t[3], e[3];
  if (w->pin_through[i]) return;
  double phi = pin_locate(w, i, c, t, e);
  // the swage gone past the point: the needle is out of that hole, and stays
  // out wherever it is taken (the point, met again by the arc metres away,
  // would otherwise pull it back as a spring stretched that far)
  if (phi < 0) {
    w->pin_through[i] = true;
    return;
  }
  if (phi > w->p.needle.arc) return; // the tip is not through it yet
  double gap = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  if (gap > w->p.pin_reach) return; // let go: a spring stretched that far would fling the needle
  dContact ct = {0};
  ct.surface.mode = dContactSoftERP | dContactSoftCFM | dContactFDir1;
  ct.surface.mu = w->p.pin_friction;
  double hk = dt * w->p.pin_stiffness, den = hk + w->p.pin_damping;
  if (!(den > 0)) return;
  ct.surface.soft_erp = hk / den;
  ct.surface.soft_cfm = 1 / den;
  double n[3];
  if (gap > 1e-12) for (int k = 0; k < 3; k++) n[k] = e[k] / gap;
  else { // on the arc: any direction across it; the one towards the centre
    double o[3], q[4];
    tx_instrument_world_needle(w, o, q);
    double r = 0;
    for (int k = 0; k < 3; k++) n[k] = o[k] - c[k], r += n[k] * n[k];
    for (int k = 0; k < 3; k++) n[k] /= sqrt(r);
  }
  for (int k = 0; k < 3; k++) ct.geom.pos[k] = c[k], ct.geom.normal[k] = n[k], ct.fdir1[k] = t[k];
  ct.geom.depth = gap;
  dJointID j = dJointCreateContact(w->world, w->contacts, &ct);
  dJointAttach(j, w->needle, 0);
}

// what instrument i overlaps now (owner bits): each of its geoms against
// every enabled geom not its own
static unsigned overlaps(const tx_instrument_world* w, const instrument* in) {
  unsigned mine = 1u << (in - w->ins), set = 0;
  int ng = dSpaceGetNumGeoms(w->space);
  for (int l = 0; l < in->urdf->nlinks; l++)
    for (dGeomID g = dBodyGetFirstGeom(in->body[l]); g; g = dBodyGetNextGeom(g))
      for (int k = 0; k < ng; k++) {
        dGeomID h = dSpaceGetGeom(w->space, k);
        unsigned o = owner(w, h);
        dContactGeom one;
        if (o != mine && !(set & o) && dGeomIsEnabled(h) && dCollide(g, h, 1, &one, sizeof one) > 0) set |= o;
      }
  return set;
}

static bool finite3(const dReal* v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

// every body's state and the step's inputs on it (the forces and torques
// added, the motors' speeds) finite: what ODE may step without turning a
// NaN into a quaternion it cannot normalise (it aborts the process)
static bool step_inputs_ok(const tx_instrument_world* w) {
  for (int b = 0; b < w->nbodies; b++) {
    dBodyID body = w->bodies[b];
    if (!dBodyIsEnabled(body)) continue;
    const dReal* q = dBodyGetQuaternion(body);
    if (!finite3(dBodyGetPosition(body)) || !finite3(dBodyGetLinearVel(body)) || !finite3(dBodyGetAngularVel(body)) ||
        !finite3(dBodyGetForce(body)) || !finite3(dBodyGetTorque(body)) || !isfinite(q[3]) || !finite3(q))
      return false;
  }
  for (int i = 0; i < w->n; i++) {
    const instrument* in = &w->ins[i];
    if (in->parked) continue;
    for (int k = 0; k < 3; k++)
      if (!isfinite(dJointGetAMotorParam(in->orient, dParamVel + k * dParamGroup))) return false;
    for (int j = 0; j < in->urdf->njoints; j++)
      if (!in->urdf->joints[j].fixed && !isfinite(dJointGetHingeParam(in->joint[j], dParamVel))) return false;
  }
  return true;
}

static bool state_ok(const tx_instrument_world* w) {
  for (int b = 0; b < w->nbodies; b++) {
    const dReal* q = dBodyGetQuaternion(w->bodies[b]);
    if (!finite3(dBodyGetPosition(w->bodies[b])) || !finite3(dBodyGetLinearVel(w->bodies[b])) ||
        !finite3(dBodyGetAngularVel(w->bodies[b])) || !isfinite(q[3]) || !finite3(q))
      return false;
  }
  return true;
}

static void save_good(tx_instrument_world* w) {
  for (int b = 0; b < w->nbodies; b++) {
    body_state* g = &w->good[b];
    memcpy(g->pos, dBodyGetPosition(w->bodies[b]), sizeof g->pos);
    memcpy(g->quat, dBodyGetQuaternion(w->bodies[b]), sizeof g->quat);
    memcpy(g->vel, dBodyGetLinearVel(w->bodies[b]), sizeof g->vel);
    memcpy(g->avel, dBodyGetAngularVel(w->bodies[b]), sizeof g->avel);
  }
}

// a fault: every body back where it was after the last good step, at rest
// (its velocities may be what led to the fault), nothing left of this
// step's forces, no hand force; each instrument then passes through what it
// overlaps there until they are apart, so the same pinch is not solved again
static void restore_good(tx_instrument_world* w) {
  for (int b = 0; b < w->nbodies; b++) {
    const body_state* g = &w->good[b];
    dBodySetPosition(w->bodies[b], g->pos[0], g->pos[1], g->pos[2]);
    dBodySetQuaternion(w->bodies[b], g->quat);
    dBodySetLinearVel(w->bodies[b], 0, 0, 0);
    dBodySetAngularVel(w->bodies[b], 0, 0, 0);
    dBodySetForce(w->bodies[b], 0, 0, 0);
    dBodySetTorque(w->bodies[b], 0, 0, 0);
  }
  for (int i = 0; i < w->n; i++) {
    memset(w->ins[i].hand_force, 0, sizeof w->ins[i].hand_force);
    w->ins[i].ghost = w->ins[i].parked ? 0 : overlaps(w, &w->ins[i]);
  }
  w->faults++;
  w->resets++;
}

void tx_instrument_world_step(tx_instrument_world* w, const tx_instrument_input* in, double dt) {
  for (int i = 0; i < w->n; i++) {
    if (w->ins[i].parked) continue;
    couple(w, &w->ins[i], &in[i]);
    drive_jaws(w, &w->ins[i], in[i].grip);
  }
  w->ncontacts = 0;
  w->depth = 0;
  for (int i = 0; i < w->n; i++) {
    memset(w->ins[i].touch, 0, sizeof w->ins[i].touch);
    memset(w->ins[i].touch_sum, 0, sizeof w->ins[i].touch_sum);
    w->ins[i].touch_n = 0;
  }
  if (w->needle) {
    double sp[3], sq[4];
    tx_instrument_world_needle_swage(w, sp, sq);
    dBodyAddForceAtPos(w->needle, w->pull[0], w->pull[1], w->pull[2], sp[0], sp[1], sp[2]);
    memset(w->pull, 0, sizeof w->pull);
    tip_push(w, dt);
    for (int i = 0; i < w->npins; i++) pin_hold(w, i, dt);
  }
  w->dt = dt;
  dSpaceCollide(w->space, w, near);
  for (int i = 0; i < w->n; i++) w->ins[i].ghost = w->ins[i].ghost_now, w->ins[i].ghost_now = 0;
  if (!(dt > 0) || !isfinite(dt) || !step_inputs_ok(w)) { // never handed to ODE
    dJointGroupEmpty(w->contacts);
    restore_good(w);
    return;
  }
  // ODE asserting inside the step (an all but singular LCP turned into a
  // quaternion it cannot normalise) comes back here instead of aborting
  jmp_buf escape;
  if (setjmp(escape)) {
    world_rebuild(w);
    return;
  }
  ode_escape = &escape;
  dWorldStep(w->world, dt);
  ode_escape = NULL;
  dJointGroupEmpty(w->contacts);
  if (!state_ok(w)) {
    restore_good(w);
    return;
  }
  save_good(w);
  if (w->needle) needle_grasp(w);
}

// a parked instrument's bodies and geoms are disabled together: ODE neither
// steps them nor collides them, and no joint ties them to an enabled body
static void enable(instrument* in, bool on) {
  for (int l = 0; l < in->urdf->nlinks; l++) {
    if (on) dBodyEnable(in->body[l]);
    else dBodyDisable(in->body[l]);
    for (dGeomID g = dBodyGetFirstGeom(in->body[l]); g; g = dBodyGetNextGeom(g))
      if (on) dGeomEnable(g);
      else dGeomDisable(g);
  }
}

void tx_instrument_world_park(tx_instrument_world* w, int i, const double pos[3]) {
  instrument* in = &w->ins[i];
  if (in->parked) return;
  if (w->hold && w->held_by == i) dJointDestroy(w->hold), w->hold = NULL, w->held_by = -1, w->releases++;
  in->was_on = false;
  memcpy(in->start, pos, sizeof in->start);
  in->start_q[0] = 1, in->start_q[1] = in->start_q[2] = in->start_q[3] = 0;
  for (int j = 0; j < in->urdf->njoints; j++)
    if (!in->urdf->joints[j].fixed) dJointSetHingeParam(in->joint[j], dParamVel, 0);
  place(w, in);
  memset(in->hand_force, 0, sizeof in->hand_force);
  enable(in, false);
  in->parked = true;
  in->ghost = in->ghost_now = 0;
  save_good(w);
}

void tx_instrument_world_take(tx_instrument_world* w, int i, const double pos[3], const double quat[4]) {
  instrument* in = &w->ins[i];
  memcpy(in->start, pos, sizeof in->start);
  double n = sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]);
  bool ok = isfinite(n) && n > 1e-9 && isfinite(pos[0] + pos[1] + pos[2]);
  for (int k = 0; k < 4; k++) in->start_q[k] = ok ? quat[k] / n : k == 0;
  if (!ok) memset(in->start, 0, sizeof in->start);
  place(w, in);
  memset(in->hand_force, 0, sizeof in->hand_force);
  enable(in, true);
  in->parked = false;
  // taken where the hand is, it may start across another body (the
  // scissors' closed blades through the wire of a needle the forceps hold):
  // pushed out at once, that pinch is the all but singular LCP ODE's exact
  // solver gives up on. It passes through what it overlaps until they are
  // apart, and its jaws, counted as already on the needle, must leave it and
  // close on it again to take it (needle_grasp)
  in->ghost = overlaps(w, in);
  in->ghost_now = 0;
  save_good(w); // placed by hand: the state to go back to
}

bool tx_instrument_world_parked(const tx_instrument_world* w, int i) { return w->ins[i].parked; }

void tx_instrument_world_needle(const tx_instrument_world* w, double pos[3], double quat[4]) {
  const dReal* bp = dBodyGetPosition(w->needle);
  const dReal* bq = dBodyGetQuaternion(w->needle);
  double r[3];
  for (int k = 0; k < 4; k++) quat[k] = bq[k];
  qrot(quat, w->needle_com, r);
  for (int k = 0; k < 3; k++) pos[k] = bp[k] - r[k];
}

void tx_instrument_world_needle_swage(const tx_instrument_world* w, double pos[3], double quat[4]) {
  double c[3], swage[3] = {w->p.needle.radius, 0, 0}, r[3];
  tx_instrument_world_needle(w, c, quat);
  qrot(quat, swage, r);
  for (int k = 0; k < 3; k++) pos[k] = c[k] + r[k];
}

void tx_instrument_world_needle_tip(const tx_instrument_world* w, double pos[3]) {
  double c[3], q[4], r[3];
  double tip[3] = {w->p.needle.radius * cos(w->p.needle.arc), w->p.needle.radius * sin(w->p.needle.arc), 0};
  tx_instrument_world_needle(w, c, q);
  qrot(q, tip, r);
  for (int k = 0; k < 3; k++) pos[k] = c[k] + r[k];
}

int tx_instrument_world_needle_held_by(const tx_instrument_world* w) { return w->held_by; }
int tx_instrument_world_needle_grasps(const tx_instrument_world* w) { return w->grasps; }
int tx_instrument_world_needle_releases(const tx_instrument_world* w) { return w->releases; }
void tx_instrument_world_needle_pull(tx_instrument_world* w, const double f[3]) {
  for (int k = 0; k < 3; k++) w->pull[k] += isfinite(f[k]) ? f[k] : 0;
}
void tx_instrument_world_needle_grasp_point(const tx_instrument_world* w, double p[3]) {
  memcpy(p, w->grasp_point, 3 * sizeof *p);
}

void tx_instrument_world_needle_tip_contact(tx_instrument_world* w, const double f[3], const double x[3], const double n[3],
                                            double k) {
  bool ok = isfinite(k) && k >= 0;
  for (int c = 0; c < 3; c++) ok = ok && isfinite(f[c]) && isfinite(x[c]) && isfinite(n[c]);
  for (int c = 0; c < 3; c++) { // what is not finite lets go of the tip
    w->tip_f[c] = ok ? f[c] : 0, w->tip_x[c] = ok ? x[c] : 0, w->tip_n[c] = ok ? n[c] : 0;
  }
  w->tip_k = ok ? k : 0;
}
void tx_instrument_world_needle_tip_force(const tx_instrument_world* w, double f[3]) {
  memcpy(f, w->tip_force, 3 * sizeof *f);
}

int tx_instrument_world_needle_pin(tx_instrument_world* w, const double point[3]) {
  if (!w->needle || w->npins >= TX_NEEDLE_PINS_MAX) return -1;
  for (int k = 0; k < 3; k++)
    if (!isfinite(point[k])) return -1;
  memcpy(w->pin[w->npins], point, sizeof w->pin[0]);
  w->pin_through[w->npins] = false;
  return w->npins++;
}
void tx_instrument_world_needle_pin_move(tx_instrument_world* w, int i, const double point[3]) {
  if (i < 0 || i >= w->npins || !isfinite(point[0] + point[1] + point[2])) return;
  memcpy(w->pin[i], point, sizeof w->pin[0]);
}
int tx_instrument_world_needle_pins(const tx_instrument_world* w) { return w->npins; }
bool tx_instrument_world_needle_pin_through(const tx_instrument_world* w, int i) {
  return i >= 0 && i < w->npins && w->pin_through[i];
}
double tx_instrument_world_needle_pin_gap(const tx_instrument_world* w, int i, double* angle) {
  double c[3], t[3], e[3];
  double phi = pin_locate(w, i, c, t, e);
  if (angle) *angle = phi;
  return sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
}
