// Surfaces and tetrahedral meshes: read, write, inspect (see mesh.h).
#include "tools/lagb/mesh.h"

#include "model/error.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tx_trimesh_free(tx_trimesh* m) {
  free(m->v);
  free(m->t);
  *m = (tx_trimesh){0};
}

void tx_tetmesh_free(tx_tetmesh* m) {
  free(m->v);
  free(m->e);
  *m = (tx_tetmesh){0};
}

// grow an array of n elements of size sz to hold at least need
static bool grow(void** p, int* cap, int need, size_t sz) {
  if (need <= *cap) return true;
  int c = *cap ? *cap : 256;
  while (c < need) c *= 2;
  void* q = realloc(*p, (size_t)c * sz);
  if (!q) return false;
  *p = q;
  *cap = c;
  return true;
}

// one OBJ index ("12", "12/3", "-1//4"): zero-based, or -1 when it is not one
static int obj_index(const char* tok, int nv) {
  char* end;
  errno = 0;
  long i = strtol(tok, &end, 10);
  if (end == tok || errno || (*end && *end != '/') || i == 0) return -1;
  long z = i > 0 ? i - 1 : nv + i;
  return z >= 0 && z < nv ? (int)z : -1;
}

bool tx_trimesh_read_obj(const char* path, tx_trimesh* m) {
  *m = (tx_trimesh){0};
  FILE* f = fopen(path, "r");
  if (!f) {
    tx_set_error("%s: %s", path, strerror(errno));
    return false;
  }
  int vcap = 0, tcap = 0, line = 0;
  char buf[4096];
  bool ok = true;
  while (ok && fgets(buf, sizeof buf, f)) {
    line++;
    if (!strchr(buf, '\n') && !feof(f)) {
      tx_set_error("%s:%d: line too long", path, line);
      ok = false;
      break;
    }
    char* s = buf;
    while (*s == ' ' || *s == '\t') s++;
    if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
      double x[3];
      char* p = s + 1;
      for (int k = 0; k < 3 && ok; k++) {
        char* end;
        x[k] = strtod(p, &end);
        if (end == p || !isfinite(x[k])) {
          tx_set_error("%s:%d: a vertex needs three finite numbers", path, line);
          ok = false;
        }
        p = end;
      }
      if (!ok) break;
      if (!grow((void**)&m->v, &vcap, m->nv + 1, 3 * sizeof(double))) {
        tx_set_error("%s: out of memory", path);
        ok = false;
        break;
      }
      memcpy(m->v + 3 * m->nv, x, sizeof x);
      m->nv++;
    } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
      int idx[64], n = 0;
      for (char* tok = strtok(s + 1, " \t\r\n"); tok; tok = strtok(NULL, " \t\r\n")) {
        if (n == 64) {
          tx_set_error("%s:%d: a face of more than 64 vertices", path, line);
          ok = false;
          break;
        }
        idx[n] = obj_index(tok, m->nv);
        if (idx[n] < 0) {
          tx_set_error("%s:%d: face index '%s' is not a vertex defined before it", path, line, tok);
          ok = false;
          break;
        }
        n++;
      }
      if (!ok) break;
      if (n < 3) {
        tx_set_error("%s:%d: a face needs at least three vertices", path, line);
        ok = false;
        break;
      }
      if (!grow((void**)&m->t, &tcap, m->nt + n - 2, 3 * sizeof(int))) {
        tx_set_error("%s: out of memory", path);
        ok = false;
        break;
      }
      for (int k = 1; k + 1 < n; k++) {
        int* t = m->t + 3 * m->nt++;
        t[0] = idx[0], t[1] = idx[k], t[2] = idx[k + 1];
      }
    }
  }
  fclose(f);
  if (ok && m->nt == 0) {
    tx_set_error("%s: no faces", path);
    ok = false;
  }
  if (!ok) tx_trimesh_free(m);
  return ok;
}

// write to PATH.part through fn, then rename over PATH
static bool write_aside(const char* path, bool (*fn)(FILE*, const void*, const void*), const void* a, const void* b) {
  char part[4096];
  if (snprintf(part, sizeof part, "%s.part", path) >= (int)sizeof part) {
    tx_set_error("%s: path too long", path);
    return false;
  }
  FILE* f = fopen(part, "w");
  if (!f) {
    tx_set_error("%s: %s", path, strerror(errno));
    return false;
  }
  bool ok = fn(f, a, b);
  ok = (fclose(f) == 0) && ok;
  if (!ok || rename(part, path) != 0) {
    tx_set_error("%s: write failed", path);
    remove(part);
    return false;
  }
  return true;
}

