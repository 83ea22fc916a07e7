// procedure.lagb: phases 2 and 3 of gastric banding and the measures of its
// scorecard, from what the organs, membranes, cautery and band publish
// (lagb_controller.h, docs/lagb.md).
#include "lagb_controller.h"

#include "lagb_steps.h"
#include "../system.h" // tx_param_json, tx_param_point

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HANDS 2
#define GRASP_HANDS 4  // rows of organs.grasp read (physics.organs' most)
#define AXIS_MAX 32    // points of the stomach's axis
#define LOOP_MAX 1024  // rows of band.centre read
enum { NO_ORGAN = -1, LIVER, STOMACH };
enum { PARS, HIS, MEMBRANES };

typedef struct lagb {
  tx_lagb_steps steps;
  double retract, opening, around; // m
  double axis[3 * AXIS_MAX];       // m, the stomach's axis, from the oesophagus down
  int naxis;
  double gej_along;                // m, the junction's arc length along the axis
  tx_port hand[HANDS], organ_events, organ_grasp, organ_x[2], membrane[MEMBRANES], band_state, band_centre, tissue;
  int nhands;
  tx_port out_step, out_steps, out_names, out_paths, out_measures, out_events;
  tx_result done_r, step_r[TX_LAGB_STEPS];
  // what has been seen
  int held[GRASP_HANDS];           // the organ each grasper holds, NO_ORGAN none
  bool taken[GRASP_HANDS];         // the pivot where it took hold is known
  double taken_at[GRASP_HANDS][3]; // m
  double last_hand[HANDS][3];
  bool hand_seen[HANDS];
  tx_step_path path[TX_LAGB_STEPS];
  tx_lagb_measures m;
} lagb;

// the phantom's stomach centre line (tools/lagb/volume.c: oesophagus, cardia,
// body, antrum), the oesophagus carried 6 cm further up so that a band round
// it is well inside the polyline's ends
static const double default_axis[][3] = {
    {-0.012, -0.052, 0.195}, {-0.015, -0.050, 0.135}, {-0.022, -0.045, 0.100}, {-0.032, -0.040, 0.075},
    {-0.058, -0.025, 0.045}, {-0.058, -0.008, 0.005}, {-0.040, 0.004, -0.040}, {-0.005, 0.010, -0.062},
};
// between the abdominal oesophagus and the cardia of the phantom
static const double default_gej[3] = {-0.027, -0.0425, 0.0875};

static const tx_param_def params[] = {
    {"hands", TX_PARAM_STRS, NULL, 0, HANDS, 0, NULL, "each hand's pose (tx_pose) for its path length; [\"device0.pose\", \"device1.pose\"] by default"},
    {"organ_events", TX_PARAM_STR, NULL, 0, 0, 0, "organs.events", "the organs' grasps and releases (physics.organs); empty: none"},
    {"organ_grasp", TX_PARAM_STR, NULL, 0, 0, 0, "organs.grasp", "the organs' pull on each grasper (tx_organ_grasp rows); empty: none"},
    {"membranes", TX_PARAM_STRS, NULL, 0, MEMBRANES, 0, NULL,
     "the pars flaccida's and the angle of His's membranes (physics.membrane names: NAME.state); [\"pars_flaccida\", \"his\"] by default"},
    {"band", TX_PARAM_STR, NULL, 0, 0, 0, "band", "the band's prefix: band.state and band.centre (physics.band); empty: none"},
    {"tissue", TX_PARAM_STR, NULL, 0, 0, 0, "cautery.tissue", "the organs' thermal damage (physics.cautery); empty: none"},
    {"retract_m", TX_PARAM_NUM, "m", 0.001, 0.1, 0.01, NULL, "2a is done once a grasper holding the liver has carried it this far"},
    {"opening_m", TX_PARAM_NUM, "m", 0.001, 0.1, 0.01, NULL, "2b, 2c: a membrane is divided once its largest hole is this long (a 5 mm grasper and the band pass)"},
    {"around_m", TX_PARAM_NUM, "m", 0.001, 0.1, 0.02, NULL,
     "the band encircles the stomach (and 3b is done) once its loop goes round the stomach's axis with the tube's tip this near the buckle"},
    {"stomach_axis_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL,
     "[[x, y, z], ...], m: the stomach's axis from above the oesophagus down (2 to 32 points); the phantom's centre line by default"},
    {"gej_m", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "[x, y, z], m: the gastro-oesophageal junction; the phantom's by default"},
};

static tx_port optional_read(tx_setup* s, const char* name, tx_type type, uint32_t cols) {
  return name && *name ? tx_setup_read_as(s, name, type, cols) : (tx_port){0};
}

