// haptics: one device, rendered every tick from the published force model.
//
// Each tick: read the device; render F = F0 + K (x - x0) from the latest
// force model (or hold F0, the papers' sample-and-hold); then the force path
// that `tactus study haptic-stability` measures (tx_haptic_tick): observe the
// energy of the force sent last tick, let the passivity controller add
// damping if asked, pass the safety chain; write the force.
// It publishes what the rest of the model needs from the device, and counts
// every safety event as a warning of the run.
#include "haptics_controller.h"

#include "device.h"
#include "passivity.h"
#include "recorder.h"
#include "render.h"
#include "safety.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W_NON_FINITE, W_CLAMPED, W_RATE, W_WATCHDOG, W_WORKSPACE, W_SILENT, W_DROPPED, W_COUNT };

typedef struct haptics {
  tx_device_handle device;
  tx_render_mode mode;
  tx_safety_limits limits;       // as configured; the path keeps its copy
  tx_haptic_path path;           // passivity and safety: the force path the stability study measures
  tx_port model;                 // the force model read, 0 for none
  tx_port tool;                  // virtual coupling: the simulated tool's pose, 0 for none
  tx_port grip;                  // deviceN.grip: the gripper angle and buttons
  tx_port input;                 // the device's input in the model (the mouse's window.pointer), 0 for none
  double coupling_k, coupling_b; // N/m, N s/m
  tx_port pose, velocity, force, energy;
  tx_warning warn[W_COUNT];
  tx_result energy_result, dissipated_result, min_energy_result, reference_result;
  tx_device_state state;         // last sample
  double silent_s;               // since the last sample
  int hand;
  bool record;                   // when the run keeps recordings
  tx_recorder* recorder;
  bool record_failed;            // the recording broke (a full disk): the run was told to stop
  tx_record rec;                 // this tick's record, filled as the tick goes
} haptics;

static double lowered(tx_setup* s, const char* key, double device_value) {
  double v = tx_table_num(s, key); // NaN: not given
  if (isnan(v)) return device_value;
  if (v > device_value)
    return tx_setup_fail(s, key, "%g is above the device's %g: a limit can only be lowered", v, device_value), device_value;
  return v;
}

#define DEVICE_S "the device's" // the safety limits default to the device's own
static const tx_param_def params[] = {
    {"device", TX_PARAM_STR, NULL, 0, 0, 0, "scripted:pierce-down", "the device spec (docs/haptics.md#devices); --device sets it"},
    {"hand", TX_PARAM_INT, "1", 0, 1, 0, NULL, "0 or 1: names its components device0.* or device1.*"},
    {"record", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "keep OUT/deviceN.bin and OUT/deviceN.csv"},
    {"mode", TX_PARAM_STR, NULL, 0, 0, 0, "local", "local: F = F0 + K (x - x0) every tick; sample_hold: F0 until the next model"},
    {"force_model", TX_PARAM_STR, NULL, 0, 0, 0, "", "the force model rendered (f64 1 x 15, \"N, m, N/m\"); \"\": none"},
    {"passivity_control", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "add damping whenever the observed energy would go negative"},
    {"passivity_reference", TX_PARAM_STR, NULL, 0, 0, 0, "spring", "what that energy is measured against: spring (the port's energy less the force model's spring store, plus the device's own damping) or port (docs/haptics.md#passivity)"},
    {"coupling_tool", TX_PARAM_STR, NULL, 0, 0, 0, "", "instead of a force model, a simulated tool's pose (f64 1 x 7) to couple to"},
    {"coupling_stiffness", TX_PARAM_NUM, "N/m", 0, 1e5, 200, NULL, "the virtual coupling's spring"},
    {"coupling_damping", TX_PARAM_NUM, "N s/m", 0, 1e3, 1, NULL, "the virtual coupling's damper"},
    {"max_force", TX_PARAM_NUM, "N", 1e-9, 1e6, 0, DEVICE_S, "largest force sent; can only lower the device's"},
    {"max_force_rate", TX_PARAM_NUM, "N/s", 1e-9, 1e12, 0, DEVICE_S, "largest change of force per second; can only lower the device's"},
    {"model_timeout_s", TX_PARAM_NUM, "s", 1e-9, 3600, 0, DEVICE_S, "a force model older than this ramps the force down"},
    {"device_timeout_s", TX_PARAM_NUM, "s", 1e-9, 3600, 0, DEVICE_S, "a device silent this long is lost"},
    {"ramp_s", TX_PARAM_NUM, "s", 1e-9, 3600, 0, DEVICE_S, "time to ramp the force up at start and down on a fault"},
};

