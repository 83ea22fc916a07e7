// Triangle surfaces and tetrahedral meshes of the LAGB asset pipeline: read
// and write them (OBJ; TetGen .node/.ele with -z numbering) and inspect them
// (closed, manifold, consistently oriented; inverted tetrahedra, dihedral
// angles). Plain C with no library behind it, so the checks are unit-tested
// on their own. Errors: false or -1 and one line in tx_error().
#ifndef TX_TOOLS_LAGB_MESH_H
#define TX_TOOLS_LAGB_MESH_H

#include <stdbool.h>

typedef struct tx_trimesh {
  int nv;     // vertices
  int nt;     // triangles
  double* v;  // positions (nv x 3), m
  int* t;     // vertex indices (nt x 3), zero-based, counter-clockwise seen from outside
} tx_trimesh;

typedef struct tx_tetmesh {
  int nv;     // nodes
  int ne;     // tetrahedra
  double* v;  // positions (nv x 3), m
  int* e;     // node indices (ne x 4), zero-based
} tx_tetmesh;

// what inspecting a surface finds; a closed, manifold, consistently oriented
// surface has every count zero and volume > 0 (outward normals)
typedef struct tx_trimesh_report {
  int boundary_edges;     // edges with one triangle: holes
  int nonmanifold_edges;  // edges with three or more triangles
  int misoriented_edges;  // edges whose two triangles run them the same way
  int nonmanifold_verts;  // vertices whose triangles do not form one fan
  int degenerate;         // triangles with a repeated vertex or zero area
  int components;         // connected pieces
  int euler;              // V - E + F (2 for each closed genus-0 piece)
  double volume;          // signed enclosed volume, m^3 (> 0: normals point out)
  double area;            // m^2
} tx_trimesh_report;

typedef struct tx_tetmesh_report {
  int inverted;           // tetrahedra of the wrong orientation
  int degenerate;         // tetrahedra of zero volume
  double volume;          // sum of |volume|, m^3
  double min_dihedral;    // smallest dihedral angle over all tetrahedra, degrees
  double max_dihedral;    // largest, degrees
} tx_tetmesh_report;

void tx_trimesh_free(tx_trimesh* m);
void tx_tetmesh_free(tx_tetmesh* m);

// OBJ: "v x y z" and "f a b c" (polygons are split into fans; "a/b/c"
// forms and negative indices are read). Refuses a file with no faces, an
// index out of range or a number that is not finite, naming the line.
bool tx_trimesh_read_obj(const char* path, tx_trimesh* m);
// writes PATH.part and renames it over PATH, so a failed run leaves nothing
bool tx_trimesh_write_obj(const tx_trimesh* m, const char* path, const char* comment);
// OFF, TetGen's simplest input
bool tx_trimesh_write_off(const tx_trimesh* m, const char* path);

// TetGen 1.5 .node and .ele (written with -z: the first index is 0)
bool tx_tetmesh_read(const char* node_path, const char* ele_path, tx_tetmesh* m);

bool tx_trimesh_inspect(const tx_trimesh* m, tx_trimesh_report* r);
// orientation: TetGen's, where the signed volume (b-a).((c-a)x(d-a))/6 of each
// tetrahedron (a, b, c, d) is positive; the sign is named here once
#define TX_TETGEN_ORIENTATION 1
void tx_tetmesh_inspect(const tx_tetmesh* m, tx_tetmesh_report* r);
// true when the report says closed, manifold, consistently oriented, outward
bool tx_trimesh_report_ok(const tx_trimesh_report* r);

// the winding number of a closed surface around P: 1 inside, 0 outside (the
// solid angle of its triangles over 4 pi; van Oosterom and Strackee's formula)
double tx_trimesh_winding(const tx_trimesh* m, const double p[3]);

// the six dihedral angles of one tetrahedron, degrees
void tx_tet_dihedrals(const double a[3], const double b[3], const double c[3], const double d[3], double out[6]);

#endif
