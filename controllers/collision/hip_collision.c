// collision.hip: the HIP's rays against the skin of the latest physics
// publish, and the local force model for the haptics controller. Each
// publish is copied and a second BVH is refitted to it over a few steps
// while the first still answers; then the two swap, so no single 4 kHz step
// carries a whole refit. A tear (triangles gone, the rest in order) empties
// the torn triangles in place and refits at once, so a hole shows in the step
// that sees it; any other change of the triangle set rebuilds the second tree
// at once.
//
// Between two physics publishes the skin is frozen while the hand moves on.
// The force computed on the frozen skin is the force where the skin last
// settled around the HIP, so the model anchors F0 at x0, the point where the
// HIP would just touch that skin along the direction it came from, and K,
// the rays' estimate of how the force grows as the skin is pushed along its
// normals, carries the force along with the hand until the next publish.
#include "hip_collision.h"

#include "hip.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct hip_ctl {
  tx_hip hip;               // the method's state
  tx_tri_bvh tree[2];       // over the skin's live triangles: one answers queries, the other is refitted
  float* xs[2];             // (xcap x 3) m, the particles each tree was fitted to, copied from the publish
  int64_t ns[2];            // simulation time of the skin publish each tree holds
  int act;                  // the tree queries use, -1 for none (no usable skin)
  bool job;                 // the other tree is being refitted to a newer publish
  uint32_t job_next;        // its nodes [0, job_next) are still to refit
  uint32_t chunk;           // nodes refitted per step: a refit is spread over a few steps
  uint32_t tri_cap, xcap;   // triangles and particles the trees and copies were sized for
  bool mechanics;           // force_mode "mechanics": the skin's reaction (SKIN.contact), else the papers' rays
  tx_port pose, x, tri, thickness, contact;  // reads (contact: mechanics mode only)
  tx_port model, state, spheres;             // writes
  uint64_t x_seq, tri_seq;  // last publishes seen
  double last_c[3];         // m, last finite pose
  double prev_c[3];         // m, the pose of the last pose publish
  uint64_t pose_seq;        // last pose publish seen
  double pose_step;         // m, how far the pose moved between its last two publishes
  tx_warning w_pose, w_skin, w_mesh; // non-finite pose, non-finite skin, triangle set too large or bad
  tx_result r_peak, r_contacts, r_pierced, r_rebuilds, r_refits, r_resets, r_tears;
  double peak;              // N, largest force sent
  uint64_t max_contacts, pierces, rebuilds, refits, tears; // tears: triangle sets shrunk without a rebuild
  bool was_pierced;
} hip_ctl;

