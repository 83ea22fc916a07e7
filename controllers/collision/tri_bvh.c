// Triangle BVH: median-split build, bottom-up refit, nearest-hit ray query.
#include "tri_bvh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


#define LEAF_MAX 4
#define STACK_MAX 128 // tree depth (log2 of the triangles) plus up to TX_BVH_ROOTS_MAX roots

int tx_tri_bvh_init(tx_tri_bvh* b, uint32_t tri_cap) {
  memset(b, 0, sizeof *b);
  if (tri_cap == 0) tri_cap = 1;
  b->tri_cap = tri_cap;
  b->nodes = calloc(2 * (size_t)tri_cap, sizeof *b->nodes);
  b->tri = calloc(3 * (size_t)tri_cap, sizeof *b->tri);
  b->raw = calloc(3 * (size_t)tri_cap, sizeof *b->raw);
  b->order = calloc(tri_cap, sizeof *b->order);
  b->slot = calloc(tri_cap, sizeof *b->slot);
  b->cen = calloc(3 * (size_t)tri_cap, sizeof *b->cen);
  if (!b->nodes || !b->tri || !b->raw || !b->order || !b->slot || !b->cen) return tx_tri_bvh_free(b), -1;
  return 0;
}

void tx_tri_bvh_free(tx_tri_bvh* b) {
  free(b->nodes);
  free(b->tri);
  free(b->raw);
  free(b->order);
  free(b->slot);
  free(b->cen);
  memset(b, 0, sizeof *b);
}

bool tx_tri_bvh_same(const tx_tri_bvh* b, const int32_t* tri, uint32_t ntri) {
  return b->nnodes > 0 && ntri == b->ntri && memcmp(tri, b->raw, 3 * (size_t)ntri * sizeof *tri) == 0;
}

