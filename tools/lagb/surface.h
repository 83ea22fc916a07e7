// Organ surfaces from a labelled volume by GTS: marching cubes
// (gts_isosurface_cartesian) on the organ's mask, lightly smoothed, then
// GTS edge-collapse decimation (Lindstrom-Turk volume-preserving cost) to a
// given number of triangles. Errors: false and one line in tx_error().
#ifndef TX_TOOLS_LAGB_SURFACE_H
#define TX_TOOLS_LAGB_SURFACE_H

#include "tools/lagb/mesh.h"
#include "tools/lagb/tetra.h"
#include "tools/lagb/volume.h"

enum { TX_LAGB_MAX_LABELS = 8 };

typedef struct tx_lagb_surface_def {
  int labels[TX_LAGB_MAX_LABELS];  // the voxel labels inside the surface
  int nlabels;
  int faces;                       // triangles to coarsen to (even: a closed surface has 3F = 2E)
} tx_lagb_surface_def;

typedef struct tx_lagb_surface_stats {
  int64_t voxels;     // voxels inside
  int mc_faces;       // triangles from marching cubes
  int dropped;        // small pieces left out (the largest is kept)
  int block;          // voxels averaged along each axis before marching cubes
  double seconds;     // time taken
} tx_lagb_surface_stats;

bool tx_lagb_surface(const tx_lagb_volume* v, const tx_lagb_surface_def* d, tx_trimesh* out,
                     tx_lagb_surface_stats* st);

// the simulation mesh of a soft organ: as the paper's PhysX soft bodies, a
// tetrahedral mesh apart from the surface that is drawn (and embedded in
// it). The surface is coarsened further until tetgen (-pYq1.6/10z: the
// coarse surface kept as the boundary, radius-edge ratio 1.6, dihedral angles
// of at least 10 degrees inside) gives about TARGET tetrahedra; writes
// PREFIX.node, PREFIX.ele, PREFIX.face.
typedef struct tx_lagb_tet_stats {
  int tets;            // tetrahedra written
  int hull_faces;      // triangles of the coarse surface they fill
  int runs;            // tetgen runs the search took
  char switches[64];   // the switches of the run kept
  double seconds;      // time taken
} tx_lagb_tet_stats;

bool tx_lagb_tets(const tx_trimesh* surface, int target, const char* prefix, const char* tetgen,
                  tx_lagb_tet_stats* st);

#endif
