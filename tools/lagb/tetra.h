// Tetrahedra by the tetgen program (TetGen 1.5), run as a child process with
// its output kept for the error line. Errors: false and one line in tx_error().
#ifndef TX_TOOLS_LAGB_TETRA_H
#define TX_TOOLS_LAGB_TETRA_H

#include "tools/lagb/mesh.h"

// runs tetgen SWITCHES on the closed surface S and writes PREFIX.node,
// PREFIX.ele and PREFIX.face (all three or none); *tets: how many. Switches
// must hold -z (zero-based numbering, as Bullet reads it). A run that takes
// over a minute is stopped.
bool tx_lagb_tetgen(const tx_trimesh* s, const char* prefix, const char* switches, const char* tetgen, int* tets);
// the same with a size for each vertex of S (m), which switches with -m make
// tetgen grade the tetrahedra by (its .mtr file)
bool tx_lagb_tetgen_sized(const tx_trimesh* s, const double* sizes, const char* prefix, const char* switches,
                          const char* tetgen, int* tets);

#endif
