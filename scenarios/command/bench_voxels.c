// tactus bench voxels: the needle-voxel scenario (voxel.needle with its
// fitted tissue, haptics with scripted:insert: in at 3 mm/s, 4 mm deep, back
// out) with blocks of 250 to 100000 voxels, 0.5 mm apart, 5 mm deep, growing
// sideways. The step time of
// each case is measured in lockstep; the haptic frequency a servo loop
// running nothing else would reach is 1 / step time. Then the 20000-voxel
// block runs in real time at 1 kHz beside the haptics controller.
#include "bench_voxels.h"

#include "../loader.h"

#include "../../controllers/system.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

// voxels along x, y (depth), z
static const int cases[][3] = {{5, 10, 5}, {10, 10, 5}, {15, 10, 5}, {10, 10, 10}, {25, 10, 20}, {40, 10, 50}, {100, 10, 100}};
enum { NCASES = sizeof cases / sizeof cases[0] };

// the voxel needle-insertion paper, Table 1: haptic servo loop Hz at 250 to
// 1000 spheres on (A) a 1.4 GHz Pentium 3 and (B) a dual 1.66 GHz Core Duo
static const double paper_a[4] = {833.3, 714.3, 666.7, 66.7};
static const double paper_b[4] = {3050.4, 1993.4, 1439.8, 1062.4};

// the shipped needle-voxel scenario (its fitted tissue, 18-gauge needle and
// scripted:insert) with the block resized and the recordings off
static tx_scenario* scene(const int c[3]) {
  char path[4096], err[512], sets[8][64];
  if (tx_scenario_locate("needle-voxel", path, sizeof path, err, sizeof err)) {
    fprintf(stderr, "tactus: %s\n", err);
    return NULL;
  }
  static const char* const axis = "xyz";
  for (int a = 0; a < 3; a++) {
    snprintf(sets[a], sizeof sets[a], "needle.count_%c=%d", axis[a], c[a]);
    snprintf(sets[3 + a], sizeof sets[3 + a], "needle.block_%c_m=%g", axis[a], c[a] * 0.5e-3);
  }
  snprintf(sets[6], sizeof sets[6], "needle.record=false");
  snprintf(sets[7], sizeof sets[7], "haptics.record=false");
  const char* list[8];
  for (int k = 0; k < 8; k++) list[k] = sets[k];
  tx_load_options o = {.sets = list, .nsets = 8};
  tx_scenario* sc = tx_scenario_load(path, &o, err, sizeof err);
  if (!sc) fprintf(stderr, "tactus: %s\n", err);
  return sc;
}

static int run(const int c[3], double seconds, bool lockstep, tx_controller_stats* st, tx_run_result* r) {
  tx_scenario* sc = scene(c);
  if (!sc) return 1;
  tx_run_options o = {.duration_s = seconds, .lockstep = lockstep, .realtime_priority = !lockstep,
                      .pin_threads = !lockstep, .keep_cpus_awake = !lockstep};
  char err[512];
  int rc = tx_system_run(sc->system, &o, r, err, sizeof err);
  if (rc) fprintf(stderr, "tactus: %s\n", err);
  else *st = tx_system_stats(sc->system, 0); // the needle
  tx_scenario_free(sc);
  return rc ? 1 : 0;
}

static void target(const char* what, const char* measured, const char* limit, bool ok) {
  printf("  %-44s %-26s %-12s %s\n", what, measured, limit, ok ? "met" : "MISSED");
}

