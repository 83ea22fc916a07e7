// physics.cautery: the hook heats the organ it touches while its button is
// held (power in watts, a Gaussian fall-off); the heat conducts and the
// blood carries it off (Pennes, thermal.h) and the tissue's damage grows by
// Arrhenius' law. The temperature lives on the organ's tetrahedra at rest
// (the material frame): the tip is taken there by the displacement that
// physics.organs gave the surface point it touches, which is exact for a
// translation and good to the strain across the source (small here).
#include "cautery_controller.h"

#include "thermal.h"

#include "../rotation.h"
#include "../thread/segment.h" // tx_tri_closest_point

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { LIVER, STOMACH, SOFT };
static const char* const names[SOFT] = {"liver", "stomach"};

typedef struct organ {
  tx_thermal* h;
  int nv, nt;
  float* rest;  // (nv x 3) the drawn surface at rest (ORGAN.obj), m
  int* tri;     // (nt x 3)
  int* tet;     // (nv x 4) the nodes each surface vertex is embedded in
  float* w;     // (nv x 4) its weights there
  double peak;  // K, the hottest surface vertex so far
  tx_port x, temp, damage;
  tx_result peak_r, damaged_r, boiled_r;
  // removal: physics.organs' tetrahedra (coarse) and their refined children
  // (the heat's, fine), which fine nodes have boiled, how much of each coarse one
  int coarse_nodes, coarse, per; // nodes and tetrahedra of physics.organs' mesh, children of each
  double* fx;                    // (fine nodes x 3) m, at rest
  int* ft;                       // (coarse x per x 4) the fine tetrahedra, a coarse one's children together
  int *at_row, *at_tet;          // CSR: the fine tetrahedra at each fine node
  bool* counted;                 // (fine nodes) boiled and counted
  double *burnt, *cvol;          // (coarse) m^3 boiled, m^3 in all
  bool* gone;                    // (coarse) removed
  int removed;                   // coarse tetrahedra removed
  double removed_m3;
  tx_port tri_in, node_in;       // the published surface's triangles and rows' nodes
} organ;

typedef struct cautery {
  organ o[SOFT];
  tx_port pose, grip;
  int button;
  double offset[3], power, radius, contact;
  double active_s, dt;
  tx_warning bad_pose, bad_surface;
  tx_result energy_r, boiled_r, active_r, substeps_r, p50_r, p99_r;
  tx_hist steps; // ns
  // removal
  double remove_fraction;   // 0: none
  tx_port events;           // TX_EVENT_BURN out
  tx_result removed_r, removed_m3_r;
  tx_port tissue;           // cautery.tissue out: each organ's damaged and boiled volume
  long steps_taken;
} cautery;

// the volume with Omega over 1 and the volume that boiled, of the tissue left
static void measure_tissue(const organ* o, double* damaged, double* boiled) {
  const double *om = tx_thermal_damage(o->h), *vol = tx_thermal_volume(o->h);
  const bool* reached = tx_thermal_reached(o->h);
  double rest = tx_thermal_damage_rest(o->h);
  *damaged = *boiled = 0;
  for (int n = 0; n < tx_thermal_nodes(o->h); n++) {
    if (om[n] + rest > 1) *damaged += vol[n];
    if (reached[n]) *boiled += vol[n];
  }
}

// cautery.tissue: a pass over every node, so at a tenth of the heat's rate
static void publish_tissue(tx_ctx* c, cautery* g) {
  tx_tissue_damage* d = tx_write(c, g->tissue);
  for (int i = 0; i < SOFT; i++) {
    measure_tissue(&g->o[i], &d[i].damaged_m3, &d[i].boiled_m3);
    d[i].peak_k = g->o[i].peak;
  }
}

