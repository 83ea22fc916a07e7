// Spherical voxel tissue: Know-Your-Neighbour lists from a uniform grid,
// sphere-sphere collision with Vieta culling (eqs. 2-5), exact spring-damper
// to the rest position (eqs. 6, 7), damage and its recovery.
#include "tissue.h"

#include "../range_check.h"

#include "../../model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

tx_voxel_tissue_def tx_voxel_tissue_def_default(void) {
  return (tx_voxel_tissue_def){
      .block_size = {5e-3, 5e-3, 5e-3},
      .origin = {0, 0, 0},
      .count = {10, 10, 10},
      .mass = 1.25e-7,
      .elasticity = 0.5,
      .spring = 0.05,
      .damper = 1e-4,
      .radius = 0.25e-3,
      .damage_shrink = 0.5,
      .recovery_time = 0.5,
      .skin = 0.1e-3,
      .max_neighbours = 32,
  };
}

// NULL if lo <= v <= hi (strictly above lo when open_lo, strictly below hi when open_hi) and finite
static int range(const char* name, double v, double lo, bool open_lo, double hi, bool open_hi,
                         const char* units) {
  return tx_check_range("voxel tissue", name, v, lo, open_lo, hi, open_hi, units);
}

static int irange(const char* name, long long v, long long lo, long long hi) {
  return tx_check_count("voxel tissue", name, v, lo, hi);
}

int tx_voxel_tissue_def_check(const tx_voxel_tissue_def* d) {
  static const char* const size_name[3] = {"block_size[0]", "block_size[1]", "block_size[2]"};
  static const char* const origin_name[3] = {"origin[0]", "origin[1]", "origin[2]"};
  static const char* const count_name[3] = {"count[0]", "count[1]", "count[2]"};
  // from a single cell to an organ; masses from a cell to a gram-scale lump
  for (int a = 0; a < 3; a++) {
    if (range(size_name[a], d->block_size[a], 0, true, 1, false, "m")) return -1;
    if (range(origin_name[a], d->origin[a], -10, false, 10, false, "m")) return -1;
    if (irange(count_name[a], d->count[a], 1, 1000)) return -1;
  }
  // a bound on the total keeps every index and list size inside 32 bits
  long long n = (long long)d->count[0] * d->count[1] * d->count[2];
  if (irange("count[0] * count[1] * count[2]", n, 1, 10000000)) return -1;
  if (range("mass", d->mass, 0, true, 1, false, "kg")) return -1;
  if (range("elasticity", d->elasticity, 0, false, 1, false, "(e of eq. 5)")) return -1;
  if (range("spring", d->spring, 0, false, 1e9, false, "N/m")) return -1;
  if (range("damper", d->damper, 0, false, 1e9, false, "N s/m")) return -1;
  if (range("radius", d->radius, 0, true, 1, false, "m")) return -1;
  if (range("damage_shrink", d->damage_shrink, 0, false, 1, true, "(fraction)")) return -1;
  if (range("recovery_time", d->recovery_time, 0, true, 1e6, false, "s")) return -1;
  if (range("skin", d->skin, 0, true, 1, false, "m")) return -1;
  if (irange("max_neighbours", d->max_neighbours, 1, 200)) return -1;
  // voxels packed tighter than this have more neighbours within reach than a
  // lattice point has within two spacings (26): the lists overflow and every
  // search crawls through crowded cells
  double spacing = INFINITY;
  for (int a = 0; a < 3; a++) spacing = fmin(spacing, d->block_size[a] / d->count[a]);
  if (2 * d->radius + d->skin > 2 * spacing)
    return tx_check_fail("voxel tissue: 2 radius + skin = %g m, must be at most twice the lattice spacing, %g m",
                         2 * d->radius + d->skin, spacing);
  return 0;
}

// ---------------------------------------------------------------------------
// Know-Your-Neighbour (section 3): uniform grid, counting sort, 27 cells

static int cell_coord(const tx_voxel_tissue* t, double x, int a) {
  double h = t->cell_size[a];
  double f = (x - t->grid_lo[a]) / h;
  // out of the grid (or not finite): clamp to the border cells; clamping
  // never separates two points closer than a cell, so no pair is lost
  if (!(f >= 0)) return 0;
  if (f >= t->grid_dims[a]) return t->grid_dims[a] - 1;
  return (int)f;
}

