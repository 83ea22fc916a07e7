// tactus study thread-accuracy: the rod against the catenary, and the
// follow-the-leader thread's length.
//
// A perfectly flexible rod (bend_factor 0: the catenary's chain) of length
// L = 12 cm hangs between two pinned ends s = 10 cm apart under gravity,
// settles (damping 10 1/s, 3 s), and is compared with the catenary
// y = a cosh(x / a) - a cosh(s / (2 a)), a from L = 2 a sinh(s / (2 a)):
// the error is the largest vertical distance of a node from the curve, as a
// fraction of the sag a cosh(s / (2 a)) - a. Swept: the node count (at 8
// iterations and 1 ms), the iterations (64 nodes, 1 ms) and the time step
// (64 nodes, 8 iterations), each with the CPU time per simulated second.
// Then follow-the-leader: its head runs 2 m along a circle and a helix and
// the length error is |length - L| / L (0 to rounding). --set path=quick:
// fewer settings, for the test.
#include "studies.h"

#include "../controllers/thread/thread.h"
#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SPAN 0.1
#define LENGTH 0.12

typedef struct acc_row {
  const char* sweep; // "nodes", "iterations" or "time_step"
  int nodes, iterations;
  double dt;
  double error;   // fraction of the sag
  double cpu;     // CPU s per simulated s
  double strain;  // the largest segment strain
} acc_row;

static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

// the catenary's a for length L over span s: 2 a sinh(s / (2 a)) = L, by
// bisection on log a (the left side falls from infinity to s as a grows)
static double catenary_a(double span, double length) {
  double lo = log(1e-6), hi = log(1e6);
  for (int i = 0; i < 200; i++) {
    double m = 0.5 * (lo + hi), a = exp(m);
    double f = 2 * a * sinh(span / (2 * a)) - length;
    if (!isfinite(f) || f > 0) lo = m;
    else hi = m;
  }
  return exp(0.5 * (lo + hi));
}

static int hang(int nodes, int iterations, double dt, double settle, acc_row* r) {
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = nodes;
  d.length = LENGTH;
  d.bend_factor = 0;
  d.damping = 10;
  d.iterations = iterations;
  d.max_substep = dt;
  d.self_collision = false;
  d.pin_tail = true;
  tx_thread* t = tx_thread_create(&d);
  double* x = malloc(sizeof(double) * 3 * nodes);
  if (!t || !x) {
    tx_thread_destroy(t);
    free(x);
    return fprintf(stderr, "tactus: study thread-accuracy: %s\n", t ? "out of memory" : tx_error()), 1;
  }
  // a parabola between the pins as the start: it settles into the catenary
  for (int i = 0; i < nodes; i++) {
    double u = -0.5 + (double)i / (nodes - 1);
    x[3 * i] = SPAN * u, x[3 * i + 1] = -0.05 * (1 - 4 * u * u), x[3 * i + 2] = 0;
  }
  tx_thread_set_positions(t, x);
  tx_thread_pin(t, nodes - 1, x + 3 * (nodes - 1));
  int steps = (int)lround(settle / dt);
  double c0 = cpu_now();
  for (int k = 0; k < steps; k++)
    if (tx_thread_step(t, dt) != TX_THREAD_OK) {
      tx_thread_destroy(t);
      free(x);
      return fprintf(stderr, "tactus: study thread-accuracy: the rod faulted at %d nodes\n", nodes), 1;
    }
  r->cpu = (cpu_now() - c0) / settle;
  double a = catenary_a(SPAN, LENGTH), top = a * cosh(SPAN / (2 * a)), sag = top - a, err = 0;
  for (int i = 0; i < nodes; i++) {
    const double* p = tx_thread_position(t, i);
    double y = a * cosh(p[0] / a) - top;
    err = fmax(err, fabs(p[1] - y));
  }
  r->nodes = nodes, r->iterations = iterations, r->dt = dt;
  r->error = err / sag;
  r->strain = tx_thread_max_strain(t);
  tx_thread_destroy(t);
  free(x);
  return 0;
}

// follow-the-leader: the head 2 m along a helix; the length error
static double ftl_length_error(void) {
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 64;
  d.length = LENGTH;
  d.self_collision = false;
  tx_thread* t = tx_thread_create(&d);
  if (!t) return NAN;
  double worst = 0;
  for (int k = 1; k <= 2000; k++) { // 1 mm a step
    double phi = k * 0.001 / 0.02;
    double head[3] = {0.02 * cos(phi) - 0.02, 0.02 * sin(phi), 0.0002 * k};
    tx_thread_set_head(t, head);
    tx_thread_step(t, 1e-3);
    worst = fmax(worst, fabs(tx_thread_current_length(t) - LENGTH) / LENGTH);
  }
  tx_thread_destroy(t);
  return worst;
}

