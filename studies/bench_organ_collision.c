// tactus bench organ-collision: the cost of one collision.organ query (the
// tool tip against both soft organs, each through its BVH, and the local
// force) on the committed liver and stomach surfaces (assets/lagb, read with
// tx_mesh_load), and of the refit that each physics publish brings. No
// physics engine is involved: the surfaces breathe (a 1 mm travelling wave
// along their normals, a new shape every 80 queries: 50 Hz physics against
// 4 kHz collision), and the tip walks from vertex to nearby vertex over both
// organs, 3 mm clear of them and pressing up to 8 mm in along the way.
#include "bench_organ_collision.h"
#include "studies.h"

#include "../scenarios/command.h"

#include <tactus/config.h>

#if TX_WITH_ASSIMP
#include "../controllers/collision/organ.h"
#include "../controllers/instruments/mesh_io.h"

#include <tactus/components.h>
#include <tactus/model.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PER_PUBLISH 80 // 4 kHz queries per 50 Hz physics publish
#define LEG 400        // queries from one waypoint to the next (0.1 s)

typedef struct organ_mesh {
  const char* name;
  float* rest;   // (nx x 3) m, as committed
  float* x;      // (nx x 3) m, this publish
  float* nrm;    // (nx x 3) 1, area-weighted vertex normals at rest
  int32_t* tri;  // (ntri x 3)
  uint32_t nx, ntri;
  tx_tri_bvh bvh;
  tx_organ_side side;
} organ_mesh;

static void organ_free(organ_mesh* o) {
  free(o->rest), free(o->x), free(o->nrm), free(o->tri);
  tx_tri_bvh_free(&o->bvh);
}

static int organ_load(organ_mesh* o, const char* name) {
  memset(o, 0, sizeof *o);
  o->name = name;
  char path[1024];
  snprintf(path, sizeof path, "%s/lagb/%s.obj", TX_ASSET_DIR, name);
  tx_mesh m;
  if (!tx_mesh_load(path, &m)) return fprintf(stderr, "tactus: bench organ-collision: %s\n", tx_error()), 1;
  o->nx = (uint32_t)m.nvertices, o->ntri = (uint32_t)m.ntriangles;
  o->rest = malloc(sizeof(float) * 3 * o->nx);
  o->x = malloc(sizeof(float) * 3 * o->nx);
  o->nrm = calloc(3 * (size_t)o->nx, sizeof(float));
  o->tri = malloc(sizeof(int32_t) * 3 * o->ntri);
  if (!o->rest || !o->x || !o->nrm || !o->tri || tx_tri_bvh_init(&o->bvh, o->ntri)) {
    tx_mesh_free(&m);
    return fprintf(stderr, "tactus: bench organ-collision: out of memory\n"), 1;
  }
  for (size_t i = 0; i < 3 * (size_t)o->nx; i++) o->rest[i] = o->x[i] = (float)m.vertices[i];
  for (size_t i = 0; i < 3 * (size_t)o->ntri; i++) o->tri[i] = m.triangles[i];
  tx_mesh_free(&m);
  for (uint32_t t = 0; t < o->ntri; t++) { // the cross product of two edges: area-weighted
    const float *a = o->rest + 3 * o->tri[3 * t], *b = o->rest + 3 * o->tri[3 * t + 1], *c = o->rest + 3 * o->tri[3 * t + 2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; k++)
      for (int a2 = 0; a2 < 3; a2++) o->nrm[3 * o->tri[3 * t + k] + a2] += (float)n[a2];
  }
  for (uint32_t i = 0; i < o->nx; i++) {
    float* n = o->nrm + 3 * i;
    float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0) n[0] /= l, n[1] /= l, n[2] /= l;
  }
  tx_organ_side_reset(&o->side);
  return 0;
}

