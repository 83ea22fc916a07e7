// The tool tip against the organ surfaces: nearest point, one-sided contact,
// and the local force (see organ.h).
#include "organ.h"

#include "../thread/segment.h" // tx_tri_closest_point

#include "../range_check.h"

#include <tactus/components.h>

#include <math.h>
#include <string.h>

#define STACK_MAX 128 // the depth of a median-split tree is log2(triangles)

static inline double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

tx_organ_tip_def tx_organ_tip_def_default(void) {
  return (tx_organ_tip_def){.radius = 2.5e-3, .hold = 2e-3, .depth_max = 0.02};
}

int tx_organ_tip_def_check(const tx_organ_tip_def* d) {
  if (tx_check_range("organ tip", "radius", d->radius, 0, true, 0.05, false, "m")) return -1;
  if (tx_check_range("organ tip", "hold", d->hold, 0, false, 0.05, false, "m")) return -1;
  if (tx_check_range("organ tip", "depth_max", d->depth_max, 0, true, 0.2, false, "m")) return -1;
  return 0;
}

// squared distance from c to the box
static inline double box_dist2(const tx_bvh_node* nd, const double c[3]) {
  double s = 0;
  for (int a = 0; a < 3; a++) {
    double e = c[a] < nd->lo[a] ? nd->lo[a] - c[a] : c[a] > nd->hi[a] ? c[a] - nd->hi[a] : 0;
    s += e * e;
  }
  return s;
}

bool tx_organ_nearest(const tx_tri_bvh* b, const float* x, const double c[3], double rmax, const double* facing,
                      tx_organ_near* out) {
  if (b->nnodes == 0 || !(rmax > 0)) return false;
  double best2 = rmax * rmax, best_cos = 0, best_d[3] = {0, 0, 0}, best_nf[3] = {0, 0, 0};
  bool found = false;
  // candidates within this of the best are ties: the same edge or corner seen from two triangles
  double tol = 1e-9 * best2;
  uint32_t stack[STACK_MAX];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const tx_bvh_node* nd = &b->nodes[stack[--sp]];
    if (box_dist2(nd, c) > best2 + tol) continue;
    if (nd->count == 0) {
      // the nearer child last, so it is searched first and the farther one is often pruned
      uint32_t l = (uint32_t)(nd - b->nodes) + 1, r = nd->first;
      double dl = box_dist2(&b->nodes[l], c), dr = box_dist2(&b->nodes[r], c);
      if (dl < dr) {
        uint32_t u = l;
        l = r, r = u;
        double t = dl;
        dl = dr, dr = t;
      }
      if (dl <= best2 + tol && sp < STACK_MAX) stack[sp++] = l;
      if (dr <= best2 + tol && sp < STACK_MAX) stack[sp++] = r;
      continue;
    }
    for (uint32_t i = nd->first; i < nd->first + nd->count; i++) {
      if (b->order[i] == UINT32_MAX) continue; // torn out
      const int32_t* t = b->tri + 3 * (size_t)i;
      double v[3][3];
      for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) v[k][a] = x[3 * (size_t)t[k] + a];
      double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
      double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
      double nf[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      double len = sqrt(dot(nf, nf));
      if (!(len > 0)) continue; // no area, no side
      for (int a = 0; a < 3; a++) nf[a] /= len;
      if (facing && !(dot(nf, facing) > 0)) continue;
      double q[3];
      tx_tri_closest_point(c, v[0], v[1], v[2], q, NULL);
      double d[3] = {c[0] - q[0], c[1] - q[1], c[2] - q[2]};
      double d2 = dot(d, d);
      double cs = d2 > 0 ? dot(d, nf) / sqrt(d2) : 1; // on the surface counts as outside
      bool take = !found ? d2 <= best2 : d2 < best2 - tol || (d2 <= best2 + tol && fabs(cs) > fabs(best_cos));
      if (!take) continue;
      if (!found || d2 < best2) {
        best2 = d2;
        tol = 1e-9 * best2;
      }
      found = true;
      best_cos = cs;
      memcpy(out->p, q, sizeof out->p);
      memcpy(best_d, d, sizeof best_d);
      memcpy(best_nf, nf, sizeof best_nf);
      out->tri = b->order[i];
    }
  }
  if (!found) return false;
  double dist = sqrt(dot(best_d, best_d)), sign = best_cos >= 0 ? 1 : -1;
  out->s = sign * dist;
  // p -> c is continuous across edges; on the surface itself the face's normal
  if (dist > 1e-12)
    for (int a = 0; a < 3; a++) out->n[a] = sign * best_d[a] / dist;
  else
    memcpy(out->n, best_nf, sizeof out->n);
  return true;
}

