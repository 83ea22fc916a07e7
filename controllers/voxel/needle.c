// The needle in the voxel tissue: contacts through the tissue's grid, eq. 5
// against an infinite mass, Coulomb friction on the shaft, cutting at the
// tip, and eq. 9's three force terms.
#include "needle.h"

#include "../range_check.h"
#include "../rotation.h"

#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// ISO 9626 nominal outer diameters, mm, gauges 10 to 34
static const double gauge_mm[25] = {3.404, 3.048, 2.769, 2.413, 2.108, 1.829, 1.651, 1.473, 1.270,
                                    1.067, 0.908, 0.819, 0.718, 0.641, 0.566, 0.515, 0.464, 0.413,
                                    0.362, 0.337, 0.312, 0.261, 0.235, 0.210, 0.159};

double tx_needle_gauge_diameter(int gauge) { return gauge >= 10 && gauge <= 34 ? gauge_mm[gauge - 10] * 1e-3 : 0; }

static const char* const tip_names[3] = {"conical", "bevel", "blunt"};

bool tx_needle_tip_parse(const char* name, tx_needle_tip* out) {
  for (int i = 0; i < 3; i++)
    if (name && strcmp(name, tip_names[i]) == 0) return *out = (tx_needle_tip)i, true;
  return false;
}

const char* tx_needle_tip_name(tx_needle_tip tip) { return (unsigned)tip < 3 ? tip_names[tip] : "?"; }

