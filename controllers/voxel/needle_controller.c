// voxel.needle: the voxel block and the needle, one frame per step.
//
// Each step reads the device pose, moves the needle there, steps the block
// with the needle's contacts inside its substeps, guards the result, and
// publishes the force model for the haptics controller: F0 = eq. 9's force
// at the tip, K = -k a a^T with k the springs the tip holds (capped). The
// drawable components (spheres, damage, the needle's segment) go out every
// draw_every steps. With a record folder, the run's haptic recording is
// written in finish as needle-recording.csv (docs/needle.md), with the
// events contact, puncture, retract and exit.
#include "needle_controller.h"

#include <tactus/components.h>

#include "guard.h"
#include "needle.h"
#include "recording.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W_RECOVERED, W_FAULTS, W_OVERFLOW, W_RECORD_FULL, W_COUNT };

typedef struct needle_ctl {
  tx_voxel_tissue tissue;
  tx_voxel_needle needle;
  tx_voxel_guard guard;
  bool ready;               // tissue, needle and guard initialised
  double max_stiffness;     // N/m, cap on K
  int draw_every;           // steps between publishes of the drawables
  uint64_t steps;
  tx_port pose, model, spheres, damage, segment, force;
  tx_warning warn[W_COUNT];
  tx_result peak_result, cuts_result, energy_result;
  uint64_t faults_seen, overflow_seen;
  double peak;              // N, largest force magnitude
  double inward;            // m/s, the needle's speed along its axis in the last frame (> 0: going in)
  tx_recording rec;         // rows kept for finish, when recording
  bool record;
  double record_max_s;
} needle_ctl;

