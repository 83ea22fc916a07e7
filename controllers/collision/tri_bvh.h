// Internal: a bounding volume hierarchy over a deforming triangle mesh.
//
// The tree is built once for a triangle set (median split on the longest axis
// of the centroids, up to 4 triangles per leaf) and refitted when only the
// vertices move: the boxes are recomputed bottom-up, the tree shape is kept.
// A ray query walks only the boxes its segment [0, tmax] crosses, so its cost
// grows with the depth of the tree, not with the triangle count. Everything
// is allocated by tx_tri_bvh_init; build, refit and queries never allocate.
//
//     tx_tri_bvh b;
//     tx_tri_bvh_init(&b, max_triangles);
//     tx_tri_bvh_build(&b, x, nx, tri, ntri);   // when the triangle set changes
//     tx_tri_bvh_refit(&b, x);                  // when only the positions change
//     tx_tri_bvh_remove(&b, tri, ntri);         // when triangles were torn out (then refit)
//     tx_ray_hit h;
//     if (tx_tri_bvh_ray(&b, x, o, d, tmax, &h)) { ... h.t, h.tri ... }
//     tx_tri_bvh_free(&b);
#ifndef TX_CONTROLLERS_COLLISION_TRI_BVH_H
#define TX_CONTROLLERS_COLLISION_TRI_BVH_H

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_bvh_node {
  float lo[3], hi[3]; // m, the box of everything below
  uint32_t first;     // leaf: first slot in order; inner: index of the right child (the left is this + 1)
  uint32_t count;     // leaf: triangles in it (1..4); inner: 0
} tx_bvh_node;

typedef struct tx_tri_bvh {
  uint32_t tri_cap;    // triangles it can hold
  uint32_t ntri;       // triangles in the current array (the build's, less any removed since)
  uint32_t nslot;      // leaf slots: the triangles at the build
  uint32_t nx;         // vertices the current build indexes
  uint32_t nnodes;     // nodes in use
  tx_bvh_node* nodes;  // (2 tri_cap) the tree, parents before children
  int32_t* tri;        // (tri_cap x 3) vertex indices, in leaf order
  uint32_t* order;     // (tri_cap) triangle ids (rows of the current array) in leaf order; UINT32_MAX once removed
  uint32_t* slot;      // (tri_cap) leaf position of each row of the current array
  float* cen;          // (tri_cap x 3) m, centroids, scratch for building
  int32_t* raw;        // (tri_cap x 3) the triangle array as given to the current build
  uint64_t visited;    // nodes visited by queries since the last reset (for cost checks)
} tx_tri_bvh;

typedef struct tx_ray_hit {
  double t;     // m, distance along the unit direction
  uint32_t tri; // triangle id (row of the triangle array)
  double n[3];  // 1, unit normal of that triangle (its winding's side)
} tx_ray_hit;

// allocate for up to tri_cap triangles; 0, or -1 when out of memory
int tx_tri_bvh_init(tx_tri_bvh* b, uint32_t tri_cap);
void tx_tri_bvh_free(tx_tri_bvh* b);
// is tri (ntri rows) the triangle array of the current build? (one memcmp)
bool tx_tri_bvh_same(const tx_tri_bvh* b, const int32_t* tri, uint32_t ntri);
// build over ntri triangles of x (nx vertices); -1 if ntri > tri_cap or an index is outside [0, nx)
int tx_tri_bvh_build(tx_tri_bvh* b, const float* x, uint32_t nx, const int32_t* tri, uint32_t ntri);
// recompute every box from moved vertices (same triangle set)
void tx_tri_bvh_refit(tx_tri_bvh* b, const float* x);
// the same for the nodes [from, to) only, last first: refitting [k, nnodes) then
// [0, k) equals one whole refit, so the work can be spread over several calls
void tx_tri_bvh_refit_nodes(tx_tri_bvh* b, const float* x, uint32_t from, uint32_t to);
// the triangle array lost rows and kept the order of the rest (a tear): the
// removed triangles are emptied in place, the tree keeps its shape; refit
// after. 0, or -1 (tree unchanged) when tri is not such a subset: rebuild then
int tx_tri_bvh_remove(tx_tri_bvh* b, const int32_t* tri, uint32_t ntri);
// make dst the same tree as src (dst sized for at least src's triangles); 0, or -1
int tx_tri_bvh_copy(tx_tri_bvh* dst, const tx_tri_bvh* src);
// Many short rays from one point (the HIP's) share one walk: gather the
// subtrees whose boxes meet the sphere (c, radius) and are no wider than it,
// then start each ray's walk from them. Returns how many (the root alone when
// more than TX_BVH_ROOTS_MAX would be needed; 0 when nothing is near).
#define TX_BVH_ROOTS_MAX 48
int tx_tri_bvh_gather(tx_tri_bvh* b, const double c[3], double radius, uint32_t roots[TX_BVH_ROOTS_MAX]);
// nearest triangle hit by o + t d, 0 <= t <= tmax, searching only below the given roots
bool tx_tri_bvh_ray_from(tx_tri_bvh* b, const uint32_t* roots, int nroots, const float* x, const double o[3],
                         const double d[3], double tmax, tx_ray_hit* hit);
// nearest triangle hit by o + t d, 0 <= t <= tmax (d unit, either side of a triangle counts)
bool tx_tri_bvh_ray(tx_tri_bvh* b, const float* x, const double o[3], const double d[3], double tmax, tx_ray_hit* hit);

#endif
