// physics.instruments: the instruments of the two hands on ODE
// (instrument_sim.h), read from their URDFs at configure, stepped at the
// controller's rate (one ODE step per tick), published as typed components.
#include "instruments_controller.h"

#include "instrument_desc.h"
#include "instrument_sim.h"
#include "cut.h"
#include "puncture.h"

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TX_THREAD_RELEASE_RAD 0.02 // jaws this much wider than closed let the thread go
#define HANDS 2
#define PER_HAND (TX_INSTRUMENTS_MAX / HANDS) // one held, the others parked
#define NEEDLE_CHORDS 16 // needle.segments: the arc drawn as this many chords
#define HOLE_PARTICLES_MAX 16384 // skins up to this many particles (102 x 102 at 1 mm) tell a torn-off flap from the patch
#define HOLE_SAMPLES 64 // the arc, tip to swage, searched for where it crosses the skin

typedef struct instruments {
  tx_instrument_sim_params p;
  tx_instrument_desc* desc[TX_INSTRUMENTS_MAX]; // per instrument in the world (a slot)
  int n, nhands;
  tx_instrument_world* world;
  // each hand's instruments (slots), the one it holds (an index into its
  // list), and its switch button as last read
  int slot[HANDS][PER_HAND], nslot[HANDS], cur[HANDS], hand_of[TX_INSTRUMENTS_MAX];
  uint32_t switch_bit;
  bool button_was[HANDS];
  int first[HANDS]; // the index each hand holds at the start (handN_holds)
  int want[HANDS]; // asked for during the run (tune handN_holds): the index to hold, -1: nothing asked
  tx_result switches;
  tx_warning switch_refused;
  int nswitches;
  tx_port dev_pose[HANDS], dev_vel[HANDS], dev_grip[HANDS];
  tx_port pose[HANDS], links[HANDS], model[HANDS], held[HANDS];
  tx_port capsules[HANDS]; // the held instrument's collision shapes as capsules, for the thread
  int link_rows[HANDS], capsule_rows[HANDS];
  tx_warning bad_input, reset;
  tx_result contacts_max, force_max, grasps, releases;
  tx_port needle_pose, needle_swage, needle_segments, events;
  int grasps_seen, releases_seen, last_holder;
  int bad_seen, resets_seen, contacts_most;
  double force_most;
  // the skin the needle's tip pierces (SKIN.x, SKIN.tri, SKIN.contact)
  bool skin;
  tx_port skin_x, skin_tri, skin_contact, skin_torn, needle_tip, punctures;
  tx_result npunct, pulled_through;
  uint64_t contact_seq;
  tx_puncture_tracker tracker;
  tx_puncture rows[TX_NEEDLE_PINS_MAX];
  int32_t pin_verts[TX_NEEDLE_PINS_MAX][3]; // the particles that carry each pin
  double pin_bary[TX_NEEDLE_PINS_MAX][3];   // and their weights
  bool at_hole[TX_NEEDLE_PINS_MAX]; // the row is at the hole: where the arc crossed the patch's sheet
  int32_t* hole_scratch; // 2 x HOLE_PARTICLES_MAX: the skin's components (tx_puncture_hole)
  tx_sheet_grid sheet;   // the skin's particles by x and z, for the clearance (up to 4 HOLE_PARTICLES_MAX)
  tx_result clearance, hand_clearance[HANDS];
  double clearance_min; // m: the lowest any held instrument's collision shapes came above the skin's sheet
  double hand_clearance_min[HANDS]; // m: the same for each hand's instruments
  double pin_offset[TX_NEEDLE_PINS_MAX][3]; // from the skin's point to the pin: the tip where it tore through
  double pin_origin[TX_NEEDLE_PINS_MAX][3]; // where each puncture was made
  int npins;
  double pin_capture; // m: a puncture's skin point this far off the needle's arc is anchored afresh
  tx_result reanchors;
  int nreanchors;
  // the thread the scissors cut (THREAD.nodes)
  tx_port thread_nodes;
  tx_result cuts;
  int ncuts;
  bool scissors[TX_INSTRUMENTS_MAX];
  double blade_length[TX_INSTRUMENTS_MAX], blade_reach[TX_INSTRUMENTS_MAX];
  tx_blades blades[TX_INSTRUMENTS_MAX];
  bool holds_thread[TX_INSTRUMENTS_MAX]; // jaws closed on the thread (not scissors)
  bool holds_skin[TX_INSTRUMENTS_MAX];   // jaws closed on the skin (not scissors)
  tx_result skin_grasps;
  int nskin_grasps;
  tx_result thread_grasps, cut_height;
  int nthread_grasps;
  double last_cut_y;
} instruments;

