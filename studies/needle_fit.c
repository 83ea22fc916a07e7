// tactus study needle-fit FILE: the voxel tissue and needle fitted to a
// haptic recording (controllers/voxel/needle_fit.h), with the RMS error
// against the search's run time, and the modelled force plotted over the
// recorded one as the voxel needle-insertion paper's Figure 5 does.
#include "studies.h"

#include "experiments/needle_fit.h"
#include "../model/error.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"
#include "../scenarios/command.h"

#include <tactus/model.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EVALS_MAX 5000

typedef struct trace {
  int n;
  double seconds[EVALS_MAX], rms[EVALS_MAX];
  double peak;
} trace;

static void progress(int evaluation, double seconds, double best, void* user) {
  trace* tr = user;
  if (tr->n < EVALS_MAX) tr->seconds[tr->n] = seconds, tr->rms[tr->n] = best, tr->n++;
  if (evaluation % 25 == 0)
    printf("  %10d %10.1f %12.5f %10.2f\n", evaluation, seconds, best, 100 * best / tr->peak), fflush(stdout);
}

// --set evals=N
static int apply(const tx_study_args* a, int* evals) {
  for (int i = 0; i < a->nsets; i++) {
    const char* text = a->sets[i];
    const char* eq = strchr(text, '=');
    double v;
    if (!eq || (size_t)(eq - text) != strlen("evals") || strncmp(text, "evals", 5) != 0)
      return tx_bad_input("--set %s: unknown key (known: evals)", text);
    if (!tx_parse_num(eq + 1, 10, EVALS_MAX, &v) || v != floor(v))
      return tx_bad_input("--set %s: expected a whole number of evaluations in [10, %d]", text, EVALS_MAX);
    *evals = (int)v;
  }
  return 0;
}

static int write_plots(const char* dir, const tx_recording* rec, const double* model, const trace* tr) {
  size_t n = rec->count;
  double* t = malloc(n * sizeof *t);
  double* fr = malloc(n * sizeof *fr);
  double* fm = malloc(n * sizeof *fm);
  if (!t || !fr || !fm) {
    free(t), free(fr), free(fm);
    tx_set_error("out of memory for the plot");
    return -1;
  }
  for (size_t k = 0; k < n; k++) t[k] = rec->rows[k].t, fr[k] = rec->rows[k].f[1], fm[k] = model[3 * k + 1];
  tx_plot_series s[] = {{"recorded", t, fr, (int)n, false, 9}, {"voxel model, fitted", t, fm, (int)n, false, 1}};
  tx_plot p = {"Needle insertion: modelled and recorded force along the needle", "time (s)", "force along the needle (N)",
               false, false, s, 2};
  char path[4200];
  snprintf(path, sizeof path, "%s/needle-fit.png", dir);
  int rc = tx_plot_png(path, &p);
  free(t), free(fr), free(fm);
  if (rc) return rc;
  tx_plot_series c[] = {{"best RMS so far", tr->seconds, tr->rms, tr->n, false, 1}};
  tx_plot q = {"Needle fit: RMS error against run time", "run time (s)", "RMS error (N)", false, true, c, 1};
  snprintf(path, sizeof path, "%s/needle-fit-rms.png", dir);
  return tx_plot_png(path, &q);
}

