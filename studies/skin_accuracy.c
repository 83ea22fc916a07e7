// tactus study skin-accuracy: does the skin converge as its spacing,
// iterations and time step are refined together, and what does each setting
// cost against its error?
//
// One refinement path, levels l = 0..L, that refines what converges for the
// skin's XPBD solver (docs/skin.md): the spacing halves at every level (10,
// 5, 2.5, 1.25 mm; the quick path of the test stops at 2.5), and the substep
// h keeps k w h^2 = 1/4 (k the link stiffness, w = 2 / m the two inverse
// masses), with 4 iterations: each level's substep is a converged implicit
// Euler step, and since m falls as the spacing squared, h halves with the
// spacing (163, 82, 41, 21 us). physics.skin runs at 120 Hz, each step split
// into whole substeps. The patch keeps one edge (10 cm) and one mass at every
// level, so only the discretisation changes.
//
// Each level is two lockstep runs. The pierce: physics.skin, collision.hip
// (26 rays) and haptics on a scripted hand going down at 1 cm/s, no gravity,
// with a recorder of the device force, the HIP height and skin.torn at every
// 1 ms tick. It gives the force at a fixed indentation (5 mm, halfway to
// the tear, where the membrane carries it: at 2 mm, 10 mN, its steps do not
// shrink on the full path; --set indentation_m) below the geometric first
// contact, the rupture force (the largest force before it collapses after the
// first torn link) and the rupture depth (where the rupture criterion was
// first met, between substeps: skin.rupture). The pierce tears at 150 N/m averaged
// over 1 cm (skin-membrane's rupture check's tension): skin's own 10^3 to
// 10^4 N/m (docs/skin.md) is not reached by a 0.5 mm HIP within the motion,
// and physics.skin's default 1 N/m is a calibration of the unconverged
// real-time skin. The sag: the skin alone under gravity, hanging for its
// settle time and 1 s more; the sag is the deepest particle's depth, averaged
// over the last 0.5 s (at 2.5 mm the patch still sways by some 1 % of its
// sag, and one instant read the sway's phase; at 1.25 mm it sways by 10 %,
// which the mean does not cure: docs/validation.md). For
// each quantity the three finest levels give the observed order p and a
// Richardson reference (skin_metrics.h, tx_converge); every level's error is
// against it. The real-time default (suturing-skin's own settings: spacing
// 2.5 mm on a 10.25 cm edge, 1 iteration, ten substeps of a 60 Hz step) runs
// the same two runs and is compared with the same reference. Run time: the
// process's CPU time of the pierce run per simulated second (CPU time, so
// other work on the machine does not count).
//
// Outputs: skin-accuracy.csv and .json (one row per setting, the orders and
// references), skin-accuracy-curves.csv (every tick of every pierce) and
// skin-accuracy.png (error against run time, log-log, one series per
// quantity).
#include "studies.h"
#include "skin_metrics.h"

#include "../scenarios/command.h"
#include "../controllers/haptics/device_scripted.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <tactus/components.h>
#include <tactus/config.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if TX_WITH_BULLET
#include "../controllers/physics/bullet/cloth.h"

#define TICKS_MAX 4000 // 3 s at 1 kHz, and room
#define LEVELS_MAX 6
#define EDGE_M 0.1         // the patch's edge on the path (size_m = EDGE_M - spacing_m)
#define THICKNESS_M 0.004  // suturing-skin's
#define RADIUS_M 0.0005    // suturing-skin's HIP
#define SAG_AFTER_S 1.0    // the sag run, after the skin's own settle time
#define SAG_WINDOW_S 0.5   // the sag: the mean over its last this long (the patch still sways)
#define MASS_KG 0.044      // physics.skin's mass_kg (the whole patch), kept at every level
#define STIFFNESS 2000.0   // physics.skin's stretch_stiffness
#define KWH2 0.25          // k w h^2 on the path: converged (skin-membrane's)
#define CELLS0 10          // level 0: 10 cells a side, 1 cm spacing
#define ITERATIONS 4       // on the path
#define RATE_HZ 120.0      // physics.skin's rate on the path
#define RUPTURE_T 150.0    // N/m, the pierce's rupture tension (see below)
#define RUPTURE_L 0.01     // m, its averaging length: two spacings at level 1, one at level 0
#define CONTACT_Y (RADIUS_M + 0.5 * THICKNESS_M) // m, the HIP height at first contact with the flat skin
#define WINDOW_M 0.0005    // m, half the indentation window the force at the indentation is fitted over
#define NQ 4               // quantities: force at the indentation, rupture force, rupture depth, sag

// ---------------------------------------------------------------------------
// the recorders: the pierce's force, HIP height and torn links per tick; the sag's deepest particle,
// averaged over its window

typedef struct curve {
  int n;
  double y[TICKS_MAX];    // m, HIP height
  double f[TICKS_MAX];    // N, device force along y
  double torn[TICKS_MAX]; // links torn so far
  double break_y;         // m, the HIP height where the rupture criterion was first met (skin.rupture; NaN: never)
} curve;

