// tactus study cautery-heat: the organs' thermal solver (controllers/organs/
// thermal.h) against closed forms for a Gaussian heat source in an infinite
// medium (studies/experiments/cautery_heat.h), on a block of tetrahedra far
// larger than the heated region: the transient with no perfusion (erfc) and
// the Pennes steady state with the liver's perfusion, each under mesh
// refinement (the step the solver's stable one, so dt ~ h^2), and the step
// refined alone on one mesh against a step 64 times finer. Error against CPU
// time and the observed order. Writes cautery-heat.csv, .json and .png.
#include "studies.h"

#include "experiments/cautery_heat.h"
#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include "../model/error.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LEVELS_MAX 4
#define STEPS 4

static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

// the bounds the finest level meets (docs/validation.md, "Heat")
#define TRANSIENT_BOUND 0.01 // at h = 0.5 mm (quick and full)
#define PERFUSED_BOUND 0.02  // at h = 1 mm (quick) ; 0.5 mm (full)

int tx_study_cautery_heat(const tx_study_args* a) {
  bool quick;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
  const int cells[2][LEVELS_MAX] = {{10, 20, 40, 80}, {12, 24, 48, 96}};
  const int nlevels[2] = {quick ? 3 : 4, quick ? 2 : 3};
  const double bound[2] = {TRANSIENT_BOUND, quick ? 0.03 : PERFUSED_BOUND};
  static const char* const names[2] = {"transient", "perfused"};
  printf("study cautery-heat: Pennes bioheat on linear tetrahedra (lumped mass, explicit Euler at the stable step), "
         "liver (IT'IS), a Gaussian source of 0.5 W and radius 1.5 mm at the centre of a block held at T_a%s\n\n",
         quick ? ", quick" : "");

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "cautery-heat.csv")) return tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "check,h_m,nodes,tetrahedra,dt_s,steps,error,max_error,order,reference,cpu_s\n");

  bool all = true;
  json_t* checks = json_array();
  double px[3][LEVELS_MAX], py[3][LEVELS_MAX];
  static const char* const what[2] = {
      "transient, no perfusion, 10 s from rest, block 20 mm: P/(4 pi k r) [erfc(r/sqrt(2 s^2 + 4 alpha t)) - erfc(r/(s sqrt 2))]",
      "steady state with the liver's perfusion (L = 3.0 mm), 600 s (9 time constants), block 24 mm: the Gaussian-smoothed "
      "P exp(-r/L)/(4 pi k r)"};
  for (int k = 0; k < 2; k++) {
    printf("  %s: %s\n  error: relative L2 within 6 mm of the source (nodal volumes), against the closed form\n"
           "  %7s %9s %10s %9s %7s %9s %9s %6s %9s\n",
           names[k], what[k], "h mm", "nodes", "tets", "dt s", "steps", "L2 err", "max err", "order", "CPU s");
    json_t* levels = json_array();
    bool falls = true;
    double prev = NAN, order = NAN;
    tx_heat_result r = {0};
    for (int l = 0; l < nlevels[k]; l++) {
      tx_heat_case c = tx_heat_case_default(k == 1);
      c.cells = cells[k][l];
      if (!tx_heat_run(&c, false, &r)) {
        tx_aside_drop(&out), json_decref(checks), json_decref(levels);
        return fprintf(stderr, "tactus: study cautery-heat: %s\n", tx_error()), 1;
      }
      order = l > 0 ? log(prev / r.error) / log(2.0) : NAN;
      if (l > 0 && !(r.error < prev)) falls = false;
      printf("  %7.3g %9d %10d %9.4g %7d %8.3f%% %8.3f%% %6.2f %9.3f\n", r.h_m * 1e3, r.nodes, r.tets, r.dt_s, r.steps,
             100 * r.error, 100 * r.max_error, order, r.cpu_s);
      fflush(stdout);
      fprintf(csv, "%s,%.6g,%d,%d,%.6g,%d,%.6g,%.6g,%.4g,closed form,%.6g\n", names[k], r.h_m, r.nodes, r.tets, r.dt_s,
              r.steps, r.error, r.max_error, order, r.cpu_s);
      json_array_append_new(levels, json_pack("{s:f,s:i,s:i,s:f,s:i,s:f,s:f,s:o,s:f,s:f}", "h_m", r.h_m, "nodes", r.nodes,
                                              "tetrahedra", r.tets, "dt_s", r.dt_s, "steps", r.steps, "error", r.error,
                                              "max_error", r.max_error, "order", num(order), "peak_rise_k", r.peak_k,
                                              "cpu_s", r.cpu_s));
      px[k][l] = r.cpu_s, py[k][l] = 100 * r.error;
      prev = r.error;
    }
    bool within = r.error <= bound[k], ordered = order >= 1.5;
    all &= falls && within && ordered;
    printf("  error falls at every refinement: %s; finest within %g%%: %s; observed order %.2f >= 1.5 (2 expected): %s\n\n",
           falls ? "yes" : "NO", 100 * bound[k], within ? "yes" : "NO", order, ordered ? "yes" : "NO");
    json_array_append_new(checks, json_pack("{s:s,s:s,s:s,s:o,s:b,s:f,s:b,s:o,s:b}", "check", names[k], "what", what[k],
                                            "rung", "closed form", "levels", levels, "error_falls", falls, "bound", bound[k],
                                            "finest_within_bound", within, "observed_order", num(order), "order_at_least_1_5",
                                            ordered));
  }

  // the step alone, on the 1 mm transient mesh: against a step 64 times
  // finer on the same mesh (a converged reference), and against the closed form
  tx_heat_case c = tx_heat_case_default(false);
  tx_heat_result ref;
  double stable;
  {
    double* x;
    int *tet, n, nt;
    if (!tx_heat_block(c.half_m, c.cells, &x, &n, &tet, &nt)) return tx_aside_drop(&out), json_decref(checks), 1;
    tx_thermal* h = tx_thermal_create(x, n, tet, nt, &c.tissue, NULL, 1);
    free(x), free(tet);
    if (!h) return tx_aside_drop(&out), json_decref(checks), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    stable = tx_thermal_stable_dt(h);
    tx_thermal_destroy(h);
  }
  int n0 = (int)ceil(c.t_end_s / stable);
  c.dt_s = c.t_end_s / (64.0 * n0);
  if (!tx_heat_run(&c, true, &ref)) return tx_aside_drop(&out), json_decref(checks), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  printf("  step: the transient on the 1 mm mesh, the step refined from the stable %.3g s; error against dt / 64 on the "
         "same mesh (converged reference) and against the closed form\n  %9s %7s %12s %6s %12s %9s\n",
         c.t_end_s / n0, "dt s", "steps", "vs dt/64", "order", "vs exact", "CPU s");
  json_t* steps = json_array();
  bool sfalls = true;
  double sprev = NAN, sorder = NAN;
  for (int l = 0; l < STEPS; l++) {
    c.dt_s = c.t_end_s / (n0 << l);
    tx_heat_result r;
    if (!tx_heat_run(&c, true, &r)) {
      free(ref.theta), tx_aside_drop(&out), json_decref(checks), json_decref(steps);
      return fprintf(stderr, "tactus: study cautery-heat: %s\n", tx_error()), 1;
    }
    double e = tx_heat_difference(&c, r.theta, ref.theta);
    free(r.theta);
    sorder = l > 0 ? log(sprev / e) / log(2.0) : NAN;
    if (l > 0 && !(e < sprev)) sfalls = false;
    printf("  %9.4g %7d %11.4f%% %6.2f %11.3f%% %9.3f\n", r.dt_s, r.steps, 100 * e, sorder, 100 * r.error, r.cpu_s);
    fflush(stdout);
    fprintf(csv, "step,%.6g,%d,%d,%.6g,%d,%.6g,%.6g,%.4g,dt/64,%.6g\n", r.h_m, r.nodes, r.tets, r.dt_s, r.steps, e,
            r.error, sorder, r.cpu_s);
    json_array_append_new(steps, json_pack("{s:f,s:i,s:f,s:o,s:f,s:f}", "dt_s", r.dt_s, "steps", r.steps,
                                           "error_vs_reference", e, "order", num(sorder), "error_vs_exact", r.error,
                                           "cpu_s", r.cpu_s));
    px[2][l] = r.cpu_s, py[2][l] = 100 * e;
    sprev = e;
  }
  free(ref.theta);
  bool sordered = fabs(sorder - 1) <= 0.2;
  all &= sfalls && sordered;
  printf("  step error falls at every refinement: %s; observed order %.2f within 0.2 of 1 (explicit Euler): %s\n\n",
         sfalls ? "yes" : "NO", sorder, sordered ? "yes" : "NO");

  if (!tx_aside_end(&out)) {
    json_decref(checks), json_decref(steps);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:b,s:s,s:o,s:{s:s,s:o,s:b,s:o,s:b},s:b}", "study", "cautery-heat", "quick", quick, "solver",
                          "Pennes bioheat, linear tetrahedra, lumped mass, explicit Euler at 0.9 x Gershgorin's stable step",
                          "checks", checks, "step", "rung", "converged reference (dt / 64, same mesh)", "levels", steps,
                          "error_falls", sfalls, "observed_order", num(sorder), "order_near_1", sordered, "all_met", all);
  if (!doc || tx_report_save(doc, a->out_dir, "cautery-heat.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "cautery-heat: out of memory"), 1;
  }
  json_decref(doc);

  char png[4200];
  snprintf(png, sizeof png, "%s/cautery-heat.png", a->out_dir);
  tx_plot_series s[] = {{"mesh refined, transient (vs erfc)", px[0], py[0], nlevels[0], false, 1},
                        {"mesh refined, perfused steady state", px[1], py[1], nlevels[1], false, 2},
                        {"step refined, 1 mm mesh (vs dt/64)", px[2], py[2], STEPS, false, 3}};
  tx_plot p = {"Cautery heat against closed forms", "CPU time (s)", "relative L2 error (%)", true, true, s, 3};
  bool plotted = tx_plot_png(png, &p) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("%s\nwrote %s/cautery-heat.json, .csv%s\n", all ? "all targets met" : "some targets MISSED", a->out_dir,
         plotted ? ", .png" : "");
  return 0;
}
