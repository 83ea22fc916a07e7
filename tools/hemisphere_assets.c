// tactus-hemisphere-assets: the organ-hemisphere check's tetrahedra for a
// tool's tip (assets/hemisphere/). A tip's contact is small (a = sqrt(R d),
// about 1 mm on the 2 cm hemisphere), so the mesh is graded toward the pole:
// the surface is cut into rings whose spacing grows with the arc length s from
// the pole, h(s) = min(h_max, h0 + g s), the base into rings at the
// equator's spacing, and tetgen fills it with the same sizes at its vertices
// (-m). Level L halves every size of level L - 1.
#include "tools/lagb/mesh.h"
#include "tools/lagb/tetra.h"

#include "model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { LEVELS = 4, MAX_RINGS = 512 };

static const double PI = 3.14159265358979323846;
static const double RADIUS = 0.02;  // m, as studies/organ_hemisphere.c
// level 0's sizes: at the pole, growth per metre of arc, largest (m)
static const double H0 = 0.4e-3, GROW = 0.6, HMAX = 12e-3;
// tetgen: a PLC (-p), quality (radius-edge 1.5, dihedral >= 15 degrees), sizes
// from the vertices (-m), zero-based (-z), quiet
static const char* const SWITCHES = "-pq1.5/15mzQ";

typedef struct surface {
  tx_trimesh m;
  double* size;  // (nv) m
  int cap_v, cap_t;  // allocated
} surface;

static int add_vertex(surface* s, double x, double y, double z, double h) {
  if (s->m.nv == s->cap_v) {
    s->cap_v = 2 * s->cap_v + 64;
    s->m.v = realloc(s->m.v, sizeof(double) * 3 * (size_t)s->cap_v);
    s->size = realloc(s->size, sizeof(double) * (size_t)s->cap_v);
    if (!s->m.v || !s->size) exit((fprintf(stderr, "tactus-hemisphere-assets: out of memory\n"), 1));
  }
  double* p = s->m.v + 3 * s->m.nv;
  p[0] = x, p[1] = y, p[2] = z;
  s->size[s->m.nv] = h;
  return s->m.nv++;
}

static void add_triangle(surface* s, int a, int b, int c) {
  if (s->m.nt == s->cap_t) {
    s->cap_t = 2 * s->cap_t + 64;
    s->m.t = realloc(s->m.t, sizeof(int) * 3 * (size_t)s->cap_t);
    if (!s->m.t) exit((fprintf(stderr, "tactus-hemisphere-assets: out of memory\n"), 1));
  }
  int* t = s->m.t + 3 * s->m.nt++;
  t[0] = a, t[1] = b, t[2] = c;
}

// a ring of n vertices at height y and radius rho, starting at angle `turn`
// of a step (rings alternate, so that the bands between them zip evenly);
// one vertex when rho is 0
typedef struct ring {
  int first, n;
} ring;

static ring make_ring(surface* s, double rho, double y, int n, double turn, double h) {
  ring r = {s->m.nv, rho > 0 ? n : 1};
  for (int k = 0; k < r.n; k++) {
    double a = 2 * PI * (k + turn) / r.n;
    add_vertex(s, rho * cos(a), y, rho * sin(a), h);
  }
  return r;
}

static double angle_of(const surface* s, int v, int wraps) {
  const double* p = s->m.v + 3 * v;
  double a = atan2(p[2], p[0]);
  if (a < 0) a += 2 * PI;
  return a + 2 * PI * wraps;
}

// triangles between ring a and the next ring b, by angle; the angle runs
// from +x toward +z, and a is nearer the pole (or the rim), so (a_i, a_i+1,
// b_j) faces outward
static void zip(surface* s, ring a, ring b) {
  if (a.n == 1 || b.n == 1) {
    ring fan = a.n == 1 ? b : a;
    int c = a.n == 1 ? a.first : b.first;
    for (int k = 0; k < fan.n; k++) {
      int u = fan.first + k, w = fan.first + (k + 1) % fan.n;
      if (a.n == 1) add_triangle(s, c, w, u);
      else add_triangle(s, u, w, c);
    }
    return;
  }
  // both rings' vertices in angle order from their first (their first is at
  // angle turn / n, the smallest): walk both, always advancing the one whose
  // next vertex comes first
  int i = 0, j = 0;
  while (i < a.n || j < b.n) {
    int ai = a.first + i % a.n, bj = b.first + j % b.n;
    double ta = angle_of(s, a.first + (i + 1) % a.n, (i + 1) / a.n);
    double tb = angle_of(s, b.first + (j + 1) % b.n, (j + 1) / b.n);
    if (j >= b.n || (i < a.n && ta < tb)) {
      add_triangle(s, ai, a.first + (i + 1) % a.n, bj);
      i++;
    } else {
      add_triangle(s, ai, b.first + (j + 1) % b.n, bj);
      j++;
    }
  }
}