// the defaults: IT'IS tissue properties database (docs/lagb.md), Arrhenius
// parameters for liver after Jacques et al. (1996), as used by Chang and
// Nguyen (2004)
static const tx_param_def params[] = {
    {"assets", TX_PARAM_STR, NULL, 0, 0, 0, "lagb", "folder of ORGAN.node/.ele/.obj, as physics.organs': a name in assets/ or a path (with a /)"},
    {"refine", TX_PARAM_INT, "1", 0, 3, 2, NULL,
     "the organs' tetrahedra each cut into 8 this many times for the heat (2: liver 35,600 nodes, 185,000 tetrahedra, "
     "about 2.5 mm apart; 0: physics.organs' own, about 1 cm, coarser than a hook's burn)"},
    {"band_k", TX_PARAM_NUM, "K", 0, 1, 1e-3, NULL,
     "only nodes off the blood's temperature by more than this, and their neighbours, are stepped (the cost follows "
     "the heated region); 0: every node"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the pose the hook follows (tx_pose; its first row: device0.pose, or instrumentN.links' root link)"},
    {"tip_x_m", TX_PARAM_NUM, "m", -0.5, 0.5, 0, NULL, "the hook's tip in the pose's frame, x"},
    {"tip_y_m", TX_PARAM_NUM, "m", -0.5, 0.5, 0, NULL, "the hook's tip in the pose's frame, y"},
    {"tip_z_m", TX_PARAM_NUM, "m", -0.5, 0.5, 0, NULL, "the hook's tip in the pose's frame, z"},
    {"grip", TX_PARAM_STR, NULL, 0, 0, 0, "device0.grip", "the device's grip and buttons (tx_device_grip); \"\": always active"},
    {"button", TX_PARAM_INT, "1", 0, 31, 0, NULL, "the bit of the grip's buttons that activates the hook (a foot pedal)"},
    {"power_w", TX_PARAM_NUM, "W", 0, 300, 30, NULL, "the power into the tissue while active (a monopolar hook's setting)"},
    {"radius_m", TX_PARAM_NUM, "m", 1e-4, 0.02, 0.002, NULL, "the source's Gaussian radius around the tip, exp(-r^2/(2 radius^2))"},
    {"contact_m", TX_PARAM_NUM, "m", 0, 0.02, 0.001, NULL, "the tip heats an organ when inside it or at most this far from its surface"},
    {"liver_k", TX_PARAM_NUM, "W/(m K)", 0.05, 5, 0.52, NULL, "liver's thermal conductivity (IT'IS)"},
    {"liver_rho", TX_PARAM_NUM, "kg/m^3", 500, 2000, 1079, NULL, "liver's density (IT'IS)"},
    {"liver_c", TX_PARAM_NUM, "J/(kg K)", 1000, 6000, 3540, NULL, "liver's heat capacity (IT'IS)"},
    {"liver_perfusion", TX_PARAM_NUM, "ml/(min kg)", 0, 10000, 860, NULL, "liver's blood perfusion (IT'IS heat transfer rate)"},
    {"stomach_k", TX_PARAM_NUM, "W/(m K)", 0.05, 5, 0.53, NULL, "stomach's thermal conductivity (IT'IS)"},
    {"stomach_rho", TX_PARAM_NUM, "kg/m^3", 500, 2000, 1088, NULL, "stomach's density (IT'IS)"},
    {"stomach_c", TX_PARAM_NUM, "J/(kg K)", 1000, 6000, 3690, NULL, "stomach's heat capacity (IT'IS)"},
    {"stomach_perfusion", TX_PARAM_NUM, "ml/(min kg)", 0, 10000, 479, NULL, "stomach's blood perfusion (IT'IS heat transfer rate)"},
    {"blood_k", TX_PARAM_NUM, "K", 300, 320, TX_BODY_TEMPERATURE_K, NULL, "the arterial blood's temperature, and the organs' at rest"},
    {"arrhenius_a", TX_PARAM_NUM, "1/s", 1, 1e100, 7.39e39, NULL, "Arrhenius frequency factor A (liver)"},
    {"arrhenius_ea", TX_PARAM_NUM, "J/mol", 1e4, 1e6, 2.577e5, NULL, "Arrhenius activation energy Ea (liver)"},
    {"vaporisation_k", TX_PARAM_NUM, "K", 320, 500, TX_VAPORISATION_K, NULL,
     "tissue boils here: no node rises above it, the heat past it is taken by boiling"},
    {"remove_fraction", TX_PARAM_NUM, "1", 0, 1, 0.5, NULL,
     "a tetrahedron of physics.organs is removed (vaporised) once this fraction of its volume has boiled (its refined "
     "children's nodes at vaporisation_k, each a quarter of each child it is in); 0: nothing is removed"},
    {"events", TX_PARAM_STR, NULL, 0, 0, 0, "cautery.burn",
     "the stream the removals go out on (TX_EVENT_BURN, one per tetrahedron; physics.organs' burn_events); \"\": none (remove_fraction 0)"},
};

static double fine_volume(const double* x, const int* t) {
  const double *a = x + 3 * t[0], *b = x + 3 * t[1], *c = x + 3 * t[2], *d = x + 3 * t[3];
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
         w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return fabs(u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) + u[2] * (v[0] * w[1] - v[1] * w[0])) / 6;
}

static int load(tx_setup* s, organ* o, const char* dir, const char* name, const tx_tissue* ts, const tx_arrhenius* d,
                double dt, int levels) {
  char base[4096], path[4200];
  if (snprintf(base, sizeof base, "%s/%s", dir, name) >= (int)sizeof base) return tx_setup_fail(s, "assets", "path too long");
  snprintf(path, sizeof path, "%s.obj", base);
  double* x;
  int n, nt, *tet;
  if (!tx_tetgen_read(base, &x, &n, &tet, &nt)) return tx_setup_fail(s, "assets", "%s", tx_error());
  if (!tx_obj_read(path, &o->rest, &o->nv, &o->tri, &o->nt)) {
    free(x), free(tet);
    return tx_setup_fail(s, "assets", "%s", tx_error());
  }
  o->tet = malloc(sizeof(int) * 4 * (size_t)o->nv);
  o->w = malloc(sizeof(float) * 4 * (size_t)o->nv);
  double* fx = NULL;
  int fn, *ft = NULL, fnt;
  if (!o->tet || !o->w || !tx_thermal_refine_embed(x, n, tet, nt, levels, o->rest, o->nv, &fx, &fn, &ft, &fnt, o->tet, o->w)) {
    free(x), free(tet);
    return -1;
  }
  o->coarse_nodes = n, o->coarse = nt;
  free(x), free(tet);
  o->h = tx_thermal_create(fx, fn, ft, fnt, ts, d, dt);
  o->fx = fx, o->ft = ft;
  if (!o->h) return tx_setup_fail(s, "assets", "%s: %s", base, tx_error());
  // removal: the fine tetrahedra at each fine node, each coarse one's volume
  o->per = fnt / nt;
  o->at_row = calloc((size_t)fn + 1, sizeof(int));
  o->at_tet = malloc(sizeof(int) * 4 * (size_t)fnt);
  o->counted = calloc((size_t)fn, sizeof(bool));
  o->burnt = calloc((size_t)nt, sizeof(double)), o->cvol = calloc((size_t)nt, sizeof(double));
  o->gone = calloc((size_t)nt, sizeof(bool));
  if (!o->at_row || !o->at_tet || !o->counted || !o->burnt || !o->cvol || !o->gone) return -1;
  for (int f = 0; f < 4 * fnt; f++) o->at_row[ft[f] + 1]++;
  for (int i = 0; i < fn; i++) o->at_row[i + 1] += o->at_row[i];
  for (int f = 0; f < fnt; f++) {
    const int* t = ft + 4 * f;
    for (int k = 0; k < 4; k++) o->at_tet[o->at_row[t[k]]++] = f;
    o->cvol[f / o->per] += fine_volume(fx, t);
  }
  for (int i = fn; i > 0; i--) o->at_row[i] = o->at_row[i - 1];
  o->at_row[0] = 0;
  return 0;
}

static int configure(tx_setup* s, void** self) {
  cautery* g = calloc(1, sizeof *g);
  if (!g) return -1;
  *self = g;
  double rate = tx_setup_rate_in(s, TX_CAUTERY_RATE_MIN_HZ, TX_CAUTERY_RATE_MAX_HZ);
  if (!rate) return -1;
  g->dt = 1 / rate;
  const char *assets = tx_table_str(s, "assets"), *pose = tx_table_str(s, "pose"), *grip = tx_table_str(s, "grip");
  if (!assets || !pose || !grip) return -1;
  if (!pose[0]) return tx_setup_fail(s, "pose", "names no pose");
  g->offset[0] = tx_table_num(s, "tip_x_m"), g->offset[1] = tx_table_num(s, "tip_y_m"), g->offset[2] = tx_table_num(s, "tip_z_m");
  g->button = (int)tx_table_int(s, "button");
  int levels = (int)tx_table_int(s, "refine");
  g->power = tx_table_num(s, "power_w"), g->radius = tx_table_num(s, "radius_m"), g->contact = tx_table_num(s, "contact_m");
  tx_arrhenius d = {tx_table_num(s, "arrhenius_a"), tx_table_num(s, "arrhenius_ea")};
  double blood = tx_table_num(s, "blood_k"), cap = tx_table_num(s, "vaporisation_k"), band = tx_table_num(s, "band_k");
  if (!(cap > blood)) return tx_setup_fail(s, "vaporisation_k", "%g K is not above the blood's %g K", cap, blood);
  char dir[4096];
  int len = strchr(assets, '/') ? snprintf(dir, sizeof dir, "%s", assets) : snprintf(dir, sizeof dir, "%s/%s", TX_ASSET_DIR, assets);
  if (len >= (int)sizeof dir - 64) return tx_setup_fail(s, "assets", "%s: path too long", assets);
  for (int i = 0; i < SOFT; i++) {
    char key[64];
    tx_tissue ts;
    snprintf(key, sizeof key, "%s_k", names[i]), ts.k = tx_table_num(s, key);
    snprintf(key, sizeof key, "%s_rho", names[i]), ts.rho = tx_table_num(s, key);
    snprintf(key, sizeof key, "%s_c", names[i]), ts.c = tx_table_num(s, key);
    snprintf(key, sizeof key, "%s_perfusion", names[i]);
    ts.perfusion = tx_perfusion_coefficient(tx_table_num(s, key), ts.rho);
    ts.t_arterial = blood;
    int rc = load(s, &g->o[i], dir, names[i], &ts, &d, g->dt, levels);
    if (rc) return rc;
    tx_thermal_cap(g->o[i].h, cap);
    tx_thermal_band(g->o[i].h, band);
    organ* o = &g->o[i];
    snprintf(key, sizeof key, "%s.x", names[i]);
    o->x = TX_READ_OF(s, key, tx_vertex);
    snprintf(key, sizeof key, "%s.temperature", names[i]);
    uint32_t rows = (uint32_t)(o->nv > o->coarse_nodes ? o->nv : o->coarse_nodes); // the drawn surface, or the cut one's nodes
    o->temp = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_temperature, rows));
    snprintf(key, sizeof key, "%s.damage", names[i]);
    o->damage = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_organ_damage, rows));
    snprintf(key, sizeof key, "%s.tri", names[i]);
    o->tri_in = TX_READ_OF(s, key, tx_triangle);
    snprintf(key, sizeof key, "%s.surface_node", names[i]);
    o->node_in = TX_READ_OF(s, key, tx_surface_node);
    snprintf(key, sizeof key, "%s_peak_k", names[i]), o->peak_r = tx_setup_result(s, key);
    snprintf(key, sizeof key, "%s_damaged_m3", names[i]), o->damaged_r = tx_setup_result(s, key);
    snprintf(key, sizeof key, "%s_boiled_m3", names[i]), o->boiled_r = tx_setup_result(s, key);
  }
  g->pose = TX_READ_OF(s, pose, tx_pose);
  if (grip[0]) g->grip = TX_READ_OF(s, grip, tx_device_grip);
  g->bad_pose = tx_setup_warning(s, "bad_pose");
  g->bad_surface = tx_setup_warning(s, "bad_surface");
  g->energy_r = tx_setup_result(s, "energy_j");
  g->boiled_r = tx_setup_result(s, "boiled_j");
  g->active_r = tx_setup_result(s, "active_s");
  g->substeps_r = tx_setup_result(s, "substeps");
  g->p50_r = tx_setup_result(s, "step_p50_ms");
  g->p99_r = tx_setup_result(s, "step_p99_ms");
  // removal
  g->remove_fraction = tx_table_num(s, "remove_fraction");
  const char* events = tx_table_str(s, "events");
  if (!events) return -1;
  if (events[0]) g->events = tx_setup_emit(s, events, 1024); // declared even when nothing is to be removed, so a listener stays valid
  else if (g->remove_fraction > 0) return tx_setup_fail(s, "events", "names no stream, but remove_fraction is %g", g->remove_fraction);
  g->removed_r = tx_setup_result(s, "removed_tets");
  g->removed_m3_r = tx_setup_result(s, "removed_m3");
  g->tissue = tx_setup_write(s, &TX_COMPONENT_OF("cautery.tissue", tx_tissue_damage, SOFT));
  tx_hist_clear(&g->steps);
  return 0;
}