static bool obj_body(FILE* f, const void* mp, const void* cp) {
  const tx_trimesh* m = mp;
  const char* comment = cp;
  if (comment && *comment) fprintf(f, "# %s\n", comment);
  fprintf(f, "# %d vertices, %d triangles, metres, counter-clockwise seen from outside\n", m->nv, m->nt);
  for (int i = 0; i < m->nv; i++) fprintf(f, "v %.6f %.6f %.6f\n", m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
  for (int i = 0; i < m->nt; i++) fprintf(f, "f %d %d %d\n", m->t[3 * i] + 1, m->t[3 * i + 1] + 1, m->t[3 * i + 2] + 1);
  return !ferror(f);
}

bool tx_trimesh_write_obj(const tx_trimesh* m, const char* path, const char* comment) {
  return write_aside(path, obj_body, m, comment);
}

static bool off_body(FILE* f, const void* mp, const void* unused) {
  const tx_trimesh* m = mp;
  fprintf(f, "OFF\n%d %d 0\n", m->nv, m->nt);
  for (int i = 0; i < m->nv; i++) fprintf(f, "%.9g %.9g %.9g\n", m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
  for (int i = 0; i < m->nt; i++) fprintf(f, "3 %d %d %d\n", m->t[3 * i], m->t[3 * i + 1], m->t[3 * i + 2]);
  return !ferror(f);
}

bool tx_trimesh_write_off(const tx_trimesh* m, const char* path) { return write_aside(path, off_body, m, NULL); }

// the next line that is not blank or a comment, split into at most n numbers
static int tet_line(FILE* f, double* x, int n, int* line) {
  char buf[1024];
  while (fgets(buf, sizeof buf, f)) {
    (*line)++;
    char* h = strchr(buf, '#');
    if (h) *h = 0;
    char* p = buf;
    int k = 0;
    while (k < n) {
      char* end;
      double v = strtod(p, &end);
      if (end == p) break;
      x[k++] = v;
      p = end;
    }
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    if (k == 0 && *p) return -1; // text that is not a number
    if (k > 0) return k;
  }
  return 0;
}

bool tx_tetmesh_read(const char* node_path, const char* ele_path, tx_tetmesh* m) {
  *m = (tx_tetmesh){0};
  FILE* f = fopen(node_path, "r");
  if (!f) {
    tx_set_error("%s: %s", node_path, strerror(errno));
    return false;
  }
  double h[8];
  int line = 0, k = tet_line(f, h, 4, &line);
  if (k < 2 || h[0] < 4 || h[0] > 1e8 || h[1] != 3) {
    fclose(f);
    tx_set_error("%s:%d: expected the header 'N 3 attributes markers'", node_path, line);
    return false;
  }
  m->nv = (int)h[0];
  m->v = malloc((size_t)m->nv * 3 * sizeof(double));
  bool ok = m->v != NULL;
  for (int i = 0; ok && i < m->nv; i++) {
    double x[8];
    k = tet_line(f, x, 4, &line);
    if (k < 4 || x[0] != i || !isfinite(x[1]) || !isfinite(x[2]) || !isfinite(x[3])) {
      tx_set_error("%s:%d: expected node %d (zero-based, TetGen -z) and three finite coordinates", node_path, line, i);
      ok = false;
    } else {
      memcpy(m->v + 3 * i, x + 1, 3 * sizeof(double));
    }
  }
  fclose(f);
  if (!ok) {
    tx_tetmesh_free(m);
    return false;
  }
  f = fopen(ele_path, "r");
  if (!f) {
    tx_set_error("%s: %s", ele_path, strerror(errno));
    tx_tetmesh_free(m);
    return false;
  }
  line = 0;
  k = tet_line(f, h, 3, &line);
  if (k < 2 || h[0] < 1 || h[0] > 1e8 || h[1] != 4) {
    fclose(f);
    tx_set_error("%s:%d: expected the header 'E 4 attributes' (linear tetrahedra)", ele_path, line);
    tx_tetmesh_free(m);
    return false;
  }
  m->ne = (int)h[0];
  m->e = malloc((size_t)m->ne * 4 * sizeof(int));
  ok = m->e != NULL;
  for (int i = 0; ok && i < m->ne; i++) {
    double x[8];
    k = tet_line(f, x, 5, &line);
    ok = k >= 5 && x[0] == i;
    for (int j = 0; ok && j < 4; j++) {
      ok = x[1 + j] >= 0 && x[1 + j] < m->nv && x[1 + j] == floor(x[1 + j]);
      if (ok) m->e[4 * i + j] = (int)x[1 + j];
    }
    if (!ok) tx_set_error("%s:%d: expected tetrahedron %d and four node indices below %d", ele_path, line, i, m->nv);
  }
  fclose(f);
  if (!ok) tx_tetmesh_free(m);
  return ok;
}

typedef struct half {
  uint64_t key;  // min << 32 | max
  int from, to;  // the direction the triangle runs it
  int tri;
} half;

static int half_cmp(const void* a, const void* b) {
  const half* x = a;
  const half* y = b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  return x->tri - y->tri;
}

static uint64_t edge_key(int a, int b) {
  uint32_t lo = (uint32_t)(a < b ? a : b), hi = (uint32_t)(a < b ? b : a);
  return (uint64_t)lo << 32 | hi;
}

static int find_root(int* parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

static void sub(const double* a, const double* b, double* o) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static void cross(const double* a, const double* b, double* o) {
  o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

bool tx_trimesh_inspect(const tx_trimesh* m, tx_trimesh_report* r) {
  *r = (tx_trimesh_report){0};
  half* h = malloc((size_t)m->nt * 3 * sizeof(half));
  int* parent = malloc((size_t)(m->nv > 0 ? m->nv : 1) * sizeof(int));
  int* fan = calloc((size_t)(m->nv > 0 ? m->nv : 1), sizeof(int));     // triangles around each vertex
  int* walked = calloc((size_t)(m->nv > 0 ? m->nv : 1), sizeof(int));  // reached by one fan walk
  if (!h || !parent || !fan || !walked) {
    free(h), free(parent), free(fan), free(walked);
    tx_set_error("out of memory inspecting a surface of %d triangles", m->nt);
    return false;
  }
  for (int i = 0; i < m->nv; i++) parent[i] = i;
  // volume, area, degenerate triangles, connectivity
  for (int i = 0; i < m->nt; i++) {
    const int* t = m->t + 3 * i;
    const double *a = m->v + 3 * t[0], *b = m->v + 3 * t[1], *c = m->v + 3 * t[2];
    double ab[3], ac[3], n[3];
    sub(b, a, ab), sub(c, a, ac), cross(ab, ac, n);
    double area = 0.5 * sqrt(dot(n, n));
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area == 0) r->degenerate++;
    r->area += area;
    double bc[3];
    cross(b, c, bc);
    r->volume += dot(a, bc) / 6.0;
    for (int k = 0; k < 3; k++) {
      int from = t[k], to = t[(k + 1) % 3];
      h[3 * i + k] = (half){edge_key(from, to), from, to, i};
      fan[from]++;
      int x = find_root(parent, from), y = find_root(parent, to);
      if (x != y) parent[x] = y;
    }
  }
  qsort(h, (size_t)m->nt * 3, sizeof(half), half_cmp);
  int edges = 0;
  for (int i = 0; i < m->nt * 3;) {
    int j = i;
    while (j < m->nt * 3 && h[j].key == h[i].key) j++;
    int n = j - i;
    edges++;
    if (n == 1) r->boundary_edges++;
    else if (n > 2) r->nonmanifold_edges++;
    else if (h[i].from == h[i + 1].from) r->misoriented_edges++;
    i = j;
  }
  // a vertex is manifold when one walk from triangle to neighbouring triangle
  // around it visits all its triangles (two cones touching at a tip fail)
  if (r->boundary_edges == 0 && r->nonmanifold_edges == 0 && r->misoriented_edges == 0) {
    int* start = calloc((size_t)m->nv + 1, sizeof(int));
    int* ring = malloc((size_t)m->nt * 3 * 2 * sizeof(int));  // (next, prev) of each corner
    if (!start || !ring) {
      free(start), free(ring), free(h), free(parent), free(fan), free(walked);
      tx_set_error("out of memory inspecting a surface of %d triangles", m->nt);
      return false;
    }
    for (int i = 0; i < m->nv; i++) start[i + 1] = start[i] + fan[i];
    for (int i = 0; i < m->nt; i++)
      for (int k = 0; k < 3; k++) {
        int v = m->t[3 * i + k], at = start[v] + walked[v]++;
        ring[2 * at] = m->t[3 * i + (k + 1) % 3];
        ring[2 * at + 1] = m->t[3 * i + (k + 2) % 3];
      }
    for (int v = 0; v < m->nv; v++) {
      int n = fan[v];
      if (n == 0) continue;
      const int* rv = ring + 2 * start[v];
      int cur = rv[0], steps = 1;
      while (cur != rv[1] && steps <= n) {  // the triangle whose prev is cur comes next
        int j = 0;
        while (j < n && rv[2 * j + 1] != cur) j++;
        if (j == n) break;
        cur = rv[2 * j];
        steps++;
      }
      if (steps != n || cur != rv[1]) r->nonmanifold_verts++;
    }
    free(start), free(ring);
  }
  free(walked);
  for (int i = 0; i < m->nv; i++)
    if (fan[i] > 0 && find_root(parent, i) == i) r->components++;
  r->euler = m->nv - edges + m->nt;
  int used = 0;
  for (int i = 0; i < m->nv; i++) used += fan[i] > 0;
  r->euler -= m->nv - used;  // vertices no triangle uses do not count
  free(h), free(parent), free(fan);
  return true;
}

bool tx_trimesh_report_ok(const tx_trimesh_report* r) {
  return r->boundary_edges == 0 && r->nonmanifold_edges == 0 && r->misoriented_edges == 0 &&
         r->nonmanifold_verts == 0 && r->degenerate == 0 && r->volume > 0;
}

void tx_tet_dihedrals(const double a[3], const double b[3], const double c[3], const double d[3], double out[6]) {
  const double* p[4] = {a, b, c, d};
  // n[i]: normal of the face opposite vertex i, pointing away from it
  double n[4][3];
  for (int i = 0; i < 4; i++) {
    const double *q0 = p[(i + 1) % 4], *q1 = p[(i + 2) % 4], *q2 = p[(i + 3) % 4];
    double u[3], w[3], to[3];
    sub(q1, q0, u), sub(q2, q0, w), cross(u, w, n[i]);
    sub(p[i], q0, to);
    if (dot(n[i], to) > 0) n[i][0] = -n[i][0], n[i][1] = -n[i][1], n[i][2] = -n[i][2];
    double l = sqrt(dot(n[i], n[i]));
    if (l > 0) n[i][0] /= l, n[i][1] /= l, n[i][2] /= l;
  }
  // the edge shared by the faces opposite i and j: its dihedral angle is pi
  // less the angle between their outward normals
  int k = 0;
  for (int i = 0; i < 4; i++)
    for (int j = i + 1; j < 4; j++) {
      double cs = dot(n[i], n[j]);
      cs = cs > 1 ? 1 : cs < -1 ? -1 : cs;
      out[k++] = 180.0 - acos(cs) * 180.0 / M_PI;
    }
}

void tx_tetmesh_inspect(const tx_tetmesh* m, tx_tetmesh_report* r) {
  *r = (tx_tetmesh_report){.min_dihedral = 180, .max_dihedral = 0};
  for (int i = 0; i < m->ne; i++) {
    const int* e = m->e + 4 * i;
    const double *a = m->v + 3 * e[0], *b = m->v + 3 * e[1], *c = m->v + 3 * e[2], *d = m->v + 3 * e[3];
    double ab[3], ac[3], ad[3], x[3];
    sub(b, a, ab), sub(c, a, ac), sub(d, a, ad), cross(ac, ad, x);
    double vol = dot(ab, x) / 6.0;
    r->volume += fabs(vol);
    if (vol == 0) {
      r->degenerate++;
      continue;
    }
    if ((vol > 0) != (TX_TETGEN_ORIENTATION > 0)) r->inverted++;
    double ang[6];
    tx_tet_dihedrals(a, b, c, d, ang);
    for (int k = 0; k < 6; k++) {
      if (ang[k] < r->min_dihedral) r->min_dihedral = ang[k];
      if (ang[k] > r->max_dihedral) r->max_dihedral = ang[k];
    }
  }
}

double tx_trimesh_winding(const tx_trimesh* m, const double p[3]) {
  double w = 0;
  for (int i = 0; i < m->nt; i++) {
    double a[3], b[3], c[3], bc[3];
    sub(m->v + 3 * m->t[3 * i], p, a), sub(m->v + 3 * m->t[3 * i + 1], p, b), sub(m->v + 3 * m->t[3 * i + 2], p, c);
    double la = sqrt(dot(a, a)), lb = sqrt(dot(b, b)), lc = sqrt(dot(c, c));
    cross(b, c, bc);
    double num = dot(a, bc);
    double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    w += 2 * atan2(num, den);
  }
  return w / (4 * M_PI);
}