static int configure(tx_setup* s, void** self) {
  haptics* h = calloc(1, sizeof *h);
  if (!h) return -1;
  *self = h;
  const double period = 1.0 / tx_setup_rate(s);
  if (tx_setup_rate(s) > 10000) return tx_setup_fail(s, NULL, "haptics runs at most at 10000 Hz, not %g", tx_setup_rate(s));
  const char* spec = tx_table_str(s, "device");
  int hand = h->hand = (int)tx_table_int(s, "hand");
  h->record = tx_table_bool(s, "record");
  const char* mode = tx_table_str(s, "mode");
  const char* model = tx_table_str(s, "force_model");
  bool control = tx_table_bool(s, "passivity_control");
  const char* reference = tx_table_str(s, "passivity_reference");
  const char* tool = tx_table_str(s, "coupling_tool");
  h->coupling_k = tx_table_num(s, "coupling_stiffness");
  h->coupling_b = tx_table_num(s, "coupling_damping");
  if (!tool) return -1;
  if (*tool && *model) return tx_setup_fail(s, "coupling_tool", "renders either a force model or a coupling, not both");
  if (!spec || !mode || !model || !reference) return -1; // a parameter error is already recorded
  // spring by default: through this very path the study finds it as good as
  // port at 0.25 ms and better at 1 and 4 ms, where port is worse than none
  tx_passivity_ref ref = TX_PASSIVITY_REF_SPRING;
  if (strcmp(reference, "port") == 0) ref = TX_PASSIVITY_REF_PORT;
  else if (strcmp(reference, "spring") != 0)
    return tx_setup_fail(s, "passivity_reference", "expected \"port\" or \"spring\", got \"%s\"", reference);
  if (strcmp(mode, "local") == 0) h->mode = TX_RENDER_LOCAL_MODEL;
  else if (strcmp(mode, "sample_hold") == 0) h->mode = TX_RENDER_SAMPLE_HOLD;
  else return tx_setup_fail(s, "mode", "expected \"local\" or \"sample_hold\", got \"%s\"", mode);

  if (tx_device_open(spec, period, &h->device)) return tx_setup_fail(s, "device", "%s", tx_error());
  tx_device_info info;
  h->device.backend->info(h->device.device, &info);
  tx_safety_limits d = tx_safety_limits_from_device(&info);
  h->limits = d;
  h->limits.max_force = lowered(s, "max_force", d.max_force);
  h->limits.max_force_rate = lowered(s, "max_force_rate", d.max_force_rate);
  h->limits.model_timeout_s = lowered(s, "model_timeout_s", d.model_timeout_s);
  h->limits.device_timeout_s = lowered(s, "device_timeout_s", d.device_timeout_s);
  h->limits.ramp_s = lowered(s, "ramp_s", d.ramp_s);
  if (tx_safety_limits_check(&h->limits)) return tx_setup_fail(s, NULL, "safety limits: %s", tx_error());
  tx_haptic_path_init(&h->path, &h->limits, control, ref, info.damping);

  if (h->device.backend->input) h->input = TX_READ_EXPECT(s, h->device.backend->input, tx_pointer);
  if (*model) h->model = TX_READ_EXPECT(s, model, tx_force_model);
  if (*tool) h->tool = TX_READ_OF(s, tool, tx_pose);
  char name[TX_NAME_MAX];
  snprintf(name, sizeof name, "device%d.pose", hand);
  h->pose = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_pose, 1));
  snprintf(name, sizeof name, "device%d.velocity", hand);
  h->velocity = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_velocity, 1));
  snprintf(name, sizeof name, "device%d.force", hand);
  h->force = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_force, 1)); // what was sent
  snprintf(name, sizeof name, "device%d.grip", hand);
  h->grip = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_device_grip, 1));
  snprintf(name, sizeof name, "device%d.energy", hand);
  h->energy = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_device_energy, 1));
  static const char* const keys[W_COUNT] = {"force_non_finite", "force_clamped", "force_rate_limited",
                                            "watchdog", "outside_workspace", "device_silent",
                                            "record_dropped"};
  for (int w = 0; w < W_COUNT; w++) h->warn[w] = tx_setup_warning(s, keys[w]);
  h->energy_result = tx_setup_result(s, "passivity_energy_j");
  h->min_energy_result = tx_setup_result(s, "passivity_min_energy_j");
  h->dissipated_result = tx_setup_result(s, "passivity_dissipated_j");
  h->reference_result = tx_setup_result(s, "passivity_reference_energy_j");
  return 0;
}

