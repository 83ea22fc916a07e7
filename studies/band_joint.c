// tactus study band-joint: the gastric band's distance joint (controllers/
// band/band_sim.h, ODE's double-ball joint between the ring's and the tube's
// rigid bodies) while the two parts are pulled apart: the tube's tip held,
// the buckle pulled straight away from it by a force ramped from 0 over
// 0.25 s and then held, at several forces. The joint's length error against
// time for each force, and the largest error against the force; the target
// (docs/lagb.md, "The band"): within 1 % at 5 N. Writes band-joint.csv,
// .json and .png. --set quick=1: 5 N alone, for 1 s.
#include "studies.h"

#include "../scenarios/command.h"
#include "../views/plot.h"
#include "../views/aside.h"
#include "../views/report.h"
#include "../model/error.h"

#include <tactus/config.h>

#if TX_WITH_BULLET && TX_WITH_ODE
#include "../controllers/band/band_sim.h"
#endif

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define FORCES_MAX 5
#define TARGET 0.01 // the issue's: within 1 % at 5 N

int tx_study_band_joint(const tx_study_args* a) {
  bool quick;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
#if !(TX_WITH_BULLET && TX_WITH_ODE)
  (void)quick;
  return tx_bad_input("study band-joint: this build has no Bullet or no ODE (TX_WITH_BULLET, TX_WITH_ODE)");
#else
  static const double full[FORCES_MAX] = {1, 2, 5, 10, 20};
  const double* forces = quick ? (const double[]){5} : full;
  const int nforces = quick ? 1 : FORCES_MAX;
  const double duration = quick ? 1.0 : 2.0, ramp = 0.25;
  char assets[4096];
  snprintf(assets, sizeof assets, "%s/lagb", TX_ASSET_DIR);
  tx_band_def d = tx_band_def_default();
  printf("study band-joint: the band of %s/band_* (ring E %.3g MPa, tube E %.3g MPa), ODE's double-ball joint between "
         "the ring's tail and the tube's head; the tube's tip held, the buckle pulled away from it, the force ramped over "
         "%.2f s and held to %.2g s%s\n\n",
         assets, d.part[TX_BAND_RING].young * 1e-6, d.part[TX_BAND_TUBE].young * 1e-6, ramp, duration, quick ? ", quick" : "");

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "band-joint.csv")) return tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "force_n,t_s,pull_n,joint_length_m,joint_error\n");

  const int steps = (int)lround(duration / d.step);
  double* px = malloc(sizeof(double) * (size_t)steps * FORCES_MAX);
  double* py = malloc(sizeof(double) * (size_t)steps * FORCES_MAX);
  json_t* runs = json_array();
  double fx[FORCES_MAX], fy[FORCES_MAX], rest = 0, at5 = NAN;
  bool ok = px && py && runs;
  printf("  %8s %14s %14s %12s %10s\n", "force N", "max |error| %", "final error %", "moved mm", "CPU s");
  for (int k = 0; k < nforces && ok; k++) {
    tx_band* b = tx_band_create(&d, assets);
    if (!b) {
      fprintf(stderr, "tactus: study band-joint: %s\n", tx_error());
      ok = false;
      break;
    }
    rest = tx_band_joint_rest(b);
    double tip[3], buckle[3], dir[3], head0[3], head[3];
    tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
    tx_band_body_position(b, TX_BAND_BUCKLE, buckle);
    tx_band_body_position(b, TX_BAND_TUBE_HEAD, head0);
    double l = sqrt(pow(buckle[0] - tip[0], 2) + pow(buckle[1] - tip[1], 2) + pow(buckle[2] - tip[2], 2));
    for (int i = 0; i < 3; i++) dir[i] = (buckle[i] - tip[i]) / l;
    tx_band_drive(b, TX_BAND_TUBE_TIP, tip);
    double worst = 0, err = 0;
    clock_t c0 = clock();
    for (int s = 0; s < steps; s++) {
      double t = (s + 1) * d.step, f = forces[k] * fmin(1, (s + 0.5) * d.step / ramp);
      tx_band_set_force(b, TX_BAND_BUCKLE, (double[3]){f * dir[0], f * dir[1], f * dir[2]});
      if (!tx_band_step(b)) {
        fprintf(stderr, "tactus: study band-joint: the band blew up at %g N, t = %g s\n", forces[k], t);
        ok = false;
        break;
      }
      double len = tx_band_joint_length(b);
      err = len / rest - 1;
      worst = fmax(worst, fabs(err));
      fprintf(csv, "%g,%.6g,%.6g,%.9g,%.6g\n", forces[k], t, f, len, err);
      px[k * steps + s] = t, py[k * steps + s] = 100 * err;
    }
    double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    tx_band_body_position(b, TX_BAND_TUBE_HEAD, head);
    double stretch = sqrt(pow(head[0] - head0[0], 2) + pow(head[1] - head0[1], 2) + pow(head[2] - head0[2], 2));
    tx_band_destroy(b);
    if (!ok) break;
    printf("  %8g %14.4f %14.4f %12.2f %10.2f\n", forces[k], 100 * worst, 100 * err, stretch * 1e3, cpu);
    fflush(stdout);
    fx[k] = forces[k], fy[k] = 100 * worst;
    if (forces[k] == 5) at5 = worst;
    json_array_append_new(runs, json_pack("{s:f,s:f,s:f,s:f,s:f}", "force_n", forces[k], "max_abs_error", worst,
                                          "final_error", err, "tube_head_moved_m", stretch, "cpu_s", cpu));
  }
  if (!ok) {
    free(px), free(py), json_decref(runs), tx_aside_drop(&out);
    return 1;
  }
  bool met = at5 <= TARGET;
  printf("\n  at 5 N the joint's length stays within %.4f %% of %.3g mm (target 1 %%): %s\n", 100 * at5, rest * 1e3,
         met ? "met" : "MISSED");
  if (!tx_aside_end(&out)) {
    free(px), free(py), json_decref(runs);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:b,s:s,s:f,s:f,s:f,s:f,s:o,s:f,s:f,s:b}", "study", "band-joint", "quick", quick, "joint",
                          "ODE double-ball (dJointCreateDBall), dWorldStep at the band's substep", "joint_rest_m", rest,
                          "substep_s", d.max_substep, "ramp_s", ramp, "duration_s", duration, "runs", runs,
                          "max_abs_error_at_5n", at5, "target", TARGET, "met", met);
  if (!doc || tx_report_save(doc, a->out_dir, "band-joint.json")) {
    json_decref(doc), free(px), free(py);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "band-joint: out of memory"), 1;
  }
  json_decref(doc);

  char png[4200];
  snprintf(png, sizeof png, "%s/band-joint.png", a->out_dir);
  char labels[FORCES_MAX][32];
  tx_plot_series s[FORCES_MAX];
  for (int k = 0; k < nforces; k++) {
    snprintf(labels[k], sizeof labels[k], "%g N", forces[k]);
    s[k] = (tx_plot_series){labels[k], px + k * steps, py + k * steps, steps, false, k + 1};
  }
  tx_plot_series worst = {"largest |error|", fx, fy, nforces, true, 1};
  tx_plot p[2] = {{"The distance joint's length error, pulled apart", "time (s)", "length error (%)", false, false, s, nforces},
                  {"Its largest error against the pull", "pull (N)", "largest |length error| (%)", false, false, &worst, 1}};
  bool plotted = tx_plot_png_panels(png, p, 2, 2) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  free(px), free(py);
  printf("%s\nwrote %s/band-joint.json, .csv%s\n", met ? "all targets met" : "some targets MISSED", a->out_dir, plotted ? ", .png" : "");
  return 0;
#endif
}
