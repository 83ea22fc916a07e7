// An instrument description whole: its URDF (urdf.h) and the visual mesh of
// each link (mesh_io.h), read and checked at configure time. Built with
// TX_WITH_URDFDOM and TX_WITH_ASSIMP.
#ifndef TX_CONTROLLERS_INSTRUMENTS_INSTRUMENT_DESC_H
#define TX_CONTROLLERS_INSTRUMENTS_INSTRUMENT_DESC_H

#include "mesh_io.h"
#include "urdf.h"

typedef struct tx_instrument_desc {
  tx_urdf* urdf;
  tx_mesh* meshes; // one per link, empty where the link has none
} tx_instrument_desc;

// NULL, with one line "URDF: element: why" (or "URDF: link 'L' <visual> <mesh>:
// MESH: why") in tx_error(), for anything tx_urdf_load refuses and for a mesh
// that is missing, unreadable or has no faces.
tx_instrument_desc* tx_instrument_desc_load(const char* path);
void tx_instrument_desc_free(tx_instrument_desc* d);

// total mass (kg) and the number of revolute joints
double tx_instrument_desc_mass(const tx_instrument_desc* d);
int tx_instrument_desc_jaws(const tx_instrument_desc* d);

#endif
