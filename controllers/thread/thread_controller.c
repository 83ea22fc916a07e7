// physics.thread: the suture thread, follow-the-leader or rod, its head on a
// pose (device0.pose by default; the needle's swage end in a full suture).
// Each step it publishes PREFIX.nodes (tx_thread_node), the tension at the
// head as PREFIX.force_model (tx_force_model) for the haptics controller,
// and on PREFIX.events a TX_EVENT_KNOT when the papers' rule finds a knot
// (value[0..1]: its first and last cylinder, value[2]: 0) and when a knot
// within fix_distance_m of the skin is fixed (value[2]: 1). With skin set,
// the thread collides with SKIN.x / SKIN.tri, with the rigid meshes
// (MESH.x / MESH.tri) of the prefixes listed in meshes, and with the rigid
// capsules (tx_capsule rows) of the components listed in capsules. With cut_events
// it takes the TX_EVENT_CUT events of that stream: the link they name (or the
// one nearest their point) is severed, PREFIX.cut_links marks it and the pieces,
// and the cut is sent again on PREFIX.events. With punctures (tx_puncture
// rows: points on triangles of the skin's particles) the thread passes through them in order
// and writes its pull on the skin at each passed one, PREFIX.puncture_loads (tx_puncture_load).
// With grasp_events, a TX_EVENT_GRASP from hand h whose point is on the
// thread holds the nearest node in the jaws' frame (instrument<h>.pose)
// until a TX_EVENT_RELEASE from h. With start_shape the thread starts on
// that component's rows (a knot tied beforehand) instead of straight.
#include "thread_controller.h"

#include "knot.h"
#include "thread.h"
#include "../system.h" // tx_param_json, tx_param_point

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TX_THREAD_HANDS 8 // grasp_hands at most

typedef struct thread_ctl {
  tx_thread* t;
  double dt;
  double tension_k;  // N/m, ftl's tension model
  double max_force;  // N, the clamp on the published force
  double fix_distance;
  int knot_every, steps;
  bool knotted, fixed;
  int knots;
  int classify_every;   // steps between two runs of the classifier; 0: never
  bool knot_confirm;    // the papers' rule's knot counts only while the classifier finds one
  bool unconfirmed_now; // the rule finds a knot the classifier does not, now
  int unconfirmed;      // times that began
  tx_result unconfirmed_result;
  tx_knot_work* work;
  int classified;       // times the classifier went from the unknot to a knot
  tx_knot_class cls;    // its last answer
  double classified_s;  // s, the first of those (-1: none)
  tx_warning classify_failed;
  tx_result classified_result, classified_s_result, class_result;
  tx_port head, nodes, force, events, skin_x, skin_tri, skin_h;
  bool draw;
  tx_port segments, spheres; // with draw: the thread as a tube for the graphics view
  tx_port caps[8];
  int nmeshes;
  tx_port mesh_x[TX_THREAD_MAX_MESHES], mesh_tri[TX_THREAD_MAX_MESHES]; // the rigid meshes' MESH.x, MESH.tri
  tx_warning bad_mesh;
  tx_port cut_in, links;     // the cut events listened to (cut_in.id 0: none); PREFIX.cut_links
  tx_port grasp_in;          // the grasp events (grasp_in.id 0: none)
  bool grasp_shared;         // grasp_in is cut_in: one stream for both
  int hands;                 // grasp_hands: instrument0.pose .. instrument<hands - 1>.pose
  tx_port jaws[TX_THREAD_HANDS];
  int hold_node[TX_THREAD_HANDS]; // the node hand h holds (-1: none)
  double hold_off[TX_THREAD_HANDS][3]; // m, that node in the jaws' frame
  double grasp_capture;      // m
  int grasps;
  tx_warning bad_grasp;
  tx_result grasps_result;
  tx_port punct_in;          // the puncture list (punct_in.id 0: none)
  double* punct;             // (max_punctures x 3) where they are this step, m
  tx_puncture* punct_rows;   // (max_punctures) their rows as read: the triangles the loads go on
  double* side;              // (max_punctures) each row's side (+1 entry, -1 exit), for the bites
  double* load_f;            // (max_punctures x 3) N, the thread's pull on the skin at each passed one
  double* load_k;            // (max_punctures) N/m, and its stiffness
  tx_port loads;             // written with punctures: PREFIX.puncture_loads (tx_puncture_load)
  int max_punct;
  tx_warning bad_puncture, too_many_punctures;
  tx_result passed_result;
  tx_result out_result;
  int cuts;
  tx_warning bad_cut;
  tx_result cuts_result;
  int ncaps;
  tx_thread_capsule* shapes; // (max_shapes) the capsules' rows gathered each step
  uint8_t* marks;
  double* start;      // (N x 3) the first shape
  tx_port start_shape; // start_shape (id 0: none): the first shape, tx_thread_node rows
  tx_warning bad_start;
  double tail[3];     // m, tail_m
  bool started;
  tx_warning fault, bad_head, bad_skin, bad_capsule, too_many;
  tx_result knots_result, first_knot_result, faults_result;
  double first_knot_s;
  double rod_after_s; // > 0: the thread turns into a rod then
  int knot_first, knot_last; // the cylinders of the last knot counted (-1: none)
  double max_strain;         // the largest segment strain seen
  int knot_lost;             // times the papers' rule lost a knot it had found
  tx_result held_result, lost_result;
  int shape_steps;            // steps in which the thread touched a capsule
  tx_result shape_steps_result;
  tx_result strain_result;
} thread_ctl;

