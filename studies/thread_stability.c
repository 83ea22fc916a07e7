// tactus study thread-stability: the thread (both models) at the extremes
// the issue names: the head at 10 m/s, a 10 cm teleport of the head,
// coincident nodes, zero-length segments, stiffness x1e6 (E = 2e15 Pa), the
// time step from 1e-5 to 1e-2 s, and a tight overhand knot pulled at 20 N
// (a smooth overhand of nylon, friction 0.3, the head drawn away from the
// pinned tail along its own tail at 10 cm/s until the rod's force on it
// reaches 20 N, then held; the stretch cap 8 %, as 20 N is 5.1 % of E A;
// the classifier's verdict reported). Each case runs 0.2 s (the knot 1 s)
// at its step; it passes when every
// node stays finite, the thread ends within 1 % of its rest length per
// segment (rod: within the stretch cap; ftl: exactly) or a fault was
// detected and put back (counted), and the published tension force (the
// controller's tx_thread_tension, clamp 10 N) never exceeds the clamp.
// Writes thread-stability.csv, .json and .png (largest force and strain per
// case).
#include "studies.h"

#include "../controllers/thread/knot.h"
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

#define CLAMP_N 10.0
#define TENSION_K 200.0

typedef struct stab_case {
  char name[64];
  int model;
  double dt;
  double max_force;   // N, the largest published
  double max_strain;  // the largest segment strain at any step
  double end_strain;  // at the end
  int faults, retries;
  bool finite, stable;
  double pulled_s;    // the knot: when the force on the head reached 20 N (-1: never)
  double peak_raw;    // N, the knot: the largest force of the rod on the head (before the clamp)
  int knot_class;     // the knot: the classifier's verdict at the end (tx_knot_class)
  double untied_s;    // the knot: when the classifier first saw no trefoil (-1: never)
} stab_case;

typedef enum kind { HEAD_10MS, TELEPORT, COINCIDENT, ZERO_LENGTH, STIFF, TIME_STEP, KNOT_20N } kind;

static bool all_finite(const tx_thread* t) {
  int n = tx_thread_node_count(t);
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++)
      if (!isfinite(tx_thread_position(t, i)[a])) return false;
  return true;
}

// a tight overhand, smooth (no kink: a stiff rod starts from a shape it can
// hold): the trefoil (sin t + 2 sin 2t, cos t - 2 cos 2t) of 0.8 mm,
// heights 1.5 mm sin 3t, cut open at its outer lobe, its ends going on
// straight along their tangents for 2 cm; nodes 0.5 mm apart along it (the
// smooth overhand of tests/controllers/thread/test_thread_tight_knot.c)
#define KNOT_U 0.0008
#define KNOT_HZ 0.0015
#define KNOT_TAIL 0.02
static void trefoil_at(double t, double p[3]) {
  p[0] = KNOT_U * (sin(t) + 2 * sin(2 * t)), p[1] = KNOT_U * (cos(t) - 2 * cos(2 * t)), p[2] = -KNOT_HZ * sin(3 * t);
}
static int overhand(double* x, int max) {
  double ts = 0, xs = -1e9;
  for (int k = 0; k < 100000; k++) {
    double t = 2 * 3.14159265358979 * k / 100000, xv = sin(t) + 2 * sin(2 * t);
    if (xv > xs) xs = xv, ts = t;
  }
  double a0 = ts + 0.3, a1 = ts + 2 * 3.14159265358979 - 0.3;
  enum { M = 2000 };
  static double pts[M + 3][3];
  double e0[3], e1[3], q[3];
  trefoil_at(a0, pts[1]);
  trefoil_at(a0 + 1e-6, q);
  for (int a = 0; a < 3; a++) e0[a] = pts[1][a] - q[a];
  for (int k = 0; k <= M; k++) trefoil_at(a0 + (a1 - a0) * k / M, pts[k + 1]);
  trefoil_at(a1 - 1e-6, q);
  for (int a = 0; a < 3; a++) e1[a] = pts[M + 1][a] - q[a];
  double l0 = sqrt(e0[0] * e0[0] + e0[1] * e0[1] + e0[2] * e0[2]), l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (int a = 0; a < 3; a++) pts[0][a] = pts[1][a] + KNOT_TAIL * e0[a] / l0, pts[M + 2][a] = pts[M + 1][a] + KNOT_TAIL * e1[a] / l1;
  int m = M + 3, n = 0, seg = 1;
  double start = 0, len = 0;
  for (int a = 0; a < 3; a++) len += pow(pts[1][a] - pts[0][a], 2);
  len = sqrt(len);
  while (n < max) {
    double at = n * 0.0005;
    while (at > start + len && seg < m - 1) {
      start += len, seg++, len = 0;
      for (int a = 0; a < 3; a++) len += pow(pts[seg][a] - pts[seg - 1][a], 2);
      len = sqrt(len);
    }
    if (at > start + len) break;
    double f = len > 0 ? (at - start) / len : 0;
    for (int a = 0; a < 3; a++) x[3 * n + a] = pts[seg - 1][a] + f * (pts[seg][a] - pts[seg - 1][a]);
    n++;
  }
  return n;
}

