// tactus study suturing-accuracy: the whole scripted suture (scenario
// suturing, in lockstep) with the skin and the thread refined together, its
// scorecard's physical quantities against the most refined setting's, and
// each run's CPU time: error against run time for the whole scenario.
//
// The levels: the skin's spacing 5, 2.5 (the scenario's) and 1.25 mm with
// the thread's nodes 16, 31 (the scenario's) and 61 over its 6 cm, so a link
// stays within a spacing or so. quick=1 runs the first two, the scenario's
// as the reference. The quantities: the wound gap at the stitch at the end,
// the thread's peak tension, the largest force on the tissue, and the two
// bites. Each run's steps done are reported beside them: a run whose script
// no longer completes the same steps measures another procedure.
#include "studies.h"

#include "../scenarios/command.h"
#include "../scenarios/loader.h"
#include "../scenarios/run.h"
#include "../model/error.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#define LEVELS 3
#define QUANTITIES 5

static const double spacing_m[LEVELS] = {0.005, 0.0025, 0.00125};
static const int thread_nodes[LEVELS] = {16, 31, 61};
// the scorecard's keys, their names in the table, and what the plot calls them
static const char* const key[QUANTITIES] = {"wound_gap_after_m", "peak_tension_n", "tissue_force_max_n", "bite_entry_m",
                                            "bite_exit_m"};
static const char* const label[QUANTITIES] = {"wound gap after", "peak tension", "force on the tissue", "entry bite",
                                              "exit bite"};

typedef struct level_run {
  double value[QUANTITIES];
  double cpu_s;   // the run's CPU time (lockstep: one thread)
  int steps_done; // of the eight
  char done[9];   // their letters
} level_run;

static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

// a measure's value in the scorecard: {"value": v} or, for the wound gap, "after"
static double measure(json_t* card, int q) {
  json_t* v = q == 0 ? json_object_get(json_object_get(card, "wound_gap_m"), "after")
                     : json_object_get(json_object_get(card, key[q]), "value");
  return json_is_number(v) ? json_number_value(v) : NAN; // null: not measured
}

static int run_level(const char* path, const char* dir, int k, level_run* r) {
  char sets[2][64], sub[4200];
  snprintf(sets[0], sizeof sets[0], "skin.spacing_m=%.17g", spacing_m[k]);
  snprintf(sets[1], sizeof sets[1], "thread.nodes=%d", thread_nodes[k]);
  const char* list[2] = {sets[0], sets[1]};
  tx_load_options o = {.sets = list, .nsets = 2};
  tx_scenario* sc = tx_scenario_load(path, &o);
  if (!sc) return fprintf(stderr, "tactus: study suturing-accuracy: %s\n", tx_error()), 1;
  snprintf(sub, sizeof sub, "%s/level%d", dir, k);
  tx_run_config cfg = {.scenario = "suturing", .lockstep = true, .out = sub, .quiet = true, .no_record = true};
  double c0 = cpu_now();
  int rc = tx_run_scenario(sc, &cfg, NULL);
  r->cpu_s = cpu_now() - c0;
  tx_scenario_free(sc);
  if (rc) return fprintf(stderr, "tactus: study suturing-accuracy: the run at %g mm failed\n", spacing_m[k] * 1e3), 1;
  char card_path[4300];
  snprintf(card_path, sizeof card_path, "%s/scorecard.json", sub);
  json_error_t e;
  json_t* card = json_load_file(card_path, 0, &e);
  if (!card) return fprintf(stderr, "tactus: %s:%d: %s\n", card_path, e.line, e.text), 1;
  for (int q = 0; q < QUANTITIES; q++) r->value[q] = measure(card, q);
  r->steps_done = tx_study_steps_done(card, r->done);
  json_decref(card);
  return 0;
}

// |v - ref| / |ref|; NaN where either is missing or the reference is zero
static double rel_error(double v, double ref) { return isfinite(v) && isfinite(ref) && ref != 0 ? fabs(v - ref) / fabs(ref) : NAN; }

