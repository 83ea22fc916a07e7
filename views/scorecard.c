// view.scorecard: a procedure's steps and measures, kept as they are
// published and written as OUT/scorecard.json and .png when the run ends
// (scorecard.h).
#include "scorecard.h"

#include "plot.h"

#include <tactus/components.h>
#include <tactus/config.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STEPS_MAX 16

typedef struct scorecard {
  char scenario[64];
  char procedure[64];
  tx_port steps, names, suture, lagb, paths;
  bool is_lagb;  // the measures are procedure.lagb's (PREFIX.lagb, PREFIX.step_paths), not procedure.suture's
  tx_procedure_step_state step[STEPS_MAX];
  tx_procedure_step name[STEPS_MAX];
  tx_step_path path[STEPS_MAX];
  int nsteps, npaths;
  tx_suture_measures m;
  tx_lagb_measures lm;
  bool have_m;
  double bite_tolerance;  // m
  double damage_tolerance; // m^3
  tx_result done_r;
} scorecard;

static const tx_param_def params[] = {
    {"procedure", TX_PARAM_STR, NULL, 0, 0, 0, "procedure",
     "the procedure controller's prefix: PREFIX.steps, PREFIX.step_names, and PREFIX.suture or PREFIX.lagb"},
    {"measures", TX_PARAM_STR, NULL, 0, 0, 0, "suture",
     "whose measures: \"suture\" (procedure.suture's PREFIX.suture) or \"lagb\" (procedure.lagb's PREFIX.lagb and PREFIX.step_paths)"},
    {"damage_tolerance_m3", TX_PARAM_NUM, "m^3", 0, 1e-3, 0, NULL,
     "lagb: a burn outside the target is thermal damage (Omega > 1) in the organs above this volume"},
    {"scenario", TX_PARAM_STR, NULL, 0, 0, 0, "", "the scenario's name, written into the scorecard"},
    {"bite_tolerance_m", TX_PARAM_NUM, "m", 0, 0.01, 0.001, NULL,
     "the two bites of a stitch are symmetric when their distances from the wound differ by at most this much"},
};

static int configure(tx_setup* s, void** self) {
  scorecard* v = calloc(1, sizeof *v);
  if (!v) return -1;
  *self = v;
  const char* prefix = tx_table_str(s, "procedure");
  const char* scenario = tx_table_str(s, "scenario");
  v->bite_tolerance = tx_table_num(s, "bite_tolerance_m");
  v->damage_tolerance = tx_table_num(s, "damage_tolerance_m3");
  const char* measures = tx_table_str(s, "measures");
  if (!prefix || !scenario || !measures) return -1;
  if (strcmp(measures, "suture") && strcmp(measures, "lagb")) return tx_setup_fail(s, "measures", "expected \"suture\" or \"lagb\", not '%s'", measures);
  v->is_lagb = !strcmp(measures, "lagb");
  if (!*prefix || strlen(prefix) >= 48) return tx_setup_fail(s, "procedure", "expected a prefix of 1 to 47 characters");
  snprintf(v->procedure, sizeof v->procedure, "%s", prefix);
  snprintf(v->scenario, sizeof v->scenario, "%s", scenario);
  char name[80];
  snprintf(name, sizeof name, "%s.steps", prefix);
  v->steps = TX_READ_OF(s, name, tx_procedure_step_state);
  snprintf(name, sizeof name, "%s.step_names", prefix);
  v->names = TX_READ_OF(s, name, tx_procedure_step);
  if (v->is_lagb) {
    snprintf(name, sizeof name, "%s.lagb", prefix);
    v->lagb = TX_READ_OF(s, name, tx_lagb_measures);
    snprintf(name, sizeof name, "%s.step_paths", prefix);
    v->paths = TX_READ_OF(s, name, tx_step_path);
  } else {
    snprintf(name, sizeof name, "%s.suture", prefix);
    v->suture = TX_READ_OF(s, name, tx_suture_measures);
  }
  v->done_r = tx_setup_result(s, "steps_done");
  return 0;
}

// keep the latest of each, so the scorecard is the last one published
static void step(tx_ctx* c, void* self) {
  scorecard* v = self;
  tx_snapshot st = tx_read(c, v->steps), nm = tx_read(c, v->names);
  if (st.seq && nm.seq) {
    int n = (int)(st.rows < nm.rows ? st.rows : nm.rows);
    v->nsteps = n < STEPS_MAX ? n : STEPS_MAX;
    memcpy(v->step, st.data, (size_t)v->nsteps * sizeof v->step[0]);
    memcpy(v->name, nm.data, (size_t)v->nsteps * sizeof v->name[0]);
  }
  if (v->is_lagb) {
    tx_snapshot ms = tx_read(c, v->lagb), ps = tx_read(c, v->paths);
    if (ms.seq) v->lm = *(const tx_lagb_measures*)ms.data, v->have_m = true;
    if (ps.seq) {
      v->npaths = (int)(ps.rows < STEPS_MAX ? ps.rows : STEPS_MAX);
      memcpy(v->path, ps.data, (size_t)v->npaths * sizeof v->path[0]);
    }
  } else {
    tx_snapshot ms = tx_read(c, v->suture);
    if (ms.seq) v->m = *(const tx_suture_measures*)ms.data, v->have_m = true;
  }
}

