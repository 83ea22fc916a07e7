// tactus study organ-stability: the LAGB paper's Figure 15. The hemisphere
// of organ-hemisphere (R = 2 cm, E = 5 kPa, nu = 0.45, 1000 kg/m^3, base
// fixed) is pressed at its pole by a rigid frictionless plate to d/R = 0.1
// and held, stepped as a physics controller at 60 Hz would step it, at a
// fixed substep: the FEM mode at the nominal body's own stable explicit step
// (no mass scaling), the links mode at 1 ms. One factor at a time is swept
// around the nominal: the geometry's scale x0.1..x10 (E, density and damping
// kept: the paper's "scaled without scaling its parameters"), the stiffness,
// the density and the damping. Every frame is checked as physics.organs
// checks its steps: a NaN, an Inf, a node faster than the limit or a force
// above the clamp is a fault, the state goes back to the last good frame, and
// nothing is reported from it; three faults in a row end the run as a blow-up
// (detected and recovered). The force at the end, over Hertz's at that scale
// and stiffness, shows whether the model stays consistent: for SI-unit FEM
// it should not depend on the scale. Writes organ-stability.csv, .json, .png.
#include "studies.h"

#include "experiments/organ_hemisphere.h"
#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"
#include "../model/error.h"

#include <tactus/config.h>

#if TX_WITH_BULLET
#include "../controllers/organs/bullet/fem.h"
#endif

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if TX_WITH_BULLET
static const double RADIUS = 0.02, YOUNG = 5e3, NU = 0.45, DENSITY = 1000, DAMPING = 20, FRAME = 1.0 / 60;
enum { FACTORS = 4, VALUES = 5 };
static const char* const factor_names[FACTORS] = {"scale", "stiffness", "density", "damping"};
static const double factor_values[FACTORS][VALUES] = {
    {0.1, 0.3, 1, 3, 10}, {0.1, 0.3, 1, 3, 10}, {0.01, 0.1, 1, 10, 100}, {0, 0.1, 1, 10, 100}};

typedef struct outcome {
  int frames, faults;
  int numerical, over_clamp;  // faults by cause: a NaN, an Inf or a node too fast; a force above the clamp
  bool blew_up;           // three faults in a row: the run ended, its state the last good one
  bool reported_finite;   // every force reported (from good frames only) finite and within the clamp
  double force_ratio;     // force at the end over Hertz's at that scale and stiffness (NAN after a blow-up)
} outcome;

static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

// one run: the hemisphere at scale s, E, rho and damping, pressed for `seconds`
static bool run(tx_fem_model model, double s, double young, double link_stiffness, double density, double damping,
                double fem_dt, int cells, double seconds, outcome* o) {
  tx_hemisphere_mesh m;
  double r = RADIUS * s;
  if (!tx_hemisphere_build(r, cells, &m)) return false;
  tx_fem_def d = tx_fem_def_default();
  d.model = model, d.young = young, d.poisson = NU, d.density = density, d.damping = damping;
  d.dt = model == TX_FEM_LINKS ? 1e-3 : fem_dt;
  d.iterations = 5, d.link_stiffness = link_stiffness, d.volume_stiffness = 1;
  double depth = 0.1 * r, ramp = seconds / 2;
  d.max_speed = 1000 * depth / ramp;  // a thousand times the plate's speed
  tx_fem* b = tx_fem_create(&d, m.v, m.nv, m.e, m.ne);
  if (!b) return tx_hemisphere_free(&m), false;
  for (int i = 0; i < m.nv; i++)
    if (m.base[i]) tx_fem_fix(b, i);
  double hertz = tx_hertz_force(young, NU, r, depth), clamp = 20 * hertz;
  int per_frame = (int)ceil(FRAME / tx_fem_dt(b) - 1e-9), frames = (int)ceil(seconds / FRAME);
  *o = (outcome){.reported_finite = true, .force_ratio = NAN};
  int in_row = 0;
  double force = NAN;
  for (int f = 1; f <= frames && !o->blew_up; f++) {
    double t = f * FRAME;
    tx_fem_set_plate(b, r - depth * fmin(t / ramp, 1));
    bool ok = tx_fem_step(b, per_frame);
    double fz = tx_fem_plate_force(b);
    if (ok && isfinite(fz) && fabs(fz) <= clamp) {
      tx_fem_save(b);
      force = fz;
      o->reported_finite &= isfinite(force) && fabs(force) <= clamp;
      in_row = 0;
    } else {
      tx_fem_restore(b);
      o->faults++;
      if (ok && isfinite(fz)) o->over_clamp++;
      else o->numerical++;
      o->blew_up = ++in_row >= 3;
    }
    o->frames = f;
  }
  if (!o->blew_up) o->force_ratio = force / hertz;
  tx_fem_destroy(b);
  tx_hemisphere_free(&m);
  return true;
}
#endif