static const tx_param_def params[] = {
    {"instrument0", TX_PARAM_STR, NULL, 0, 0, 0, "needle_holder",
     "held by device0: a name in assets/instruments/ or a path to a .urdf"},
    {"instrument1", TX_PARAM_STR, NULL, 0, 0, 0, "", "held by device1; \"\": none"},
    {"hand0", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "device0's instruments, by name or path, separated by spaces (at most 2): it holds the first, its switch_button takes the next; \"\": instrument0 alone"},
    {"hand1", TX_PARAM_STR, NULL, 0, 0, 0, "", "device1's instruments, as hand0; \"\": instrument1 alone"},
    {"switch_button", TX_PARAM_INT, "1", 0, 31, 0, NULL,
     "the device button (bit of deviceN.grip's buttons) whose press puts the held instrument down and takes the hand's next"},
    {"hand0_holds", TX_PARAM_INT, "1", 0, PER_HAND - 1, 0, NULL,
     "which of device0's instruments it holds (0: the first of hand0); changed during a run (the trainer's Tune panel), the hand puts down what it holds and takes that one, as its switch button does"},
    {"hand1_holds", TX_PARAM_INT, "1", 0, PER_HAND - 1, 0, NULL, "the same for device1"},
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
    {"needle_x_m", TX_PARAM_NUM, "m", -10, 10, 0.03, NULL, "its circle's centre on the table (or in foam), x"},
    {"needle_z_m", TX_PARAM_NUM, "m", -10, 10, 0, NULL, "its circle's centre on the table (or in foam), z"},
    {"needle_in_jaws", TX_PARAM_INT, "1", -1, 1, -1, NULL,
     "-1: the needle starts on the table; N: it starts held in instrumentN's jaws (then needle_x_m, needle_z_m are unused)"},
    {"needle_grasp_m", TX_PARAM_NUM, "m", 0.005, 0.1, 0.03, NULL, "held from the start: the wire this far ahead of the jaws' pivot"},
    {"needle_grasp_rad", TX_PARAM_NUM, "rad", 0, 3.9, 0.2, NULL,
     "held from the start: at this angle along the arc from the swage; the arc curves towards the root's +y"},
    {"needle_foam", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL,
     "the needle stands upright in foam, still until jaws take it: its arc in the x-y plane, its point needle_grasp_rad from the swage one radius along +x from its centre"},
    {"needle_y_m", TX_PARAM_NUM, "m", -10, 10, 0, NULL, "in foam: its circle's centre's height"},
    {"skin", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "the skin the needle's tip pierces: reads SKIN.x, SKIN.tri, SKIN.contact, SKIN.torn (physics.skin with pose needle.tip); \"\": none"},
    {"thread", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "the thread the scissors cut and other jaws grasp: reads THREAD.nodes; \"\": none"},
    {"puncture_separation_m", TX_PARAM_NUM, "m", 0, 0.1, 0.003, NULL,
     "a tear nearer than this to the last puncture is that puncture's tear running on"},
    {"pin_stiffness", TX_PARAM_NUM, "N/m", 0, 1e5, 200, NULL,
     "a puncture holds the needle's arc on its point across the arc with this spring"},
    {"pin_damping", TX_PARAM_NUM, "N s/m", 0, 1e3, 0.1, NULL, "and this damper"},
    {"pin_friction_n", TX_PARAM_NUM, "N", 0, 100, 0.02, NULL, "the most force a puncture puts against the needle sliding along its arc"},
    {"pin_capture_m", TX_PARAM_NUM, "m", 1e-4, 0.05, 0.005, NULL,
     "a puncture's point farther than this off the needle's arc holds nothing (a torn flap the tip carried off); the puncture moves to where the arc crosses the skin"},
};

// a bare name is a shipped instrument; anything else is a path
static void resolve(const char* given, char* path, size_t n) {
  size_t len = strlen(given);
  if (strchr(given, '/') || (len > 5 && strcmp(given + len - 5, ".urdf") == 0)) snprintf(path, n, "%s", given);
  else snprintf(path, n, "%s/instruments/%s.urdf", TX_ASSET_DIR, given);
}

// a scissors (its name says so) cuts with its jaws' parts ahead of the
// pivot, other jaws grasp with them: their reach along the root's x from the
// pivot and their half width across
static void blades_of(instruments* m, int i) {
  const tx_urdf* u = m->desc[i]->urdf;
  m->scissors[i] = strstr(u->name, "scissors") != NULL;
  m->blades[i] = (tx_blades){.open = 0.1, .closed = 0.03};
  for (int j = 0; j < u->njoints; j++) {
    if (u->joints[j].fixed) continue;
    const tx_urdf_link* l = &u->links[u->joints[j].child];
    for (int k = 0; k < l->nshapes; k++) {
      const tx_urdf_shape* sh = &l->shapes[k];
      if (sh->kind != TX_URDF_BOX || sh->pose.p[0] <= 0) continue;
      m->blade_length[i] = fmax(m->blade_length[i], u->joints[j].origin.p[0] + sh->pose.p[0] + sh->size[0] / 2);
      m->blade_reach[i] = fmax(m->blade_reach[i], fmax(sh->size[1], sh->size[2]) / 2);
    }
  }
}

static void rotate(const double q[4], const double v[3], double o[3]) {
  double t[3] = {2 * (q[2] * v[2] - q[3] * v[1]), 2 * (q[3] * v[0] - q[1] * v[2]), 2 * (q[1] * v[1] - q[2] * v[0])};
  o[0] = v[0] + q[0] * t[0] + q[2] * t[2] - q[3] * t[1];
  o[1] = v[1] + q[0] * t[1] + q[3] * t[0] - q[1] * t[2];
  o[2] = v[2] + q[0] * t[2] + q[1] * t[1] - q[2] * t[0];
}

// a shape's centre c and orientation q in the world, from its link's pose (lp, lq)
static void shape_frame(const double lp[3], const double lq[4], const tx_urdf_shape* sh, double c[3], double q[4]) {
  rotate(lq, sh->pose.p, c);
  for (int j = 0; j < 3; j++) c[j] += lp[j];
  q[0] = lq[0] * sh->pose.q[0] - lq[1] * sh->pose.q[1] - lq[2] * sh->pose.q[2] - lq[3] * sh->pose.q[3];
  q[1] = lq[0] * sh->pose.q[1] + lq[1] * sh->pose.q[0] + lq[2] * sh->pose.q[3] - lq[3] * sh->pose.q[2];
  q[2] = lq[0] * sh->pose.q[2] - lq[1] * sh->pose.q[3] + lq[2] * sh->pose.q[0] + lq[3] * sh->pose.q[1];
  q[3] = lq[0] * sh->pose.q[3] + lq[1] * sh->pose.q[2] - lq[2] * sh->pose.q[1] + lq[3] * sh->pose.q[0];
}

// The instrument's collision shapes, for the thread to keep out of: each box
// ahead of its link's pivot (a jaw, a blade, a tine) as a capsule along its
// longest side, as thick as its thinnest, so that two closing jaws leave the
// thread room between them until they are nearly shut (a holder's jaws 0.5
// mm apart 20 mm out at 0.0125 rad, well after the grasp at 0.03 rad); a
// cylinder (the pivot's lump) as a capsule along its axis, a sphere as
// itself. The lump keeps a loop wound round the jaws from sliding off them
// backwards. The shanks (boxes behind the pivot) are left out: the thread
// leaves the needle's swage along the holder from the first grasp, and a
// coarse thread (4 mm links) snagged on them (the suturing-accuracy study's 5
// mm level never finished B). Fills out (NULL: only counts) at the
// instrument's current link poses; returns how many.
static int instrument_capsules(const instruments* m, int i, tx_capsule* out) {
  const tx_urdf* u = m->desc[i]->urdf;
  int n = 0;
  for (int l = 0; l < u->nlinks; l++) {
    double lp[3], lq[4];
    if (out) tx_instrument_world_link(m->world, i, l, lp, lq);
    for (int k = 0; k < u->links[l].nshapes; k++) {
      const tx_urdf_shape* sh = &u->links[l].shapes[k];
      if (sh->kind == TX_URDF_BOX && sh->pose.p[0] <= 0) continue; // a shank
      if (!out) { n++; continue; }
      double c[3], q[4], half[3] = {0, 0, 0}, d[3];
      shape_frame(lp, lq, sh, c, q);
      if (sh->kind == TX_URDF_BOX) {
        int along = 0, thin = 0;
        for (int a = 1; a < 3; a++) {
          if (sh->size[a] > sh->size[along]) along = a;
          if (sh->size[a] < sh->size[thin]) thin = a;
        }
        out[n].radius = sh->size[thin] / 2;
        half[along] = fmax(sh->size[along] / 2 - out[n].radius, 0);
      } else if (sh->kind == TX_URDF_CYLINDER) { // radius, length; its axis along z
        out[n].radius = sh->size[0];
        half[2] = sh->size[1] / 2;
      } else {
        out[n].radius = sh->size[0];
      }
      rotate(q, half, d);
      for (int a = 0; a < 3; a++) out[n].a[a] = c[a] - d[a], out[n].b[a] = c[a] + d[a];
      n++;
    }
  }
  return n;
}

