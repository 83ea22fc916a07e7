// Triangle BVH: median-split build, bottom-up refit, nearest-hit ray query.
#include "tri_bvh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <tactus/model.h>

#define LEAF_MAX 4
#define STACK_MAX 64

int tx_tri_bvh_init(tx_tri_bvh* b, uint32_t tri_cap) {
  memset(b, 0, sizeof *b);
  if (tri_cap == 0) tri_cap = 1;
  b->tri_cap = tri_cap;
  b->nodes = calloc(2 * (size_t)tri_cap, sizeof *b->nodes);
  b->tri = calloc(3 * (size_t)tri_cap, sizeof *b->tri);
  b->order = calloc(tri_cap, sizeof *b->order);
  b->cen = calloc(3 * (size_t)tri_cap, sizeof *b->cen);
  if (!b->nodes || !b->tri || !b->order || !b->cen) return tx_tri_bvh_free(b), -1;
  return 0;
}

void tx_tri_bvh_free(tx_tri_bvh* b) {
  free(b->nodes);
  free(b->tri);
  free(b->order);
  free(b->cen);
  memset(b, 0, sizeof *b);
}

uint64_t tx_tri_bvh_hash(const int32_t* tri, uint32_t ntri) {
  return tx_hash(TX_HASH_SEED ^ ntri, tri, (size_t)ntri * 3 * sizeof *tri);
}

// box of the triangles order[first .. first + count)
static void leaf_box(const tx_tri_bvh* b, const float* x, tx_bvh_node* nd) {
  for (int a = 0; a < 3; a++) nd->lo[a] = INFINITY, nd->hi[a] = -INFINITY;
  for (uint32_t i = nd->first; i < nd->first + nd->count; i++) {
    const int32_t* t = b->tri + 3 * (size_t)b->order[i];
    for (int v = 0; v < 3; v++)
      for (int a = 0; a < 3; a++) {
        float p = x[3 * (size_t)t[v] + a];
        if (p < nd->lo[a]) nd->lo[a] = p;
        if (p > nd->hi[a]) nd->hi[a] = p;
      }
  }
}

// put the triangle of rank k (by centroid along axis) at order[k], smaller ones before it
static void select_kth(tx_tri_bvh* b, uint32_t lo, uint32_t hi, uint32_t k, int axis) {
  uint32_t* o = b->order;
  while (hi - lo > 1) {
    float pivot = b->cen[3 * (size_t)o[lo + (hi - lo - 1) / 2] + axis]; // lower middle: Hoare never stalls
    uint32_t i = lo, j = hi - 1;
    // Hoare partition around the pivot value
    for (;;) {
      while (b->cen[3 * (size_t)o[i] + axis] < pivot) i++;
      while (b->cen[3 * (size_t)o[j] + axis] > pivot) j--;
      if (i >= j) break;
      uint32_t t = o[i];
      o[i] = o[j];
      o[j] = t;
      i++;
      j--;
    }
    if (k <= j) hi = j + 1;
    else lo = j + 1;
  }
}

// build the subtree over order[first .. first + count); returns its node index
static uint32_t build_node(tx_tri_bvh* b, const float* x, uint32_t first, uint32_t count) {
  uint32_t id = b->nnodes++;
  tx_bvh_node* nd = &b->nodes[id];
  if (count <= LEAF_MAX) {
    nd->first = first;
    nd->count = count;
    leaf_box(b, x, nd);
    return id;
  }
  // split the centroids at the median of their longest extent
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = first; i < first + count; i++)
    for (int a = 0; a < 3; a++) {
      float c = b->cen[3 * (size_t)b->order[i] + a];
      if (c < lo[a]) lo[a] = c;
      if (c > hi[a]) hi[a] = c;
    }
  int axis = 0;
  for (int a = 1; a < 3; a++)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  uint32_t half = count / 2;
  select_kth(b, first, first + count, first + half, axis);
  build_node(b, x, first, half); // the left child is id + 1
  uint32_t right = build_node(b, x, first + half, count - half);
  nd = &b->nodes[id];
  nd->first = right;
  nd->count = 0;
  const tx_bvh_node* l = &b->nodes[id + 1];
  const tx_bvh_node* r = &b->nodes[right];
  for (int a = 0; a < 3; a++) {
    nd->lo[a] = fminf(l->lo[a], r->lo[a]);
    nd->hi[a] = fmaxf(l->hi[a], r->hi[a]);
  }
  return id;
}