// the surface at time t: a 1 mm wave along the normals, travelling across the organ
static void breathe(organ_mesh* o, double t) {
  for (uint32_t i = 0; i < o->nx; i++) {
    const float* p = o->rest + 3 * i;
    double w = 1e-3 * sin(2 * M_PI * (1.5 * t + (p[0] + p[2]) / 0.05));
    for (int a = 0; a < 3; a++) o->x[3 * i + a] = (float)(p[a] + w * o->nrm[3 * i + a]);
  }
}

// the next waypoint: a vertex 5 to 15 mm from vertex v, picked by a fixed sequence
static uint32_t next_vertex(const organ_mesh* o, uint32_t v, unsigned* seed) {
  uint32_t pick[64];
  int n = 0;
  const float* p = o->rest + 3 * v;
  for (uint32_t i = 0; i < o->nx && n < 64; i++) {
    const float* q = o->rest + 3 * i;
    double d = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
    if (d > 5e-3 && d < 15e-3) pick[n++] = i;
  }
  *seed = *seed * 1103515245u + 12345u;
  return n ? pick[(*seed >> 8) % (unsigned)n] : (v + 1) % o->nx;
}

static bool finite_all(const float* v, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

int tx_bench_organ_collision(double duration_s) {
  const double seconds = duration_s > 0 ? duration_s : 10;
  const long queries = lround(seconds * 4000);
  organ_mesh org[2];
  if (organ_load(&org[0], "liver")) return 1;
  if (organ_load(&org[1], "stomach")) return organ_free(&org[0]), 1;
  double build_ms[2];
  for (int i = 0; i < 2; i++) {
    breathe(&org[i], 0);
    int64_t t0 = tx_mono_ns();
    tx_tri_bvh_build(&org[i].bvh, org[i].x, org[i].nx, org[i].tri, org[i].ntri);
    build_ms[i] = (tx_mono_ns() - t0) * 1e-6;
  }
  tx_organ_tip_def def = tx_organ_tip_def_default();
  static tx_hist hq, hr[2], ht; // not on the stack
  tx_hist_clear(&hq), tx_hist_clear(&ht), tx_hist_clear(&hr[0]), tx_hist_clear(&hr[1]);
  const double k_pen = 100;
  // the physics' reaction, taken on at every other publish: the carried force's few multiplications
  tx_skin_contact reaction = {.f = {0, 0.3, 0}, .n = {0, 1, 0}, .k = 150, .depth = 3e-3, .touching = 1};
  unsigned seed = 1;
  int which = 0; // the organ being walked over: the liver for 5 legs, then the stomach for 5
  uint32_t from = 0, to = next_vertex(&org[0], 0, &seed);
  long in_contact = 0, onsets = 0, gave = 0, reacting = 0;
  double peak = 0;
  for (long k = 0; k < queries; k++) {
    double t = k / 4000.0;
    if (k % PER_PUBLISH == 0 && k > 0) { // a physics publish: what the controller does with it
      for (int i = 0; i < 2; i++) breathe(&org[i], t);
      int64_t all = 0;
      for (int i = 0; i < 2; i++) {
        int64_t a = tx_mono_ns();
        bool same = finite_all(org[i].x, 3 * (size_t)org[i].nx) && tx_tri_bvh_same(&org[i].bvh, org[i].tri, org[i].ntri);
        if (same) tx_tri_bvh_refit(&org[i].bvh, org[i].x);
        int64_t d = tx_mono_ns() - a;
        tx_hist_add(&hr[i], d);
        all += d;
      }
      tx_hist_add(&ht, all);
    }
    if (k % LEG == 0 && k > 0) { // the next leg: five over one organ, then five over the other
      if ((k / LEG) % 5 == 0) {
        which = !which;
        to = next_vertex(&org[which], (uint32_t)(k % org[which].nx), &seed);
      }
      from = to;
      to = next_vertex(&org[which], from, &seed);
    }
    // along the leg from vertex to vertex, 3 mm clear at its ends and 8 mm in at its middle
    const organ_mesh* w = &org[which];
    double s = (k % LEG) / (double)LEG, depth = -3e-3 + 11e-3 * (0.5 - 0.5 * cos(2 * M_PI * s)), c[3];
    for (int a = 0; a < 3; a++) {
      double p = (1 - s) * w->rest[3 * from + a] + s * w->rest[3 * to + a];
      double n = (1 - s) * w->nrm[3 * from + a] + s * w->nrm[3 * to + a];
      c[a] = p + (def.radius - depth) * n;
    }
    reaction.x[0] = c[0], reaction.x[1] = c[1], reaction.x[2] = c[2];
    reaction.touching = (k / PER_PUBLISH) % 2;
    // the query: both organs, then the force
    tx_organ_touch touch[2];
    tx_organ_force_out f;
    int64_t a = tx_mono_ns();
    for (int i = 0; i < 2; i++) tx_organ_tip(&org[i].side, &def, &org[i].bvh, org[i].x, c, &touch[i]);
    tx_organ_force(touch, 2, &reaction, k_pen, def.depth_max, c, &f);
    tx_hist_add(&hq, tx_mono_ns() - a);
    in_contact += touch[0].on || touch[1].on;
    onsets += touch[0].onset + touch[1].onset;
    gave += touch[0].gave_way + touch[1].gave_way;
    reacting += f.kind == TX_ORGAN_FORCE_REACTION;
    double fn = sqrt(f.f[0] * f.f[0] + f.f[1] * f.f[1] + f.f[2] * f.f[2]);
    if (fn > peak) peak = fn;
  }
  tx_percentiles q = tx_hist_percentiles(&hq), rt = tx_hist_percentiles(&ht), rl = tx_hist_percentiles(&hr[0]),
                 rs = tx_hist_percentiles(&hr[1]);
  printf("bench organ-collision: one collision.organ query (tip radius %.1f mm) against the committed liver\n"
         "(%u triangles) and stomach (%u), %ld queries at 4 kHz, both surfaces refitted every %d (50 Hz physics)\n\n",
         def.radius * 1e3, org[0].ntri, org[1].ntri, queries, PER_PUBLISH);
  printf("  %-34s %9s %9s %9s\n", "operation", "p50 us", "p99 us", "max us");
  printf("  %-34s %9.2f %9.2f %9.2f\n", "query, both organs", q.p50 * 1e-3, q.p99 * 1e-3, q.max * 1e-3);
  printf("  %-34s %9.2f %9.2f %9.2f\n", "refit, liver", rl.p50 * 1e-3, rl.p99 * 1e-3, rl.max * 1e-3);
  printf("  %-34s %9.2f %9.2f %9.2f\n", "refit, stomach", rs.p50 * 1e-3, rs.p99 * 1e-3, rs.max * 1e-3);
  printf("  %-34s %9.2f %9.2f %9.2f\n", "refit, both (one publish)", rt.p50 * 1e-3, rt.p99 * 1e-3, rt.max * 1e-3);
  printf("  %-34s %9.2f ms (liver), %.2f ms (stomach)\n", "build", build_ms[0], build_ms[1]);
  printf("\n  in contact %.1f%% of queries, %ld contacts begun, %ld gave way, %.1f%% on the carried reaction,"
         " peak %.2f N\n", 100.0 * in_contact / queries, onsets, gave, 100.0 * reacting / queries, peak);
  printf("  (refit: the finite check, the triangle compare and the refit of the step that sees a publish)\n");
  printf("\ntargets:\n");
  tx_bench_target_us("query, both organs, p99", q.p99 * 1e-3, 100);
  organ_free(&org[0]), organ_free(&org[1]);
  return 0;
}
#else
int tx_bench_organ_collision(double duration_s) {
  (void)duration_s;
  return tx_bad_input("bench organ-collision: built without assimp (TX_WITH_ASSIMP): the organ surfaces cannot be read");
}
#endif
