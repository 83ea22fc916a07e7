// tactus study skin-accuracy: how far the pierce-down force curve of a
// cheaper skin lies from the finest one, against what the run costs.
//
// Every setting is one lockstep run of physics.skin, collision.hip (26 rays)
// and haptics on the same scripted hand (down at 1 cm/s from 1 cm above the
// skin to 1.5 cm below it), with a recorder that keeps the device force and
// the HIP position of every 1 ms tick. The hand is the same in every run, so
// the curves are compared tick by tick: the error of a setting is the RMS of
// its force (y) less the reference's, over the whole motion, also given
// relative to the reference's peak force; the peak force and the HIP height
// at rupture are compared too. The run time is the process's CPU time for
// the whole lockstep run (skin, HIP, haptics) per simulated second: CPU
// time, so that other work on the machine does not count.
//
// The sweeps go one parameter at a time from the finest setting (spacing
// 0.1 cm, 20 iterations, 120 Hz): particle spacing 0.5 / 0.25 / 0.1 cm,
// solver iterations 2 / 5 / 10 / 20, physics rate 20 / 30 / 60 / 120 Hz;
// plus the two real-time settings (0.25 cm and 0.1 cm at 10 iterations,
// 60 Hz). Outputs: skin-accuracy.csv and .json (one row per setting),
// skin-accuracy-curves.csv (every tick of every run) and skin-accuracy.png
// (error against run time).
#include "studies.h"

#include "../scenarios/command.h"
#include "../controllers/haptics/device_scripted.h"
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

#define TICKS_MAX 4000 // 3 s at 1 kHz, and room

// ---------------------------------------------------------------------------
// the recorder: device force and HIP position at every haptics tick

typedef struct curve {
  int n;
  double y[TICKS_MAX]; // m, HIP height
  double f[TICKS_MAX]; // N, device force along y
} curve;

static curve* recording; // the study's buffer for the run under way (one run at a time)

typedef struct recorder {
  tx_port pose, force;
} recorder;

static int recorder_configure(tx_setup* s, void** self) {
  recorder* r = calloc(1, sizeof *r);
  if (!r) return -1;
  *self = r;
  r->pose = TX_READ_OF(s, "device0.pose", tx_pose);
  r->force = TX_READ_OF(s, "device0.force", tx_force);
  return 0;
}

static void recorder_step(tx_ctx* c, void* self) {
  recorder* r = self;
  const tx_pose* p = tx_read(c, r->pose).data;
  const tx_force* f = tx_read(c, r->force).data;
  if (recording && recording->n < TICKS_MAX) {
    recording->y[recording->n] = p->pos[1];
    recording->f[recording->n] = f->f[1];
    recording->n++;
  }
}

static void recorder_fini(void* self) { free(self); }

static const tx_controller_class recorder_class = {.type = "study.force_recorder",
                                                   .view = true,
                                                   .summary = "keeps device0.pose y and device0.force y per tick",
                                                   .configure = recorder_configure,
                                                   .step = recorder_step,
                                                   .fini = recorder_fini};

// ---------------------------------------------------------------------------
// settings

typedef struct setting {
  const char* sweep; // "reference", "spacing", "iterations", "rate", "real time"
  double spacing;    // m
  int iterations;
  double rate_hz;
} setting;

static const setting settings[] = {
    {"reference", 0.001, 20, 120},
    {"spacing", 0.005, 20, 120},
    {"spacing", 0.0025, 20, 120},
    {"iterations", 0.001, 2, 120},
    {"iterations", 0.001, 5, 120},
    {"iterations", 0.001, 10, 120},
    {"rate", 0.001, 20, 20},
    {"rate", 0.001, 20, 30},
    {"rate", 0.001, 20, 60},
    {"real time", 0.0025, 10, 60},
    {"real time", 0.001, 10, 60},
};
#define NSETTINGS ((int)(sizeof settings / sizeof settings[0]))

typedef struct row {
  double cpu_s_per_s;   // process CPU time of the lockstep run per simulated second
  double wall_s;        // the whole lockstep run
  double rms_n, rel;    // error against the reference: N, and over its peak
  double peak_n;        // largest |force| of the run
  double rupture_y;     // m, HIP height where the force collapsed after its peak (NaN: none)
  int torn;
} row;

