// physics.membrane: a thin membrane attached all round (a cloth patch in its
// own frame, placed in the scene by centre, normal and axis) that a cautery
// hook boils away particle by particle, that scissors cut, and that counts
// the tools passing through its holes. Every step publishes the particles in
// the scene frame, the live triangles, the temperatures and the state; a
// numerical fault of the cloth is counted and the patch goes back to its
// last good state.
#include "membrane_controller.h"

#include "membrane_heat.h"
#include "../physics/bullet/cloth.h"
#include "../rotation.h"
#include "../system.h" // tx_param_json, tx_param_point

#include <tactus/components.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TOOLS_MAX 8

typedef struct membrane {
  tx_cloth* cloth;        // in the local frame: plane y = 0, centre at the origin
  tx_membrane_heat* heat; // on the same particles
  int nx, nz, n, ntri;
  double dt, spacing, thickness;
  double origin[2];       // m, local x and z of particle 0 at rest
  double center[3];       // m, the patch's centre in the scene
  double rot[3][3];       // columns: the local x, y (normal), z axes in the scene
  // the hook
  tx_port pose, grip;
  int button;
  double offset[3], power, radius, contact;
  double active_s;
  // the scissors
  tx_port scissors;
  double open_rad, closed_rad, blade, reach;
  bool was_open;
  // tools that may pass through
  int ntools;
  tx_port tools[TOOLS_MAX];
  double tool_prev[TOOLS_MAX][3]; // m, local, last step
  bool tool_seen[TOOLS_MAX];
  // the mesh now
  float* xl;           // (n x 3) m, local positions
  int32_t* tri;        // (ntri x 3) scratch: the live triangles
  int live;            // live triangles at the last count
  uint8_t* cell;       // ((nx - 1)(nz - 1)) live triangles in each cell
  int32_t *queue, *mark; // ((nx - 1)(nz - 1)) scratch: the flood over open cells
  int32_t* ends;         // (2 (nz - 1)) scratch: an opening's first and last cell in each row
  tx_membrane_state st;
  double peak;         // K, the hottest particle of the run
  tx_port x_out, tri_out, temp_out, state_out;
  tx_warning fault, bad_pose, through_tissue;
  tx_result removed_r, burnt_r, cut_r, fallen_r, passes_r, opening_r, peak_r, damaged_r, energy_r, boiled_r, active_r,
      faults_r, p50_r, p99_r;
  tx_hist steps; // ns
} membrane;