int tx_voxel_tissue_cell_of_point(const tx_voxel_tissue* t, const double p[3]) {
  return (cell_coord(t, p[2], 2) * t->grid_dims[1] + cell_coord(t, p[1], 1)) * t->grid_dims[0] + cell_coord(t, p[0], 0);
}

// the grid is a linked list per cell, so that one voxel can change cells alone
static void cell_unlink(tx_voxel_tissue* t, int i) {
  int c = t->cell_of[i], nx = t->cell_next[i], pv = t->cell_prev[i];
  if (pv >= 0) t->cell_next[pv] = nx;
  else t->cell_head[c] = nx;
  if (nx >= 0) t->cell_prev[nx] = pv;
}

static void cell_link(tx_voxel_tissue* t, int i, int c) {
  t->cell_of[i] = c;
  t->cell_prev[i] = -1;
  t->cell_next[i] = t->cell_head[c];
  if (t->cell_head[c] >= 0) t->cell_prev[t->cell_head[c]] = i;
  t->cell_head[c] = i;
}

static void list_add(tx_voxel_tissue* t, int i, int j) {
  const int cap = t->def.max_neighbours;
  if (t->nbr_count[i] < cap) t->nbr[(size_t)i * (size_t)cap + (size_t)t->nbr_count[i]++] = j;
  else t->overflow++;
}

static void list_remove(tx_voxel_tissue* t, int i, int j) {
  int32_t* list = t->nbr + (size_t)i * (size_t)t->def.max_neighbours;
  for (int k = 0; k < t->nbr_count[i]; k++)
    if (list[k] == j) {
      list[k] = list[--t->nbr_count[i]];
      return;
    }
}

// the voxels within reach of voxel i in the 27 cells around its own; with
// add_both each found pair goes on both lists (i's lists are empty then),
// otherwise only pairs j > i, the other half coming from j's own search
static void search(tx_voxel_tissue* t, int i, bool add_both) {
  const int gx = t->grid_dims[0], gy = t->grid_dims[1], gz = t->grid_dims[2];
  const double reach2 = t->reach * t->reach;
  const double* pi = t->pos + 3 * i;
  int c = t->cell_of[i];
  int cx = c % gx, cy = (c / gx) % gy, cz = c / (gx * gy);
  for (int z = cz - 1; z <= cz + 1; z++) {
    if (z < 0 || z >= gz) continue;
    for (int y = cy - 1; y <= cy + 1; y++) {
      if (y < 0 || y >= gy) continue;
      for (int x = cx - 1; x <= cx + 1; x++) {
        if (x < 0 || x >= gx) continue;
        for (int j = t->cell_head[(z * gy + y) * gx + x]; j >= 0; j = t->cell_next[j]) {
          if (j == i || (!add_both && j < i)) continue;
          const double* pj = t->pos + 3 * j;
          double dx = pj[0] - pi[0], dy = pj[1] - pi[1], dz = pj[2] - pi[2];
          if (dx * dx + dy * dy + dz * dz >= reach2) continue;
          list_add(t, i, j);
          list_add(t, j, i);
        }
      }
    }
  }
}

void tx_voxel_tissue_refresh_neighbours(tx_voxel_tissue* t) {
  const int n = t->n;
  const int cells = t->grid_dims[0] * t->grid_dims[1] * t->grid_dims[2];
  // bin every voxel afresh, then each pair once
  for (int c = 0; c < cells; c++) t->cell_head[c] = -1;
  for (int i = n - 1; i >= 0; i--) cell_link(t, i, tx_voxel_tissue_cell_of_point(t, t->pos + 3 * i));
  memset(t->nbr_count, 0, sizeof *t->nbr_count * (size_t)n);
  for (int i = 0; i < n; i++) search(t, i, false);
  memcpy(t->pos_built, t->pos, sizeof *t->pos * 3 * (size_t)n);
  t->rebuilds++;
}

void tx_voxel_tissue_refresh_voxel(tx_voxel_tissue* t, int i) {
  // forget i on its neighbours' lists, move it to its cell, search again
  const int32_t* list = t->nbr + (size_t)i * (size_t)t->def.max_neighbours;
  for (int k = 0; k < t->nbr_count[i]; k++) list_remove(t, list[k], i);
  t->nbr_count[i] = 0;
  int c = tx_voxel_tissue_cell_of_point(t, t->pos + 3 * i);
  if (c != t->cell_of[i]) {
    cell_unlink(t, i);
    cell_link(t, i, c);
  }
  search(t, i, true);
  memcpy(t->pos_built + 3 * i, t->pos + 3 * i, 3 * sizeof *t->pos);
  t->refreshes++;
}

