// tactus study suturing-stability: the whole scripted suture (scenario
// suturing, in lockstep) with the hands jittered, the time steps varied and
// the tissue's stiffness scaled from x0.01 to x100. A case passes when the
// run completes (a fault it met detected, counted and recovered: the skin's
// and the thread's numerical_fault, the instruments' reset), nothing sent to
// or read from either hand is NaN or Inf (the haptics' force_non_finite
// and every value of the devices' recordings), and no force sent to a hand
// exceeds that device's clamp. Each case's steps done are reported: a case
// may well score another procedure. Exit 1 unless every case passes.
//
// The jitter: every waypoint of both hands' scripts moved by up to a
// distance in each axis (uniform, a fixed seed), written beside the run.
#include "studies.h"

#include "../controllers/haptics/device.h"
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
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SETS_MAX 4
#define QUICK_S 12.5 // the quick path's runs: through the needle's pass (A ends at 12.04 s as scripted)

typedef struct stab_case {
  const char* name;
  const char* sets[SETS_MAX]; // --set overrides
  double jitter_m;            // each waypoint moved by up to this in x, y and z; 0: the scripts as they are
  bool quick;                 // in the quick path
} stab_case;

static const stab_case cases[] = {
    {"as scripted", {NULL}, 0, false},
    {"hands jittered 0.5 mm", {NULL}, 0.0005, false},
    {"hands jittered 2 mm", {NULL}, 0.002, true},
    {"skin at 30 Hz", {"skin.rate_hz=30"}, 0, false},
    {"skin at 120 Hz", {"skin.rate_hz=120"}, 0, false},
    {"instruments and thread at 500 Hz", {"instruments.rate_hz=500", "thread.rate_hz=500"}, 0, true},
    {"instruments and thread at 2 kHz", {"instruments.rate_hz=2000", "thread.rate_hz=2000"}, 0, false},
    {"stiffness x0.01",
     {"skin.stretch_stiffness=20", "skin.bend_stiffness=0.2", "thread.tension_n_per_m=2"}, 0, false},
    {"stiffness x0.1", {"skin.stretch_stiffness=200", "skin.bend_stiffness=2", "thread.tension_n_per_m=20"}, 0, false},
    {"stiffness x10",
     {"skin.stretch_stiffness=20000", "skin.bend_stiffness=200", "thread.tension_n_per_m=2000"}, 0, false},
    {"stiffness x100",
     {"skin.stretch_stiffness=200000", "skin.bend_stiffness=2000", "thread.tension_n_per_m=20000"}, 0, true},
};
#define NCASES (int)(sizeof cases / sizeof cases[0])

typedef struct outcome {
  int rc;            // the run's exit: 0 completed
  int faults;        // detected and recovered: skin and thread numerical_fault, instruments reset
  int non_finite;    // haptics force_non_finite, and values of the recordings that are not finite
  double force_max;  // N, the largest force sent to either hand
  double clamp;      // N, the smaller of the two devices' clamps
  int steps_done;
  char done[9];
  bool pass;
} outcome;

// the scripts' x, y, z moved by up to j each, every data row; the rest as it is
static int jitter(const char* from, const char* to, double j, uint64_t* seed) {
  FILE* in = fopen(from, "r");
  if (!in) return tx_set_error("%s: cannot be read", from), -1;
  FILE* out = fopen(to, "w");
  if (!out) return fclose(in), tx_set_error("%s: cannot be written", to), -1;
  char line[1024];
  while (fgets(line, sizeof line, in)) {
    double v[4];
    int used = 0;
    if (line[0] >= '0' && line[0] <= '9' && sscanf(line, "%lf,%lf,%lf,%lf%n", &v[0], &v[1], &v[2], &v[3], &used) == 4) {
      fprintf(out, "%.6f", v[0]);
      for (int a = 1; a < 4; a++) {
        *seed = *seed * 6364136223846793005ULL + 1442695040888963407ULL; // a fixed sequence (PCG's LCG step)
        double u = (double)(*seed >> 11) / 9007199254740992.0;           // [0, 1)
        fprintf(out, ",%.6f", v[a] + j * (2 * u - 1));
      }
      fputs(line + used, out);
    } else {
      fputs(line, out);
    }
  }
  fclose(in);
  return fclose(out) ? (tx_set_error("%s: cannot be written", to), -1) : 0;
}