// IT'IS tissue properties database v4.1 (Hasgall et al. 2022), fat (the
// omentum is fatty areolar tissue); Arrhenius A and Ea as physics.cautery's
static const tx_param_def params[] = {
    {"center_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: the patch's centre in the scene; [0, 0, 0] by default"},
    {"normal", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z]: the patch's normal (its local +y) in the scene; [0, 1, 0] by default"},
    {"axis", TX_PARAM_JSON, NULL, 0, 0, 0, NULL,
     "[x, y, z]: the patch's local +x in the scene, made square to normal; [1, 0, 0] by default"},
    {"size_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[w, h], m: the patch's extents along local x and z, each dividing by spacing_m; [0.03, 0.03] by default"},
    {"spacing_m", TX_PARAM_NUM, "m", 2e-4, 0.01, 0.001, NULL, "particle spacing"},
    {"thickness_m", TX_PARAM_NUM, "m", 1e-5, 0.01, 0.001, NULL, "the membrane's thickness: heat capacity, conduction, perfusion, mass"},
    {"stretch_stiffness", TX_PARAM_NUM, "N/m", 1e-3, 1e6, 10, NULL,
     "k of the stretch and shear links; E t = 1.5 k = 15 N/m, E = 15 kPa at 1 mm: soft fatty areolar tissue"},
    {"bend_stiffness", TX_PARAM_NUM, "N/m", 0, 1e6, 0.1, NULL, "k of the bending links: a membrane barely resists bending"},
    {"damping", TX_PARAM_NUM, "1/s", 0, 1e4, 5, NULL, "decay rate of particle velocities"},
    {"tissue_k", TX_PARAM_NUM, "W/(m K)", 0.01, 5, 0.21, NULL, "thermal conductivity (IT'IS, fat)"},
    {"tissue_rho", TX_PARAM_NUM, "kg/m^3", 100, 3000, 911, NULL, "density (IT'IS, fat); also the cloth's mass"},
    {"tissue_c", TX_PARAM_NUM, "J/(kg K)", 100, 10000, 2348, NULL, "heat capacity (IT'IS, fat)"},
    {"perfusion", TX_PARAM_NUM, "ml/(min kg)", 0, 10000, 33, NULL, "blood perfusion (IT'IS heat transfer rate, fat)"},
    {"blood_k", TX_PARAM_NUM, "K", 300, 320, TX_BODY_TEMPERATURE_K, NULL, "the arterial blood's temperature, and the membrane's at rest"},
    {"vaporisation_k", TX_PARAM_NUM, "K", 320, 500, TX_VAPORISATION_K, NULL,
     "tissue boils here: a particle that reaches it is vaporised, its links and triangles gone"},
    {"insulated_border", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "the border ring is insulated; false: held at blood_k (attached to perfused organs)"},
    {"arrhenius_a", TX_PARAM_NUM, "1/s", 1, 1e100, 7.39e39, NULL, "Arrhenius frequency factor A (as physics.cautery)"},
    {"arrhenius_ea", TX_PARAM_NUM, "J/mol", 1e4, 1e6, 2.577e5, NULL, "Arrhenius activation energy Ea (as physics.cautery)"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device1.pose", "the pose the hook follows (tx_pose); \"\": no hook"},
    {"tip_x_m", TX_PARAM_NUM, "m", -0.5, 0.5, 0, NULL, "the hook's tip in the pose's frame, x"},
    {"tip_y_m", TX_PARAM_NUM, "m", -0.5, 0.5, 0, NULL, "the hook's tip in the pose's frame, y"},
    {"tip_z_m", TX_PARAM_NUM, "m", -0.5, 0.5, 0, NULL, "the hook's tip in the pose's frame, z"},
    {"grip", TX_PARAM_STR, NULL, 0, 0, 0, "device1.grip", "the device's grip and buttons (tx_device_grip); \"\": always active"},
    {"button", TX_PARAM_INT, "1", 0, 31, 0, NULL, "the bit of the grip's buttons that activates the hook (a foot pedal)"},
    {"power_w", TX_PARAM_NUM, "W", 0, 300, 30, NULL, "the power into the membrane while active and touching; 0: no hook"},
    {"radius_m", TX_PARAM_NUM, "m", 1e-4, 0.02, 0.002, NULL, "the source's Gaussian radius around the tip, exp(-r^2/(2 radius^2))"},
    {"contact_m", TX_PARAM_NUM, "m", 0, 0.02, 0.002, NULL,
     "the tip heats when at most this plus half the thickness from the nearest live particle"},
    {"scissors", TX_PARAM_STR, NULL, 0, 0, 0, "", "the scissors' pose and jaw (tx_instrument_pose, pivot at pos, blades along x); \"\": none"},
    {"open_rad", TX_PARAM_NUM, "rad", 0, 3.2, 0.2, NULL, "jaws seen at or above this are open"},
    {"closed_rad", TX_PARAM_NUM, "rad", 0, 3.2, 0.1, NULL, "open jaws that come to or below this have closed: a cut; below open_rad"},
    {"blade_length_m", TX_PARAM_NUM, "m", 1e-3, 0.1, 0.015, NULL, "the blades run this far from the pivot along the pose's x"},
    {"cut_reach_m", TX_PARAM_NUM, "m", 0, 0.05, 0.003, NULL, "the part of the blades this close to the membrane's plane cuts it"},
    {"tools", TX_PARAM_STRS, NULL, 0, TOOLS_MAX, 0, NULL, "tool poses (tx_pose) whose crossings of the membrane are counted"},
};

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// a scene point in the patch's frame
static void to_local(const membrane* m, const double p[3], double out[3]) {
  const double d[3] = {p[0] - m->center[0], p[1] - m->center[1], p[2] - m->center[2]};
  for (int a = 0; a < 3; a++) out[a] = d[0] * m->rot[0][a] + d[1] * m->rot[1][a] + d[2] * m->rot[2][a];
}