tx_voxel_needle_def tx_voxel_needle_def_default(void) {
  return (tx_voxel_needle_def){
      .gauge = 18,
      .tip = TX_NEEDLE_CONICAL,
      .tip_angle_deg = 15,
      .length = 0.04,
      .friction = 0.3,
      .rupture_force = 0.2,
      .cutting_force = 0.1,
      .load_time = 0.005,
      .axis = {0, -1, 0},
      .side = {1, 0, 0},
  };
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

int tx_voxel_needle_def_check(const tx_voxel_needle_def* d) {
  if (tx_check_count("needle", "gauge", d->gauge, 10, 34)) return -1;
  if ((unsigned)d->tip > TX_NEEDLE_BLUNT) return tx_check_fail("needle: tip = %d, must be conical, bevel or blunt", (int)d->tip);
  if (tx_check_range("needle", "tip_angle_deg", d->tip_angle_deg, 0, true, 90, true, "degrees")) return -1;
  if (tx_check_range("needle", "length", d->length, 0, true, 1, false, "m")) return -1;
  if (tx_check_range("needle", "friction", d->friction, 0, false, 10, false, "(Coulomb coefficient)")) return -1;
  if (tx_check_range("needle", "rupture_force", d->rupture_force, 0, true, 1e4, false, "N")) return -1;
  if (tx_check_range("needle", "cutting_force", d->cutting_force, 0, true, 1e4, false, "N")) return -1;
  if (tx_check_range("needle", "load_time", d->load_time, 0, true, 1, false, "s")) return -1;
  for (int a = 0; a < 3; a++)
    if (!isfinite(d->axis[a]) || !isfinite(d->side[a])) return tx_check_fail("needle: axis and side must be finite");
  double la = sqrt(dot(d->axis, d->axis)), ls = sqrt(dot(d->side, d->side));
  if (fabs(la - 1) > 1e-6 || fabs(ls - 1) > 1e-6) return tx_check_fail("needle: axis and side must be unit vectors");
  if (fabs(dot(d->axis, d->side)) > 1e-6) return tx_check_fail("needle: side must be normal to axis");
  return 0;
}

bool tx_voxel_needle_init(tx_voxel_needle* out, const tx_voxel_needle_def* def, const tx_voxel_tissue* t) {
  if (tx_voxel_needle_def_check(def)) return false;
  tx_voxel_needle n;
  memset(&n, 0, sizeof n);
  n.def = *def;
  n.radius = 0.5 * tx_needle_gauge_diameter(def->gauge);
  n.cut_scale = def->tip == TX_NEEDLE_BLUNT ? 1 : sin(def->tip_angle_deg * M_PI / 180);
  memcpy(n.dir, def->axis, sizeof n.dir); // until a pose turns it
  memcpy(n.side, def->side, sizeof n.side);
  size_t un = (size_t)t->n;
  n.cut = calloc(un, sizeof *n.cut);
  n.cut_list = calloc(un, sizeof *n.cut_list);
  n.load = calloc(un, sizeof *n.load);
  n.load_t = calloc(un, sizeof *n.load_t);
  if (!n.cut || !n.cut_list || !n.load || !n.load_t) {
    free(n.cut), free(n.cut_list), free(n.load), free(n.load_t);
    return tx_set_error("needle: out of memory for %d voxels", t->n), false;
  }
  *out = n;
  tx_voxel_needle_reset(out);
  return true;
}

void tx_voxel_needle_fini(tx_voxel_needle* n) {
  free(n->cut), free(n->cut_list), free(n->load), free(n->load_t);
  memset(n, 0, sizeof *n);
}

void tx_voxel_needle_reset(tx_voxel_needle* n) {
  for (int k = 0; k < n->n_cut; k++) n->cut[n->cut_list[k]] = 0;
  n->n_cut = 0;
  n->placed = false;
  n->time = 0;
  n->energy_in = 0;
  n->punctured = false;
  n->cuts = 0;
  n->contacts = 0;
  n->k_axial = 0;
  memset(n->force, 0, sizeof n->force);
  memset(n->stiffness, 0, sizeof n->stiffness);
  memset(n->friction, 0, sizeof n->friction);
  memset(n->cutting, 0, sizeof n->cutting);
}

// ---------------------------------------------------------------------------
// one substep of contacts

typedef struct frame {
  tx_voxel_needle* n;
  double imp_stiff[3], imp_fric[3], imp_cut[3]; // N s, on the needle over the frame
  double k_axial;                              // N/m, of the last substep
  int contacts;
} frame;

static double voxel_energy(const tx_voxel_tissue* t, int i) {
  const double* p = t->pos + 3 * i;
  const double* p0 = t->pos0 + 3 * i;
  const double* v = t->vel + 3 * i;
  double x0 = p[0] - p0[0], x1 = p[1] - p0[1], x2 = p[2] - p0[2];
  return 0.5 * (t->mass[i] * dot(v, v) + t->def.spring * (x0 * x0 + x1 * x1 + x2 * x2));
}

static void cut_voxel(tx_voxel_needle* n, tx_voxel_tissue* t, int i) {
  tx_voxel_tissue_damage(t, i, 1.0);
  if (!n->cut[i]) {
    n->cut[i] = 1;
    n->cut_list[n->n_cut++] = i;
  }
  n->cuts++;
  n->punctured = true;
}

enum { SHAFT, TIP };

// voxel i against the needle with its tip at T moving at V
static void touch(frame* f, tx_voxel_tissue* t, int i, const double T[3]) {
  tx_voxel_needle* n = f->n;
  const double* a = n->dir;
  double* p = t->pos + 3 * i;
  double* v = t->vel + 3 * i;
  const double R = n->radius, r = t->radius[i], L = n->def.length;
  double d[3] = {p[0] - T[0], p[1] - T[1], p[2] - T[2]};
  double s = dot(d, a);
  if (s < -L - r || s > r) return;
  double q[3] = {d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]};
  double rho = sqrt(dot(q, q));
  if (rho >= R + r) return;
  // the outward radial direction; a voxel on the axis is parted toward a
  // direction of its own (golden angle by id), so that the block opens evenly
  double qh[3];
  if (rho > 1e-9 * R) {
    for (int k = 0; k < 3; k++) qh[k] = q[k] / rho;
  } else {
    double ang = 2.399963229728653 * i, c = cos(ang), sn = sin(ang);
    double w[3] = {a[1] * n->side[2] - a[2] * n->side[1], a[2] * n->side[0] - a[0] * n->side[2],
                   a[0] * n->side[1] - a[1] * n->side[0]};
    for (int k = 0; k < 3; k++) qh[k] = c * n->side[k] + sn * w[k];
  }
  // contact normal (out of the needle) and depth
  double nrm[3], pen;
  int kind = SHAFT;
  if (n->cut[i]) {
    // a cut voxel parts around the needle, in front of the tip as beside it
    pen = R + r - rho;
    memcpy(nrm, qh, sizeof nrm);
  } else if (s >= 0) {
    kind = TIP;
    if (rho <= R) {
      pen = r - s;
      memcpy(nrm, a, sizeof nrm);
    } else { // the rim of the tip
      double e2 = rho - R, dist = sqrt(s * s + e2 * e2);
      pen = r - dist;
      if (!(dist > 0)) return;
      for (int k = 0; k < 3; k++) nrm[k] = (s * a[k] + e2 * qh[k]) / dist;
    }
  } else if (s < -L) { // behind the hub: its end face
    return;
  } else if (rho >= R || R - rho < -s) {
    pen = R + r - rho; // beside the shaft, or nearer its side than its tip
    memcpy(nrm, qh, sizeof nrm);
  } else {
    kind = TIP; // inside, nearer the tip face
    pen = r - s;
    memcpy(nrm, a, sizeof nrm);
  }
  if (!(pen > 0)) return;
  // a bevel pushes what its face meets along the face's normal
  if (kind == TIP && n->def.tip == TX_NEEDLE_BEVEL && nrm[0] == a[0] && nrm[1] == a[1] && nrm[2] == a[2]) {
    double b = n->def.tip_angle_deg * M_PI / 180;
    for (int k = 0; k < 3; k++) nrm[k] = sin(b) * a[k] + cos(b) * n->side[k];
  }
  double e_before = voxel_energy(t, i);
  const double m = t->mass[i], e = t->elasticity[i], mu = n->def.friction;
  const double* V = n->vel;
  // out of the needle, then eq. 5 with the needle's infinite mass
  for (int k = 0; k < 3; k++) p[k] += pen * nrm[k];
  double vn = dot(v, nrm), Vn = dot(V, nrm), jn = 0, jt = 0, wh[3] = {0, 0, 0};
  if (vn < Vn) {
    double dv = (1 + e) * (Vn - vn);
    for (int k = 0; k < 3; k++) v[k] += dv * nrm[k];
    jn = m * dv;
    // Coulomb friction against the sliding, bounded by mu times the normal impulse
    double rel[3] = {v[0] - V[0], v[1] - V[1], v[2] - V[2]};
    double rn = dot(rel, nrm);
    double w[3] = {rel[0] - rn * nrm[0], rel[1] - rn * nrm[1], rel[2] - rn * nrm[2]};
    double wl = sqrt(dot(w, w));
    if (wl > 0 && mu > 0) {
      jt = fmin(m * wl, mu * jn);
      for (int k = 0; k < 3; k++) wh[k] = w[k] / wl, v[k] -= jt / m * wh[k];
    }
  }
  tx_voxel_tissue_wake(t, i);
  n->energy_in += voxel_energy(t, i) - e_before;
  f->contacts++;
  // the needle gets the opposite of what the voxel got
  double* into = kind == TIP && n->punctured ? f->imp_cut : f->imp_stiff;
  for (int k = 0; k < 3; k++) {
    into[k] -= jn * nrm[k];
    f->imp_fric[k] += jt * wh[k];
  }
  if (kind != TIP) return;
  f->k_axial += t->def.spring;
  // the tip's load on this voxel, averaged over load_time, against the cutting load
  double age = n->time - n->load_t[i];
  n->load[i] = n->load[i] * exp(-age / n->def.load_time) + jn;
  n->load_t[i] = n->time;
  // the first cut of an insertion (puncture) takes the rupture force, those
  // after it (the crack running on) the smaller cutting force
  double limit = n->punctured ? n->def.cutting_force : n->def.rupture_force;
  if (n->load[i] / n->def.load_time >= limit * n->cut_scale) {
    cut_voxel(n, t, i);
    n->load[i] = 0;
  }
}

