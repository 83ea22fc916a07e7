// tactus study haptic-stability: how stiff a virtual wall can be on the
// simulated device before it goes unstable, against Colgate's passivity
// bound K_max = 2 (b - |B|) / T and the exact stability boundary of the
// sampled loop, at servo periods of 0.25, 1 and 4 ms, and what the passivity
// controller adds, run through the `haptics` controller's own force path
// (tx_haptic_tick). The experiment is wall_stability.c.
#include "studies.h"

#include "experiments/wall_stability.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"
#include "../scenarios/command.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define PERIODS_MAX 3

// the wall dampings of the second table, as fractions of the device's b:
// none (Colgate's bound is then the boundary), a damper half the device's
// (the two part: the boundary is near 2 (b + B) / T) and a negative one of
// that size (a wall that cancels friction: they agree again)
static const double b_fractions[] = {0, 0.5, -0.5};
#define NB 3

typedef struct row {
  double period, theory, exact, measured, port_pc, spring_pc;
  double b_damping[NB], b_colgate[NB], b_exact[NB], b_measured[NB];
} row;

// --set KEY=VALUE onto the case; one period replaces the three
static int apply(tx_wall_case* c, const tx_study_args* a, double* periods, int* nperiods) {
  for (int i = 0; i < a->nsets; i++) {
    const char* text = a->sets[i];
    const char* eq = strchr(text, '=');
    double v;
    if (!eq || !tx_parse_num(eq + 1, -1e300, 1e300, &v))
      return tx_bad_input("--set %s: expected KEY=NUMBER", text);
    size_t len = (size_t)(eq - text);
    struct { const char* key; double* field; } keys[] = {
        {"device.damping", &c->device.damping}, {"device.mass", &c->device.mass},
        {"device.quantum", &c->device.quantum}, {"wall.damping", &c->damping}};
    bool found = false;
    for (size_t k = 0; k < sizeof keys / sizeof keys[0] && !found; k++)
      if (strlen(keys[k].key) == len && strncmp(text, keys[k].key, len) == 0) *keys[k].field = v, found = true;
    if (!found && len == strlen("device.period") && strncmp(text, "device.period", len) == 0)
      periods[0] = v, *nperiods = 1, found = true;
    if (!found)
      return tx_bad_input("--set %s: unknown key (known: device.damping, device.mass, device.period, device.quantum, "
                          "wall.damping)", text);
  }
  for (int p = 0; p < *nperiods; p++) {
    c->device.period = periods[p];
    if (tx_wall_case_check(c)) return tx_bad_input("--set: %s", tx_error());
  }
  return 0;
}

// 0 when not even the lowest stiffness is stable (a wall damping below -b)
static double largest(tx_wall_case c, tx_wall_pc pc) {
  c.passivity = pc;
  tx_wall_search s = tx_wall_largest_stable(&c, 10, 1e6, 0.01);
  return s.lo_unstable ? 0 : s.k;
}

// a JSON number, or null for a ratio to a bound of 0 (JSON has no infinity)
static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