// box of the leaf's triangles, in locals: stores to the box cannot alias the reads of x
static inline void leaf_box(const tx_tri_bvh* b, const float* restrict x, tx_bvh_node* nd) {
  float lo0 = INFINITY, lo1 = INFINITY, lo2 = INFINITY, hi0 = -INFINITY, hi1 = -INFINITY, hi2 = -INFINITY;
  const int32_t* t = b->tri + 3 * (size_t)nd->first;
  const int32_t* end = t + 3 * (size_t)nd->count;
  for (; t < end; t++) {
    const float* p = x + 3 * (size_t)*t;
    float p0 = p[0], p1 = p[1], p2 = p[2];
    lo0 = p0 < lo0 ? p0 : lo0, hi0 = p0 > hi0 ? p0 : hi0;
    lo1 = p1 < lo1 ? p1 : lo1, hi1 = p1 > hi1 ? p1 : hi1;
    lo2 = p2 < lo2 ? p2 : lo2, hi2 = p2 > hi2 ? p2 : hi2;
  }
  nd->lo[0] = lo0, nd->lo[1] = lo1, nd->lo[2] = lo2;
  nd->hi[0] = hi0, nd->hi[1] = hi1, nd->hi[2] = hi2;
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

// shape the subtree over order[first .. first + count); returns its node index.
// Boxes are filled afterwards by a refit, once the triangles are in leaf order.
static uint32_t build_node(tx_tri_bvh* b, uint32_t first, uint32_t count) {
  uint32_t id = b->nnodes++;
  tx_bvh_node* nd = &b->nodes[id];
  if (count <= LEAF_MAX) {
    nd->first = first;
    nd->count = count;
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
  build_node(b, first, half); // the left child is id + 1
  uint32_t right = build_node(b, first + half, count - half);
  nd = &b->nodes[id];
  nd->first = right;
  nd->count = 0;
  return id;
}

int tx_tri_bvh_build(tx_tri_bvh* b, const float* x, uint32_t nx, const int32_t* tri, uint32_t ntri) {
  if (ntri > b->tri_cap) return -1;
  for (size_t i = 0; i < 3 * (size_t)ntri; i++)
    if (tri[i] < 0 || (uint32_t)tri[i] >= nx) return -1;
  b->ntri = b->nslot = ntri;
  b->nx = nx;
  b->nnodes = 0;
  memcpy(b->raw, tri, 3 * (size_t)ntri * sizeof *tri);
  for (uint32_t i = 0; i < ntri; i++) {
    b->order[i] = i;
    const int32_t* t = tri + 3 * (size_t)i;
    for (int a = 0; a < 3; a++)
      b->cen[3 * (size_t)i + a] = (x[3 * (size_t)t[0] + a] + x[3 * (size_t)t[1] + a] + x[3 * (size_t)t[2] + a]) / 3.0f;
  }
  // the split only permutes order; the triangles follow it, so leaves read memory in sequence
  if (ntri > 0) build_node(b, 0, ntri);
  for (uint32_t i = 0; i < ntri; i++) {
    memcpy(b->tri + 3 * (size_t)i, tri + 3 * (size_t)b->order[i], 3 * sizeof *tri);
    b->slot[b->order[i]] = i;
  }
  tx_tri_bvh_refit(b, x);
  return 0;
}

void tx_tri_bvh_refit(tx_tri_bvh* b, const float* x) { tx_tri_bvh_refit_nodes(b, x, 0, b->nnodes); }

int tx_tri_bvh_copy(tx_tri_bvh* dst, const tx_tri_bvh* src) {
  if (src->nslot > dst->tri_cap) return -1;
  memcpy(dst->nodes, src->nodes, src->nnodes * sizeof *src->nodes);
  memcpy(dst->tri, src->tri, 3 * (size_t)src->nslot * sizeof *src->tri);
  memcpy(dst->order, src->order, src->nslot * sizeof *src->order);
  memcpy(dst->raw, src->raw, 3 * (size_t)src->ntri * sizeof *src->raw);
  memcpy(dst->slot, src->slot, src->ntri * sizeof *src->slot);
  dst->ntri = src->ntri, dst->nslot = src->nslot, dst->nx = src->nx, dst->nnodes = src->nnodes;
  return 0;
}

int tx_tri_bvh_remove(tx_tri_bvh* b, const int32_t* tri, uint32_t ntri) {
  if (b->nnodes == 0 || ntri > b->ntri) return -1;
  // first make sure tri is the current array less some rows, in order
  uint32_t j = 0;
  for (uint32_t i = 0; i < b->ntri; i++)
    if (j < ntri && memcmp(b->raw + 3 * (size_t)i, tri + 3 * (size_t)j, 3 * sizeof *tri) == 0) j++;
  if (j != ntri) return -1;
  // then empty the removed triangles where they sit, and renumber the kept rows
  j = 0;
  for (uint32_t i = 0; i < b->ntri; i++) {
    uint32_t at = b->slot[i];
    if (j < ntri && memcmp(b->raw + 3 * (size_t)i, tri + 3 * (size_t)j, 3 * sizeof *tri) == 0) {
      b->slot[j] = at;
      b->order[at] = j++;
      continue;
    }
    int32_t* t = b->tri + 3 * (size_t)at; // all three corners on one particle: no area, no hit
    t[1] = t[2] = t[0];
    b->order[at] = UINT32_MAX;
  }
  memcpy(b->raw, tri, 3 * (size_t)ntri * sizeof *tri);
  b->ntri = ntri;
  return 0;
}

void tx_tri_bvh_refit_nodes(tx_tri_bvh* b, const float* x, uint32_t from, uint32_t to) {
  if (to > b->nnodes) to = b->nnodes;
  // children come after their parent, so walking backwards sees them first
  for (uint32_t i = to; i-- > from;) {
    tx_bvh_node* nd = &b->nodes[i];
    if (nd->count) {
      leaf_box(b, x, nd);
      continue;
    }
    const tx_bvh_node* l = &b->nodes[i + 1];
    const tx_bvh_node* r = &b->nodes[nd->first];
    for (int a = 0; a < 3; a++) {
      float lo = l->lo[a] < r->lo[a] ? l->lo[a] : r->lo[a], hi = l->hi[a] > r->hi[a] ? l->hi[a] : r->hi[a];
      nd->lo[a] = lo, nd->hi[a] = hi;
    }
  }
}

// entry distance of o + t d into the box within [0, tmax], or -1 (inv: 1/d, finite)
static inline double ray_box(const tx_bvh_node* nd, const double o[3], const double inv[3], double tmax) {
  double t0 = 0, t1 = tmax;
  for (int a = 0; a < 3; a++) {
    double ta = (nd->lo[a] - o[a]) * inv[a], tb = (nd->hi[a] - o[a]) * inv[a];
    if (ta > tb) {
      double t = ta;
      ta = tb;
      tb = t;
    }
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
    if (t0 > t1) return -1;
  }
  return t0;
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
  // a hair of slack on the barycentric bounds: a ray along an edge two triangles share meets both
  const double eps = 1e-9;
  if (u < -eps || u > 1 + eps) return -1;
  qv[0] = s[1] * e1[2] - s[2] * e1[1];
  qv[1] = s[2] * e1[0] - s[0] * e1[2];
  qv[2] = s[0] * e1[1] - s[1] * e1[0];
  double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
  if (v < -eps || u + v > 1 + eps) return -1;
  double t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  return t;
}

bool tx_tri_bvh_ray_from(tx_tri_bvh* b, const uint32_t* roots, int nroots, const float* x, const double o[3],
                         const double d[3], double tmax, tx_ray_hit* hit) {
  if (b->nnodes == 0 || nroots <= 0) return false;
  double inv[3];
  for (int a = 0; a < 3; a++) // a zero component gets a huge slope, so its slab test stays finite
    inv[a] = 1.0 / (fabs(d[a]) > 1e-30 ? d[a] : (d[a] < 0 ? -1e-30 : 1e-30));
  uint32_t stack[STACK_MAX];
  double enter[STACK_MAX]; // entry distance of each stacked node
  bool found = false;
  double best = tmax;
  uint64_t visited = 0;
  int sp = 0;
  for (int i = 0; i < nroots && i < TX_BVH_ROOTS_MAX; i++) {
    double t = ray_box(&b->nodes[roots[i]], o, inv, best);
    visited++;
    if (t >= 0) stack[sp] = roots[i], enter[sp++] = t;
  }
  while (sp > 0) {
    sp--;
    if (enter[sp] > best) continue; // a nearer hit was found since it was stacked
    const tx_bvh_node* nd = &b->nodes[stack[sp]];
    if (nd->count == 0) {
      // both children: the nearer one is searched first, the farther skipped once beaten
      uint32_t l = (uint32_t)(nd - b->nodes) + 1, r = nd->first;
      double tl = ray_box(&b->nodes[l], o, inv, best), tr = ray_box(&b->nodes[r], o, inv, best);
      visited += 2;
      if (tl >= 0 && tr >= 0 && tl < tr) {
        uint32_t u = l;
        double tu = tl;
        l = r, tl = tr, r = u, tr = tu;
      }
      // the depth of a median-split tree is log2(triangles), far below STACK_MAX
      if (tl >= 0 && sp < STACK_MAX) stack[sp] = l, enter[sp++] = tl;
      if (tr >= 0 && sp < STACK_MAX) stack[sp] = r, enter[sp++] = tr;
      continue;
    }
    for (uint32_t i = nd->first; i < nd->first + nd->count; i++) {
      const int32_t* t = b->tri + 3 * (size_t)i;
      double n[3];
      double th = ray_tri(o, d, x + 3 * (size_t)t[0], x + 3 * (size_t)t[1], x + 3 * (size_t)t[2], n);
      if (th >= 0 && th <= best) {
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 0)) continue; // a degenerate triangle has no side
        best = th;
        found = true;
        hit->t = th;
        hit->tri = b->order[i];
        for (int a = 0; a < 3; a++) hit->n[a] = n[a] / len;
      }
    }
  }
  b->visited += visited;
  return found;
}