// the surface the tip is located on: physics.organs' latest publish (the
// drawn surface, or once cut its live tetrahedra's boundary, each row a
// node), or the drawn surface at rest
typedef struct surface {
  const float* cur;    // (rows x 3) m, now
  const int32_t* tri;  // (nt x 3)
  int rows, nt;
  const int32_t* node; // (rows) the node of each row (cut), or NULL (drawn: rest is o->rest)
} surface;

static double rest_of(const organ* o, const surface* f, int row, int a) {
  return f->node ? o->fx[3 * f->node[row] + a] : o->rest[3 * row + a];
}

// where the tip is against an organ's surface now: the signed distance
// (negative inside) and the tip taken to the rest frame
static double locate(const organ* o, const surface* f, const double tip[3], double mat[3]) {
  const float* cur = f->cur;
  double best = INFINITY, sign = 1;
  int bt = 0;
  double bb[3] = {1, 0, 0};
  for (int t = 0; t < f->nt; t++) {
    const int32_t* v = f->tri + 3 * t;
    double p[3][3], cp[3], bary[3];
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) p[k][a] = cur[3 * v[k] + a];
    tx_tri_closest_point(tip, p[0], p[1], p[2], cp, bary);
    double d[3] = {tip[0] - cp[0], tip[1] - cp[1], tip[2] - cp[2]};
    double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (d2 < best) {
      double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      best = d2, bt = t, sign = d[0] * n[0] + d[1] * n[1] + d[2] * n[2] < 0 ? -1 : 1;
      memcpy(bb, bary, sizeof bb);
    }
  }
  const int32_t* v = f->tri + 3 * bt;
  for (int a = 0; a < 3; a++) {
    double u = 0;
    for (int k = 0; k < 3 && f->nt > 0; k++) u += bb[k] * (cur[3 * v[k] + a] - rest_of(o, f, v[k], a));
    mat[a] = tip[a] - u;
  }
  return sign * sqrt(best);
}