int tx_study_needle_fit(const tx_study_args* a) {
  int evals = 200;
  int rc = apply(a, &evals);
  if (rc) return rc;
  tx_recording rec;
  if (!tx_recording_read(&rec, a->file)) return tx_bad_input("%s", tx_error());
  static trace tr; // large; one study per process
  memset(&tr, 0, sizeof tr);
  for (size_t k = 0; k < rec.count; k++) {
    const double* f = rec.rows[k].f;
    tr.peak = fmax(tr.peak, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  }
  if (!(tr.peak > 0)) {
    tx_recording_free(&rec);
    return tx_bad_input("%s: every force is zero: nothing to fit", a->file);
  }
  tx_needle_fit_params p = tx_needle_fit_params_default();
  double start = tx_needle_fit_simulate(&p, &rec, NULL);
  printf("study needle-fit: %s, %zu rows over %.3f s, peak force %.4f N; at most %d simulations\n", a->file, rec.count,
         rec.rows[rec.count - 1].t - rec.rows[0].t, tr.peak, evals);
  printf("  starting RMS %.5f N (%.2f%% of the peak)\n\n", start, 100 * start / tr.peak);
  printf("  %10s %10s %12s %10s\n", "simulation", "run time s", "best RMS N", "% of peak");
  tx_needle_fit_result res;
  if (!tx_needle_fit(&rec, &p, evals, progress, &tr, &res)) {
    fprintf(stderr, "tactus: %s\n", tx_error());
    tx_recording_free(&rec);
    return 1;
  }
  printf("  %10d %10.1f %12.5f %10.2f\n", res.evaluations, res.seconds, res.rms, 100 * res.rms / res.peak);

  // the best parameters once more, for the plot and the force CSV
  double* model = malloc(3 * rec.count * sizeof *model);
  double rms = model ? tx_needle_fit_simulate(&p, &rec, model) : -1;
  if (rms < 0) {
    fprintf(stderr, "tactus: needle fit: %s\n", model ? tx_error() : "out of memory");
    free(model), tx_recording_free(&rec);
    return 1;
  }
  char rms_text[128];
  int status = 0;
  tx_aside o;
  if (!tx_aside_begin(&o, a->out_dir, "needle-fit.csv")) {
    status = 1;
  } else {
    fprintf(o.f, "simulation,run_time_s,best_rms_n,best_rms_percent_of_peak\n");
    for (int i = 0; i < tr.n; i++) fprintf(o.f, "%d,%.6f,%.9g,%.6g\n", i + 1, tr.seconds[i], tr.rms[i], 100 * tr.rms[i] / tr.peak);
    if (!tx_aside_end(&o)) status = 1;
  }
  if (!status && !tx_aside_begin(&o, a->out_dir, "needle-fit-force.csv")) {
    status = 1;
  } else if (!status) {
    fprintf(o.f, "t_s,depth_m,recorded_fx_n,recorded_fy_n,recorded_fz_n,model_fx_n,model_fy_n,model_fz_n\n");
    for (size_t k = 0; k < rec.count; k++) {
      const tx_recording_row* r = &rec.rows[k];
      fprintf(o.f, "%.6f,%.9f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", r->t, r->depth, r->f[0], r->f[1], r->f[2], model[3 * k],
              model[3 * k + 1], model[3 * k + 2]);
    }
    if (!tx_aside_end(&o)) status = 1;
  }
  if (status) fprintf(stderr, "tactus: %s\n", tx_error());
  bool met = rms <= 0.1 * tr.peak;
  json_t* doc = json_pack(
      "{s:s,s:s,s:i,s:f,s:f,s:f,s:f,s:i,s:f,s:b,s:{s:f,s:f,s:f,s:f,s:f,s:f,s:f,s:f,s:f,s:f},s:s}", "study", "needle-fit",
      "recording", a->file, "rows", (int)rec.count, "peak_force_n", tr.peak, "start_rms_n", start, "rms_n", rms,
      "rms_percent_of_peak", 100 * rms / tr.peak, "simulations", res.evaluations, "run_time_s", res.seconds,
      "target_met", met, "params", "spring_n_m", p.spring, "damper_n_s_m", 2 * p.damping_ratio * sqrt(p.spring * p.mass),
      "damping_ratio", p.damping_ratio, "radius_m", p.radius, "mass_kg", p.mass, "elasticity", p.elasticity,
      "damage_shrink", p.damage_shrink, "rupture_force_n", p.rupture_force, "cutting_force_n", p.cutting_force,
      "friction", p.friction, "target", "RMS <= 10% of the peak recorded force");
  if (!status && (!doc || tx_report_save(doc, a->out_dir, "needle-fit.json")))
    status = 1, fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "out of memory");
  json_decref(doc);
  bool plotted = !status && write_plots(a->out_dir, &rec, model, &tr) == 0;
  if (!status && !plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("\nfitted: k_s %.4g N/m, k_d %.4g N s/m (damping ratio %.3f), radius %.4g m, mass %.4g kg, e %.3f,\n"
         "        damage shrink %.3f, rupture %.4g N, cutting %.4g N, friction %.3f\n",
         p.spring, 2 * p.damping_ratio * sqrt(p.spring * p.mass), p.damping_ratio, p.radius, p.mass, p.elasticity,
         p.damage_shrink, p.rupture_force, p.cutting_force, p.friction);
  printf("\ntargets:\n  %-44s %-26s %-12s %s\n", "RMS error of the fitted model",
         (snprintf(rms_text, sizeof rms_text, "%.4f N = %.2f%% of %.4f N", rms, 100 * rms / tr.peak, tr.peak), rms_text),
         "<= 10% peak", met ? "met" : "MISSED");
  if (!status)
    printf("wrote %s/needle-fit.json, .csv, needle-fit-force.csv%s\n", a->out_dir,
           plotted ? ", needle-fit.png and needle-fit-rms.png" : "");
  free(model);
  tx_recording_free(&rec);
  return status;
}