// ---------------------------------------------------------------------------
// init, fini, reset

static void free_all(tx_voxel_tissue* t) {
  free(t->id), free(t->mass), free(t->elasticity), free(t->radius0), free(t->radius), free(t->damage);
  free(t->pos0), free(t->pos), free(t->vel0), free(t->vel);
  free(t->nbr), free(t->nbr_count), free(t->pos_built);
  free(t->cell_head), free(t->cell_next), free(t->cell_prev), free(t->cell_of);
  free(t->damaged), free(t->is_damaged), free(t->awake_list), free(t->is_awake);
}

bool tx_voxel_tissue_init(tx_voxel_tissue* out, const tx_voxel_tissue_def* def) {
  if (tx_voxel_tissue_def_check(def)) return false;
  tx_voxel_tissue t;
  memset(&t, 0, sizeof t);
  t.def = *def;
  const int n = def->count[0] * def->count[1] * def->count[2];
  t.n = n;
  const size_t un = (size_t)n;
  // the grid covers the block and half a block more on each side (voxels
  // pushed further are clamped into the border cells); cells are at least
  // the reach wide and their number is bounded, so a tiny radius costs
  // bigger cells, not memory
  t.reach = 2 * def->radius + def->skin;
  // a voxel is filed under the cell of where its list was built, up to a
  // quarter of the skin away, so cells are that much wider than the reach
  const double edge = t.reach + 0.25 * def->skin;
  long long cells = 1;
  for (int a = 0; a < 3; a++) {
    t.grid_lo[a] = def->origin[a] - 0.5 * def->block_size[a] - edge;
    double extent = 2 * def->block_size[a] + 2 * edge;
    double dims = floor(extent / edge);
    t.grid_dims[a] = dims < 1 ? 1 : dims > 4096 ? 4096 : (int)dims;
  }
  const long long max_cells = 8LL * n + 4096;
  for (;;) {
    cells = (long long)t.grid_dims[0] * t.grid_dims[1] * t.grid_dims[2];
    if (cells <= max_cells) break;
    int a = t.grid_dims[0] >= t.grid_dims[1] ? 0 : 1;
    if (t.grid_dims[2] > t.grid_dims[a]) a = 2;
    t.grid_dims[a] = (t.grid_dims[a] + 1) / 2;
  }
  for (int a = 0; a < 3; a++) t.cell_size[a] = (2 * def->block_size[a] + 2 * edge) / t.grid_dims[a];

  const size_t cap = (size_t)def->max_neighbours;
  t.id = calloc(un, sizeof *t.id);
  t.mass = calloc(un, sizeof *t.mass);
  t.elasticity = calloc(un, sizeof *t.elasticity);
  t.radius0 = calloc(un, sizeof *t.radius0);
  t.radius = calloc(un, sizeof *t.radius);
  t.damage = calloc(un, sizeof *t.damage);
  t.pos0 = calloc(3 * un, sizeof *t.pos0);
  t.pos = calloc(3 * un, sizeof *t.pos);
  t.vel0 = calloc(3 * un, sizeof *t.vel0);
  t.vel = calloc(3 * un, sizeof *t.vel);
  t.nbr = calloc(un * cap, sizeof *t.nbr);
  t.nbr_count = calloc(un, sizeof *t.nbr_count);
  t.pos_built = calloc(3 * un, sizeof *t.pos_built);
  t.cell_head = calloc((size_t)cells, sizeof *t.cell_head);
  t.cell_next = calloc(un, sizeof *t.cell_next);
  t.cell_prev = calloc(un, sizeof *t.cell_prev);
  t.cell_of = calloc(un, sizeof *t.cell_of);
  t.damaged = calloc(un, sizeof *t.damaged);
  t.is_damaged = calloc(un, sizeof *t.is_damaged);
  t.awake_list = calloc(un, sizeof *t.awake_list);
  t.is_awake = calloc(un, sizeof *t.is_awake);
  if (!t.id || !t.mass || !t.elasticity || !t.radius0 || !t.radius || !t.damage || !t.pos0 || !t.pos || !t.vel0 ||
      !t.vel || !t.nbr || !t.nbr_count || !t.pos_built || !t.cell_head || !t.cell_next || !t.cell_prev || !t.cell_of ||
      !t.damaged || !t.is_damaged || !t.awake_list || !t.is_awake) {
    free_all(&t);
    tx_set_error("voxel tissue: out of memory for %d voxels", n);
    return false;
  }
  // voxel centres at the middle of the lattice cells of the block
  int i = 0;
  for (int z = 0; z < def->count[2]; z++)
    for (int y = 0; y < def->count[1]; y++)
      for (int x = 0; x < def->count[0]; x++, i++) {
        const int c[3] = {x, y, z};
        for (int a = 0; a < 3; a++)
          t.pos0[3 * i + a] = def->origin[a] + (c[a] + 0.5) * def->block_size[a] / def->count[a];
        t.id[i] = i;
        t.mass[i] = def->mass;
        t.elasticity[i] = def->elasticity;
        t.radius0[i] = def->radius;
      }
  *out = t;
  tx_voxel_tissue_reset(out);
  return true;
}

