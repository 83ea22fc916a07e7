// physics.skin: the suturing skin patch (the SutureHap papers' cloth) on a
// Bullet soft body, with the HIP as a kinematic sphere that follows the
// device pose. Every step publishes the particles, the live triangles, the
// thickness and the torn-link count; a numerical fault is counted and the
// patch goes back to its last good state, so the model never holds a NaN.
#include "skin_controller.h"

#include "bullet/cloth.h"
#include "../rotation.h"
#include "../system.h" // tx_param_json, tx_param_point

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GRASP_HANDS_MAX 4

typedef struct skin {
  tx_cloth* cloth;     // the patch; made in configure, stepped only by this instance
  double hip_radius;   // m, 0: no HIP
  double dt;           // s, one step at the instance's rate
  tx_port pose;        // read: the pose the HIP follows (f64 1 x 7)
  tx_port x, tri, thickness, torn, contact, rupture; // written: skin.*
  double prev_f, prev_w; // N, m: the reaction along its normal and the indentation of the last step in contact (0: none)
  double k;              // N/m, the last tangent stiffness
  tx_warning fault, bad_pose;
  tx_result torn_result, pulled_result, fault_result, pierce_result, freed_result, pieces_result;
  // grasps: the particles between a hand's jaws follow its instrument<h>.pose
  tx_port grasp_in;                     // listened: the grasp stream (0: none)
  tx_port jaws[GRASP_HANDS_MAX];        // read: instrument<h>.pose
  int hands;                            // hands whose grasps count
  double grasp_radius;                  // m
  int n;                                // particles
  int8_t* holder;                       // (n) the hand holding each particle, -1 none
  double* offset;                       // (n x 3) m, a held particle in its jaws' frame
  int32_t* held;                        // (n) the held particles, in the order taken
  int nheld;
  int grasps;                           // grasps that took particles
  tx_result grasp_result;
  int wound_links;                      // links the wound cut (wound_a_m to wound_b_m), 0: none
  tx_result wound_result;
  // the thread's pull at its punctures (thread_loads): each row's force spread
  // over the particles near its point (thread_load_radius_m) on its side of the
  // wound, or shared by its triangle's particles by their barycentric weights
  tx_port loads_in;                     // read: tx_puncture_load rows (0: none)
  double load_radius;                   // m, each row's force spread over the particles this near its point; 0: its triangle's
  bool has_wound;                       // a load stays on its side of the wound line
  double wound[2][3];                   // m, the wound's ends
  double* load;                         // (n x 3) N, the load on each particle now
  double* load_k;                       // (n) N/m, the stiffness it comes with (its share of its rows')
  uint8_t* listed;                      // (n) 1: in loaded
  int32_t* loaded;                      // (n) the particles with a load, nloaded of them
  int nloaded;
  tx_warning bad_load;
  double load_max;                      // N, the largest row's force so far
  tx_result load_result;
} skin;

// the wound's ends (wound_a_m, wound_b_m, both or neither): 1 with them, 0 for none, -1 refused
static int read_wound(tx_setup* s, double w[2][3]) {
  json_t* a = tx_param_json(s, "wound_a_m");
  json_t* b = tx_param_json(s, "wound_b_m");
  bool has_a = a && !json_is_null(a), has_b = b && !json_is_null(b);
  if (has_a != has_b) return tx_setup_fail(s, has_a ? "wound_b_m" : "wound_a_m", "the wound needs both ends (wound_a_m, wound_b_m)");
  if (!has_a) return 0;
  static const double none[3] = {0, 0, 0};
  if (tx_param_point(s, "wound_a_m", none, w[0]) || tx_param_point(s, "wound_b_m", none, w[1])) return -1;
  return 1;
}

