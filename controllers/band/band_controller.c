// physics.band: the gastric band (band_sim.h) as a controller. Each step
// advances the band, publishes its surfaces and state, and sends a latch
// event when the band locks. Graspers take the band's ends (their rigid
// bodies) or, elsewhere, pick its surface triangles (../organs/picking.h).
// A numerical fault is counted and the band goes back to its last good
// state, so the model never holds a NaN.
#include "band_controller.h"

#include "band_sim.h"
#include "../organs/picking.h"
#include "../rotation.h"
#include "../system.h" // tx_param_json, tx_param_point

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define HANDS_MAX 4
enum { GRASPABLE = 2 }; // the bodies a grasper can take: the tube's tip and the buckle
static const int graspable[GRASPABLE] = {TX_BAND_TUBE_TIP, TX_BAND_BUCKLE};

// a grasper's jaws on the band: closing them near the tube's tip or the
// buckle takes that body, which then follows the jaws until they open;
// closing them anywhere else picks the surface triangles between them
typedef struct jaws {
  tx_port pose;     // read: instrumentN.pose (tx_instrument_pose)
  bool was_open;    // seen open since the last close
  bool on_end;      // closed on an end since they last opened (still, after letting it go at the lock)
  int body;         // the body held, -1 none
  double offset[3]; // m, its position in the jaws' frame when taken
} jaws;

typedef struct band {
  tx_band* b;
  int nv[TX_BAND_PARTS], nf[TX_BAND_PARTS];
  double* pos;  // (nodes x 3) m, scratch
  tx_port x, tri, state, pose, events, centre;
  int sections; // rows of band.centre: the ring's cross-sections, then the tube's
  bool hold_buckle, release_on_lock, following;
  tx_warning fault, bad_pose;
  tx_result locked_result, error_result, fault_result, substeps_result, p50_result, p99_result;
  double max_error;
  long faults;
  bool was_locked;
  tx_hist steps; // ns
  jaws hand[HANDS_MAX];
  int hands;
  double grasp_length, grasp_reach, grasp_closed, grasp_open; // m, m, rad, rad
  tx_result grasps_result, nodes_result, force_result;
  int grasps;
  tx_picking* pick;                 // the triangles picked, by hand (NULL: no graspers)
  double* part_pos[TX_BAND_PARTS];  // (nodes x 3) m, each part's nodes before the step, for the picking
  int32_t* identity;                // (largest part's nodes) a surface vertex is its node
  int pick_nodes_max;               // the most nodes one hand held
  double pick_force_max;            // N, the largest pull of the band on a hand's jaws through picked nodes
  // sleeping, as rigid-body engines do: a band at rest is not stepped (its
  // explicit substeps take about a core) until a grasper takes or picks it,
  // the only way anything moves it (it meets no other body but the fixed
  // obstacles)
  double dt;                        // s, the controller's period
  double sleep_speed, sleep_after;  // m/s, s
  double* prev;                     // (nodes x 3) m, the nodes after the last step taken
  double still_s;                   // s, how long the band has stayed slower than sleep_speed, untouched
  bool asleep;
  long slept_steps, wakes;
  tx_result slept_result, wakes_result;
} band;

