// The trainer's panels: the run's controls (pause, resume, single step,
// reset, time scale), what each controller does live (rate, jitter,
// deadlines missed), its live parameters, and each device's force and
// position as scrolling plots, for the system tx_system_run is running.
#include "gui.h"
#include "gui_inspect.h"
#include "gui_series.h"

#include "../../controllers/system.h"

#include <tactus/model.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define RATE_WINDOW_NS 500000000 // the live rate is counted over half a second
#define MAX_SHOWN 64             // controllers listed

static struct {
  tx_system* sys;                  // the one the rates below belong to
  int64_t since_ns;                // start of the current counting window
  uint64_t steps_then[MAX_SHOWN];  // each one's steps at since_ns
  double hz[MAX_SHOWN];            // over the last whole window
} live;

static void count_rates(tx_system* s, int n) {
  int64_t now = tx_mono_ns();
  if (live.sys != s) {
    live.sys = s;
    live.since_ns = now;
    for (int i = 0; i < n; i++) live.steps_then[i] = tx_system_live(s, i).steps, live.hz[i] = 0;
    return;
  }
  if (now - live.since_ns < RATE_WINDOW_NS) return;
  for (int i = 0; i < n; i++) {
    uint64_t steps = tx_system_live(s, i).steps;
    live.hz[i] = (double)(steps - live.steps_then[i]) * 1e9 / (double)(now - live.since_ns);
    live.steps_then[i] = steps;
  }
  live.since_ns = now;
}

static tx_series_set series; // the devices' force and position, one sample per frame

void tx_gui_sample(const char* device, double t_s, const double pos[3], const double* force) {
  (void)tx_series_push(&series, device, t_s, pos, force); // a fifth device is not plotted
}

static void device_plots(void) {
  if (series.count == 0) tx_gui_text("no device drawn");
  for (int d = 0; d < series.count; d++) {
    const tx_series* e = &series.dev[d];
    int last = (e->next + TX_SERIES_LEN - 1) % TX_SERIES_LEN, off = tx_series_offset(e);
    char label[64];
    if (e->has_force) {
      tx_gui_text("%s F (%.2f, %.2f, %.2f) N", e->name, e->fxyz[0], e->fxyz[1], e->fxyz[2]);
      snprintf(label, sizeof label, "|F| N##%s", e->name);
      tx_gui_plot(label, e->force, e->count, off, 40);
    }
    tx_gui_text("%s at (%.1f, %.1f, %.1f) mm", e->name, e->pos[0][last], e->pos[1][last], e->pos[2][last]);
    snprintf(label, sizeof label, "y mm##%s", e->name);
    tx_gui_plot(label, e->pos[1], e->count, off, 40);
  }
}

static struct {
  bool known;    // the run has a procedure.step
  char text[72];
} procedure;

void tx_gui_procedure(const char* text) {
  procedure.known = text != NULL;
  snprintf(procedure.text, sizeof procedure.text, "%s", text ? text : "");
}

// each component's publish number, its age (wall clock) and the simulation time of its latest publish
#define ROWS_MAX 256
static void components_table(tx_system* s) {
  static tx_component_row rows[ROWS_MAX];
  int n = tx_inspect_components(tx_system_model(s), tx_mono_ns(), rows, ROWS_MAX);
  if (!tx_gui_table_begin("components", 4)) return;
  static const char* const head[] = {"name", "seq", "age ms", "at s"};
  tx_gui_table_row(head, 4);
  for (int i = 0; i < n; i++) {
    char seq[32], age[32], at[32];
    snprintf(seq, sizeof seq, "%llu", (unsigned long long)rows[i].seq);
    snprintf(age, sizeof age, rows[i].seq ? "%.1f" : "-", rows[i].age_ms);
    snprintf(at, sizeof at, rows[i].seq ? "%.3f" : "-", rows[i].sim_s);
    const char* row[] = {rows[i].name, seq, age, at};
    tx_gui_table_row(row, 4);
  }
  tx_gui_table_end();
}

// the live parameters of each controller (tx_controller_class.live), as the scenario
// gave them or as last set here; every other parameter is fixed for the run
#define TUNE_MAX 64
static struct {
  tx_system* sys;
  int inst[TUNE_MAX], param[TUNE_MAX];
  double value[TUNE_MAX];
  int n;
  char error[256]; // the last refusal, shown under them
} tune;

static void tune_collect(tx_system* s, int n) {
  tune.sys = s;
  tune.n = 0;
  tune.error[0] = 0;
  for (int i = 0; i < n; i++) {
    const tx_controller_class* cls = tx_system_class(s, i);
    for (int p = 0; p < cls->nparams && tune.n < TUNE_MAX; p++) {
      const tx_param_def* d = &cls->params[p];
      if (!tx_param_live(cls, d->key)) continue;
      json_t* given = json_object_get(tx_system_params(s, i), d->key); // read only: configure is long over
      tune.inst[tune.n] = i;
      tune.param[tune.n] = p;
      tune.value[tune.n++] = json_is_number(given) ? json_number_value(given) : json_is_boolean(given) ? json_is_true(given) : d->def_num;
    }
  }
}

