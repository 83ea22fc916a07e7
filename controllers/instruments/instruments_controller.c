// physics.instruments: the instruments of the two hands on ODE
// (instrument_sim.h), read from their URDFs at configure, stepped at the
// controller's rate (one ODE step per tick), published as typed components.
#include "instruments_controller.h"

#include "instrument_desc.h"
#include "instrument_sim.h"

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct instruments {
  tx_instrument_sim_params p;
  tx_instrument_desc* desc[TX_INSTRUMENTS_MAX];
  int n;
  tx_instrument_world* world;
  tx_port dev_pose[TX_INSTRUMENTS_MAX], dev_vel[TX_INSTRUMENTS_MAX], dev_grip[TX_INSTRUMENTS_MAX];
  tx_port pose[TX_INSTRUMENTS_MAX], links[TX_INSTRUMENTS_MAX], model[TX_INSTRUMENTS_MAX];
  tx_warning bad_input, reset;
  tx_result contacts_max, force_max, grasps, releases;
  tx_port needle_pose, needle_swage, events;
  int grasps_seen, releases_seen, last_holder;
  int bad_seen, resets_seen, contacts_most;
  double force_most;
} instruments;

static const tx_param_def params[] = {
    {"instrument0", TX_PARAM_STR, NULL, 0, 0, 0, "needle_holder",
     "held by device0: a name in assets/instruments/ or a path to a .urdf"},
    {"instrument1", TX_PARAM_STR, NULL, 0, 0, 0, "", "held by device1; \"\": none"},
    {"coupling_stiffness", TX_PARAM_NUM, "N/m", 0, 1e5, 200, NULL,
     "the virtual coupling's spring between a device and its instrument's root"},
    {"coupling_damping", TX_PARAM_NUM, "N s/m", 0, 1e3, 1, NULL, "the virtual coupling's damper"},
    {"max_force_n", TX_PARAM_NUM, "N", 0, 100, 3.3, NULL, "the coupling force is clamped to this (the device's limit)"},
    {"jaw_gain", TX_PARAM_NUM, "1/s", 0, 1e4, 40, NULL,
     "a jaw motor's speed is jaw_gain x its angle error, within the joint's velocity limit"},
    {"orient_rate", TX_PARAM_NUM, "1/s", 0, 1e4, 50, NULL,
     "the root turns towards its device's orientation at this rate x the angle left"},
    {"orient_torque", TX_PARAM_NUM, "N m", 0, 100, 0.2, NULL, "the most torque that turning uses"},
    {"gravity_m_s2", TX_PARAM_NUM, "m/s^2", 0, 100, 9.81, NULL, "gravity, down (-y)"},
    {"table_height_m", TX_PARAM_NUM, "m", -10, 10, -0.05, NULL, "the rigid scene: a table filling y < table_height_m"},
    {"friction", TX_PARAM_NUM, "1", 0, 10, 0.5, NULL, "Coulomb friction coefficient of every contact"},
    {"needle", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "a curved needle lies on the table, for the instruments to take"},
    {"needle_circle", TX_PARAM_NUM, "1", 0.25, 0.625, 0.375, NULL, "the needle's arc as a fraction of a circle: 3/8 or 1/2"},
    {"needle_length_m", TX_PARAM_NUM, "m", 0.003, 0.1, 0.019, NULL, "the needle's length along its arc"},
    {"needle_wire_diameter_m", TX_PARAM_NUM, "m", 5e-5, 0.003, 0.0006, NULL, "the needle's wire diameter"},
    {"needle_x_m", TX_PARAM_NUM, "m", -10, 10, 0.03, NULL, "where its circle's centre lies on the table, x"},
    {"needle_z_m", TX_PARAM_NUM, "m", -10, 10, 0, NULL, "where its circle's centre lies on the table, z"},
};

// a bare name is a shipped instrument; anything else is a path
static void resolve(const char* given, char* path, size_t n) {
  size_t len = strlen(given);
  if (strchr(given, '/') || (len > 5 && strcmp(given + len - 5, ".urdf") == 0)) snprintf(path, n, "%s", given);
  else snprintf(path, n, "%s/instruments/%s.urdf", TX_ASSET_DIR, given);
}