static int read_axis(tx_setup* s, lagb* k) {
  json_t* j = tx_param_json(s, "stomach_axis_m");
  if (!j || json_is_null(j)) {
    k->naxis = (int)(sizeof default_axis / sizeof default_axis[0]);
    memcpy(k->axis, default_axis, sizeof default_axis);
    return 0;
  }
  if (!json_is_array(j) || json_array_size(j) < 2 || json_array_size(j) > AXIS_MAX)
    return tx_setup_fail(s, "stomach_axis_m", "expected a list of 2 to %d points [x, y, z], m", AXIS_MAX);
  k->naxis = (int)json_array_size(j);
  for (int i = 0; i < k->naxis; i++) {
    json_t* p = json_array_get(j, (size_t)i);
    for (int a = 0; a < 3; a++) {
      json_t* v = json_is_array(p) && json_array_size(p) == 3 ? json_array_get(p, (size_t)a) : NULL;
      double x = v && json_is_number(v) ? json_number_value(v) : NAN;
      if (!(fabs(x) <= 10)) return tx_setup_fail(s, "stomach_axis_m", "point %d: expected [x, y, z], each within 10 m", i);
      k->axis[3 * i + a] = x;
    }
  }
  return 0;
}

static int configure(tx_setup* s, void** self) {
  lagb* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  k->retract = tx_table_num(s, "retract_m");
  k->opening = tx_table_num(s, "opening_m");
  k->around = tx_table_num(s, "around_m");
  double gej[3];
  if (read_axis(s, k) || tx_param_point(s, "gej_m", default_gej, gej)) return -1;
  k->gej_along = tx_lagb_along(k->axis, k->naxis, gej, NULL);

  const char* hands[HANDS];
  k->nhands = tx_table_strs(s, "hands", hands, HANDS);
  if (k->nhands == 0) hands[0] = "device0.pose", hands[1] = "device1.pose", k->nhands = HANDS;
  for (int h = 0; h < k->nhands; h++) k->hand[h] = optional_read(s, hands[h], tx_pose_TYPE, tx_pose_COLS);
  const char* ev = tx_table_str(s, "organ_events");
  if (ev && *ev) k->organ_events = tx_setup_listen(s, ev);
  k->organ_grasp = optional_read(s, tx_table_str(s, "organ_grasp"), tx_organ_grasp_TYPE, tx_organ_grasp_COLS);
  if (k->organ_events.id) {
    k->organ_x[LIVER] = TX_READ_OF(s, "liver.x", tx_vertex);
    k->organ_x[STOMACH] = TX_READ_OF(s, "stomach.x", tx_vertex);
  }
  const char* mem[MEMBRANES];
  int nm = tx_table_strs(s, "membranes", mem, MEMBRANES);
  if (nm == 0) mem[PARS] = "pars_flaccida", mem[HIS] = "his", nm = MEMBRANES;
  if (nm != MEMBRANES) return tx_setup_fail(s, "membranes", "expected two names: the pars flaccida's membrane, then the angle of His's");
  char name[TX_NAME_MAX + 16];
  for (int i = 0; i < MEMBRANES; i++) {
    snprintf(name, sizeof name, "%s.state", mem[i]);
    k->membrane[i] = TX_READ_OF(s, name, tx_membrane_state);
  }
  const char* band = tx_table_str(s, "band");
  if (band && *band) {
    snprintf(name, sizeof name, "%s.state", band);
    k->band_state = TX_READ_OF(s, name, tx_band_state);
    snprintf(name, sizeof name, "%s.centre", band);
    k->band_centre = TX_READ_OF(s, name, tx_vertex);
  }
  k->tissue = optional_read(s, tx_table_str(s, "tissue"), tx_tissue_damage_TYPE, tx_tissue_damage_COLS);

  const char* me = tx_setup_name(s);
  snprintf(name, sizeof name, "%s.step", me);
  k->out_step = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_procedure_step, 1));
  snprintf(name, sizeof name, "%s.steps", me);
  k->out_steps = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_procedure_step_state, TX_LAGB_STEPS));
  snprintf(name, sizeof name, "%s.step_names", me);
  k->out_names = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_procedure_step, TX_LAGB_STEPS));
  snprintf(name, sizeof name, "%s.step_paths", me);
  k->out_paths = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_step_path, TX_LAGB_STEPS));
  snprintf(name, sizeof name, "%s.lagb", me);
  k->out_measures = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_lagb_measures, 1));
  snprintf(name, sizeof name, "%s.events", me);
  k->out_events = tx_setup_emit(s, name, 64);
  k->done_r = tx_setup_result(s, "steps_done");
  for (int i = 0; i < TX_LAGB_STEPS; i++) {
    snprintf(name, sizeof name, "step_%s", tx_lagb_step_id(i));
    k->step_r[i] = tx_setup_result(s, name);
  }
  return 0;
}

