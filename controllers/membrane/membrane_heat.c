// Heat in a thin membrane on its particle grid (membrane_heat.h).
#include "membrane_heat.h"

#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// the edges' indices around particle (ix, iz): -1 where the grid ends
static int edge_x(const tx_membrane_heat_def* d, int ix, int iz) { return ix < 0 || ix >= d->nx - 1 ? -1 : iz * (d->nx - 1) + ix; }
static int edge_z(const tx_membrane_heat_def* d, int ix, int iz) { return iz < 0 || iz >= d->nz - 1 ? -1 : iz * d->nx + ix; }

static bool finite_in(double v, double lo, double hi) { return isfinite(v) && v >= lo && v <= hi; }

tx_membrane_heat* tx_membrane_heat_create(const tx_membrane_heat_def* def) {
  const tx_tissue* ts = &def->tissue;
  if (def->nx < 2 || def->nz < 2 || def->nx > 1024 || def->nz > 1024)
    return tx_set_error("membrane heat: %d x %d particles, each in [2, 1024]", def->nx, def->nz), NULL;
  if (!finite_in(def->spacing, 1e-6, 1) || !finite_in(def->thickness, 1e-6, 1))
    return tx_set_error("membrane heat: spacing %g m, thickness %g m, each in [1e-6, 1]", def->spacing, def->thickness), NULL;
  if (!finite_in(ts->k, 1e-6, 1e3) || !finite_in(ts->rho, 1, 1e5) || !finite_in(ts->c, 1, 1e5) ||
      !finite_in(ts->perfusion, 0, 1e9) || !finite_in(ts->t_arterial, 200, 400))
    return tx_set_error("membrane heat: a tissue property is out of range (k %g, rho %g, c %g, perfusion %g, T_a %g)", ts->k,
                        ts->rho, ts->c, ts->perfusion, ts->t_arterial), NULL;
  if (!finite_in(def->vaporisation_k, ts->t_arterial, 1000) || !(def->vaporisation_k > ts->t_arterial))
    return tx_set_error("membrane heat: vaporisation %g K is not above T_a %g K", def->vaporisation_k, ts->t_arterial), NULL;
  if (!finite_in(def->damage.a, 0, 1e300) || !finite_in(def->damage.ea, 0, 1e7))
    return tx_set_error("membrane heat: Arrhenius A %g, Ea %g out of range", def->damage.a, def->damage.ea), NULL;

  tx_membrane_heat* h = calloc(1, sizeof *h);
  if (!h) return tx_set_error("membrane heat: out of memory"), NULL;
  h->def = *def;
  const int nx = def->nx, nz = def->nz, n = nx * nz;
  h->n = n;
  h->t = malloc(sizeof(double) * (size_t)n), h->omega = calloc((size_t)n, sizeof(double));
  h->area = malloc(sizeof(double) * (size_t)n), h->cap = malloc(sizeof(double) * (size_t)n);
  h->perf = malloc(sizeof(double) * (size_t)n), h->q = calloc((size_t)n, sizeof(double));
  h->next = malloc(sizeof(double) * (size_t)n), h->boiled_now = malloc(sizeof(int32_t) * (size_t)n);
  h->ex = malloc((size_t)(nx - 1) * (size_t)nz), h->ez = malloc((size_t)nx * (size_t)(nz - 1));
  h->gone = calloc((size_t)n, 1), h->held = calloc((size_t)n, 1);
  if (!h->t || !h->omega || !h->area || !h->cap || !h->perf || !h->q || !h->next || !h->boiled_now || !h->ex || !h->ez ||
      !h->gone || !h->held) {
    tx_membrane_heat_destroy(h);
    return tx_set_error("membrane heat: out of memory"), NULL;
  }
  memset(h->ex, 2, (size_t)(nx - 1) * (size_t)nz);
  memset(h->ez, 2, (size_t)nx * (size_t)(nz - 1));
  // an edge of the patch has one triangle beside it
  for (int ix = 0; ix < nx - 1; ix++) h->ex[edge_x(def, ix, 0)] = h->ex[edge_x(def, ix, nz - 1)] = 1;
  for (int iz = 0; iz < nz - 1; iz++) h->ez[edge_z(def, 0, iz)] = h->ez[edge_z(def, nx - 1, iz)] = 1;

  // each particle's share of the area, its capacity and perfusion
  const double s = def->spacing, t = def->thickness;
  for (int iz = 0; iz < nz; iz++)
    for (int ix = 0; ix < nx; ix++) {
      const int i = ix + nx * iz;
      const bool bx = ix == 0 || ix == nx - 1, bz = iz == 0 || iz == nz - 1;
      h->area[i] = s * s * (bx ? 0.5 : 1) * (bz ? 0.5 : 1);
      h->cap[i] = ts->rho * ts->c * t * h->area[i];
      h->perf[i] = ts->perfusion * t * h->area[i];
      h->t[i] = ts->t_arterial;
      h->held[i] = !def->insulated && (bx || bz);
    }

  // Gershgorin: the largest eigenvalue of C^-1 (G + P) is at most
  // (2 sum_j G_ij + P_i) / C_i; explicit Euler is stable below 2 over it
  const double g = ts->k * t / 2;
  double lmax = 0;
  for (int iz = 0; iz < nz; iz++)
    for (int ix = 0; ix < nx; ix++) {
      const int i = ix + nx * iz;
      const int e[4] = {edge_x(def, ix - 1, iz), edge_x(def, ix, iz), edge_z(def, ix, iz - 1), edge_z(def, ix, iz)};
      double sum = 0;
      for (int k = 0; k < 4; k++)
        if (e[k] >= 0) sum += g * (k < 2 ? h->ex[e[k]] : h->ez[e[k]]);
      lmax = fmax(lmax, (2 * sum + h->perf[i]) / h->cap[i]);
    }
  h->dt_max = lmax > 0 ? 0.9 * 2 / lmax : INFINITY;
  h->peak = ts->t_arterial;
  return h;
}

