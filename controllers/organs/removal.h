// Internal: the surface of an organ that has lost tetrahedra (docs/lagb.md,
// "Removal"). physics.organs publishes, once an organ is cut, the boundary
// of its live tetrahedra (tx_fem_hull) instead of the drawn surface: the
// hole shows and the exposed inner faces are in it. tx_compact_surface
// numbers its nodes as rows (each row one node, no row unused) and
// tx_surface_check checks what a reader is promised. Needs no optional
// library; nothing here allocates.
#ifndef TX_CONTROLLERS_ORGANS_REMOVAL_H
#define TX_CONTROLLERS_ORGANS_REMOVAL_H

#include <stdbool.h>
#include <stdint.h>

// faces (nf x 3 node numbers) as a surface of rows: the nodes in order of
// first use, node_of[row] the node, tri (nf x 3) the faces in rows.
// row_of: one per node, scratch, every entry -1 on entry and again on
// return. Returns the rows.
int tx_compact_surface(const int* faces, int nf, int32_t* row_of, int32_t* node_of, int32_t* tri);

// the same, with the rows' positions: x (rows x 3) from pos (nodes x 3)
int tx_cut_surface(const int* faces, int nf, const double* pos, int32_t* row_of, int32_t* node_of, float* x, int32_t* tri);

// what tx_surface_check finds; a sound closed surface has every count 0
// but nonmanifold_edges, which is tissue meeting along an edge only
typedef struct tx_surface_report {
  int rows, triangles, edges;
  int out_of_range;      // triangle corners outside [0, rows)
  int degenerate;        // triangles naming a row twice
  int unreferenced;      // rows no triangle names (dangling vertices)
  int doubled;           // rows naming a node another row names (node_of given)
  int open_edges;        // edges not run as often one way as the other: a hole, a flipped or doubled face
  int nonmanifold_edges; // edges of more than two triangles
} tx_surface_report;

// tri (nt x 3) over rows rows; node_of (rows, NULL: not checked) over nodes.
// keys: scratch of 3 nt; seen: scratch of max(rows, nodes). True when every
// count but nonmanifold_edges is 0.
bool tx_surface_check(const int32_t* tri, int nt, int rows, const int32_t* node_of, int nodes, uint64_t* keys, int32_t* seen,
                      tx_surface_report* out);

// a structured block for tests and the removal study: nx x ny x nz cubes
// of side h from the origin, each cut into 6 tetrahedra around its
// diagonal (Kuhn's: every cube the same way, so faces match across cubes),
// positive volume in TetGen's order. malloc'd *x ((nx+1)(ny+1)(nz+1) x 3)
// and *tet (6 nx ny nz x 4); false (tx_error) on memory or a bad size
bool tx_block_mesh(int nx, int ny, int nz, double h, double** x, int* nv, int** tet, int* ne);

#endif