// the hand motion: down through the skin at 1 cm/s (controllers/haptics/device_scripted.c)
#define MOTION "accuracy-pierce-down"

// when the motion ends, s
static double motion_end_s(void) {
  const tx_hand_motion* m = tx_hand_motion_find(MOTION);
  return m ? m->t_pos[m->count - 1][0] : 0;
}

static int write_motion(const char* path) {
  char tmp[4300];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE* f = fopen(tmp, "w");
  if (!f) return -1;
  fprintf(f, "# t_s, x_m, y_m, z_m: pierce-down at 1 cm/s, tactus study skin-accuracy\n");
  const tx_hand_motion* m = tx_hand_motion_find(MOTION);
  for (int i = 0; m && i < m->count; i++) fprintf(f, "%g,%g,%g,%g\n", m->t_pos[i][0], m->t_pos[i][1], m->t_pos[i][2], m->t_pos[i][3]);
  if (fclose(f) != 0 || rename(tmp, path) != 0) return remove(tmp), -1;
  return 0;
}

// where the force collapses: the first tick after the peak under a tenth of it
static double rupture_height(const curve* c, double* peak) {
  int at = 0;
  *peak = 0;
  for (int i = 0; i < c->n; i++)
    if (fabs(c->f[i]) > *peak) *peak = fabs(c->f[i]), at = i;
  for (int i = at; i < c->n && *peak > 0; i++)
    if (fabs(c->f[i]) < 0.1 * *peak) return c->y[i];
  return NAN;
}

static int run_setting(const setting* s, const char* device, curve* out, row* r, char* err, size_t en) {
  json_t* doc = json_pack(
      "{s:s,s:[{s:s,s:s,s:f,s:{s:f,s:f,s:f,s:i}},{s:s,s:s,s:f,s:{s:f,s:i}},"
      "{s:s,s:s,s:f,s:{s:s,s:s}},{s:s,s:s,s:f}]}",
      "name", "skin-accuracy", "controllers",
      "name", "skin", "type", "physics.skin", "rate_hz", s->rate_hz, "params", "spacing_m", s->spacing,
      "thickness_m", 0.004, "hip_radius_m", 0.0005, "iterations", s->iterations,
      "name", "hip", "type", "collision.hip", "rate_hz", 4000.0, "params", "radius_m", 0.0005, "rays", 26,
      "name", "haptics", "type", "haptics", "rate_hz", 1000.0, "params", "device", device, "force_model",
      "tool0.force_model",
      "name", "recorder", "type", "study.force_recorder", "rate_hz", 1000.0);
  char* text = doc ? json_dumps(doc, JSON_COMPACT) : NULL;
  json_decref(doc);
  if (!text) return snprintf(err, en, "skin-accuracy: out of memory"), -1;
  tx_scenario* sc = tx_scenario_load_text("skin-accuracy", text, strlen(text), NULL);
  free(text);
  if (!sc) return snprintf(err, en, "%s", tx_error()), -1;
  out->n = 0;
  recording = out;
  tx_run_options o = {.duration_s = motion_end_s(), .lockstep = true};
  tx_run_result res;
  int64_t t0 = tx_mono_ns();
  struct timespec c0, c1;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
  int rc = tx_system_run(sc->system, &o, &res);
  if (rc) snprintf(err, en, "%s", tx_error());
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
  r->wall_s = (double)(tx_mono_ns() - t0) * 1e-9;
  r->cpu_s_per_s = ((double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec)) / motion_end_s();
  recording = NULL;
  if (rc == 0) {
    for (int k = 0; k < tx_system_results(sc->system); k++)
      if (strcmp(tx_system_result_key(sc->system, k), "skin.torn_links") == 0)
        r->torn = (int)tx_system_result(sc->system, k);
    r->rupture_y = rupture_height(out, &r->peak_n);
  }
  tx_scenario_free(sc);
  return rc ? -1 : 0;
}

