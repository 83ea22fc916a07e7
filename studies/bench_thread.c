// tactus bench thread: the cost of one 1 kHz step of the suture thread
// (controllers/thread/thread.h), follow-the-leader and rod, at 100 and 1000
// nodes of 1 mm (a 0.5 mm thread). The thread hangs doubled: its head and
// its pinned tail 2 r apart, two legs side by side down to a loop, so the
// broadphase and the self contacts have work at every step (the legs touch over
// their upper part); it settles for 2 s first (rod), then the head circles at
// 5 cm/s on a 2 mm circle, gravity on (--duration S: S seconds a row and
// S of settling, instead of 2 s and 0.5 s after 2 s). Each step is timed on the wall clock
// and in the thread's CPU time: on a loaded machine the wall clock also
// counts the time the step was descheduled. Timings are printed, never asserted.
#include "bench_thread.h"
#include "studies.h"

#include "../controllers/thread/thread.h"

#include <tactus/model.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define PI 3.14159265358979323846

typedef struct thread_row {
  int nodes;
  tx_thread_model model;
  tx_percentiles step;  // ns, wall clock
  tx_percentiles cpu;   // ns, the thread's CPU time
  double self_pairs;    // touching cylinder pairs per step, mean
  double broad_pairs;   // pairs the broadphase proposed per step, mean
  double substeps;      // mean
} thread_row;

static int run_row(int nodes, tx_thread_model model, int steps, int settle, thread_row* row) {
  static tx_hist hist, cpu;
  tx_hist_clear(&hist);
  tx_hist_clear(&cpu);
  tx_thread_def d = tx_thread_def_default();
  d.model = model;
  d.nodes = nodes;
  d.length = 0.001 * (nodes - 1);
  d.pin_tail = true;
  d.damping = 5;
  tx_thread* t = tx_thread_create(&d);
  double* x = malloc(sizeof(double) * 3 * nodes);
  if (!t || !x) {
    fprintf(stderr, "tactus: bench thread: %s\n", t ? "out of memory" : tx_error());
    tx_thread_destroy(t);
    free(x);
    return 1;
  }
  // two legs 0.6 mm apart joined by a half circle at the bottom
  double gap = 2 * d.radius, arc = PI * gap / 2, leg = 0.5 * (d.length - arc);
  for (int i = 0; i < nodes; i++) {
    double s = d.length * i / (nodes - 1), *p = x + 3 * i;
    p[2] = 0;
    if (s <= leg) {
      p[0] = 0, p[1] = -s;
    } else if (s <= leg + arc) {
      double phi = (s - leg) / (gap / 2);
      p[0] = gap / 2 * (1 - cos(phi)), p[1] = -leg - gap / 2 * sin(phi);
    } else {
      p[0] = gap, p[1] = -leg + (s - leg - arc);
    }
  }
  tx_thread_set_positions(t, x);
  if (model == TX_THREAD_ROD)
    for (int k = 0; k < settle; k++) tx_thread_step(t, 1e-3);
  double self = 0, broad = 0, sub = 0;
  for (int k = 0; k < steps; k++) {
    double a = 0.05 / 0.002 * k * 1e-3; // 5 cm/s on a 2 mm circle
    double head[3] = {x[0] + 0.002 * (cos(a) - 1), x[1], x[2] + 0.002 * sin(a)};
    tx_thread_set_head(t, head);
    struct timespec c0, c1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
    int64_t t0 = tx_mono_ns();
    tx_thread_status st = tx_thread_step(t, 1e-3);
    tx_hist_add(&hist, tx_mono_ns() - t0);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
    tx_hist_add(&cpu, (int64_t)(c1.tv_sec - c0.tv_sec) * 1000000000 + (c1.tv_nsec - c0.tv_nsec));
    if (st != TX_THREAD_OK) {
      fprintf(stderr, "tactus: bench thread: step %d of %d nodes %s\n", k, nodes,
              st == TX_THREAD_FAULT ? "faulted" : tx_error());
      tx_thread_destroy(t);
      free(x);
      return 1;
    }
    tx_thread_contacts c;
    tx_thread_last_contacts(t, &c);
    self += c.self_pairs;
    broad += c.broad_pairs;
    sub += c.substeps;
  }
  row->nodes = nodes;
  row->model = model;
  row->step = tx_hist_percentiles(&hist);
  row->cpu = tx_hist_percentiles(&cpu);
  row->self_pairs = self / steps;
  row->broad_pairs = broad / steps;
  row->substeps = sub / steps;
  tx_thread_destroy(t);
  free(x);
  return 0;
}

int tx_bench_thread(double duration_s) {
  thread_row rows[4];
  static const int sizes[2] = {100, 1000};
  int steps[2] = {2000, 500}, settle = 2000;
  if (duration_s > 0) { // a shorter run (the test's): that many seconds a row, settling as long
    steps[0] = steps[1] = settle = (int)ceil(duration_s * 1000);
  }
  printf("bench thread: one 1 kHz step of a 0.5 mm thread of 1 mm segments hanging doubled (legs touching),\n"
         "tail pinned, the head circling at 5 cm/s, gravity on; %d and %d steps\n\n", steps[0], steps[1]);
  for (int m = 0; m < 2; m++)
    for (int s = 0; s < 2; s++)
      if (run_row(sizes[s], (tx_thread_model)m, steps[s], settle, &rows[2 * m + s])) return 1;
  printf("  %-6s %-6s %10s %10s %10s %10s %10s %10s %9s\n", "model", "nodes", "cpu p50", "cpu p99", "wall p50",
         "wall p99", "touching", "broad pairs", "substeps");
  for (int i = 0; i < 4; i++)
    printf("  %-6s %-6d %7.1f us %7.1f us %7.1f us %7.1f us %10.1f %10.0f %9.2f\n",
           rows[i].model == TX_THREAD_ROD ? "rod" : "ftl", rows[i].nodes, rows[i].cpu.p50 * 1e-3,
           rows[i].cpu.p99 * 1e-3, rows[i].step.p50 * 1e-3, rows[i].step.p99 * 1e-3, rows[i].self_pairs,
           rows[i].broad_pairs, rows[i].substeps);
  printf("\n  touching: cylinder pairs within 2 r per step; broad pairs: the pairs the broadphase proposed\n");
  printf("\ntargets:\n");
  tx_bench_target_us("step, ftl, 100 nodes, self collision, cpu p99", rows[0].cpu.p99 * 1e-3, 100);
  tx_bench_target_us("step, ftl, 1000 nodes, self collision, cpu p99", rows[1].cpu.p99 * 1e-3, 1000);
  tx_bench_target_us("step, rod, 100 nodes, self collision, cpu p99", rows[2].cpu.p99 * 1e-3, 100);
  tx_bench_target_us("step, rod, 1000 nodes, self collision, cpu p99", rows[3].cpu.p99 * 1e-3, 1000);
  return 0;
}