// sources of the values: docs/lagb.md, "The band"
static const tx_param_def params[] = {
    {"assets", TX_PARAM_STR, NULL, 0, 0, 0, "lagb", "folder of band_ring/band_tube .node/.ele: a name in assets/ or a path (with a /)"},
    {"ring_young_pa", TX_PARAM_NUM, "Pa", 1e4, 1e8, 5e6, NULL, "the ring's Young's modulus (silicone elastomer, its stiff end)"},
    {"ring_poisson", TX_PARAM_NUM, "1", 0, 0.49, 0.3, NULL, "the ring's Poisson's ratio (below silicone's 0.49: one layer of tetrahedra would lock)"},
    {"ring_density", TX_PARAM_NUM, "kg/m^3", 100, 1e5, 1100, NULL, "the ring's density (silicone)"},
    {"ring_damping", TX_PARAM_NUM, "1/s", 0, 1e4, 60, NULL, "decay rate of the ring's node velocities: highly damped"},
    {"tube_young_pa", TX_PARAM_NUM, "Pa", 1e4, 1e8, 1e6, NULL, "the tube's Young's modulus (silicone elastomer, its soft end)"},
    {"tube_poisson", TX_PARAM_NUM, "1", 0, 0.49, 0.3, NULL, "the tube's Poisson's ratio"},
    {"tube_density", TX_PARAM_NUM, "kg/m^3", 100, 1e5, 1100, NULL, "the tube's density (silicone)"},
    {"tube_damping", TX_PARAM_NUM, "1/s", 0, 1e4, 2, NULL, "decay rate of the tube's node velocities: little"},
    {"body_mass_kg", TX_PARAM_NUM, "kg", 1e-5, 1, 0.002, NULL, "each of the four rigid bodies (buckle, connectors)"},
    {"max_substep_s", TX_PARAM_NUM, "s", 0, 1e-3, 2.5e-5, NULL,
     "the explicit substep at most; 0: the FEM's own estimate (safe by a factor of about 3, 2.5 times slower)"},
    {"buckle_radius_m", TX_PARAM_NUM, "m", 1e-4, 0.05, 0.006, NULL, "the buckle's opening: the tube's tip latches within this of its centre"},
    {"buckle_offset_m", TX_PARAM_NUM, "m", 0, 0.05, 0.006, NULL, "the opening's centre beyond the ring's head, along its tangent"},
    {"gravity", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "9.81 m/s^2 along -y; off: the band floats (nothing here holds it up)"},
    {"max_speed", TX_PARAM_NUM, "m/s", 0.01, 1e4, 50, NULL, "a faster node is a blow-up"},
    {"pull", TX_PARAM_STR, NULL, 0, 0, 0, "", "the pose the tube's tip follows (tx_pose), a grasper's or a device's; \"\": none"},
    {"hold_buckle", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "the buckle held where it is (the other hand's grasper)"},
    {"release_on_lock", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "the pull (or a grasper) lets go of the tip when the band locks"},
    {"origin_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: where the assets' origin goes in the scene; [0, 0, 0] by default"},
    {"rotation_deg", TX_PARAM_JSON, NULL, 0, 0, 0, NULL,
     "[rx, ry, rz], degrees: the assets turned about x, then y, then z (before origin_m); [0, 0, 0] by default"},
    {"obstacles", TX_PARAM_JSON, NULL, 0, 0, 0, NULL,
     "[[ax, ay, az, bx, by, bz, r], ...], m: rigid capsules the band is kept out of (the oesophagus, the cardia); none by default"},
    {"grasp", TX_PARAM_STRS, NULL, 0, HANDS_MAX, 0, NULL,
     "graspers (tx_instrument_pose: instrumentN.pose) whose closing jaws take the tube's tip or the buckle, or else pick the band's surface; none: no grasping"},
    {"grasp_length_m", TX_PARAM_NUM, "m", 0.001, 0.1, 0.02, NULL, "the jaws reach this far ahead of the pivot along the pose's x"},
    {"grasp_reach_m", TX_PARAM_NUM, "m", 0, 0.05, 0.008, NULL,
     "closing jaws take the tube's tip or the buckle when its body is this close to their line (the end's half width and the jaws')"},
    {"grasp_triangle_reach_m", TX_PARAM_NUM, "m", 0, 0.02, 0.003, NULL,
     "closing jaws with neither end in reach pick the band's surface triangles this close to their line (the jaws' half width, 2 mm, and 1 mm)"},
    {"grasp_closed_rad", TX_PARAM_NUM, "rad", 0, 1, 0.1, NULL, "jaws at or below this angle have closed: a grasp, if they were open since the last"},
    {"grasp_open_rad", TX_PARAM_NUM, "rad", 0.001, 3.2, 0.2, NULL, "jaws at or above this have opened: what they held is let go"},
    {"sleep_speed_m_s", TX_PARAM_NUM, "m/s", 0, 1, 0.001, NULL,
     "a band whose nodes all stay slower than this for sleep_after_s, held by no grasper and pulled by no pose, sleeps: it is not stepped until a grasper takes or picks it; 0: never"},
    {"sleep_after_s", TX_PARAM_NUM, "s", 0.05, 10, 0.5, NULL, "how long the band stays that still before it sleeps"},
};