void tx_membrane_heat_destroy(tx_membrane_heat* h) {
  if (!h) return;
  free(h->t), free(h->omega), free(h->area), free(h->cap), free(h->perf), free(h->q), free(h->next), free(h->boiled_now);
  free(h->ex), free(h->ez), free(h->gone), free(h->held);
  free(h);
}

void tx_membrane_heat_edges(tx_membrane_heat* h, const int32_t* tri, int m) {
  const tx_membrane_heat_def* d = &h->def;
  memset(h->ex, 0, (size_t)(d->nx - 1) * (size_t)d->nz);
  memset(h->ez, 0, (size_t)d->nx * (size_t)(d->nz - 1));
  for (int f = 0; f < m; f++)
    for (int k = 0; k < 3; k++) {
      int a = tri[3 * f + k], b = tri[3 * f + (k + 1) % 3];
      if (a < 0 || b < 0 || a >= h->n || b >= h->n) continue;
      if (a > b) { int c = a; a = b; b = c; }
      const int ax = a % d->nx, az = a / d->nx, bx = b % d->nx, bz = b / d->nx;
      if (az == bz && bx == ax + 1) h->ex[edge_x(d, ax, az)]++;
      else if (ax == bx && bz == az + 1) h->ez[edge_z(d, ax, az)]++;
      // a diagonal carries no heat in the 5-point stencil
    }
}

bool tx_membrane_heat_live(const tx_membrane_heat* h, int i) {
  if (i < 0 || i >= h->n || h->gone[i]) return false;
  const tx_membrane_heat_def* d = &h->def;
  const int ix = i % d->nx, iz = i / d->nx;
  const int e[4] = {edge_x(d, ix - 1, iz), edge_x(d, ix, iz), edge_z(d, ix, iz - 1), edge_z(d, ix, iz)};
  for (int k = 0; k < 4; k++)
    if (e[k] >= 0 && (k < 2 ? h->ex[e[k]] : h->ez[e[k]]) > 0) return true;
  return false;
}