// the voxels in the grid cells within reach of the needle
static void substep(tx_voxel_tissue* t, int s, int ns, double h, void* user) {
  frame* f = user;
  tx_voxel_needle* n = f->n;
  n->time += h;
  double u = (double)(s + 1) / ns, T[3];
  for (int k = 0; k < 3; k++) T[k] = n->tip0[k] + u * (n->tip1[k] - n->tip0[k]);
  f->k_axial = 0;
  // voxels drift up to half the skin from the cells they were sorted into
  const double rmax = t->def.radius, reach = n->radius + rmax + 0.25 * t->def.skin;
  const double* a = n->dir;
  double from[3], to[3]; // hub and just past the tip
  for (int k = 0; k < 3; k++) from[k] = T[k] - n->def.length * a[k], to[k] = T[k] + rmax * a[k];
  // clip the segment to the grid, widened by the reach
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 3; k++) {
    double lo = t->grid_lo[k] - reach, hi = t->grid_lo[k] + t->grid_dims[k] * t->cell_size[k] + reach;
    double dk = to[k] - from[k];
    if (fabs(dk) < 1e-300) {
      if (from[k] < lo || from[k] > hi) return;
      continue;
    }
    double ta = (lo - from[k]) / dk, tb = (hi - from[k]) / dk;
    if (ta > tb) { double x = ta; ta = tb; tb = x; }
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
  }
  if (t0 > t1) return;
  // the cells of the clipped segment's box whose centre lies within the
  // reach plus half a cell diagonal of the segment: each visited once
  double p0[3], p1[3], seg[3], seg2 = 0;
  int lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    p0[k] = from[k] + t0 * (to[k] - from[k]);
    p1[k] = from[k] + t1 * (to[k] - from[k]);
    seg[k] = p1[k] - p0[k];
    seg2 += seg[k] * seg[k];
    double fl = floor((fmin(p0[k], p1[k]) - reach - t->grid_lo[k]) / t->cell_size[k]);
    double fh = floor((fmax(p0[k], p1[k]) + reach - t->grid_lo[k]) / t->cell_size[k]);
    lo[k] = fl < 0 ? 0 : fl >= t->grid_dims[k] ? t->grid_dims[k] - 1 : (int)fl;
    hi[k] = fh < 0 ? 0 : fh >= t->grid_dims[k] ? t->grid_dims[k] - 1 : (int)fh;
  }
  const double* cs = t->cell_size;
  double half_diag = 0.5 * sqrt(cs[0] * cs[0] + cs[1] * cs[1] + cs[2] * cs[2]), lim = reach + half_diag;
  for (int z = lo[2]; z <= hi[2]; z++)
    for (int y = lo[1]; y <= hi[1]; y++)
      for (int x = lo[0]; x <= hi[0]; x++) {
        double c[3] = {t->grid_lo[0] + (x + 0.5) * cs[0], t->grid_lo[1] + (y + 0.5) * cs[1], t->grid_lo[2] + (z + 0.5) * cs[2]};
        double w[3] = {c[0] - p0[0], c[1] - p0[1], c[2] - p0[2]};
        double along = seg2 > 0 ? dot(w, seg) / seg2 : 0;
        along = along < 0 ? 0 : along > 1 ? 1 : along;
        double dx = w[0] - along * seg[0], dy = w[1] - along * seg[1], dz = w[2] - along * seg[2];
        // border cells also hold every voxel beyond the grid: always visited
        bool border = x == 0 || y == 0 || z == 0 || x == t->grid_dims[0] - 1 || y == t->grid_dims[1] - 1 ||
                      z == t->grid_dims[2] - 1;
        if (!border && dx * dx + dy * dy + dz * dz > lim * lim) continue;
        int cell = (z * t->grid_dims[1] + y) * t->grid_dims[0] + x;
        for (int i = t->cell_head[cell]; i >= 0; i = t->cell_next[i]) touch(f, t, i, T);
      }
}

