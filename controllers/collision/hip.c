// The simplified method: per-ray contact points, eq. 5, 7 and 8 of the
// SutureHap conference paper (eq. 3 of the journal paper).
#include "hip.h"

#include "../range_check.h"

#include <tactus/components.h>

#include <math.h>
#include <string.h>

tx_hip_def tx_hip_def_default(void) {
  return (tx_hip_def){
      .radius = 0.0005, // 0.05 cm
      .rays = 26,
      .alpha = 20.0, // 0.2 N/cm
      .k = 0.3,
      .slide_max = 0.003, // 0.3 cm
      .pierce_range = 0.01,
      .hold = 5e-4, // 0.05 cm: the skin may lead the HIP by its speed over one physics period
      .join_anchor = true,
  };
}

int tx_hip_def_check(const tx_hip_def* d) {
  if (tx_check_range("hip", "radius", d->radius, 0, true, 0.05, false, "m")) return -1;
  if (d->rays != 26 && d->rays != 98) return tx_check_fail("hip: rays = %d, must be 26 or 98", d->rays);
  if (tx_check_range("hip", "alpha", d->alpha, 0, false, 1e6, false, "N/m")) return -1;
  if (tx_check_range("hip", "k", d->k, 0, false, 1, true, "1")) return -1;
  if (tx_check_range("hip", "slide_max", d->slide_max, 0, true, 1, false, "m")) return -1;
  if (tx_check_range("hip", "pierce_range", d->pierce_range, 0, true, 1, false, "m")) return -1;
  if (tx_check_range("hip", "hold", d->hold, 0, false, 0.01, false, "m")) return -1;
  return 0;
}

void tx_hip_init(tx_hip* h, const tx_hip_def* def) {
  memset(h, 0, sizeof *h);
  h->def = *def;
  h->nrays = tx_hip_rays(def->rays, h->dir);
}