static bool finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

// a direction parameter: its JSON [x, y, z], def when absent; -1 for a zero one
static int read_direction(tx_setup* s, const char* key, const double def[3], double out[3]) {
  if (tx_param_point(s, key, def, out)) return -1;
  double l = sqrt(dot(out, out));
  if (!(l > 1e-9)) return tx_setup_fail(s, key, "a direction must not be zero");
  for (int a = 0; a < 3; a++) out[a] /= l;
  return 0;
}

// size_m: [w, h], each a whole number of spacings from 2 to 1023
static int read_size(tx_setup* s, double spacing, double size[2], int res[2]) {
  size[0] = size[1] = 0.03;
  json_t* j = tx_param_json(s, "size_m");
  if (j && !json_is_null(j)) {
    if (!json_is_array(j) || json_array_size(j) != 2) return tx_setup_fail(s, "size_m", "expected [w, h] in m");
    for (int a = 0; a < 2; a++) {
      json_t* v = json_array_get(j, (size_t)a);
      if (!json_is_number(v) || !(json_number_value(v) > 0) || !(json_number_value(v) <= 1))
        return tx_setup_fail(s, "size_m", "element %d must be a number in (0, 1]", a);
      size[a] = json_number_value(v);
    }
  }
  for (int a = 0; a < 2; a++) {
    double cells = size[a] / spacing;
    if (fabs(cells - lround(cells)) > 1e-6 * cells || lround(cells) < 2 || lround(cells) > 1023)
      return tx_setup_fail(s, "size_m", "%g m is not 2 to 1023 whole spacings of %g m", size[a], spacing);
    res[a] = (int)lround(cells) + 1;
    size[a] = (res[a] - 1) * spacing;
  }
  return 0;
}