bool tx_voxel_needle_step(tx_voxel_needle* n, tx_voxel_tissue* t, const double tip[3], const double quat[4], double dt) {
  double qn = sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]);
  if (!(isfinite(tip[0] + tip[1] + tip[2]) && isfinite(qn) && qn > 1e-9))
    return tx_set_error("needle: the pose is not finite"), false;
  if (!(isfinite(dt) && dt > 0 && dt <= 1)) return tx_set_error("needle: step dt = %g s, must be in (0, 1]", dt), false;
  double q[4] = {quat[0] / qn, quat[1] / qn, quat[2] / qn, quat[3] / qn};
  tx_quat_rotate(q, false, n->def.axis, n->dir);
  tx_quat_rotate(q, false, n->def.side, n->side);
  if (!n->placed) memcpy(n->tip1, tip, sizeof n->tip1), n->placed = true;
  memcpy(n->tip0, n->tip1, sizeof n->tip0);
  memcpy(n->tip1, tip, sizeof n->tip1);
  double travel = 0;
  for (int k = 0; k < 3; k++) {
    n->vel[k] = (n->tip1[k] - n->tip0[k]) / dt;
    travel += (n->tip1[k] - n->tip0[k]) * (n->tip1[k] - n->tip0[k]);
  }
  // the needle moves at most a quarter of the skin, or of a voxel, per substep
  double quarter = 0.25 * fmin(t->def.skin, t->def.radius);
  double need = ceil(sqrt(travel) / quarter);
  int min_sub = need < 1 ? 1 : need > TX_VOXEL_MAX_SUBSTEPS ? TX_VOXEL_MAX_SUBSTEPS : (int)need;
  frame f;
  memset(&f, 0, sizeof f);
  f.n = n;
  if (!tx_voxel_tissue_step_with(t, dt, min_sub, substep, &f)) return false;
  for (int k = 0; k < 3; k++) {
    n->stiffness[k] = f.imp_stiff[k] / dt;
    n->friction[k] = f.imp_fric[k] / dt;
    n->cutting[k] = f.imp_cut[k] / dt;
    n->force[k] = n->stiffness[k] + n->friction[k] + n->cutting[k];
  }
  n->k_axial = f.k_axial;
  n->contacts = f.contacts;
  if (!f.contacts) n->punctured = false; // out of the tissue: the next insertion punctures again
  // a healed voxel must be cut again
  for (int k = 0; k < n->n_cut;) {
    int i = n->cut_list[k];
    if (t->damage[i] > 0) {
      k++;
      continue;
    }
    n->cut[i] = 0;
    n->cut_list[k] = n->cut_list[--n->n_cut];
  }
  return true;
}