// count the safety events of this tick as run warnings
static void warn_new(tx_ctx* c, haptics* h, const tx_safety_counts* before) {
  const tx_safety_counts* now = &h->path.safety.counts;
  if (now->non_finite > before->non_finite) tx_warn(c, h->warn[W_NON_FINITE]);
  if (now->clamped > before->clamped) tx_warn(c, h->warn[W_CLAMPED]);
  if (now->rate_limited > before->rate_limited) tx_warn(c, h->warn[W_RATE]);
  if (now->watchdog > before->watchdog) tx_warn(c, h->warn[W_WATCHDOG]);
  if (now->workspace > before->workspace) tx_warn(c, h->warn[W_WORKSPACE]);
}

// a device whose input is in the model gets this tick's row before it is read
static void feed(tx_ctx* c, haptics* h) {
  if (!h->input.id) return;
  tx_snapshot in = tx_read(c, h->input);
  h->device.backend->feed(h->device.device, in.seq ? in.data : NULL);
}

// what the rest of the model sees of the device
static void publish(tx_ctx* c, haptics* h, const double force[3]) {
  tx_pose* pose = tx_write(c, h->pose);
  memcpy(pose->pos, h->state.pos, sizeof pose->pos);
  memcpy(pose->quat, h->state.quat, sizeof pose->quat);
  tx_velocity* vel = tx_write(c, h->velocity);
  memcpy(vel->v, h->state.vel, sizeof vel->v);
  tx_force* sent = tx_write(c, h->force);
  memcpy(sent->f, force, sizeof sent->f);
  tx_device_grip* g = tx_write(c, h->grip);
  g->grip = h->state.grip;
  g->buttons = h->state.buttons;
  tx_device_energy* e = tx_write(c, h->energy);
  e->observed = h->path.passivity.energy;
  e->dissipated = h->path.passivity.dissipated;
}

// the device's first sample is published at time 0, so that the controllers
// that run at time 0 (collision, physics) see where the tool really is
static int init(tx_ctx* c, void* self) {
  haptics* h = self;
  feed(c, h);
  if (!h->device.backend->read(h->device.device, 0, &h->state)) h->state.quat[0] = 1;
  const double zero[3] = {0, 0, 0};
  publish(c, h, zero);
  if (h->record && tx_record_dir(c)) {
    tx_device_info info;
    h->device.backend->info(h->device.device, &info);
    h->recorder = tx_recorder_start(tx_record_dir(c), h->hand, tx_rate(c), &info);
    if (!h->recorder) {
      tx_stop_run(c, "recording: %s", tx_error()); // the run fails with this reason
      return -1;
    }
  }
  return 0;
}