// obstacles: a list of capsules, each [a, b, r] flattened, within 10 m
static int read_obstacles(tx_setup* s, tx_band_def* d) {
  json_t* j = tx_param_json(s, "obstacles");
  if (!j || json_is_null(j)) return 0;
  if (!json_is_array(j) || json_array_size(j) > TX_BAND_OBSTACLES_MAX)
    return tx_setup_fail(s, "obstacles", "expected a list of at most %d capsules [ax, ay, az, bx, by, bz, r]", TX_BAND_OBSTACLES_MAX);
  d->obstacles = (int)json_array_size(j);
  for (int c = 0; c < d->obstacles; c++) {
    json_t* cap = json_array_get(j, (size_t)c);
    if (!json_is_array(cap) || json_array_size(cap) != 7)
      return tx_setup_fail(s, "obstacles", "capsule %d: expected [ax, ay, az, bx, by, bz, r], m", c);
    for (int k = 0; k < 7; k++) {
      json_t* v = json_array_get(cap, (size_t)k);
      double x = json_is_number(v) ? json_number_value(v) : NAN;
      if (!(fabs(x) <= 10) || (k == 6 && !(x > 0 && x <= 1)))
        return tx_setup_fail(s, "obstacles", "capsule %d: expected [ax, ay, az, bx, by, bz, r], each within 10 m, r in (0, 1] m", c);
      d->obstacle[c][k] = x;
    }
  }
  return 0;
}

// rotation_deg: three angles within a turn, or none
static int read_rotation(tx_setup* s, double r[3][3]) {
  double deg[3] = {0, 0, 0};
  json_t* j = tx_param_json(s, "rotation_deg");
  if (j && !json_is_null(j)) {
    if (!json_is_array(j) || json_array_size(j) != 3) return tx_setup_fail(s, "rotation_deg", "expected [rx, ry, rz] in degrees");
    for (int a = 0; a < 3; a++) {
      json_t* v = json_array_get(j, (size_t)a);
      deg[a] = json_is_number(v) ? json_number_value(v) : NAN;
      if (!(fabs(deg[a]) <= 360)) return tx_setup_fail(s, "rotation_deg", "expected [rx, ry, rz], each a number of degrees in [-360, 360]");
    }
  }
  tx_rotation_from_degrees(deg, r);
  return 0;
}