bool tx_tri_bvh_ray(tx_tri_bvh* b, const float* x, const double o[3], const double d[3], double tmax, tx_ray_hit* hit) {
  const uint32_t root = 0;
  return tx_tri_bvh_ray_from(b, &root, 1, x, o, d, tmax, hit);
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

int tx_tri_bvh_gather(tx_tri_bvh* b, const double c[3], double radius, uint32_t roots[TX_BVH_ROOTS_MAX]) {
  if (b->nnodes == 0) return 0;
  uint32_t stack[STACK_MAX];
  int sp = 0, n = 0;
  stack[sp++] = 0;
  double r2 = radius * radius;
  uint64_t visited = 0;
  while (sp > 0) {
    uint32_t id = stack[--sp];
    const tx_bvh_node* nd = &b->nodes[id];
    visited++;
    if (box_dist2(nd, c) > r2) continue;
    // stop at boxes no wider than the sphere: the rays' own walk goes on from there
    double w = 0;
    for (int a = 0; a < 3; a++)
      if (nd->hi[a] - nd->lo[a] > w) w = nd->hi[a] - nd->lo[a];
    if (nd->count || w <= radius) {
      if (n == TX_BVH_ROOTS_MAX) { // too many: the rays start from the top instead
        b->visited += visited;
        roots[0] = 0;
        return 1;
      }
      roots[n++] = id;
      continue;
    }
    if (sp + 2 > STACK_MAX) continue;
    stack[sp++] = nd->first;
    stack[sp++] = id + 1;
  }
  b->visited += visited;
  return n;
}