static void arc_point(const instruments* m, double a, double out[3]);

// the needle's wire between jaws (pivot, dir) closing: those jaws take the
// needle (ODE's grasp, a few steps later, once they squeeze the wire), not
// the thread that leaves its swage between them too
static bool needle_between(const instruments* m, int i, const double pivot[3], const double dir[3]) {
  tx_thread_node wire[NEEDLE_CHORDS + 1];
  for (int k = 0; k <= NEEDLE_CHORDS; k++) {
    arc_point(m, m->p.needle.arc * k / NEEDLE_CHORDS, wire[k].x);
    wire[k].radius = m->p.needle.wire_diameter / 2;
  }
  double at[3];
  return tx_scissors_cut(pivot, dir, m->blade_length[i], m->blade_reach[i], wire, NEEDLE_CHORDS + 1, at) >= 0;
}

// scissors closing on the thread cut it between their blades; other jaws
// closing on it grasp it, or else grasp the skin between them (until they
// open again)
static void cut(tx_ctx* c, instruments* m, int i, double jaw) {
  if (!m->thread_nodes.id && !m->skin) return;
  if ((m->holds_thread[i] || m->holds_skin[i]) && jaw > m->blades[i].closed + TX_THREAD_RELEASE_RAD) {
    m->holds_thread[i] = m->holds_skin[i] = false;
    tx_emit(c, m->events, &(tx_event){.kind = TX_EVENT_RELEASE, .source = (uint32_t)m->hand_of[i]});
  }
  if (!tx_blades_close(&m->blades[i], jaw)) return;
  if (!m->scissors[i] && m->p.needle.enabled && tx_instrument_world_needle_held_by(m->world) == i) return; // on the needle
  double pivot[3], q[4], dir[3], point[3];
  tx_instrument_world_link(m->world, i, 0, pivot, q);
  // the root's x axis: the closed blades
  dir[0] = 1 - 2 * (q[2] * q[2] + q[3] * q[3]), dir[1] = 2 * (q[1] * q[2] + q[0] * q[3]), dir[2] = 2 * (q[1] * q[3] - q[0] * q[2]);
  if (!m->scissors[i] && m->p.needle.enabled && needle_between(m, i, pivot, dir)) return;
  tx_snapshot nodes = m->thread_nodes.id ? tx_read(c, m->thread_nodes) : (tx_snapshot){0};
  int seg = nodes.seq ? tx_scissors_cut(pivot, dir, m->blade_length[i], m->blade_reach[i], nodes.data, (int)nodes.rows, point) : -1;
  if (seg >= 0 && m->scissors[i]) {
    tx_event e = {.kind = TX_EVENT_CUT, .source = (uint32_t)seg};
    memcpy(e.cut.point, point, sizeof point);
    tx_emit(c, m->events, &e);
    m->ncuts++;
    m->last_cut_y = point[1];
    return;
  }
  if (m->scissors[i]) return;
  if (seg < 0) { // not on the thread: on the skin?
    tx_snapshot x = m->skin ? tx_read(c, m->skin_x) : (tx_snapshot){0};
    if (!x.seq || tx_jaws_pinch(pivot, dir, m->blade_length[i], m->blade_reach[i], x.data, (int)x.rows, point) < 0) return;
  }
  // a grasp: its point on the thread or the skin, between the jaws; the
  // thread and the skin each take the grasp whose point is theirs
  tx_event e = {.kind = TX_EVENT_GRASP, .source = (uint32_t)m->hand_of[i]};
  memcpy(e.grasp.point, point, sizeof point);
  e.grasp.jaw = jaw;
  tx_emit(c, m->events, &e);
  if (seg >= 0) m->holds_thread[i] = true, m->nthread_grasps++;
  else m->holds_skin[i] = true, m->nskin_grasps++;
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
  nd->held_by = (int)tx_table_int(s, "needle_in_jaws");
  nd->foam = tx_table_bool(s, "needle_foam");
  if (nd->foam) nd->pos[1] = tx_table_num(s, "needle_y_m");
  if (nd->foam && nd->held_by >= 0) return tx_setup_fail(s, "needle_foam", "the needle starts in the jaws (needle_in_jaws)");
  if (nd->foam && !nd->enabled) return tx_setup_fail(s, "needle_foam", "no needle (needle: true)");
  nd->grasp_distance = tx_table_num(s, "needle_grasp_m");
  nd->grasp_angle = tx_table_num(s, "needle_grasp_rad");
  if (nd->held_by >= 0 && !nd->enabled) return tx_setup_fail(s, "needle_in_jaws", "no needle to hold (needle: true)");
  if (nd->grasp_angle > nd->arc) return tx_setup_fail(s, "needle_grasp_rad", "past the needle's tip (its arc is %g rad)", nd->arc);
  m->p.pin_stiffness = tx_table_num(s, "pin_stiffness");
  m->p.pin_damping = tx_table_num(s, "pin_damping");
  m->p.pin_friction = tx_table_num(s, "pin_friction_n");
  m->pin_capture = m->p.pin_reach = tx_table_num(s, "pin_capture_m");
  const char* skin = tx_table_str(s, "skin");
  if (!skin) return -1;
  if (*skin && !nd->enabled) return tx_setup_fail(s, "skin", "a skin to pierce needs the needle (needle: true)");
  if (*skin) {
    char name[TX_NAME_MAX];
    m->skin = true;
    snprintf(name, sizeof name, "%s.x", skin);
    m->skin_x = TX_READ_OF(s, name, tx_vertex);
    snprintf(name, sizeof name, "%s.tri", skin);
    m->skin_tri = TX_READ_OF(s, name, tx_triangle);
    snprintf(name, sizeof name, "%s.contact", skin);
    m->skin_contact = TX_READ_OF(s, name, tx_skin_contact);
    snprintf(name, sizeof name, "%s.torn", skin);
    m->skin_torn = TX_READ_OF(s, name, tx_torn);
    m->hole_scratch = calloc(2 * HOLE_PARTICLES_MAX, sizeof *m->hole_scratch);
    if (!m->hole_scratch || !tx_sheet_grid_init(&m->sheet, 4 * HOLE_PARTICLES_MAX)) return -1;
    tx_puncture_tracker_init(&m->tracker, tx_table_num(s, "puncture_separation_m"), 0);
  }
  for (int h = 0; h < HANDS; h++) {
    char key[32], hkey[32], path[2048], name[TX_NAME_MAX], list[1024];
    snprintf(key, sizeof key, "instrument%d", h);
    snprintf(hkey, sizeof hkey, "hand%d", h);
    const char* given = tx_table_str(s, key);
    const char* hand = tx_table_str(s, hkey);
    if (!given || !hand) return -1;
    const char* used = *hand ? hkey : key;
    snprintf(list, sizeof list, "%s", *hand ? hand : given);
    char* save = NULL;
    for (char* nm = strtok_r(list, " \t", &save); nm; nm = strtok_r(NULL, " \t", &save)) {
      if (h > m->nhands) return tx_setup_fail(s, used, "device%d has instruments but device%d has none", h, m->nhands);
      if (m->nslot[h] == PER_HAND) return tx_setup_fail(s, used, "more than %d instruments in one hand", PER_HAND);
      int i = m->n;
      resolve(nm, path, sizeof path);
      m->desc[i] = tx_instrument_desc_load(path);
      if (!m->desc[i]) return tx_setup_fail(s, used, "%s", tx_error());
      if (m->desc[i]->urdf->nlinks > TX_INSTRUMENT_LINKS_MAX)
        return tx_setup_fail(s, used, "%s: more than %d links", path, TX_INSTRUMENT_LINKS_MAX);
      m->hand_of[i] = h;
      m->slot[h][m->nslot[h]++] = i;
      m->n = i + 1;
      if (m->desc[i]->urdf->nlinks > m->link_rows[h]) m->link_rows[h] = m->desc[i]->urdf->nlinks;
      int shapes = instrument_capsules(m, i, NULL);
      if (shapes > m->capsule_rows[h]) m->capsule_rows[h] = shapes;
    }
    if (!m->nslot[h]) continue;
    m->nhands = h + 1;
    snprintf(name, sizeof name, "device%d.pose", h);
    m->dev_pose[h] = TX_READ_OF(s, name, tx_pose);
    snprintf(name, sizeof name, "device%d.velocity", h);
    m->dev_vel[h] = TX_READ_OF(s, name, tx_velocity);
    snprintf(name, sizeof name, "device%d.grip", h);
    m->dev_grip[h] = TX_READ_OF(s, name, tx_device_grip);
    snprintf(name, sizeof name, "instrument%d.pose", h);
    m->pose[h] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_instrument_pose, 1));
    snprintf(name, sizeof name, "instrument%d.links", h);
    m->links[h] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_pose, (uint32_t)m->link_rows[h]));
    snprintf(name, sizeof name, "instrument%d.force_model", h);
    m->model[h] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_force_model, 1));
    snprintf(name, sizeof name, "instrument%d.held", h);
    m->held[h] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_instrument_held, 1));
    if (m->capsule_rows[h] > 0) {
      snprintf(name, sizeof name, "instrument%d.capsules", h);
      m->capsules[h] = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_capsule, (uint32_t)m->capsule_rows[h]));
    }
  }
  if (m->n == 0) return tx_setup_fail(s, "instrument0", "no instrument: give instrument0");
  if (nd->held_by >= m->nhands) return tx_setup_fail(s, "needle_in_jaws", "there is no instrument%d", nd->held_by);
  for (int h = 0; h < HANDS; h++) {
    char key[32];
    snprintf(key, sizeof key, "hand%d_holds", h);
    m->first[h] = (int)tx_table_int(s, key);
    if (m->first[h] > 0 && m->first[h] >= m->nslot[h])
      return tx_setup_fail(s, key, "device%d has %d instrument%s: give 0%s", h, m->nslot[h], m->nslot[h] == 1 ? "" : "s",
                           m->nslot[h] > 1 ? " or 1" : "");
  }
  if (nd->held_by >= 0) nd->held_by = m->slot[nd->held_by][m->first[nd->held_by]]; // the world counts slots
  m->switch_bit = 1u << tx_table_int(s, "switch_button");
  m->switches = tx_setup_result(s, "switches");
  m->switch_refused = tx_setup_warning(s, "switch_refused");
  const char* thread = tx_table_str(s, "thread");
  if (!thread) return -1;
  if (*thread) {
    char name[TX_NAME_MAX];
    snprintf(name, sizeof name, "%s.nodes", thread);
    m->thread_nodes = TX_READ_OF(s, name, tx_thread_node);
    m->cuts = tx_setup_result(s, "thread_cuts");
    m->thread_grasps = tx_setup_result(s, "thread_grasps");
    m->cut_height = tx_setup_result(s, "thread_cut_y_m");
  }
  if (*skin) m->skin_grasps = tx_setup_result(s, "skin_grasps");
  if (*thread || nd->enabled || m->n > m->nhands) m->events = tx_setup_emit(s, "instruments.events", 64);
  for (int i = 0; i < m->n; i++) blades_of(m, i);
  m->bad_input = tx_setup_warning(s, "device_not_finite");
  m->reset = tx_setup_warning(s, "reset");
  m->contacts_max = tx_setup_result(s, "contacts_max");
  if (nd->enabled) {
    m->needle_pose = tx_setup_write(s, &TX_COMPONENT_OF("needle.pose", tx_pose, 1));
    m->needle_swage = tx_setup_write(s, &TX_COMPONENT_OF("needle.swage", tx_pose, 1));
    m->needle_tip = tx_setup_write(s, &TX_COMPONENT_OF("needle.tip", tx_pose, 1));
    m->needle_segments = tx_setup_write(s, &TX_COMPONENT_OF("needle.segments", tx_segment, NEEDLE_CHORDS));
    m->punctures = tx_setup_write(s, &TX_COMPONENT_OF("needle.punctures", tx_puncture, TX_NEEDLE_PINS_MAX));
    m->npunct = tx_setup_result(s, "needle_punctures");
    m->pulled_through = tx_setup_result(s, "needle_pulled_through");
    if (*skin) m->reanchors = tx_setup_result(s, "needle_reanchors");
    if (*skin) m->clearance = tx_setup_result(s, "skin_clearance_m");
    if (*skin) m->hand_clearance[0] = tx_setup_result(s, "hand0_skin_clearance_m");
    if (*skin) m->hand_clearance[1] = tx_setup_result(s, "hand1_skin_clearance_m");
    m->grasps = tx_setup_result(s, "needle_grasps");
    m->releases = tx_setup_result(s, "needle_releases");
  }
  m->force_max = tx_setup_result(s, "coupling_force_max_n");
  return 0;
}