static int configure(tx_setup* s, void** self) {
  band* g = calloc(1, sizeof *g);
  if (!g) return -1;
  *self = g;
  double rate = tx_setup_rate_in(s, TX_BAND_RATE_MIN_HZ, TX_BAND_RATE_MAX_HZ);
  if (!rate) return -1;
  const char *assets = tx_table_str(s, "assets"), *pull = tx_table_str(s, "pull");
  if (!assets || !pull) return -1;
  tx_band_def d = tx_band_def_default();
  const char* pre[TX_BAND_PARTS] = {"ring", "tube"};
  for (int i = 0; i < TX_BAND_PARTS; i++) {
    char key[64];
    snprintf(key, sizeof key, "%s_young_pa", pre[i]), d.part[i].young = tx_table_num(s, key);
    snprintf(key, sizeof key, "%s_poisson", pre[i]), d.part[i].poisson = tx_table_num(s, key);
    snprintf(key, sizeof key, "%s_density", pre[i]), d.part[i].density = tx_table_num(s, key);
    snprintf(key, sizeof key, "%s_damping", pre[i]), d.part[i].damping = tx_table_num(s, key);
  }
  d.step = 1.0 / rate;
  d.body_mass = tx_table_num(s, "body_mass_kg");
  d.max_substep = tx_table_num(s, "max_substep_s");
  d.buckle_radius = tx_table_num(s, "buckle_radius_m");
  d.buckle_offset = tx_table_num(s, "buckle_offset_m");
  d.max_speed = tx_table_num(s, "max_speed");
  if (tx_table_bool(s, "gravity")) d.gravity[1] = -9.81;
  if (tx_param_point(s, "origin_m", (const double[3]){0, 0, 0}, d.origin) || read_rotation(s, d.rotation) || read_obstacles(s, &d)) return -1;
  g->hold_buckle = tx_table_bool(s, "hold_buckle");
  g->release_on_lock = tx_table_bool(s, "release_on_lock");
  char dir[4096];
  int len = strchr(assets, '/') ? snprintf(dir, sizeof dir, "%s", assets) : snprintf(dir, sizeof dir, "%s/%s", TX_ASSET_DIR, assets);
  if (len >= (int)sizeof dir - 64) return tx_setup_fail(s, "assets", "%s: path too long", assets);
  g->b = tx_band_create(&d, dir);
  if (!g->b) return tx_setup_fail(s, "assets", "%s", tx_error());
  int nodes = 0, faces = 0;
  for (int i = 0; i < TX_BAND_PARTS; i++) {
    g->nv[i] = tx_band_nodes(g->b, i), g->nf[i] = tx_band_faces(g->b, i);
    nodes += g->nv[i], faces += g->nf[i];
  }
  g->pos = malloc(sizeof(double) * 3 * (size_t)nodes);
  g->prev = malloc(sizeof(double) * 3 * (size_t)nodes);
  if (!g->pos || !g->prev) return -1;
  g->dt = d.step;
  g->sleep_speed = tx_table_num(s, "sleep_speed_m_s");
  g->sleep_after = tx_table_num(s, "sleep_after_s");
  g->x = tx_setup_write(s, &TX_COMPONENT_OF("band.x", tx_vertex, (uint32_t)nodes));
  g->tri = tx_setup_write(s, &TX_COMPONENT_OF("band.tri", tx_triangle, (uint32_t)faces));
  g->state = tx_setup_write(s, &TX_COMPONENT_OF("band.state", tx_band_state, 1));
  g->sections = tx_band_sections(g->b, TX_BAND_RING) + tx_band_sections(g->b, TX_BAND_TUBE);
  if (tx_band_sections(g->b, TX_BAND_RING) < 2 || tx_band_sections(g->b, TX_BAND_TUBE) < 2)
    return tx_setup_fail(s, "assets", "%s: the band's nodes do not come cross-section by cross-section (tactus-band-assets)", assets);
  g->centre = tx_setup_write(s, &TX_COMPONENT_OF("band.centre", tx_vertex, (uint32_t)g->sections));
  g->events = tx_setup_emit(s, "band.events", 16);
  if (pull[0]) g->pose = TX_READ_OF(s, pull, tx_pose);
  g->fault = tx_setup_warning(s, "numerical_fault");
  g->bad_pose = tx_setup_warning(s, "bad_pose");
  g->locked_result = tx_setup_result(s, "locked");
  g->error_result = tx_setup_result(s, "joint_error_max");
  g->fault_result = tx_setup_result(s, "faults");
  g->substeps_result = tx_setup_result(s, "substeps");
  g->p50_result = tx_setup_result(s, "step_p50_ms");
  g->p99_result = tx_setup_result(s, "step_p99_ms");
  g->slept_result = tx_setup_result(s, "asleep_s");
  g->wakes_result = tx_setup_result(s, "wakes");
  tx_hist_clear(&g->steps);
  if (g->hold_buckle) {
    double p[3];
    tx_band_body_position(g->b, TX_BAND_BUCKLE, p);
    tx_band_drive(g->b, TX_BAND_BUCKLE, p);
  }
  g->following = g->pose.id != 0;
  const char* grasp[HANDS_MAX];
  g->hands = tx_table_strs(s, "grasp", grasp, HANDS_MAX);
  g->grasp_length = tx_table_num(s, "grasp_length_m");
  g->grasp_reach = tx_table_num(s, "grasp_reach_m");
  g->grasp_closed = tx_table_num(s, "grasp_closed_rad");
  g->grasp_open = tx_table_num(s, "grasp_open_rad");
  if (g->hands > 0 && !(g->grasp_open > g->grasp_closed))
    return tx_setup_fail(s, "grasp_open_rad", "must be above grasp_closed_rad (%g)", g->grasp_closed);
  for (int h = 0; h < g->hands; h++) {
    for (int k = 0; k < h; k++)
      if (!strcmp(grasp[k], grasp[h])) return tx_setup_fail(s, "grasp", "'%s' named twice", grasp[h]);
    g->hand[h].pose = TX_READ_OF(s, grasp[h], tx_instrument_pose);
  }
  if (g->hands > 0) {
    g->grasps_result = tx_setup_result(s, "grasps");
    g->nodes_result = tx_setup_result(s, "grasp_nodes_max");
    g->force_result = tx_setup_result(s, "grasp_force_max_n");
    // the picking: the jaws' move of a step spread over the band's substeps
    tx_pick_def pd = {g->grasp_length, tx_table_num(s, "grasp_triangle_reach_m"), g->grasp_closed, g->grasp_open,
                      tx_band_substeps(g->b)};
    g->pick = tx_picking_create(&pd, g->hands);
    int most = g->nv[TX_BAND_RING] > g->nv[TX_BAND_TUBE] ? g->nv[TX_BAND_RING] : g->nv[TX_BAND_TUBE];
    g->identity = malloc(sizeof(int32_t) * (size_t)most);
    if (!g->pick || !g->identity) return tx_setup_fail(s, "grasp", "%s", g->pick ? "out of memory" : tx_error());
    for (int i = 0; i < most; i++) g->identity[i] = i;
    for (int i = 0; i < TX_BAND_PARTS; i++) {
      tx_pick_surface surf = {.nv = g->nv[i], .nt = g->nf[i], .tri = tx_band_face_nodes(g->b, i), .per = 1, .node = g->identity};
      g->part_pos[i] = malloc(sizeof(double) * 3 * (size_t)g->nv[i]);
      if (!g->part_pos[i] || tx_picking_add(g->pick, tx_band_fem(g->b, i), &surf) < 0)
        return tx_setup_fail(s, "grasp", "%s", g->part_pos[i] ? tx_error() : "out of memory");
    }
  }
  return 0;
}