void tx_hip_reset(tx_hip* h) {
  memset(h->on, 0, sizeof h->on);
  h->touching = false;
  h->pierced = false;
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// the HIP has left a pierce behind: back on the side it came from, or pierce_range from where it went through
static bool clear_of_pierce(const tx_hip* h, const double c[3], double reach) {
  double d[3] = {c[0] - h->pierce_at[0], c[1] - h->pierce_at[1], c[2] - h->pierce_at[2]};
  return dot(d, h->approach) < -reach || sqrt(dot(d, d)) > h->def.pierce_range;
}

// r: the skin's reaction (mechanics mode), NULL for the papers' method
static void query(tx_hip* h, tx_tri_bvh* b, const float* x, double thickness, const double c[3],
                  const tx_skin_contact* r, tx_hip_out* out) {
  memset(out, 0, sizeof *out);
  memcpy(out->x0, c, sizeof out->x0);
  const double rad = h->def.radius;
  const double reach = rad + 0.5 * thickness; // contact: mid-plane closer than this
  double nearest = reach + h->def.hold, towards[3] = {0, 0, 0};
  double t[TX_HIP_RAYS_MAX];
  bool fresh[TX_HIP_RAYS_MAX] = {false};
  int n = 0;
  // every ray starts at c and ends within reach: one walk finds what they can meet
  uint32_t roots[TX_BVH_ROOTS_MAX];
  int nroots = tx_tri_bvh_gather(b, c, reach + h->def.hold, roots);
  // which rays touch: contact begins at t < reach and holds up to reach + hold
  for (int i = 0; i < h->nrays; i++) {
    const double* d = h->dir[i];
    tx_ray_hit hit;
    double limit = h->on[i] ? reach + h->def.hold : reach;
    if (!tx_tri_bvh_ray_from(b, roots, nroots, x, c, d, limit, &hit) || !(hit.t < limit)) {
      h->on[i] = false;
      continue;
    }
    t[i] = hit.t;
    if (!h->on[i]) fresh[i] = true; // its first contact point is set below, once the anchor is known
    for (int a = 0; a < 3; a++) towards[a] += d[a];
    if (hit.t < nearest) nearest = hit.t;
    n++;
  }
  // the anchor: the HIP centre the rays already in contact measure from (mean of P_in - t0 d)
  double anchor[3] = {c[0], c[1], c[2]};
  int held = 0;
  for (int i = 0; i < h->nrays; i++)
    if (h->on[i] && !fresh[i]) {
      if (held++ == 0) anchor[0] = anchor[1] = anchor[2] = 0;
      for (int a = 0; a < 3; a++) anchor[a] += h->p_in[i][a] - h->t0[i] * h->dir[i][a];
    }
  for (int a = 0; a < 3 && held > 0; a++) anchor[a] /= held;
  if (held == 0 && h->touching && !h->pierced) memcpy(anchor, h->anchor, sizeof anchor); // through a gap
  // first contact of a ray: where it meets the skin now (each ray by its own
  // onset) or as seen from the anchor (rays joining a contact start where it started)
  for (int i = 0; i < h->nrays; i++)
    if (fresh[i]) {
      h->on[i] = true;
      h->t0[i] = t[i];
      const double* base = h->def.join_anchor ? anchor : c;
      for (int a = 0; a < 3; a++) h->p_in[i][a] = base[a] + t[i] * h->dir[i][a];
    }
  // a pierced HIP stays so until it is clear of the pierce: a torn flap
  // that touches it again is not a whole skin
  if (h->pierced && clear_of_pierce(h, c, reach)) {
    h->pierced = false;
    h->touching = false;
  }
  if (n == 0 && !(r && r->touching > 0 && !h->pierced)) { // contact over: a later touch starts afresh
    // unless it ended through a hole: nothing ahead along the approach (the rays lost a
    // torn skin all at once); then it is a pierce, and a flap touching again is no skin
    tx_ray_hit gone;
    if (h->touching && !h->pierced && !tx_tri_bvh_ray(b, x, c, h->approach, h->def.pierce_range, &gone) &&
        (!r || r->torn > h->torn_at_touch)) {
      h->pierced = true;
      memcpy(h->pierce_at, c, sizeof h->pierce_at);
    }
    // the rays lost an untorn skin that is still ahead, with the HIP pressed past where
    // the contact began: the skin wraps the HIP between the rays, the contact goes on
    double in = (c[0] - h->anchor[0]) * h->approach[0] + (c[1] - h->anchor[1]) * h->approach[1] +
                (c[2] - h->anchor[2]) * h->approach[2];
    if (!r && h->touching && !h->pierced && in > 0 &&
        tx_tri_bvh_ray(b, x, c, h->approach, h->def.pierce_range, &gone)) {
      for (int e = 0; e < 3; e++) {
        out->f[e] = h->def.alpha * in * h->approach[e] * -1;
        for (int a = 0; a < 3; a++) out->k[3 * e + a] = -h->def.alpha * h->approach[e] * h->approach[a];
      }
      return;
    }
    h->touching = false;
    out->pierced = h->pierced;
    return;
  }
  if (!h->touching && !h->pierced) { // contact begins: remember which way the skin lies
    double l = sqrt(dot(towards, towards));
    if (l > 0)
      for (int a = 0; a < 3; a++) h->approach[a] = towards[a] / l;
    else if (r && r->touching > 0)
      for (int a = 0; a < 3; a++) h->approach[a] = -r->n[a];
    else
      memcpy(h->approach, h->dir[0], sizeof h->approach);
    h->torn_at_touch = r ? r->torn : 0;
  }
  h->touching = true;
  memcpy(h->anchor, anchor, sizeof h->anchor);
  // through the skin: no skin left ahead along the approach (in mechanics mode,
  // with links torn since the contact began). Where it is found, the HIP would
  // just touch this (frozen) skin at x0 = c + (t - reach) approach
  tx_ray_hit ahead;
  if (!h->pierced) {
    bool found = tx_tri_bvh_ray(b, x, c, h->approach, h->def.pierce_range, &ahead);
    if (!found && (!r || r->torn > h->torn_at_touch)) {
      h->pierced = true;
      memcpy(h->pierce_at, c, sizeof h->pierce_at);
    } else if (found && !r) {
      for (int a = 0; a < 3; a++) out->x0[a] = c[a] + (ahead.t - reach) * h->approach[a];
    }
  }
  out->depth = reach > nearest ? reach - nearest : 0;
  if (h->pierced) {
    out->pierced = true;
    return;
  }
  if (r) {
    // the skin's reaction at x, carried to c along n at most reach deep, never a pull
    double k = isfinite(r->k) && r->k > 0 ? r->k : 0, mv[3] = {c[0] - r->x[0], c[1] - r->x[1], c[2] - r->x[2]};
    double along = dot(mv, r->n), f[3];
    bool inside = along > -reach;
    if (!inside) along = -reach;
    for (int e = 0; e < 3; e++) f[e] = r->f[e] - k * along * r->n[e];
    if (!(r->touching > 0) || !(dot(f, r->n) > 0) || !isfinite(f[0] + f[1] + f[2])) return; // no contact
    memcpy(out->f, f, sizeof out->f);
    out->contacts = n > 0 ? n : 1;
    if (inside)
      for (int e = 0; e < 3; e++)
        for (int a = 0; a < 3; a++) out->k[3 * e + a] = -k * r->n[e] * r->n[a];
    return;
  }
  double sum[3] = {0, 0, 0};
  const double* a_n = h->approach;
  for (int i = 0; i < h->nrays; i++) {
    if (!h->on[i]) continue;
    const double* d = h->dir[i];
    double p[3] = {c[0] + t[i] * d[0], c[1] + t[i] * d[1], c[2] + t[i] * d[2]}; // P_n
    double rn[3] = {p[0] - h->p_in[i][0], p[1] - h->p_in[i][1], p[2] - h->p_in[i][2]}; // eq. 5
    // eq. 8: past slide_max along the skin (across the direction it was met from),
    // the first contact point follows the hand
    double along = dot(rn, a_n);
    double tang[3] = {rn[0] - along * a_n[0], rn[1] - along * a_n[1], rn[2] - along * a_n[2]};
    // (applied across the approach only: P_in = P_n - (R_normal + k R_tangential), so a slide
    // drags without letting go of the push)
    if (sqrt(dot(tang, tang)) > h->def.slide_max) {
      for (int e = 0; e < 3; e++) {
        h->p_in[i][e] += (1 - h->def.k) * tang[e];
        rn[e] = p[e] - h->p_in[i][e];
      }
      h->resets++;
    }
    for (int e = 0; e < 3; e++) sum[e] += rn[e];
  }
  out->contacts = n;
  for (int e = 0; e < 3; e++) out->f[e] = -h->def.alpha * sum[e] / n; // eq. 7
  // K = dF/dc with every contact point moving with the HIP, as the skin held at the HIP's
  // surface does along the push and the rays' own hits do across it: each R_n grows with c
  for (int e = 0; e < 3; e++) out->k[4 * e] = -h->def.alpha;
}

void tx_hip_query(tx_hip* h, tx_tri_bvh* b, const float* x, double thickness, const double c[3], tx_hip_out* out) {
  query(h, b, x, thickness, c, NULL, out);
}

void tx_hip_query_reaction(tx_hip* h, tx_tri_bvh* b, const float* x, double thickness, const double c[3],
                           const tx_skin_contact* r, tx_hip_out* out) {
  query(h, b, x, thickness, c, r, out);
}