// defaults are tx_thread_def_default()'s
static const tx_param_def params[] = {
    {"model", TX_PARAM_STR, NULL, 0, 0, 0, "ftl", "ftl (follow-the-leader, kinematic) or rod (XPBD, E and diameter)"},
    {"nodes", TX_PARAM_INT, "1", 2, 100000, 64, NULL, "N, spheres joined by N - 1 cylinders"},
    {"radius_m", TX_PARAM_NUM, "m", 1e-6, 0.01, 0.00025, NULL, "r of the spheres and cylinders (a 0.5 mm thread)"},
    {"length_m", TX_PARAM_NUM, "m", 1e-4, 10, 0.2, NULL, "rest length head to tail"},
    {"youngs_modulus_pa", TX_PARAM_NUM, "Pa", 1, 1e16, 2e9, NULL, "rod: E (monofilament nylon, 2 GPa)"},
    {"bend_factor", TX_PARAM_NUM, "1", 0, 1, 1, NULL, "rod: bending stiffness bend_factor E I (0: perfectly flexible)"},
    {"density_kg_m3", TX_PARAM_NUM, "kg/m^3", 1, 1e5, 1140, NULL, "rod: the thread's density (nylon)"},
    {"gravity", TX_PARAM_NUM, "m/s^2", 0, 100, 9.81, NULL, "rod: along -y"},
    {"damping", TX_PARAM_NUM, "1/s", 0, 1e4, 1, NULL, "rod: decay rate of node velocities"},
    {"iterations", TX_PARAM_INT, "1", 1, 1000, 2, NULL, "rod: direct solves per substep; ftl: passes towards a pinned tail"},
    {"max_substep_s", TX_PARAM_NUM, "s", 1e-7, 0.1, 1e-3, NULL, "substeps no longer than this (shorter when nodes move fast)"},
    {"max_substeps", TX_PARAM_INT, "1", 1, 10000, 64, NULL, "at most this many substeps a step"},
    {"max_stretch", TX_PARAM_NUM, "1", 0, 1, 0.05, NULL, "rod: no segment longer than (1 + this) its rest length"},
    {"self_collision", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "cylinders of the thread push each other apart"},
    {"self_friction", TX_PARAM_NUM, "1", 0, 10, 0, NULL, "rod: Coulomb friction coefficient of the thread's contacts with itself"},
    {"slack", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "ftl: a node follows only when pulled (no segment longer than its rest length, some shorter)"},
    {"pin_tail", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "the tail stays where it starts"},
    {"start_shape", TX_PARAM_STR, NULL, 0, 0, 0, "", "a component of N tx_thread_node rows (e.g. a knot tied beforehand) the thread starts on, at rest; empty: straight from the head towards tail_m"},
    {"tail_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: where the thread starts straight towards from the head; [0.2, 0, 0] by default"},
    {"head", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the pose the head follows (f64 1 x 7)"},
    {"prefix", TX_PARAM_STR, NULL, 0, 0, 0, "thread", "writes PREFIX.nodes, PREFIX.force_model, PREFIX.events"},
    {"skin", TX_PARAM_STR, NULL, 0, 0, 0, "", "a skin's prefix (skin): collide with SKIN.x and SKIN.tri; empty: none"},
    {"capsules", TX_PARAM_STRS, NULL, 0, 8, 0, NULL, "components of rigid capsules (tx_capsule rows: instrument jaws, the needle) the thread keeps out of"},
    {"meshes", TX_PARAM_STRS, NULL, 0, TX_THREAD_MAX_MESHES, 0, NULL, "prefixes of rigid triangle meshes (MESH.x tx_vertex, MESH.tri tx_triangle rows: an organ, an instrument's surface) the thread keeps r off"},
    {"max_mesh_triangles", TX_PARAM_INT, "1", 1, 10000000, 20000, NULL, "room for each rigid mesh's triangles"},
    {"max_shapes", TX_PARAM_INT, "1", 0, 4096, 16, NULL, "room for the capsules' rows, all together"},
    {"max_triangles", TX_PARAM_INT, "1", 1, 10000000, 200000, NULL, "room for the skin's triangles"},
    {"tension_n_per_m", TX_PARAM_NUM, "N/m", 0, 1e6, 200, NULL, "ftl: force (length - rest length) x this, along the segments' sum"},
    {"max_force_n", TX_PARAM_NUM, "N", 0, 100, 10, NULL, "the published force never exceeds this"},
    {"knot_every", TX_PARAM_INT, "1", 1, 100000, 10, NULL, "steps between two knot checks (the papers' rule, O(N^2))"},
    {"draw", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "also write PREFIX.segments and PREFIX.spheres: the thread as a tube for the graphics view"},
    {"rod_after_s", TX_PARAM_NUM, "s", 0, 1e6, 0, NULL, "ftl: from this time on the thread is a rod (XPBD, self contacts), e.g. to pull a knot tight; 0: never"},
    {"classify_every", TX_PARAM_INT, "1", 0, 100000, 0, NULL, "steps between two runs of the knot classifier (Gauss code, 32 projections); 0: never"},
    {"knot_confirm", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL,
     "a knot the papers' rule finds counts (its event, its fixing) only while the classifier finds the thread knotted: the rule alone takes strands lying side by side for a knot; needs classify_every > 0"},
    {"fix_distance_m", TX_PARAM_NUM, "m", 0, 1, 0.002, NULL, "a knot this near the skin is fixed"},
    {"punctures", TX_PARAM_STR, NULL, 0, 0, 0, "", "a puncture list (tx_puncture rows: points on triangles of SKIN.x particles, e.g. needle.punctures) the thread passes through in order; needs skin; empty: none"},
    {"max_punctures", TX_PARAM_INT, "1", 0, 1024, 16, NULL, "room for the puncture list's rows"},
    {"puncture_friction_n", TX_PARAM_NUM, "N", 0, 100, 0, NULL, "the force along the thread a puncture holds it with before it slides (Coulomb), felt at the hand while it slides; rod: it slides also once holding it would stretch it by half max_stretch"},
    {"puncture_capture_m", TX_PARAM_NUM, "m", 1e-6, 0.1, 0.001, NULL, "the head has gone through a puncture once the thread behind it is this near it"},
    {"cut_events", TX_PARAM_STR, NULL, 0, 0, 0, "", "an event stream (instruments.events) whose TX_EVENT_CUT events cut the thread; empty: none"},
    {"grasp_events", TX_PARAM_STR, NULL, 0, 0, 0, "", "an event stream (instruments.events) whose TX_EVENT_GRASP from hand h holds the thread's nearest node in instrument<h>.pose's frame until h's TX_EVENT_RELEASE; empty: none"},
    {"grasp_capture_m", TX_PARAM_NUM, "m", 0, 0.1, 0.001, NULL, "a grasp holds the thread when its point is this near the thread (farther: another thing in the jaws, e.g. the needle)"},
    {"grasp_hands", TX_PARAM_INT, "1", 1, TX_THREAD_HANDS, 2, NULL, "with grasp_events: the jaws' frames read, instrument0.pose .. instrument<this - 1>.pose"},
};

static int configure(tx_setup* s, void** self) {
  thread_ctl* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  k->dt = 1.0 / tx_setup_rate(s);
  if (k->dt > 1) return tx_setup_fail(s, NULL, "physics.thread runs at 1 Hz or faster, not %g", tx_setup_rate(s));
  tx_thread_def d = tx_thread_def_default();
  const char* model = tx_table_str(s, "model");
  if (!model) return -1;
  if (strcmp(model, "ftl") == 0) d.model = TX_THREAD_FTL;
  else if (strcmp(model, "rod") == 0) d.model = TX_THREAD_ROD;
  else return tx_setup_fail(s, "model", "'%s': expected ftl or rod", model);
  d.nodes = (int)tx_table_int(s, "nodes");
  d.radius = tx_table_num(s, "radius_m");
  d.length = tx_table_num(s, "length_m");
  d.youngs_modulus = tx_table_num(s, "youngs_modulus_pa");
  d.bend_factor = tx_table_num(s, "bend_factor");
  d.density = tx_table_num(s, "density_kg_m3");
  d.gravity = tx_table_num(s, "gravity");
  d.damping = tx_table_num(s, "damping");
  d.iterations = (int)tx_table_int(s, "iterations");
  d.max_substep = tx_table_num(s, "max_substep_s");
  d.max_substeps = (int)tx_table_int(s, "max_substeps");
  d.max_stretch = tx_table_num(s, "max_stretch");
  d.self_collision = tx_table_bool(s, "self_collision");
  d.self_friction = tx_table_num(s, "self_friction");
  d.pin_tail = tx_table_bool(s, "pin_tail");
  d.slack = tx_table_bool(s, "slack");
  d.max_shapes = (int)tx_table_int(s, "max_shapes");
  d.max_punctures = (int)tx_table_int(s, "max_punctures");
  d.puncture_friction = tx_table_num(s, "puncture_friction_n");
  d.puncture_capture = tx_table_num(s, "puncture_capture_m");
  k->tension_k = tx_table_num(s, "tension_n_per_m");
  k->max_force = tx_table_num(s, "max_force_n");
  k->knot_every = (int)tx_table_int(s, "knot_every");
  k->fix_distance = tx_table_num(s, "fix_distance_m");
  k->classify_every = (int)tx_table_int(s, "classify_every");
  k->knot_confirm = tx_table_bool(s, "knot_confirm");
  if (k->knot_confirm && k->classify_every == 0)
    return tx_setup_fail(s, "knot_confirm", "needs the classifier: set classify_every > 0");
  k->rod_after_s = tx_table_num(s, "rod_after_s");
  double tail[3];
  if (tx_param_point(s, "tail_m", (const double[3]){0.2, 0, 0}, tail)) return -1;
  const char* head = tx_table_str(s, "head");
  const char* start_shape = tx_table_str(s, "start_shape");
  if (!start_shape) return -1;
  const char* prefix = tx_table_str(s, "prefix");
  const char* skin = tx_table_str(s, "skin");
  if (!head || !prefix || !skin) return -1;
  if (!*prefix) return tx_setup_fail(s, "prefix", "must not be empty");
  bool with_skin = *skin != 0;
  d.max_triangles = with_skin ? (int)tx_table_int(s, "max_triangles") : 0;
  const char* meshes[TX_THREAD_MAX_MESHES];
  k->nmeshes = tx_table_strs(s, "meshes", meshes, TX_THREAD_MAX_MESHES);
  d.max_meshes = k->nmeshes;
  d.max_mesh_triangles = k->nmeshes ? (int)tx_table_int(s, "max_mesh_triangles") : 0;
  // until the head's first pose the thread lies from the origin towards
  // tail_m; then it starts again straight from the head towards tail_m
  for (int a = 0; a < 3; a++) d.direction[a] = tail[a];
  if (tx_thread_def_check(&d)) {
    // name the parameter behind the field
    static const char* const keys[][2] = {{"nodes", "nodes"}, {"radius", "radius_m"}, {"length", "length_m"},
                                          {"direction", "tail_m"}, {"max_stretch", "max_stretch"}};
    const char* key = NULL;
    for (size_t i = 0; i < sizeof keys / sizeof keys[0] && !key; i++)
      if (strstr(tx_error(), keys[i][0])) key = keys[i][1];
    return tx_setup_fail(s, key, "%s", tx_error());
  }
  k->t = tx_thread_create(&d);
  if (!k->t) return tx_setup_fail(s, NULL, "%s", tx_error());
  k->marks = malloc((size_t)d.nodes);
  k->start = malloc(sizeof(double) * 3 * (size_t)d.nodes);
  memcpy(k->tail, tail, sizeof k->tail);
  if (!k->marks || !k->start) return tx_setup_fail(s, NULL, "out of memory");
  if (k->classify_every > 0 && !(k->work = tx_knot_work_create(d.nodes))) return tx_setup_fail(s, NULL, "out of memory");
  char name[256];
  k->head = TX_READ_OF(s, head, tx_pose);
  if (*start_shape) k->start_shape = TX_READ_OF(s, start_shape, tx_thread_node);
  k->bad_start = tx_setup_warning(s, "bad_start_shape");
  snprintf(name, sizeof name, "%s.nodes", prefix);
  k->nodes = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_thread_node, (uint32_t)d.nodes));
  snprintf(name, sizeof name, "%s.force_model", prefix);
  k->force = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_force_model, 1));
  snprintf(name, sizeof name, "%s.events", prefix);
  k->events = tx_setup_emit(s, name, 64);
  snprintf(name, sizeof name, "%s.cut_links", prefix);
  k->links = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_thread_link, (uint32_t)d.nodes - 1));
  const char* cut_events = tx_table_str(s, "cut_events");
  if (!cut_events) return -1;
  if (*cut_events) k->cut_in = tx_setup_listen(s, cut_events);
  const char* grasp_events = tx_table_str(s, "grasp_events");
  if (!grasp_events) return -1;
  k->grasp_capture = tx_table_num(s, "grasp_capture_m");
  k->hands = (int)tx_table_int(s, "grasp_hands");
  for (int h = 0; h < TX_THREAD_HANDS; h++) k->hold_node[h] = -1;
  if (*grasp_events) {
    // one stream for both: one reader, each event taken once
    k->grasp_shared = *cut_events && strcmp(cut_events, grasp_events) == 0;
    k->grasp_in = k->grasp_shared ? k->cut_in : tx_setup_listen(s, grasp_events);
    for (int h = 0; h < k->hands; h++) {
      snprintf(name, sizeof name, "instrument%d.pose", h);
      k->jaws[h] = TX_READ_OF(s, name, tx_instrument_pose);
    }
  }
  k->bad_grasp = tx_setup_warning(s, "bad_grasp");
  k->grasps_result = tx_setup_result(s, "grasps");
  k->held_result = tx_setup_result(s, "knot_held");
  k->lost_result = tx_setup_result(s, "knot_lost");
  const char* punctures = tx_table_str(s, "punctures");
  if (!punctures) return -1;
  if (*punctures) {
    if (!with_skin) return tx_setup_fail(s, "punctures", "'%s' needs skin: its rows are points on SKIN.x's triangles", punctures);
    // the layout and its units: a list of poses (f64 x 7 too) is refused at load
    k->punct_in = TX_READ_EXPECT(s, punctures, tx_puncture);
  }
  k->max_punct = d.max_punctures;
  k->punct = malloc(sizeof(double) * 3 * (size_t)(d.max_punctures + 1));
  k->punct_rows = malloc(sizeof(tx_puncture) * (size_t)(d.max_punctures + 1));
  k->side = malloc(sizeof(double) * (size_t)(d.max_punctures + 1));
  k->load_f = malloc(sizeof(double) * 3 * (size_t)(d.max_punctures + 1));
  k->load_k = malloc(sizeof(double) * (size_t)(d.max_punctures + 1));
  if (!k->punct || !k->punct_rows || !k->side || !k->load_f || !k->load_k) return tx_setup_fail(s, NULL, "out of memory");
  if (k->punct_in.id) {
    snprintf(name, sizeof name, "%s.puncture_loads", prefix);
    k->loads = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_puncture_load, (uint32_t)d.max_punctures + 1));
  }
  k->bad_puncture = tx_setup_warning(s, "bad_puncture");
  k->too_many_punctures = tx_setup_warning(s, "too_many_punctures");
  k->passed_result = tx_setup_result(s, "punctures_passed");
  k->out_result = tx_setup_result(s, "punctures_out");
  k->bad_cut = tx_setup_warning(s, "bad_cut");
  k->cuts_result = tx_setup_result(s, "cuts");
  k->draw = tx_table_bool(s, "draw");
  if (k->draw) {
    snprintf(name, sizeof name, "%s.segments", prefix);
    k->segments = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_segment, (uint32_t)d.nodes - 1));
    snprintf(name, sizeof name, "%s.spheres", prefix);
    k->spheres = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_sphere, (uint32_t)d.nodes));
  }
  if (with_skin) {
    snprintf(name, sizeof name, "%s.x", skin);
    k->skin_x = TX_READ_OF(s, name, tx_vertex);
    snprintf(name, sizeof name, "%s.tri", skin);
    k->skin_tri = TX_READ_OF(s, name, tx_triangle);
    snprintf(name, sizeof name, "%s.thickness", skin);
    k->skin_h = TX_READ_OF(s, name, tx_thickness);
  }
  for (int i = 0; i < k->nmeshes; i++) {
    if (!*meshes[i]) return tx_setup_fail(s, "meshes", "entry %d is empty: expected a mesh's prefix", i);
    snprintf(name, sizeof name, "%s.x", meshes[i]);
    k->mesh_x[i] = TX_READ_OF(s, name, tx_vertex);
    snprintf(name, sizeof name, "%s.tri", meshes[i]);
    k->mesh_tri[i] = TX_READ_OF(s, name, tx_triangle);
  }
  k->bad_mesh = tx_setup_warning(s, "bad_mesh");
  const char* caps[8];
  k->ncaps = tx_table_strs(s, "capsules", caps, 8);
  for (int i = 0; i < k->ncaps; i++) k->caps[i] = TX_READ_OF(s, caps[i], tx_capsule);
  k->shapes = malloc(sizeof(tx_thread_capsule) * (size_t)(d.max_shapes + 1));
  if (!k->shapes) return tx_setup_fail(s, NULL, "out of memory");
  k->too_many = tx_setup_warning(s, "too_many_capsules");
  if (k->ncaps) k->shape_steps_result = tx_setup_result(s, "capsule_contact_steps");
  k->fault = tx_setup_warning(s, "numerical_fault");
  k->bad_head = tx_setup_warning(s, "bad_head");
  k->bad_skin = tx_setup_warning(s, "bad_skin");
  k->bad_capsule = tx_setup_warning(s, "bad_capsule");
  k->knots_result = tx_setup_result(s, "knots");
  k->first_knot_result = tx_setup_result(s, "first_knot_s");
  k->strain_result = tx_setup_result(s, "max_strain");
  k->knot_first = k->knot_last = -1;
  k->faults_result = tx_setup_result(s, "faults");
  k->first_knot_s = -1;
  k->classify_failed = tx_setup_warning(s, "classify_failed");
  k->classified_result = tx_setup_result(s, "classifier_knots");
  k->classified_s_result = tx_setup_result(s, "classifier_knot_s");
  k->class_result = tx_setup_result(s, "knot_class");
  k->unconfirmed_result = tx_setup_result(s, "knots_unconfirmed");
  k->classified_s = -1;
  return 0;
}