static void step(tx_ctx* c, void* self) {
  haptics* h = self;
  const double dt = 1.0 / tx_rate(c), t = (double)tx_sim_ns(c) * 1e-9;
  feed(c, h);
  if (h->device.backend->read(h->device.device, t, &h->state)) h->silent_s = 0;
  else h->silent_s += dt, tx_warn(c, h->warn[W_SILENT]);

  double f[3] = {0, 0, 0}, model_age = 0, stored = 0;
  if (h->model.id) {
    tx_snapshot snap = tx_read(c, h->model);
    tx_force_model fm = *(const tx_force_model*)snap.data;
    memcpy(h->rec.force_model, &fm, sizeof h->rec.force_model);
    // seq 0: never published yet (the first tick runs before collision), so
    // there is nothing to render and nothing stale to warn about
    if (snap.seq) {
      tx_render_force(&fm, h->mode, h->state.pos, f);
      // what the rendered spring holds; held forces (sample_hold) follow no spring
      if (h->mode == TX_RENDER_LOCAL_MODEL) stored = tx_spring_energy(fm.k, f);
      model_age = (double)(tx_sim_ns(c) - snap.sim_ns) * 1e-9;
    }
  } else if (h->tool.id) {
    // virtual coupling: a spring-damper pulls the device toward the simulated
    // tool, which the physics moves
    tx_snapshot snap = tx_read(c, h->tool);
    const double still[3] = {0, 0, 0};
    if (snap.seq) {
      tx_render_coupling(h->coupling_k, h->coupling_b, ((const tx_pose*)snap.data)->pos, still, h->state.pos, h->state.vel, f);
      model_age = (double)(tx_sim_ns(c) - snap.sim_ns) * 1e-9;
    }
  }
  // a broken recording stops the run at once; until it ends, the force ramps to zero
  if (h->recorder && !h->record_failed) {
    const char* file;
    int e = tx_recorder_error(h->recorder, &file);
    if (e) {
      tx_stop_run(c, "%s: %s", file, strerror(e));
      h->record_failed = true;
    }
  }
  // the observer, the passivity controller and the safety chain: one call,
  // the same the stability study measures
  tx_haptic_input in = {{f[0], f[1], f[2]}, stored, h->record_failed, model_age, h->silent_s};
  tx_safety_counts before = h->path.safety.counts;
  double out[3];
  tx_haptic_tick(&h->path, dt, &in, h->state.pos, h->state.vel, out);
  warn_new(c, h, &before);
  h->device.backend->write(h->device.device, out);
  publish(c, h, out);
  if (h->recorder) {
    tx_record* r = &h->rec;
    r->t_s = t;
    memcpy(r->pos, h->state.pos, sizeof r->pos);
    memcpy(r->quat, h->state.quat, sizeof r->quat);
    memcpy(r->vel, h->state.vel, sizeof r->vel);
    r->grip = h->state.grip;
    r->buttons = h->state.buttons;
    memcpy(r->force, out, sizeof r->force);
    if (!tx_recorder_push(h->recorder, r)) tx_warn(c, h->warn[W_DROPPED]);
  }
}

// the run is over: the recording is made whole (binary and CSV) before the
// report; one that cannot be is a fault that stops the run (exit 1, named)
static void finish(tx_ctx* c, void* self) {
  haptics* h = self;
  tx_set_result(c, h->energy_result, h->path.passivity.energy);
  tx_set_result(c, h->min_energy_result, h->path.passivity.min_energy);
  tx_set_result(c, h->dissipated_result, h->path.passivity.dissipated);
  tx_set_result(c, h->reference_result, h->path.reference_energy);
  if (tx_recorder_stop(h->recorder) && !h->record_failed) // else the run's stop reason says it
    tx_stop_run(c, "recording: %s", tx_error());
  h->recorder = NULL;
}

static void fini(void* self) {
  haptics* h = self;
  if (!h) return;
  // a run that failed before its first step: its folder is taken back, and the
  // run's own error is the one to report
  tx_recorder_stop(h->recorder);
  tx_device_close(&h->device);
  free(h);
}

const tx_controller_class tx_haptics_controller = {
    .type = "haptics",
    .summary = "renders F = F0 + K(x - x0) (or holds F0) on a device, through passivity and safety limits",
    .configure = configure,
    .init = init,
    .step = step,
    .fini = fini,
    .finish = finish,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
