// tactus bench thermal: the target for the cautery, the thermal
// update at >= 100 Hz on the organs with a step p99 <= 2 ms. What
// physics.cautery does each step, on one thread: the hook's 30 W Gaussian
// source (2 mm) moved across the liver, an explicit bioheat step of the liver
// and of the stomach (their tetrahedra refined twice: 71,000 nodes, 371,000
// tetrahedra), and each organ's nodal
// temperature and damage interpolated onto its drawn surface (2,200 vertices).
#include "bench_thermal.h"
#include "studies.h"

#include "../controllers/organs/thermal.h"
#include "../model/error.h"

#include <tactus/config.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define RATE_HZ 100.0
#define REFINE 2 // physics.cautery's default

typedef struct organ {
  tx_thermal* h;
  int nv, nodes, tets;
  int* tet;  // (nv x 4)
  float* w;  // (nv x 4)
  float *t, *omega; // (nv): the surface's
} organ;

static bool load(organ* o, const char* name, const tx_tissue* ts, const tx_arrhenius* d) {
  char base[4096], path[4200];
  snprintf(base, sizeof base, "%s/lagb/%s", TX_ASSET_DIR, name);
  snprintf(path, sizeof path, "%s.obj", base);
  double* x;
  int n, nt, *tet, *tri, ntri;
  float* sx;
  if (!tx_tetgen_read(base, &x, &n, &tet, &nt)) return false;
  if (!tx_obj_read(path, &sx, &o->nv, &tri, &ntri)) return free(x), free(tet), false;
  o->tet = malloc(sizeof(int) * 4 * (size_t)o->nv), o->w = malloc(sizeof(float) * 4 * (size_t)o->nv);
  o->t = malloc(sizeof(float) * (size_t)o->nv), o->omega = malloc(sizeof(float) * (size_t)o->nv);
  double* fx = NULL;
  int fn, *ft = NULL, fnt;
  bool ok = o->tet && o->w && o->t && o->omega &&
            tx_thermal_refine_embed(x, n, tet, nt, REFINE, sx, o->nv, &fx, &fn, &ft, &fnt, o->tet, o->w);
  if (ok) o->h = tx_thermal_create(fx, fn, ft, fnt, ts, d, 1 / RATE_HZ), ok = o->h != NULL;
  if (ok) tx_thermal_band(o->h, 1e-3); // physics.cautery's default
  o->nodes = ok ? fn : 0, o->tets = ok ? fnt : 0;
  free(x), free(tet), free(sx), free(tri), free(fx), free(ft);
  return ok;
}

static void surface(organ* o) {
  const double *t = tx_thermal_temperature(o->h), *om = tx_thermal_damage(o->h), rest = tx_thermal_damage_rest(o->h);
  for (int v = 0; v < o->nv; v++) {
    double a = 0, b = 0;
    for (int k = 0; k < 4; k++) a += o->w[4 * v + k] * t[o->tet[4 * v + k]], b += o->w[4 * v + k] * om[o->tet[4 * v + k]];
    o->t[v] = (float)a, o->omega[v] = (float)fmin(b + rest, 1e30);
  }
}

static void release(organ* o) {
  tx_thermal_destroy(o->h);
  free(o->tet), free(o->w), free(o->t), free(o->omega);
}

int tx_bench_thermal(double duration_s) {
  double seconds = duration_s > 0 ? duration_s : 10;
  organ org[2] = {{0}};
  tx_tissue ts[2] = {tx_tissue_liver(), tx_tissue_stomach()};
  tx_arrhenius d = tx_arrhenius_liver();
  static const char* const names[2] = {"liver", "stomach"};
  for (int i = 0; i < 2; i++)
    if (!load(&org[i], names[i], &ts[i], &d)) {
      fprintf(stderr, "tactus: bench thermal: %s\n", tx_error());
      release(&org[0]), release(&org[1]);
      return 1;
    }
  printf("bench thermal: the committed liver and stomach (assets/lagb) refined %d times as physics.cautery does "
         "(%d + %d nodes, %d + %d tetrahedra), Pennes bioheat at %g Hz (%d and %d substeps), a 30 W hook (Gaussian, 2 mm) "
         "sliding over the liver, 1 s on and 1 s off; %g s; CPU time of a step on its thread\n\n",
         REFINE, org[0].nodes, org[1].nodes, org[0].tets, org[1].tets, RATE_HZ, tx_thermal_substeps(org[0].h),
         tx_thermal_substeps(org[1].h), seconds);
  static tx_hist hist;
  tx_hist_clear(&hist);
  int steps = (int)lround(seconds * RATE_HZ);
  for (int s = 0; s < steps; s++) {
    double t = s / RATE_HZ, ph = fmod(t, 2.0);
    // on the liver's anterior surface (y = 55 mm at x = z = 60 mm), 1 s on, 1 s off
    const double tip[3] = {0.06 - 0.02 * ph / 2, 0.054, 0.06};
    struct timespec t0, t1;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0);
    tx_thermal_source(org[0].h, tip, 0.002, ph < 1 ? 30 : 0);
    tx_thermal_source(org[1].h, tip, 0.002, 0);
    for (int i = 0; i < 2; i++) tx_thermal_step(org[i].h), surface(&org[i]);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
    tx_hist_add(&hist, (int64_t)(t1.tv_sec - t0.tv_sec) * 1000000000 + (t1.tv_nsec - t0.tv_nsec));
  }
  tx_percentiles p = tx_hist_percentiles(&hist);
  double peak = 0;
  for (int v = 0; v < org[0].nv; v++) peak = fmax(peak, org[0].t[v]);
  printf("  %-22s %9s %9s %9s %9s %12s\n", "organs", "steps", "p50 ms", "p99 ms", "max ms", "liver peak K");
  printf("  %-22s %9d %9.4f %9.4f %9.4f %12.1f\n", "liver and stomach", steps, p.p50 * 1e-6, p.p99 * 1e-6, p.max * 1e-6, peak);
  printf("\ntargets:\n");
  char measured[64];
  snprintf(measured, sizeof measured, "%.4f ms", p.p99 * 1e-6);
  tx_bench_target("thermal step at 100 Hz, both organs, p99", measured, "<= 2 ms", p.p99 * 1e-6 <= 2);
  release(&org[0]), release(&org[1]);
  return 0;
}
