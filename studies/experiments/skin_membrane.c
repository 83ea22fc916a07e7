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
  tx_membrane_case k = {kind, 0.04, 100, 2000, 4.4, 0.02, 0.005, 9.81, 0.15, 300, 0};
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

// A membrane clamped at radius a: a square of side 2 a + 2 s around the disc,
// a particle at the centre, areal density rho_t (kg/m^2) per cell, no bending
// links, and the converged solver: the substep makes k w h^2 = 1/4, where one
// iteration already takes most of a link's stretch, and 4 iterations finish it;
// or (implicit) the implicit solver as physics.skin ships it (one substep a
// 60 Hz step). half: the particles from the centre to the edge
static bool disc_patch(double a, double spacing, double rho_t, double stiffness, bool implicit, tx_cloth_def* d,
                       int* half) {
  double cells = a / spacing;
  if (!(spacing > 0) || fabs(cells - lround(cells)) > 1e-6 * cells || lround(cells) < 4)
    return tx_set_error("skin-membrane: spacing %g m must divide the radius %g m into at least 4 cells", spacing, a), false;
  *half = (int)lround(cells) + 1;
  const int res = 2 * *half + 1;
  const double size = (res - 1) * spacing;
  *d = tx_cloth_def_default();
  d->size[0] = d->size[1] = size;
  d->res[0] = d->res[1] = res;
  d->mass = rho_t * size * size * (double)(res * res) / ((double)(res - 1) * (res - 1));
  d->stretch_stiffness = stiffness;
  d->bend_stiffness = 0;
  d->clamp_radius = a;
  if (implicit) return true;
  d->solver = TX_CLOTH_XPBD;
  d->max_substep = tx_cloth_converged_substep(stiffness, d->mass / (res * res), 0.25);
  d->iterations = 4;
  return true;
}

// steps c at 60 Hz for time s; the centre particle's sag (m) and its change over the last 10 %
static bool settle(tx_cloth* c, int centre, double time, double* sag, double* drift) {
  const int frames = (int)ceil(time * 60), tail = frames / 10 > 0 ? frames / 10 : 1;
  double p[3], before = 0;
  for (int f = 0; f < frames; f++) {
    if (tx_cloth_step(c, 1.0 / 60) != TX_CLOTH_OK) return false;
    if (f == frames - 1 - tail) tx_cloth_particle(c, centre, p), before = p[1];
  }
  tx_cloth_particle(c, centre, p);
  *sag = -p[1];
  *drift = fabs(p[1] - before);
  return true;
}

bool tx_membrane_run(const tx_membrane_case* k, double spacing, tx_membrane_result* out) {
  tx_cloth_def d;
  int half;
  if (!disc_patch(k->radius, spacing, k->density, k->stiffness, k->implicit != 0, &d, &half)) return false;
  const int res = d.res[0];
  d.pretension = k->tension;
  d.rupture_tension = 0;
  d.rupture_length = 0.25 * k->radius; // only for the tension it reports
  d.damping = k->damping;
  d.gravity = k->kind == TX_MEMBRANE_SAG ? k->gravity : 0;
  d.settle_time = 0;
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
  double t0 = wall_now();
  if (!settle(c, centre, k->time, &out->measured, &out->drift)) {
    tx_cloth_destroy(c);
    return tx_set_error("skin-membrane: the cloth faulted at %g m spacing", spacing), false;
  }
  out->spacing = spacing;
  out->particles = res * res;
  out->substep = (1.0 / 60) / ceil((1.0 / 60) / d.max_substep - 1e-9);
  out->iterations = d.iterations;
  out->exact = tx_membrane_exact(k);
  out->error = fabs(out->measured - out->exact) / out->exact;
  out->tension = tx_cloth_membrane_tension(c, centre);
  out->seconds = wall_now() - t0;
  tx_cloth_destroy(c);
  return true;
}
// the vertical force the membrane puts on its clamp (N, up positive): the
// tensions of the links from a free particle to a clamped one; at rest it
// balances the HIP's push, without the contact's impulses and their noise
static double clamp_force(const tx_cloth* c, const unsigned char* fixed) {
  double sum = 0;
  for (int id = 0, n = tx_cloth_link_total(c); id < n; id++) {
    int32_t e[2];
    tx_cloth_link_ends(c, id, e);
    if (fixed[e[0]] == fixed[e[1]]) continue;
    int in = fixed[e[0]] ? e[1] : e[0], out = fixed[e[0]] ? e[0] : e[1];
    double pi[3], po[3];
    tx_cloth_particle(c, in, pi);
    tx_cloth_particle(c, out, po);
    double dx = po[0] - pi[0], dy = po[1] - pi[1], dz = po[2] - pi[2], len = sqrt(dx * dx + dy * dy + dz * dz);
    if (len > 0) sum += tx_cloth_link_tension(c, id) * dy / len; // pulls the free particle towards the clamp
  }
  return sum;
}