static int init(tx_ctx* c, void* self) {
  (void)c;
  lagb* k = self;
  tx_lagb_steps_start(&k->steps, 0);
  for (int h = 0; h < GRASP_HANDS; h++) k->held[h] = NO_ORGAN, k->taken[h] = false;
  memset(k->hand_seen, 0, sizeof k->hand_seen);
  memset(k->path, 0, sizeof k->path);
  k->m = (tx_lagb_measures){.damage_outside_m3 = NAN, .band_from_gej_m = NAN, .band_off_axis_m = NAN};
  return 0;
}

// the organ whose published surface has a vertex nearest p
static int organ_at(tx_ctx* c, const lagb* k, const double p[3]) {
  int best = NO_ORGAN;
  double d2min = INFINITY;
  for (int o = LIVER; o <= STOMACH; o++) {
    tx_snapshot x = tx_read(c, k->organ_x[o]);
    const float* v = x.seq ? ((const tx_vertex*)x.data)->x : NULL;
    for (uint32_t i = 0; v && i < x.rows; i++) {
      double d2 = 0;
      for (int a = 0; a < 3; a++) d2 += (v[3 * i + a] - p[a]) * (v[3 * i + a] - p[a]);
      if (d2 < d2min) d2min = d2, best = o;
    }
  }
  return best;
}

// 2a: a grasper holding the liver has carried it retract_m; the organs' pull
// on each grasper, by the organ it holds
static void follow_grasps(tx_ctx* c, lagb* k, double t) {
  tx_event e;
  if (k->organ_events.id)
    while (tx_next_event(c, k->organ_events, &e)) {
      if (e.source >= GRASP_HANDS) continue;
      if (e.kind == TX_EVENT_GRASP) k->held[e.source] = organ_at(c, k, e.grasp.point), k->taken[e.source] = false;
      else if (e.kind == TX_EVENT_RELEASE) k->held[e.source] = NO_ORGAN;
    }
  if (!k->organ_grasp.id) return;
  tx_snapshot g = tx_read(c, k->organ_grasp);
  const tx_organ_grasp* rows = g.data;
  for (uint32_t h = 0; g.seq && h < g.rows && h < GRASP_HANDS; h++) {
    if (k->held[h] == NO_ORGAN || !(rows[h].nodes > 0)) continue;
    if (!k->taken[h]) memcpy(k->taken_at[h], rows[h].x, sizeof k->taken_at[h]), k->taken[h] = true;
    const double* f = rows[h].f;
    double pull = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    double* max = k->held[h] == LIVER ? &k->m.liver_force_max_n : &k->m.stomach_force_max_n;
    if (isfinite(pull)) *max = fmax(*max, pull);
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (rows[h].x[a] - k->taken_at[h][a]) * (rows[h].x[a] - k->taken_at[h][a]);
    if (k->held[h] == LIVER && sqrt(d2) >= k->retract) tx_lagb_steps_done_at(&k->steps, TX_LAGB_RETRACT, t);
  }
}

// 2b, 2c: each membrane divided; 3a: a tool has passed through both holes
static void follow_membranes(tx_ctx* c, lagb* k, double t) {
  bool passed = true;
  for (int i = 0; i < MEMBRANES; i++) {
    tx_snapshot s = tx_read(c, k->membrane[i]);
    const tx_membrane_state* m = s.seq ? s.data : NULL;
    if (m && m->opening_m >= k->opening) tx_lagb_steps_done_at(&k->steps, i == PARS ? TX_LAGB_PARS : TX_LAGB_HIS, t);
    passed = passed && m && m->passes >= 1;
  }
  if (passed) tx_lagb_steps_done_at(&k->steps, TX_LAGB_BEHIND, t);
}