// the largest force in a recording (deviceN.csv: fx, fy, fz in columns 5 to
// 7) and how many of its values are not finite
static int scan_recording(const char* path, double* force_max, int* non_finite) {
  FILE* f = fopen(path, "r");
  if (!f) return tx_set_error("%s: cannot be read", path), -1;
  char line[4096];
  if (!fgets(line, sizeof line, f)) return fclose(f), tx_set_error("%s: empty", path), -1; // the header
  while (fgets(line, sizeof line, f)) {
    double force[3] = {0, 0, 0};
    int col = 0;
    for (char* p = line; *p && *p != '\n'; col++) {
      char* end;
      double v = strtod(p, &end);
      if (end == p || !isfinite(v)) (*non_finite)++;
      if (col >= 4 && col <= 6) force[col - 4] = v;
      p = *end == ',' ? end + 1 : end + (*end != 0 && *end != '\n');
    }
    double m = sqrt(force[0] * force[0] + force[1] * force[1] + force[2] * force[2]);
    if (m > *force_max) *force_max = m;
  }
  fclose(f);
  return 0;
}

static double warning(json_t* report, const char* key) {
  return json_number_value(json_object_get(json_object_get(report, "warnings"), key));
}

// the clamp a device declares (the scripted hands': their spec)
static double device_clamp(const char* spec) {
  tx_device_handle h;
  if (tx_device_open(spec, 1e-3, &h)) return NAN;
  tx_device_info info = {0};
  h.backend->info(h.device, &info);
  tx_device_close(&h);
  return info.max_force > 0 ? info.max_force : NAN;
}