// a parked instrument waits a metre above the scene (it is out of the
// world's collisions anyway), each at its own place
static const double* park_at(int slot) {
  static const double at[TX_INSTRUMENTS_MAX][3] = {{0, 1, 0}, {0.1, 1, 0}, {0.2, 1, 0}, {0.3, 1, 0}};
  return at[slot];
}

static bool button(const instruments* m, const tx_device_grip* g) {
  double b = g->buttons;
  return isfinite(b) && b >= 0 && b < 4294967296.0 && ((uint32_t)b & m->switch_bit);
}

// the world is made on the thread that steps it: ODE keeps per-thread data
static int init(tx_ctx* c, void* self) {
  instruments* m = self;
  tx_instrument_world_destroy(m->world); // each run starts afresh
  m->world = NULL;
  const tx_urdf* urdfs[TX_INSTRUMENTS_MAX];
  double start[TX_INSTRUMENTS_MAX][3] = {{0}};
  tx_pose hand_at[HANDS];
  bool hand_known[HANDS] = {false};
  for (int i = 0; i < m->n; i++) {
    urdfs[i] = m->desc[i]->urdf;
    tx_snapshot p = tx_read(c, m->dev_pose[m->hand_of[i]]);
    if (p.seq) memcpy(start[i], ((const tx_pose*)p.data)->pos, sizeof start[i]);
    if (p.seq) hand_at[m->hand_of[i]] = *(const tx_pose*)p.data, hand_known[m->hand_of[i]] = true;
    for (int k = 0; k < 3; k++)
      if (!isfinite(start[i][k])) start[i][k] = 0;
  }
  m->npins = m->nreanchors = 0;
  m->clearance_min = m->hand_clearance_min[0] = m->hand_clearance_min[1] = INFINITY;
  m->ncuts = m->nthread_grasps = m->nskin_grasps = 0;
  for (int i = 0; i < m->n; i++) m->blades[i].armed = 0, m->holds_thread[i] = m->holds_skin[i] = false;
  m->contact_seq = 0;
  for (int i = 0; i < TX_NEEDLE_PINS_MAX; i++) m->rows[i] = (tx_puncture){.v = {-1, -1, -1}};
  tx_puncture_tracker_init(&m->tracker, m->tracker.separation, 0);
  m->world = tx_instrument_world_create(&m->p, urdfs, m->n, (const double(*)[3])start);
  if (!m->world) {
    tx_stop_run(c, "physics.instruments: %s", tx_error());
    return -1;
  }
  m->nswitches = 0;
  for (int h = 0; h < HANDS; h++) m->want[h] = -1;
  for (int h = 0; h < m->nhands; h++) { // each hand holds handN_holds; a button held from the start is no press
    m->cur[h] = m->first[h];
    // turned as the hand is: built square to the world, the coupling swung
    // each instrument round to its device's first orientation in the first
    // tenth of a second, through the scene (the holder 180 degrees about y in
    // scenario suturing, its jaws 13 cm about, and into the needle's foam
    // when the hand was half a millimetre off). The needle's holder from the
    // start keeps the square start its needle was placed for
    int i = m->slot[h][m->cur[h]];
    if (hand_known[h] && tx_instrument_world_needle_held_by(m->world) != i)
      tx_instrument_world_take(m->world, i, hand_at[h].pos, hand_at[h].quat);
    for (int k = 0; k < m->nslot[h]; k++)
      if (k != m->cur[h]) tx_instrument_world_park(m->world, m->slot[h][k], park_at(m->slot[h][k]));
    tx_snapshot g = tx_read(c, m->dev_grip[h]);
    m->button_was[h] = g.seq && button(m, g.data);
  }
  return 0;
}