// 3b, 3c: the band's loop round the stomach's axis, and locked so
static void follow_band(tx_ctx* c, lagb* k, double t) {
  if (!k->band_state.id) return;
  tx_snapshot st = tx_read(c, k->band_state), ce = tx_read(c, k->band_centre);
  if (!st.seq || !ce.seq || ce.rows < 3 || ce.rows > LOOP_MAX) return;
  const tx_band_state* b = st.data;
  const float* loop = ((const tx_vertex*)ce.data)->x;
  int lk = tx_lagb_linking(loop, (int)ce.rows, k->axis, k->naxis);
  k->m.linking = lk;
  // round it only with the loop closed by the band itself: the chord from a
  // tip far from the buckle could close it round anything (at the start, the
  // tube's tip 15 cm off to the left gives +1 already)
  k->m.encircles = abs(lk) == 1 && b->tip_to_buckle <= k->around;
  k->m.locked = b->locked > 0.5;
  double mid[3] = {0, 0, 0};
  for (uint32_t i = 0; i < ce.rows; i++)
    for (int a = 0; a < 3; a++) mid[a] += loop[3 * i + a] / ce.rows;
  k->m.band_from_gej_m = tx_lagb_along(k->axis, k->naxis, mid, &k->m.band_off_axis_m) - k->gej_along;
  if (k->m.encircles) tx_lagb_steps_done_at(&k->steps, TX_LAGB_AROUND, t);
  if (k->m.encircles && k->m.locked) tx_lagb_steps_done_at(&k->steps, TX_LAGB_LOCK, t);
}

static void follow_hands(tx_ctx* c, lagb* k) {
  for (int h = 0; h < k->nhands; h++) {
    if (!k->hand[h].id) continue;
    tx_snapshot s = tx_read(c, k->hand[h]);
    if (!s.seq) continue;
    const double* p = ((const tx_pose*)s.data)->pos;
    if (!isfinite(p[0] + p[1] + p[2])) continue;
    if (k->hand_seen[h]) {
      double d = 0;
      for (int a = 0; a < 3; a++) d += (p[a] - k->last_hand[h][a]) * (p[a] - k->last_hand[h][a]);
      d = sqrt(d);
      k->m.path_m[h] += d;
      for (int i = 0; i < TX_LAGB_STEPS; i++)
        if (k->steps.step[i].status == TX_STEP_UNDER_WAY) k->path[i].path_m[h] += d;
    }
    memcpy(k->last_hand[h], p, sizeof k->last_hand[h]);
    k->hand_seen[h] = true;
  }
}

static void step(tx_ctx* c, void* self) {
  lagb* k = self;
  double t = (double)tx_sim_ns(c) * 1e-9;
  tx_procedure_step_state before[TX_LAGB_STEPS];
  memcpy(before, k->steps.step, sizeof before);
  if (tx_step_index(c) == 0) before[TX_LAGB_RETRACT].status = TX_STEP_NOT_REACHED; // 2a's start goes out with the first step
  follow_hands(c, k);
  follow_grasps(c, k, t);
  follow_membranes(c, k, t);
  follow_band(c, k, t);
  if (k->tissue.id) {
    tx_snapshot s = tx_read(c, k->tissue);
    const tx_tissue_damage* d = s.data;
    if (s.seq && s.rows >= 2) k->m.damage_outside_m3 = d[0].damaged_m3 + d[1].damaged_m3;
  }
  for (int i = 0; i < TX_LAGB_STEPS; i++) {
    if (before[i].status == k->steps.step[i].status) continue;
    tx_event e = {.kind = TX_EVENT_STEP, .source = (uint32_t)i};
    e.value[0] = k->steps.step[i].status;
    tx_emit(c, k->out_events, &e);
  }
  tx_procedure_step* text = tx_write(c, k->out_step);
  int i = tx_lagb_steps_current(&k->steps);
  if (i < TX_LAGB_STEPS) snprintf(text->text, sizeof text->text, "%d/%d %s %s", i + 1, TX_LAGB_STEPS, tx_lagb_step_id(i), tx_lagb_step_name(i));
  else snprintf(text->text, sizeof text->text, "done: %d of %d steps", tx_lagb_steps_done(&k->steps), TX_LAGB_STEPS);
  memcpy(tx_write(c, k->out_steps), k->steps.step, sizeof k->steps.step);
  tx_procedure_step* names = tx_write(c, k->out_names);
  for (int n = 0; n < TX_LAGB_STEPS; n++) snprintf(names[n].text, sizeof names[n].text, "%s %s", tx_lagb_step_id(n), tx_lagb_step_name(n));
  memcpy(tx_write(c, k->out_paths), k->path, sizeof k->path);
  *(tx_lagb_measures*)tx_write(c, k->out_measures) = k->m;
}

static void finish(tx_ctx* c, void* self) {
  lagb* k = self;
  tx_set_result(c, k->done_r, tx_lagb_steps_done(&k->steps));
  for (int i = 0; i < TX_LAGB_STEPS; i++) tx_set_result(c, k->step_r[i], k->steps.step[i].status);
}

static void fini(void* self) { free(self); }

const tx_controller_class tx_procedure_lagb = {
    .type = "procedure.lagb",
    .summary = "phases 2 and 3 of gastric banding (dissection, band placement) and their scorecard's measures, from the organs, "
               "membranes, cautery and band",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