static int configure(tx_setup* s, void** self) {
  membrane* m = calloc(1, sizeof *m);
  if (!m) return -1;
  *self = m;
  double rate = tx_setup_rate_in(s, TX_MEMBRANE_RATE_MIN_HZ, TX_MEMBRANE_RATE_MAX_HZ);
  if (!rate) return -1;
  m->dt = 1 / rate;

  // placement: local x = axis, y = normal, z = x cross y
  double normal[3], axis[3], size[2];
  int res[2];
  if (tx_param_point(s, "center_m", (double[3]){0, 0, 0}, m->center)) return -1;
  if (read_direction(s, "normal", (double[3]){0, 1, 0}, normal) || read_direction(s, "axis", (double[3]){1, 0, 0}, axis)) return -1;
  double along = dot(axis, normal);
  for (int a = 0; a < 3; a++) axis[a] -= along * normal[a];
  double l = sqrt(dot(axis, axis));
  if (!(l > 1e-3)) return tx_setup_fail(s, "axis", "is parallel to normal");
  for (int a = 0; a < 3; a++) m->rot[a][0] = axis[a] / l, m->rot[a][1] = normal[a];
  m->rot[0][2] = m->rot[1][0] * m->rot[2][1] - m->rot[2][0] * m->rot[1][1];
  m->rot[1][2] = m->rot[2][0] * m->rot[0][1] - m->rot[0][0] * m->rot[2][1];
  m->rot[2][2] = m->rot[0][0] * m->rot[1][1] - m->rot[1][0] * m->rot[0][1];
  m->spacing = tx_table_num(s, "spacing_m");
  m->thickness = tx_table_num(s, "thickness_m");
  if (read_size(s, m->spacing, size, res)) return -1;

  // the cloth: attached all round, no gravity (the organs hold it), torn only by heat and scissors
  const double rho = tx_table_num(s, "tissue_rho");
  tx_cloth_def d = tx_cloth_def_default();
  d.size[0] = size[0], d.size[1] = size[1];
  d.res[0] = res[0], d.res[1] = res[1];
  d.thickness = m->thickness;
  d.mass = rho * m->thickness * size[0] * size[1];
  d.stretch_stiffness = tx_table_num(s, "stretch_stiffness");
  d.bend_stiffness = tx_table_num(s, "bend_stiffness");
  d.damping = tx_table_num(s, "damping");
  d.gravity = 0;
  d.fixed_border = true;
  d.rupture_tension = 0;
  if (tx_cloth_def_check(&d)) return tx_setup_fail(s, NULL, "%s", tx_error());
  m->cloth = tx_cloth_create(&d);
  if (!m->cloth) return tx_setup_fail(s, NULL, "%s", tx_error());
  m->nx = res[0], m->nz = res[1];
  m->n = tx_cloth_particle_count(m->cloth), m->ntri = tx_cloth_triangle_count(m->cloth);
  double p0[3];
  tx_cloth_particle(m->cloth, 0, p0);
  m->origin[0] = p0[0], m->origin[1] = p0[2];

  // the heat on the same grid
  tx_membrane_heat_def hd = {.nx = res[0], .nz = res[1], .spacing = m->spacing, .thickness = m->thickness};
  hd.tissue.k = tx_table_num(s, "tissue_k");
  hd.tissue.rho = rho;
  hd.tissue.c = tx_table_num(s, "tissue_c");
  hd.tissue.perfusion = tx_perfusion_coefficient(tx_table_num(s, "perfusion"), rho);
  hd.tissue.t_arterial = tx_table_num(s, "blood_k");
  hd.vaporisation_k = tx_table_num(s, "vaporisation_k");
  hd.insulated = tx_table_bool(s, "insulated_border");
  hd.damage = (tx_arrhenius){tx_table_num(s, "arrhenius_a"), tx_table_num(s, "arrhenius_ea")};
  if (!(hd.vaporisation_k > hd.tissue.t_arterial))
    return tx_setup_fail(s, "vaporisation_k", "%g K is not above the blood's %g K", hd.vaporisation_k, hd.tissue.t_arterial);
  m->heat = tx_membrane_heat_create(&hd);
  if (!m->heat) return tx_setup_fail(s, NULL, "%s", tx_error());

  // the hook
  const char *pose = tx_table_str(s, "pose"), *grip = tx_table_str(s, "grip"), *scissors = tx_table_str(s, "scissors");
  if (!pose || !grip || !scissors) return -1;
  m->offset[0] = tx_table_num(s, "tip_x_m"), m->offset[1] = tx_table_num(s, "tip_y_m"), m->offset[2] = tx_table_num(s, "tip_z_m");
  m->button = (int)tx_table_int(s, "button");
  m->power = tx_table_num(s, "power_w"), m->radius = tx_table_num(s, "radius_m"), m->contact = tx_table_num(s, "contact_m");
  if (pose[0] && m->power > 0) {
    m->pose = TX_READ_OF(s, pose, tx_pose);
    if (grip[0]) m->grip = TX_READ_OF(s, grip, tx_device_grip);
  }
  // the scissors
  m->open_rad = tx_table_num(s, "open_rad"), m->closed_rad = tx_table_num(s, "closed_rad");
  m->blade = tx_table_num(s, "blade_length_m"), m->reach = tx_table_num(s, "cut_reach_m");
  if (!(m->closed_rad < m->open_rad))
    return tx_setup_fail(s, "closed_rad", "%g rad is not below open_rad = %g rad", m->closed_rad, m->open_rad);
  if (scissors[0]) m->scissors = TX_READ_OF(s, scissors, tx_instrument_pose);
  // the tools
  const char* tools[TOOLS_MAX];
  m->ntools = tx_table_strs(s, "tools", tools, TOOLS_MAX);
  for (int t = 0; t < m->ntools; t++) {
    if (!tools[t][0]) return tx_setup_fail(s, "tools", "entry %d names no pose", t);
    for (int u = 0; u < t; u++)
      if (!strcmp(tools[u], tools[t])) return tx_setup_fail(s, "tools", "'%s' named twice", tools[t]);
    // the hook's own pose is read once, and counted as a tool too
    m->tools[t] = m->pose.id && !strcmp(tools[t], pose) ? m->pose : TX_READ_OF(s, tools[t], tx_pose);
  }

  // what it writes, under its own name
  const char* name = tx_setup_name(s);
  char key[TX_NAME_MAX + 16];
  snprintf(key, sizeof key, "%s.x", name), m->x_out = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_vertex, (uint32_t)m->n));
  snprintf(key, sizeof key, "%s.tri", name), m->tri_out = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_triangle, (uint32_t)m->ntri));
  snprintf(key, sizeof key, "%s.temperature", name);
  m->temp_out = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_temperature, (uint32_t)m->n));
  // the header's units, while they fit the model's TX_UNITS_MAX; otherwise the same units, each named once
  const char* units = sizeof tx_membrane_state_UNITS <= TX_UNITS_MAX ? tx_membrane_state_UNITS : "m, 1, K, m^2";
  snprintf(key, sizeof key, "%s.state", name);
  m->state_out = tx_setup_write(s, &(tx_component_def){key, tx_membrane_state_TYPE, 1, tx_membrane_state_COLS, units});
  m->fault = tx_setup_warning(s, "numerical_fault");
  m->bad_pose = tx_setup_warning(s, "bad_pose");
  m->through_tissue = tx_setup_warning(s, "passed_through_tissue");
  const char* results[] = {"removed", "burnt", "cut", "fallen", "passes", "opening_m", "peak_k", "damaged_m2", "energy_j",
                           "boiled_j", "active_s", "faults", "step_p50_ms", "step_p99_ms"};
  tx_result* slots[] = {&m->removed_r, &m->burnt_r, &m->cut_r, &m->fallen_r, &m->passes_r, &m->opening_r, &m->peak_r,
                        &m->damaged_r, &m->energy_r, &m->boiled_r, &m->active_r, &m->faults_r, &m->p50_r, &m->p99_r};
  for (int r = 0; r < 14; r++) *slots[r] = tx_setup_result(s, results[r]);

  // the scratch of a step, made here: a step never allocates
  const size_t cells = (size_t)(m->nx - 1) * (size_t)(m->nz - 1);
  m->xl = malloc(sizeof(float) * 3 * (size_t)m->n);
  m->tri = malloc(sizeof(int32_t) * 3 * (size_t)m->ntri);
  m->cell = malloc(cells), m->queue = malloc(sizeof(int32_t) * cells), m->mark = malloc(sizeof(int32_t) * cells);
  m->ends = malloc(sizeof(int32_t) * 2 * (size_t)(m->nz - 1));
  if (!m->xl || !m->tri || !m->cell || !m->queue || !m->mark || !m->ends) return tx_setup_fail(s, NULL, "out of memory");
  tx_hist_clear(&m->steps);
  return 0;
}