// the press of the switch button (an edge), or a tune of handN_holds, puts
// the hand's instrument down and takes another (index k of its list), at the
// device's pose, its coupling at rest
static void switch_instrument(tx_ctx* c, instruments* m, int h, int k, const tx_instrument_input* dev) {
  int from = m->slot[h][m->cur[h]], was = m->cur[h];
  m->cur[h] = k;
  int to = m->slot[h][k];
  tx_instrument_world_park(m->world, from, park_at(from));
  tx_instrument_world_take(m->world, to, dev->pos, dev->quat);
  if (m->holds_thread[from] || m->holds_skin[from]) // put down: what it held is let go
    tx_emit(c, m->events, &(tx_event){.kind = TX_EVENT_RELEASE, .source = (uint32_t)h});
  m->holds_thread[from] = m->holds_thread[to] = m->holds_skin[from] = m->holds_skin[to] = false;
  m->blades[to].armed = 0;
  m->nswitches++;
  tx_event e = {.kind = TX_EVENT_INSTRUMENT_SWITCH, .source = (uint32_t)h};
  e.value[0] = m->cur[h];
  e.value[1] = was;
  tx_emit(c, m->events, &e);
}

// handN_holds, asked for while the run goes: taken at the hand's next step
static void tune(tx_ctx* c, void* self, const char* key, double value) {
  (void)c;
  instruments* m = self;
  int h = strcmp(key, "hand1_holds") == 0;
  m->want[h] = (int)value;
}