static json_t* number_or_null(double x) { return isfinite(x) ? json_real(x) : json_null(); }

static void measure(json_t* root, const char* key, double value, const char* unit, const char* rule) {
  json_object_set_new(root, key, json_pack("{s:o, s:s, s:s}", "value", number_or_null(value), "unit", unit, "rule", rule));
}

static const char* const status_names[] = {"not reached", "under way", "done", "skipped"};

// procedure.lagb's measures: the band, the force on each organ, the burns
static json_t* build_lagb(const scorecard* v, json_t* root) {
  const tx_lagb_measures* m = &v->lm;
  json_object_set_new(
      root, "band",
      json_pack("{s:b, s:b, s:i, s:o, s:o, s:s}", "locked", m->locked > 0.5, "encircles_stomach", m->encircles > 0.5, "linking_number",
                (int)m->linking, "from_gej_m", number_or_null(m->band_from_gej_m), "off_axis_m", number_or_null(m->band_off_axis_m), "rule",
                "locked: the tube's tip latched in the buckle; encircles_stomach: the tube's tip near the buckle (procedure.lagb's "
                "around_m) and the band's centre line, closed there, winding once round the stomach's axis (linking number "
                "+-1); from_gej_m: its centre from the gastro-oesophageal "
                "junction along the axis, + toward the stomach; off_axis_m: from the axis"));
  measure(root, "path_hand0_m", m->path_m[0], "m", "the path length of hand 0's tool point: economy of motion (OSATS, time and motion)");
  measure(root, "path_hand1_m", m->path_m[1], "m", "the path length of hand 1's tool point");
  measure(root, "liver_force_max_n", m->liver_force_max_n, "N", "the largest pull of the liver on a grasper holding it");
  measure(root, "stomach_force_max_n", m->stomach_force_max_n, "N", "the largest pull of the stomach on a grasper holding it");
  measure(root, "damage_outside_target_m3", m->damage_outside_m3, "m^3",
          "thermal damage outside the membranes the dissection divides: the liver's and the stomach's volume with Arrhenius Omega > 1");
  json_object_set_new(root, "burn_outside_target",
                      isfinite(m->damage_outside_m3) ? json_boolean(m->damage_outside_m3 > v->damage_tolerance) : json_null());
  return root;
}