// one row per row of the surface: a drawn vertex reads its refined
// tetrahedron, a node of the cut surface its own value (physics.organs'
// nodes keep their numbers in the refined mesh: tx_tet_refine)
static void publish(tx_ctx* c, organ* o, const surface* f) {
  const double *t = tx_thermal_temperature(o->h), *om = tx_thermal_damage(o->h), rest = tx_thermal_damage_rest(o->h);
  tx_temperature* ot = tx_write(c, o->temp);
  tx_organ_damage* od = tx_write(c, o->damage);
  if (f && f->node) {
    for (int r = 0; r < f->rows; r++) {
      int n = f->node[r];
      ot[r].t = (float)t[n], od[r].omega = (float)fmin(fmax(om[n], 0) + rest, 1e30);
      o->peak = fmax(o->peak, t[n]);
    }
    tx_write_rows(c, o->temp, (uint32_t)f->rows), tx_write_rows(c, o->damage, (uint32_t)f->rows);
    return;
  }
  tx_write_rows(c, o->temp, (uint32_t)o->nv), tx_write_rows(c, o->damage, (uint32_t)o->nv);
  for (int v = 0; v < o->nv; v++) {
    double a = 0, b = 0, lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 4; k++) {
      int n = o->tet[4 * v + k];
      a += o->w[4 * v + k] * t[n], b += o->w[4 * v + k] * om[n];
      lo = fmin(lo, t[n]), hi = fmax(hi, t[n]);
    }
    // a vertex a little off the tetrahedra's hull extrapolates: kept within its nodes' range
    a = fmin(fmax(a, lo), hi), b = fmax(b, 0);
    ot[v].t = (float)a, od[v].omega = (float)fmin(b + rest, 1e30); // Omega grows without bound in boiled tissue
    o->peak = fmax(o->peak, a);
  }
}