static int write_outputs(const char* dir, const level_run* r, int n, bool quick) {
  const level_run* ref = &r[n - 1];
  tx_aside o;
  FILE* f = tx_aside_begin(&o, dir, "suturing-accuracy.csv") ? o.f : NULL;
  if (f) {
    fprintf(f, "spacing_m,thread_nodes,cpu_s,steps_done,steps");
    for (int q = 0; q < QUANTITIES; q++) fprintf(f, ",%s,%s_rel_error", key[q], key[q]);
    fprintf(f, "\n");
    for (int k = 0; k < n; k++) {
      fprintf(f, "%.9g,%d,%.6g,%d,%s", spacing_m[k], thread_nodes[k], r[k].cpu_s, r[k].steps_done, r[k].done);
      for (int q = 0; q < QUANTITIES; q++) fprintf(f, ",%.9g,%.6g", r[k].value[q], rel_error(r[k].value[q], ref->value[q]));
      fprintf(f, "\n");
    }
  }
  if (!f || !tx_aside_end(&o)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_t* rows = json_array();
  for (int k = 0; k < n && rows; k++) {
    json_t* row = json_pack("{s:f,s:i,s:f,s:i,s:s}", "spacing_m", spacing_m[k], "thread_nodes", thread_nodes[k], "cpu_s",
                            r[k].cpu_s, "steps_done", r[k].steps_done, "steps", r[k].done);
    for (int q = 0; q < QUANTITIES && row; q++) {
      double e = rel_error(r[k].value[q], ref->value[q]);
      json_object_set_new(row, key[q], isfinite(r[k].value[q]) ? json_real(r[k].value[q]) : json_null());
      char name[64];
      snprintf(name, sizeof name, "%s_rel_error", key[q]);
      json_object_set_new(row, name, isfinite(e) ? json_real(e) : json_null());
    }
    json_array_append_new(rows, row);
  }
  json_t* doc = json_pack("{s:s,s:s,s:s,s:o}", "study", "suturing-accuracy", "path", quick ? "quick" : "full", "error",
                          "each quantity's |value - reference| / |reference|, the reference the last row (the most "
                          "refined run); the scripted suture in lockstep, the skin's spacing and the thread's nodes "
                          "refined together",
                          "rows", rows);
  if (!doc || tx_report_save(doc, dir, "suturing-accuracy.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "suturing-accuracy: out of memory"), 1;
  }
  json_decref(doc);
  return 0;
}

static int write_plot(const char* dir, const level_run* r, int n) {
  static double x[QUANTITIES][LEVELS], y[QUANTITIES][LEVELS];
  tx_plot_series s[QUANTITIES];
  int ns = 0;
  for (int q = 0; q < QUANTITIES; q++) {
    int m = 0;
    for (int k = 0; k + 1 < n; k++) { // the reference's own error is 0: off a log axis
      double e = rel_error(r[k].value[q], r[n - 1].value[q]);
      if (!(e > 0)) continue;
      x[q][m] = r[k].cpu_s, y[q][m] = 100 * e;
      m++;
    }
    if (m) s[ns++] = (tx_plot_series){label[q], x[q], y[q], m, m == 1, 1 + 2 * q};
  }
  if (!ns) return tx_set_error("suturing-accuracy: no error to plot (every run as the reference)"), -1;
  char path[4200];
  snprintf(path, sizeof path, "%s/suturing-accuracy.png", dir);
  tx_plot p = {"The scripted suture: error vs run time", "run time (CPU s for the 17 s procedure)",
               "error (% of the most refined run's)", true, true, s, ns};
  return tx_plot_png(path, &p);
}

int tx_study_suturing_accuracy(const tx_study_args* a) {
  bool quick;
  if (tx_study_quick_set(a, &quick)) return TX_EXIT_BAD_INPUT;
  char path[PATH_MAX];
  if (tx_scenario_locate("suturing", path, sizeof path)) return tx_bad_input("study suturing-accuracy: %s", tx_error());
  int n = quick ? 2 : LEVELS;
  printf("study suturing-accuracy: the scripted suture in lockstep, the skin's spacing and the thread's nodes refined\n"
         "together; each quantity against the last row's (%s); the runs are in %s/levelN\n\n",
         quick ? "quick: the scenario's own setting" : "the most refined", a->out_dir);
  printf("  %-8s %-6s %8s %-9s", "spacing", "nodes", "CPU s", "steps");
  for (int q = 0; q < QUANTITIES; q++) printf(" %20s", label[q]);
  printf("\n");
  level_run r[LEVELS];
  for (int k = 0; k < n; k++) {
    if (run_level(path, a->out_dir, k, &r[k])) return 1;
    printf("  %5.2f mm %-6d %8.2f %-9s", spacing_m[k] * 1e3, thread_nodes[k], r[k].cpu_s, r[k].done);
    for (int q = 0; q < QUANTITIES; q++) printf(" %20.6g", r[k].value[q]);
    printf("\n");
    fflush(stdout);
  }
  printf("\n  relative error against the last row:\n");
  for (int k = 0; k + 1 < n; k++) {
    printf("  %5.2f mm %-6d %8.2f %-9s", spacing_m[k] * 1e3, thread_nodes[k], r[k].cpu_s, r[k].done);
    for (int q = 0; q < QUANTITIES; q++) printf(" %19.1f%%", 100 * rel_error(r[k].value[q], r[n - 1].value[q]));
    printf("\n");
  }
  if (write_outputs(a->out_dir, r, n, quick)) return 1;
  bool plotted = write_plot(a->out_dir, r, n) == 0; // a build without PLplot keeps the CSV and the JSON
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("\nwrote %s/suturing-accuracy.json, .csv%s\n", a->out_dir, plotted ? " and suturing-accuracy.png" : "");
  return 0;
}