static double segment_distance(const double p[3], const double a[3], const double b[3]) {
  double ab[3], ap[3], t = 0, l2 = 0;
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ap[k] = p[k] - a[k], t += ab[k] * ap[k], l2 += ab[k] * ab[k];
  t = l2 > 0 ? fmin(fmax(t / l2, 0), 1) : 0;
  double d2 = 0;
  for (int k = 0; k < 3; k++) d2 += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
  return sqrt(d2);
}

static void let_go(tx_ctx* c, band* g, int h, bool event) {
  jaws* j = &g->hand[h];
  if (j->body < 0) return;
  bool held_still = (j->body == TX_BAND_BUCKLE && g->hold_buckle) || (j->body == TX_BAND_TUBE_TIP && g->following);
  if (!held_still) tx_band_free(g->b, j->body);
  j->body = -1;
  if (event) tx_emit(c, g->events, &(tx_event){.kind = TX_EVENT_RELEASE, .source = (uint32_t)h});
}

// each grasper: closing jaws take the nearest graspable body within reach,
// opening ones let it go; a held body is driven where the jaws carry it
static void grasp_step(tx_ctx* c, band* g) {
  for (int i = 0; i < TX_BAND_PARTS && g->pick; i++) tx_band_positions(g->b, i, g->part_pos[i]);
  for (int h = 0; h < g->hands; h++) {
    jaws* j = &g->hand[h];
    tx_snapshot sn = tx_read(c, j->pose);
    if (!sn.seq) continue;
    const tx_instrument_pose* p = sn.data;
    double qn = sqrt(p->quat[0] * p->quat[0] + p->quat[1] * p->quat[1] + p->quat[2] * p->quat[2] + p->quat[3] * p->quat[3]);
    if (!isfinite(p->pos[0] + p->pos[1] + p->pos[2] + p->jaw) || !(qn > 0.5 && qn < 2)) {
      tx_warn(c, g->bad_pose);
      continue;
    }
    const double q[4] = {p->quat[0] / qn, p->quat[1] / qn, p->quat[2] / qn, p->quat[3] / qn};
    if (p->jaw >= g->grasp_open) {
      j->was_open = true;
      j->on_end = false;
      let_go(c, g, h, true);
    } else if (p->jaw <= g->grasp_closed && j->was_open && j->body < 0) {
      j->was_open = false;
      double ahead[3], end[3], best = g->grasp_reach;
      tx_quat_rotate(q, false, (const double[3]){g->grasp_length, 0, 0}, ahead);
      for (int k = 0; k < 3; k++) end[k] = p->pos[k] + ahead[k];
      for (int i = 0; i < GRASPABLE; i++) {
        bool taken = false;
        for (int o = 0; o < g->hands; o++) taken |= g->hand[o].body == graspable[i];
        double at[3];
        tx_band_body_position(g->b, graspable[i], at);
        double d = segment_distance(at, p->pos, end);
        if (!taken && d <= best) best = d, j->body = graspable[i];
      }
      if (j->body >= 0) {
        double at[3], rel[3];
        tx_band_body_position(g->b, j->body, at);
        for (int k = 0; k < 3; k++) rel[k] = at[k] - p->pos[k];
        tx_quat_rotate(q, true, rel, j->offset);
        tx_event e = {.kind = TX_EVENT_GRASP, .source = (uint32_t)h};
        for (int k = 0; k < 3; k++) e.grasp.point[k] = at[k];
        e.grasp.jaw = p->jaw;
        tx_emit(c, g->events, &e);
        g->grasps++;
        j->on_end = true;
      }
    }
    if (j->body >= 0) {
      double at[3];
      tx_quat_rotate(q, false, j->offset, at);
      for (int k = 0; k < 3; k++) at[k] += p->pos[k];
      tx_band_drive(g->b, j->body, at);
      continue;
    }
    if (j->on_end) continue; // they let go of an end at the lock, still closed: nothing else until they open
    // no end held: the jaws pick the triangles between them, or carry what they picked
    tx_instrument_pose jw = *p;
    memcpy(jw.quat, q, sizeof q);
    tx_event e;
    if (tx_picking_update(g->pick, h, &jw, (const double* const*)g->part_pos, &e)) {
      tx_emit(c, g->events, &e);
      if (e.kind == TX_EVENT_GRASP) g->grasps++;
    }
    if (tx_picking_nodes(g->pick, h) > g->pick_nodes_max) g->pick_nodes_max = tx_picking_nodes(g->pick, h);
  }
}

