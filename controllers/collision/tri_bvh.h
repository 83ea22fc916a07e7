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
  uint32_t ntri;       // triangles in the current build
  uint32_t nx;         // vertices the current build indexes
  uint32_t nnodes;     // nodes in use
  tx_bvh_node* nodes;  // (2 tri_cap) the tree, parents before children
  int32_t* tri;        // (tri_cap x 3) vertex indices, in leaf order
  uint32_t* order;     // (tri_cap) triangle ids (rows of the built array) in leaf order
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
// nearest triangle hit by o + t d, 0 <= t <= tmax (d unit, either side of a triangle counts)
bool tx_tri_bvh_ray(tx_tri_bvh* b, const float* x, const double o[3], const double d[3], double tmax, tx_ray_hit* hit);

#endif
