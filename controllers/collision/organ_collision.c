// collision.organ: the tool tip against the soft organs' surfaces of the
// latest physics publish, at the haptic rate, and the local force model for
// the haptics controller. Each organ has its own BVH, built on its first
// publish and refitted whole in the step that sees a new one (a 2484-triangle
// liver refits in a few microseconds, so no spreading over steps as
// collision.hip does for its larger skins); a new triangle set rebuilds it.
//
// The physics runs at 20 to 60 Hz while the hand moves on: the force is the
// organs' own reaction (organs.contact) carried to the hand with its tangent
// stiffness while the physics sees the contact, and a penalty on the
// geometric penetration of the frozen surfaces when the tip meets one that
// the physics has not seen it touch yet (organ.h).
#include "organ_collision.h"

#include "organ.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ORGANS_MAX 4

typedef struct organ_surface {
  tx_port x, tri;          // ORGAN.x, ORGAN.tri
  uint64_t x_seq, tri_seq; // the publishes taken
  tx_tri_bvh bvh;          // over the surface's triangles
  float* xs;               // (xcap x 3) m, the vertices the tree was fitted to, copied from the publish
  uint32_t xcap;           // vertices the copy holds
  bool ready;              // a good publish is in xs and bvh
  tx_organ_side side;      // the tip's contact with this organ
} organ_surface;

typedef struct organ_ctl {
  tx_organ_tip_def def;
  double k_default;  // N/m, penalty stiffness until organs.contact gives one
  double k_last;     // N/m, the last tangent stiffness organs.contact gave while touching (0: none yet)
  int n;             // organs
  organ_surface org[ORGANS_MAX];
  tx_organ_touch touch[ORGANS_MAX];
  tx_port pose, contact, model;
  bool has_contact;
  double last_c[3], prev_c[3]; // m: the last finite pose; the pose of the last pose publish
  uint64_t pose_seq;
  double pose_step;            // m, how far the pose moved between its last two publishes
  tx_warning w_pose, w_organ, w_mesh;
  tx_result r_peak, r_onsets, r_gave, r_inside, r_penalty, r_reaction, r_rebuilds, r_refits;
  double peak;
  uint64_t onsets, gave_way, inside, penalty, reaction, rebuilds, refits;
  bool was_inside;
} organ_ctl;