static void publish(tx_ctx* c, thread_ctl* k) {
  tx_thread* t = k->t;
  int n = tx_thread_node_count(t);
  double r = tx_thread_get_def(t)->radius;
  tx_thread_node* out = tx_write(c, k->nodes);
  for (int i = 0; i < n; i++) {
    memcpy(out[i].x, tx_thread_position(t, i), sizeof out[i].x);
    out[i].radius = r;
  }
  const uint8_t* cut = tx_thread_severed(t);
  tx_thread_link* ln = tx_write(c, k->links);
  for (int i = 0, piece = 0; i + 1 < n; i++) {
    ln[i].severed = cut[i];
    ln[i].piece = piece;
    piece += cut[i];
  }
  if (k->draw) { // cylinders joined by spheres: a tube
    tx_segment* sg = tx_write(c, k->segments);
    tx_sphere* sp = tx_write(c, k->spheres);
    for (int i = 0; i < n; i++) {
      for (int a = 0; a < 3; a++) {
        sp[i].c[a] = (float)tx_thread_position(t, i)[a];
        if (i + 1 < n) sg[i].a[a] = sp[i].c[a], sg[i].b[a] = (float)tx_thread_position(t, i + 1)[a];
      }
      sp[i].r = (float)r;
      if (i + 1 < n) sg[i].r = cut[i] ? 0.0f : (float)r; // a cut link: radius 0, not drawn
    }
  }
  tx_force_model* m = tx_write(c, k->force);
  memset(m, 0, sizeof *m);
  memcpy(m->x0, tx_thread_position(t, 0), sizeof m->x0);
  tx_thread_tension(t, k->tension_k, k->max_force, m->f0, m->k);
  if (k->loads.id) { // the pull on the skin at each passed puncture, on its triangle
    int passed = tx_thread_puncture_loads(t, k->tension_k, k->max_force, k->load_f, k->load_k);
    tx_puncture_load* ld = tx_write(c, k->loads);
    for (int j = 0; j < passed; j++) {
      memcpy(ld[j].v, k->punct_rows[j].v, sizeof ld[j].v);
      memcpy(ld[j].bary, k->punct_rows[j].bary, sizeof ld[j].bary);
      memcpy(ld[j].f, k->load_f + 3 * j, sizeof ld[j].f);
      ld[j].k = k->load_k[j];
    }
    memset(&ld[passed], 0, sizeof ld[passed] * (size_t)(k->max_punct + 1 - passed));
    for (int j = passed; j <= k->max_punct; j++) ld[j].v[0] = -1;
  }
}