// the live triangles now (into m->tri); their count
static int count_live(membrane* m) { return tx_cloth_triangles(m->cloth, m->tri); }

// The largest opening: the cells with both triangles gone, 4-connected; of
// the largest set, its longest extent at rest (the farthest two cell
// centres, plus one spacing for the cells' own width). The farthest two lie
// on the set's convex hull, so each is the first or the last of its row:
// pairs of those, not of every cell (a membrane burnt whole has 900 cells)
static double opening(membrane* m) {
  const int cx = m->nx - 1, cz = m->nz - 1, cells = cx * cz;
  for (int c = 0; c < cells; c++) m->mark[c] = 0;
  int best = 0;
  double extent = 0;
  for (int c0 = 0; c0 < cells; c0++) {
    if (m->cell[c0] || m->mark[c0]) continue;
    int tail = 0;
    m->queue[tail++] = c0, m->mark[c0] = 1;
    for (int head = 0; head < tail; head++) {
      const int c = m->queue[head], x = c % cx, z = c / cx;
      const int nb[4] = {x > 0 ? c - 1 : -1, x < cx - 1 ? c + 1 : -1, z > 0 ? c - cx : -1, z < cz - 1 ? c + cx : -1};
      for (int k = 0; k < 4; k++)
        if (nb[k] >= 0 && !m->cell[nb[k]] && !m->mark[nb[k]]) m->mark[nb[k]] = 1, m->queue[tail++] = nb[k];
    }
    if (tail < best) continue;
    int32_t *lo = m->ends, *hi = m->ends + cz;
    for (int z = 0; z < cz; z++) lo[z] = cx, hi[z] = -1;
    for (int a = 0; a < tail; a++) {
      const int x = m->queue[a] % cx, z = m->queue[a] / cx;
      lo[z] = x < lo[z] ? x : lo[z], hi[z] = x > hi[z] ? x : hi[z];
    }
    double far2 = 0;
    for (int za = 0; za < cz; za++)
      for (int zb = za; zb < cz && hi[za] >= 0; zb++) {
        if (hi[zb] < 0) continue;
        const double dz = zb - za, d1 = hi[zb] - lo[za], d2 = hi[za] - lo[zb];
        far2 = fmax(far2, fmax(d1 * d1, d2 * d2) + dz * dz);
      }
    const double e = (sqrt(far2) + 1) * m->spacing;
    if (tail > best || e > extent) extent = e;
    best = tail;
  }
  return extent;
}