void tx_voxel_tissue_fini(tx_voxel_tissue* t) {
  free_all(t);
  memset(t, 0, sizeof *t);
}

void tx_voxel_tissue_reset(tx_voxel_tissue* t) {
  const size_t un = (size_t)t->n;
  memcpy(t->pos, t->pos0, sizeof *t->pos * 3 * un);
  memcpy(t->vel, t->vel0, sizeof *t->vel * 3 * un);
  memcpy(t->radius, t->radius0, sizeof *t->radius * un);
  memset(t->damage, 0, sizeof *t->damage * un);
  memset(t->is_damaged, 0, sizeof *t->is_damaged * un);
  t->n_damaged = 0;
  memset(t->is_awake, 0, sizeof *t->is_awake * un);
  t->n_awake = 0;
  t->phi_dt = 0;
  t->steps = t->rebuilds = t->refreshes = t->pairs = t->culled = t->contacts = t->overflow = t->faults = 0;
  tx_voxel_tissue_refresh_neighbours(t);
}

// ---------------------------------------------------------------------------
// damage (section 5): a needle contact shrinks the radius; it recovers over Delta t

static void set_radius_from_damage(tx_voxel_tissue* t, int i) {
  t->radius[i] = t->radius0[i] * (1 - t->def.damage_shrink * t->damage[i]);
}

bool tx_voxel_tissue_damage(tx_voxel_tissue* t, int id, double amount) {
  if (id < 0 || id >= t->n) {
    tx_set_error("voxel tissue: damage to voxel %d, must be in [0, %d)", id, t->n);
    return false;
  }
  if (!(isfinite(amount) && amount > 0 && amount <= 1)) {
    tx_set_error("voxel tissue: damage amount = %g, must be finite and in (0, 1]", amount);
    return false;
  }
  double d = t->damage[id] + amount;
  t->damage[id] = d > 1 ? 1 : d;
  set_radius_from_damage(t, id);
  if (!t->is_damaged[id]) {
    t->is_damaged[id] = 1;
    t->damaged[t->n_damaged++] = id;
  }
  return true;
}

// linear recovery: full damage heals in recovery_time
static void recover(tx_voxel_tissue* t, double dt) {
  const double heal = dt / t->def.recovery_time;
  for (int k = 0; k < t->n_damaged;) {
    int i = t->damaged[k];
    double d = t->damage[i] - heal;
    if (d > 0) {
      t->damage[i] = d;
      set_radius_from_damage(t, i);
      k++;
    } else {
      t->damage[i] = 0;
      t->radius[i] = t->radius0[i];
      t->is_damaged[i] = 0;
      t->damaged[k] = t->damaged[--t->n_damaged];
    }
  }
}

void tx_voxel_tissue_wake(tx_voxel_tissue* t, int i) {
  if (t->is_awake[i]) return;
  t->is_awake[i] = 1;
  t->awake_list[t->n_awake++] = i;
}

// ---------------------------------------------------------------------------
// collision (section 4)

bool tx_voxel_vieta_may_collide(const double p[3], const double v[3], double r) {
  // eq. 3 with a = v.v, b = 2 p.v, c = p.p - r^2; eq. 4: t1 t2 = c/a and
  // t1 + t2 = -b/a, so with a > 0 both roots are positive only when c > 0
  // and b < 0 (b < 0 implies a > 0)
  double b = 2 * (p[0] * v[0] + p[1] * v[1] + p[2] * v[2]);
  double c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - r * r;
  return c > 0 && b < 0;
}