static void emit_knot(tx_ctx* c, thread_ctl* k, const tx_knot_papers* p, bool fixed) {
  tx_event e = {.kind = TX_EVENT_KNOT, .source = (uint32_t)k->knots, .sim_ns = tx_sim_ns(c)};
  e.value[0] = p->first;
  e.value[1] = p->last;
  e.value[2] = fixed ? 1 : 0;
  tx_emit(c, k->events, &e);
}

static void check_knot(tx_ctx* c, thread_ctl* k) {
  tx_thread* t = k->t;
  int n = tx_thread_node_count(t);
  tx_knot_rule rule = tx_knot_rule_papers();
  tx_knot_contacts(tx_thread_position(t, 0), n, tx_thread_get_def(t)->radius, rule.min_gap, k->marks);
  const uint8_t* cut = tx_thread_severed(t);
  for (int i = 0; i + 1 < n; i++)
    if (cut[i]) k->marks[i] = 0; // a cut link is no cylinder
  tx_knot_papers p;
  bool knot = tx_knot_papers_rule(k->marks, n - 1, &rule, &p);
  if (k->knot_confirm) { // the rule's knot only if the thread is knotted at all
    const bool unconfirmed = knot && k->cls == TX_KNOT_UNKNOT;
    if (unconfirmed && !k->unconfirmed_now) k->unconfirmed++;
    k->unconfirmed_now = unconfirmed;
    knot = knot && !unconfirmed;
  }
  // a knot on cylinders that overlap the last one counted is that knot again:
  // held at exactly 2 r, a tight knot's contacts flicker across the 1 % margin
  bool same = k->knot_first >= 0 && p.first <= k->knot_last && p.last >= k->knot_first;
  if (knot) k->knot_first = p.first, k->knot_last = p.last;
  if (knot && !k->knotted && !same) {
    k->knots++;
    if (k->first_knot_s < 0) k->first_knot_s = (double)tx_sim_ns(c) * 1e-9;
    emit_knot(c, k, &p, false);
  }
  if (knot && !k->fixed && k->skin_x.id && tx_thread_fix_near_mesh(t, p.first, p.last, k->fix_distance) == 1) {
    k->fixed = true;
    emit_knot(c, k, &p, true);
  }
  if (k->knotted && !knot) k->knot_lost++;
  k->knotted = knot;
}