// after triangles left: the cells' counts, the heat's edges, the opening
static void remesh(membrane* m, int live) {
  const int cx = m->nx - 1;
  memset(m->cell, 0, (size_t)cx * (size_t)(m->nz - 1));
  for (int f = 0; f < live; f++) {
    const int32_t* v = m->tri + 3 * f;
    int x = m->nx, z = m->nz;
    for (int k = 0; k < 3; k++) {
      const int vx = v[k] % m->nx, vz = v[k] / m->nx;
      x = vx < x ? vx : x, z = vz < z ? vz : z;
    }
    m->cell[z * cx + x]++;
  }
  tx_membrane_heat_edges(m->heat, m->tri, live);
  m->st.opening_m = opening(m);
  m->live = live;
}

// the hook's tip in the local frame, when the hook is on: active (its
// button held) and its pose finite
static bool hook_tip(tx_ctx* c, membrane* m, double tip[3]) {
  if (!m->pose.id) return false;
  tx_snapshot p = tx_read(c, m->pose);
  if (p.seq == 0) return false;
  const tx_pose* pose = p.data;
  double off[3], at[3];
  tx_quat_rotate(pose->quat, false, m->offset, off);
  for (int a = 0; a < 3; a++) at[a] = pose->pos[a] + off[a];
  if (!finite3(at)) return tx_warn(c, m->bad_pose), false;
  if (m->grip.id) {
    tx_snapshot gs = tx_read(c, m->grip);
    double b = gs.seq > 0 ? ((const tx_device_grip*)gs.data)->buttons : 0;
    if (!(b >= 0 && b < 4294967296.0 && (((uint32_t)b >> m->button) & 1u))) return false;
  }
  to_local(m, at, tip);
  return true;
}

// the power goes in while the tip touches: within contact + half the
// thickness of the nearest live particle
static void heat_source(tx_ctx* c, membrane* m) {
  double tip[3];
  bool on = hook_tip(c, m, tip);
  double near2 = INFINITY;
  for (int i = 0; on && i < m->n; i++) {
    if (!tx_membrane_heat_live(m->heat, i)) continue;
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (m->xl[3 * i + a] - tip[a]) * (m->xl[3 * i + a] - tip[a]);
    near2 = fmin(near2, d2);
  }
  const double reach = m->contact + m->thickness / 2;
  if (on && near2 <= reach * reach && tx_membrane_heat_source(m->heat, m->xl, tip, m->radius, m->power) > 0) m->active_s += m->dt;
  else tx_membrane_heat_source(m->heat, m->xl, tip, m->radius, 0);
}

