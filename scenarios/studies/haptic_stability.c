// tactus study haptic-stability: how stiff a virtual wall can be on the
// simulated device before it goes unstable, against Colgate's passivity
// bound K_max = 2 (b - B) / T, at servo periods of 0.25, 1 and 4 ms, and
// what the passivity controller adds. The experiment is wall_stability.c.
#include "studies.h"

#include "../../controllers/haptics/wall_stability.h"
#include "../../views/plot.h"
#include "../../views/report.h"
#include "../command/command.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define PERIODS_MAX 3

typedef struct row {
  double period, theory, measured, spring_pc, port_pc;
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
    const char* bad = tx_wall_case_check(c);
    if (bad) return tx_bad_input("--set: %s", bad);
  }
  return 0;
}

static double largest(tx_wall_case c, tx_wall_pc pc) {
  c.passivity = pc;
  return tx_wall_largest_stable(&c, 10, 1e6, 0.01).k;
}

static int write_plot(const char* dir, const tx_wall_case* c, const row* rows, int n, char* err, size_t en) {
  enum { DENSE = 64 };
  double tx[DENSE], ty[DENSE], px[PERIODS_MAX], measured[PERIODS_MAX], spring[PERIODS_MAX], port[PERIODS_MAX];
  for (int i = 0; i < DENSE; i++) {
    tx[i] = 0.1 * pow(100, i / (DENSE - 1.0)); // 0.1 to 10 ms
    ty[i] = tx_wall_colgate_bound(c->device.damping, c->damping, tx[i] * 1e-3);
  }
  for (int i = 0; i < n; i++)
    px[i] = rows[i].period * 1e3, measured[i] = rows[i].measured, spring[i] = rows[i].spring_pc, port[i] = rows[i].port_pc;
  tx_plot_series s[] = {
      {"Colgate bound 2(b-B)/T", tx, ty, DENSE, false, 1},
      {"measured, no passivity control", px, measured, n, true, 9},
      {"passivity control (spring reference)", px, spring, n, true, 10},
      {"passivity control (port energy)", px, port, n, true, 8},
  };
  char title[160], path[4200];
  snprintf(title, sizeof title, "Largest stable wall stiffness: m = %g kg, b = %g N s/m, B = %g N s/m",
           c->device.mass, c->device.damping, c->damping);
  tx_plot p = {title, "servo period T (ms)", "largest stable stiffness K (N/m)", true, true, s, 4};
  snprintf(path, sizeof path, "%s/haptic-stability.png", dir);
  return tx_plot_png(path, &p, err, en);
}

int tx_study_haptic_stability(const tx_study_args* a) {
  tx_wall_case c = tx_wall_case_default();
  double periods[PERIODS_MAX] = {0.25e-3, 1e-3, 4e-3};
  int n = PERIODS_MAX;
  int rc = apply(&c, a, periods, &n);
  if (rc) return rc;

  printf("study haptic-stability: a wall on the simulated device, m = %g kg, b = %g N s/m, wall damping B = %g N s/m\n",
         c.device.mass, c.device.damping, c.damping);
  printf("  %8s %12s %12s %7s %16s %7s %16s %7s\n", "T ms", "bound N/m", "measured", "ratio", "PC spring N/m", "gain",
         "PC port N/m", "gain");
  row rows[PERIODS_MAX];
  for (int i = 0; i < n; i++) {
    c.device.period = periods[i];
    row* r = &rows[i];
    r->period = periods[i];
    r->theory = tx_wall_colgate_bound(c.device.damping, c.damping, periods[i]);
    r->measured = largest(c, TX_WALL_PC_OFF);
    r->spring_pc = largest(c, TX_WALL_PC_SPRING);
    r->port_pc = largest(c, TX_WALL_PC_PORT);
    printf("  %8.3g %12.1f %12.1f %7.3f %16.1f %7.2f %16.1f %7.2f\n", periods[i] * 1e3, r->theory, r->measured,
           r->measured / r->theory, r->spring_pc, r->spring_pc / r->measured, r->port_pc, r->port_pc / r->measured);
  }

  // JSON and CSV, each whole or absent
  json_t* cases = json_array();
  char csv_path[4200], tmp[4300];
  snprintf(csv_path, sizeof csv_path, "%s/haptic-stability.csv", a->out_dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", csv_path);
  FILE* csv = fopen(tmp, "w");
  if (!csv) return tx_bad_input("--out %s: cannot write haptic-stability.csv", a->out_dir);
  fprintf(csv, "period_s,k_max_theory_n_m,k_max_measured_n_m,k_max_with_passivity_control_n_m,"
               "k_max_with_port_passivity_control_n_m\n");
  for (int i = 0; i < n; i++) {
    const row* r = &rows[i];
    fprintf(csv, "%.9g,%.6g,%.6g,%.6g,%.6g\n", r->period, r->theory, r->measured, r->spring_pc, r->port_pc);
    json_array_append_new(cases, json_pack("{s:f,s:f,s:f,s:f,s:f,s:f,s:f}", "period_s", r->period, "k_max_theory",
                                           r->theory, "k_max_measured", r->measured, "measured_over_theory",
                                           r->measured / r->theory, "k_max_with_passivity_control", r->spring_pc,
                                           "passivity_control_gain", r->spring_pc / r->measured,
                                           "k_max_with_port_passivity_control", r->port_pc));
  }
  char err[1024];
  if (fclose(csv) != 0 || rename(tmp, csv_path) != 0) return remove(tmp), fprintf(stderr, "tactus: %s: cannot write\n", csv_path), 1;
  json_t* doc = json_pack("{s:s,s:{s:f,s:f,s:f,s:f},s:f,s:s,s:s,s:o}", "study", "haptic-stability", "device", "mass_kg",
                          c.device.mass, "damping_n_s_m", c.device.damping, "quantum_m", c.device.quantum,
                          "hand_stiffness_n_m", c.device.hand_stiffness, "wall_damping_n_s_m", c.damping, "units",
                          "stiffness in N/m, period in s", "passivity_control",
                          "spring: the observer less the energy an ideal continuous spring holds; port: the energy "
                          "at the device port alone",
                          "cases", cases);
  if (!doc || tx_report_save(doc, a->out_dir, "haptic-stability.json", err, sizeof err)) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", err), 1;
  }
  json_decref(doc);
  bool plotted = write_plot(a->out_dir, &c, rows, n, err, sizeof err) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", err);

  printf("\ntargets:\n");
  bool all = true;
  for (int i = 0; i < n; i++) {
    double off = fabs(rows[i].measured / rows[i].theory - 1) * 100, gain = rows[i].spring_pc / rows[i].measured;
    printf("  T = %-6.3g ms: measured within 25%% of the bound: %5.1f%% off %-8s passivity control >= 2x: %5.2fx %s\n",
           rows[i].period * 1e3, off, off <= 25 ? "met" : "MISSED", gain, gain >= 2 ? "met" : "MISSED");
    all &= off <= 25 && gain >= 2;
  }
  printf("%s\nwrote %s/haptic-stability.json, .csv%s\n", all ? "all targets met" : "some targets MISSED", a->out_dir,
         plotted ? " and .png" : "");
  return 0;
}