// beside the papers' rule: the topology, which a loose knot has too
static void classify(tx_ctx* c, thread_ctl* k) {
  tx_knot_diagram d;
  if (tx_knot_classify(k->work, tx_thread_position(k->t, 0), tx_thread_node_count(k->t), &d)) {
    tx_warn(c, k->classify_failed);
    return;
  }
  if (d.cls != TX_KNOT_UNKNOT && k->cls == TX_KNOT_UNKNOT) {
    k->classified++;
    if (k->classified_s < 0) k->classified_s = (double)tx_sim_ns(c) * 1e-9;
  }
  k->cls = d.cls;
}

// the cut events since the last step: the link named by source, or the one
// nearest the blades' point when source is no link of this thread; each new
// cut goes out again on PREFIX.events (source: the link, point: its point
// nearest the blades)
static void take_grasp(tx_ctx* c, thread_ctl* k, const tx_event* e);

static void take_cuts(tx_ctx* c, thread_ctl* k) {
  tx_thread* t = k->t;
  int nseg = tx_thread_node_count(t) - 1;
  for (tx_event e; tx_next_event(c, k->cut_in, &e);) {
    if (k->grasp_shared && (e.kind == TX_EVENT_GRASP || e.kind == TX_EVENT_RELEASE)) take_grasp(c, k, &e);
    if (e.kind != TX_EVENT_CUT) continue;
    const double* p = e.cut.point;
    bool finite = isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
    double at[3];
    int seg = e.source < (uint32_t)nseg ? (int)e.source : finite ? tx_thread_nearest_link(t, p, at) : -1;
    if (seg < 0) {
      tx_warn(c, k->bad_cut);
      continue;
    }
    if (tx_thread_cut(t, seg) != 1) continue; // already cut
    k->cuts++;
    const double *a = tx_thread_position(t, seg), *b = tx_thread_position(t, seg + 1);
    double u = 0.5, ee = 0, ep = 0;
    for (int i = 0; i < 3 && finite; i++) {
      ee += (b[i] - a[i]) * (b[i] - a[i]);
      ep += (p[i] - a[i]) * (b[i] - a[i]);
    }
    if (finite && ee > 0) u = fmin(1, fmax(0, ep / ee));
    tx_event out = {.kind = TX_EVENT_CUT, .source = (uint32_t)seg};
    for (int i = 0; i < 3; i++) out.cut.point[i] = a[i] + u * (b[i] - a[i]);
    tx_emit(c, k->events, &out);
  }
}