static const tx_param_def params[] = {
    {"organs", TX_PARAM_STRS, NULL, 0, ORGANS_MAX, 0, NULL, "the soft organs read: ORGAN.x, ORGAN.tri (none given: liver and stomach)"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the tool pose read (f64 1 x 7): the tip sphere's centre"},
    {"contact", TX_PARAM_STR, NULL, 0, 0, 0, "organs.contact", "the organs' reaction on the tool read (f64 1 x 13); \"\": the penalty alone"},
    {"force_model", TX_PARAM_STR, NULL, 0, 0, 0, "tool0.force_model", "the force model written (f64 1 x 15)"},
    {"radius_m", TX_PARAM_NUM, "m", 1e-4, 0.02, 2.5e-3, NULL, "the tool tip sphere's radius (a 5 mm laparoscopic instrument)"},
    {"hold_m", TX_PARAM_NUM, "m", 0, 0.02, 2e-3, NULL, "a contact lasts while the tip is within radius + hold of the surface"},
    {"depth_max_m", TX_PARAM_NUM, "m", 1e-3, 0.1, 0.02, NULL, "deepest penetration a contact follows; past it the organ gave way"},
    {"stiffness", TX_PARAM_NUM, "N/m", 0, 1e5, 100, NULL, "penalty stiffness before the contact component has given its tangent stiffness"},
};

static int configure(tx_setup* s, void** self) {
  organ_ctl* h = calloc(1, sizeof *h);
  if (!h) return -1;
  *self = h;
  h->def.radius = tx_table_num(s, "radius_m");
  h->def.hold = tx_table_num(s, "hold_m");
  h->def.depth_max = tx_table_num(s, "depth_max_m");
  h->k_default = tx_table_num(s, "stiffness");
  if (h->def.depth_max <= h->def.radius)
    return tx_setup_fail(s, "depth_max_m", "%g m must be more than radius_m (%g m)", h->def.depth_max, h->def.radius);
  if (tx_organ_tip_def_check(&h->def)) return tx_setup_fail(s, NULL, "%s", tx_error());
  const char* names[ORGANS_MAX];
  h->n = tx_table_strs(s, "organs", names, ORGANS_MAX);
  if (h->n == 0) {
    names[0] = "liver", names[1] = "stomach";
    h->n = 2;
  }
  for (int i = 0; i < h->n; i++) {
    char x[TX_NAME_MAX], tri[TX_NAME_MAX];
    if (!names[i] || !*names[i]) return tx_setup_fail(s, "organs", "entry %d is empty", i);
    for (int j = 0; j < i; j++)
      if (strcmp(names[i], names[j]) == 0) return tx_setup_fail(s, "organs", "'%s' is named twice", names[i]);
    if (snprintf(x, sizeof x, "%s.x", names[i]) >= TX_NAME_MAX || snprintf(tri, sizeof tri, "%s.tri", names[i]) >= TX_NAME_MAX)
      return tx_setup_fail(s, "organs", "'%s' is too long", names[i]);
    h->org[i].x = TX_READ_OF(s, x, tx_vertex);
    h->org[i].tri = TX_READ_OF(s, tri, tx_triangle);
  }
  const char* pose = tx_table_str(s, "pose");
  const char* contact = tx_table_str(s, "contact");
  const char* model = tx_table_str(s, "force_model");
  if (!pose || !contact || !model) return -1;
  h->pose = TX_READ_OF(s, pose, tx_pose);
  h->has_contact = *contact != 0;
  if (h->has_contact) h->contact = TX_READ_OF(s, contact, tx_skin_contact);
  h->model = tx_setup_write(s, &TX_COMPONENT_OF(model, tx_force_model, 1));
  h->w_pose = tx_setup_warning(s, "pose_not_finite");
  h->w_organ = tx_setup_warning(s, "organ_not_finite");
  h->w_mesh = tx_setup_warning(s, "organ_mesh_rejected");
  h->r_peak = tx_setup_result(s, "peak_force_N");
  h->r_onsets = tx_setup_result(s, "contacts");
  h->r_gave = tx_setup_result(s, "gave_way");
  h->r_inside = tx_setup_result(s, "inside_unentered");
  h->r_penalty = tx_setup_result(s, "penalty_steps");
  h->r_reaction = tx_setup_result(s, "reaction_steps");
  h->r_rebuilds = tx_setup_result(s, "bvh_rebuilds");
  h->r_refits = tx_setup_result(s, "bvh_refits");
  return 0;
}

static int init(tx_ctx* c, void* self) {
  organ_ctl* h = self;
  // before an organ's first publish a read holds its full capacity: size everything by it
  for (int i = 0; i < h->n; i++) {
    organ_surface* o = &h->org[i];
    tx_snapshot tri = tx_read(c, o->tri), x = tx_read(c, o->x);
    o->xcap = x.rows > 0 ? x.rows : 1;
    if (tx_tri_bvh_init(&o->bvh, tri.rows > 0 ? tri.rows : 1)) return -1;
    if (!(o->xs = calloc(3 * (size_t)o->xcap, sizeof(float)))) return -1;
    tx_organ_side_reset(&o->side);
  }
  return 0;
}

static bool all_finite(const float* v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

// a new publish of one organ: copy it, then refit the tree (the same triangles) or rebuild it
static void take_surface(tx_ctx* c, organ_ctl* h, organ_surface* o, tx_snapshot x, tx_snapshot tri) {
  o->ready = false;
  if (x.rows > o->xcap) {
    tx_warn(c, h->w_mesh);
    return;
  }
  memcpy(o->xs, x.data, 3 * (size_t)x.rows * sizeof(float));
  if (!all_finite(o->xs, 3 * (size_t)x.rows)) { // no force from a broken surface, until a good one
    tx_warn(c, h->w_organ);
    return;
  }
  if (x.rows == o->bvh.nx && tx_tri_bvh_same(&o->bvh, tri.data, tri.rows)) {
    tx_tri_bvh_refit(&o->bvh, o->xs);
    h->refits++;
  } else if (tx_tri_bvh_build(&o->bvh, o->xs, x.rows, tri.data, tri.rows)) {
    tx_warn(c, h->w_mesh); // more triangles than at start, or an index outside the vertices
    o->bvh.nnodes = 0;     // (and the next publish is not taken for a refit of it)
    return;
  } else {
    h->rebuilds++;
  }
  o->ready = true;
}

static void step(tx_ctx* c, void* self) {
  organ_ctl* h = self;
  tx_snapshot ps = tx_read(c, h->pose);
  const tx_pose* pose = ps.data;
  double centre[3] = {pose->pos[0], pose->pos[1], pose->pos[2]};
  if (!(isfinite(centre[0]) && isfinite(centre[1]) && isfinite(centre[2]))) {
    tx_warn(c, h->w_pose);
    memcpy(centre, h->last_c, sizeof centre); // hold the last good pose
  }
  memcpy(h->last_c, centre, sizeof centre);
  if (ps.seq != h->pose_seq) { // the hand's move over one device tick
    double d[3] = {centre[0] - h->prev_c[0], centre[1] - h->prev_c[1], centre[2] - h->prev_c[2]};
    h->pose_step = h->pose_seq ? sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) : 0;
    h->pose_seq = ps.seq;
    memcpy(h->prev_c, centre, sizeof centre);
  }

  bool inside = false;
  for (int i = 0; i < h->n; i++) {
    organ_surface* o = &h->org[i];
    tx_snapshot x = tx_read(c, o->x), tri = tx_read(c, o->tri);
    if (x.seq != 0 && (x.seq != o->x_seq || tri.seq != o->tri_seq)) {
      o->x_seq = x.seq;
      o->tri_seq = tri.seq;
      take_surface(c, h, o, x, tri);
    }
    if (o->ready) {
      tx_organ_tip(&o->side, &h->def, &o->bvh, o->xs, centre, &h->touch[i]);
    } else {
      tx_organ_side_reset(&o->side);
      memset(&h->touch[i], 0, sizeof h->touch[i]);
    }
    if (h->touch[i].onset) h->onsets++;
    if (h->touch[i].gave_way) h->gave_way++;
    inside |= h->touch[i].inside;
  }
  if (inside && !h->was_inside) h->inside++;
  h->was_inside = inside;

  const tx_skin_contact* r = NULL;
  if (h->has_contact) {
    r = tx_read(c, h->contact).data;
    if (r->touching > 0 && isfinite(r->k) && r->k > 0) h->k_last = r->k;
  }
  tx_organ_force_out f;
  tx_organ_force(h->touch, h->n, r, h->k_last > 0 ? h->k_last : h->k_default, h->def.depth_max, centre, &f);
  if (f.kind == TX_ORGAN_FORCE_PENALTY) h->penalty++;
  if (f.kind == TX_ORGAN_FORCE_REACTION) h->reaction++;

  // the local model at the tip's centre
  tx_force_model* m = tx_write(c, h->model);
  memset(m, 0, sizeof *m);
  memcpy(m->x0, centre, sizeof m->x0);
  memcpy(m->f0, f.f, sizeof m->f0);
  // a hand that moves more than the tip's radius in one device tick would carry the linear
  // model far past the surfaces this query saw: hold F0 until the next query
  if (h->pose_step <= h->def.radius) memcpy(m->k, f.k, sizeof m->k);
  double fn = sqrt(f.f[0] * f.f[0] + f.f[1] * f.f[1] + f.f[2] * f.f[2]);
  if (fn > h->peak) h->peak = fn;
}

static void finish(tx_ctx* c, void* self) {
  organ_ctl* h = self;
  tx_set_result(c, h->r_peak, h->peak);
  tx_set_result(c, h->r_onsets, (double)h->onsets);
  tx_set_result(c, h->r_gave, (double)h->gave_way);
  tx_set_result(c, h->r_inside, (double)h->inside);
  tx_set_result(c, h->r_penalty, (double)h->penalty);
  tx_set_result(c, h->r_reaction, (double)h->reaction);
  tx_set_result(c, h->r_rebuilds, (double)h->rebuilds);
  tx_set_result(c, h->r_refits, (double)h->refits);
}

static void fini(void* self) {
  organ_ctl* h = self;
  if (!h) return;
  for (int i = 0; i < h->n; i++) {
    tx_tri_bvh_free(&h->org[i].bvh);
    free(h->org[i].xs);
  }
  free(h);
}

const tx_controller_class tx_collision_organ = {
    .type = "collision.organ",
    .summary = "the tool tip sphere against the soft organs' surfaces (one BVH each, refitted per publish): local model F0, x0, K",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