// the point on the needle's arc at angle a (rad from the swage), world
static void arc_point(const instruments* m, double a, double out[3]) {
  double o[3], q[4], R = m->p.needle.radius, v[3] = {R * cos(a), R * sin(a), 0};
  tx_instrument_world_needle(m->world, o, q);
  double t[3] = {2 * (q[2] * v[2] - q[3] * v[1]), 2 * (q[3] * v[0] - q[1] * v[2]), 2 * (q[1] * v[1] - q[2] * v[0])};
  out[0] = o[0] + v[0] + q[0] * t[0] + (q[2] * t[2] - q[3] * t[1]);
  out[1] = o[1] + v[1] + q[0] * t[1] + (q[3] * t[0] - q[1] * t[2]);
  out[2] = o[2] + v[2] + q[0] * t[2] + (q[1] * t[1] - q[2] * t[0]);
}

// A puncture's particles can be a flap torn loose around the hole, which the
// tip carries off: its point then leaves the needle (the pin lets go of the
// arc beyond pin_capture). The hole itself is where the arc crosses the skin
// sheet: once the point is pin_capture off the arc, the puncture moves to the
// skin nearest the arc within pin_capture of it, of such places the nearest
// where it was made; its row of needle.punctures follows, for the thread.
// Rare (a flap carried off), so the search along the arc is affordable.
#define REANCHOR_SAMPLES 64
static void reanchor(instruments* m, int i, const float* xs, int nx, const int32_t* tri, int ntri) {
  double angle, gap = tx_instrument_world_needle_pin_gap(m->world, i, &angle);
  if (tx_instrument_world_needle_pin_through(m->world, i) || gap <= m->pin_capture) return;
  double best = INFINITY, best_c[3] = {0}, best_point[3] = {0}, best_bary[3] = {0};
  int best_t = -1;
  for (int k = 0; k <= REANCHOR_SAMPLES; k++) {
    double c[3], bary[3], point[3], d = 0, o = 0;
    arc_point(m, m->p.needle.arc * k / REANCHOR_SAMPLES, c);
    int t = tx_nearest_triangle(xs, nx, tri, ntri, c, bary, point);
    if (t < 0) continue;
    for (int j = 0; j < 3; j++) d += (point[j] - c[j]) * (point[j] - c[j]), o += (c[j] - m->pin_origin[i][j]) * (c[j] - m->pin_origin[i][j]);
    if (sqrt(d) > m->pin_capture || o >= best) continue;
    best = o, best_t = t;
    memcpy(best_c, c, sizeof c), memcpy(best_point, point, sizeof point), memcpy(best_bary, bary, sizeof bary);
  }
  if (best_t < 0) return;
  for (int v = 0; v < 3; v++) {
    m->pin_verts[i][v] = tri[3 * best_t + v];
    m->pin_bary[i][v] = best_bary[v];
  }
  for (int k = 0; k < 3; k++) m->pin_offset[i][k] = best_c[k] - best_point[k];
  tx_instrument_world_needle_pin_move(m->world, i, best_c);
  m->nreanchors++;
}

// The row of needle.punctures (for the thread) is the hole in the patch: the
// tear's place, the triangles nearest the HIP, is torn on as the tip goes
// through, and a particle of it can come loose and be carried off under the
// skin. At the tear the arc has not crossed the sheet yet (the HIP tears at
// its contact distance), so at each publish until it has, and again if the
// row's triangle is later torn or cut off from the patch, the row moves to
// the patch's triangle nearest where the arc crosses the sheet (its rim).
// The pin (the needle's own hold) keeps its particles.
static void hole_row(instruments* m, int i, const float* xs, int nx, const int32_t* tri, int ntri) {
  if (tx_instrument_world_needle_pin_through(m->world, i)) return; // the thread holds it where it is now
  double arc[HOLE_SAMPLES + 1][3], on_arc[3], bary[3], point[3], at[3] = {0};
  for (int k = 0; k <= HOLE_SAMPLES; k++) arc_point(m, m->p.needle.arc * (1 - (double)k / HOLE_SAMPLES), arc[k]);
  int32_t rv[3];
  for (int v = 0; v < 3; v++) {
    rv[v] = (int32_t)m->rows[i].v[v];
    for (int k = 0; k < 3 && rv[v] >= 0 && rv[v] < nx; k++) at[k] += m->rows[i].bary[v] * xs[3 * rv[v] + k];
  }
  // until it is at its hole, the other punctures' holes are not its own
  double taken[TX_NEEDLE_PINS_MAX][3];
  int ntaken = 0;
  for (int j = 0; j < m->npins && !m->at_hole[i]; j++) {
    if (j == i || !m->at_hole[j]) continue;
    memset(taken[ntaken], 0, sizeof taken[ntaken]);
    for (int v = 0; v < 3; v++)
      for (int k = 0; k < 3 && m->rows[j].v[v] >= 0 && m->rows[j].v[v] < nx; k++)
        taken[ntaken][k] += m->rows[j].bary[v] * xs[3 * (int)m->rows[j].v[v] + k];
    ntaken++;
  }
  int hole = tx_puncture_hole(xs, nx, tri, ntri, (const double(*)[3])arc, HOLE_SAMPLES + 1, m->at_hole[i] ? at : NULL,
                              m->pin_capture, (const double(*)[3])taken, ntaken, m->tracker.separation, m->hole_scratch,
                              2 * HOLE_PARTICLES_MAX, bary, point, on_arc);
  if (hole < 0) { // lost: its triangle torn or cut off from the patch, the next publish looks from the tip again
    if (m->at_hole[i] && !tx_puncture_attached(nx, tri, ntri, m->hole_scratch, 2 * HOLE_PARTICLES_MAX, rv)) m->at_hole[i] = false;
    return;
  }
  for (int k = 0; k < 3; k++) m->rows[i].v[k] = tri[3 * hole + k], m->rows[i].bary[k] = bary[k];
  m->at_hole[i] = true;
}