// v rotated by the unit quaternion q (w, x, y, z), or by its inverse
static void rotate(const double q[4], const double v[3], bool inverse, double out[3]) {
  double w = q[0], x = inverse ? -q[1] : q[1], y = inverse ? -q[2] : q[2], z = inverse ? -q[3] : q[3];
  double tx = 2 * (y * v[2] - z * v[1]), ty = 2 * (z * v[0] - x * v[2]), tz = 2 * (x * v[1] - y * v[0]);
  out[0] = v[0] + w * tx + y * tz - z * ty;
  out[1] = v[1] + w * ty + z * tx - x * tz;
  out[2] = v[2] + w * tz + x * ty - y * tx;
}

// a grasp from hand h whose point is within grasp_capture of the thread
// (a link not cut) holds that link's node nearer the point, at its place
// in the jaws' frame, until a release from h. A hand's latest grasp is
// what its jaws hold: any grasp from h ends h's hold first. Grasps of other
// things (the needle) are farther from the thread, or nearest its head
// (which is on the needle's swage): they hold no node.
static void take_grasp(tx_ctx* c, thread_ctl* k, const tx_event* e) {
  tx_thread* t = k->t;
  int h = (int)e->source;
  if (h < 0 || h >= k->hands) {
    tx_warn(c, k->bad_grasp);
    return;
  }
  if (k->hold_node[h] >= 0) tx_thread_release(t, k->hold_node[h]);
  k->hold_node[h] = -1;
  if (e->kind == TX_EVENT_RELEASE) return;
  const double* p = e->grasp.point;
  if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) {
    tx_warn(c, k->bad_grasp);
    return;
  }
  double at[3];
  int seg = tx_thread_nearest_link(t, p, at);
  if (seg < 0) return;
  double d = 0;
  for (int a = 0; a < 3; a++) d += (at[a] - p[a]) * (at[a] - p[a]);
  if (sqrt(d) > k->grasp_capture) return; // not the thread
  const double *a0 = tx_thread_position(t, seg), *a1 = tx_thread_position(t, seg + 1);
  double d0 = 0, d1 = 0;
  for (int a = 0; a < 3; a++) d0 += (a0[a] - p[a]) * (a0[a] - p[a]), d1 += (a1[a] - p[a]) * (a1[a] - p[a]);
  int node = d1 <= d0 ? seg + 1 : seg;
  if (node == 0) return; // at the head: the needle's swage
  tx_snapshot js = tx_read(c, k->jaws[h]);
  if (js.seq == 0) return; // no jaws to hold it in yet
  const tx_instrument_pose* jp = js.data;
  const double* x = tx_thread_position(t, node);
  double rel[3] = {x[0] - jp->pos[0], x[1] - jp->pos[1], x[2] - jp->pos[2]};
  rotate(jp->quat, rel, true, k->hold_off[h]);
  k->hold_node[h] = node;
  k->grasps++;
}