static int write_plot(const char* dir, const tx_wall_case* c, const row* rows, int n) {
  enum { DENSE = 64 };
  double tx[DENSE], ty[DENSE], px[PERIODS_MAX], measured[PERIODS_MAX], spring[PERIODS_MAX], port[PERIODS_MAX];
  for (int i = 0; i < DENSE; i++) {
    tx[i] = 0.1 * pow(100, i / (DENSE - 1.0)); // 0.1 to 10 ms
    ty[i] = tx_wall_colgate_bound(c->device.damping, c->damping, tx[i] * 1e-3);
  }
  double ex[DENSE];
  tx_sim_device_def d = c->device;
  for (int i = 0; i < DENSE; i++) {
    d.period = tx[i] * 1e-3;
    ex[i] = tx_wall_exact_bound(&d, c->damping);
  }
  for (int i = 0; i < n; i++)
    px[i] = rows[i].period * 1e3, measured[i] = rows[i].measured, spring[i] = rows[i].spring_pc, port[i] = rows[i].port_pc;
  tx_plot_series s[] = {
      {"Colgate bound 2(b-|B|)/T", tx, ty, DENSE, false, 1},
      {"exact boundary (eigenvalues)", tx, ex, DENSE, false, 3},
      {"measured, no passivity control", px, measured, n, true, 9},
      {"passivity control, spring reference (default)", px, spring, n, true, 10},
      {"passivity control, port reference", px, port, n, true, 8},
  };
  char title[160], path[4200];
  snprintf(title, sizeof title, "Largest stable wall stiffness: m = %g kg, b = %g N s/m, B = %g N s/m",
           c->device.mass, c->device.damping, c->damping);
  tx_plot p = {title, "servo period T (ms)", "largest stable stiffness K (N/m)", true, true, s, 5};
  snprintf(path, sizeof path, "%s/haptic-stability.png", dir);
  return tx_plot_png(path, &p);
}