// smaller root of a t^2 + b t + c with c > 0, b < 0, in the form that never
// subtracts nearly equal numbers; false when the roots are not real and
// distinct (a miss, or a graze with t1 = t2, which the paper neglects)
static bool first_root(double a, double b, double c, double* t1) {
  double disc = b * b - 4 * a * c;
  if (!(disc > 0)) return false;
  double q = 0.5 * (-b + sqrt(disc));
  *t1 = c / q;
  return true;
}

bool tx_voxel_time_of_impact(const double p[3], const double v[3], double r, double dt, double* t) {
  if (!tx_voxel_vieta_may_collide(p, v, r) || !(dt >= 0)) return false;
  double a = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  double b = 2 * (p[0] * v[0] + p[1] * v[1] + p[2] * v[2]);
  double c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - r * r;
  double t1;
  if (!first_root(a, b, c, &t1) || !(t1 <= dt)) return false;
  *t = t1;
  return true;
}

// eq. 5 at time th into the frame. The pair's normal is taken where the
// centres are at th; velocities change at th, so each position is shifted by
// -dv th: moving at the new velocity for the whole frame then lands where
// the old velocity until th and the new one after it would.
static bool respond(tx_voxel_tissue* t, int i, int j, const double p[3], const double v[3], double th) {
  double nx = p[0] + v[0] * th, ny = p[1] + v[1] * th, nz = p[2] + v[2] * th;
  double len = sqrt(nx * nx + ny * ny + nz * nz);
  if (!(len > 0)) return false; // coincident centres have no normal
  nx /= len, ny /= len, nz /= len;
  // c of eq. 5: the closing speed along N, as eq. 8 defines it
  double close = -(v[0] * nx + v[1] * ny + v[2] * nz);
  if (!(close > 0)) return false;
  double mi = t->mass[i], mj = t->mass[j];
  double e = 0.5 * (t->elasticity[i] + t->elasticity[j]);
  double k = close * (e + 1) / (mi + mj);
  double* vi = t->vel + 3 * i;
  double* vj = t->vel + 3 * j;
  double* xi = t->pos + 3 * i;
  double* xj = t->pos + 3 * j;
  const double n3[3] = {nx, ny, nz};
  for (int a = 0; a < 3; a++) {
    double dvi = -k * mj * n3[a], dvj = k * mi * n3[a];
    vi[a] += dvi, vj[a] += dvj;
    xi[a] -= dvi * th, xj[a] -= dvj * th;
  }
  return true;
}

static inline bool still(const double v[3]) { return v[0] == 0 && v[1] == 0 && v[2] == 0; }

static void collide(tx_voxel_tissue* t, double dt) {
  const int cap = t->def.max_neighbours;
  uint64_t pairs = 0, culled = 0, contacts = 0;
  const double* vel = t->vel;
  // voxels woken by a contact join the end of the list and are seen in this pass
  for (int w = 0; w < t->n_awake; w++) {
    const int i = t->awake_list[w];
    // a pair of voxels at rest cannot meet: a resting voxel's pairs are
    // taken from its moving neighbours' side, so a block mostly at rest
    // costs one test per voxel
    if (still(vel + 3 * i)) continue;
    const int32_t* list = t->nbr + (size_t)i * (size_t)cap;
    const int m = t->nbr_count[i];
    for (int k = 0; k < m; k++) {
      int j = list[k];
      if (j < i && !still(vel + 3 * j)) continue; // each pair once
      pairs++;
      const double* pi = t->pos + 3 * i;
      const double* pj = t->pos + 3 * j;
      const double* vi = t->vel + 3 * i;
      const double* vj = t->vel + 3 * j;
      // relative motion of eq. 2
      double p[3] = {pj[0] - pi[0], pj[1] - pi[1], pj[2] - pi[2]};
      double v[3] = {vj[0] - vi[0], vj[1] - vi[1], vj[2] - vi[2]};
      double r = t->radius[i] + t->radius[j];
      double b = 2 * (p[0] * v[0] + p[1] * v[1] + p[2] * v[2]);
      double c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - r * r;
      double th;
      if (!(b < 0)) {
        culled++; // t1 + t2 <= 0 (eq. 4): receding or keeping their distance
        continue;
      }
      if (c > 0) {
        // apart and closing: both roots positive; the first must be in the frame
        double a = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (!first_root(a, b, c, &th) || th > dt) continue;
      } else {
        // touching or overlapping and closing: t1 <= 0 < t2, which eq. 4
        // would cull; answered now so that voxels pushed into each other
        // do not pass through
        th = 0;
      }
      if (respond(t, i, j, p, v, th)) {
        contacts++;
        tx_voxel_tissue_wake(t, j);
      }
    }
  }
  t->pairs += pairs, t->culled += culled, t->contacts += contacts;
}

