// The skin's cloth against closed-form membrane solutions (skin_membrane.h).
#include "skin_membrane.h"

#include "../../model/error.h"

#include <tactus/config.h>
#include <tactus/model.h>

#include <math.h>
#include <stdlib.h>
#include <time.h>

#if TX_WITH_BULLET
#include "../../controllers/physics/bullet/cloth.h"
#endif

tx_membrane_case tx_membrane_case_default(tx_membrane_kind kind) {
  tx_membrane_case k = {kind, 0.04, 100, 2000, 4.4, 0.02, 0.005, 9.81, 0.15, 300};
  return k;
}

double tx_membrane_exact(const tx_membrane_case* k) {
  if (k->kind == TX_MEMBRANE_DISC) return k->load * (log(k->radius / k->load_radius) + 0.5) / (2 * M_PI * k->tension);
  return k->density * k->gravity * k->radius * k->radius / (4 * k->tension);
}

#if TX_WITH_BULLET
static double wall_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

// the part of a cell of side s centred at (x, z) that lies inside the disc r < r0 (8 x 8 samples)
static double inside(double x, double z, double s, double r0) {
  int in = 0;
  for (int i = 0; i < 8; i++)
    for (int j = 0; j < 8; j++) {
      double px = x + (i + 0.5) / 8 * s - 0.5 * s, pz = z + (j + 0.5) / 8 * s - 0.5 * s;
      in += px * px + pz * pz < r0 * r0;
    }
  return in / 64.0;
}

bool tx_membrane_run(const tx_membrane_case* k, double spacing, tx_membrane_result* out) {
  double cells = k->radius / spacing;
  if (!(spacing > 0) || fabs(cells - lround(cells)) > 1e-6 * cells || lround(cells) < 4) {
    tx_set_error("skin-membrane: spacing %g m must divide the radius %g m into at least 4 cells", spacing, k->radius);
    return false;
  }
  // a square of side 2 a + 2 s around the disc, a particle at the centre
  const int half = (int)lround(cells) + 1, res = 2 * half + 1;
  const double size = (res - 1) * spacing;
  tx_cloth_def d = tx_cloth_def_default();
  d.size[0] = d.size[1] = size;
  d.res[0] = d.res[1] = res;
  d.mass = k->density * size * size * (double)(res * res) / ((double)(res - 1) * (res - 1)); // rho t per cell
  d.stretch_stiffness = k->stiffness;
  d.bend_stiffness = 0; // a membrane
  d.clamp_radius = k->radius;
  d.pretension = k->tension;
  d.rupture_tension = 0;
  d.rupture_length = 0.25 * k->radius; // only for the tension it reports
  d.damping = k->damping;
  d.gravity = k->kind == TX_MEMBRANE_SAG ? k->gravity : 0;
  d.settle_time = 0;
  // converged range: the substep makes k w h^2 = 1/4, where one iteration
  // already takes most of a link's stretch; 4 iterations finish it
  const double m = d.mass / (res * res);
  double h = 0.5 / sqrt(k->stiffness * 2 / m);
  d.max_substep = h;
  d.iterations = 4;
  tx_cloth* c = tx_cloth_create(&d);
  if (!c) return false;
  if (k->kind == TX_MEMBRANE_DISC) {
    // F over r < r0 by the part of each particle's cell inside, summing to F exactly
    double total = 0;
    for (int pass = 0; pass < 2; pass++)
      for (int iz = 0; iz < res; iz++)
        for (int ix = 0; ix < res; ix++) {
          double x = (ix - half) * spacing, z = (iz - half) * spacing;
          double part = inside(x, z, spacing, k->load_radius);
          if (part <= 0) continue;
          if (pass == 0) total += part;
          else tx_cloth_set_load(c, iz * res + ix, (double[3]){0, -k->load * part / total, 0});
        }
  }
  const int centre = half * res + half;
  const int frames = (int)ceil(k->time * 60), tail = frames / 10 > 0 ? frames / 10 : 1;
  double t0 = wall_now(), p[3], before = 0;
  for (int f = 0; f < frames; f++) {
    if (tx_cloth_step(c, 1.0 / 60) != TX_CLOTH_OK) {
      tx_cloth_destroy(c);
      tx_set_error("skin-membrane: the cloth faulted at %g m spacing", spacing);
      return false;
    }
    if (f == frames - 1 - tail) tx_cloth_particle(c, centre, p), before = p[1];
  }
  tx_cloth_particle(c, centre, p);
  out->spacing = spacing;
  out->particles = res * res;
  out->substep = (1.0 / 60) / ceil((1.0 / 60) / h - 1e-9);
  out->iterations = d.iterations;
  out->measured = -p[1];
  out->exact = tx_membrane_exact(k);
  out->error = fabs(out->measured - out->exact) / out->exact;
  out->drift = fabs(p[1] - before);
  out->tension = tx_cloth_membrane_tension(c, centre);
  out->seconds = wall_now() - t0;
  tx_cloth_destroy(c);
  return true;
}
#else
bool tx_membrane_run(const tx_membrane_case* k, double spacing, tx_membrane_result* out) {
  (void)k, (void)spacing, (void)out;
  tx_set_error("skin-membrane: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
  return false;
}
#endif