static curve* recording; // the study's buffer for the pierce under way (one run at a time)
static double sag_sum; // m, the lowest particle y of skin.x, summed over the sag's window
static int sag_count;  // steps summed

typedef struct recorder {
  tx_port pose, force, torn, x, rupture;
} recorder;

static int pierce_configure(tx_setup* s, void** self) {
  recorder* r = calloc(1, sizeof *r);
  if (!r) return -1;
  *self = r;
  r->pose = TX_READ_OF(s, "device0.pose", tx_pose);
  r->force = TX_READ_OF(s, "device0.force", tx_force);
  r->torn = TX_READ_OF(s, "skin.torn", tx_torn);
  r->rupture = TX_READ_OF(s, "skin.rupture", tx_skin_rupture);
  return 0;
}

static void pierce_step(tx_ctx* c, void* self) {
  recorder* r = self;
  const tx_pose* p = tx_read(c, r->pose).data;
  const tx_force* f = tx_read(c, r->force).data;
  const tx_torn* t = tx_read(c, r->torn).data;
  const tx_skin_rupture* ru = tx_read(c, r->rupture).data;
  if (recording && ru->broke != 0 && isnan(recording->break_y)) recording->break_y = ru->at[1];
  if (recording && recording->n < TICKS_MAX) {
    recording->y[recording->n] = p->pos[1];
    recording->f[recording->n] = f->f[1];
    recording->torn[recording->n] = t->links;
    recording->n++;
  }
}

static int sag_configure(tx_setup* s, void** self) {
  recorder* r = calloc(1, sizeof *r);
  if (!r) return -1;
  *self = r;
  r->x = TX_READ_OF(s, "skin.x", tx_vertex);
  return 0;
}

static void sag_step(tx_ctx* c, void* self) {
  recorder* r = self;
  if ((double)tx_sim_ns(c) * 1e-9 < SAG_AFTER_S - SAG_WINDOW_S - 1e-9) return;
  tx_snapshot x = tx_read(c, r->x);
  const tx_vertex* v = x.data;
  double lowest = INFINITY;
  for (uint32_t i = 0; i < x.rows; i++)
    if (v[i].x[1] < lowest) lowest = v[i].x[1];
  sag_sum += lowest;
  sag_count++;
}

static void recorder_fini(void* self) { free(self); }

static const tx_controller_class pierce_class = {.type = "study.pierce_recorder",
                                                 .view = true,
                                                 .summary = "keeps device0.pose y, device0.force y and skin.torn per tick",
                                                 .configure = pierce_configure,
                                                 .step = pierce_step,
                                                 .fini = recorder_fini};
static const tx_controller_class sag_class = {.type = "study.sag_recorder",
                                              .view = true,
                                              .summary = "averages the lowest particle of skin.x over the sag's window",
                                              .configure = sag_configure,
                                              .step = sag_step,
                                              .fini = recorder_fini};

// ---------------------------------------------------------------------------
// settings

typedef struct setting {
  char name[32];  // "level 0".., "real time", "real time (particle)" or "real time (cell middle)"
  double spacing; // m
  double hip_offset; // m, the hand's offset along x and z from the patch's centre
  double size;    // m, size_m (the edge is size + spacing)
  int iterations;
  double rate_hz; // physics.skin's rate
  double substep; // s, its max_substep_s
  char solver[12]; // "xpbd" or "implicit"
  int newton_steps, cg_iterations; // implicit only
  double cg_tolerance;
  int coarse_block; // implicit only: the CG's coarse level (0: none)
} setting;

typedef struct row {
  double cpu_s_per_s; // process CPU time of the pierce run per simulated second
  double wall_s;      // the pierce and the sag runs
  double q[NQ];       // the quantities (NaN: not measured)
  double err[NQ];     // relative error against the reference
  double contact_y;   // m, HIP height at first contact
  int torn;
} row;

static const char* const q_key[NQ] = {"force_at_indentation_n", "rupture_force_n", "rupture_depth_m", "sag_m"};
static const char* const q_label[NQ] = {"force at indentation", "rupture force", "rupture depth", "sag"};

// the path: level l halves the spacing of level 0 (cells0 cells a side) and
// takes the substep that keeps k w h^2 = KWH2 (w = 2 / m, m the particle's
// mass, which falls as the spacing squared, so h halves with the spacing),
// with ITERATIONS iterations: the range where XPBD converges to the links'
// true stiffness (docs/skin.md). physics.skin runs at RATE_HZ; h is its step
// split into whole substeps.
static setting level_setting(int l, int cells0) {
  setting s = {.iterations = ITERATIONS, .rate_hz = RATE_HZ, .solver = "xpbd", .newton_steps = 1, .cg_iterations = 1,
               .cg_tolerance = 1};
  snprintf(s.name, sizeof s.name, "level %d", l);
  int cells = cells0 << l;
  s.spacing = EDGE_M / (double)cells;
  s.size = EDGE_M - s.spacing;
  double m = MASS_KG / ((double)cells * cells);
  double h = tx_cloth_converged_substep(STIFFNESS, m, KWH2);
  s.substep = (1 / RATE_HZ) / ceil((1 / RATE_HZ) / h - 1e-9);
  return s;
}