// physics.organs' latest surface of organ o; its rest shape (drawn) when it
// has published none yet or what it published does not hold together
static void read_surface(tx_ctx* c, cautery* g, organ* o, surface* f) {
  *f = (surface){.cur = o->rest, .tri = o->tri, .rows = o->nv, .nt = o->nt, .node = NULL};
  tx_snapshot xs = tx_read(c, o->x), ts = tx_read(c, o->tri_in), ns = tx_read(c, o->node_in);
  if (xs.seq == 0) return;
  // the three from one publish (physics.organs writes them together)
  const int32_t* node = ns.seq > 0 && ns.rows > 0 ? &((const tx_surface_node*)ns.data)->node : NULL;
  bool cut = node && ns.seq == xs.seq && ts.seq == xs.seq && ns.rows == xs.rows && node[0] >= 0;
  if (!cut) { // the drawn surface; or a cut one read across a publish: its rest shape, this once
    bool drawn = !node || node[0] < 0;
    if (drawn && xs.rows == (uint32_t)o->nv) f->cur = ((const tx_vertex*)xs.data)->x;
    else if (drawn) tx_warn(c, g->bad_surface);
    return;
  }
  const int32_t* tri = ((const tx_triangle*)ts.data)->v;
  for (uint32_t r = 0; r < xs.rows; r++)
    if (node[r] < 0 || node[r] >= o->coarse_nodes) return tx_warn(c, g->bad_surface);
  for (uint32_t k = 0; k < 3 * ts.rows; k++)
    if (tri[k] < 0 || tri[k] >= (int32_t)xs.rows) return tx_warn(c, g->bad_surface);
  *f = (surface){.cur = ((const tx_vertex*)xs.data)->x, .tri = tri, .rows = (int)xs.rows, .nt = (int)ts.rows, .node = node};
}

