// The simplified method: per-ray contact points, eq. 5, 7 and 8 of the
// SutureHap conference paper (eq. 3 of the journal paper).
#include "hip.h"

#include "../range_check.h"

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

const char* tx_hip_def_check(const tx_hip_def* d) {
  const char* e;
  if ((e = tx_check_range_msg("hip", "radius", d->radius, 0, true, 0.05, false, "m"))) return e;
  if (d->rays != 26 && d->rays != 98) return tx_check_fail_msg("hip: rays = %d, must be 26 or 98", d->rays);
  if ((e = tx_check_range_msg("hip", "alpha", d->alpha, 0, false, 1e6, false, "N/m"))) return e;
  if ((e = tx_check_range_msg("hip", "k", d->k, 0, false, 1, true, "1"))) return e;
  if ((e = tx_check_range_msg("hip", "slide_max", d->slide_max, 0, true, 1, false, "m"))) return e;
  if ((e = tx_check_range_msg("hip", "pierce_range", d->pierce_range, 0, true, 1, false, "m"))) return e;
  if ((e = tx_check_range_msg("hip", "hold", d->hold, 0, false, 0.01, false, "m"))) return e;
  return NULL;
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

void tx_hip_query(tx_hip* h, tx_tri_bvh* b, const float* x, double thickness, const double c[3], tx_hip_out* out) {
  memset(out, 0, sizeof *out);
  memcpy(out->x0, c, sizeof out->x0);
  const double r = h->def.radius;
  const double reach = r + 0.5 * thickness; // contact: mid-plane closer than this
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
  // the anchor: the HIP centre the rays already in contact measure from (mean of P_in - r d)
  double anchor[3] = {c[0], c[1], c[2]};
  int held = 0;
  for (int i = 0; i < h->nrays; i++)
    if (h->on[i] && !fresh[i]) {
      if (held++ == 0) anchor[0] = anchor[1] = anchor[2] = 0;
      for (int a = 0; a < 3; a++) anchor[a] += h->p_in[i][a] - r * h->dir[i][a];
    }
  for (int a = 0; a < 3 && held > 0; a++) anchor[a] /= held;
  // first contact of a ray: the ray's point at the HIP's radius, now (each ray by its
  // own onset) or as of the anchor (rays joining a contact start where it started)
  for (int i = 0; i < h->nrays; i++)
    if (fresh[i]) {
      h->on[i] = true;
      const double* base = h->def.join_anchor ? anchor : c;
      for (int a = 0; a < 3; a++) h->p_in[i][a] = base[a] + r * h->dir[i][a];
    }
  if (n == 0) { // contact over: a later touch starts afresh
    h->touching = false;
    h->pierced = false;
    return;
  }
  if (!h->touching) { // contact begins: remember which way the skin lies
    double l = sqrt(dot(towards, towards));
    if (l > 0)
      for (int a = 0; a < 3; a++) h->approach[a] = towards[a] / l;
    else
      memcpy(h->approach, h->dir[0], sizeof h->approach);
    h->touching = true;
  }
  // through the skin: no skin left ahead along the approach. Where it is found, the
  // HIP would just touch this (frozen) skin at x0 = c + (t - reach) approach
  tx_ray_hit ahead;
  memcpy(out->x0, c, sizeof out->x0);
  if (!h->pierced) {
    if (!tx_tri_bvh_ray(b, x, c, h->approach, h->def.pierce_range, &ahead)) h->pierced = true;
    else
      for (int a = 0; a < 3; a++) out->x0[a] = c[a] + (ahead.t - reach) * h->approach[a];
  }
  out->depth = reach > nearest ? reach - nearest : 0;
  if (h->pierced) {
    out->pierced = true;
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