static int run_case(kind k, int model, double dt, stab_case* c) {
  tx_thread_def d = tx_thread_def_default();
  d.model = (tx_thread_model)model;
  d.nodes = 41;
  d.length = 0.04;
  d.damping = 5;
  if (k == STIFF) d.youngs_modulus = 2e15;
  // 20 N on E A = 393 N (0.5 mm nylon) is a strain of 5.1 %: above the
  // default 5 % cap, which would hold the force under 19.7 N
  if (k == KNOT_20N) d.max_stretch = 0.08;
  static double x[3 * 400];
  double pull[3] = {0, 0, 0};
  int n = d.nodes;
  if (k == KNOT_20N) {
    n = overhand(x, 400);
    d.nodes = n;
    d.length = 0.0005 * (n - 1);
    d.pin_tail = true;
    d.gravity = 0;
    d.self_friction = 0.3; // nylon on nylon
    for (int a = 0; a < 3; a++) pull[a] = x[a] - x[3 + a]; // along the head's own tail, away from the knot
    double l = sqrt(pull[0] * pull[0] + pull[1] * pull[1] + pull[2] * pull[2]);
    for (int a = 0; a < 3; a++) pull[a] /= l;
  }
  tx_thread* t = tx_thread_create(&d);
  if (!t) return fprintf(stderr, "tactus: study thread-stability: %s\n", tx_error()), 1;
  if (k == KNOT_20N) {
    tx_thread_set_positions(t, x);
  } else if (k == COINCIDENT || k == ZERO_LENGTH) {
    for (int i = 0; i < n; i++) {
      const double* p = tx_thread_position(t, k == COINCIDENT ? 0 : i - i % 4); // every node on one point, or fours
      for (int a = 0; a < 3; a++) x[3 * i + a] = p[a];
    }
    tx_thread_set_positions(t, x);
  }
  double head[3];
  memcpy(head, tx_thread_position(t, 0), sizeof head);
  double duration = k == KNOT_20N ? 1 : 0.2;
  int steps = (int)lround(duration / dt);
  c->model = model;
  c->dt = dt;
  c->max_force = c->max_strain = 0;
  c->finite = true;
  c->retries = 0;
  bool holding = false;
  c->pulled_s = -1;
  c->peak_raw = 0;
  c->knot_class = -1;
  c->untied_s = -1;
  tx_knot_work* kw = NULL;
  if (k == KNOT_20N && !(kw = tx_knot_work_create(n)))
    return tx_thread_destroy(t), fprintf(stderr, "tactus: study thread-stability: out of memory\n"), 1;
  for (int s = 0; s < steps; s++) {
    if (k == HEAD_10MS) head[0] -= 10 * dt;                 // 10 m/s away along -x
    if (k == TELEPORT && s == steps / 2) head[1] += 0.1;    // 10 cm in one step
    if (k == TIME_STEP) head[0] -= 0.05 * dt;               // a slow pull
    if (k == KNOT_20N && !holding)                          // 10 cm/s until 20 N, then held
      for (int a = 0; a < 3; a++) head[a] += 0.1 * dt * pull[a];
    if (fabs(head[0]) > 9) head[0] = copysign(9, head[0]);
    tx_thread_set_head(t, head);
    tx_thread_step(t, dt);
    double f[3], K[9], raw[3];
    tx_thread_tension(t, TENSION_K, CLAMP_N, f, K);
    tx_thread_head_force(t, raw);
    double rawn = sqrt(raw[0] * raw[0] + raw[1] * raw[1] + raw[2] * raw[2]);
    c->peak_raw = fmax(c->peak_raw, rawn);
    if (k == KNOT_20N && model == 1 && !holding && rawn >= 20) holding = true, c->pulled_s = (s + 1) * dt;
    c->max_force = fmax(c->max_force, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    c->max_strain = fmax(c->max_strain, tx_thread_max_strain(t));
    c->finite &= all_finite(t);
    tx_thread_contacts ct;
    tx_thread_last_contacts(t, &ct);
    c->retries += ct.retries;
    tx_knot_diagram dg;
    if (kw && c->untied_s < 0) {
      tx_thread_positions(t, x);
      if (tx_knot_classify(kw, x, n, &dg) == 0 && dg.cls != TX_KNOT_TREFOIL) c->untied_s = (s + 1) * dt;
    }
  }
  c->faults = tx_thread_faults(t);
  if (kw) {
    tx_knot_diagram dg;
    tx_thread_positions(t, x);
    c->knot_class = tx_knot_classify(kw, x, n, &dg) == 0 ? (int)dg.cls : -1;
    tx_knot_work_destroy(kw);
  }
  c->end_strain = tx_thread_max_strain(t);
  double cap = model == 1 ? d.max_stretch + 1e-9 : 1e-9;
  c->stable = c->finite && c->max_force <= CLAMP_N * (1 + 1e-12) && (c->end_strain <= cap || c->faults > 0);
  if (k == KNOT_20N) c->stable &= c->pulled_s >= 0; // the case is the pull: it must reach 20 N
  tx_thread_destroy(t);
  return 0;
}

int tx_study_thread_stability(const tx_study_args* a) {
  for (int i = 0; i < a->nsets; i++)
    return tx_bad_input("--set %s: thread-stability takes no settings", a->sets[i]);
  static const char* const names[] = {"head at 10 m/s", "10 cm teleport", "coincident nodes", "zero-length segments",
                                      "stiffness x1e6", "time step", "knot pulled at 20 N"};
  static const double dts[] = {1e-5, 1e-4, 1e-3, 1e-2};
  stab_case cases[64];
  int n = 0;
  bool all = true;
  printf("study thread-stability: 41 nodes, 4 cm (the knot: a tight overhand), both models, clamp %g N\n\n", CLAMP_N);
  printf("  %-30s %-5s %8s %12s %12s %12s %7s %8s %s\n", "case", "model", "step s", "max force N", "max strain",
         "end strain", "faults", "retries", "");
  for (int k = HEAD_10MS; k <= KNOT_20N; k++)
    for (int model = 0; model < 2; model++) {
      int ndt = k == TIME_STEP ? 4 : 1;
      for (int j = 0; j < ndt; j++) {
        if (k == KNOT_20N && model == 0) continue; // ftl has no force of its own to pull with
        stab_case* c = &cases[n];
        snprintf(c->name, sizeof c->name, "%s", names[k]);
        if (run_case((kind)k, model, k == TIME_STEP ? dts[j] : 1e-3, c)) return 1;
        printf("  %-30s %-5s %8.0e %12.4g %12.4g %12.4g %7d %8d %s\n", c->name, model ? "rod" : "ftl", c->dt, c->max_force,
               c->max_strain, c->end_strain, c->faults, c->retries, c->stable ? "stable" : "UNSTABLE");
        if (k == KNOT_20N)
          printf("  %-30s the rod's force on the head reached 20 N at %.3f s (-1: never), peak %.2f N; the classifier: "
                 "a trefoil until %.3f s (-1: throughout), %s at the end\n",
                 "", c->pulled_s, c->peak_raw, c->untied_s, c->knot_class >= 0 ? tx_knot_class_name((tx_knot_class)c->knot_class) : "?");
        all &= c->stable;
        n++;
      }
    }
  printf("\n%s\n", all ? "every case ends stable: no NaN, the force within the clamp, the length kept" : "some case is UNSTABLE");
  // outputs
  char path[4200];
  tx_aside o;
  FILE* f = tx_aside_begin(&o, a->out_dir, "thread-stability.csv") ? o.f : NULL;
  if (f) {
    fprintf(f, "case,model,time_step_s,max_force_n,max_strain,end_strain,faults,retries,finite,stable\n");
    for (int i = 0; i < n; i++)
      fprintf(f, "%s,%s,%.9g,%.6g,%.6g,%.6g,%d,%d,%d,%d\n", cases[i].name, cases[i].model ? "rod" : "ftl", cases[i].dt,
              cases[i].max_force, cases[i].max_strain, cases[i].end_strain, cases[i].faults, cases[i].retries,
              cases[i].finite, cases[i].stable);
  }
  if (!f || !tx_aside_end(&o)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_t* list = json_array();
  for (int i = 0; i < n && list; i++)
    json_array_append_new(list, json_pack("{s:s,s:s,s:f,s:f,s:f,s:f,s:i,s:i,s:b,s:b,s:f,s:f,s:f,s:s}", "case", cases[i].name, "model",
                                          cases[i].model ? "rod" : "ftl", "time_step_s", cases[i].dt, "max_force_n",
                                          cases[i].max_force, "max_strain", cases[i].max_strain, "end_strain",
                                          cases[i].end_strain, "faults", cases[i].faults, "retries", cases[i].retries,
                                          "finite", cases[i].finite, "stable", cases[i].stable, "pulled_20n_s",
                                          cases[i].pulled_s, "peak_head_force_n", cases[i].peak_raw, "untied_s",
                                          cases[i].untied_s, "knot_class",
                                          cases[i].knot_class >= 0 ? tx_knot_class_name((tx_knot_class)cases[i].knot_class) : ""));
  json_t* doc = json_pack("{s:s,s:f,s:b,s:o}", "study", "thread-stability", "clamp_n", CLAMP_N, "all_stable", all,
                          "cases", list);
  if (!doc || tx_report_save(doc, a->out_dir, "thread-stability.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "thread-stability: out of memory"), 1;
  }
  json_decref(doc);
  static double cx[64], cf[64], cs[64];
  for (int i = 0; i < n; i++) cx[i] = i + 1, cf[i] = cases[i].max_force, cs[i] = 100 * cases[i].max_strain;
  tx_plot_series s[2] = {{"largest force (N)", cx, cf, n, true, 1}, {"largest strain (%)", cx, cs, n, true, 9}};
  snprintf(path, sizeof path, "%s/thread-stability.png", a->out_dir);
  tx_plot p = {"Thread at the extremes (cases in the order of the CSV)", "case", "force (N), strain (%)", false, false, s, 2};
  bool plotted = tx_plot_png(path, &p) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("wrote %s/thread-stability.json, .csv%s\n", a->out_dir, plotted ? " and thread-stability.png" : "");
  return all ? 0 : 1;
}