static int write_plot(const char* dir, const row* rows, char* err, size_t en) {
  // one series per sweep; the reference itself has no error to draw on a log axis
  static const char* sweeps[] = {"spacing", "iterations", "rate", "real time"};
  static const int colours[] = {1, 3, 9, 13};
  double x[4][NSETTINGS], y[4][NSETTINGS];
  tx_plot_series s[4];
  int ns = 0;
  for (int k = 0; k < 4; k++) {
    int n = 0;
    for (int i = 1; i < NSETTINGS; i++) {
      if (strcmp(settings[i].sweep, sweeps[k]) != 0) continue;
      x[k][n] = rows[i].cpu_s_per_s;
      y[k][n] = fmax(100 * rows[i].rel, 1e-3); // a log axis: an exact match sits at the floor
      n++;
    }
    if (n) s[ns++] = (tx_plot_series){sweeps[k], x[k], y[k], n, true, colours[k]};
  }
  char path[4200];
  snprintf(path, sizeof path, "%s/skin-accuracy.png", dir);
  tx_plot p = {"Skin force error vs run time (pierce-down; ref. spacing 1 mm, 20 it, 120 Hz)",
               "run time (CPU s per simulated s)", "RMS force error (% of the reference peak)",
               true, true, s, ns};
  return tx_plot_png(path, &p) ? (snprintf(err, en, "%s", tx_error()), -1) : 0;
}