// the nodes that boiled since the last step count a quarter of each fine
// tetrahedron they are in toward its coarse parent; a coarse tetrahedron
// past remove_fraction is sent to physics.organs to be removed and its
// children leave the heat's solve
static void vaporise(tx_ctx* c, cautery* g, int which) {
  organ* o = &g->o[which];
  const bool* reached = tx_thermal_reached(o->h);
  int n = tx_thermal_nodes(o->h);
  for (int i = 0; i < n; i++) {
    if (!reached[i] || o->counted[i]) continue;
    o->counted[i] = true;
    for (int a = o->at_row[i]; a < o->at_row[i + 1]; a++) {
      int f = o->at_tet[a], e = f / o->per;
      if (o->gone[e]) continue;
      o->burnt[e] += fine_volume(o->fx, o->ft + 4 * f) / 4;
      if (o->burnt[e] < g->remove_fraction * o->cvol[e] * (1 - 1e-12)) continue;
      // gone: its centroid at rest, its children out of the heat's solve
      tx_event ev = {.kind = TX_EVENT_BURN, .source = (uint32_t)e};
      ev.burn.organ = which, ev.burn.fraction = o->burnt[e] / o->cvol[e];
      for (int k = e * o->per; k < (e + 1) * o->per; k++) {
        const int* t = o->ft + 4 * k;
        double v = fine_volume(o->fx, t) / o->cvol[e];
        for (int q = 0; q < 4; q++)
          for (int ax = 0; ax < 3; ax++) ev.burn.point[ax] += v * o->fx[3 * t[q] + ax] / 4;
        tx_thermal_remove(o->h, t);
      }
      o->gone[e] = true, o->removed++, o->removed_m3 += o->cvol[e];
      tx_emit(c, g->events, &ev);
    }
  }
}

static int init(tx_ctx* c, void* self) {
  cautery* g = self;
  for (int i = 0; i < SOFT; i++) publish(c, &g->o[i], NULL); // at rest, at time 0
  g->steps_taken = 0;
  publish_tissue(c, g);
  return 0;
}