// distance from a point to the block's rest box, m (0 inside)
static double box_distance(const tx_voxel_tissue* t, const double p[3]) {
  double d2 = 0;
  for (int k = 0; k < 3; k++) {
    double lo = t->def.origin[k], hi = lo + t->def.block_size[k];
    double e = p[k] < lo ? lo - p[k] : p[k] > hi ? p[k] - hi : 0;
    d2 += e * e;
  }
  return sqrt(d2);
}

double tx_voxel_needle_depth(const tx_voxel_needle* n, const tx_voxel_tissue* t) {
  // where the axis line through the tip enters the rest box (slab method)
  const double* a = n->dir;
  double lo = -INFINITY, hi = INFINITY;
  for (int k = 0; k < 3; k++) {
    double b0 = t->def.origin[k], b1 = b0 + t->def.block_size[k];
    if (fabs(a[k]) < 1e-12) {
      if (n->tip1[k] < b0 || n->tip1[k] > b1) return -box_distance(t, n->tip1);
      continue;
    }
    double ta = (b0 - n->tip1[k]) / a[k], tb = (b1 - n->tip1[k]) / a[k];
    if (ta > tb) { double x = ta; ta = tb; tb = x; }
    lo = fmax(lo, ta), hi = fmin(hi, tb);
  }
  if (lo > hi || !isfinite(lo)) return -box_distance(t, n->tip1);
  return -lo; // the entry lies lo along the axis from the tip
}