// tissue and needle defaults are tx_voxel_tissue_def_default()'s and
// tx_voxel_needle_def_default()'s (tests/controllers/test_param_tables.c checks)
static const tx_param_def params[] = {
    {"count_x", TX_PARAM_INT, "1", 1, 1000, 10, NULL, "voxels along x (at most 10^7 in all)"},
    {"count_y", TX_PARAM_INT, "1", 1, 1000, 10, NULL, "voxels along y"},
    {"count_z", TX_PARAM_INT, "1", 1, 1000, 10, NULL, "voxels along z"},
    {"block_x_m", TX_PARAM_NUM, "m", 1e-5, 1, 5e-3, NULL, "the block's edge along x, centred on x = 0"},
    {"block_y_m", TX_PARAM_NUM, "m", 1e-5, 1, 5e-3, NULL, "the block's edge along y, below top_y_m"},
    {"block_z_m", TX_PARAM_NUM, "m", 1e-5, 1, 5e-3, NULL, "the block's edge along z, centred on z = 0"},
    {"top_y_m", TX_PARAM_NUM, "m", -10, 10, 0, NULL, "the y of the block's top face"},
    {"mass_kg", TX_PARAM_NUM, "kg", 1e-15, 1, 1.25e-7, NULL, "each voxel's mass"},
    {"elasticity", TX_PARAM_NUM, "1", 0, 1, 0.5, NULL, "e of eq. 5"},
    {"spring_n_m", TX_PARAM_NUM, "N/m", 0, 1e9, 0.05, NULL, "each voxel's spring to its rest position"},
    {"damper_n_s_m", TX_PARAM_NUM, "N s/m", 0, 1e9, 1e-4, NULL, "each voxel's damper to rest"},
    {"radius_m", TX_PARAM_NUM, "m", 1e-7, 1, 0.25e-3, NULL, "each voxel's rest radius"},
    {"damage_shrink", TX_PARAM_NUM, "1", 0, 0.99, 0.5, NULL, "the part of the radius lost at full damage"},
    {"recovery_s", TX_PARAM_NUM, "s", 1e-3, 1e6, 0.5, NULL, "time for damage to heal"},
    {"skin_m", TX_PARAM_NUM, "m", 1e-7, 1, 0.1e-3, NULL, "the neighbour lists' skin"},
    {"gauge", TX_PARAM_INT, "1", 10, 34, 18, NULL, "the needle's gauge"},
    {"tip", TX_PARAM_STR, NULL, 0, 0, 0, "conical", "the tip: conical, bevel or blunt"},
    {"tip_angle_deg", TX_PARAM_NUM, "deg", 1, 89, 15, NULL, "the tip's half angle"},
    {"length_m", TX_PARAM_NUM, "m", 1e-3, 1, 0.04, NULL, "the needle's length"},
    {"friction", TX_PARAM_NUM, "1", 0, 10, 0.3, NULL, "the needle's friction coefficient"},
    {"rupture_force_n", TX_PARAM_NUM, "N", 1e-9, 1e4, 0.2, NULL, "load on the tip that punctures the surface"},
    {"cutting_force_n", TX_PARAM_NUM, "N", 1e-9, 1e4, 0.1, NULL, "load that cuts on inside the tissue"},
    {"load_time_s", TX_PARAM_NUM, "s", 1e-5, 1, 0.005, NULL, "time over which the tip's load is averaged"},
    {"max_stiffness_n_m", TX_PARAM_NUM, "N/m", 0, 1e5, 500, NULL, "cap on the published K"},
    {"draw_every", TX_PARAM_INT, "1", 1, 100000, 16, NULL, "steps between publishes of the drawables"},
    {"checkpoint_steps", TX_PARAM_INT, "1", 1, 100000, 100, NULL, "steps between the guard's checkpoints"},
    {"record", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "keep OUT/needle-recording.csv"},
    {"record_max_s", TX_PARAM_NUM, "s", 1, 3600, 120, NULL, "the longest recording kept"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the tool pose read (f64 1 x 7)"},
    {"force_model", TX_PARAM_STR, NULL, 0, 0, 0, "tool0.force_model", "the force model written (f64 1 x 15)"},
};

static int configure(tx_setup* s, void** self) {
  needle_ctl* c = calloc(1, sizeof *c);
  if (!c) return -1;
  *self = c;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  static const char* const size_keys[3] = {"block_x_m", "block_y_m", "block_z_m"};
  static const char* const count_keys[3] = {"count_x", "count_y", "count_z"};
  for (int a = 0; a < 3; a++) {
    d.block_size[a] = tx_table_num(s, size_keys[a]);
    d.count[a] = (int)tx_table_int(s, count_keys[a]);
  }
  // the block's top face at y = top_y_m, centred on x = z = 0
  double top = tx_table_num(s, "top_y_m");
  d.origin[0] = -0.5 * d.block_size[0];
  d.origin[1] = top - d.block_size[1];
  d.origin[2] = -0.5 * d.block_size[2];
  d.mass = tx_table_num(s, "mass_kg");
  d.elasticity = tx_table_num(s, "elasticity");
  d.spring = tx_table_num(s, "spring_n_m");
  d.damper = tx_table_num(s, "damper_n_s_m");
  d.radius = tx_table_num(s, "radius_m");
  d.damage_shrink = tx_table_num(s, "damage_shrink");
  d.recovery_time = tx_table_num(s, "recovery_s");
  d.skin = tx_table_num(s, "skin_m");
  tx_voxel_needle_def nd = tx_voxel_needle_def_default();
  nd.gauge = (int)tx_table_int(s, "gauge");
  const char* tip = tx_table_str(s, "tip");
  nd.tip_angle_deg = tx_table_num(s, "tip_angle_deg");
  nd.length = tx_table_num(s, "length_m");
  nd.friction = tx_table_num(s, "friction");
  nd.rupture_force = tx_table_num(s, "rupture_force_n");
  nd.cutting_force = tx_table_num(s, "cutting_force_n");
  nd.load_time = tx_table_num(s, "load_time_s");
  c->max_stiffness = tx_table_num(s, "max_stiffness_n_m");
  c->draw_every = (int)tx_table_int(s, "draw_every");
  int every = (int)tx_table_int(s, "checkpoint_steps");
  c->record = tx_table_bool(s, "record");
  c->record_max_s = tx_table_num(s, "record_max_s");
  const char* pose = tx_table_str(s, "pose");
  const char* model = tx_table_str(s, "force_model");
  if (!tip || !pose || !model) return -1;
  if (!tx_needle_tip_parse(tip, &nd.tip))
    return tx_setup_fail(s, "tip", "expected \"conical\", \"bevel\" or \"blunt\", got \"%s\"", tip);
  if (tx_voxel_tissue_def_check(&d) || tx_voxel_needle_def_check(&nd)) return tx_setup_fail(s, NULL, "%s", tx_error());
  if (!tx_voxel_tissue_init(&c->tissue, &d)) return tx_setup_fail(s, NULL, "%s", tx_error());
  if (!tx_voxel_needle_init(&c->needle, &nd, &c->tissue) || !tx_voxel_guard_init(&c->guard, &c->tissue, every)) {
    c->ready = true; // fini frees whatever was made
    return tx_setup_fail(s, NULL, "%s", tx_error());
  }
  c->ready = true;
  const uint32_t n = (uint32_t)c->tissue.n;
  c->pose = TX_READ_OF(s, pose, tx_pose);
  c->model = tx_setup_write(s, &TX_COMPONENT_OF(model, tx_force_model, 1));
  c->spheres = tx_setup_write(s, &TX_COMPONENT_OF("tissue.spheres", tx_sphere, n));
  c->damage = tx_setup_write(s, &TX_COMPONENT_OF("tissue.damage", tx_damage, n));
  c->segment = tx_setup_write(s, &TX_COMPONENT_OF("needle.segments", tx_segment, 1));
  c->force = tx_setup_write(s, &TX_COMPONENT_OF("needle.force", tx_needle_force, 1)); // eq. 9 apart
  static const char* const keys[W_COUNT] = {"recovered", "voxel_faults", "neighbour_overflow", "record_full"};
  for (int w = 0; w < W_COUNT; w++) c->warn[w] = tx_setup_warning(s, keys[w]);
  c->peak_result = tx_setup_result(s, "peak_force_n");
  c->cuts_result = tx_setup_result(s, "voxels_cut");
  c->energy_result = tx_setup_result(s, "max_energy_j");
  return 0;
}

static void publish_drawables(tx_ctx* ctx, needle_ctl* c) {
  const tx_voxel_tissue* t = &c->tissue;
  tx_sphere* sp = tx_write(ctx, c->spheres);
  tx_damage* dm = tx_write(ctx, c->damage);
  for (int i = 0; i < t->n; i++) {
    for (int a = 0; a < 3; a++) sp[i].c[a] = (float)t->pos[3 * i + a];
    sp[i].r = (float)t->radius[i];
    dm[i].d = (float)t->damage[i];
  }
  const tx_voxel_needle* nd = &c->needle;
  tx_segment* seg = tx_write(ctx, c->segment);
  for (int a = 0; a < 3; a++) {
    seg->a[a] = (float)(nd->tip1[a] - nd->def.length * nd->dir[a]);
    seg->b[a] = (float)nd->tip1[a];
  }
  seg->r = (float)nd->radius;
}

static void publish_forces(tx_ctx* ctx, needle_ctl* c) {
  const tx_voxel_needle* nd = &c->needle;
  tx_force_model* m = tx_write(ctx, c->model);
  memcpy(m->f0, nd->force, sizeof m->f0);
  memcpy(m->x0, nd->tip1, sizeof m->x0);
  double k = fmin(nd->k_axial, c->max_stiffness);
  for (int r = 0; r < 3; r++)
    for (int col = 0; col < 3; col++) m->k[3 * r + col] = -k * nd->dir[r] * nd->dir[col];
  tx_needle_force* f = tx_write(ctx, c->force);
  memcpy(f->total, nd->force, sizeof f->total);
  memcpy(f->stiffness, nd->stiffness, sizeof f->stiffness);
  memcpy(f->friction, nd->friction, sizeof f->friction);
  memcpy(f->cutting, nd->cutting, sizeof f->cutting);
  f->depth = tx_voxel_needle_depth(nd, &c->tissue);
}

static int init(tx_ctx* ctx, void* self) {
  needle_ctl* c = self;
  // the needle is placed by the first step's pose (haptics publishes it at time 0)
  tx_snapshot pose = tx_read(ctx, c->pose);
  if (pose.seq) memcpy(c->needle.tip1, ((const tx_pose*)pose.data)->pos, sizeof c->needle.tip1);
  publish_forces(ctx, c);
  publish_drawables(ctx, c);
  if (c->record && tx_record_dir(ctx)) {
    size_t rows = (size_t)ceil(c->record_max_s * tx_rate(ctx)) + 1;
    if (!tx_recording_alloc(&c->rec, rows)) {
      tx_stop_run(ctx, "%s", tx_error()); // the run fails with this reason
      return -1;
    }
  }
  return 0;
}

static void step(tx_ctx* ctx, void* self) {
  needle_ctl* c = self;
  const double dt = 1.0 / tx_rate(ctx);
  const tx_pose* pose = tx_read(ctx, c->pose).data;
  bool was_punctured = c->needle.punctured;
  int was_contacts = c->needle.contacts;
  double was_in = c->inward; // m/s, the needle's speed along its axis over the last frame
  if (!tx_voxel_needle_step(&c->needle, &c->tissue, pose->pos, pose->quat, dt)) {
    tx_warn(ctx, c->warn[W_RECOVERED]); // a non-finite pose: hold the last force model
    return;
  }
  if (tx_voxel_guard_check(&c->guard, &c->tissue, &c->needle)) tx_warn(ctx, c->warn[W_RECOVERED]);
  if (c->tissue.faults > c->faults_seen) c->faults_seen = c->tissue.faults, tx_warn(ctx, c->warn[W_FAULTS]);
  if (c->tissue.overflow > c->overflow_seen) c->overflow_seen = c->tissue.overflow, tx_warn(ctx, c->warn[W_OVERFLOW]);
  const double* f = c->needle.force;
  c->peak = fmax(c->peak, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  publish_forces(ctx, c);
  if (++c->steps % (uint64_t)c->draw_every == 0) publish_drawables(ctx, c);
  const tx_voxel_needle* nd = &c->needle;
  c->inward = nd->vel[0] * nd->dir[0] + nd->vel[1] * nd->dir[1] + nd->vel[2] * nd->dir[2];
  if (c->rec.cap) {
    tx_needle_event ev = TX_EVENT_NONE;
    if (!was_contacts && nd->contacts) ev = TX_EVENT_CONTACT;
    else if (!was_punctured && nd->punctured) ev = TX_EVENT_PUNCTURE;
    else if (was_contacts && !nd->contacts) ev = TX_EVENT_EXIT;
    else if (nd->contacts && was_in > 0 && c->inward < 0) ev = TX_EVENT_RETRACT;
    tx_recording_row row = {(double)tx_sim_ns(ctx) * 1e-9, tx_voxel_needle_depth(&c->needle, &c->tissue),
                            {f[0], f[1], f[2]}, ev};
    if (!tx_recording_push(&c->rec, &row)) tx_warn(ctx, c->warn[W_RECORD_FULL]);
  }
}

static void finish(tx_ctx* ctx, void* self) {
  needle_ctl* c = self;
  tx_set_result(ctx, c->peak_result, c->peak);
  tx_set_result(ctx, c->cuts_result, (double)c->needle.cuts);
  tx_set_result(ctx, c->energy_result, c->guard.energy_max);
  if (c->rec.cap && tx_record_dir(ctx)) {
    char path[4200];
    snprintf(path, sizeof path, "%s/needle-recording.csv", tx_record_dir(ctx));
    // a recording that cannot be written ends the run in a fault (exit 1, named)
    if (!tx_recording_write(&c->rec, path)) tx_stop_run(ctx, "%s", tx_error());
  }
}

static void fini(void* self) {
  needle_ctl* c = self;
  if (c->ready) {
    tx_voxel_guard_fini(&c->guard);
    tx_voxel_needle_fini(&c->needle);
    tx_voxel_tissue_fini(&c->tissue);
  }
  tx_recording_free(&c->rec);
  free(c);
}

const tx_controller_class tx_voxel_needle_controller = {
    .type = "voxel.needle",
    .summary = "spherical voxel tissue and a straight needle at the haptic rate: force model, spheres, damage",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