int tx_bench_voxels(double duration_s) {
  const double seconds = duration_s > 0 ? duration_s : 3.8;
  printf("bench voxels: the needle-voxel scenario (3 mm/s, 4 mm deep, out again) with the block resized, %g s per\n"
         "case, lockstep; a step of voxel.needle = needle contacts, collisions, springs, guard, force model publish\n\n",
         seconds);
  printf("  %8s %10s %10s %10s %12s %12s   %s\n", "voxels", "p50 us", "p99 us", "max us", "Hz at p50", "Hz at p99",
         "paper Table 1 Hz: (A) P3 1.4 GHz, (B) Core Duo 1.66 GHz");
  double logn[NCASES], logt[NCASES], hz99[NCASES];
  for (int k = 0; k < NCASES; k++) {
    int n = cases[k][0] * cases[k][1] * cases[k][2];
    tx_controller_stats st;
    tx_run_result r;
    if (run(cases[k], seconds, true, &st, &r)) return 1;
    double p50 = st.step_ns.p50 * 1e-3, p99 = st.step_ns.p99 * 1e-3, mx = st.step_ns.max * 1e-3;
    logn[k] = log(n), logt[k] = log(p50), hz99[k] = 1e6 / p99;
    char paper[64] = "-";
    if (k < 4) snprintf(paper, sizeof paper, "(A) %.1f  (B) %.1f", paper_a[k], paper_b[k]);
    printf("  %8d %10.1f %10.1f %10.1f %12.0f %12.0f   %s\n", n, p50, p99, mx, 1e6 / p50, 1e6 / p99, paper);
    fflush(stdout);
  }
  // least squares of log(step) on log(voxels)
  double mx = 0, my = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < NCASES; k++) mx += logn[k] / NCASES, my += logt[k] / NCASES;
  for (int k = 0; k < NCASES; k++) sxx += (logn[k] - mx) * (logn[k] - mx), sxy += (logn[k] - mx) * (logt[k] - my);
  double slope = sxy / sxx;
  // the same over the large blocks alone, where the per-voxel passes dominate
  double mx2 = 0, my2 = 0, sxx2 = 0, sxy2 = 0;
  for (int k = 4; k < NCASES; k++) mx2 += logn[k] / 3, my2 += logt[k] / 3;
  for (int k = 4; k < NCASES; k++) sxx2 += (logn[k] - mx2) * (logn[k] - mx2), sxy2 += (logn[k] - mx2) * (logt[k] - my2);
  double slope_large = sxy2 / sxx2;
  printf("\n  step cost ~ voxels^b: b = %.3f over all rows, b = %.3f over 5000 to 100000 voxels\n", slope, slope_large);
  printf("  (the paper's Table 1: 1000 voxels at 1062.4 Hz on (B); Figure 6 shows the 5 x 5 x 5 mm sample)\n");

  // the 20000-voxel block at 1 kHz in real time
  tx_controller_stats rt;
  tx_run_result rr;
  if (run(cases[5], seconds, false, &rt, &rr)) return 1;
  double missed = 100.0 * (double)rt.missed / (double)(rt.steps + rt.missed ? rt.steps + rt.missed : 1);
  printf("\n  real time, 20000 voxels at 1 kHz for %g s: %.1f Hz achieved, %llu of %llu deadlines missed (%.2f%%), "
         "step p50/p99/max %.1f/%.1f/%.1f us; %s\n",
         seconds, rt.achieved_hz, (unsigned long long)rt.missed, (unsigned long long)(rt.steps + rt.missed), missed,
         rt.step_ns.p50 * 1e-3, rt.step_ns.p99 * 1e-3, rt.step_ns.max * 1e-3, rr.scheduler);
  if (rr.steal_s > 0) printf("  host steal during the run: %.2f s\n", rr.steal_s);

  printf("\ntargets:\n");
  char m[64];
  snprintf(m, sizeof m, "%.0f Hz at p99 (lockstep)", hz99[5]);
  target("20000 voxels: haptic frequency at p99", m, ">= 1000 Hz", hz99[5] >= 1000);
  snprintf(m, sizeof m, "%.2f%% missed (%.1f Hz)", missed, rt.achieved_hz);
  target("20000 voxels at 1 kHz in real time, missed", m, "<= 1%", missed <= 1);
  snprintf(m, sizeof m, "b = %.3f (large: %.3f)", slope, slope_large);
  target("step cost about linear in voxels (b <= 1.15)", m, "b <= 1.15", slope <= 1.15 && slope_large <= 1.15);
  snprintf(m, sizeof m, "%.0f Hz at p50", exp(-logt[3]) * 1e6);
  target("1000 voxels beyond the paper's 1062.4 Hz", m, "> 1062.4 Hz", exp(-logt[3]) * 1e6 > 1062.4);
  return 0;
}
