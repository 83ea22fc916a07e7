// tactus study skin-stability: the skin under stiff and extreme cases, each
// one a lockstep run of physics.skin, collision.hip and haptics on a
// scripted hand, with a guard controller that reads every publish:
//   stiffness x1e-3 to x1e3; physics time steps from 1/20 to 1/1000 s; the
//   HIP teleporting 10 cm in one 1 ms tick, through the skin and while in
//   contact; the HIP at 10 m/s, through the skin and along it; a skin of
//   zero thickness.
// A case passes when the model never held a non-finite value and the device
// force never passed the clamp; it is "stable" when the skin found no fault,
// "recovered" when it found some, counted them as warnings and went back to
// its last good state.
#include "skin_stability.h"
#include "studies.h"

#include "../model/error.h"
#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/report.h"

#include <tactus/components.h>
#include <tactus/config.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// ---------------------------------------------------------------------------
// the guard: reads skin.x, tool0.force_model and device0.force every tick

typedef struct guard {
  tx_port x, model, force;
  uint64_t x_seq;
  long nan_values;
  double max_force, max_model_force;
  tx_result r_nan, r_force, r_model;
} guard;

static int guard_configure(tx_setup* s, void** self) {
  guard* g = calloc(1, sizeof *g);
  if (!g) return -1;
  *self = g;
  g->x = TX_READ_OF(s, "skin.x", tx_vertex);
  g->model = TX_READ_OF(s, "tool0.force_model", tx_force_model);
  g->force = TX_READ_OF(s, "device0.force", tx_force);
  g->r_nan = tx_setup_result(s, "nan_values");
  g->r_force = tx_setup_result(s, "max_device_force_N");
  g->r_model = tx_setup_result(s, "max_model_force_N");
  return 0;
}

