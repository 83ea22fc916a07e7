// The surface of a cut organ: its live tetrahedra's boundary as rows and
// triangles, and the checks a reader relies on (removal.h).
#include "removal.h"

#include "../../model/error.h"

#include <stdlib.h>

int tx_compact_surface(const int* faces, int nf, int32_t* row_of, int32_t* node_of, int32_t* tri) {
  int rows = 0;
  for (int f = 0; f < 3 * nf; f++) {
    int n = faces[f];
    if (row_of[n] < 0) row_of[n] = rows, node_of[rows++] = n;
    tri[f] = row_of[n];
  }
  for (int r = 0; r < rows; r++) row_of[node_of[r]] = -1; // scratch left as found
  return rows;
}

int tx_cut_surface(const int* faces, int nf, const double* pos, int32_t* row_of, int32_t* node_of, float* x, int32_t* tri) {
  int rows = tx_compact_surface(faces, nf, row_of, node_of, tri);
  for (int r = 0; r < rows; r++)
    for (int a = 0; a < 3; a++) x[3 * r + a] = (float)pos[3 * node_of[r] + a];
  return rows;
}

static int cmp_u64(const void* a, const void* b) {
  uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
  return (x > y) - (x < y);
}

bool tx_surface_check(const int32_t* tri, int nt, int rows, const int32_t* node_of, int nodes, uint64_t* keys, int32_t* seen,
                      tx_surface_report* out) {
  *out = (tx_surface_report){.rows = rows, .triangles = nt};
  for (int r = 0; r < rows; r++) seen[r] = 0;
  int nk = 0;
  for (int t = 0; t < nt; t++) {
    const int32_t* v = tri + 3 * t;
    bool in = true;
    for (int k = 0; k < 3; k++) in = in && v[k] >= 0 && v[k] < rows;
    if (!in) {
      out->out_of_range++;
      continue;
    }
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) out->degenerate++;
    for (int k = 0; k < 3; k++) {
      seen[v[k]] = 1;
      // the edge v[k] -> v[k+1], undirected key and its direction in bit 0
      uint64_t a = (uint32_t)v[k], b = (uint32_t)v[(k + 1) % 3];
      keys[nk++] = a < b ? (a << 33) | (b << 1) : (b << 33) | (a << 1) | 1u;
    }
  }
  for (int r = 0; r < rows; r++) out->unreferenced += !seen[r];
  qsort(keys, (size_t)nk, sizeof *keys, cmp_u64);
  for (int i = 0; i < nk;) {
    int j = i, fwd = 0;
    for (; j < nk && keys[j] >> 1 == keys[i] >> 1; j++) fwd += !(keys[j] & 1u);
    int back = (j - i) - fwd;
    out->edges++;
    if (fwd != back) out->open_edges++;
    if (j - i > 2) out->nonmanifold_edges++;
    i = j;
  }
  if (node_of) {
    for (int n = 0; n < nodes; n++) seen[n] = 0;
    for (int r = 0; r < rows; r++) {
      int n = node_of[r];
      if (n < 0 || n >= nodes || seen[n]++) out->doubled++;
    }
  }
  return out->out_of_range == 0 && out->degenerate == 0 && out->unreferenced == 0 && out->doubled == 0 &&
         out->open_edges == 0;
}

bool tx_block_mesh(int nx, int ny, int nz, double h, double** x, int* nv, int** tet, int* ne) {
  if (nx < 1 || ny < 1 || nz < 1 || nx > 1000 || ny > 1000 || nz > 1000 || !(h > 0))
    return tx_set_error("block: %d x %d x %d cubes of %g m: need 1 to 1000 a side and h > 0", nx, ny, nz, h), false;
  int n = (nx + 1) * (ny + 1) * (nz + 1), m = 6 * nx * ny * nz;
  *x = malloc(sizeof(double) * 3 * (size_t)n);
  *tet = malloc(sizeof(int) * 4 * (size_t)m);
  if (!*x || !*tet) {
    free(*x), free(*tet), *x = NULL, *tet = NULL;
    return tx_set_error("block: out of memory for %d tetrahedra", m), false;
  }
#define NODE(i, j, k) ((i) + (nx + 1) * ((j) + (ny + 1) * (k)))
  for (int k = 0; k <= nz; k++)
    for (int j = 0; j <= ny; j++)
      for (int i = 0; i <= nx; i++) {
        double* p = *x + 3 * NODE(i, j, k);
        p[0] = i * h, p[1] = j * h, p[2] = k * h;
      }
  static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int e = 0;
  for (int k = 0; k < nz; k++)
    for (int j = 0; j < ny; j++)
      for (int i = 0; i < nx; i++)
        for (int p = 0; p < 6; p++) {
          // from the cube's corner (0,0,0) to (1,1,1) one axis at a time, in this order
          int c[3] = {0, 0, 0}, *t = *tet + 4 * e++;
          t[0] = NODE(i, j, k);
          for (int s = 0; s < 3; s++) {
            c[perm[p][s]] = 1;
            t[s + 1] = NODE(i + c[0], j + c[1], k + c[2]);
          }
          if (p == 1 || p == 2 || p == 5) { // odd permutations: the other turn
            int w = t[1];
            t[1] = t[2], t[2] = w;
          }
        }
#undef NODE
  *nv = n, *ne = m;
  return true;
}
