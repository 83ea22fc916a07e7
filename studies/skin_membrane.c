// tactus study skin-membrane: the skin's cloth against closed-form membrane
// solutions at three or more spacings (studies/experiments/skin_membrane.h):
// a pre-tensioned circular membrane under a disc load and under its own
// weight; the rupture force of a HIP pressing down at four spacings; and the
// journal paper's gravity test with physical skin, converged and at the
// real-time default. Writes skin-membrane.csv, .json and .png.
#include "studies.h"

#include "experiments/skin_membrane.h"
#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <tactus/config.h>
#include <tactus/model.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define LEVELS_MAX 4

static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

int tx_study_skin_membrane(const tx_study_args* a) {
  bool quick;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
#if !TX_WITH_BULLET
  (void)num, (void)quick;
  return tx_bad_input("study skin-membrane: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
#else
  // the closed forms at a / 8, a / 16, a / 32 (a = 4 cm); quick: the first two
  const double spacing[] = {0.005, 0.0025, 0.00125};
  const int nlevels = quick ? 2 : 3;
  const double rspacing[] = {0.0015, 0.001, 0.00075, 0.0005}; // the rupture, r = 1.5 cm; quick: the first two
  const int nrupture = quick ? 2 : 4;
  const int gres[] = {21, 42}; // the gravity test; quick: 21 only
  const int ngrav = quick ? 1 : 2;
  printf("study skin-membrane: the cloth against closed-form membranes, converged XPBD (k w h^2 = 1/4, 4 iterations), and the implicit solver on the disc%s\n\n",
         quick ? ", quick" : "");

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "skin-membrane.csv")) return tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "check,spacing_m,particles,substep_s,measured,exact,error,units\n");

  bool all = true;
  json_t* checks = json_array();
  double x[3][LEVELS_MAX], y[3][LEVELS_MAX];
  static const char* const names[3] = {"disc", "sag", "disc_implicit"};
  static const char* const what[3] = {
      "pre-tensioned clamped circle (a = 4 cm, T = 100 N/m) under F = 0.02 N over r0 = 5 mm: w0 = F (ln(a/r0) + 1/2) / (2 pi T)",
      "pre-tensioned clamped circle (a = 4 cm, T = 100 N/m) under its own weight (4.4 kg/m^2): w0 = rho t g a^2 / (4 T)",
      "the disc load with the implicit solver at its real-time defaults (one 1/60 s substep, Newton and CG)"};
  for (int k = 0; k < 3; k++) {
    tx_membrane_case mc = tx_membrane_case_default(k == 1 ? TX_MEMBRANE_SAG : TX_MEMBRANE_DISC);
    mc.implicit = k == 2;
    printf("  %s: %s\n  %10s %9s %10s %12s %12s %8s %8s\n", names[k], what[k], "spacing mm", "particles", "substep us",
           "w0 mm", "exact mm", "error", "T N/m");
    json_t* levels = json_array();
    bool falls = true;
    double error = NAN;
    for (int l = 0; l < nlevels; l++) {
      tx_membrane_result r;
      if (!tx_membrane_run(&mc, spacing[l], &r)) {
        tx_aside_drop(&out), json_decref(checks), json_decref(levels);
        return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
      }
      printf("  %10.3g %9d %10.3g %12.5f %12.5f %7.2f%% %8.2f\n", r.spacing * 1e3, r.particles, r.substep * 1e6,
             r.measured * 1e3, r.exact * 1e3, 100 * r.error, r.tension);
      fflush(stdout);
      fprintf(csv, "%s,%.6g,%d,%.6g,%.9g,%.9g,%.6g,m\n", names[k], r.spacing, r.particles, r.substep, r.measured, r.exact,
              r.error);
      if (l > 0 && !(r.error < error)) falls = false;
      error = r.error;
      x[k][l] = tx_plot_length(r.spacing);
      y[k][l] = 100 * r.error;
      json_array_append_new(levels, json_pack("{s:f,s:i,s:f,s:i,s:f,s:f,s:f,s:f,s:f}", "spacing_m", r.spacing,
                                              "particles", r.particles, "substep_s", r.substep, "iterations",
                                              r.iterations, "measured_m", r.measured, "exact_m", r.exact, "error",
                                              r.error, "drift_m", r.drift, "membrane_tension_n_m", r.tension));
    }
    bool within = error <= 0.05;
    all &= falls && within;
    printf("  error falls at every refinement: %s; finest within 5%%: %s\n\n", falls ? "yes" : "NO", within ? "yes" : "NO");
    json_array_append_new(checks, json_pack("{s:s,s:s,s:o,s:b,s:b}", "check", names[k], "what", what[k], "levels", levels,
                                            "error_falls", falls, "finest_within_5_percent", within));
  }

  // rupture: the same pierce at four spacings
  printf("  rupture: a HIP (r = 0.5 mm, skin 4 mm) pressing a clamped circle (a = 1.5 cm, T = 50 N/m) at 2 cm/s;\n"
         "  tears at 150 N/m averaged over 2 mm\n  %10s %9s %12s %10s %12s %9s\n",
         "spacing mm", "particles", "force N", "depth mm", "T tear N/m", "change");
  json_t* rup = json_array();
  double last = NAN, change = NAN;
  for (int l = 0; l < nrupture; l++) {
    tx_membrane_rupture r;
    if (!tx_membrane_rupture_run(rspacing[l], &r)) {
      tx_aside_drop(&out), json_decref(checks), json_decref(rup);
      return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    }
    change = l > 0 ? fabs(r.force - last) / last : NAN;
    printf("  %10.3g %9d %12.4f %10.3f %12.1f %8.1f%%\n", r.spacing * 1e3, r.particles, r.force, r.depth * 1e3, r.tension,
           100 * change);
    fflush(stdout);
    fprintf(csv, "rupture,%.6g,%d,,%.9g,,%.6g,N\n", r.spacing, r.particles, r.force, change);
    json_array_append_new(rup, json_pack("{s:f,s:i,s:f,s:f,s:f,s:o}", "spacing_m", r.spacing, "particles", r.particles,
                                         "force_n", r.force, "depth_m", r.depth, "tension_n_m", r.tension,
                                         "change_from_coarser", num(change)));
    last = r.force;
  }
  bool converged = change <= 0.10;
  all &= converged;
  printf("  rupture force changes by %.1f%% between the two finest: %s\n\n", 100 * change, converged ? "yes" : "NO");

  // the journal paper's gravity test
  printf("  gravity: the 10 x 10 cm patch, border fixed, 1100 kg/m^3, 4 mm, E t = 3100 N/m, 9.81 m/s^2\n"
         "  %9s %14s %16s\n",
         "particles", "converged mm", "real-time mm");
  json_t* grav = json_array();
  for (int l = 0; l < ngrav; l++) {
    tx_membrane_sag r;
    if (!tx_membrane_gravity_run(gres[l], &r)) {
      tx_aside_drop(&out), json_decref(checks), json_decref(rup), json_decref(grav);
      return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    }
    printf("  %4d x %-3d %14.3f %16.3f\n", r.res, r.res, r.converged * 1e3, r.realtime * 1e3);
    fflush(stdout);
    fprintf(csv, "gravity,%.6g,%d,,%.9g,,,m\n", 0.1 / (r.res - 1), r.res * r.res, r.converged);
    json_array_append_new(grav, json_pack("{s:i,s:f,s:f,s:f}", "particles", r.res * r.res, "sag_converged_m",
                                          r.converged, "drift_m", r.drift, "sag_realtime_m", r.realtime));
  }
  printf("  the journal paper: about 10 mm (first contact at y = -1.0 cm with gravity, -0.1 cm without)\n\n");

  if (!tx_aside_end(&out)) {
    json_decref(checks), json_decref(rup), json_decref(grav);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:b,s:s,s:o,s:{s:o,s:b},s:o,s:b}", "study", "skin-membrane", "quick", quick, "solver",
                          "XPBD, substep with k w h^2 = 1/4, 4 iterations", "checks", checks, "rupture", "levels", rup,
                          "converged_within_10_percent", converged, "gravity", grav, "all_met", all);
  if (!doc || tx_report_save(doc, a->out_dir, "skin-membrane.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "skin-membrane: out of memory"), 1;
  }
  json_decref(doc);

  // error against spacing, both checks, log-log
  char png[4200];
  snprintf(png, sizeof png, "%s/skin-membrane.png", a->out_dir);
  tx_plot_series s[] = {{"disc load", x[0], y[0], nlevels, true, 1}, {"own weight", x[1], y[1], nlevels, true, 2},
                        {"disc load, implicit", x[2], y[2], nlevels, true, 3}};
  tx_plot p = {"Skin membrane against the closed forms", "particle spacing (" TX_PLOT_LENGTH_UNIT ")",
               "error of the centre deflection (%)", true, true, s, 3};
  bool plotted = tx_plot_png(png, &p) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("%s\nwrote %s/skin-membrane.json, .csv%s\n", all ? "all targets met" : "some targets MISSED", a->out_dir,
         plotted ? ", .png" : "");
  return 0;
#endif
}