static void publish(tx_ctx* c, band* g) {
  float* x = ((tx_vertex*)tx_write(c, g->x))->x;
  int32_t* t = ((tx_triangle*)tx_write(c, g->tri))->v;
  float* centre = ((tx_vertex*)tx_write(c, g->centre))->x;
  int base = 0, row = 0;
  for (int i = 0; i < TX_BAND_PARTS; i++) {
    tx_band_positions(g->b, i, g->pos);
    for (int k = 0; k < 3 * g->nv[i]; k++) x[3 * base + k] = (float)g->pos[k];
    // the loop from the buckle: the ring from its head (its last section) back, the tube from its head on
    int n = tx_band_sections(g->b, i);
    for (int k = 0; k < n; k++, row++) {
      double m[3];
      tx_band_section_centre(g->b, i, i == TX_BAND_RING ? n - 1 - k : k, g->pos, m);
      for (int a = 0; a < 3; a++) centre[3 * row + a] = (float)m[a];
    }
    const int32_t* f = tx_band_face_nodes(g->b, i);
    for (int k = 0; k < 3 * g->nf[i]; k++) *t++ = f[k] + base;
    base += g->nv[i];
  }
  tx_band_state* st = tx_write(c, g->state);
  double l = tx_band_joint_length(g->b), r = tx_band_joint_rest(g->b), tip[3], bc[3], ax[3];
  tx_band_body_position(g->b, TX_BAND_TUBE_TIP, tip);
  tx_band_buckle(g->b, bc, ax);
  st->locked = tx_band_locked(g->b);
  st->joint_length = l;
  st->joint_error = l / r - 1;
  st->tip_to_buckle = sqrt((tip[0] - bc[0]) * (tip[0] - bc[0]) + (tip[1] - bc[1]) * (tip[1] - bc[1]) + (tip[2] - bc[2]) * (tip[2] - bc[2]));
  g->max_error = fmax(g->max_error, fabs(st->joint_error));
}

// the largest node move since the last step taken, m; the nodes kept for the next
static double nodes_moved(band* g) {
  double most = 0;
  int base = 0;
  for (int i = 0; i < TX_BAND_PARTS; i++) {
    tx_band_positions(g->b, i, g->pos + 3 * base);
    base += g->nv[i];
  }
  for (int k = 0; k < base; k++) {
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (g->pos[3 * k + a] - g->prev[3 * k + a]) * (g->pos[3 * k + a] - g->prev[3 * k + a]);
    most = fmax(most, d2);
  }
  memcpy(g->prev, g->pos, sizeof(double) * 3 * (size_t)base);
  return sqrt(most);
}

static bool touched(const band* g) {
  if (g->following) return true;
  for (int h = 0; h < g->hands; h++)
    if (g->hand[h].body >= 0 || (g->pick && tx_picking_nodes(g->pick, h) > 0)) return true;
  return false;
}