// the closed hemisphere surface at level L: the cap's rings by arc length,
// then the base's from the rim inward
static bool build(int level, surface* s) {
  double scale = 1.0 / (1 << level), h0 = H0 * scale, grow = GROW, hmax = HMAX * scale;
  double arc = RADIUS * PI / 2, at[MAX_RINGS];
  int n = 0;
  at[n++] = 0;
  while (at[n - 1] < arc && n < MAX_RINGS) at[n] = at[n - 1] + fmin(hmax, h0 + grow * scale * at[n - 1]), n++;
  if (n == MAX_RINGS) return tx_set_error("level %d: more than %d rings", level, MAX_RINGS), false;
  ring prev = {0, 0};
  double h = 0;
  for (int k = 0; k < n; k++) {
    double sk = at[k] * arc / at[n - 1], th = sk / RADIUS;  // stretched so that the last ring is the equator
    h = fmin(hmax, h0 + grow * scale * sk);
    double rho = k == n - 1 ? RADIUS : RADIUS * sin(th), y = k == n - 1 ? 0 : RADIUS * cos(th);
    int count = (int)fmax(6, round(2 * PI * rho / h));
    ring r = make_ring(s, rho, y, count, 0.5 * (k % 2), h);
    if (k > 0) zip(s, prev, r);
    prev = r;
  }
  // the base at the equator's spacing
  for (int k = 1;; k++) {
    double rho = RADIUS - k * h;
    bool centre = rho < 0.5 * h;
    ring r = make_ring(s, centre ? 0 : rho, 0, (int)fmax(6, round(2 * PI * rho / h)), 0.5 * ((n - 1 + k) % 2), h);
    zip(s, prev, r);
    if (centre) break;
    prev = r;
  }
  return true;
}

int main(int argc, char** argv) {
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
    fprintf(argc < 2 ? stderr : stdout,
            "usage: tactus-hemisphere-assets OUTDIR [LEVEL ...]\n"
            "  writes OUTDIR/graded-L.node and .ele for each level L (0 to %d; default all): the 2 cm hemisphere,\n"
            "  graded toward its pole for a tool's tip; level 0's sizes %g mm at the pole, growing %g mm per mm\n"
            "  of arc, at most %g mm; each level halves them. tetgen %s (TACTUS_TETGEN overrides the program)\n",
            LEVELS - 1, H0 * 1e3, GROW, HMAX * 1e3, SWITCHES);
    return argc < 2 ? 2 : 0;
  }
  struct stat st;
  if (stat(argv[1], &st) != 0 || !S_ISDIR(st.st_mode))
    return fprintf(stderr, "tactus-hemisphere-assets: %s: not a folder\n", argv[1]), 2;
  bool want[LEVELS] = {argc == 2, argc == 2, argc == 2, argc == 2};
  for (int a = 2; a < argc; a++) {
    char* end;
    long l = strtol(argv[a], &end, 10);
    if (end == argv[a] || *end || l < 0 || l >= LEVELS)
      return fprintf(stderr, "tactus-hemisphere-assets: %s: expected a level from 0 to %d\n", argv[a], LEVELS - 1), 2;
    want[l] = true;
  }
  const char* tetgen = getenv("TACTUS_TETGEN");
#ifdef TX_TETGEN
  if (!tetgen) tetgen = TX_TETGEN;
#endif
  for (int level = 0; level < LEVELS; level++) {
    if (!want[level]) continue;
    surface s = {0};
    tx_trimesh_report r;
    char prefix[4200];
    snprintf(prefix, sizeof prefix, "%s/graded-%d", argv[1], level);
    int tets = 0;
    bool ok = build(level, &s) && tx_trimesh_inspect(&s.m, &r);
    if (ok && !tx_trimesh_report_ok(&r)) {
      tx_set_error("level %d: the surface is not closed, manifold and outward (%d holes, %d misoriented edges)", level,
                   r.boundary_edges, r.misoriented_edges);
      ok = false;
    }
    ok = ok && tx_lagb_tetgen_sized(&s.m, s.size, prefix, SWITCHES, tetgen, &tets);
    if (ok) {
      // the .face file is not read by the study: the boundary is found from the tetrahedra
      char face[4300];
      snprintf(face, sizeof face, "%s.face", prefix);
      remove(face);
      printf("%s.node/.ele: level %d, %d surface vertices, %d tetrahedra\n", prefix, level, s.m.nv, tets);
    }
    tx_trimesh_free(&s.m);
    free(s.size);
    if (!ok) return fprintf(stderr, "tactus-hemisphere-assets: %s\n", tx_error()), 1;
  }
  return 0;
}