// each held node where its jaws are now
static void follow_jaws(tx_ctx* c, thread_ctl* k) {
  for (int h = 0; h < k->hands; h++) {
    if (k->hold_node[h] < 0) continue;
    tx_snapshot js = tx_read(c, k->jaws[h]);
    if (js.seq == 0) continue;
    const tx_instrument_pose* jp = js.data;
    double q[4], n = 0, at[3];
    for (int a = 0; a < 4; a++) n += jp->quat[a] * jp->quat[a];
    n = sqrt(n);
    for (int a = 0; a < 4; a++) q[a] = n > 0 ? jp->quat[a] / n : a == 0;
    rotate(q, k->hold_off[h], false, at);
    for (int a = 0; a < 3; a++) at[a] += jp->pos[a];
    if (tx_thread_hold(k->t, k->hold_node[h], at) != TX_THREAD_OK) tx_warn(c, k->bad_grasp);
  }
}

// the puncture list's points where their triangles' particles are now
// (rows of SKIN.x, which a tear never renumbers); it ends at the first row
// with v[0] = -1. A malformed row (a corner that is no row of SKIN.x,
// barycentric coordinates that are not finite or do not sum to 1) ends it
// too, counted as bad_puncture.
static void take_punctures(tx_ctx* c, thread_ctl* k, tx_snapshot sx) {
  tx_snapshot sp = tx_read(c, k->punct_in);
  if (sp.seq == 0) return;
  const tx_puncture* rows = sp.data;
  const tx_vertex* vx = sx.data;
  int n = 0;
  for (uint32_t r = 0; r < sp.rows; r++) {
    const tx_puncture* q = &rows[r];
    if (q->v[0] == -1) break;
    double sum = q->bary[0] + q->bary[1] + q->bary[2];
    bool ok = isfinite(sum) && fabs(sum - 1) <= 1e-6;
    uint32_t v[3] = {0, 0, 0};
    for (int a = 0; ok && a < 3; a++) {
      ok = q->v[a] >= 0 && q->v[a] < sx.rows && q->v[a] == floor(q->v[a]);
      if (ok) v[a] = (uint32_t)q->v[a];
    }
    if (!ok) {
      tx_warn(c, k->bad_puncture);
      break;
    }
    if (n == k->max_punct) {
      tx_warn(c, k->too_many_punctures);
      break;
    }
    for (int a = 0; a < 3; a++) {
      double p = 0;
      for (int j = 0; j < 3; j++) p += q->bary[j] * vx[v[j]].x[a];
      k->punct[3 * n + a] = p;
    }
    k->side[n] = q->side;
    k->punct_rows[n++] = *q;
  }
  if (tx_thread_set_punctures(k->t, k->punct, k->side, n) != TX_THREAD_OK) tx_warn(c, k->bad_puncture);
}

// the first shape: start_shape's rows when set (waiting for its first
// publish; a count other than N or a row not finite is counted and the
// thread starts straight), else straight from the head's first pose towards tail_m
static void start(tx_ctx* c, thread_ctl* k, const tx_pose* pose) {
  const tx_thread_def* d = tx_thread_get_def(k->t);
  int n = d->nodes;
  if (k->start_shape.id) {
    tx_snapshot sh = tx_read(c, k->start_shape);
    if (sh.seq == 0) return;
    const tx_thread_node* rows = sh.data;
    bool ok = sh.rows == (uint32_t)n;
    for (int i = 0; i < n && ok; i++)
      for (int a = 0; a < 3; a++) {
        ok &= isfinite(rows[i].x[a]) && fabs(rows[i].x[a]) <= 10;
        k->start[3 * i + a] = ok ? rows[i].x[a] : 0;
      }
    if (ok) {
      tx_thread_set_positions(k->t, k->start);
      k->started = true;
      return;
    }
    tx_warn(c, k->bad_start);
  }
  double dir[3], l = 0;
  for (int a = 0; a < 3; a++) {
    dir[a] = k->tail[a] - pose->pos[a];
    l += dir[a] * dir[a];
  }
  l = sqrt(l);
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++)
      k->start[3 * i + a] = pose->pos[a] + (l > 0 ? dir[a] / l : a == 0) * d->length * i / (n - 1);
  tx_thread_set_positions(k->t, k->start);
  k->started = true;
}