void tx_organ_side_reset(tx_organ_side* s) { memset(s, 0, sizeof *s); }

void tx_organ_tip(tx_organ_side* side, const tx_organ_tip_def* d, tx_tri_bvh* b, const float* x, const double c[3],
                  tx_organ_touch* out) {
  memset(out, 0, sizeof *out);
  const double r = d->radius;
  tx_organ_near nr;
  if (!side->on) {
    bool got = tx_organ_nearest(b, x, c, r, NULL, &nr);
    if (got && nr.s >= 0) {
      side->on = out->onset = true;
      memcpy(side->n, nr.n, sizeof side->n);
    } else if (side->has_prev) {
      // a hand faster than r per query: the move since the last one entered through a face's outer side
      double mv[3] = {c[0] - side->prev[0], c[1] - side->prev[1], c[2] - side->prev[2]}, len = sqrt(dot(mv, mv));
      tx_ray_hit h;
      if (len > 0) {
        double dir[3] = {mv[0] / len, mv[1] / len, mv[2] / len};
        if (tx_tri_bvh_ray(b, x, side->prev, dir, len, &h) && dot(h.n, dir) < 0) {
          side->on = out->onset = true;
          memcpy(side->n, h.n, sizeof side->n);
        }
      }
    }
    if (!side->on && got) out->inside = true; // within r of the surface on its inner side, not entered
  }
  if (side->on) {
    // only the faces that look the way the contact does: never out through the far side
    double range = fmax(r + d->hold, d->depth_max - r);
    bool got = tx_organ_nearest(b, x, c, range, side->n, &nr);
    if (got && r - nr.s > d->depth_max) {
      side->on = false;
      out->gave_way = out->inside = true;
    } else if (!got || nr.s >= r + d->hold) {
      // nothing facing within the range: far outside (ended), or deep inside (gave way)
      if (!got && side->deep) out->gave_way = out->inside = true;
      side->on = false;
    } else {
      out->on = true;
      out->depth = r - nr.s;
      memcpy(out->n, nr.n, sizeof out->n);
      memcpy(out->p, nr.p, sizeof out->p);
      memcpy(side->n, nr.n, sizeof side->n);
      side->deep = nr.s < 0;
    }
    if (!side->on) out->onset = false;
  }
  memcpy(side->prev, c, sizeof side->prev);
  side->has_prev = true;
}

void tx_organ_force(const tx_organ_touch* t, int n, const tx_skin_contact* r, double k_pen, double depth_max,
                    const double c[3], tx_organ_force_out* out) {
  memset(out, 0, sizeof *out);
  bool any = false;
  for (int i = 0; i < n; i++) any |= t[i].on;
  if (!any) return; // the surfaces decide contact: a reaction the hand has left is not felt
  bool finite = r && isfinite(r->f[0] + r->f[1] + r->f[2] + r->x[0] + r->x[1] + r->x[2] + r->n[0] + r->n[1] + r->n[2]);
  if (finite && r->touching > 0) {
    // the physics' reaction at x, carried to c along its direction at most depth_max deep, never a pull
    double k = isfinite(r->k) && r->k > 0 ? r->k : 0, mv[3] = {c[0] - r->x[0], c[1] - r->x[1], c[2] - r->x[2]};
    double along = dot(mv, r->n), f[3];
    bool lin = along > -depth_max;
    if (!lin) along = -depth_max; // past that the linearisation is not trusted: the force holds
    for (int e = 0; e < 3; e++) f[e] = r->f[e] - k * along * r->n[e];
    if (!(dot(f, r->n) > 0) || !isfinite(f[0] + f[1] + f[2])) return;
    memcpy(out->f, f, sizeof out->f);
    out->kind = TX_ORGAN_FORCE_REACTION;
    if (lin)
      for (int e = 0; e < 3; e++)
        for (int a = 0; a < 3; a++) out->k[3 * e + a] = -k * r->n[e] * r->n[a];
    return;
  }
  // the physics has not seen this contact yet: a penalty along each organ's normal
  for (int i = 0; i < n; i++) {
    if (!t[i].on || !(t[i].depth > 0)) continue;
    const double* nn = t[i].n;
    for (int e = 0; e < 3; e++) {
      out->f[e] += k_pen * t[i].depth * nn[e];
      for (int a = 0; a < 3; a++) out->k[3 * e + a] -= k_pen * nn[e] * nn[a];
    }
    out->kind = TX_ORGAN_FORCE_PENALTY;
  }
}