// where the HIP comes down on a setting's patch: over its centre particle (an
// odd count of particles a side puts one at the centre) or over the middle of
// a cell, with the hand offset by hip_offset along x and z
static bool over_particle(const setting* s) {
  long count = lround((s->size + s->spacing) / s->spacing) + 1; // particles a side
  bool centre_particle = count % 2 == 1;
  return s->hip_offset == 0 ? centre_particle : !centre_particle;
}

// a parameter of physics.skin: what the scenario's skin sets, else the class default
static const tx_param_def* skin_param(const char* key) {
  tx_register_builtin();
  const tx_controller_class* k = tx_find_controller("physics.skin");
  for (int i = 0; k && i < k->nparams; i++)
    if (strcmp(k->params[i].key, key) == 0) return &k->params[i];
  return NULL;
}

static double num_of(json_t* params, const char* key) {
  json_t* v = json_object_get(params, key);
  if (json_is_number(v)) return json_number_value(v);
  const tx_param_def* p = skin_param(key);
  return p ? p->def_num : NAN;
}

// suturing-skin as it ships: the skin's rate and parameters in its scenario
// file, the rest physics.skin's defaults. 0, or 1 with a message
static int real_time_setting(setting* s) {
  memset(s, 0, sizeof *s);
  snprintf(s->name, sizeof s->name, "real time");
  char path[4096];
  if (tx_scenario_locate("suturing-skin", path, sizeof path)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_error_t e;
  json_t* doc = json_load_file(path, 0, &e);
  json_t* skin = NULL;
  size_t i;
  json_t* ctl;
  json_array_foreach(json_object_get(doc, "controllers"), i, ctl)
    if (json_is_string(json_object_get(ctl, "type")) &&
        strcmp(json_string_value(json_object_get(ctl, "type")), "physics.skin") == 0)
      skin = ctl;
  if (!skin) {
    json_decref(doc);
    return fprintf(stderr, "tactus: skin-accuracy: %s has no physics.skin\n", path), 1;
  }
  json_t* params = json_object_get(skin, "params");
  s->rate_hz = json_number_value(json_object_get(skin, "rate_hz"));
  s->spacing = num_of(params, "spacing_m");
  s->size = num_of(params, "size_m");
  s->iterations = (int)num_of(params, "iterations");
  s->substep = num_of(params, "max_substep_s");
  s->newton_steps = (int)num_of(params, "newton_steps");
  s->cg_iterations = (int)num_of(params, "cg_iterations");
  s->cg_tolerance = num_of(params, "cg_tolerance");
  s->coarse_block = (int)num_of(params, "coarse_block");
  json_t* sv = json_object_get(params, "solver");
  const tx_param_def* sp = skin_param("solver");
  snprintf(s->solver, sizeof s->solver, "%s", json_is_string(sv) ? json_string_value(sv) : sp ? sp->def_str : "?");
  json_decref(doc);
  // the study's substeps are whole divisions of the step, as physics.skin's
  if (!(s->rate_hz > 0) || !(s->substep > 0) || !(s->spacing > 0))
    return fprintf(stderr, "tactus: skin-accuracy: %s: no rate or spacing for its skin\n", path), 1;
  s->substep = (1 / s->rate_hz) / ceil((1 / s->rate_hz) / s->substep - 1e-9);
  return 0;
}

// the hand: down at 1 cm/s. The full path uses the table's accuracy-pierce-down
// (1 cm above the mid-plane to 1.5 cm below, 3 s); the quick path a shorter
// one, 0.5 mm above first contact to 12.5 mm below it (the path tears at
// 10 to 10.5 mm).
static const tx_hand_motion quick_motion = {
    "accuracy-pierce-down-short", 4, {{0, 0, 0.003, 0}, {0.1, 0, 0.003, 0}, {1.4, 0, -0.010, 0}, {1.5, 0, -0.010, 0}}};

// the motion as DIR/NAME, its path into path; -1: tx_error() says why
static int write_motion(const char* dir, const char* name, const tx_hand_motion* m, double offset, char* path, size_t size) {
  tx_aside o;
  if (!tx_aside_begin(&o, dir, name)) return -1;
  fprintf(o.f, "# t_s, x_m, y_m, z_m: %s at 1 cm/s, tactus study skin-accuracy\n", m->name);
  for (int i = 0; i < m->count; i++)
    fprintf(o.f, "%.9g,%.9g,%.9g,%.9g\n", m->t_pos[i][0], m->t_pos[i][1] + offset, m->t_pos[i][2], m->t_pos[i][3] + offset);
  snprintf(path, size, "%s", o.path);
  return tx_aside_end(&o) ? 0 : -1;
}

// the pierce's quantities from its ticks. Indentation is measured from the
// geometric first contact, CONTACT_Y (the skin lies flat at y = 0 and has no
// gravity): the first non-zero force comes up to a physics step later, and
// with a force that grows as the cube of the indentation that step alone is
// some 10 % at 2 mm. The force at the indentation `depth` is a least-squares
// quadratic in the indentation over the ticks within WINDOW_M of it, before
// any tear, taken at `depth`: the force is held for a physics step and
// jumps with the contact's impulses (some 3 mN rms at 2 mm), which one tick
// would carry into the error. The rupture force: the largest force before the
// force collapses (under a tenth of the largest so far) once a link has torn.
// The rupture depth: the HIP's depth below CONTACT_Y where the rupture
// criterion was first met, which physics.skin resolves between its substeps,
// linear in the tension (skin.rupture): the force's peak is found only to a
// physics step (83 um at 120 Hz), too coarse to see the depth converge.
static void measure_pierce(const curve* c, double depth, row* r) {
  int contact = -1;
  for (int i = 0; i < c->n && contact < 0; i++)
    if (c->f[i] != 0) contact = i;
  r->contact_y = contact >= 0 ? c->y[contact] : NAN;
  r->q[0] = r->q[1] = r->q[2] = NAN;
  if (contact < 0) return;
  // the normal equations of f = a + b u + c u^2, u = indentation - depth
  double s[5] = {0}, t[3] = {0};
  int n = 0;
  for (int i = 0; i < c->n && c->torn[i] == 0; i++) {
    double u = CONTACT_Y - c->y[i] - depth;
    if (fabs(u) > WINDOW_M) continue;
    double f = fabs(c->f[i]), p = 1;
    for (int k = 0; k < 5; k++, p *= u) {
      s[k] += p;
      if (k < 3) t[k] += p * f;
    }
    n++;
  }
  if (n >= 10) { // the window was passed untorn: Cramer's rule for a
    double m[3][3] = {{s[0], s[1], s[2]}, {s[1], s[2], s[3]}, {s[2], s[3], s[4]}};
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double num = t[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (t[1] * m[2][2] - m[1][2] * t[2]) +
                 m[0][2] * (t[1] * m[2][1] - m[1][1] * t[2]);
    if (det != 0) r->q[0] = num / det;
  }
  int peak = contact;
  for (int i = contact; i < c->n; i++) {
    if (fabs(c->f[i]) > fabs(c->f[peak])) peak = i;
    if (c->torn[i] > c->torn[contact] && fabs(c->f[i]) < 0.1 * fabs(c->f[peak])) {
      r->q[1] = fabs(c->f[peak]);
      r->q[2] = CONTACT_Y - c->break_y; // NaN if the skin never reported where
      return;
    }
  }
}

// hanging must not tear the skin: the sag is measured on a skin that
// cannot tear (a rupture tension of 0 means never)
static void no_rupture(json_t* params) { json_object_set_new(params, "rupture_tension_n_per_m", json_real(0)); }

static json_t* skin_params(const setting* s, bool gravity, double hip_radius) {
  json_t* p = json_pack("{s:f,s:f,s:f,s:f,s:i,s:f,s:b,s:s,s:i,s:i,s:f}", "spacing_m", s->spacing, "size_m", s->size,
                        "thickness_m", THICKNESS_M, "hip_radius_m", hip_radius, "iterations", s->iterations,
                        "max_substep_s", s->substep, "gravity", gravity, "solver", s->solver, "newton_steps",
                        s->newton_steps, "cg_iterations", s->cg_iterations, "cg_tolerance", s->cg_tolerance);
  if (p && s->coarse_block > 0) json_object_set_new(p, "coarse_block", json_integer(s->coarse_block));
  if (p && gravity) no_rupture(p);
  else if (p) {
    json_object_set_new(p, "rupture_tension_n_per_m", json_real(RUPTURE_T));
    json_object_set_new(p, "rupture_length_m", json_real(RUPTURE_L));
  }
  return p;
}

// one lockstep run of a scenario given as JSON; its CPU and wall seconds
static int run_doc(json_t* doc, const char* label, double duration, double* cpu_s, double* wall_s, int* torn) {
  char* text = doc ? json_dumps(doc, JSON_COMPACT) : NULL;
  json_decref(doc);
  if (!text) return fprintf(stderr, "tactus: skin-accuracy: out of memory\n"), 1;
  tx_scenario* sc = tx_scenario_load_text(label, text, strlen(text), NULL);
  free(text);
  if (!sc) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  tx_run_options o = {.duration_s = duration, .lockstep = true};
  tx_run_result res;
  int64_t t0 = tx_mono_ns();
  struct timespec c0, c1;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
  int rc = tx_system_run(sc->system, &o, &res);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
  *wall_s = (double)(tx_mono_ns() - t0) * 1e-9;
  *cpu_s = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
  if (rc) fprintf(stderr, "tactus: %s\n", tx_error());
  for (int k = 0; rc == 0 && torn && k < tx_system_results(sc->system); k++)
    if (strcmp(tx_system_result_key(sc->system, k), "skin.torn_links") == 0) *torn = (int)tx_system_result(sc->system, k);
  tx_scenario_free(sc);
  return rc ? 1 : 0;
}

static int run_setting(const setting* s, const char* device, double duration, double depth, curve* out, row* r) {
  json_t* pierce = json_pack(
      "{s:s,s:[{s:s,s:s,s:f,s:o},{s:s,s:s,s:f,s:{s:f,s:i}},{s:s,s:s,s:f,s:{s:s,s:s}},{s:s,s:s,s:f}]}", "name",
      "skin-accuracy", "controllers", "name", "skin", "type", "physics.skin", "rate_hz", s->rate_hz, "params",
      skin_params(s, false, RADIUS_M), "name", "hip", "type", "collision.hip", "rate_hz", 4000.0, "params", "radius_m",
      RADIUS_M, "rays", 26, "name", "haptics", "type", "haptics", "rate_hz", 1000.0, "params", "device", device,
      "force_model", "tool0.force_model", "name", "recorder", "type", pierce_class.type, "rate_hz", 1000.0);
  out->n = 0;
  out->break_y = NAN;
  recording = out;
  double cpu, wall, wall2, cpu2;
  int rc = run_doc(pierce, "skin-accuracy (pierce)", duration, &cpu, &wall, &r->torn);
  recording = NULL;
  if (rc) return rc;
  r->cpu_s_per_s = cpu / duration;
  measure_pierce(out, depth, r);
  // the sag: the skin alone, under gravity, without a HIP
  json_t* sag = json_pack("{s:s,s:[{s:s,s:s,s:f,s:o},{s:s,s:s,s:f}]}", "name", "skin-accuracy-sag", "controllers",
                          "name", "skin", "type", "physics.skin", "rate_hz", s->rate_hz, "params", skin_params(s, true, 0),
                          "name", "recorder", "type", sag_class.type, "rate_hz", s->rate_hz);
  sag_sum = 0;
  sag_count = 0;
  rc = run_doc(sag, "skin-accuracy (sag)", SAG_AFTER_S, &cpu2, &wall2, NULL);
  r->wall_s = wall + wall2;
  r->q[3] = sag_count ? -sag_sum / sag_count : NAN;
  return rc;
}

static int write_plot(const char* dir, const setting* set, const row* rows, int nlev) {
  // one line per quantity along the path, and the real-time default as points.
  // A zero error (the finest level standing in for a reference that could not
  // be extrapolated, or a quantity that does not change) has no place on a log axis.
  static const int colours[NQ] = {1, 3, 9, 13};
  double x[NQ][LEVELS_MAX], y[NQ][LEVELS_MAX], rx[NQ][2], ry[NQ][2];
  static char labels[NQ][64];
  tx_plot_series s[2 * NQ];
  int ns = 0;
  for (int k = 0; k < NQ; k++) {
    int n = 0;
    for (int l = 0; l < nlev; l++)
      if (rows[l].err[k] > 0) {
        x[k][n] = rows[l].cpu_s_per_s;
        y[k][n] = 100 * rows[l].err[k];
        n++;
      }
    if (n) s[ns++] = (tx_plot_series){q_label[k], x[k], y[k], n, false, colours[k]};
  }
  for (int k = 0; k < NQ; k++) { // the real-time default, the HIP over a particle and over a cell's middle
    int n = 0;
    for (int i = nlev; i < nlev + 2; i++)
      if (rows[i].err[k] > 0) {
        rx[k][n] = rows[i].cpu_s_per_s;
        ry[k][n] = 100 * rows[i].err[k];
        n++;
      }
    snprintf(labels[k], sizeof labels[k], "%s, real-time default", q_label[k]);
    if (n) s[ns++] = (tx_plot_series){labels[k], rx[k], ry[k], n, true, colours[k]};
  }
  (void)set;
  char path[4200];
  snprintf(path, sizeof path, "%s/skin-accuracy.png", dir);
  tx_plot p = {"Skin error vs run time along the refinement path (zero errors not drawn)",
               "run time (CPU s per simulated s)", "error (% of the reference)", true, true, s, ns};
  return tx_plot_png(path, &p);
}

// the study's own --set keys
typedef struct options {
  bool quick;
  int levels;
  double depth; // m
} options;

static int parse_options(const tx_study_args* a, options* o) {
  *o = (options){false, 0, 0.005};
  for (int i = 0; i < a->nsets; i++) {
    const char* s = a->sets[i];
    const char* eq = strchr(s, '=');
    if (!eq) return tx_bad_input("--set %s: expected KEY=VALUE", s);
    const char* v = eq + 1;
    char* end;
    if (strncmp(s, "path=", 5) == 0) {
      if (strcmp(v, "full") == 0) o->quick = false;
      else if (strcmp(v, "quick") == 0) o->quick = true;
      else return tx_bad_input("--set path: expected full or quick, not '%s'", v);
    } else if (strncmp(s, "levels=", 7) == 0) {
      long n = strtol(v, &end, 10);
      if (end == v || *end || n < 3 || n > LEVELS_MAX)
        return tx_bad_input("--set levels: expected a whole number from 3 to %d, not '%s'", LEVELS_MAX, v);
      o->levels = (int)n;
    } else if (strncmp(s, "indentation_m=", 14) == 0) {
      double d = strtod(v, &end);
      if (end == v || *end || !(d >= 2 * WINDOW_M && d <= 0.01)) // its fit window starts at contact or after
        return tx_bad_input("--set indentation_m: expected a depth in [0.001, 0.01] m, not '%s'", v);
      o->depth = d;
    } else
      return tx_bad_input("--set %s: skin-accuracy takes path, levels and indentation_m", s);
  }
  if (!o->levels) o->levels = o->quick ? 3 : 4;
  // the finest level must stay within physics.skin's spacing (>= 0.5 mm)
  if ((CELLS0 << (o->levels - 1)) > 200)
    return tx_bad_input("--set levels: %d levels of the %s path go past 0.5 mm spacing", o->levels,
                        o->quick ? "quick" : "full");
  return 0;
}

static void print_row(const setting* s, const row* r) {
  printf("  %-22s %-8s %7.3f %5d %7.0f %8.5f %9.3f %8.2f | %9.2f %6.2f | %9.2f %6.2f | %8.3f %6.2f | %8.3f %6.2f\n", s->name,
         s->solver, s->spacing * 1e3, s->iterations, 1 / s->substep, s->size + s->spacing, r->cpu_s_per_s, r->wall_s,
         r->q[0] * 1e3, 100 * r->err[0], r->q[1] * 1e3, 100 * r->err[1], r->q[2] * 1e3, 100 * r->err[2], r->q[3] * 1e3,
         100 * r->err[3]);
}

// k w h^2 of a setting's substep: under about 1, its iterations converge
static double k_w_h2(const setting* s) {
  double cells = round((s->size + s->spacing) / s->spacing);
  return STIFFNESS * 2 / (MASS_KG / (cells * cells)) * s->substep * s->substep;
}

// the real-time default's error: the larger of its two placements (NaN if either is)
static double real_time_error(const row* rows, int nset, int k) {
  double a = rows[nset - 2].err[k], b = rows[nset - 1].err[k];
  return isnan(a) || isnan(b) ? NAN : fmax(a, b);
}

static int write_outputs(const char* dir, const setting* set, const row* rows, const curve* curves, int nset,
                         const tx_convergence* conv, const options* o, const char* motion) {
  // one row per setting
  tx_aside out;
  FILE* f = tx_aside_begin(&out, dir, "skin-accuracy.csv") ? out.f : NULL;
  if (f) {
    fprintf(f, "setting,spacing_m,edge_m,iterations,rate_hz,time_step_s,cpu_s_per_sim_s,wall_s,contact_y_m,torn_links");
    for (int k = 0; k < NQ; k++) fprintf(f, ",%s,%s_error_rel", q_key[k], q_key[k]);
    fprintf(f, "\n");
    for (int i = 0; i < nset; i++) {
      const setting* s = &set[i];
      fprintf(f, "%s,%g,%g,%d,%g,%.9g,%.6g,%.6g,%.9g,%d", s->name, s->spacing, s->size + s->spacing, s->iterations,
              s->rate_hz, s->substep, rows[i].cpu_s_per_s, rows[i].wall_s, rows[i].contact_y, rows[i].torn);
      for (int k = 0; k < NQ; k++) fprintf(f, ",%.9g,%.6g", rows[i].q[k], rows[i].err[k]);
      fprintf(f, "\n");
    }
  }
  if (!f || !tx_aside_end(&out)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  // every tick of every pierce
  f = tx_aside_begin(&out, dir, "skin-accuracy-curves.csv") ? out.f : NULL;
  if (f) {
    fprintf(f, "setting,spacing_m,iterations,time_step_s,tick,hip_y_m,force_y_n,torn_links\n");
    for (int i = 0; i < nset; i++)
      for (int t = 0; t < curves[i].n; t++)
        fprintf(f, "%s,%g,%d,%.9g,%d,%.6g,%.6g,%.0f\n", set[i].name, set[i].spacing, set[i].iterations, set[i].substep,
                t, curves[i].y[t], curves[i].f[t], curves[i].torn[t]);
  }
  if (!f || !tx_aside_end(&out)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  // JSON: the path, each quantity's order and reference, each setting; NaN is no JSON number: null
  json_t* list = json_array();
  json_t* quantities = json_object();
  for (int i = 0; i < nset && list; i++) {
    const setting* s = &set[i];
    json_t* r = json_pack("{s:s,s:s,s:f,s:f,s:i,s:f,s:f,s:f,s:f,s:f,s:i}", "setting", s->name, "solver", s->solver, "spacing_m", s->spacing,
                          "edge_m", s->size + s->spacing, "iterations", s->iterations, "rate_hz", s->rate_hz,
                          "time_step_s", s->substep, "k_w_h2", k_w_h2(s), "cpu_s_per_sim_s", rows[i].cpu_s_per_s, "wall_s", rows[i].wall_s,
                          "torn_links", rows[i].torn);
    json_object_set_new(r, "hip_over", json_string(over_particle(s) ? "particle" : "cell middle"));
    json_object_set_new(r, "hip_offset_m", json_real(s->hip_offset));
    for (int k = 0; r && k < NQ; k++) {
      char key[64];
      snprintf(key, sizeof key, "%s_error_rel", q_key[k]);
      json_object_set_new(r, q_key[k], isfinite(rows[i].q[k]) ? json_real(rows[i].q[k]) : json_null());
      json_object_set_new(r, key, isfinite(rows[i].err[k]) ? json_real(rows[i].err[k]) : json_null());
    }
    json_array_append_new(list, r);
  }
  for (int k = 0; k < NQ && quantities; k++) {
    json_t* q = json_pack("{s:s,s:o,s:o,s:b,s:o}", "status", tx_conv_status_name(conv[k].status), "order_p",
                          isfinite(conv[k].p) ? json_real(conv[k].p) : json_null(), "reference",
                          isfinite(conv[k].reference) ? json_real(conv[k].reference) : json_null(), "error_falls",
                          conv[k].monotone, "real_time_error_rel",
                          isfinite(real_time_error(rows, nset, k)) ? json_real(real_time_error(rows, nset, k)) : json_null());
    for (int i = nset - 2; q && i < nset; i++) // the real-time default in each placement
      json_object_set_new(q, over_particle(&set[i]) ? "real_time_particle_error_rel" : "real_time_cell_error_rel",
                          isfinite(rows[i].err[k]) ? json_real(rows[i].err[k]) : json_null());
    json_object_set_new(quantities, q_key[k], q);
  }
  json_t* doc = json_pack(
      "{s:s,s:s,s:{s:i,s:f,s:f,s:i,s:s},s:f,s:{s:f,s:f},s:f,s:s,s:f,s:s,s:s,s:s,s:o,s:o}", "study", "skin-accuracy", "path", o->quick ? "quick" : "full",
      "refinement", "levels", nset - 2, "ratio", 2.0, "k_w_h2", KWH2, "iterations", ITERATIONS, "rule",
      "at each level the spacing halves; the substep keeps k w h^2 = 1/4 (k the link stiffness, w the two particles' inverse masses), so it halves with the spacing; 4 iterations at every level; physics.skin at 120 Hz, each step split into whole substeps; 10 cm edge, one mass", "indentation_m", o->depth,
      "rupture", "tension_n_per_m", RUPTURE_T, "length_m", RUPTURE_L, "contact_y_m", CONTACT_Y, "indentation_from",
      "the geometric first contact: HIP height r + t / 2 above the flat skin; the force there is a quadratic fit over +-0.5 mm",
      "window_m", WINDOW_M, "motion", motion, "error",
      "|q - reference| / |reference|; reference: Richardson from the three finest levels with the observed order "
      "(the finest level when the quantity does not converge: see status)",
      "run_time", "process CPU time of the pierce run (skin, HIP, haptics) per simulated second", "quantities",
      quantities, "settings", list);
  if (!doc || tx_report_save(doc, dir, "skin-accuracy.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "skin-accuracy: out of memory"), 1;
  }
  json_decref(doc);
  return 0;
}

int tx_study_skin_accuracy(const tx_study_args* a) {
  options o;
  int bad = parse_options(a, &o);
  if (bad) return bad;
  const tx_hand_motion* motion = o.quick ? &quick_motion : tx_hand_motion_find("accuracy-pierce-down");
  if (!motion) return fprintf(stderr, "tactus: skin-accuracy: no hand motion accuracy-pierce-down\n"), 1;
  double duration = motion->t_pos[motion->count - 1][0];
  char path[4200], device[4300];
  if (write_motion(a->out_dir, "motion-pierce-down.csv", motion, 0, path, sizeof path)) return tx_bad_input("--out %s", tx_error());
  snprintf(device, sizeof device, "scripted:%s", path);
  if (!tx_find_controller(pierce_class.type)) tx_register_controller(&pierce_class);
  if (!tx_find_controller(sag_class.type)) tx_register_controller(&sag_class);

  // the path, then the real-time default
  // the real-time default twice, on the path's patch (its 10 cm edge: the
  // continuum the reference is of; suturing-skin's own edge, 10.25 cm, is 2.5 %
  // wider, and the force at an indentation of an untensioned membrane falls as
  // 1 / a^2, some 5 %): the HIP over the centre particle, as at every level of
  // the path, then half a spacing along x and z, over a cell's middle. Where the
  // HIP falls on the mesh is the real-time skin's own error: both count.
  int nlev = o.levels, nset = nlev + 2;
  setting set[LEVELS_MAX + 2];
  for (int l = 0; l < nlev; l++) set[l] = level_setting(l, CELLS0);
  if (real_time_setting(&set[nlev])) return 1;
  set[nlev].size = EDGE_M - set[nlev].spacing;
  set[nlev].hip_offset = over_particle(&set[nlev]) ? 0 : 0.5 * set[nlev].spacing;
  set[nlev + 1] = set[nlev];
  set[nlev + 1].hip_offset = set[nlev].hip_offset == 0 ? 0.5 * set[nlev].spacing : 0;
  for (int i = nlev; i < nset; i++)
    snprintf(set[i].name, sizeof set[i].name, "real time (%s)", over_particle(&set[i]) ? "particle" : "cell middle");
  char offset_path[4200], offset_device[4300];
  if (write_motion(a->out_dir, "motion-pierce-down-offset.csv", motion, 0.5 * set[nlev].spacing, offset_path, sizeof offset_path))
    return tx_bad_input("--out %s", tx_error());
  snprintf(offset_device, sizeof offset_device, "scripted:%s", offset_path);
  curve* curves = calloc((size_t)nset, sizeof *curves);
  row rows[LEVELS_MAX + 2];
  if (!curves) return fprintf(stderr, "tactus: out of memory\n"), 1;
  printf("study skin-accuracy (%s path, %d levels): pierce-down at 1 cm/s, HIP r = 0.5 mm, 0.4 cm skin, 26 rays; "
         "force %.1f mm below first contact; tears at %.0f N/m over %.0f mm; sag: mean over %.1f to %.1f s hanging\n",
         o.quick ? "quick" : "full", nlev, o.depth * 1e3, RUPTURE_T, RUPTURE_L * 1e3, 1 + SAG_AFTER_S - SAG_WINDOW_S, 1 + SAG_AFTER_S);
  printf("  %-22s %-8s %7s %5s %7s %8s %9s %8s | %9s %6s | %9s %6s | %8s %6s | %8s %6s\n", "setting", "solver", "dx mm", "iter",
         "1/dt Hz", "edge m", "CPU s/s", "wall s", "F_ind mN", "err %", "F_rup mN", "err %", "d_rup mm", "err %",
         "sag mm", "err %");
  int rc = 0;
  for (int i = 0; i < nset && rc == 0; i++) {
    memset(&rows[i], 0, sizeof rows[i]);
    rc = run_setting(&set[i], set[i].hip_offset != 0 ? offset_device : device, duration, o.depth, &curves[i], &rows[i]);
    for (int k = 0; k < NQ; k++) rows[i].err[k] = NAN;
    if (rc == 0) print_row(&set[i], &rows[i]); // progress: the errors come once the path is done
    fflush(stdout);
  }

  // convergence of each quantity along the path; every setting against its reference
  tx_convergence conv[NQ];
  if (rc == 0) {
    for (int k = 0; k < NQ; k++) {
      double q[LEVELS_MAX], e[LEVELS_MAX];
      for (int l = 0; l < nlev; l++) q[l] = rows[l].q[k];
      conv[k] = tx_converge(q, nlev, 2, e);
      for (int l = 0; l < nlev; l++) rows[l].err[k] = e[l];
      double ref = conv[k].reference;
      for (int i = nlev; i < nset; i++) rows[i].err[k] = ref != 0 ? fabs(rows[i].q[k] - ref) / fabs(ref) : NAN;
    }
    printf("\nagainst the reference:\n");
    for (int i = 0; i < nset; i++) print_row(&set[i], &rows[i]);
    printf("\n  %-22s %-12s %8s %14s %12s %16s %16s\n", "quantity", "status", "order p", "reference", "error falls",
           "real-time error", "(particle/cell)");
    for (int k = 0; k < NQ; k++) {
      const row* part = over_particle(&set[nlev]) ? &rows[nlev] : &rows[nlev + 1];
      const row* cell = over_particle(&set[nlev]) ? &rows[nlev + 1] : &rows[nlev];
      printf("  %-22s %-12s %8.2f %11.4f %-2s %12s %15.2f%% %7.2f%%/%.2f%%\n", q_label[k],
             tx_conv_status_name(conv[k].status), conv[k].p, conv[k].reference * 1e3, k >= 2 ? "mm" : "mN",
             conv[k].monotone ? "yes" : "NO", 100 * real_time_error(rows, nset, k), 100 * part->err[k], 100 * cell->err[k]);
    }
    rc = write_outputs(a->out_dir, set, rows, curves, nset, conv, &o, motion->name);
  }
  if (rc == 0) {
    bool plotted = write_plot(a->out_dir, set, rows, nlev) == 0;
    if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
    bool all = true;
    for (int k = 0; k < NQ; k++) all &= conv[k].monotone;
    printf("\n%s\nwrote %s/skin-accuracy.json, .csv, skin-accuracy-curves.csv%s\n",
           all ? "every quantity converges, its error falling at every level"
               : "some quantity does NOT converge along the path (status above): its error is against the finest level",
           a->out_dir, plotted ? " and skin-accuracy.png" : "");
  }
  free(curves);
  return rc;
}

#else

int tx_study_skin_accuracy(const tx_study_args* a) {
  (void)a;
  return tx_bad_input("study skin-accuracy: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
}

#endif