// jaws seen open and now closed cut along the blades' part within reach of
// the plane, projected onto it
static void scissors(tx_ctx* c, membrane* m) {
  if (!m->scissors.id) return;
  tx_snapshot p = tx_read(c, m->scissors);
  if (p.seq == 0) return;
  const tx_instrument_pose* jp = p.data;
  const double qq = jp->quat[0] * jp->quat[0] + jp->quat[1] * jp->quat[1] + jp->quat[2] * jp->quat[2] + jp->quat[3] * jp->quat[3];
  if (!finite3(jp->pos) || !isfinite(jp->jaw) || !(qq > 0.5 && qq < 2)) return tx_warn(c, m->bad_pose);
  if (jp->jaw >= m->open_rad) m->was_open = true;
  if (!(m->was_open && jp->jaw <= m->closed_rad)) return;
  m->was_open = false;
  double q[4] = {jp->quat[0] / sqrt(qq), jp->quat[1] / sqrt(qq), jp->quat[2] / sqrt(qq), jp->quat[3] / sqrt(qq)}, dir[3], end[3];
  tx_quat_rotate(q, false, (double[3]){m->blade, 0, 0}, dir);
  for (int a = 0; a < 3; a++) end[a] = jp->pos[a] + dir[a];
  double a[3], b[3];
  to_local(m, jp->pos, a), to_local(m, end, b);
  // the part with |y| <= reach: t in [lo, hi] along a-b
  double lo = 0, hi = 1, dy = b[1] - a[1];
  if (fabs(dy) < 1e-15) {
    if (fabs(a[1]) > m->reach) return;
  } else {
    double t1 = (-m->reach - a[1]) / dy, t2 = (m->reach - a[1]) / dy;
    lo = fmax(lo, fmin(t1, t2)), hi = fmin(hi, fmax(t1, t2));
    if (!(lo < hi)) return;
  }
  double pa[3], pb[3];
  for (int k = 0; k < 3; k++) pa[k] = a[k] + lo * (b[k] - a[k]), pb[k] = a[k] + hi * (b[k] - a[k]);
  pa[1] = pb[1] = 0;
  const int before = count_live(m);
  tx_cloth_cut(m->cloth, pa, pb);
  m->st.cut += before - count_live(m);
}

// each tool's move since the last step: crossing the plane inside the patch
// through an open cell is a pass, through tissue a warning
static void passes(tx_ctx* c, membrane* m) {
  const int cx = m->nx - 1, cz = m->nz - 1;
  for (int t = 0; t < m->ntools; t++) {
    tx_snapshot p = tx_read(c, m->tools[t]);
    if (p.seq == 0) continue;
    const tx_pose* pose = p.data;
    if (!finite3(pose->pos)) {
      tx_warn(c, m->bad_pose);
      continue;
    }
    double now[3], *was = m->tool_prev[t];
    to_local(m, pose->pos, now);
    bool seen = m->tool_seen[t];
    m->tool_seen[t] = true;
    double y0 = was[1], y1 = now[1];
    bool crossed = seen && ((y0 > 0 && y1 <= 0) || (y0 < 0 && y1 >= 0));
    if (crossed) {
      const double f = y0 / (y0 - y1), x = was[0] + f * (now[0] - was[0]), z = was[2] + f * (now[2] - was[2]);
      const double gx = (x - m->origin[0]) / m->spacing, gz = (z - m->origin[1]) / m->spacing;
      if (gx >= 0 && gz >= 0 && gx < cx && gz < cz) {
        if (m->cell[(int)gz * cx + (int)gx]) tx_warn(c, m->through_tissue);
        else m->st.passes++;
      }
    }
    memcpy(was, now, sizeof now);
  }
}