static int write_outputs(const char* dir, const acc_row* rows, int n, double ftl_err, bool quick) {
  tx_aside o;
  FILE* f = tx_aside_begin(&o, dir, "thread-accuracy.csv") ? o.f : NULL;
  if (f) {
    fprintf(f, "sweep,nodes,iterations,time_step_s,error_of_sag,cpu_s_per_sim_s,max_strain\n");
    for (int i = 0; i < n; i++)
      fprintf(f, "%s,%d,%d,%.9g,%.6g,%.6g,%.6g\n", rows[i].sweep, rows[i].nodes, rows[i].iterations, rows[i].dt,
              rows[i].error, rows[i].cpu, rows[i].strain);
  }
  if (!f || !tx_aside_end(&o)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_t* list = json_array();
  for (int i = 0; i < n && list; i++)
    json_array_append_new(list, json_pack("{s:s,s:i,s:i,s:f,s:f,s:f,s:f}", "sweep", rows[i].sweep, "nodes",
                                          rows[i].nodes, "iterations", rows[i].iterations, "time_step_s", rows[i].dt,
                                          "error_of_sag", rows[i].error, "cpu_s_per_sim_s", rows[i].cpu, "max_strain",
                                          rows[i].strain));
  double a = catenary_a(SPAN, LENGTH);
  json_t* doc = json_pack("{s:s,s:s,s:{s:f,s:f,s:f,s:f},s:s,s:o,s:f}", "study", "thread-accuracy", "path",
                          quick ? "quick" : "full", "catenary", "span_m", SPAN, "length_m", LENGTH, "a_m", a, "sag_m",
                          a * cosh(SPAN / (2 * a)) - a, "error",
                          "the largest vertical distance of a node from the catenary, as a fraction of the sag; a "
                          "perfectly flexible rod (bend_factor 0), E = 2 GPa, 0.5 mm, 1140 kg/m^3, damping 10 1/s",
                          "rows", list, "ftl_length_error_rel", ftl_err);
  if (!doc || tx_report_save(doc, dir, "thread-accuracy.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "thread-accuracy: out of memory"), 1;
  }
  json_decref(doc);
  return 0;
}

static int write_plot(const char* dir, const acc_row* rows, int n) {
  static const char* const sweeps[3] = {"nodes", "iterations", "time_step"};
  static const char* const labels[3] = {"node count (8 iterations, 1 ms)", "iterations (64 nodes, 1 ms)",
                                        "time step (64 nodes, 8 iterations)"};
  static double x[3][16], y[3][16];
  tx_plot_series s[3];
  int ns = 0;
  for (int k = 0; k < 3; k++) {
    int m = 0;
    for (int i = 0; i < n && m < 16; i++)
      if (strcmp(rows[i].sweep, sweeps[k]) == 0 && rows[i].error > 0) {
        x[k][m] = rows[i].cpu;
        y[k][m] = 100 * rows[i].error;
        m++;
      }
    if (m) s[ns++] = (tx_plot_series){labels[k], x[k], y[k], m, false, 1 + 4 * k};
  }
  char path[4200];
  snprintf(path, sizeof path, "%s/thread-accuracy.png", dir);
  tx_plot p = {"Rod against the catenary: error vs run time", "run time (CPU s per simulated s)",
               "error (% of the sag)", true, true, s, ns};
  return tx_plot_png(path, &p);
}

int tx_study_thread_accuracy(const tx_study_args* a) {
  bool quick = false;
  for (int i = 0; i < a->nsets; i++) {
    if (strcmp(a->sets[i], "path=quick") == 0) quick = true;
    else if (strcmp(a->sets[i], "path=full") == 0) quick = false;
    else return tx_bad_input("--set %s: thread-accuracy takes path=quick or path=full", a->sets[i]);
  }
  static const int nodes_full[] = {8, 16, 32, 64, 128}, nodes_quick[] = {16, 64};
  static const int its_full[] = {1, 2, 4, 8}, its_quick[] = {1, 8};
  static const double dt_full[] = {1e-4, 3e-4, 1e-3, 3e-3, 1e-2}, dt_quick[] = {3e-3};
  const int* nodes = quick ? nodes_quick : nodes_full;
  const int* its = quick ? its_quick : its_full;
  const double* dts = quick ? dt_quick : dt_full;
  int nn = quick ? 2 : 5, ni = quick ? 2 : 4, nd = quick ? 1 : 5;
  double settle = 3; // s: the slowest mode has decayed by e^-30
  acc_row rows[32];
  int n = 0;
  printf("study thread-accuracy (%s): a flexible rod of %g cm hanging between pins %g cm apart vs the catenary\n\n",
         quick ? "quick" : "full", LENGTH * 100, SPAN * 100);
  printf("  %-10s %6s %10s %10s %12s %14s\n", "sweep", "nodes", "iterations", "step s", "error % sag", "CPU s / sim s");
  for (int s = 0; s < 3; s++) {
    int count = s == 0 ? nn : s == 1 ? ni : nd;
    for (int k = 0; k < count; k++) {
      acc_row* r = &rows[n];
      int rc = s == 0   ? hang(nodes[k], 8, 1e-3, settle, r)
               : s == 1 ? hang(64, its[k], 1e-3, settle, r)
                        : hang(64, 8, dts[k], settle, r);
      if (rc) return 1;
      r->sweep = s == 0 ? "nodes" : s == 1 ? "iterations" : "time_step";
      printf("  %-10s %6d %10d %10.0e %12.4f %14.4f\n", r->sweep, r->nodes, r->iterations, r->dt, 100 * r->error,
             r->cpu);
      n++;
    }
  }
  double ftl = ftl_length_error();
  printf("\n  ftl: the head 2 m along a helix, 64 nodes: length error %.3g of the length\n", ftl);
  double at64 = NAN;
  for (int i = 0; i < n; i++)
    if (strcmp(rows[i].sweep, "nodes") == 0 && rows[i].nodes == 64) at64 = rows[i].error;
  printf("\ntargets:\n");
  printf("  %-44s %-24.4f %-12s %s\n", "catenary error at 64 nodes, 8 iterations (%)", 100 * at64, "<= 1 %",
         at64 <= 0.01 ? "met" : "MISSED");
  printf("  %-44s %-24.3g %-12s %s\n", "ftl length error (fraction)", ftl, "<= 1e-12", ftl <= 1e-12 ? "met" : "MISSED");
  if (write_outputs(a->out_dir, rows, n, ftl, quick)) return 1;
  bool plotted = write_plot(a->out_dir, rows, n) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("\nwrote %s/thread-accuracy.json, .csv%s\n", a->out_dir, plotted ? " and thread-accuracy.png" : "");
  return 0;
}
