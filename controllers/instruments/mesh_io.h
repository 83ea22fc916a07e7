// Triangle meshes read with assimp: every mesh the project reads goes through
// tx_mesh_load (docs/instruments.md, "Meshes"). Built with TX_WITH_ASSIMP.
#ifndef TX_CONTROLLERS_INSTRUMENTS_MESH_IO_H
#define TX_CONTROLLERS_INSTRUMENTS_MESH_IO_H

#include <stdbool.h>

// vertices in the file's units and frame (node transforms applied), triangles
// as vertex indices, counter-clockwise as the file gives them
typedef struct tx_mesh {
  double* vertices; // 3 * nvertices
  int* triangles; // 3 * ntriangles
  int nvertices, ntriangles;
} tx_mesh;

// Reads every mesh of PATH (OBJ, STL, PLY, ... whatever assimp reads) into
// one triangle mesh. False, with "PATH: why" in tx_error(), for a file that
// is missing, unreadable, malformed or has no faces; *out is then empty.
bool tx_mesh_load(const char* path, tx_mesh* out);
void tx_mesh_free(tx_mesh* m);

// signed volume by the divergence theorem: positive for a closed mesh wound
// outwards
double tx_mesh_volume(const tx_mesh* m);

#endif
