// tactus bench voxels: the needle-voxel scenario (voxel.needle with its
// fitted tissue, haptics with scripted:insert: in at 3 mm/s, 4 mm deep, back
// out) with blocks of 250 to 100000 voxels, 0.5 mm apart, 5 mm deep, growing
// sideways. The step time of
// each case is measured in lockstep; the haptic frequency a servo loop
// running nothing else would reach is 1 / step time. Then the 20000-voxel
// block runs in real time at 1 kHz beside the haptics controller.
#include "bench_voxels.h"

#include "../scenarios/loader.h"

#include <tactus/stats.h>
#include "../controllers/system.h"
#include "experiments/needle_fit.h"

#include <tactus/model.h>

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
  char path[4096], sets[8][64];
  if (tx_scenario_locate("needle-voxel", path, sizeof path)) {
    fprintf(stderr, "tactus: %s\n", tx_error());
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
  tx_scenario* sc = tx_scenario_load(path, &o);
  if (!sc) fprintf(stderr, "tactus: %s\n", tx_error());
  return sc;
}

static int run(const int c[3], double seconds, bool lockstep, tx_controller_stats* st, tx_run_result* r) {
  tx_scenario* sc = scene(c);
  if (!sc) return 1;
  tx_run_options o = {.duration_s = seconds, .lockstep = lockstep, .realtime_priority = !lockstep,
                      .pin_threads = !lockstep, .keep_cpus_awake = !lockstep};
  int rc = tx_system_run(sc->system, &o, r);
  if (rc) fprintf(stderr, "tactus: %s\n", tx_error());
  else *st = tx_system_stats(sc->system, 0); // the needle
  tx_scenario_free(sc);
  return rc ? 1 : 0;
}

// the paper's loop touches every voxel every frame: here every voxel is kept
// awake by a small random kick before each frame (1 mm/s, outside the timed
// step), the needle going in at 3 mm/s as before. The kicks put in energy the
// needle did not, which the guard would rightly undo, so the timed frame is
// the needle step plus the guard's energy sum, without the guard's verdict.
// Returns the p50 frame in ns
static double all_awake(const int c[3], int frames, double* p99) {
  tx_needle_fit_params p = tx_needle_fit_params_default();
  tx_voxel_tissue_def td;
  tx_voxel_needle_def nd;
  tx_needle_fit_defs(&p, &td, &nd);
  for (int a = 0; a < 3; a++) td.count[a] = c[a], td.block_size[a] = c[a] * 0.5e-3;
  td.origin[0] = -0.5 * td.block_size[0], td.origin[1] = -td.block_size[1], td.origin[2] = -0.5 * td.block_size[2];
  tx_voxel_tissue t;
  tx_voxel_needle n;
  static tx_hist st; // not on the stack
  tx_hist_clear(&st);
  if (!tx_voxel_tissue_init(&t, &td)) return -1;
  if (!tx_voxel_needle_init(&n, &nd, &t)) {
    tx_voxel_tissue_fini(&t);
    return -1;
  }
  uint64_t seed = 12345;
  const double q[4] = {1, 0, 0, 0};
  double energy = 0; // the guard's sum, part of the frame's cost
  for (int k = 0; k < frames; k++) {
    for (int i = 0; i < t.n; i++) {
      for (int a = 0; a < 3; a++) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        t.vel[3 * i + a] += 1e-3 * ((double)(seed >> 11) / 9007199254740992.0 - 0.5);
      }
      tx_voxel_tissue_wake(&t, i);
    }
    double tip[3] = {0, 1e-3 - 3e-3 * k * 1e-3, 0};
    int64_t t0 = tx_mono_ns();
    tx_voxel_needle_step(&n, &t, tip, q, 1e-3);
    energy += tx_voxel_tissue_energy(&t);
    tx_hist_add(&st, tx_mono_ns() - t0);
  }
  if (!isfinite(energy)) fprintf(stderr, "tactus: bench voxels: the all-awake tissue's energy is not finite\n");
  tx_percentiles pc = tx_hist_percentiles(&st);
  *p99 = pc.p99;
  tx_voxel_needle_fini(&n);
  tx_voxel_tissue_fini(&t);
  return pc.p50;
}

// least squares slope of log(y) on log(x) over rows [from, to)
static double loglog_slope(const double* lx, const double* ly, int from, int to) {
  double mx = 0, my = 0, sxx = 0, sxy = 0, m = to - from;
  for (int k = from; k < to; k++) mx += lx[k] / m, my += ly[k] / m;
  for (int k = from; k < to; k++) sxx += (lx[k] - mx) * (lx[k] - mx), sxy += (lx[k] - mx) * (ly[k] - my);
  return sxy / sxx;
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
  double slope = loglog_slope(logn, logt, 0, NCASES), slope_large = loglog_slope(logn, logt, 4, NCASES);
  printf("\n  step cost ~ voxels^b: b = %.3f over all rows, b = %.3f over 5000 to 100000 voxels\n", slope, slope_large);
  printf("  (the paper's Table 1: 1000 voxels at 1062.4 Hz on (B); Figure 6 shows the 5 x 5 x 5 mm sample)\n");
  printf("  resting voxels sleep, so a step costs what the needle disturbs, not the block\n");

  // every voxel awake, as the paper's loop visits every voxel every frame
  const int frames = 200;
  printf("\n  every voxel awake (kicked at random before each frame), %d frames each:\n", frames);
  printf("  %8s %10s %10s %12s %12s\n", "voxels", "p50 us", "p99 us", "Hz at p50", "Hz at p99");
  double loga[NCASES], hz_awake[NCASES];
  for (int k = 0; k < NCASES; k++) {
    int n = cases[k][0] * cases[k][1] * cases[k][2];
    double p99, p50 = all_awake(cases[k], frames, &p99);
    if (p50 < 0) return fprintf(stderr, "tactus: bench voxels: %s\n", tx_error()), 1;
    loga[k] = log(p50), hz_awake[k] = 1e9 / p50;
    printf("  %8d %10.1f %10.1f %12.0f %12.0f\n", n, p50 * 1e-3, p99 * 1e-3, 1e9 / p50, 1e9 / p99);
    fflush(stdout);
  }
  double slope_awake = loglog_slope(logn, loga, 0, NCASES), slope_awake_large = loglog_slope(logn, loga, 4, NCASES);
  printf("\n  every voxel awake: step cost ~ voxels^b, b = %.3f over all rows, b = %.3f over 5000 to 100000;\n"
         "  %.0f voxels per millisecond at 1000 voxels, %.0f at 20000 (the paper: 'over 1000 voxels per millisecond')\n",
         slope_awake, slope_awake_large, 1000 * hz_awake[3] / 1000, 20000 * hz_awake[5] / 1000);

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
  target("step cost no worse than linear, needle scene", m, "b <= 1.15", slope <= 1.15 && slope_large <= 1.15);
  snprintf(m, sizeof m, "b = %.3f (large: %.3f)", slope_awake, slope_awake_large);
  target("step cost about linear, every voxel awake", m, "0.8 <= b <= 1.2",
         slope_awake_large >= 0.8 && slope_awake_large <= 1.2);
  snprintf(m, sizeof m, "%.0f Hz at p50", exp(-logt[3]) * 1e6);
  target("1000 voxels beyond the paper's 1062.4 Hz", m, "> 1062.4 Hz", exp(-logt[3]) * 1e6 > 1062.4);
  return 0;
}
