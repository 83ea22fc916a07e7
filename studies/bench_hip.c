// tactus bench hip: the cost of one collision.hip query (98 rays) against a
// deformed synthetic skin of 10404 and of 102400 particles, in mechanics mode
// (the default: the rays find contact and pierce, the force is the skin's
// reaction carried from the last publish) and in the papers' mode, and of the
// BVH refit each physics publish brings. The skin is a 10 x 10 cm grid pressed in
// by a moving dent, so no physics engine is involved; the HIP sits in the dent,
// touching it, and moves a little between queries as a hand would.
#include "bench_hip.h"
#include "studies.h"

#include "../controllers/collision/hip.h"
#include "experiments/skin_dent.h"
#include "../controllers/physics/skin_grid.h"
#include <tactus/stats.h>

#include <tactus/components.h>
#include <tactus/model.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define QUERIES 20000    // per skin size
#define PER_PUBLISH 67   // 4 kHz queries per 60 Hz physics publish

typedef struct hip_bench_row {
  uint32_t particles;
  bool mechanics;              // force_mode mechanics, else paper
  tx_percentiles query, refit; // one query; one whole refit (the sum of its shares)
  tx_percentiles take, share;  // per publish: copy, finite check and triangle compare; one step's share of the refit
  double rebuild_ms;      // one build from scratch (a tear)
  double nodes_per_query; // BVH nodes visited, mean
  double contacts;        // rays in contact, mean
} hip_bench_row;

static bool finite_all(const float* v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

// the dent of the skin at time t: 4 to 6 mm deep, wandering 1 mm around the middle
static void press(float* x, const float* flat, uint32_t count, double t) {
  memcpy(x, flat, sizeof(float) * 3 * count);
  double c[3] = {1e-3 * sin(3 * t), 0, 1e-3 * cos(2 * t)};
  tx_skin_dent(x, count, c, 5e-3 + 1e-3 * sin(5 * t), 0.01);
}

static int run_size(uint32_t n, bool mechanics, hip_bench_row* row) {
  uint32_t count = n * n, ntri_max = 2 * (n - 1) * (n - 1);
  float* flat = malloc(sizeof(float) * 3 * count);
  float* x = malloc(sizeof(float) * 3 * count);
  float* copy = malloc(sizeof(float) * 3 * count);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * ntri_max);
  static tx_hist q, r, tk, sh; // not on the stack
  tx_hist_clear(&q), tx_hist_clear(&r), tx_hist_clear(&tk), tx_hist_clear(&sh);
  tx_tri_bvh b;
  bool ok = flat && x && copy && tri &&
            tx_tri_bvh_init(&b, ntri_max) == 0;
  if (!ok) return fprintf(stderr, "tactus: bench hip: out of memory\n"), 1;
  uint32_t ntri = tx_skin_grid((int)n, (int)n, 0.1 / (n - 1), 0.1 / (n - 1), (double[3]){0, 0, 0}, flat, tri);
  press(x, flat, count, 0);
  int64_t t0 = tx_mono_ns();
  tx_tri_bvh_build(&b, x, count, tri, ntri);
  row->rebuild_ms = (tx_mono_ns() - t0) * 1e-6;

  tx_hip_def def = tx_hip_def_default();
  def.rays = 98;
  tx_hip hip;
  tx_hip_init(&hip, &def);
  const double thickness = 4e-3; // the journal paper's 0.4 cm
  uint64_t contacts = 0;
  b.visited = 0;
  // the reaction a publish brings (mechanics): a push out of the dent where the HIP was then
  tx_skin_contact reaction = {.f = {0, 0.2, 0}, .n = {0, 1, 0}, .k = 100, .depth = 5e-3, .touching = 1};
  for (int k = 0; k < QUERIES; k++) {
    double t = k / 4000.0;
    if (k % PER_PUBLISH == 0 && k > 0) { // a physics publish: what the controller does with it
      press(copy, flat, count, t);
      int64_t a = tx_mono_ns();
      memcpy(x, copy, sizeof(float) * 3 * count);
      bool good = finite_all(x, 3 * (size_t)count) && tx_tri_bvh_same(&b, tri, ntri);
      tx_hist_add(&tk, tx_mono_ns() - a);
      // the refit in the controller's shares (up to 8 steps at 4 kHz)
      uint32_t chunk = 2 * ntri_max / 8 + 1 > 8192 ? 2 * ntri_max / 8 + 1 : 8192;
      int64_t whole = 0;
      for (uint32_t to = b.nnodes; good && to > 0;) {
        uint32_t from = to > chunk ? to - chunk : 0;
        int64_t s0 = tx_mono_ns();
        tx_tri_bvh_refit_nodes(&b, x, from, to);
        int64_t d = tx_mono_ns() - s0;
        tx_hist_add(&sh, d);
        whole += d;
        to = from;
      }
      tx_hist_add(&r, whole);
      reaction.x[0] = 1e-3 * sin(3 * t);
      reaction.x[1] = -5e-3 - 1e-3 * sin(5 * t) + 1.5e-3;
      reaction.x[2] = 1e-3 * cos(2 * t);
    }
    // the HIP touches the dent's bottom and circles 0.2 mm around it
    double c[3] = {1e-3 * sin(3 * t) + 2e-4 * cos(40 * t), -5e-3 - 1e-3 * sin(5 * t) + 1.5e-3,
                   1e-3 * cos(2 * t) + 2e-4 * sin(40 * t)};
    tx_hip_out o;
    int64_t a = tx_mono_ns();
    if (mechanics) tx_hip_query_reaction(&hip, &b, x, thickness, c, &reaction, &o);
    else tx_hip_query(&hip, &b, x, thickness, c, &o);
    tx_hist_add(&q, tx_mono_ns() - a);
    contacts += (uint64_t)o.contacts;
  }
  row->particles = count;
  row->mechanics = mechanics;
  row->query = tx_hist_percentiles(&q);
  row->refit = tx_hist_percentiles(&r);
  row->take = tx_hist_percentiles(&tk);
  row->share = tx_hist_percentiles(&sh);
  row->nodes_per_query = (double)b.visited / QUERIES;
  row->contacts = (double)contacts / QUERIES;
  tx_tri_bvh_free(&b);
  free(copy);
  free(flat);
  free(x);
  free(tri);
  return 0;
}