static void publish(tx_ctx* c, membrane* m) {
  float* x = ((tx_vertex*)tx_write(c, m->x_out))->x;
  if (!tx_cloth_positions(m->cloth, m->xl)) { // the model must never hold a NaN: a last guard behind the cloth's own
    tx_warn(c, m->fault);
    tx_cloth_restore(m->cloth);
    tx_cloth_positions(m->cloth, m->xl);
  }
  for (int i = 0; i < m->n; i++) {
    const float* p = m->xl + 3 * i;
    for (int a = 0; a < 3; a++)
      x[3 * i + a] = (float)(m->center[a] + m->rot[a][0] * p[0] + m->rot[a][1] * p[1] + m->rot[a][2] * p[2]);
  }
  const int live = count_live(m);
  if (live != m->live) remesh(m, live);
  memcpy(((tx_triangle*)tx_write(c, m->tri_out))->v, m->tri, sizeof(int32_t) * 3 * (size_t)live);
  tx_write_rows(c, m->tri_out, (uint32_t)live);
  tx_temperature* t = tx_write(c, m->temp_out);
  for (int i = 0; i < m->n; i++) t[i].t = (float)m->heat->t[i];
  m->st.removed = m->ntri - live;
  m->st.peak_k = m->heat->peak;
  m->st.damaged_m2 = tx_membrane_heat_damaged(m->heat);
  m->peak = fmax(m->peak, m->heat->peak);
}

static int init(tx_ctx* c, void* self) {
  membrane* m = self;
  tx_cloth_positions(m->cloth, m->xl);
  m->live = count_live(m);
  remesh(m, m->live);
  m->peak = m->heat->peak;
  publish(c, m); // the patch at rest, at time 0
  *(tx_membrane_state*)tx_write(c, m->state_out) = m->st;
  return 0;
}

static void step(tx_ctx* c, void* self) {
  membrane* m = self;
  struct timespec t0, t1;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
  // heat, and what boiled leaves the cloth
  heat_source(c, m);
  const int boiled = tx_membrane_heat_step(m->heat, m->dt);
  if (boiled) {
    const int before = count_live(m);
    for (int k = 0; k < boiled; k++) tx_cloth_remove_particle(m->cloth, m->heat->boiled_now[k]);
    m->st.burnt += before - count_live(m);
  }
  scissors(c, m);
  if (tx_cloth_step(m->cloth, m->dt) == TX_CLOTH_FAULT) tx_warn(c, m->fault);
  publish(c, m);
  passes(c, m);
  *(tx_membrane_state*)tx_write(c, m->state_out) = m->st;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  tx_hist_add(&m->steps, (int64_t)(t1.tv_sec - t0.tv_sec) * 1000000000 + (t1.tv_nsec - t0.tv_nsec));
}

static void finish(tx_ctx* c, void* self) {
  membrane* m = self;
  tx_percentiles p = tx_hist_percentiles(&m->steps);
  tx_set_result(c, m->removed_r, m->st.removed);
  tx_set_result(c, m->burnt_r, m->st.burnt);
  tx_set_result(c, m->cut_r, m->st.cut);
  tx_set_result(c, m->fallen_r, m->st.removed - m->st.burnt - m->st.cut); // pieces cut off, and faults' restores
  tx_set_result(c, m->passes_r, m->st.passes);
  tx_set_result(c, m->opening_r, m->st.opening_m);
  tx_set_result(c, m->peak_r, m->peak);
  tx_set_result(c, m->damaged_r, m->st.damaged_m2);
  tx_set_result(c, m->energy_r, m->heat->energy);
  tx_set_result(c, m->boiled_r, m->heat->boiled);
  tx_set_result(c, m->active_r, m->active_s);
  tx_set_result(c, m->faults_r, tx_cloth_faults(m->cloth));
  tx_set_result(c, m->p50_r, p.p50 * 1e-6);
  tx_set_result(c, m->p99_r, p.p99 * 1e-6);
}

static void fini(void* self) {
  membrane* m = self;
  if (!m) return;
  tx_cloth_destroy(m->cloth);
  tx_membrane_heat_destroy(m->heat);
  free(m->xl), free(m->tri), free(m->cell), free(m->queue), free(m->mark), free(m->ends);
  free(m);
}

const tx_controller_class tx_physics_membrane = {
    .type = "physics.membrane",
    .summary = "LAGB thin membrane (pars flaccida, angle of His) on a Bullet cloth: a hook boils it away, scissors cut it, "
               "tools pass through its holes; writes NAME.x, NAME.tri, NAME.temperature, NAME.state",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