// defaults are tx_cloth_def_default()'s (tests/controllers/test_param_tables.c checks)
static const tx_param_def params[] = {
    {"size_m", TX_PARAM_NUM, "m", 0.01, 1, 0.1, NULL, "the patch's side (10 cm); the edge is size_m + spacing_m"},
    {"spacing_m", TX_PARAM_NUM, "m", 0.0005, 0.05, 0.0025, NULL, "particle spacing, dividing size_m; 0.001 is the papers' high density"},
    {"thickness_m", TX_PARAM_NUM, "m", 0, 0.02, 0.004, NULL, "the skin's thickness; only the contact uses it"},
    {"mass_kg", TX_PARAM_NUM, "kg", 1e-6, 100, 0.044, NULL, "the whole patch (10 x 10 x 0.4 cm at 1100 kg/m^3)"},
    {"stretch_stiffness", TX_PARAM_NUM, "N/m", 1e-6, 1e9, 2000, NULL,
     "k of eq. 1 for stretch and shear links; the membrane's E t along x and z is 1.5 k (docs/skin.md)"},
    {"bend_stiffness", TX_PARAM_NUM, "N/m", 0, 1e9, 20, NULL, "k of the bending links"},
    {"damping", TX_PARAM_NUM, "1/s", 0, 1e4, 5, NULL, "decay rate of particle velocities"},
    {"gravity", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "9.81 m/s^2 along -y"},
    {"fixed_border", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "the outer ring of particles does not move"},
    {"pretension_n_per_m", TX_PARAM_NUM, "N/m", 0, 1e9, 0, NULL,
     "isotropic tension of the flat skin at rest against its fixed border; below (3 k + 4 k_bend) / 2"},
    {"rupture_tension_n_per_m", TX_PARAM_NUM, "N/m", 0, 1e7, 80, NULL,
     "membrane tension, averaged over rupture_length_m, that tears the skin within the HIP's reach (the needle's "
     "tip cuts); 0: the skin never tears"},
    {"blunt_rupture_tension_n_per_m", TX_PARAM_NUM, "N/m", 0, 1e7, 1000, NULL,
     "the same beyond the HIP's reach, where a thread or jaws only pull (skin's own strength, docs/skin.md); 0: "
     "rupture_tension_n_per_m everywhere"},
    {"rupture_length_m", TX_PARAM_NUM, "m", 1e-4, 0.05, 0.002, NULL, "radius over which the tension is averaged"},
    {"solver", TX_PARAM_STR, NULL, 0, 0, 0, "implicit",
     "\"implicit\": backward Euler, Newton and preconditioned CG (real time); \"xpbd\": XPBD, converged only with k w h^2 <= 1/4"},
    {"force_reading", TX_PARAM_STR, NULL, 0, 0, 0, "balance",
     "implicit: \"balance\": the force on the HIP is the patch's momentum balance; \"held\": the held particles' own imbalance (docs/skin.md)"},
    {"iterations", TX_PARAM_INT, "1", 1, 200, 1, NULL, "XPBD iterations per substep"},
    {"newton_steps", TX_PARAM_INT, "1", 1, 20, 2, NULL, "implicit: most Newton steps per substep; they stop once the gradient is a tenth of the first step's"},
    {"cg_iterations", TX_PARAM_INT, "1", 1, 10000, 100, NULL, "implicit: most CG iterations per Newton step"},
    {"cg_tolerance", TX_PARAM_NUM, "1", 1e-12, 1, 1e-2, NULL, "implicit: CG stops at this relative residual"},
    {"coarse_block", TX_PARAM_INT, "1", 0, 64, 0, NULL,
     "implicit: 0, CG preconditioned by block Jacobi; else in [2, 64], plus a coarse level of one particle per block of this many a side"},
    {"max_substep_s", TX_PARAM_NUM, "s", 1e-6, 0.1, 1.0 / 60, NULL, "a step is split into substeps of at most this"},
    {"max_speed", TX_PARAM_NUM, "m/s", 1e-3, 1e4, 100, NULL, "a faster particle is a blow-up"},
    {"hip_radius_m", TX_PARAM_NUM, "m", 0, 0.01, 0.0005, NULL, "the HIP sphere (0.05 cm); 0: no HIP"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the pose the HIP follows (f64 1 x 7)"},
    {"grasp_events", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "stream of the jaws' grasps and releases (source = hand h; its jaws' frame is instrument<h>.pose); \"\": none"},
    {"grasp_radius_m", TX_PARAM_NUM, "m", 1e-4, 0.05, 0.002, NULL,
     "a grasp takes the free particles this close to its point; none in reach: not the skin's"},
    {"grasp_hands", TX_PARAM_INT, "1", 1, GRASP_HANDS_MAX, 2, NULL,
     "with grasp_events: hands 0 to this less one, each with its instrument<h>.pose"},
    {"wound_a_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL,
     "[x, y, z], m: one end of a straight wound cut through the skin (in x-z) before the run; with wound_b_m; none by default"},
    {"wound_b_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: the wound's other end"},
    {"thread_loads", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "the thread's pull at its punctures (tx_puncture_load rows, e.g. thread.puncture_loads) on the skin: a tight stitch closes the wound; \"\": none"},
    {"thread_load_radius_m", TX_PARAM_NUM, "m", 0, 0.02, 0.004, NULL,
     "a puncture's load is spread over the particles this near it on its side of the wound, weights falling linearly to 0 at this distance (the thread bears on the tissue along its bite); 0: on its triangle's three particles"},
};

static int configure(tx_setup* s, void** self) {
  skin* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  double rate = tx_setup_rate_in(s, TX_SKIN_RATE_MIN_HZ, TX_SKIN_RATE_MAX_HZ);
  if (!rate) return -1;
  k->dt = 1.0 / rate;

  // the patch, in metres (the papers' centimetres / 100)
  tx_cloth_def d = tx_cloth_def_default();
  double size = tx_table_num(s, "size_m");
  double spacing = tx_table_num(s, "spacing_m");
  d.thickness = tx_table_num(s, "thickness_m");
  d.mass = tx_table_num(s, "mass_kg");
  d.stretch_stiffness = tx_table_num(s, "stretch_stiffness");
  d.bend_stiffness = tx_table_num(s, "bend_stiffness");
  d.damping = tx_table_num(s, "damping");
  d.gravity = tx_table_bool(s, "gravity") ? 9.81 : 0;
  d.fixed_border = tx_table_bool(s, "fixed_border");
  d.pretension = tx_table_num(s, "pretension_n_per_m");
  d.rupture_tension = tx_table_num(s, "rupture_tension_n_per_m");
  d.blunt_rupture_tension = tx_table_num(s, "blunt_rupture_tension_n_per_m");
  d.rupture_length = tx_table_num(s, "rupture_length_m");
  const char* solver = tx_table_str(s, "solver");
  if (!solver) return -1;
  if (strcmp(solver, "implicit") == 0) d.solver = TX_CLOTH_IMPLICIT;
  else if (strcmp(solver, "xpbd") == 0) d.solver = TX_CLOTH_XPBD;
  else return tx_setup_fail(s, "solver", "expected \"implicit\" or \"xpbd\", got \"%s\"", solver);
  const char* reading = tx_table_str(s, "force_reading");
  if (!reading) return -1;
  if (strcmp(reading, "balance") == 0) d.reading = TX_CLOTH_BALANCE;
  else if (strcmp(reading, "held") == 0) d.reading = TX_CLOTH_HELD;
  else return tx_setup_fail(s, "force_reading", "expected \"balance\" or \"held\", got \"%s\"", reading);
  d.iterations = (int)tx_table_int(s, "iterations");
  d.newton_steps = (int)tx_table_int(s, "newton_steps");
  d.cg_iterations = (int)tx_table_int(s, "cg_iterations");
  d.cg_tolerance = tx_table_num(s, "cg_tolerance");
  d.coarse_block = (int)tx_table_int(s, "coarse_block");
  if (d.coarse_block == 1) return tx_setup_fail(s, "coarse_block", "1: a block must hold 2 or more particles a side (0: none)");
  d.max_substep = tx_table_num(s, "max_substep_s");
  d.max_speed = tx_table_num(s, "max_speed");
  k->hip_radius = tx_table_num(s, "hip_radius_m");
  const char* pose = tx_table_str(s, "pose");
  if (!pose) return -1;

  // the papers' counts: size / spacing + 1 cells a side (42 x 42 particles at
  // 0.25 cm, 102 x 102 at 0.1 cm), so the edge is size + spacing
  double cells = size / spacing;
  if (fabs(cells - lround(cells)) > 1e-6 * cells)
    return tx_setup_fail(s, "spacing_m", "%g m does not divide size_m = %g m into whole cells", spacing, size);
  int res = (int)lround(cells) + 2;
  if (res > 1024) return tx_setup_fail(s, "spacing_m", "%g m gives %d particles a side, at most 1024", spacing, res);
  d.size[0] = d.size[1] = (res - 1) * spacing;
  d.res[0] = d.res[1] = res;
  if (tx_cloth_def_check(&d)) return tx_setup_fail(s, NULL, "%s", tx_error());
  k->cloth = tx_cloth_create(&d);
  if (!k->cloth) return tx_setup_fail(s, NULL, "%s", tx_error());
  double wound[2][3];
  int has_wound = read_wound(s, wound);
  if (has_wound < 0) return -1;
  k->has_wound = has_wound > 0;
  memcpy(k->wound, wound, sizeof wound);
  if (has_wound && !(k->wound_links = tx_cloth_cut(k->cloth, wound[0], wound[1])))
    return tx_setup_fail(s, "wound_a_m", "the wound to wound_b_m crosses no link of the patch");
  k->wound_result = tx_setup_result(s, "wound_links_cut");

  uint32_t n = (uint32_t)tx_cloth_particle_count(k->cloth), m = (uint32_t)tx_cloth_triangle_count(k->cloth);
  if (k->hip_radius > 0) k->pose = TX_READ_OF(s, pose, tx_pose);
  k->x = tx_setup_write(s, &TX_COMPONENT_OF("skin.x", tx_vertex, n));
  k->tri = tx_setup_write(s, &TX_COMPONENT_OF("skin.tri", tx_triangle, m));
  k->thickness = tx_setup_write(s, &TX_COMPONENT_OF("skin.thickness", tx_thickness, 1));
  k->torn = tx_setup_write(s, &TX_COMPONENT_OF("skin.torn", tx_torn, 1));
  k->contact = tx_setup_write(s, &TX_COMPONENT_OF("skin.contact", tx_skin_contact, 1));
  k->rupture = tx_setup_write(s, &TX_COMPONENT_OF("skin.rupture", tx_skin_rupture, 1));
  k->fault = tx_setup_warning(s, "numerical_fault");
  k->bad_pose = tx_setup_warning(s, "bad_pose");
  k->torn_result = tx_setup_result(s, "torn_links");
  k->pulled_result = tx_setup_result(s, "torn_pulled_links");
  k->fault_result = tx_setup_result(s, "faults");
  k->pierce_result = tx_setup_result(s, "pierces");
  k->freed_result = tx_setup_result(s, "freed_particles");
  k->pieces_result = tx_setup_result(s, "freed_pieces");

  const char* grasps = tx_table_str(s, "grasp_events");
  if (!grasps) return -1;
  k->grasp_radius = tx_table_num(s, "grasp_radius_m");
  k->hands = (int)tx_table_int(s, "grasp_hands");
  k->n = (int)n;
  if (*grasps) {
    k->grasp_in = tx_setup_listen(s, grasps);
    for (int h = 0; h < k->hands; h++) {
      char name[TX_NAME_MAX];
      snprintf(name, sizeof name, "instrument%d.pose", h);
      k->jaws[h] = TX_READ_OF(s, name, tx_instrument_pose);
    }
    k->holder = malloc((size_t)n * sizeof *k->holder);
    k->offset = calloc((size_t)n * 3, sizeof *k->offset);
    k->held = malloc((size_t)n * sizeof *k->held);
    if (!k->holder || !k->offset || !k->held) return tx_setup_fail(s, NULL, "out of memory");
    memset(k->holder, -1, (size_t)n * sizeof *k->holder);
  }
  k->grasp_result = tx_setup_result(s, "grasps");
  const char* loads = tx_table_str(s, "thread_loads");
  if (!loads) return -1;
  if (*loads) {
    k->loads_in = TX_READ_EXPECT(s, loads, tx_puncture_load);
    k->load = calloc((size_t)n * 3, sizeof *k->load);
    k->load_k = calloc((size_t)n, sizeof *k->load_k);
    k->listed = calloc((size_t)n, 1);
    k->loaded = malloc((size_t)n * sizeof *k->loaded);
    if (!k->load || !k->load_k || !k->listed || !k->loaded) return tx_setup_fail(s, NULL, "out of memory");
  }
  k->load_radius = tx_table_num(s, "thread_load_radius_m");
  k->bad_load = tx_setup_warning(s, "bad_load");
  k->load_result = tx_setup_result(s, "thread_load_max_n");
  return 0;
}

// the jaws of hand h now; false when nothing is published yet or not finite
static bool jaws_of(tx_ctx* c, const skin* k, int h, tx_instrument_pose* out) {
  tx_snapshot p = tx_read(c, k->jaws[h]);
  if (p.seq == 0) return false;
  *out = *(const tx_instrument_pose*)p.data;
  double qq = 0;
  for (int a = 0; a < 4; a++) qq += out->quat[a] * out->quat[a];
  for (int a = 0; a < 3; a++)
    if (!isfinite(out->pos[a])) return false;
  if (!(qq > 0.5 && qq < 2)) return false; // no rotation
  for (int a = 0; a < 4; a++) out->quat[a] /= sqrt(qq);
  return true;
}

static void release(skin* k, int h) {
  int kept = 0;
  for (int j = 0; j < k->nheld; j++) {
    int i = k->held[j];
    if (k->holder[i] != h) {
      k->held[kept++] = i;
      continue;
    }
    k->holder[i] = -1;
    tx_cloth_unpin(k->cloth, i);
  }
  k->nheld = kept;
}

// a grasp by hand h at point: the free particles within grasp_radius become its
// jaws', each kept at its offset in their frame; none in reach: not the skin's
// (the needle's and the thread's grasps come on the same stream)
static void grasp(tx_ctx* c, skin* k, int h, const double point[3]) {
  tx_instrument_pose jp;
  if (!jaws_of(c, k, h, &jp)) return;
  const double r2 = k->grasp_radius * k->grasp_radius;
  int took = 0;
  for (int i = 0; i < k->n; i++) {
    if (k->holder[i] >= 0) continue; // the other hand's already
    double x[3], d2 = 0;
    tx_cloth_particle(k->cloth, i, x);
    for (int a = 0; a < 3; a++) d2 += (x[a] - point[a]) * (x[a] - point[a]);
    if (!(d2 <= r2)) continue;
    if (tx_cloth_freed(k->cloth, i)) continue; // a piece cut off is no longer the skin's
    if (tx_cloth_pin(k->cloth, i, x) != TX_CLOTH_OK) continue; // the fixed border stays where it is
    double rel[3] = {x[0] - jp.pos[0], x[1] - jp.pos[1], x[2] - jp.pos[2]};
    tx_quat_rotate(jp.quat, true, rel, &k->offset[(size_t)i * 3]);
    k->holder[i] = (int8_t)h;
    k->held[k->nheld++] = i;
    took++;
  }
  if (took > 0) k->grasps++;
}

// the grasps and releases sent since the last step, then every held particle
// where its jaws now put it
static void follow_jaws(tx_ctx* c, skin* k) {
  for (tx_event e; tx_next_event(c, k->grasp_in, &e);) {
    if (e.source >= (uint32_t)k->hands) continue; // a hand this skin does not watch
    const int h = (int)e.source;
    if (e.kind == TX_EVENT_RELEASE) release(k, h);
    else if (e.kind == TX_EVENT_GRASP) {
      bool finite = isfinite(e.grasp.point[0]) && isfinite(e.grasp.point[1]) && isfinite(e.grasp.point[2]);
      if (finite) grasp(c, k, h, e.grasp.point);
    }
  }
  for (int h = 0; h < k->hands; h++) {
    tx_instrument_pose jp;
    bool any = false;
    for (int j = 0; j < k->nheld && !any; j++) any = k->holder[k->held[j]] == h;
    if (!any || !jaws_of(c, k, h, &jp)) continue; // a pose gone bad: they stay where they are
    for (int j = 0; j < k->nheld; j++) {
      const int i = k->held[j];
      if (k->holder[i] != h) continue;
      double x[3];
      tx_quat_rotate(jp.quat, false, &k->offset[(size_t)i * 3], x);
      for (int a = 0; a < 3; a++) x[a] += jp.pos[a];
      tx_cloth_pin(k->cloth, i, x);
    }
  }
}

// which side of the wound line a point lies on, in x-z (+1 or -1; 1 without a wound)
static int wound_side(const skin* k, const double p[3]) {
  if (!k->has_wound) return 1;
  const double *a = k->wound[0], *b = k->wound[1];
  return (b[0] - a[0]) * (p[2] - a[2]) - (b[2] - a[2]) * (p[0] - a[0]) >= 0 ? 1 : -1;
}

static void add_load(skin* k, int i, double w, const tx_puncture_load* q) {
  double* l = &k->load[3 * (size_t)i];
  if (!k->listed[i]) k->listed[i] = 1, k->loaded[k->nloaded++] = i;
  for (int e = 0; e < 3; e++) l[e] += w * q->f[e];
  k->load_k[i] += w * q->k;
}

// one row's force on the particles: by their distance from its point, weights
// 1 - d / R summing to 1, over the free particles within R on its side of the
// wound; on its triangle by the barycentric weights when R is 0 or none is in reach
static void spread(skin* k, const tx_puncture_load* q) {
  double p[3] = {0, 0, 0}, x[3];
  for (int a = 0; a < 3; a++) {
    tx_cloth_particle(k->cloth, (int)q->v[a], x);
    for (int e = 0; e < 3; e++) p[e] += q->bary[a] * x[e];
  }
  const double R = k->load_radius;
  double total = 0;
  const int side = wound_side(k, p);
  for (int pass = 0; pass < 2 && R > 0; pass++) // the weights' sum, then the loads
    for (int i = 0; i < k->n; i++) {
      if (tx_cloth_freed(k->cloth, i)) continue;
      tx_cloth_particle(k->cloth, i, x);
      double d = sqrt((x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) + (x[2] - p[2]) * (x[2] - p[2]));
      if (!(d < R) || wound_side(k, x) != side) continue;
      if (pass == 0) total += 1 - d / R;
      else add_load(k, i, (1 - d / R) / total, q);
    }
  if (total > 0) return;
  for (int a = 0; a < 3; a++) add_load(k, (int)q->v[a], q->bary[a], q);
}

// no particle loaded any more
static void clear_loads(skin* k) {
  static const double zero[3] = {0, 0, 0};
  for (int j = 0; j < k->nloaded; j++) {
    const int i = k->loaded[j];
    memset(&k->load[3 * (size_t)i], 0, sizeof(double) * 3);
    k->load_k[i] = 0;
    k->listed[i] = 0;
    tx_cloth_set_spring(k->cloth, i, zero, 0);
    tx_cloth_set_load(k->cloth, i, zero);
  }
  k->nloaded = 0;
}

// the thread's latest pull at its punctures on their particles, in place of
// the last: a row that is not a triangle of this skin with weights summing to
// 1, a finite force and a stiffness in [0, 1e9] N/m is counted (bad_load) and
// left out
static void take_loads(tx_ctx* c, skin* k) {
  tx_snapshot sl = tx_read(c, k->loads_in);
  if (sl.seq == 0) return;
  clear_loads(k);
  const tx_puncture_load* rows = sl.data;
  for (uint32_t r = 0; r < sl.rows && rows[r].v[0] != -1; r++) {
    const tx_puncture_load* q = &rows[r];
    double sum = q->bary[0] + q->bary[1] + q->bary[2];
    bool ok = isfinite(sum) && fabs(sum - 1) <= 1e-6 && isfinite(q->f[0]) && isfinite(q->f[1]) && isfinite(q->f[2]) &&
              q->k >= 0 && q->k <= 1e9;
    for (int a = 0; ok && a < 3; a++) ok = q->v[a] >= 0 && q->v[a] < k->n && q->v[a] == floor(q->v[a]);
    if (!ok) {
      tx_warn(c, k->bad_load);
      continue;
    }
    k->load_max = fmax(k->load_max, sqrt(q->f[0] * q->f[0] + q->f[1] * q->f[1] + q->f[2] * q->f[2]));
    spread(k, q);
  }
  // each particle's pull as a spring that gives as it moves (anchored load / k
  // beyond it now), which the implicit step takes whole; without a stiffness, a load
  for (int j = 0; j < k->nloaded; j++) {
    const int i = k->loaded[j];
    const double* l = &k->load[3 * (size_t)i];
    double x[3], anchor[3];
    tx_cloth_particle(k->cloth, i, x);
    tx_cloth_status st;
    if (k->load_k[i] > 0) {
      for (int e = 0; e < 3; e++) anchor[e] = x[e] + l[e] / k->load_k[i];
      st = tx_cloth_set_spring(k->cloth, i, anchor, k->load_k[i]);
    } else {
      st = tx_cloth_set_load(k->cloth, i, l);
    }
    if (st != TX_CLOTH_OK) tx_warn(c, k->bad_load);
  }
}

// The skin's reaction on the HIP and its tangent stiffness k = d|f|/dw. A
// membrane under a point load pushes back as |f| ~ w^p, p from 1 (held by its
// pre-tension: w = |f| ln(a/r0) / (2 pi T)) to 3 (stretched by the load alone,
// Foppl-Hencky), so k = p |f| / w lies in [|f|/w, 3|f|/w]. The secant between
// two steps in contact picks p; the bounds keep it sound when the indentation
// barely moved (noise, a hand at rest).
static void publish_contact(tx_ctx* c, skin* k) {
  tx_cloth_contact_info ci;
  tx_cloth_contact(k->cloth, &ci);
  tx_skin_contact* out = tx_write(c, k->contact);
  memset(out, 0, sizeof *out);
  out->torn = tx_cloth_torn(k->cloth);
  double f = sqrt(ci.f[0] * ci.f[0] + ci.f[1] * ci.f[1] + ci.f[2] * ci.f[2]), w = ci.depth;
  memcpy(out->x, ci.x, sizeof out->x);
  if (ci.held == 0 || !(f > 0) || !isfinite(f) || !isfinite(w)) {
    k->prev_f = k->prev_w = k->k = 0;
    return;
  }
  for (int a = 0; a < 3; a++) {
    out->f[a] = ci.f[a];
    out->n[a] = ci.f[a] / f;
  }
  out->depth = w;
  out->touching = 1;
  if (w > 1e-7) {
    double lo = f / w, hi = 3 * f / w, kk = k->k;
    if (k->prev_w > 0 && fabs(w - k->prev_w) > 1e-6) kk = (f - k->prev_f) / (w - k->prev_w);
    k->k = kk < lo ? lo : kk > hi ? hi : kk;
  }
  out->k = k->k;
  k->prev_f = f;
  k->prev_w = w;
}

static void publish(tx_ctx* c, skin* k) {
  float* x = ((tx_vertex*)tx_write(c, k->x))->x; // the cloth fills n x 3 floats: n tx_vertex
  if (!tx_cloth_positions(k->cloth, x)) { // the model must never hold a NaN: a last guard behind the cloth's own
    tx_warn(c, k->fault);
    tx_cloth_restore(k->cloth);
    tx_cloth_positions(k->cloth, x);
  }
  int32_t* tri = ((tx_triangle*)tx_write(c, k->tri))->v; // m x 3 indices: m tx_triangle
  tx_write_rows(c, k->tri, (uint32_t)tx_cloth_triangles(k->cloth, tri));
  ((tx_thickness*)tx_write(c, k->thickness))->m = tx_cloth_get_def(k->cloth)->thickness;
  *(tx_torn*)tx_write(c, k->torn) = (tx_torn){tx_cloth_torn(k->cloth), tx_cloth_torn_pulled(k->cloth), tx_cloth_pierces(k->cloth)};
  publish_contact(c, k);
  tx_skin_rupture* r = tx_write(c, k->rupture);
  r->tension = tx_cloth_peak_tension(k->cloth);
  r->broke = tx_cloth_broke_at(k->cloth, r->at) ? 1 : 0;
}

static int init(tx_ctx* c, void* self) {
  skin* k = self;
  for (int h = 0; h < k->hands && k->grasp_in.id; h++) release(k, h); // a run starts with open jaws
  k->grasps = 0;
  if (k->loads_in.id) clear_loads(k); // a run starts with no pull
  k->load_max = 0;
  publish(c, self); // the patch at rest, at time 0
  return 0;
}

static void step(tx_ctx* c, void* self) {
  skin* k = self;
  if (k->pose.id) {
    tx_snapshot p = tx_read(c, k->pose);
    if (p.seq > 0) { // nothing published yet: the HIP waits
      const tx_pose* pose = p.data;
      if (tx_cloth_set_hip(k->cloth, pose->pos, k->hip_radius) != TX_CLOTH_OK) tx_warn(c, k->bad_pose);
    }
  }
  if (k->grasp_in.id) follow_jaws(c, k);
  if (k->loads_in.id) take_loads(c, k);
  if (tx_cloth_step(k->cloth, k->dt) == TX_CLOTH_FAULT) tx_warn(c, k->fault);
  publish(c, k);
}

static void finish(tx_ctx* c, void* self) {
  skin* k = self;
  tx_set_result(c, k->torn_result, tx_cloth_torn(k->cloth));
  tx_set_result(c, k->pulled_result, tx_cloth_torn_pulled(k->cloth));
  tx_set_result(c, k->wound_result, k->wound_links);
  tx_set_result(c, k->fault_result, tx_cloth_faults(k->cloth));
  tx_set_result(c, k->grasp_result, k->grasps);
  tx_set_result(c, k->load_result, k->load_max);
  tx_set_result(c, k->pierce_result, tx_cloth_pierces(k->cloth));
  tx_set_result(c, k->freed_result, tx_cloth_freed_count(k->cloth));
  tx_set_result(c, k->pieces_result, tx_cloth_pieces_freed(k->cloth));
}

static void fini(void* self) {
  skin* k = self;
  if (!k) return;
  tx_cloth_destroy(k->cloth);
  free(k->holder);
  free(k->offset);
  free(k->held);
  free(k->load);
  free(k->loaded);
  free(k->load_k);
  free(k->listed);
  free(k);
}

const tx_controller_class tx_physics_skin = {
    .type = "physics.skin",
    .summary = "suturing skin on a Bullet soft body: rupture, HIP contact; writes skin.x, skin.tri, skin.thickness, skin.torn, skin.contact, skin.rupture",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