static void step(tx_ctx* c, void* self) {
  cautery* g = self;
  struct timespec t0, t1;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
  bool active = false;
  double tip[3] = {0, 0, 0};
  tx_snapshot p = tx_read(c, g->pose);
  if (p.seq > 0) {
    const tx_pose* pose = p.data;
    double off[3];
    tx_quat_rotate(pose->quat, false, g->offset, off);
    for (int a = 0; a < 3; a++) tip[a] = pose->pos[a] + off[a];
    active = isfinite(tip[0] + tip[1] + tip[2]);
    if (!active) tx_warn(c, g->bad_pose);
  }
  if (active && g->grip.id) {
    tx_snapshot gs = tx_read(c, g->grip);
    double b = gs.seq > 0 ? ((const tx_device_grip*)gs.data)->buttons : 0;
    active = b >= 0 && b < 4294967296.0 && (((uint32_t)b >> g->button) & 1u);
  }
  // each organ's surface as physics.organs last published it
  surface sf[SOFT];
  for (int i = 0; i < SOFT; i++) read_surface(c, g, &g->o[i], &sf[i]);
  // the organ the tip touches (the deepest in, if both)
  int hot = -1;
  double best = INFINITY, mat[SOFT][3] = {{0}};
  for (int i = 0; i < SOFT && active && g->power > 0; i++) {
    double d = locate(&g->o[i], &sf[i], tip, mat[i]);
    if (d <= g->contact && d < best) best = d, hot = i;
  }
  for (int i = 0; i < SOFT; i++) {
    organ* o = &g->o[i];
    tx_thermal_source(o->h, mat[i], g->radius, i == hot ? g->power : 0);
    tx_thermal_step(o->h);
    if (g->remove_fraction > 0) vaporise(c, g, i);
    publish(c, o, &sf[i]);
  }
  if (hot >= 0) g->active_s += g->dt;
  if (++g->steps_taken % 10 == 0) publish_tissue(c, g);
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  tx_hist_add(&g->steps, (int64_t)(t1.tv_sec - t0.tv_sec) * 1000000000 + (t1.tv_nsec - t0.tv_nsec));
}

static void finish(tx_ctx* c, void* self) {
  cautery* g = self;
  double energy = 0, boiled = 0;
  for (int i = 0; i < SOFT; i++) {
    organ* o = &g->o[i];
    double damaged, gone;
    measure_tissue(o, &damaged, &gone);
    tx_set_result(c, o->peak_r, o->peak);
    tx_set_result(c, o->damaged_r, damaged);
    tx_set_result(c, o->boiled_r, gone);
    energy += tx_thermal_energy(o->h), boiled += tx_thermal_boiled(o->h);
  }
  tx_percentiles p = tx_hist_percentiles(&g->steps);
  tx_set_result(c, g->energy_r, energy);
  tx_set_result(c, g->boiled_r, boiled);
  tx_set_result(c, g->active_r, g->active_s);
  tx_set_result(c, g->substeps_r, fmax(tx_thermal_substeps(g->o[0].h), tx_thermal_substeps(g->o[1].h)));
  tx_set_result(c, g->p50_r, p.p50 * 1e-6);
  tx_set_result(c, g->p99_r, p.p99 * 1e-6);
  tx_set_result(c, g->removed_r, g->o[0].removed + g->o[1].removed);
  tx_set_result(c, g->removed_m3_r, g->o[0].removed_m3 + g->o[1].removed_m3);
}

static void fini(void* self) {
  cautery* g = self;
  if (!g) return;
  for (int i = 0; i < SOFT; i++) {
    organ* o = &g->o[i];
    tx_thermal_destroy(o->h);
    free(o->rest), free(o->tri), free(o->tet), free(o->w);
    free(o->fx), free(o->ft), free(o->at_row), free(o->at_tet), free(o->counted), free(o->burnt), free(o->cvol), free(o->gone);
  }
  free(g);
}

const tx_controller_class tx_physics_cautery = {
    .type = "physics.cautery",
    .summary = "LAGB cautery: a hook heats the liver and stomach (Pennes bioheat on their tetrahedra, Arrhenius damage); "
               "writes liver.temperature/.damage, stomach.temperature/.damage",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