int tx_study_organ_stability(const tx_study_args* a) {
  bool quick;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
#if !TX_WITH_BULLET
  (void)quick;
  return tx_bad_input("study organ-stability: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
#else
  const int cells = quick ? 1 : 2;
  const double seconds = quick ? 0.2 : 0.5;
  // the FEM substep: the nominal body's own stable explicit step
  double fem_dt;
  {
    tx_hemisphere_mesh m;
    if (!tx_hemisphere_build(RADIUS, cells, &m)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    tx_fem_def d = tx_fem_def_default();
    d.young = YOUNG, d.poisson = NU, d.density = DENSITY;
    tx_fem* b = tx_fem_create(&d, m.v, m.nv, m.e, m.ne);
    tx_hemisphere_free(&m);
    if (!b) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    fem_dt = tx_fem_dt(b);
    tx_fem_destroy(b);
  }
  printf("study organ-stability: hemisphere R = %g cm, E = %g kPa, nu = %g, %g kg/m^3, damping %g/s, %d cells per "
         "radius, pressed to d/R = 0.1 over %g s and held; frames of 1/60 s; FEM substep %.1f us (the nominal's stable "
         "step), links 1 ms, 5 iterations, kLST 0.1%s\n\n",
         RADIUS * 1e2, YOUNG * 1e-3, NU, DENSITY, DAMPING, cells, seconds / 2, fem_dt * 1e6, quick ? ", quick" : "");

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "organ-stability.csv")) return tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "mode,factor,value,frames,faults,numerical_faults,clamp_faults,blew_up,reported_finite,force_over_hertz\n");

  const tx_fem_model models[2] = {TX_FEM_COROTATED, TX_FEM_LINKS};
  const char* mode_names[2] = {"fem", "links"};
  double scale_ratio[2][VALUES];
  json_t* jruns = json_array();
  bool all_finite = true, fem_consistent = true;
  int blowups = 0, recovered = 0;
  printf("  %-6s %-10s %7s %7s %7s  %-38s %12s\n", "mode", "factor", "value", "frames", "faults", "outcome", "F / Hertz");
  for (int md = 0; md < 2; md++)
    for (int f = 0; f < FACTORS; f++)
      for (int v = 0; v < VALUES; v++) {
        double x = factor_values[f][v];
        // stiffness: E for FEM; the links body has no E, so its kLST (0.1 nominal, at most 1), the Hertz
        // reference kept at the nominal E
        double s = f == 0 ? x : 1, e = YOUNG * (f == 1 && md == 0 ? x : 1), rho = DENSITY * (f == 2 ? x : 1),
               c = DAMPING * (f == 3 ? x : 1), k = fmin(1, 0.1 * (f == 1 ? x : 1));
        outcome o;
        if (!run(models[md], s, e, k, rho, c, fem_dt, cells, seconds, &o)) {
          tx_aside_drop(&out), json_decref(jruns);
          return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
        }
        char what[64];
        const char* cause = o.numerical && o.over_clamp ? "NaN/speed and clamp" : o.numerical ? "NaN/speed" : "force over clamp";
        if (o.blew_up) snprintf(what, sizeof what, "blew up (%s): restored", cause);
        else if (o.faults) snprintf(what, sizeof what, "%d faults (%s): recovered", o.faults, cause);
        else snprintf(what, sizeof what, "stable");
        blowups += o.blew_up;
        recovered += o.faults > 0;
        all_finite &= o.reported_finite;
        if (f == 0) scale_ratio[md][v] = o.force_ratio;
        printf("  %-6s %-10s %7g %7d %7d  %-38s %12.3f\n", mode_names[md], factor_names[f], x, o.frames, o.faults, what,
               o.force_ratio);
        fprintf(csv, "%s,%s,%g,%d,%d,%d,%d,%d,%d,%.6g\n", mode_names[md], factor_names[f], x, o.frames, o.faults,
                o.numerical, o.over_clamp, o.blew_up, o.reported_finite, o.force_ratio);
        json_array_append_new(jruns, json_pack("{s:s,s:s,s:f,s:i,s:i,s:i,s:i,s:b,s:b,s:o}", "mode", mode_names[md],
                                               "factor", factor_names[f], "value", x, "frames", o.frames, "faults",
                                               o.faults, "numerical_faults", o.numerical, "clamp_faults", o.over_clamp,
                                               "blew_up", o.blew_up, "reported_finite", o.reported_finite,
                                               "force_over_hertz", num(o.force_ratio)));
      }
  // SI-unit FEM under scale: where it ran, the force over Hertz does not
  // depend on the scale (within 5 %); the links body's does
  double fem_ref = scale_ratio[0][2], links_lo = INFINITY, links_hi = -INFINITY;
  for (int v = 0; v < VALUES; v++) {
    if (isfinite(scale_ratio[0][v])) fem_consistent &= fabs(scale_ratio[0][v] / fem_ref - 1) <= 0.05;
    if (isfinite(scale_ratio[1][v])) links_lo = fmin(links_lo, scale_ratio[1][v]), links_hi = fmax(links_hi, scale_ratio[1][v]);
  }
  double links_spread = links_hi / links_lo;
  printf("\n  %d runs blew up and %d met faults, every one detected and recovered; every force reported finite and "
         "within the clamp: %s\n  FEM (SI units) under scale: force over Hertz the same within 5%% wherever it ran: %s; "
         "links: it varies %.1f-fold over the scales\n",
         blowups, recovered, all_finite ? "yes" : "NO", fem_consistent ? "yes" : "NO", links_spread);
  if (!tx_aside_end(&out)) {
    json_decref(jruns);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:b,s:{s:f,s:f,s:f,s:f,s:f,s:i,s:f,s:f},s:o,s:i,s:i,s:b,s:b,s:o}", "study",
                          "organ-stability", "quick", quick, "nominal", "radius_m", RADIUS, "young_pa", YOUNG, "poisson",
                          NU, "density", DENSITY, "damping_per_s", DAMPING, "cells_per_radius", cells, "fem_dt_s", fem_dt,
                          "links_dt_s", 1e-3, "runs", jruns, "blew_up", blowups, "met_faults", recovered, "finite",
                          all_finite, "fem_consistent_under_scale", fem_consistent, "links_spread_under_scale",
                          num(links_spread));
  if (!doc || tx_report_save(doc, a->out_dir, "organ-stability.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "organ-stability: out of memory"), 1;
  }
  json_decref(doc);
  // the force over Hertz against the scale, both modes (blown-up runs left out)
  double xs[2][VALUES], ys[2][VALUES];
  int n[2] = {0, 0};
  for (int md = 0; md < 2; md++)
    for (int v = 0; v < VALUES; v++)
      if (isfinite(scale_ratio[md][v])) xs[md][n[md]] = factor_values[0][v], ys[md][n[md]++] = scale_ratio[md][v];
  char png[4200];
  snprintf(png, sizeof png, "%s/organ-stability.png", a->out_dir);
  tx_plot_series series[] = {{"FEM (SI units)", xs[0], ys[0], n[0], true, 1}, {"links", xs[1], ys[1], n[1], true, 2}};
  tx_plot p = {"Geometry scaled, parameters kept: force at d/R = 0.1 over Hertz", "scale of the geometry",
               "force / Hertz force at that scale", true, true, series, 2};
  bool plotted = tx_plot_png(png, &p) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("\nwrote %s/organ-stability.json, .csv%s\n", a->out_dir, plotted ? ", .png" : "");
  return all_finite ? 0 : 1;
#endif
}