// defaults are tx_hip_def_default()'s (tests/controllers/test_param_tables.c checks)
static const tx_param_def params[] = {
    {"force_mode", TX_PARAM_STR, NULL, 0, 0, 0, "mechanics", "\"mechanics\": the skin's reaction from the physics (SKIN.contact); \"paper\": the papers' rays, F = -alpha sum(R_n)/N"},
    {"radius_m", TX_PARAM_NUM, "m", 1e-5, 0.05, 0.0005, NULL, "the HIP sphere's radius (the papers' 0.05 cm)"},
    {"rays", TX_PARAM_INT, "1", 26, 98, 26, NULL, "rays cast from the HIP: 26 or 98"},
    {"alpha", TX_PARAM_NUM, "N/m", 0, 1e6, 20, NULL, "force per metre of mean ray depth, F = -alpha sum(R_n)/N (0.2 N/cm)"},
    {"k", TX_PARAM_NUM, "1", 0, 0.999, 0.3, NULL, "eq. 8 factor: how far P_in follows the surface per update"},
    {"slide_max_m", TX_PARAM_NUM, "m", 1e-6, 1, 0.003, NULL, "how far the HIP slides before P_in moves (0.3 cm)"},
    {"pierce_range_m", TX_PARAM_NUM, "m", 1e-5, 1, 0.01, NULL, "how far a pierced HIP may go from its entry point"},
    {"hold_m", TX_PARAM_NUM, "m", 0, 0.01, 5e-4, NULL, "how far the skin may lead the HIP over one physics period"},
    {"join", TX_PARAM_STR, NULL, 0, 0, 0, "anchor", "\"anchor\" or \"own\": where a pierced HIP joins the surface"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the tool pose read (f64 1 x 7)"},
    {"skin", TX_PARAM_STR, NULL, 0, 0, 0, "skin", "the mesh read: SKIN.x, SKIN.tri, SKIN.thickness"},
    {"force_model", TX_PARAM_STR, NULL, 0, 0, 0, "tool0.force_model", "the force model written (f64 1 x 15)"},
    {"state", TX_PARAM_STR, NULL, 0, 0, 0, "hip0.state", "the HIP state written (f64 1 x 8)"},
    {"spheres", TX_PARAM_STR, NULL, 0, 0, 0, "hip0.spheres", "the HIP for views, written"},
};

static int configure(tx_setup* s, void** self) {
  hip_ctl* h = calloc(1, sizeof *h);
  if (!h) return -1;
  *self = h;
  tx_hip_def def = tx_hip_def_default();
  def.radius = tx_table_num(s, "radius_m");
  def.rays = (int)tx_table_int(s, "rays");
  def.alpha = tx_table_num(s, "alpha");
  def.k = tx_table_num(s, "k");
  def.slide_max = tx_table_num(s, "slide_max_m");
  def.pierce_range = tx_table_num(s, "pierce_range_m");
  def.hold = tx_table_num(s, "hold_m");
  const char* join = tx_table_str(s, "join");
  if (!join) return -1;
  if (strcmp(join, "anchor") && strcmp(join, "own")) return tx_setup_fail(s, "join", "expected \"anchor\" or \"own\", got \"%s\"", join);
  def.join_anchor = strcmp(join, "anchor") == 0;
  const char* mode = tx_table_str(s, "force_mode");
  if (!mode) return -1;
  if (strcmp(mode, "mechanics") && strcmp(mode, "paper"))
    return tx_setup_fail(s, "force_mode", "expected \"mechanics\" or \"paper\", got \"%s\"", mode);
  h->mechanics = strcmp(mode, "mechanics") == 0;
  if (def.rays != 26 && def.rays != 98) return tx_setup_fail(s, "rays", "must be 26 or 98, got %d", def.rays);
  if (tx_hip_def_check(&def)) return tx_setup_fail(s, NULL, "%s", tx_error());
  tx_hip_init(&h->hip, &def);
  const char* pose = tx_table_str(s, "pose");
  const char* skin = tx_table_str(s, "skin");
  const char* model = tx_table_str(s, "force_model");
  const char* state = tx_table_str(s, "state");
  const char* spheres = tx_table_str(s, "spheres");
  if (!pose || !skin || !model || !state || !spheres) return -1;
  char name[4][TX_NAME_MAX];
  if (snprintf(name[0], TX_NAME_MAX, "%s.x", skin) >= TX_NAME_MAX) return tx_setup_fail(s, "skin", "name too long");
  snprintf(name[1], TX_NAME_MAX, "%s.tri", skin);
  snprintf(name[2], TX_NAME_MAX, "%s.thickness", skin);
  if (snprintf(name[3], TX_NAME_MAX, "%s.contact", skin) >= TX_NAME_MAX) return tx_setup_fail(s, "skin", "name too long");
  h->pose = TX_READ_OF(s, pose, tx_pose);
  h->x = TX_READ_OF(s, name[0], tx_vertex);
  h->tri = TX_READ_OF(s, name[1], tx_triangle);
  h->thickness = TX_READ_OF(s, name[2], tx_thickness);
  if (h->mechanics) h->contact = TX_READ_OF(s, name[3], tx_skin_contact);
  h->model = tx_setup_write(s, &TX_COMPONENT_OF(model, tx_force_model, 1));
  h->state = tx_setup_write(s, &TX_COMPONENT_OF(state, tx_hip_state, 1));
  h->spheres = tx_setup_write(s, &TX_COMPONENT_OF(spheres, tx_sphere, 1));
  h->w_pose = tx_setup_warning(s, "pose_not_finite");
  h->w_skin = tx_setup_warning(s, "skin_not_finite");
  h->w_mesh = tx_setup_warning(s, "skin_mesh_rejected");
  h->r_peak = tx_setup_result(s, "peak_force_N");
  h->r_contacts = tx_setup_result(s, "max_contacts");
  h->r_pierced = tx_setup_result(s, "pierces");
  h->r_rebuilds = tx_setup_result(s, "bvh_rebuilds");
  h->r_refits = tx_setup_result(s, "bvh_refits");
  h->r_resets = tx_setup_result(s, "eq8_updates");
  h->r_tears = tx_setup_result(s, "bvh_tears");
  return 0;
}

static int init(tx_ctx* c, void* self) {
  hip_ctl* h = self;
  // before the skin's first publish a read holds its full capacity: size everything by it
  tx_snapshot tri = tx_read(c, h->tri), x = tx_read(c, h->x);
  h->tri_cap = tri.rows > 0 ? tri.rows : 1;
  h->xcap = x.rows > 0 ? x.rows : 1;
  h->act = -1;
  for (int i = 0; i < 2; i++) {
    if (tx_tri_bvh_init(&h->tree[i], h->tri_cap)) return -1;
    if (!(h->xs[i] = calloc(3 * (size_t)h->xcap, sizeof(float)))) return -1;
  }
  // a refit of up to 8192 nodes (about 12000 triangles: the 1764-particle skin) is done in
  // the step that sees the publish; a larger one is spread over up to 8 steps at 4 kHz
  // (2 ms, well inside a 120 Hz physics period), or fewer at lower rates
  double spread = floor(tx_rate(c) / 500);
  size_t share = 2 * (size_t)h->tri_cap / (spread < 1 ? 1 : spread > 16 ? 16 : spread) + 1;
  h->chunk = (uint32_t)(share > 8192 ? share : 8192);
  return 0;
}

static bool all_finite(const float* v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

// a new skin publish: copy it beside the tree in use, then refit the other tree to it over the
// next steps, or rebuild that tree now when the triangle set changed
static void take_skin(tx_ctx* c, hip_ctl* h, tx_snapshot x, tx_snapshot tri) {
  int b = h->act == 0 ? 1 : 0;
  h->job = false;
  if (x.rows > h->xcap) {
    tx_warn(c, h->w_mesh);
    h->act = -1;
    return;
  }
  memcpy(h->xs[b], x.data, 3 * (size_t)x.rows * sizeof(float));
  if (!all_finite(h->xs[b], 3 * (size_t)x.rows)) { // no force from a broken skin, until a good one
    tx_warn(c, h->w_skin);
    h->act = -1;
    return;
  }
  h->ns[b] = x.sim_ns;
  tx_tri_bvh* cur = h->act >= 0 ? &h->tree[h->act] : NULL;
  if (cur && x.rows == cur->nx && tx_tri_bvh_same(cur, tri.data, tri.rows)) {
    // the same triangles: the other tree takes this shape (if it was left behind) and is refitted
    if (!(x.rows == h->tree[b].nx && tx_tri_bvh_same(&h->tree[b], tri.data, tri.rows))) tx_tri_bvh_copy(&h->tree[b], cur);
    h->job = true;
    h->job_next = h->tree[b].nnodes;
    return;
  }
  if (cur && x.rows == cur->nx && tri.rows < cur->ntri && tx_tri_bvh_copy(&h->tree[b], cur) == 0 &&
      tx_tri_bvh_remove(&h->tree[b], tri.data, tri.rows) == 0) {
    // a tear took triangles out: they are emptied in the other tree's shape, which is refitted
    // at once, so that a hole under the HIP counts in this very step
    tx_tri_bvh_refit(&h->tree[b], h->xs[b]);
    h->act = b;
    h->tears++;
    return;
  }
  if (tx_tri_bvh_build(&h->tree[b], h->xs[b], x.rows, tri.data, tri.rows)) {
    tx_warn(c, h->w_mesh); // more triangles than at start, or an index outside the particles
    h->act = -1;
    return;
  }
  h->act = b;
  h->rebuilds++;
}

// one step's share of the refit; the refitted tree takes over when it is whole
static void refit_some(hip_ctl* h) {
  int b = h->act == 0 ? 1 : 0;
  uint32_t from = h->job_next > h->chunk ? h->job_next - h->chunk : 0;
  tx_tri_bvh_refit_nodes(&h->tree[b], h->xs[b], from, h->job_next);
  h->job_next = from;
  if (from == 0) {
    h->act = b;
    h->job = false;
    h->refits++;
  }
}

static void step(tx_ctx* c, void* self) {
  hip_ctl* h = self;
  const tx_pose* pose = tx_read(c, h->pose).data;
  double centre[3] = {pose->pos[0], pose->pos[1], pose->pos[2]};
  if (!(isfinite(centre[0]) && isfinite(centre[1]) && isfinite(centre[2]))) {
    tx_warn(c, h->w_pose);
    memcpy(centre, h->last_c, sizeof centre); // hold the last good pose
  }
  memcpy(h->last_c, centre, sizeof centre);
  tx_snapshot ps = tx_read(c, h->pose);
  if (ps.seq != h->pose_seq) { // the hand's move over one device tick
    double d[3] = {centre[0] - h->prev_c[0], centre[1] - h->prev_c[1], centre[2] - h->prev_c[2]};
    h->pose_step = h->pose_seq ? sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) : 0;
    h->pose_seq = ps.seq;
    memcpy(h->prev_c, centre, sizeof centre);
  }

  // a new physics publish: take the skin
  tx_snapshot x = tx_read(c, h->x), tri = tx_read(c, h->tri);
  double thickness = ((const tx_thickness*)tx_read(c, h->thickness).data)->m;
  if (!isfinite(thickness) || thickness < 0) thickness = 0;
  if (x.seq != 0 && (x.seq != h->x_seq || tri.seq != h->tri_seq)) {
    h->x_seq = x.seq;
    h->tri_seq = tri.seq;
    take_skin(c, h, x, tri);
  }
  if (h->job) refit_some(h);

  tx_hip_out out;
  if (h->act >= 0 && h->mechanics) {
    const tx_skin_contact* r = tx_read(c, h->contact).data;
    tx_hip_query_reaction(&h->hip, &h->tree[h->act], h->xs[h->act], thickness, centre, r, &out);
  } else if (h->act >= 0) {
    tx_hip_query(&h->hip, &h->tree[h->act], h->xs[h->act], thickness, centre, &out);
  } else {
    tx_hip_reset(&h->hip);
    memset(&out, 0, sizeof out);
    memcpy(out.x0, centre, sizeof centre);
  }
  if (out.pierced && !h->was_pierced) h->pierces++;
  h->was_pierced = out.pierced;

  // the local model: F0 where the frozen skin would just touch the HIP, K from the rays
  tx_force_model* m = tx_write(c, h->model);
  memset(m, 0, sizeof *m);
  bool force = out.contacts > 0 || out.f[0] != 0 || out.f[1] != 0 || out.f[2] != 0; // (a contact held through a gap in the rays has none)
  memcpy(m->x0, force ? out.x0 : centre, sizeof m->x0);
  if (force) {
    memcpy(m->f0, out.f, sizeof m->f0);
    // a hand that moves more than the contact distance in one device tick would carry
    // the linear model past the skin (through a pierce the next query will see): hold F0
    if (h->pose_step <= h->hip.def.radius + 0.5 * thickness) memcpy(m->k, out.k, sizeof m->k);
    double f = sqrt(out.f[0] * out.f[0] + out.f[1] * out.f[1] + out.f[2] * out.f[2]);
    if (f > h->peak) h->peak = f;
    if ((uint64_t)out.contacts > h->max_contacts) h->max_contacts = (uint64_t)out.contacts;
  }
  tx_hip_state* st = tx_write(c, h->state);
  st->contacts = out.contacts;
  st->pierced = out.pierced;
  memcpy(st->f, out.f, sizeof st->f);
  st->depth = out.depth;
  st->resets = (double)h->hip.resets;
  st->skin_t = h->act >= 0 ? h->ns[h->act] * 1e-9 : 0;
  tx_sphere* sp = tx_write(c, h->spheres);
  for (int a = 0; a < 3; a++) sp->c[a] = (float)centre[a];
  sp->r = (float)h->hip.def.radius;
}

static void finish(tx_ctx* c, void* self) {
  hip_ctl* h = self;
  tx_set_result(c, h->r_peak, h->peak);
  tx_set_result(c, h->r_contacts, (double)h->max_contacts);
  tx_set_result(c, h->r_pierced, (double)h->pierces);
  tx_set_result(c, h->r_rebuilds, (double)h->rebuilds);
  tx_set_result(c, h->r_refits, (double)h->refits);
  tx_set_result(c, h->r_resets, (double)h->hip.resets);
  tx_set_result(c, h->r_tears, (double)h->tears);
}

static void fini(void* self) {
  hip_ctl* h = self;
  if (!h) return;
  for (int i = 0; i < 2; i++) {
    tx_tri_bvh_free(&h->tree[i]);
    free(h->xs[i]);
  }
  free(h);
}

const tx_controller_class tx_collision_hip = {
    .type = "collision.hip",
    .summary = "the suturing papers' ray-casting HIP against the skin mesh: F = -alpha sum(R_n)/N, eq. 8, local model F0, x0, K",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