static void step(tx_ctx* c, void* self) {
  thread_ctl* k = self;
  if (k->cut_in.id) take_cuts(c, k);
  if (k->grasp_in.id && !k->grasp_shared)
    for (tx_event e; tx_next_event(c, k->grasp_in, &e);)
      if (e.kind == TX_EVENT_GRASP || e.kind == TX_EVENT_RELEASE) take_grasp(c, k, &e);
  tx_snapshot p = tx_read(c, k->head);
  if (p.seq > 0) { // nothing published yet: the head waits
    const tx_pose* pose = p.data;
    if (tx_thread_set_head(k->t, pose->pos) != TX_THREAD_OK) tx_warn(c, k->bad_head);
    if (!k->started) start(c, k, pose);
  }
  if (k->skin_x.id) {
    tx_snapshot sx = tx_read(c, k->skin_x), st = tx_read(c, k->skin_tri), sh = tx_read(c, k->skin_h);
    if (sx.seq > 0 && st.seq > 0 && sh.seq > 0 &&
        tx_thread_set_mesh(k->t, sx.data, sx.rows, st.data, st.rows, ((const tx_thickness*)sh.data)->m) != TX_THREAD_OK)
      tx_warn(c, k->bad_skin);
    if (k->punct_in.id && sx.seq > 0 && st.seq > 0) take_punctures(c, k, sx);
  }
  for (int i = 0; i < k->nmeshes; i++) { // kinematic: as published this step (refitted when only moved)
    tx_snapshot mx = tx_read(c, k->mesh_x[i]), mt = tx_read(c, k->mesh_tri[i]);
    if (mx.seq > 0 && mt.seq > 0 && tx_thread_set_rigid_mesh(k->t, i, mx.data, mx.rows, mt.data, mt.rows) != TX_THREAD_OK)
      tx_warn(c, k->bad_mesh);
  }
  if (k->ncaps) { // every capsule row, as far as there is room
    int m = 0, max = tx_thread_get_def(k->t)->max_shapes;
    for (int i = 0; i < k->ncaps; i++) {
      tx_snapshot sc = tx_read(c, k->caps[i]);
      const tx_capsule* rows = sc.data;
      for (uint32_t r = 0; sc.seq > 0 && r < sc.rows; r++) {
        if (m == max) {
          tx_warn(c, k->too_many);
          break;
        }
        memcpy(k->shapes[m].a, rows[r].a, sizeof rows[r].a);
        memcpy(k->shapes[m].b, rows[r].b, sizeof rows[r].b);
        k->shapes[m++].radius = rows[r].radius;
      }
    }
    if (tx_thread_set_capsules(k->t, k->shapes, m) != TX_THREAD_OK) tx_warn(c, k->bad_capsule);
  }
  if (k->grasp_in.id) follow_jaws(c, k);
  if (k->rod_after_s > 0 && tx_thread_get_def(k->t)->model == TX_THREAD_FTL && tx_sim_ns(c) * 1e-9 >= k->rod_after_s)
    tx_thread_set_model(k->t, TX_THREAD_ROD);
  if (tx_thread_step(k->t, k->dt) == TX_THREAD_FAULT) tx_warn(c, k->fault);
  tx_thread_contacts hit;
  tx_thread_last_contacts(k->t, &hit);
  k->shape_steps += hit.shape_hits > 0;
  double strain = tx_thread_max_strain(k->t);
  if (strain > k->max_strain) k->max_strain = strain;
  // the classifier first: a knot to confirm is confirmed by this step's answer
  if (k->classify_every > 0 && k->steps % k->classify_every == 0) classify(c, k);
  if (k->steps % k->knot_every == 0) check_knot(c, k);
  k->steps++;
  publish(c, k);
}

static int init(tx_ctx* c, void* self) {
  publish(c, self);
  return 0;
}

static void finish(tx_ctx* c, void* self) {
  thread_ctl* k = self;
  tx_set_result(c, k->knots_result, k->knots);
  tx_set_result(c, k->cuts_result, k->cuts);
  tx_set_result(c, k->grasps_result, k->grasps);
  tx_set_result(c, k->held_result, k->knotted ? 1 : 0);
  tx_set_result(c, k->lost_result, k->knot_lost);
  tx_set_result(c, k->passed_result, tx_thread_punctures_passed(k->t));
  tx_set_result(c, k->out_result, tx_thread_punctures_out(k->t));
  tx_set_result(c, k->first_knot_result, k->first_knot_s);
  tx_set_result(c, k->strain_result, k->max_strain);
  tx_set_result(c, k->faults_result, tx_thread_faults(k->t));
  tx_set_result(c, k->classified_result, k->classified);
  tx_set_result(c, k->classified_s_result, k->classified_s);
  tx_set_result(c, k->class_result, (double)k->cls);
  tx_set_result(c, k->unconfirmed_result, k->unconfirmed);
  tx_set_result(c, k->shape_steps_result, k->shape_steps);
}

static void fini(void* self) {
  thread_ctl* k = self;
  if (!k) return;
  tx_thread_destroy(k->t);
  tx_knot_work_destroy(k->work);
  free(k->marks);
  free(k->start);
  free(k->shapes);
  free(k->punct);
  free(k->punct_rows);
  free(k->side);
  free(k->load_f);
  free(k->load_k);
  free(k);
}

const tx_controller_class tx_physics_thread = {
    .type = "physics.thread",
    .summary = "suture thread, ftl or XPBD rod, head on a pose: writes THREAD.nodes, THREAD.cut_links, THREAD.force_model, THREAD.events (knots, cuts)",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