int tx_tri_bvh_build(tx_tri_bvh* b, const float* x, uint32_t nx, const int32_t* tri, uint32_t ntri) {
  if (ntri > b->tri_cap) return -1;
  for (size_t i = 0; i < 3 * (size_t)ntri; i++)
    if (tri[i] < 0 || (uint32_t)tri[i] >= nx) return -1;
  memcpy(b->tri, tri, 3 * (size_t)ntri * sizeof *tri);
  b->ntri = ntri;
  b->nx = nx;
  b->nnodes = 0;
  b->topo_hash = tx_tri_bvh_hash(tri, ntri);
  for (uint32_t i = 0; i < ntri; i++) {
    b->order[i] = i;
    for (int a = 0; a < 3; a++) {
      const int32_t* t = tri + 3 * (size_t)i;
      b->cen[3 * (size_t)i + a] = (x[3 * (size_t)t[0] + a] + x[3 * (size_t)t[1] + a] + x[3 * (size_t)t[2] + a]) / 3.0f;
    }
  }
  if (ntri > 0) build_node(b, x, 0, ntri);
  return 0;
}

void tx_tri_bvh_refit(tx_tri_bvh* b, const float* x) {
  // children come after their parent, so walking backwards sees them first
  for (uint32_t i = b->nnodes; i-- > 0;) {
    tx_bvh_node* nd = &b->nodes[i];
    if (nd->count) {
      leaf_box(b, x, nd);
      continue;
    }
    const tx_bvh_node* l = &b->nodes[i + 1];
    const tx_bvh_node* r = &b->nodes[nd->first];
    for (int a = 0; a < 3; a++) {
      nd->lo[a] = fminf(l->lo[a], r->lo[a]);
      nd->hi[a] = fmaxf(l->hi[a], r->hi[a]);
    }
  }
}

// does o + t d meet the box for some t in [0, tmax]?
static bool ray_box(const tx_bvh_node* nd, const double o[3], const double inv[3], double tmax) {
  double t0 = 0, t1 = tmax;
  for (int a = 0; a < 3; a++) {
    double ta = (nd->lo[a] - o[a]) * inv[a], tb = (nd->hi[a] - o[a]) * inv[a];
    if (ta > tb) {
      double t = ta;
      ta = tb;
      tb = t;
    }
    if (isnan(ta) || isnan(tb)) { // direction parallel to this slab: inside it or never
      if (o[a] < nd->lo[a] || o[a] > nd->hi[a]) return false;
      continue;
    }
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return false;
  }
  return true;
}

// Moller-Trumbore, either side; distance or -1
static double ray_tri(const double o[3], const double d[3], const float* p0, const float* p1, const float* p2,
                      double n[3]) {
  double e1[3], e2[3], s[3], pv[3], qv[3];
  for (int a = 0; a < 3; a++) e1[a] = p1[a] - p0[a], e2[a] = p2[a] - p0[a], s[a] = o[a] - p0[a];
  pv[0] = d[1] * e2[2] - d[2] * e2[1];
  pv[1] = d[2] * e2[0] - d[0] * e2[2];
  pv[2] = d[0] * e2[1] - d[1] * e2[0];
  double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
  if (fabs(det) < 1e-30) return -1;
  double inv = 1.0 / det;
  double u = (s[0] * pv[0] + s[1] * pv[1] + s[2] * pv[2]) * inv;
  if (u < 0 || u > 1) return -1;
  qv[0] = s[1] * e1[2] - s[2] * e1[1];
  qv[1] = s[2] * e1[0] - s[0] * e1[2];
  qv[2] = s[0] * e1[1] - s[1] * e1[0];
  double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
  if (v < 0 || u + v > 1) return -1;
  double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  return t;
}

bool tx_tri_bvh_ray(tx_tri_bvh* b, const float* x, const double o[3], const double d[3], double tmax, tx_ray_hit* hit) {
  if (b->nnodes == 0) return false;
  double inv[3];
  for (int a = 0; a < 3; a++) inv[a] = 1.0 / d[a]; // +-inf on a zero component
  uint32_t stack[STACK_MAX];
  int sp = 0;
  stack[sp++] = 0;
  bool found = false;
  double best = tmax;
  uint64_t visited = 0;
  while (sp > 0) {
    const tx_bvh_node* nd = &b->nodes[stack[--sp]];
    visited++;
    if (!ray_box(nd, o, inv, best)) continue;
    if (nd->count == 0) {
      // the depth of a median-split tree is log2(triangles), far below STACK_MAX
      if (sp + 2 > STACK_MAX) continue;
      stack[sp++] = nd->first;
      stack[sp++] = (uint32_t)(nd - b->nodes) + 1;
      continue;
    }
    for (uint32_t i = nd->first; i < nd->first + nd->count; i++) {
      uint32_t id = b->order[i];
      const int32_t* t = b->tri + 3 * (size_t)id;
      double n[3];
      double th = ray_tri(o, d, x + 3 * (size_t)t[0], x + 3 * (size_t)t[1], x + 3 * (size_t)t[2], n);
      if (th >= 0 && th <= best) {
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(l > 0)) continue; // a degenerate triangle has no side
        best = th;
        found = true;
        hit->t = th;
        hit->tri = id;
        for (int a = 0; a < 3; a++) hit->n[a] = n[a] / l;
      }
    }
  }
  b->visited += visited;
  return found;
}