static int configure(tx_setup* s, void** self) {
  instruments* m = calloc(1, sizeof *m);
  if (!m) return -1;
  *self = m;
  m->p = tx_instrument_sim_defaults();
  m->p.coupling_k = tx_table_num(s, "coupling_stiffness");
  m->p.coupling_b = tx_table_num(s, "coupling_damping");
  m->p.max_force = tx_table_num(s, "max_force_n");
  m->p.jaw_gain = tx_table_num(s, "jaw_gain");
  m->p.orient_rate = tx_table_num(s, "orient_rate");
  m->p.orient_torque = tx_table_num(s, "orient_torque");
  m->p.gravity[0] = m->p.gravity[2] = 0;
  m->p.gravity[1] = -tx_table_num(s, "gravity_m_s2");
  m->p.table_height = tx_table_num(s, "table_height_m");
  m->p.friction = tx_table_num(s, "friction");
  tx_needle_params* nd = &m->p.needle;
  nd->enabled = tx_table_bool(s, "needle");
  nd->arc = 2 * M_PI * tx_table_num(s, "needle_circle");
  nd->radius = tx_table_num(s, "needle_length_m") / nd->arc;
  nd->wire_diameter = tx_table_num(s, "needle_wire_diameter_m");
  if (nd->wire_diameter > nd->radius) return tx_setup_fail(s, "needle_wire_diameter_m", "thicker than the needle's radius");
  nd->pos[0] = tx_table_num(s, "needle_x_m");
  nd->pos[1] = m->p.table_height + nd->wire_diameter / 2;
  nd->pos[2] = tx_table_num(s, "needle_z_m");
  for (int i = 0; i < TX_INSTRUMENTS_MAX; i++) {
    char key[32], path[2048], name[TX_NAME_MAX];
    snprintf(key, sizeof key, "instrument%d", i);
    const char* given = tx_table_str(s, key);
    if (!given || !*given) continue;
    if (i > m->n) return tx_setup_fail(s, key, "instrument%d is given without instrument%d", i, m->n);
    resolve(given, path, sizeof path);
    m->desc[i] = tx_instrument_desc_load(path);
    if (!m->desc[i]) return tx_setup_fail(s, key, "%s", tx_error());
    if (m->desc[i]->urdf->nlinks > TX_INSTRUMENT_LINKS_MAX)
      return tx_setup_fail(s, key, "%s: more than %d links", path, TX_INSTRUMENT_LINKS_MAX);
    m->n = i + 1;
    snprintf(name, sizeof name, "device%d.pose", i);
    m->dev_pose[i] = TX_READ_OF(s, name, tx_pose);
    snprintf(name, sizeof name, "device%d.velocity", i);
    m->dev_vel[i] = TX_READ_OF(s, name, tx_velocity);
    snprintf(name, sizeof name, "device%d.grip", i);
    m->dev_grip[i] = TX_READ_OF(s, name, tx_device_grip);
    snprintf(name, sizeof name, "instrument%d.pose", i);
    m->pose[i] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_instrument_pose, 1));
    snprintf(name, sizeof name, "instrument%d.links", i);
    m->links[i] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_pose, (uint32_t)m->desc[i]->urdf->nlinks));
    snprintf(name, sizeof name, "instrument%d.force_model", i);
    m->model[i] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_force_model, 1));
  }
  if (m->n == 0) return tx_setup_fail(s, "instrument0", "no instrument: give instrument0");
  m->bad_input = tx_setup_warning(s, "device_not_finite");
  m->reset = tx_setup_warning(s, "reset");
  m->contacts_max = tx_setup_result(s, "contacts_max");
  if (nd->enabled) {
    m->needle_pose = tx_setup_write(s, &TX_COMPONENT_OF("needle.pose", tx_pose, 1));
    m->needle_swage = tx_setup_write(s, &TX_COMPONENT_OF("needle.swage", tx_pose, 1));
    m->events = tx_setup_emit(s, "instruments.events", 64);
    m->grasps = tx_setup_result(s, "needle_grasps");
    m->releases = tx_setup_result(s, "needle_releases");
  }
  m->force_max = tx_setup_result(s, "coupling_force_max_n");
  return 0;
}

// the world is made on the thread that steps it: ODE keeps per-thread data
static int init(tx_ctx* c, void* self) {
  instruments* m = self;
  tx_instrument_world_destroy(m->world); // each run starts afresh
  m->world = NULL;
  const tx_urdf* urdfs[TX_INSTRUMENTS_MAX];
  double start[TX_INSTRUMENTS_MAX][3] = {{0}};
  for (int i = 0; i < m->n; i++) {
    urdfs[i] = m->desc[i]->urdf;
    tx_snapshot p = tx_read(c, m->dev_pose[i]);
    if (p.seq) memcpy(start[i], ((const tx_pose*)p.data)->pos, sizeof start[i]);
    for (int k = 0; k < 3; k++)
      if (!isfinite(start[i][k])) start[i][k] = 0;
  }
  m->world = tx_instrument_world_create(&m->p, urdfs, m->n, (const double(*)[3])start);
  if (!m->world) {
    tx_stop_run(c, "physics.instruments: %s", tx_error());
    return -1;
  }
  return 0;
}