static double norm3(const double* v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static void guard_step(tx_ctx* c, void* self) {
  guard* g = self;
  tx_snapshot x = tx_read(c, g->x);
  if (x.seq != g->x_seq) { // a new skin: every coordinate
    g->x_seq = x.seq;
    const tx_vertex* p = x.data;
    for (uint32_t i = 0; i < x.rows; i++)
      for (int a = 0; a < 3; a++) g->nan_values += !isfinite(p[i].x[a]);
  }
  const tx_force_model* m = tx_read(c, g->model).data;
  const double* every = &m->f0[0]; // each of the model's values, whatever it means
  for (size_t i = 0; i < tx_force_model_COLS; i++) g->nan_values += !isfinite(every[i]);
  const tx_force* f = tx_read(c, g->force).data;
  for (int i = 0; i < 3; i++) g->nan_values += !isfinite(f->f[i]);
  if (norm3(f->f) > g->max_force) g->max_force = norm3(f->f);
  if (norm3(m->f0) > g->max_model_force) g->max_model_force = norm3(m->f0);
}

static void guard_finish(tx_ctx* c, void* self) {
  guard* g = self;
  tx_set_result(c, g->r_nan, (double)g->nan_values);
  tx_set_result(c, g->r_force, g->max_force);
  tx_set_result(c, g->r_model, g->max_model_force);
}

static void guard_fini(void* self) { free(self); }

static const tx_controller_class guard_class = {
    .type = "study.skin_guard",
    .view = true,
    .summary = "counts non-finite values in skin.x, tool0.force_model, device0.force; largest forces",
    .configure = guard_configure,
    .step = guard_step,
    .finish = guard_finish,
    .fini = guard_fini,
};

// ---------------------------------------------------------------------------
// the cases

#define H 2000.0 // the default stretch stiffness, N/m (bend: 20)

static const tx_skin_stability_case cases[] = {
    {"stiffness x1e-3", "pierce", 1e-3, 60, 1.0 / 600, 0.004, 100},
    {"stiffness x1e-2", "pierce", 1e-2, 60, 1.0 / 600, 0.004, 100},
    {"stiffness x1e-1", "pierce", 1e-1, 60, 1.0 / 600, 0.004, 100},
    {"stiffness x1", "pierce", 1, 60, 1.0 / 600, 0.004, 100},
    {"stiffness x1e1", "pierce", 1e1, 60, 1.0 / 600, 0.004, 100},
    {"stiffness x1e2", "pierce", 1e2, 60, 1.0 / 600, 0.004, 100},
    {"stiffness x1e3", "pierce", 1e3, 60, 1.0 / 600, 0.004, 100},
    {"time step 1/20 s", "pierce", 1, 20, 1.0 / 20, 0.004, 100},
    {"time step 1/60 s", "pierce", 1, 60, 1.0 / 60, 0.004, 100},
    {"time step 1/120 s", "pierce", 1, 120, 1.0 / 120, 0.004, 100},
    {"time step 1/250 s", "pierce", 1, 60, 1.0 / 250, 0.004, 100},
    {"time step 1/500 s", "pierce", 1, 60, 1.0 / 500, 0.004, 100},
    {"time step 1/1000 s", "pierce", 1, 60, 1.0 / 1000, 0.004, 100},
    {"stiffness x1e3, 1/20 s", "pierce", 1e3, 20, 1.0 / 20, 0.004, 100},
    {"teleport 10 cm through", "teleport-through", 1, 60, 1.0 / 600, 0.004, 100},
    {"teleport 10 cm in contact", "teleport-in-contact", 1, 60, 1.0 / 600, 0.004, 100},
    {"10 m/s through", "fast-through", 1, 60, 1.0 / 600, 0.004, 100},
    {"10 m/s along, in contact", "fast-sideways", 1, 60, 1.0 / 600, 0.004, 100},
    {"zero thickness", "pierce", 1, 60, 1.0 / 600, 0, 100},
    // a blow-up bound below what a 10 m/s HIP gives the skin before it pierces it (it no longer drags the
    // torn skin after: 1 m/s is not reached): detected, recovered, counted
    {"10 m/s through, bound 0.3 m/s", "fast-through", 1, 60, 1.0 / 600, 0.004, 0.3},
};

int tx_skin_stability_cases(const tx_skin_stability_case** out) {
  *out = cases;
  return (int)(sizeof cases / sizeof cases[0]);
}

// hand motions: waypoints t, x, y, z (s, m); one ms is one haptics tick
typedef struct motion {
  const char* name;
  int n;
  double w[6][4];
  double duration; // s
} motion;

static const motion motions[] = {
    // down at 1 cm/s from 1 cm above through the mid-plane to 1.5 cm below
    {"pierce", 4, {{0, 0, 0.010, 0}, {0.2, 0, 0.010, 0}, {2.7, 0, -0.015, 0}, {3.0, 0, -0.015, 0}}, 3.0},
    // from 5 cm above to 5 cm below in one tick
    {"teleport-through", 3, {{0, 0, 0.05, 0}, {0.5, 0, 0.05, 0}, {0.501, 0, -0.05, 0}}, 1.5},
    // pressed 3 mm into the skin (the contact begins 2.5 mm above), then 10 cm along x in one tick
    {"teleport-in-contact", 4, {{0, -0.02, 0.01, 0}, {0.3, -0.02, 0.01, 0}, {1.0, -0.02, -0.003, 0}, {1.001, 0.08, -0.003, 0}}, 2.0},
    // 10 cm down in 10 ms
    {"fast-through", 3, {{0, 0, 0.05, 0}, {0.5, 0, 0.05, 0}, {0.51, 0, -0.05, 0}}, 1.5},
    // pressed 3 mm in, then 8 cm along x in 8 ms
    {"fast-sideways", 4, {{0, -0.04, 0.01, 0}, {0.3, -0.04, 0.01, 0}, {1.0, -0.04, -0.003, 0}, {1.008, 0.04, -0.003, 0}}, 2.0},
};

static const motion* find_motion(const char* name) {
  for (size_t i = 0; i < sizeof motions / sizeof motions[0]; i++)
    if (strcmp(motions[i].name, name) == 0) return &motions[i];
  return NULL;
}

// the motion as DIR/motion-NAME.csv, its path into path; -1: tx_error() says why
static int write_motion(const motion* m, const char* dir, char* path, size_t size) {
  char name[96];
  snprintf(name, sizeof name, "motion-%s.csv", m->name);
  tx_aside o;
  if (!tx_aside_begin(&o, dir, name)) return -1;
  fprintf(o.f, "# t_s, x_m, y_m, z_m: the %s motion of tactus study skin-stability\n", m->name);
  for (int i = 0; i < m->n; i++) fprintf(o.f, "%.6f,%.6f,%.6f,%.6f\n", m->w[i][0], m->w[i][1], m->w[i][2], m->w[i][3]);
  snprintf(path, size, "%s", o.path);
  return tx_aside_end(&o) ? 0 : -1;
}

static double result(tx_system* s, const char* key) {
  for (int k = 0; k < tx_system_results(s); k++)
    if (strcmp(tx_system_result_key(s, k), key) == 0) return tx_system_result(s, k);
  return NAN;
}

int tx_skin_stability_run(const tx_skin_stability_case* c, const char* dir, tx_skin_stability_row* row) {
  memset(row, 0, sizeof *row);
  const motion* m = find_motion(c->motion);
  if (!m) return tx_set_error("skin-stability: no motion '%s'", c->motion), -1;
  char path[4200];
  if (write_motion(m, dir, path, sizeof path)) return -1;
  if (!tx_find_controller(guard_class.type)) tx_register_controller(&guard_class);

  // the scenario, built as JSON so that any folder name is quoted right
  char device[4300];
  snprintf(device, sizeof device, "scripted:%s", path);
  json_t* doc = json_pack(
      "{s:s,s:[{s:s,s:s,s:f,s:{s:f,s:f,s:f,s:f,s:f,s:f,s:f}},{s:s,s:s,s:f,s:{s:f,s:i}},"
      "{s:s,s:s,s:f,s:{s:s,s:s,s:f}},{s:s,s:s,s:f}]}",
      "name", "skin-stability", "controllers",
      "name", "skin", "type", "physics.skin", "rate_hz", c->rate_hz, "params", "spacing_m", 0.0025, "thickness_m",
      c->thickness_m, "hip_radius_m", 0.0005, "stretch_stiffness", H * c->stiffness, "bend_stiffness",
      H / 100 * c->stiffness, "max_substep_s", c->substep_s, "max_speed", c->max_speed,
      "name", "hip", "type", "collision.hip", "rate_hz", 4000.0, "params", "radius_m", 0.0005, "rays", 26,
      "name", "haptics", "type", "haptics", "rate_hz", 1000.0, "params", "device", device, "force_model",
      "tool0.force_model", "max_force", TX_SKIN_STABILITY_CLAMP_N,
      "name", "guard", "type", "study.skin_guard", "rate_hz", 1000.0);
  char* text = doc ? json_dumps(doc, JSON_COMPACT) : NULL;
  json_decref(doc);
  if (!text) return tx_set_error("skin-stability: out of memory"), -1;
  tx_scenario* sc = tx_scenario_load_text("skin-stability", text, strlen(text), NULL);
  free(text);
  if (!sc) return -1;
  tx_run_options o = {.duration_s = m->duration, .lockstep = true};
  tx_run_result r;
  int rc = tx_system_run(sc->system, &o, &r);
  if (rc) {
    tx_scenario_free(sc);
    return -1;
  }

  // what the run says
  tx_system* s = sc->system;
  for (int i = 0; i < tx_system_count(s); i++)
    if (strcmp(tx_system_name(s, i), "skin") == 0) row->skin_steps = (int)tx_system_stats(s, i).steps;
  size_t used = 0;
  for (int w = 0; w < tx_system_warnings(s); w++) {
    uint64_t count = tx_system_warning_count(s, w);
    const char* key = tx_system_warning_key(s, w);
    if (strcmp(key, "skin.numerical_fault") == 0) row->faults = (int)count;
    if (strcmp(key, "haptics.force_clamped") == 0) row->clamped = (long)count;
    if (count && used + 2 < sizeof row->warnings)
      used += (size_t)snprintf(row->warnings + used, sizeof row->warnings - used, "%s%s=%llu", used ? " " : "", key,
                               (unsigned long long)count);
    if (used >= sizeof row->warnings) used = sizeof row->warnings - 1;
  }
  row->torn = (int)result(s, "skin.torn_links");
  row->nan_values = (long)result(s, "guard.nan_values");
  row->max_force = result(s, "guard.max_device_force_N");
  row->max_model_force = result(s, "guard.max_model_force_N");
  tx_scenario_free(sc);
  row->ok = row->nan_values == 0 && row->max_force <= TX_SKIN_STABILITY_CLAMP_N * (1 + 1e-9);
  snprintf(row->outcome, sizeof row->outcome, "%s", !row->ok ? "FAILED" : row->faults ? "recovered" : "stable");
  return 0;
}

// ---------------------------------------------------------------------------
// the study

int tx_study_skin_stability(const tx_study_args* a) {
#if !TX_WITH_BULLET
  (void)a;
  return tx_bad_input("study skin-stability: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
#else
  if (a->nsets) return tx_bad_input("--set %s: skin-stability takes no --set (its cases are fixed)", a->sets[0]);
  const tx_skin_stability_case* cs;
  int n = tx_skin_stability_cases(&cs);
  printf("study skin-stability: 1764-particle skin, collision.hip (26 rays), haptics clamp %.1f N, lockstep\n\n",
         TX_SKIN_STABILITY_CLAMP_N);
  printf("  %-26s %6s %6s %6s %5s %10s %11s %8s  %-9s\n", "case", "steps", "faults", "torn", "NaN", "max |F| N",
         "max |F0| N", "clamped", "outcome");
  json_t* list = json_array();
  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "skin-stability.csv")) return json_decref(list), tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "case,motion,stiffness_factor,rate_hz,substep_s,thickness_m,max_speed_m_s,skin_steps,faults,torn_links,nan_values,"
               "max_device_force_n,max_model_force_n,force_clamped,outcome\n");
  int failed = 0;
  for (int i = 0; i < n; i++) {
    tx_skin_stability_row r;
    if (tx_skin_stability_run(&cs[i], a->out_dir, &r)) {
      tx_aside_drop(&out);
      json_decref(list);
      return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    }
    failed += !r.ok;
    printf("  %-26s %6d %6d %6d %5ld %10.4f %11.4f %8ld  %-9s %s\n", cs[i].name, r.skin_steps, r.faults, r.torn,
           r.nan_values, r.max_force, r.max_model_force, r.clamped, r.outcome, r.warnings);
    fprintf(csv, "%s,%s,%g,%g,%.6g,%g,%g,%d,%d,%d,%ld,%.6g,%.6g,%ld,%s\n", cs[i].name, cs[i].motion, cs[i].stiffness,
            cs[i].rate_hz, cs[i].substep_s, cs[i].thickness_m, cs[i].max_speed, r.skin_steps, r.faults, r.torn, r.nan_values,
            r.max_force, r.max_model_force, r.clamped, r.outcome);
    json_array_append_new(
        list, json_pack("{s:s,s:s,s:f,s:f,s:f,s:f,s:i,s:i,s:i,s:I,s:f,s:f,s:I,s:s,s:s}", "case", cs[i].name, "motion",
                        cs[i].motion, "stiffness_factor", cs[i].stiffness, "rate_hz", cs[i].rate_hz, "substep_s",
                        cs[i].substep_s, "thickness_m", cs[i].thickness_m, "skin_steps", r.skin_steps, "faults",
                        r.faults, "torn_links", r.torn, "nan_values", (json_int_t)r.nan_values, "max_device_force_n",
                        r.max_force, "max_model_force_n", r.max_model_force, "force_clamped", (json_int_t)r.clamped,
                        "outcome", r.outcome, "warnings", r.warnings));
  }
  if (!tx_aside_end(&out)) {
    json_decref(list);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:f,s:s,s:o}", "study", "skin-stability", "clamp_n", TX_SKIN_STABILITY_CLAMP_N,
                          "units", "stiffness as a factor on 2000 N/m stretch and 20 N/m bend; s, m, N", "cases", list);
  if (!doc || tx_report_save(doc, a->out_dir, "skin-stability.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_decref(doc);
  printf("\ntargets:\n  every case stable or recovered, no NaN in the model, |F| <= %.1f N: %s (%d of %d failed)\n",
         TX_SKIN_STABILITY_CLAMP_N, failed ? "MISSED" : "met", failed, n);
  printf("wrote %s/skin-stability.json and .csv\n", a->out_dir);
  return failed ? 1 : 0;
#endif
}