static json_t* build(const scorecard* v) {
  json_t* root = json_object();
  json_object_set_new(root, "scenario", json_string(v->scenario));
  json_object_set_new(root, "procedure", json_string(v->procedure));
  json_t* steps = json_array();
  for (int i = 0; i < v->nsteps; i++) {
    char id[8] = "", nm[64] = "";
    const char* text = v->name[i].text;
    size_t len = strnlen(text, sizeof v->name[i].text);
    const char* space = memchr(text, ' ', len);
    size_t idlen = space ? (size_t)(space - text) : len;
    snprintf(id, sizeof id, "%.*s", (int)(idlen < 7 ? idlen : 7), text);
    if (space) snprintf(nm, sizeof nm, "%.*s", (int)(len - idlen - 1), space + 1);
    int status = (int)v->step[i].status;
    if (status < 0 || status > 3) status = 0;
    json_t* entry = json_pack("{s:s, s:s, s:b, s:s, s:o, s:o}", "id", id, "name", nm, "done", status == TX_STEP_DONE, "status",
                              status_names[status], "t_start_s", number_or_null(v->step[i].t_start_s), "t_end_s",
                              number_or_null(v->step[i].t_end_s));
    if (i < v->npaths)
      json_object_set_new(entry, "path_m", json_pack("[o, o]", number_or_null(v->path[i].path_m[0]), number_or_null(v->path[i].path_m[1])));
    json_array_append_new(steps, entry);
  }
  json_object_set_new(root, "steps", steps);
  if (!v->have_m) return root;
  if (v->is_lagb) return build_lagb(v, root);
  const tx_suture_measures* m = &v->m;
  measure(root, "bite_entry_m", m->bite_entry_m, "m",
          "the stitch's entry puncture from the wound line, across the skin; bites are placed 3-5 mm from the edge");
  measure(root, "bite_exit_m", m->bite_exit_m, "m", "its exit puncture, on the other edge, from the wound line");
  double asym = fabs(m->bite_entry_m - m->bite_exit_m);
  measure(root, "bite_asymmetry_m", asym, "m",
          "the difference of the two bites; the two sides of a simple interrupted stitch are placed symmetrically");
  json_object_set_new(root, "bite_symmetric", isfinite(asym) ? json_boolean(asym <= v->bite_tolerance) : json_null());
  measure(root, "punctures", m->punctures, "1", "punctures the needle made");
  measure(root, "knots", m->knots, "1", "knots found by the suturing papers' rule (10 colliding cylinders in two blocks)");
  measure(root, "knots_fixed", m->knots_fixed, "1", "knots fixed at the skin: within the thread's fix distance of it");
  measure(root, "peak_tension_n", m->peak_tension_n, "N", "the thread's largest tension at the needle (its force model's F0)");
  measure(root, "path_hand0_m", m->path_m[0], "m", "the path length of hand 0's tool point: economy of motion (OSATS, time and motion)");
  measure(root, "path_hand1_m", m->path_m[1], "m", "the path length of hand 1's tool point");
  json_object_set_new(root, "wound_gap_m",
                      json_pack("{s:o, s:o, s:s, s:s}", "before", number_or_null(m->wound_gap_before_m), "after",
                                number_or_null(m->wound_gap_after_m), "unit", "m", "rule",
                                "the distance across the wound where the stitch crosses it, between its two edges' skin "
                                "nearest there: as the run found the skin, and at its end; a stitch draws the edges together "
                                "(at rest the edges are a particle spacing apart: compare after with before)"));
  measure(root, "tissue_force_max_n", m->tissue_force_max_n, "N",
          "the largest force of the skin on the needle's tip; OSATS's respect for tissue asks for no unnecessary force");
  measure(root, "tears", m->tears, "1", "links the skin tore (the punctures' own included), the wound's cut not counted");
  measure(root, "tears_pulled", m->tears_pulled, "1",
          "of them, the links a pull tore (the thread's or the jaws'), away from the needle's tip: a stitch pulled too "
          "hard tears out; OSATS's respect for tissue");
  return root;
}

// the steps against time: a bar per step from its start to its end
static int plot(const scorecard* v, const char* path) {
  double xs[STEPS_MAX][2], ys[STEPS_MAX][2];
  char labels[STEPS_MAX][72];
  tx_plot_series s[STEPS_MAX];
  int n = 0;
  for (int i = 0; i < v->nsteps && n < TX_PLOT_SERIES_MAX; i++) {
    if (!isfinite(v->step[i].t_start_s) || !isfinite(v->step[i].t_end_s)) continue;
    xs[n][0] = v->step[i].t_start_s, xs[n][1] = v->step[i].t_end_s;
    ys[n][0] = ys[n][1] = v->nsteps - i;
    bool done = v->step[i].status == TX_STEP_DONE;
    snprintf(labels[n], sizeof labels[n], "%.*s (%s)", 60, v->name[i].text, done ? "done" : "skipped");
    // a step that began and ended at once (skipped by a later step's event) is a marker, not an empty bar
    bool instant = xs[n][1] <= xs[n][0];
    s[n] = (tx_plot_series){labels[n], xs[n], ys[n], instant ? 1 : 2, instant, done ? 1 + n % 14 : 15};
    n++;
  }
  if (n == 0) return 0;
  tx_plot p = {"the procedure's steps", "time (s)", "step (the first at the top)", false, false, s, n};
  return tx_plot_png(path, &p);
}

static void finish(tx_ctx* c, void* self) {
  scorecard* v = self;
  step(c, v);
  int done = 0;
  for (int i = 0; i < v->nsteps; i++) done += v->step[i].status == TX_STEP_DONE;
  tx_set_result(c, v->done_r, done);
  const char* dir = tx_output_dir(c);
  if (!dir) return;
  char path[4200], tmp[4300];
  snprintf(path, sizeof path, "%s/scorecard.json", dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  json_t* root = build(v);
  int bad = json_dump_file(root, tmp, JSON_INDENT(2) | JSON_REAL_PRECISION(9)) != 0 || rename(tmp, path) != 0;
  json_decref(root);
  if (bad) {
    remove(tmp);
    tx_stop_run(c, "%s: cannot be written", path);
    return;
  }
  snprintf(path, sizeof path, "%s/scorecard.png", dir);
  if (TX_WITH_PLPLOT && plot(v, path)) tx_stop_run(c, "%s", tx_error()); // a build without PLplot keeps the JSON
}

static void fini(void* self) { free(self); }

const tx_controller_class tx_view_scorecard = {
    .type = "view.scorecard",
    .summary = "a procedure's scorecard: its steps and measures, written as scorecard.json and scorecard.png",
    .configure = configure,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
    .view = true,
};