bool tx_membrane_rupture_run(double spacing, tx_membrane_rupture* out) {
  const double a = 0.015, r = 0.0005, thickness = 0.004, rc = r + 0.5 * thickness, speed = 0.02;
  tx_cloth_def d;
  int half;
  if (!disc_patch(a, spacing, 100 * 4.4, 2000, false, &d, &half)) return false;
  const int res = d.res[0];
  d.thickness = thickness;
  d.pretension = 50;
  d.rupture_tension = 150;
  d.rupture_length = 0.002;
  d.damping = 5;
  unsigned char* fixed = calloc((size_t)(res * res), 1);
  tx_cloth* c = fixed ? tx_cloth_create(&d) : NULL;
  if (!c) return free(fixed), false;
  for (int iz = 0; iz < res; iz++)
    for (int ix = 0; ix < res; ix++) {
      double x = (ix - half) * spacing, z = (iz - half) * spacing;
      fixed[iz * res + ix] = ix == 0 || iz == 0 || ix == res - 1 || iz == res - 1 || x * x + z * z >= a * a * (1 - 1e-12);
    }
  const double dt = 1.0 / 600;
  double h[3] = {0, rc + 0.0005, 0}, last = 0, t0 = wall_now();
  out->force = out->depth = out->tension = NAN;
  for (int s = 0; s < 600 && tx_cloth_torn(c) == 0; s++) { // at most 1 s, 2 cm down
    h[1] = rc + 0.0005 - speed * dt * (s + 1);
    tx_cloth_set_hip(c, h, r);
    if (tx_cloth_step(c, dt) != TX_CLOTH_OK) {
      tx_cloth_destroy(c);
      free(fixed);
      tx_set_error("skin-membrane: the cloth faulted at %g m spacing", spacing);
      return false;
    }
    if (tx_cloth_torn(c) > 0) {
      out->force = last; // the step before the tear, whole
      out->depth = -(h[1] - rc);
      out->tension = tx_cloth_peak_tension(c);
    }
    last = clamp_force(c, fixed);
  }
  free(fixed);
  out->spacing = spacing;
  out->particles = res * res;
  out->seconds = wall_now() - t0;
  tx_cloth_destroy(c);
  if (isnan(out->force)) {
    tx_set_error("skin-membrane: no tear within 2 cm at %g m spacing", spacing);
    return false;
  }
  return true;
}
// the centre's sag (m) after `time` s hanging from flat; drift: its change over the last 10 %
static bool hang(const tx_cloth_def* d, double time, double* sag, double* drift) {
  tx_cloth* c = tx_cloth_create(d);
  if (!c) return false;
  bool ok = settle(c, (d->res[1] / 2) * d->res[0] + d->res[0] / 2, time, sag, drift);
  tx_cloth_destroy(c);
  return ok || (tx_set_error("skin-membrane: the hanging cloth faulted"), false);
}

bool tx_membrane_gravity_run(int res, tx_membrane_sag* out) {
  if (res < 5 || res > 201) return tx_set_error("skin-membrane: %d particles a side, expected 5 to 201", res), false;
  tx_cloth_def d = tx_cloth_def_default();
  d.res[0] = d.res[1] = res;
  d.mass = 1100 * 0.004 * d.size[0] * d.size[1];
  d.gravity = 9.81;
  d.settle_time = 0;
  d.rupture_tension = 0;
  double t0 = wall_now(), drift;
  if (!hang(&d, 3, &out->realtime, &drift)) return false; // the real-time default, as it comes
  d.damping = 50; // to rest sooner; the rest state does not depend on it
  d.solver = TX_CLOTH_XPBD;
  d.max_substep = tx_cloth_converged_substep(d.stretch_stiffness, d.mass / (res * res), 0.25);
  d.iterations = 4;
  if (!hang(&d, 0.5, &out->converged, &out->drift)) return false;
  out->res = res;
  out->seconds = wall_now() - t0;
  return true;
}
#else
bool tx_membrane_gravity_run(int res, tx_membrane_sag* out) {
  (void)res, (void)out;
  tx_set_error("skin-membrane: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
  return false;
}
bool tx_membrane_rupture_run(double spacing, tx_membrane_rupture* out) {
  (void)spacing, (void)out;
  tx_set_error("skin-membrane: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
  return false;
}
bool tx_membrane_run(const tx_membrane_case* k, double spacing, tx_membrane_result* out) {
  (void)k, (void)spacing, (void)out;
  tx_set_error("skin-membrane: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
  return false;
}
#endif