static int init(tx_ctx* c, void* self) {
  band* g = self;
  for (int h = 0; h < g->hands; h++) g->hand[h].body = -1, g->hand[h].was_open = g->hand[h].on_end = false;
  g->grasps = g->pick_nodes_max = 0;
  g->pick_force_max = 0;
  if (g->pick) tx_picking_release(g->pick, -1);
  g->asleep = false, g->still_s = 0, g->slept_steps = g->wakes = 0;
  nodes_moved(g);
  publish(c, self); // the band at rest, at time 0
  return 0;
}

static void step(tx_ctx* c, void* self) {
  band* g = self;
  struct timespec t0, t1;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
  if (g->following) {
    tx_snapshot p = tx_read(c, g->pose);
    if (p.seq > 0) { // nothing published yet: the tip waits
      const tx_pose* pose = p.data;
      if (isfinite(pose->pos[0] + pose->pos[1] + pose->pos[2])) tx_band_drive(g->b, TX_BAND_TUBE_TIP, pose->pos);
      else tx_warn(c, g->bad_pose);
    }
  }
  grasp_step(c, g); // on the still band as it lies, asleep or not
  if (g->asleep && !touched(g)) { // nothing moves it: nothing to step or publish
    g->slept_steps++;
    return;
  }
  if (g->asleep) g->asleep = false, g->still_s = 0, g->wakes++;
  if (tx_band_step(g->b)) {
    tx_band_save(g->b);
    for (int h = 0; h < g->hands && g->pick; h++) {
      double f[3];
      tx_picking_force(g->pick, h, f);
      g->pick_force_max = fmax(g->pick_force_max, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    }
  } else {
    tx_warn(c, g->fault);
    g->faults++;
    tx_band_restore(g->b);
  }
  bool locked = tx_band_locked(g->b);
  if (locked && !g->was_locked) {
    tx_event e = {.kind = TX_EVENT_LATCH, .source = 0};
    double bc[3], ax[3];
    tx_band_buckle(g->b, bc, ax);
    for (int a = 0; a < 3; a++) e.value[a] = bc[a];
    tx_emit(c, g->events, &e);
    if (g->release_on_lock && g->following) g->following = false, tx_band_free(g->b, TX_BAND_TUBE_TIP);
    for (int h = 0; h < g->hands && g->release_on_lock; h++)
      if (g->hand[h].body == TX_BAND_TUBE_TIP) let_go(c, g, h, true);
  }
  g->was_locked = locked;
  publish(c, g);
  bool still = nodes_moved(g) < g->sleep_speed * g->dt && !touched(g);
  g->still_s = still ? g->still_s + g->dt : 0;
  g->asleep = g->sleep_speed > 0 && g->still_s >= g->sleep_after;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  tx_hist_add(&g->steps, (int64_t)(t1.tv_sec - t0.tv_sec) * 1000000000 + (t1.tv_nsec - t0.tv_nsec));
}

static void finish(tx_ctx* c, void* self) {
  band* g = self;
  tx_percentiles p = tx_hist_percentiles(&g->steps);
  tx_set_result(c, g->locked_result, tx_band_locked(g->b) ? 1 : 0);
  tx_set_result(c, g->error_result, g->max_error);
  tx_set_result(c, g->fault_result, (double)g->faults);
  tx_set_result(c, g->substeps_result, tx_band_substeps(g->b));
  tx_set_result(c, g->p50_result, p.p50 * 1e-6);
  tx_set_result(c, g->p99_result, p.p99 * 1e-6);
  tx_set_result(c, g->slept_result, (double)g->slept_steps * g->dt);
  tx_set_result(c, g->wakes_result, (double)g->wakes);
  if (g->hands > 0) {
    tx_set_result(c, g->grasps_result, g->grasps);
    tx_set_result(c, g->nodes_result, g->pick_nodes_max);
    tx_set_result(c, g->force_result, g->pick_force_max);
  }
}

static void fini(void* self) {
  band* g = self;
  if (!g) return;
  tx_band_destroy(g->b);
  tx_picking_destroy(g->pick);
  for (int i = 0; i < TX_BAND_PARTS; i++) free(g->part_pos[i]);
  free(g->identity);
  free(g->pos);
  free(g->prev);
  free(g);
}

const tx_controller_class tx_physics_band = {
    .type = "physics.band",
    .summary = "LAGB gastric band on Bullet and ODE: a ring and a tube (FEM), their rigid bodies, a double-ball joint, "
               "the latch at the buckle; writes band.x/.tri, band.state, band.events",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