static void step(tx_ctx* c, void* self) {
  instruments* m = self;
  tx_instrument_input in[TX_INSTRUMENTS_MAX];
  for (int i = 0; i < m->n; i++) {
    tx_snapshot p = tx_read(c, m->dev_pose[i]), v = tx_read(c, m->dev_vel[i]), g = tx_read(c, m->dev_grip[i]);
    in[i] = (tx_instrument_input){.quat = {1, 0, 0, 0}};
    if (p.seq) {
      memcpy(in[i].pos, ((const tx_pose*)p.data)->pos, sizeof in[i].pos);
      memcpy(in[i].quat, ((const tx_pose*)p.data)->quat, sizeof in[i].quat);
    } else { // no device yet: hold the instrument where it is
      double q[4];
      tx_instrument_world_link(m->world, i, 0, in[i].pos, q);
    }
    if (v.seq) memcpy(in[i].vel, ((const tx_velocity*)v.data)->v, sizeof in[i].vel);
    in[i].grip = g.seq ? ((const tx_device_grip*)g.data)->grip : 0;
  }
  tx_instrument_world_step(m->world, in, 1.0 / tx_rate(c));
  if (tx_instrument_world_bad_inputs(m->world) > m->bad_seen) tx_warn(c, m->bad_input);
  if (tx_instrument_world_resets(m->world) > m->resets_seen) tx_warn(c, m->reset);
  m->bad_seen = tx_instrument_world_bad_inputs(m->world);
  m->resets_seen = tx_instrument_world_resets(m->world);
  if (tx_instrument_world_contacts(m->world) > m->contacts_most) m->contacts_most = tx_instrument_world_contacts(m->world);
  if (m->p.needle.enabled) {
    tx_pose* np = tx_write(c, m->needle_pose);
    tx_instrument_world_needle(m->world, np->pos, np->quat);
    tx_pose* sw = tx_write(c, m->needle_swage);
    tx_instrument_world_needle_swage(m->world, sw->pos, sw->quat);
    int held = tx_instrument_world_needle_held_by(m->world);
    if (tx_instrument_world_needle_grasps(m->world) > m->grasps_seen) {
      tx_event e = {.kind = TX_EVENT_GRASP, .source = (uint32_t)held};
      tx_instrument_world_needle_grasp_point(m->world, e.grasp.point);
      e.grasp.jaw = 0;
      for (int j = 0; j < m->desc[held]->urdf->njoints; j++) e.grasp.jaw += tx_instrument_world_joint(m->world, held, j);
      tx_emit(c, m->events, &e);
    }
    if (tx_instrument_world_needle_releases(m->world) > m->releases_seen)
      tx_emit(c, m->events, &(tx_event){.kind = TX_EVENT_RELEASE, .source = (uint32_t)m->last_holder});
    if (held >= 0) m->last_holder = held;
    m->grasps_seen = tx_instrument_world_needle_grasps(m->world);
    m->releases_seen = tx_instrument_world_needle_releases(m->world);
  }
  for (int i = 0; i < m->n; i++) {
    const tx_urdf* u = m->desc[i]->urdf;
    tx_pose* links = tx_write(c, m->links[i]);
    for (int l = 0; l < u->nlinks; l++) tx_instrument_world_link(m->world, i, l, links[l].pos, links[l].quat);
    tx_instrument_pose* ip = tx_write(c, m->pose[i]);
    memcpy(ip->pos, links[0].pos, sizeof ip->pos);
    memcpy(ip->quat, links[0].quat, sizeof ip->quat);
    ip->jaw = 0;
    for (int j = 0; j < u->njoints; j++) ip->jaw += tx_instrument_world_joint(m->world, i, j);
    // F = f0 + K (x - x0) at the haptics rate: the coupling's spring about
    // where the hand was, unless the clamp holds it (then a constant)
    tx_force_model* fm = tx_write(c, m->model[i]);
    memset(fm, 0, sizeof *fm);
    tx_instrument_world_hand_force(m->world, i, fm->f0);
    memcpy(fm->x0, in[i].pos, sizeof fm->x0);
    double f = sqrt(fm->f0[0] * fm->f0[0] + fm->f0[1] * fm->f0[1] + fm->f0[2] * fm->f0[2]);
    if (f > m->force_most) m->force_most = f;
    if (f < m->p.max_force * (1 - 1e-9))
      for (int k = 0; k < 3; k++) fm->k[4 * k] = -m->p.coupling_k;
    if (!isfinite(f)) memset(fm, 0, sizeof *fm);
  }
}

static void finish(tx_ctx* c, void* self) {
  instruments* m = self;
  if (m->p.needle.enabled) {
    tx_set_result(c, m->grasps, m->grasps_seen);
    tx_set_result(c, m->releases, m->releases_seen);
  }
  // the world goes on the thread that made and stepped it, with ODE's data for that thread
  tx_instrument_world_destroy(m->world);
  m->world = NULL;
  tx_set_result(c, m->contacts_max, m->contacts_most);
  tx_set_result(c, m->force_max, m->force_most);
}

static void fini(void* self) {
  instruments* m = self;
  if (!m) return;
  tx_instrument_world_destroy(m->world);
  for (int i = 0; i < TX_INSTRUMENTS_MAX; i++) tx_instrument_desc_free(m->desc[i]);
  free(m);
}

const tx_controller_class tx_physics_instruments = {
    .type = "physics.instruments",
    .summary = "instruments (URDF) on ODE: jaws follow the grip, the root follows the device through a virtual coupling",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