int tx_study_skin_accuracy(const tx_study_args* a) {
  if (a->nsets) return tx_bad_input("--set %s: skin-accuracy takes no --set (its settings are fixed)", a->sets[0]);
  char path[4200], device[4300], err[1024];
  snprintf(path, sizeof path, "%s/motion-pierce-down.csv", a->out_dir);
  if (write_motion(path)) return tx_bad_input("--out %s: cannot write motion-pierce-down.csv", a->out_dir);
  snprintf(device, sizeof device, "scripted:%s", path);
  if (!tx_find_controller(recorder_class.type)) tx_register_controller(&recorder_class);

  curve* curves = calloc(NSETTINGS, sizeof *curves);
  row rows[NSETTINGS];
  memset(rows, 0, sizeof rows);
  if (!curves) return fprintf(stderr, "tactus: out of memory\n"), 1;
  printf("study skin-accuracy: pierce-down at 1 cm/s, HIP r = 0.5 mm, 0.4 cm skin, 26 rays; reference: 0.1 cm, 20 "
         "iterations, 120 Hz\n\n");
  printf("  %-10s %8s %5s %7s %10s %8s %9s %8s %9s %11s %6s\n", "sweep", "spacing", "iter", "rate Hz", "CPU s/s",
         "wall s", "RMS mN", "RMS %", "peak mN", "rupture mm", "torn");
  int rc = 0;
  for (int i = 0; i < NSETTINGS && rc == 0; i++) {
    if (run_setting(&settings[i], device, &curves[i], &rows[i], err, sizeof err)) {
      fprintf(stderr, "tactus: %s\n", err);
      rc = 1;
      break;
    }
    // against the reference, tick by tick (the same hand in every run)
    const curve* ref = &curves[0];
    int n = curves[i].n < ref->n ? curves[i].n : ref->n;
    double sum = 0;
    for (int t = 0; t < n; t++) sum += (curves[i].f[t] - ref->f[t]) * (curves[i].f[t] - ref->f[t]);
    rows[i].rms_n = n ? sqrt(sum / n) : NAN;
    rows[i].rel = rows[0].peak_n > 0 ? rows[i].rms_n / rows[0].peak_n : NAN;
    const setting* s = &settings[i];
    printf("  %-10s %6.2fcm %5d %7.0f %10.3f %8.2f %9.3f %8.2f %9.2f %11.2f %6d\n", s->sweep, s->spacing * 100,
           s->iterations, s->rate_hz, rows[i].cpu_s_per_s, rows[i].wall_s, rows[i].rms_n * 1e3, 100 * rows[i].rel,
           rows[i].peak_n * 1e3, rows[i].rupture_y * 1e3, rows[i].torn);
    fflush(stdout);
  }

  // the table as CSV and JSON, the curves as CSV; each whole or absent
  if (rc == 0) {
    char csv_path[4200], tmp[4300];
    snprintf(csv_path, sizeof csv_path, "%s/skin-accuracy.csv", a->out_dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", csv_path);
    FILE* f = fopen(tmp, "w");
    json_t* list = json_array();
    if (f) {
      fprintf(f, "sweep,spacing_m,iterations,rate_hz,cpu_s_per_sim_s,wall_s,rms_error_n,rms_error_rel,peak_force_n,"
                 "rupture_hip_y_m,torn_links\n");
      for (int i = 0; i < NSETTINGS; i++) {
        const setting* s = &settings[i];
        fprintf(f, "%s,%g,%d,%g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n", s->sweep, s->spacing, s->iterations, s->rate_hz,
                rows[i].cpu_s_per_s, rows[i].wall_s, rows[i].rms_n, rows[i].rel, rows[i].peak_n, rows[i].rupture_y,
                rows[i].torn);
        json_t* o = json_pack("{s:s,s:f,s:i,s:f,s:f,s:f,s:f,s:f,s:f,s:i}", "sweep", s->sweep, "spacing_m", s->spacing,
                              "iterations", s->iterations, "rate_hz", s->rate_hz, "cpu_s_per_sim_s",
                              rows[i].cpu_s_per_s, "wall_s", rows[i].wall_s, "rms_error_n", rows[i].rms_n,
                              "rms_error_rel", rows[i].rel, "peak_force_n", rows[i].peak_n, "torn_links", rows[i].torn);
        json_object_set_new(o, "rupture_hip_y_m", isfinite(rows[i].rupture_y) ? json_real(rows[i].rupture_y) : json_null());
        json_array_append_new(list, o);
      }
    }
    if (!f || fclose(f) != 0 || rename(tmp, csv_path) != 0) {
      remove(tmp);
      fprintf(stderr, "tactus: %s: cannot be written\n", csv_path);
      rc = 1;
    }
    snprintf(csv_path, sizeof csv_path, "%s/skin-accuracy-curves.csv", a->out_dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", csv_path);
    f = rc ? NULL : fopen(tmp, "w");
    if (f) {
      fprintf(f, "setting,sweep,spacing_m,iterations,rate_hz,tick,hip_y_m,force_y_n\n");
      for (int i = 0; i < NSETTINGS; i++)
        for (int t = 0; t < curves[i].n; t++)
          fprintf(f, "%d,%s,%g,%d,%g,%d,%.6g,%.6g\n", i, settings[i].sweep, settings[i].spacing, settings[i].iterations,
                  settings[i].rate_hz, t, curves[i].y[t], curves[i].f[t]);
    }
    if (rc == 0 && (!f || fclose(f) != 0 || rename(tmp, csv_path) != 0)) {
      remove(tmp);
      fprintf(stderr, "tactus: %s: cannot be written\n", csv_path);
      rc = 1;
    }
    json_t* doc = json_pack("{s:s,s:s,s:s,s:o}", "study", "skin-accuracy", "error",
                            "RMS of the device force (y) less the reference's, tick by tick over the pierce-down; rel: "
                            "over the reference's peak force",
                            "run_time", "process CPU time of the whole lockstep run (skin, HIP, haptics) per simulated second",
                            "settings", list);
    if (rc == 0 && (!doc || tx_report_save(doc, a->out_dir, "skin-accuracy.json"))) {
      fprintf(stderr, "tactus: %s\n", tx_error());
      rc = 1;
    }
    json_decref(doc);
  }
  bool plotted = false;
  if (rc == 0) {
    plotted = write_plot(a->out_dir, rows, err, sizeof err) == 0;
    if (!plotted) fprintf(stderr, "tactus: %s\n", err);
    // what the sweeps show: the error falls as each parameter nears the reference
    printf("\nfindings:\n");
    printf("  reference peak force %.1f mN; real-time 0.25 cm / 10 it / 60 Hz: %.1f%% RMS at %.3f CPU s/s; "
           "0.1 cm / 10 it / 60 Hz: %.1f%% at %.3f CPU s/s\n",
           rows[0].peak_n * 1e3, 100 * rows[9].rel, rows[9].cpu_s_per_s, 100 * rows[10].rel, rows[10].cpu_s_per_s);
    printf("wrote %s/skin-accuracy.json, .csv, skin-accuracy-curves.csv%s\n", a->out_dir, plotted ? " and skin-accuracy.png" : "");
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