// ---------------------------------------------------------------------------
// spring-damper (eqs. 6, 7): m x'' = -k_s x - k_d x' per axis, x from rest

// exact map of (x, v) over dt: exp(A dt) with A = (0, 1; -w2, -c). For a 2 x 2
// matrix exp(A dt) = e^(mu dt) (C I + S (A - mu I)), mu = -c/2, q^2 = mu^2 - w2;
// the exponentials are combined so that no overflow meets an underflow
static void transition(double m, double ks, double kd, double dt, double phi[4]) {
  double w2 = ks / m, c = kd / m, mu = -0.5 * c, q2 = mu * mu - w2;
  double C, S; // e^(mu dt) cosh(q dt) and e^(mu dt) sinh(q dt) / q, or their trigonometric forms
  if (q2 > 0) {
    double q = sqrt(q2);
    double lo = exp((mu - q) * dt), hi = exp((mu + q) * dt);
    C = 0.5 * (hi + lo);
    S = 2 * q * dt < 1 ? lo * expm1(2 * q * dt) / (2 * q) : (hi - lo) / (2 * q);
  } else if (q2 < 0) {
    double w = sqrt(-q2), em = exp(mu * dt);
    C = em * cos(w * dt);
    S = em * sin(w * dt) / w;
  } else {
    double em = exp(mu * dt);
    C = em;
    S = em * dt;
  }
  phi[0] = C - mu * S;
  phi[1] = S;
  phi[2] = -w2 * S;
  phi[3] = C + mu * S;
}

// puts voxel i back at rest: the recovery from a numerical fault
static void restore(tx_voxel_tissue* t, int i) {
  for (int a = 0; a < 3; a++) t->pos[3 * i + a] = t->pos0[3 * i + a], t->vel[3 * i + a] = 0;
  t->faults++;
}

static void spring_damper(tx_voxel_tissue* t, double dt) {
  const tx_voxel_tissue_def* d = &t->def;
  if (t->phi_dt != dt) {
    transition(d->mass, d->spring, d->damper, dt, t->phi);
    t->phi_dt = dt;
  }
  for (int w = 0; w < t->n_awake;) {
    const int i = t->awake_list[w];
    double* p = t->pos + 3 * i;
    double* v = t->vel + 3 * i;
    const double* p0 = t->pos0 + 3 * i;
    double x[3] = {p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]};
    // a voxel back within a millionth of its radius of rest, and too slow to
    // leave that in a substep, is put to rest and sleeps (the paper's section
    // 3: only voxels displaced lately need the spring-damper)
    double eps = 1e-6 * t->radius0[i];
    if (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] < eps * eps &&
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * dt * dt < eps * eps) {
      memcpy(p, p0, 3 * sizeof *p);
      memset(v, 0, 3 * sizeof *v);
      t->is_awake[i] = 0;
      t->awake_list[w] = t->awake_list[--t->n_awake];
      continue;
    }
    w++;
    double own[4];
    const double* ph = t->phi;
    if (t->mass[i] != d->mass) { // a voxel given its own mass
      transition(t->mass[i], d->spring, d->damper, dt, own);
      ph = own;
    }
    for (int a = 0; a < 3; a++) {
      double xn = ph[0] * x[a] + ph[1] * v[a];
      double vn = ph[2] * x[a] + ph[3] * v[a];
      p[a] = p0[a] + xn;
      // a decaying velocity would end in subnormals, which cost a hundred
      // times more; far below any motion that matters it is zero
      v[a] = fabs(vn) < 1e-100 ? 0 : vn;
    }
    if (!isfinite(p[0] + p[1] + p[2] + v[0] + v[1] + v[2])) restore(t, i);
  }
}

// ---------------------------------------------------------------------------
// step