int tx_bench_hip(void) {
  static const uint32_t sides[] = {102, 320}; // 10404 and 102400 particles on 10 x 10 cm
  hip_bench_row rows[4];                      // mechanics, then paper; each size
  printf("bench hip: one collision.hip query (98 rays, radius 0.05 cm, skin 0.4 cm) on a dented 10 x 10 cm skin,\n"
         "%d queries per size and mode, a refit every %d (4 kHz against 60 Hz physics)\n\n", QUERIES, PER_PUBLISH);
  for (int i = 0; i < 4; i++)
    if (run_size(sides[i % 2], i < 2, &rows[i])) return 1;
  printf("  %-10s %-10s %9s %9s %9s %11s %10s %10s %11s %9s %9s\n", "mode", "particles", "q p50 us", "q p99 us",
         "q max us", "refit p50", "share p99", "take p99", "rebuild ms", "nodes/q", "contacts");
  for (int i = 0; i < 4; i++)
    printf("  %-10s %-10u %9.2f %9.2f %9.2f %8.0f us %7.0f us %7.0f us %11.2f %9.0f %9.1f\n",
           rows[i].mechanics ? "mechanics" : "paper", rows[i].particles, rows[i].query.p50 * 1e-3,
           rows[i].query.p99 * 1e-3, rows[i].query.max * 1e-3, rows[i].refit.p50 * 1e-3, rows[i].share.p99 * 1e-3,
           rows[i].take.p99 * 1e-3, rows[i].rebuild_ms, rows[i].nodes_per_query, rows[i].contacts);
  printf("\n  refit: a whole refit; share: the part of it one 4 kHz step does; take: the copy, finite check\n"
         "  and triangle compare of the step that sees a publish\n");
  printf("\n  particles x%.1f, query p50 x%.2f, nodes per query x%.2f (mechanics)\n",
         (double)rows[1].particles / rows[0].particles, rows[1].query.p50 / rows[0].query.p50,
         rows[1].nodes_per_query / rows[0].nodes_per_query);
  printf("\ntargets:\n");
  tx_bench_target_us("query, mechanics, 10404 particles, p99", rows[0].query.p99 * 1e-3, 100);
  tx_bench_target_us("query, mechanics, 102400 particles, p99", rows[1].query.p99 * 1e-3, 250);
  tx_bench_target_us("query, paper, 10404 particles, p99", rows[2].query.p99 * 1e-3, 100);
  tx_bench_target_us("query, paper, 102400 particles, p99", rows[3].query.p99 * 1e-3, 250);
  return 0;
}