static int run_case(const char* scenario, const char* dir, int k, double duration_s, outcome* o) {
  const stab_case* c = &cases[k];
  char sub[4200], scripts[2][4300], specs[2][4400], from[PATH_MAX + 64];
  snprintf(sub, sizeof sub, "%s/case%d", dir, k);
  const char* devices[2];
  int ndevices = 0;
  if (c->jitter_m > 0) {
    uint64_t seed = 2026;
    const char* slash = strrchr(scenario, '/');
    int folder = slash ? (int)(slash - scenario) : 0; // scenarios/suturing: the scripts are in scenarios/instruments
    for (int h = 0; h < 2; h++) {
      snprintf(from, sizeof from, "%.*s/../instruments/hand%d.csv", folder, scenario, h);
      snprintf(scripts[h], sizeof scripts[h], "%s/case%d-hand%d.csv", dir, k, h);
      if (jitter(from, scripts[h], c->jitter_m, &seed)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
      snprintf(specs[h], sizeof specs[h], "scripted:%.4290s", scripts[h]);
      devices[ndevices++] = specs[h];
    }
  }
  int nsets = 0;
  while (nsets < SETS_MAX && c->sets[nsets]) nsets++;
  tx_load_options lo = {.sets = c->sets, .nsets = nsets, .devices = devices, .ndevices = ndevices};
  tx_scenario* sc = tx_scenario_load(scenario, &lo);
  if (!sc) return fprintf(stderr, "tactus: study suturing-stability: %s: %s\n", c->name, tx_error()), 1;
  tx_run_config cfg = {.scenario = "suturing", .duration_s = duration_s, .lockstep = true, .out = sub, .quiet = true};
  json_t* report = NULL;
  o->rc = tx_run_scenario(sc, &cfg, &report);
  tx_scenario_free(sc);
  o->faults = (int)(warning(report, "skin.numerical_fault") + warning(report, "thread.numerical_fault") +
                    warning(report, "instruments.reset"));
  o->non_finite = (int)(warning(report, "haptics0.force_non_finite") + warning(report, "haptics1.force_non_finite"));
  json_decref(report);
  o->force_max = 0;
  o->clamp = INFINITY;
  for (int h = 0; h < 2; h++) {
    char rec[4300], spec[4400];
    snprintf(rec, sizeof rec, "%s/device%d.csv", sub, h);
    if (scan_recording(rec, &o->force_max, &o->non_finite)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    snprintf(spec, sizeof spec, "scripted:instruments/hand%d.csv", h);
    o->clamp = fmin(o->clamp, device_clamp(ndevices ? specs[h] : spec));
  }
  if (!(o->clamp < INFINITY)) return fprintf(stderr, "tactus: study suturing-stability: no device clamp: %s\n", tx_error()), 1;
  char card_path[4300];
  snprintf(card_path, sizeof card_path, "%s/scorecard.json", sub);
  json_t* card = json_load_file(card_path, 0, NULL); // NULL: a run stopped before its scorecard, no step done
  o->steps_done = tx_study_steps_done(card, o->done);
  json_decref(card);
  o->pass = o->rc == 0 && o->non_finite == 0 && o->force_max <= o->clamp * (1 + 1e-9);
  return 0;
}

static int write_outputs(const char* dir, const outcome* o, const int* which, int n, bool quick) {
  tx_aside out;
  FILE* f = tx_aside_begin(&out, dir, "suturing-stability.csv") ? out.f : NULL;
  if (f) {
    fprintf(f, "case,completed,faults_recovered,non_finite,force_max_n,clamp_n,steps_done,steps,pass\n");
    for (int i = 0; i < n; i++)
      fprintf(f, "%s,%d,%d,%d,%.6g,%.6g,%d,%s,%d\n", cases[which[i]].name, o[i].rc == 0, o[i].faults, o[i].non_finite,
              o[i].force_max, o[i].clamp, o[i].steps_done, o[i].done, o[i].pass);
  }
  if (!f || !tx_aside_end(&out)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_t* rows = json_array();
  for (int i = 0; i < n && rows; i++)
    json_array_append_new(rows, json_pack("{s:s,s:b,s:i,s:i,s:f,s:f,s:i,s:s,s:b}", "case", cases[which[i]].name,
                                          "completed", o[i].rc == 0, "faults_recovered", o[i].faults, "non_finite",
                                          o[i].non_finite, "force_max_n", o[i].force_max, "clamp_n", o[i].clamp,
                                          "steps_done", o[i].steps_done, "steps", o[i].done, "pass", o[i].pass));
  json_t* doc = json_pack("{s:s,s:s,s:s,s:o}", "study", "suturing-stability", "path", quick ? "quick" : "full", "pass",
                          "the run completes (faults detected, counted and recovered), nothing sent to or read from a "
                          "hand is NaN or Inf, and no force sent exceeds the device's clamp",
                          "cases", rows);
  if (!doc || tx_report_save(doc, dir, "suturing-stability.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "suturing-stability: out of memory"), 1;
  }
  json_decref(doc);
  return 0;
}

// the steps each case's procedure still completes (the forces are in the
// table: in every case so far the coupling reached the clamp)
static int write_plot(const char* dir, const outcome* o, int n) {
  static double x[NCASES], y[NCASES];
  for (int i = 0; i < n; i++) x[i] = i + 1, y[i] = o[i].steps_done;
  tx_plot_series s[1] = {{"steps done of the eight, case by case (the table's order)", x, y, n, true, 1}};
  char path[4200];
  snprintf(path, sizeof path, "%s/suturing-stability.png", dir);
  tx_plot p = {"The scripted suture at the extremes: what it still completes", "case", "steps done", false, false, s, 1};
  return tx_plot_png(path, &p);
}

int tx_study_suturing_stability(const tx_study_args* a) {
  bool quick;
  if (tx_study_quick_set(a, &quick)) return TX_EXIT_BAD_INPUT;
  char path[PATH_MAX];
  if (tx_scenario_locate("suturing", path, sizeof path)) return tx_bad_input("study suturing-stability: %s", tx_error());
  printf("study suturing-stability: the scripted suture in lockstep at its extremes (%s); the runs are in %s/caseN\n\n",
         quick ? "quick: three cases, their first 12.5 s" : "every case", a->out_dir);
  printf("  %-34s %-9s %6s %10s %9s %7s %-9s %s\n", "case", "completed", "faults", "non-finite", "force N", "clamp N",
         "steps", "");
  outcome o[NCASES];
  int which[NCASES], n = 0;
  bool all = true;
  for (int k = 0; k < NCASES; k++) {
    if (quick && !cases[k].quick) continue;
    if (run_case(path, a->out_dir, k, quick ? QUICK_S : 0, &o[n])) return 1;
    printf("  %-34s %-9s %6d %10d %9.3f %7.2f %-9s %s\n", cases[k].name, o[n].rc == 0 ? "yes" : "NO", o[n].faults,
           o[n].non_finite, o[n].force_max, o[n].clamp, o[n].done, o[n].pass ? "pass" : "FAIL");
    fflush(stdout);
    all &= o[n].pass;
    which[n++] = k;
  }
  if (write_outputs(a->out_dir, o, which, n, quick)) return 1;
  bool plotted = write_plot(a->out_dir, o, n) == 0; // a build without PLplot keeps the CSV and the JSON
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("\n%s; wrote %s/suturing-stability.json, .csv%s\n", all ? "every case passes" : "a case FAILED", a->out_dir,
         plotted ? " and suturing-stability.png" : "");
  return all ? 0 : 1;
}