int tx_study_haptic_stability(const tx_study_args* a) {
  tx_wall_case c = tx_wall_case_default();
  double periods[PERIODS_MAX] = {0.25e-3, 1e-3, 4e-3};
  int n = PERIODS_MAX;
  int rc = apply(&c, a, periods, &n);
  if (rc) return rc;

  printf("study haptic-stability: a wall on the simulated device, m = %g kg, b = %g N s/m, wall damping B = %g N s/m,\n"
         "through the haptics controller's force path (passivity observer and controller, safety chain)\n",
         c.device.mass, c.device.damping, c.damping);
  printf("  %6s %10s %10s %10s %7s %7s %15s %6s %15s %6s\n", "T ms", "Colgate", "exact", "measured", "/Colg.",
         "/exact", "PC spring N/m", "gain", "PC port N/m", "gain");
  row rows[PERIODS_MAX];
  for (int i = 0; i < n; i++) {
    c.device.period = periods[i];
    row* r = &rows[i];
    r->period = periods[i];
    r->theory = tx_wall_colgate_bound(c.device.damping, c.damping, periods[i]);
    r->exact = tx_wall_exact_bound(&c.device, c.damping);
    r->measured = largest(c, TX_WALL_PC_OFF);
    r->port_pc = largest(c, TX_WALL_PC_PORT);
    r->spring_pc = largest(c, TX_WALL_PC_SPRING);
    printf("  %6.3g %10.1f %10.1f %10.1f %7.3f %7.3f %15.1f %6.2f %15.1f %6.2f\n", periods[i] * 1e3, r->theory,
           r->exact, r->measured, r->measured / r->theory, r->measured / r->exact, r->spring_pc,
           r->spring_pc / r->measured, r->port_pc, r->port_pc / r->measured);
  }
  printf("\nwall damping B against the two bounds, no passivity control:\n  %6s %8s %10s %10s %10s %7s\n", "T ms",
         "B N s/m", "Colgate", "exact", "measured", "/exact");
  for (int i = 0; i < n; i++) {
    row* r = &rows[i];
    tx_wall_case cb = c;
    cb.device.period = periods[i];
    for (int j = 0; j < NB; j++) {
      cb.damping = b_fractions[j] * c.device.damping;
      r->b_damping[j] = cb.damping;
      r->b_colgate[j] = tx_wall_colgate_bound(c.device.damping, cb.damping, periods[i]);
      r->b_exact[j] = tx_wall_exact_bound(&cb.device, cb.damping);
      r->b_measured[j] = largest(cb, TX_WALL_PC_OFF);
      printf("  %6.3g %8.3g %10.1f %10.1f %10.1f %7.3f\n", periods[i] * 1e3, cb.damping, r->b_colgate[j],
             r->b_exact[j], r->b_measured[j], r->b_measured[j] / r->b_exact[j]);
    }
  }

  // JSON and CSV, each whole or absent
  json_t* cases = json_array();
  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "haptic-stability.csv")) return json_decref(cases), tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "period_s,k_max_theory_n_m,k_max_exact_n_m,k_max_measured_n_m,k_max_with_passivity_control_n_m,"
               "k_max_with_port_passivity_control_n_m\n");
  for (int i = 0; i < n; i++) {
    const row* r = &rows[i];
    fprintf(csv, "%.9g,%.6g,%.6g,%.6g,%.6g,%.6g\n", r->period, r->theory, r->exact, r->measured, r->spring_pc,
            r->port_pc);
    json_t* damping = json_array();
    for (int j = 0; j < NB; j++)
      json_array_append_new(damping, json_pack("{s:f,s:f,s:f,s:f}", "wall_damping_n_s_m", r->b_damping[j],
                                               "k_max_theory", r->b_colgate[j], "k_max_exact", r->b_exact[j],
                                               "k_max_measured", r->b_measured[j]));
    json_array_append_new(cases, json_pack("{s:f,s:f,s:f,s:f,s:o,s:o,s:f,s:o,s:f,s:o}", "period_s", r->period,
                                           "k_max_theory", r->theory, "k_max_exact", r->exact, "k_max_measured",
                                           r->measured, "measured_over_theory", num(r->measured / r->theory),
                                           "measured_over_exact", num(r->measured / r->exact),
                                           "k_max_with_passivity_control", r->spring_pc, "passivity_control_gain",
                                           num(r->spring_pc / r->measured), "k_max_with_port_passivity_control",
                                           r->port_pc, "wall_damping", damping));
  }
  if (!tx_aside_end(&out)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_t* doc = json_pack("{s:s,s:{s:f,s:f,s:f,s:f},s:f,s:s,s:s,s:o}", "study", "haptic-stability", "device", "mass_kg",
                          c.device.mass, "damping_n_s_m", c.device.damping, "quantum_m", c.device.quantum,
                          "hand_stiffness_n_m", c.device.hand_stiffness, "wall_damping_n_s_m", c.damping, "units",
                          "stiffness in N/m, period in s", "passivity_control",
                          "the haptics controller's: k_max_with_passivity_control with its default reference, "
                          "spring (the energy at the device port less what the wall's spring holds, plus what the "
                          "device's damping absorbed); port: the energy at the device port",
                          "cases", cases);
  if (!doc || tx_report_save(doc, a->out_dir, "haptic-stability.json")) {
    fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "out of memory");
    return json_decref(doc), 1;
  }
  json_decref(doc);
  bool plotted = write_plot(a->out_dir, &c, rows, n) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());

  // the exact boundary is what the simulation must find; Colgate's bound is
  // checked where it should hold, B = 0 (the first wall damping above); the
  // shipped passivity control must not make the wall softer (but for the
  // search's 1% tolerance, twice)
  printf("\ntargets:\n");
  bool all = true;
  for (int i = 0; i < n; i++) {
    double off = fabs(rows[i].b_measured[0] / rows[i].b_colgate[0] - 1) * 100;
    double worst = 0;
    for (int j = 0; j < NB; j++) worst = fmax(worst, fabs(rows[i].b_measured[j] / rows[i].b_exact[j] - 1) * 100);
    double gain = rows[i].spring_pc / rows[i].measured;
    printf("  T = %-6.3g ms: B = 0 within 25%% of Colgate's bound: %5.1f%% off %-8s every B within 5%% of the exact "
           "boundary: %5.1f%% off %-8s passivity control >= 0.98x: %5.2fx %s\n",
           rows[i].period * 1e3, off, off <= 25 ? "met" : "MISSED", worst, worst <= 5 ? "met" : "MISSED", gain,
           gain >= 0.98 ? "met" : "MISSED");
    all &= off <= 25 && worst <= 5 && (gain >= 0.98 || rows[i].measured == 0); // nothing to soften
  }
  printf("%s\nwrote %s/haptic-stability.json, .csv%s\n", all ? "all targets met" : "some targets MISSED", a->out_dir,
         plotted ? " and .png" : "");
  return 0;
}