static void tune_panel(tx_system* s, int n) {
  if (tune.sys != s) tune_collect(s, n);
  if (tune.n == 0) tx_gui_text("no live parameters");
  for (int k = 0; k < tune.n; k++) {
    const tx_param_def* d = &tx_system_class(s, tune.inst[k])->params[tune.param[k]];
    char label[160];
    snprintf(label, sizeof label, "%s.%s (%s)", tx_system_name(s, tune.inst[k]), d->key, d->units ? d->units : "0/1");
    double v = tune.value[k];
    if (tx_gui_input(label, &v, "%g")) {
      if (tx_system_tune(s, tune.inst[k], d->key, v) == 0) tune.value[k] = v, tune.error[0] = 0;
      else snprintf(tune.error, sizeof tune.error, "%s", tx_error());
    }
  }
  if (tune.error[0]) tx_gui_text("%s", tune.error);
}

// the rest of each controller's table, as the scenario gave it: fixed for the run
static void params_panel(tx_system* s, int n) {
  for (int i = 0; i < n; i++) {
    const tx_controller_class* cls = tx_system_class(s, i);
    char label[160], value[96];
    snprintf(label, sizeof label, "%s (%s)##params%d", tx_system_name(s, i), cls->type, i);
    if (!tx_gui_tree_begin(label)) continue;
    int shown = 0;
    for (int p = 0; cls->params && p < cls->nparams; p++) {
      const tx_param_def* d = &cls->params[p];
      if (tx_param_live(cls, d->key)) continue; // a field above
      tx_param_value_text(d, tx_system_params(s, i), 40, value, sizeof value);
      bool unit = d->units && strcmp(d->units, "1") != 0;
      tx_gui_text("%s = %s%s%s", d->key, value, unit ? " " : "", unit ? d->units : "");
      shown++;
    }
    if (!shown) tx_gui_text(cls->params ? "no fixed parameters" : "no parameter table");
    tx_gui_tree_end();
  }
}

void tx_gui_panels(float eye_w, float eye_h) {
  tx_system* s = tx_system_running();
  if (!tx_gui_begin("tactus", eye_w - 312, 8, 304, eye_h - 16 < 300 ? 300 : eye_h - 16)) {
    tx_gui_end();
    return;
  }
  if (!s) {
    tx_gui_text("no run");
    tx_gui_end();
    return;
  }
  bool paused = tx_system_paused(s);
  tx_gui_text("T %.3f s  %s  x%.2f", tx_system_sim_time(s), paused ? "PAUSED" : "running", tx_system_time_scale(s));
  if (tx_gui_button(paused ? "Resume (P)" : "Pause (P)")) (void)(paused ? tx_system_resume(s) : tx_system_pause(s));
  tx_gui_same_line();
  if (tx_gui_button("Step (N)")) (void)tx_system_step(s);
  tx_gui_same_line();
  if (tx_gui_button("Reset (R)")) (void)tx_system_reset(s);
  double scale = tx_system_time_scale(s);
  if (tx_gui_slider("time scale", &scale, TX_TIME_SCALE_MIN, 1, "x%.2f")) (void)tx_system_set_time_scale(s, scale);
  tx_gui_text("step = %.1f ms; resets %llu", tx_system_step_period(s) * 1e3, (unsigned long long)tx_system_resets_done(s));
  if (procedure.known) tx_gui_text("step: %s", procedure.text[0] ? procedure.text : "(none yet)");

  int n = tx_system_count(s);
  if (n > MAX_SHOWN) n = MAX_SHOWN;
  count_rates(s, n);
  if (tx_gui_header("Controllers", true) && tx_gui_table_begin("controllers", 5)) {
    static const char* const head[] = {"name", "Hz", "of", "jitter us", "missed"};
    tx_gui_table_row(head, 5);
    for (int i = 0; i < n; i++) {
      tx_live_stats st = tx_system_live(s, i);
      char hz[32], nominal[32], jitter[32], missed[32];
      snprintf(hz, sizeof hz, "%.0f", live.hz[i]);
      snprintf(nominal, sizeof nominal, "%g", tx_system_rate(s, i));
      snprintf(jitter, sizeof jitter, "%.0f", (double)st.jitter_ns * 1e-3);
      snprintf(missed, sizeof missed, "%llu", (unsigned long long)st.missed);
      const char* row[] = {tx_system_name(s, i), hz, nominal, jitter, missed};
      tx_gui_table_row(row, 5);
    }
    tx_gui_table_end();
  }
  if (tx_gui_header("Tune", true)) tune_panel(s, n);
  if (tx_gui_header("Devices", true)) device_plots();
  if (tx_gui_header("Parameters", false)) params_panel(s, n);
  if (tx_gui_header("Components", false)) components_table(s);
  tx_gui_end();
}