// Know-Your-Neighbour by each voxel: one whose drift since its own list was
// built, plus its travel along its velocity over a frame of h, may exceed a
// quarter of the skin searches again (bounded without a square root by
// (a + b)^2 <= 2 (a^2 + b^2)). A pair off the lists was at least the reach
// apart when the later of its two voxels searched; since then one has moved
// at most a quarter of the skin and the other at most half, so they are
// still more than 2 radius apart, and no contact is missed.
static void refresh_moved(tx_voxel_tissue* t, double h) {
  const double quarter = 0.25 * t->def.skin, lim = quarter * quarter;
  for (int w = 0; w < t->n_awake; w++) {
    const int i = t->awake_list[w];
    const double* p = t->pos + 3 * i;
    const double* b = t->pos_built + 3 * i;
    const double* v = t->vel + 3 * i;
    double dx = p[0] - b[0], dy = p[1] - b[1], dz = p[2] - b[2];
    double drift = dx * dx + dy * dy + dz * dz;
    double travel = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * h * h;
    if (2 * (drift + travel) > lim) tx_voxel_tissue_refresh_voxel(t, i);
  }
}

// puts right what a caller may have written into awake voxels between steps
// (non-finite positions or velocities, bad masses) and returns the largest
// speed squared; sleeping voxels are at rest and cost nothing
static double scan(tx_voxel_tissue* t) {
  double vmax2 = 0;
  for (int w = 0; w < t->n_awake; w++) {
    const int i = t->awake_list[w];
    const double* p = t->pos + 3 * i;
    const double* v = t->vel + 3 * i;
    if (!isfinite(p[0] + p[1] + p[2] + v[0] + v[1] + v[2])) restore(t, i);
    if (!(isfinite(t->mass[i]) && t->mass[i] > 0)) t->mass[i] = t->def.mass, t->faults++;
    double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (v2 > vmax2) vmax2 = v2;
  }
  return vmax2;
}

bool tx_voxel_tissue_step(tx_voxel_tissue* t, double dt) { return tx_voxel_tissue_step_with(t, dt, 1, NULL, NULL); }

bool tx_voxel_tissue_step_with(tx_voxel_tissue* t, double dt, int min_substeps, tx_voxel_substep_fn fn, void* user) {
  if (!(isfinite(dt) && dt > 0 && dt <= 1)) {
    tx_set_error("voxel tissue: step dt = %g s, must be finite and in (0, 1]", dt);
    return false;
  }
  // a voxel that would cross more than an eighth of the skin in one frame
  // splits it, so that the lists stay valid without growing their reach
  double travel = sqrt(scan(t)) * dt, quarter = 0.125 * t->def.skin;
  int sub = 1;
  if (travel > quarter) {
    double s = ceil(travel / quarter);
    sub = s > TX_VOXEL_MAX_SUBSTEPS ? TX_VOXEL_MAX_SUBSTEPS : (int)s;
  }
  if (min_substeps > sub) sub = min_substeps > TX_VOXEL_MAX_SUBSTEPS ? TX_VOXEL_MAX_SUBSTEPS : min_substeps;
  t->substeps = sub;
  t->pairs = t->culled = t->contacts = 0;
  const double h = dt / sub;
  for (int s = 0; s < sub; s++) {
    // a tool acts first, so that its pushes take part in this substep's contacts
    if (fn) fn(t, s, sub, h, user);
    // know your neighbour: a voxel searches again only when it could miss a contact
    refresh_moved(t, h);
    // contacts on the velocities at the start of the frame, then the springs
    collide(t, h);
    spring_damper(t, h);
  }
  if (t->n_damaged) recover(t, dt);
  t->steps++;
  return true;
}

double tx_voxel_tissue_energy(const tx_voxel_tissue* t) {
  const double ks = t->def.spring;
  double e = 0; // a sleeping voxel is at rest: no energy
  for (int w = 0; w < t->n_awake; w++) {
    const int i = t->awake_list[w];
    const double* p = t->pos + 3 * i;
    const double* p0 = t->pos0 + 3 * i;
    const double* v = t->vel + 3 * i;
    double x0 = p[0] - p0[0], x1 = p[1] - p0[1], x2 = p[2] - p0[2];
    e += 0.5 * (t->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + ks * (x0 * x0 + x1 * x1 + x2 * x2));
  }
  return e;
}