// The lowest the held instruments come above the skin: every corner of
// their collision boxes, the lowest point of each cylinder's rim and of each
// sphere, against the sheet under it (tx_height_above_sheet), at each publish
// of the skin. The skin does not collide with the instruments (only with the
// needle's tip), so this is what keeps them out of it.
static void clearance(instruments* m, const float* xs, int nx) {
  double top = -INFINITY;
  for (int i = 0; i < nx; i++) top = fmax(top, xs[3 * i + 1]);
  // the particles bucketed once for all the points below (a larger skin: each point scans them)
  bool grid = nx <= m->sheet.cap;
  if (grid) tx_sheet_grid_build(&m->sheet, xs, nx);
  for (int h = 0; h < m->nhands; h++) {
    int i = m->slot[h][m->cur[h]];
    const tx_urdf* u = m->desc[i]->urdf;
    for (int l = 0; l < u->nlinks; l++) {
      double lp[3], lq[4];
      tx_instrument_world_link(m->world, i, l, lp, lq);
      for (int k = 0; k < u->links[l].nshapes; k++) {
        const tx_urdf_shape* sh = &u->links[l].shapes[k];
        double c[3], q[4], pts[8][3];
        int n = 0;
        shape_frame(lp, lq, sh, c, q);
        if (sh->kind == TX_URDF_BOX) {
          for (int corner = 0; corner < 8; corner++, n++) {
            double v[3] = {(corner & 1 ? 0.5 : -0.5) * sh->size[0], (corner & 2 ? 0.5 : -0.5) * sh->size[1],
                           (corner & 4 ? 0.5 : -0.5) * sh->size[2]};
            rotate(q, v, pts[n]);
            for (int j = 0; j < 3; j++) pts[n][j] += c[j];
          }
        } else if (sh->kind == TX_URDF_CYLINDER) { // the lower end's rim, at its lowest
          double z[3] = {0, 0, 1}, a[3];
          rotate(q, z, a);
          double e = a[1] > 0 ? -sh->size[1] / 2 : sh->size[1] / 2, up[3] = {-a[1] * a[0], 1 - a[1] * a[1], -a[1] * a[2]};
          double un = sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
          for (int j = 0; j < 3; j++) pts[n][j] = c[j] + e * a[j] - (un > 1e-12 ? sh->size[0] * up[j] / un : 0);
          n++;
        } else {
          memcpy(pts[n], c, sizeof c), pts[n][1] -= sh->size[0], n++;
        }
        for (int j = 0; j < n; j++)
          if (pts[j][1] < top + 0.01)
            m->hand_clearance_min[h] = fmin(m->hand_clearance_min[h], grid ? tx_sheet_height(&m->sheet, xs, pts[j])
                                                                           : tx_height_above_sheet(xs, nx, pts[j]));
      }
    }
    m->clearance_min = fmin(m->clearance_min, m->hand_clearance_min[h]);
  }
}

// the skin against the tip: its contact pushes the tip; each puncture it
// tears pins the needle's arc there, is an event and a row of needle.punctures
static void pierce(tx_ctx* c, instruments* m) {
  tx_snapshot ct = tx_read(c, m->skin_contact), x = tx_read(c, m->skin_x), tri = tx_read(c, m->skin_tri);
  if (!ct.seq || !x.seq) return;
  const tx_skin_contact* sc = ct.data;
  const float* xs = x.data;
  double zero[3] = {0};
  if (sc->touching > 0) tx_instrument_world_needle_tip_contact(m->world, sc->f, sc->x, sc->n, sc->k);
  else tx_instrument_world_needle_tip_contact(m->world, zero, zero, zero, 0);
  for (int i = 0; i < m->npins; i++) { // the points move with the skin
    double p[3] = {0};
    for (int v = 0; v < 3; v++)
      for (int k = 0; k < 3; k++)
        if (m->pin_verts[i][v] < (int32_t)x.rows) p[k] += m->pin_bary[i][v] * xs[3 * m->pin_verts[i][v] + k];
    for (int k = 0; k < 3; k++) p[k] += m->pin_offset[i][k];
    tx_instrument_world_needle_pin_move(m->world, i, p);
  }
  if (ct.seq == m->contact_seq) return; // one look at each of the skin's publishes
  m->contact_seq = ct.seq;
  clearance(m, xs, (int)x.rows);
  if (tri.seq)
    for (int i = 0; i < m->npins; i++) {
      reanchor(m, i, xs, (int)x.rows, tri.data, (int)tri.rows);
      hole_row(m, i, xs, (int)x.rows, tri.data, (int)tri.rows);
    }
  tx_snapshot torn = tx_read(c, m->skin_torn);
  if (torn.seq) tx_puncture_skin_pierces(&m->tracker, ((const tx_torn*)torn.data)->pierces);
  tx_puncture_found f;
  if (!tri.seq || !tx_puncture_update(&m->tracker, sc, xs, (int)x.rows, tri.data, (int)tri.rows, &f)) return;
  // the pin starts at the tip, which is on the arc (the hole's rim, where the
  // triangle's point is, lies a few millimetres off it), and moves with the skin's point
  double tip[3];
  tx_instrument_world_needle_tip(m->world, tip);
  if (m->npins >= TX_NEEDLE_PINS_MAX || tx_instrument_world_needle_pin(m->world, tip) < 0) return;
  for (int k = 0; k < 3; k++) m->pin_offset[m->npins][k] = tip[k] - f.point[k];
  memcpy(m->pin_origin[m->npins], f.point, sizeof f.point);
  m->rows[m->npins] = f.row;
  memcpy(m->pin_verts[m->npins], f.verts, sizeof f.verts);
  memcpy(m->pin_bary[m->npins], f.row.bary, sizeof f.row.bary);
  m->at_hole[m->npins] = false;
  m->npins++;
  hole_row(m, m->npins - 1, xs, (int)x.rows, tri.data, (int)tri.rows);
  // source: the skin.tri row at this publish (the next tear renumbers it; the row of needle.punctures keeps the particles)
  tx_event e = {.kind = TX_EVENT_PUNCTURE, .source = (uint32_t)f.triangle};
  memcpy(e.puncture.point, f.point, sizeof f.point);
  e.puncture.force = f.force;
  e.puncture.depth = f.depth;
  tx_emit(c, m->events, &e);
}