double tx_membrane_heat_source(tx_membrane_heat* h, const float* x, const double tip[3], double radius, double power) {
  memset(h->q, 0, sizeof(double) * (size_t)h->n);
  if (!(power > 0) || !(radius > 0)) return 0;
  const double inv = 1 / (2 * radius * radius);
  double sum = 0;
  for (int i = 0; i < h->n; i++) {
    if (!tx_membrane_heat_live(h, i)) continue;
    double r2 = 0;
    for (int a = 0; a < 3; a++) r2 += (x[3 * i + a] - tip[a]) * (x[3 * i + a] - tip[a]);
    h->q[i] = h->area[i] * exp(-r2 * inv);
    sum += h->q[i];
  }
  if (!(sum > 0)) {
    memset(h->q, 0, sizeof(double) * (size_t)h->n);
    return 0;
  }
  for (int i = 0; i < h->n; i++) h->q[i] *= power / sum;
  return power;
}

int tx_membrane_heat_step(tx_membrane_heat* h, double dt) {
  const tx_membrane_heat_def* d = &h->def;
  const double ta = d->tissue.t_arterial, cap_t = d->vaporisation_k, g = d->tissue.k * d->thickness / 2;
  // Omega is counted above T_a + 1 K: below, A exp(-Ea / (R T)) is under 4e-4 1/s, nothing in a run
  const double damage_from = ta + 1;
  const int nx = d->nx, nz = d->nz;
  int boiled = 0;
  h->peak = ta;
  h->substeps = !(dt > 0) ? 0 : dt <= h->dt_max ? 1 : (int)ceil(dt / h->dt_max);
  const double sub = h->substeps ? dt / h->substeps : 0;
  for (int k = 0; k < h->substeps; k++) {
    // the new temperatures from the old
    for (int iz = 0; iz < nz; iz++)
      for (int ix = 0; ix < nx; ix++) {
        const int i = ix + nx * iz;
        if (h->gone[i] || h->held[i]) {
          h->next[i] = ta;
          if (h->held[i] && !h->gone[i]) h->energy += h->q[i] * sub; // into the attachment: a perfect sink
          continue;
        }
        const double ti = h->t[i];
        double flux = h->q[i] - h->perf[i] * (ti - ta);
        const int nb[4] = {ix > 0 ? i - 1 : -1, ix < nx - 1 ? i + 1 : -1, iz > 0 ? i - nx : -1, iz < nz - 1 ? i + nx : -1};
        const int e[4] = {edge_x(d, ix - 1, iz), edge_x(d, ix, iz), edge_z(d, ix, iz - 1), edge_z(d, ix, iz)};
        for (int j = 0; j < 4; j++) {
          if (nb[j] < 0 || h->gone[nb[j]]) continue;
          const uint8_t live = j < 2 ? h->ex[e[j]] : h->ez[e[j]];
          if (live) flux += g * live * (h->t[nb[j]] - ti);
        }
        h->next[i] = ti + sub * flux / h->cap[i];
        h->energy += h->q[i] * sub;
      }
    // boiling and damage at the new temperatures
    for (int i = 0; i < h->n; i++) {
      if (h->gone[i] || h->held[i]) {
        h->t[i] = ta;
        continue;
      }
      double ti = h->next[i];
      if (ti >= cap_t) { // vaporised: the heat past the cap, and its own above T_a, leave with the vapour
        h->boiled += h->cap[i] * (ti - ta);
        ti = cap_t;
        h->gone[i] = 1;
        h->boiled_now[boiled++] = i;
      }
      if (ti > damage_from) h->omega[i] += sub * tx_arrhenius_rate(&d->damage, ti);
      h->peak = fmax(h->peak, ti);
      h->t[i] = h->gone[i] ? ta : ti;
    }
  }
  return boiled;
}

double tx_membrane_heat_content(const tx_membrane_heat* h) {
  double e = 0;
  for (int i = 0; i < h->n; i++)
    if (!h->gone[i] && !h->held[i]) e += h->cap[i] * (h->t[i] - h->def.tissue.t_arterial);
  return e;
}

double tx_membrane_heat_damaged(const tx_membrane_heat* h) {
  double a = 0;
  for (int i = 0; i < h->n; i++)
    if (h->omega[i] >= 1) a += h->area[i];
  return a;
}