static void step(tx_ctx* c, void* self) {
  instruments* m = self;
  tx_instrument_input in[TX_INSTRUMENTS_MAX], dev[HANDS];
  for (int i = 0; i < m->n; i++) in[i] = (tx_instrument_input){.quat = {1, 0, 0, 0}}; // parked: unread
  for (int h = 0; h < m->nhands; h++) {
    int i = m->slot[h][m->cur[h]];
    tx_snapshot p = tx_read(c, m->dev_pose[h]), v = tx_read(c, m->dev_vel[h]), g = tx_read(c, m->dev_grip[h]);
    dev[h] = (tx_instrument_input){.quat = {1, 0, 0, 0}};
    if (p.seq) {
      memcpy(dev[h].pos, ((const tx_pose*)p.data)->pos, sizeof dev[h].pos);
      memcpy(dev[h].quat, ((const tx_pose*)p.data)->quat, sizeof dev[h].quat);
    } else { // no device yet: hold the instrument where it is
      double q[4];
      tx_instrument_world_link(m->world, i, 0, dev[h].pos, q);
    }
    if (v.seq) memcpy(dev[h].vel, ((const tx_velocity*)v.data)->v, sizeof dev[h].vel);
    dev[h].grip = g.seq ? ((const tx_device_grip*)g.data)->grip : 0;
    bool pressed = g.seq && button(m, g.data);
    if (pressed && !m->button_was[h] && m->nslot[h] > 1) switch_instrument(c, m, h, (m->cur[h] + 1) % m->nslot[h], &dev[h]);
    m->button_was[h] = pressed;
    if (m->want[h] >= m->nslot[h]) tx_warn(c, m->switch_refused); // the hand has no such instrument
    else if (m->want[h] >= 0 && m->want[h] != m->cur[h]) switch_instrument(c, m, h, m->want[h], &dev[h]);
    m->want[h] = -1;
    in[m->slot[h][m->cur[h]]] = dev[h];
  }
  for (int h = m->nhands; h < HANDS; h++)
    if (m->want[h] >= 0) tx_warn(c, m->switch_refused), m->want[h] = -1; // a hand with no instrument
  if (m->skin) pierce(c, m);
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
    tx_pose* tip = tx_write(c, m->needle_tip);
    tx_instrument_world_needle_tip(m->world, tip->pos);
    memcpy(tip->quat, np->quat, sizeof tip->quat);
    memcpy(tx_write(c, m->punctures), m->rows, sizeof m->rows);
    tx_segment* seg = tx_write(c, m->needle_segments);
    for (int k = 0; k < NEEDLE_CHORDS; k++) { // swage to tip
      double a[3], b[3];
      arc_point(m, m->p.needle.arc * k / NEEDLE_CHORDS, a);
      arc_point(m, m->p.needle.arc * (k + 1) / NEEDLE_CHORDS, b);
      for (int j = 0; j < 3; j++) seg[k].a[j] = (float)a[j], seg[k].b[j] = (float)b[j];
      seg[k].r = (float)(m->p.needle.wire_diameter / 2);
    }
    int held = tx_instrument_world_needle_held_by(m->world);
    if (tx_instrument_world_needle_grasps(m->world) > m->grasps_seen) {
      tx_event e = {.kind = TX_EVENT_GRASP, .source = (uint32_t)m->hand_of[held]};
      tx_instrument_world_needle_grasp_point(m->world, e.grasp.point);
      e.grasp.jaw = 0;
      for (int j = 0; j < m->desc[held]->urdf->njoints; j++) e.grasp.jaw += tx_instrument_world_joint(m->world, held, j);
      tx_emit(c, m->events, &e);
    }
    if (tx_instrument_world_needle_releases(m->world) > m->releases_seen)
      tx_emit(c, m->events, &(tx_event){.kind = TX_EVENT_RELEASE, .source = (uint32_t)m->hand_of[m->last_holder]});
    if (held >= 0) m->last_holder = held;
    m->grasps_seen = tx_instrument_world_needle_grasps(m->world);
    m->releases_seen = tx_instrument_world_needle_releases(m->world);
  }
  for (int h = 0; h < m->nhands; h++) { // each hand's component show the instrument it holds
    int i = m->slot[h][m->cur[h]];
    const tx_urdf* u = m->desc[i]->urdf;
    tx_pose* links = tx_write(c, m->links[h]);
    for (int l = 0; l < m->link_rows[h]; l++) // rows past its links repeat its root
      tx_instrument_world_link(m->world, i, l < u->nlinks ? l : 0, links[l].pos, links[l].quat);
    ((tx_instrument_held*)tx_write(c, m->held[h]))->index = m->cur[h];
    if (m->capsules[h].id) tx_write_rows(c, m->capsules[h], (uint32_t)instrument_capsules(m, i, tx_write(c, m->capsules[h])));
    tx_instrument_pose* ip = tx_write(c, m->pose[h]);
    memcpy(ip->pos, links[0].pos, sizeof ip->pos);
    memcpy(ip->quat, links[0].quat, sizeof ip->quat);
    ip->jaw = 0;
    for (int j = 0; j < u->njoints; j++) ip->jaw += tx_instrument_world_joint(m->world, i, j);
    cut(c, m, i, ip->jaw);
    // F = f0 + K (x - x0) at the haptics rate: the coupling's spring about
    // where the hand was, unless the clamp holds it (then a constant)
    tx_force_model* fm = tx_write(c, m->model[h]);
    memset(fm, 0, sizeof *fm);
    tx_instrument_world_hand_force(m->world, i, fm->f0);
    memcpy(fm->x0, dev[h].pos, sizeof fm->x0);
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
    tx_set_result(c, m->npunct, m->npins);
    int through = 0;
    for (int i = 0; i < m->npins; i++) through += tx_instrument_world_needle_pin_through(m->world, i);
    tx_set_result(c, m->pulled_through, through);
    if (m->skin) tx_set_result(c, m->reanchors, m->nreanchors), tx_set_result(c, m->skin_grasps, m->nskin_grasps);
    if (m->skin && isfinite(m->clearance_min)) tx_set_result(c, m->clearance, m->clearance_min);
    for (int h = 0; h < HANDS; h++)
      if (m->skin && isfinite(m->hand_clearance_min[h])) tx_set_result(c, m->hand_clearance[h], m->hand_clearance_min[h]);
  }
  // the world goes on the thread that made and stepped it, with ODE's data for that thread
  tx_instrument_world_destroy(m->world);
  m->world = NULL;
  if (m->thread_nodes.id) {
    tx_set_result(c, m->cuts, m->ncuts), tx_set_result(c, m->thread_grasps, m->nthread_grasps);
    if (m->ncuts) tx_set_result(c, m->cut_height, m->last_cut_y);
  }
  tx_set_result(c, m->contacts_max, m->contacts_most);
  tx_set_result(c, m->switches, m->nswitches);
  tx_set_result(c, m->force_max, m->force_most);
}

static void fini(void* self) {
  instruments* m = self;
  if (!m) return;
  tx_instrument_world_destroy(m->world);
  for (int i = 0; i < TX_INSTRUMENTS_MAX; i++) tx_instrument_desc_free(m->desc[i]);
  free(m->hole_scratch);
  tx_sheet_grid_free(&m->sheet);
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
    .live = (const char* const[]){"hand0_holds", "hand1_holds", NULL},
    .tune = tune,
};
