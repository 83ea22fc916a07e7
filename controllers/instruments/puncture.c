// Punctures from the skin's publishes (puncture.h).
#include "puncture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// the point of triangle abc nearest p, as barycentric coordinates (Ericson,
// Real-Time Collision Detection, 5.1.5: by the Voronoi regions of the corners and edges)
static void closest_bary(const double a[3], const double b[3], const double c[3], const double p[3], double w[3]) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k], bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) { w[0] = 1, w[1] = w[2] = 0; return; }
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) { w[1] = 1, w[0] = w[2] = 0; return; }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    w[0] = 1 - v, w[1] = v, w[2] = 0;
    return;
  }
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) { w[2] = 1, w[0] = w[1] = 0; return; }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double u = d2 / (d2 - d6);
    w[0] = 1 - u, w[2] = u, w[1] = 0;
    return;
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    double u = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    w[1] = 1 - u, w[2] = u, w[0] = 0;
    return;
  }
  double den = 1 / (va + vb + vc);
  w[1] = vb * den, w[2] = vc * den, w[0] = 1 - w[1] - w[2];
}

static void corner(const float* x, int32_t i, double o[3]) {
  for (int k = 0; k < 3; k++) o[k] = x[3 * i + k];
}

// the nearest point of the triangles whose first particle is in component
// `patch` of `root` (all of them when root is NULL)
static bool valid(const int32_t* v, int nx) {
  return v[0] >= 0 && v[1] >= 0 && v[2] >= 0 && v[0] < nx && v[1] < nx && v[2] < nx;
}

// the longest edge from a triangle's first corner, over all the triangles:
// no point of a triangle is farther than that from its first corner
static double triangles_reach(const float* x, int nx, const int32_t* tri, int ntri) {
  double reach2 = 0;
  for (int t = 0; t < ntri; t++) {
    const int32_t* v = tri + 3 * t;
    if (!valid(v, nx)) continue;
    const float *a = x + 3 * v[0], *b = x + 3 * v[1], *c = x + 3 * v[2];
    double ab = 0, ac = 0;
    for (int k = 0; k < 3; k++) ab += (double)(b[k] - a[k]) * (b[k] - a[k]), ac += (double)(c[k] - a[k]) * (c[k] - a[k]);
    reach2 = fmax(reach2, fmax(ab, ac));
  }
  return sqrt(reach2);
}

// reach: triangles_reach of these triangles. A triangle whose first corner
// is farther from p than reach plus the best distance so far cannot be
// nearer: it is skipped before its closest point is sought (the answer is
// the same)
static int nearest_of(const float* x, int nx, const int32_t* tri, int ntri, const int32_t* root, int32_t patch,
                      double reach, const double p[3], double bary[3], double point[3]) {
  double bound2 = INFINITY;
  int best = -1;
  double best_d2 = INFINITY;
  for (int t = 0; t < ntri; t++) {
    const int32_t* v = tri + 3 * t;
    if (!valid(v, nx)) continue;
    if (root && root[v[0]] != patch) continue;
    const float* f = x + 3 * v[0];
    double e0 = f[0] - p[0], e1 = f[1] - p[1], e2 = f[2] - p[2];
    if (e0 * e0 + e1 * e1 + e2 * e2 > bound2) continue;
    double a[3], b[3], c[3], w[3], q[3], d2 = 0;
    corner(x, v[0], a), corner(x, v[1], b), corner(x, v[2], c);
    closest_bary(a, b, c, p, w);
    for (int k = 0; k < 3; k++) q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k], d2 += (q[k] - p[k]) * (q[k] - p[k]);
    if (d2 < best_d2) {
      best_d2 = d2, best = t;
      memcpy(bary, w, sizeof w);
      memcpy(point, q, sizeof q);
      bound2 = (sqrt(d2) + reach) * (sqrt(d2) + reach) * (1 + 1e-9);
    }
  }
  return best;
}

int tx_nearest_triangle(const float* x, int nx, const int32_t* tri, int ntri, const double p[3], double bary[3],
                        double point[3]) {
  return nearest_of(x, nx, tri, ntri, NULL, 0, triangles_reach(x, nx, tri, ntri), p, bary, point);
}

static int32_t find(int32_t* up, int32_t i) {
  while (up[i] != i) up[i] = up[up[i]], i = up[i];
  return i;
}

// which side of the patch's sheet p is on: the sign of the nearest
// triangle's normal (by its corners' order) dotted with p - that point
static int side_of(const float* x, int nx, const int32_t* tri, int ntri, const int32_t* root, int32_t patch,
                   double reach, const double p[3], double* dist) {
  double bary[3], q[3], a[3], b[3], c[3], ab[3], ac[3];
  int t = nearest_of(x, nx, tri, ntri, root, patch, reach, p, bary, q);
  if (t < 0) return 0;
  corner(x, tri[3 * t], a), corner(x, tri[3 * t + 1], b), corner(x, tri[3 * t + 2], c);
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k];
  double n[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
  double len = sqrt(dot(n, n)), d = (n[0] * (p[0] - q[0]) + n[1] * (p[1] - q[1]) + n[2] * (p[2] - q[2])) / len;
  if (!(len > 0) || !isfinite(d)) return 0;
  *dist = fabs(d);
  return d >= 0 ? 1 : -1;
}

// the particles' components joined by the live triangles (up[i]: particle
// i's), and the patch: the one the most triangles join; false without room
static bool components(const int32_t* tri, int nx, int ntri, int32_t* scratch, int nscratch, int32_t* patch) {
  if (!scratch || nscratch < 2 * nx || nx <= 0) return false;
  int32_t *up = scratch, *count = scratch + nx;
  for (int32_t i = 0; i < nx; i++) up[i] = i, count[i] = 0;
  for (int t = 0; t < ntri; t++) {
    const int32_t* v = tri + 3 * t;
    if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= nx || v[1] >= nx || v[2] >= nx) continue;
    int32_t r0 = find(up, v[0]), r1 = find(up, v[1]);
    up[r1] = r0;
    up[find(up, v[2])] = r0;
  }
  for (int32_t i = 0; i < nx; i++) up[i] = find(up, i);
  for (int t = 0; t < ntri; t++)
    if (tri[3 * t] >= 0 && tri[3 * t] < nx) count[up[tri[3 * t]]]++;
  *patch = 0;
  for (int32_t i = 0; i < nx; i++)
    if (count[i] > count[*patch]) *patch = i;
  return true;
}

bool tx_puncture_attached(int nx, const int32_t* tri, int ntri, int32_t* scratch, int nscratch, const int32_t v[3]) {
  int32_t patch;
  bool live = false;
  for (int t = 0; t < ntri && !live; t++) // the same three particles, in any turn of their order
    for (int r = 0; r < 3 && !live; r++)
      live = tri[3 * t] == v[r] && tri[3 * t + 1] == v[(r + 1) % 3] && tri[3 * t + 2] == v[(r + 2) % 3];
  if (!live || v[0] < 0 || v[0] >= nx) return false;
  return !components(tri, nx, ntri, scratch, nscratch, &patch) || scratch[v[0]] == patch;
}

int tx_puncture_hole(const float* x, int nx, const int32_t* tri, int ntri, const double (*arc)[3], int narc,
                     const double near_to[3], double within, const double (*taken)[3], int ntaken, double apart,
                     int32_t* scratch, int nscratch, double bary[3], double point[3], double on_arc[3]) {
  int32_t patch = 0;
  const int32_t* root = components(tri, nx, ntri, scratch, nscratch, &patch) ? scratch : NULL;
  // the crossings of the sheet along the arc (the side flips between two
  // points, where the signed distance goes through zero): the first from the
  // tip, or the one nearest near_to within `within` of it; none taken
  double d0 = 0, d1 = 0, best = INFINITY, reach = -1;
  int s0 = 0, found = 0;
  for (int k = 0; k < narc; k++) {
    if (near_to) {
      double e2 = 0;
      for (int j = 0; j < 3; j++) e2 += (arc[k][j] - near_to[j]) * (arc[k][j] - near_to[j]);
      if (e2 > within * within) {
        s0 = 0;
        continue;
      }
    }
    if (reach < 0) reach = triangles_reach(x, nx, tri, ntri);  // once for every search below
    int s1 = side_of(x, nx, tri, ntri, root, patch, reach, arc[k], &d1);
    if (s0 && s1 && s1 != s0) {
      double u = d0 + d1 > 0 ? d0 / (d0 + d1) : 0.5, c[3], e2 = 0;
      for (int j = 0; j < 3; j++) c[j] = arc[k - 1][j] + u * (arc[k][j] - arc[k - 1][j]);
      bool other = false; // another puncture's hole
      for (int h = 0; h < ntaken && !other; h++) {
        double o2 = 0;
        for (int j = 0; j < 3; j++) o2 += (c[j] - taken[h][j]) * (c[j] - taken[h][j]);
        other = o2 < apart * apart;
      }
      if (near_to)
        for (int j = 0; j < 3; j++) e2 += (c[j] - near_to[j]) * (c[j] - near_to[j]);
      if (!other && e2 < best) best = e2, found = 1, memcpy(on_arc, c, sizeof c);
      if (found && !near_to) break;
    }
    s0 = s1, d0 = d1;
  }
  if (!found) return -1;
  int t = nearest_of(x, nx, tri, ntri, root, patch, reach, on_arc, bary, point);
  if (t < 0) return -1;
  // the crossing itself, in the rim triangle's plane: its coordinates in
  // that plane (summing to 1, outside [0, 1] off the triangle), so the
  // point rides on the rim where the hole's centre is
  double a[3], b[3], c[3], e0[3], e1[3], e2[3];
  corner(x, tri[3 * t], a), corner(x, tri[3 * t + 1], b), corner(x, tri[3 * t + 2], c);
  for (int j = 0; j < 3; j++) e0[j] = b[j] - a[j], e1[j] = c[j] - a[j], e2[j] = on_arc[j] - a[j];
  double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(e2, e0), d21 = dot(e2, e1);
  double den = d00 * d11 - d01 * d01;
  if (!(den > 0)) return t; // a degenerate rim triangle: its nearest point
  double v = (d11 * d20 - d01 * d21) / den, w2 = (d00 * d21 - d01 * d20) / den;
  bary[0] = 1 - v - w2, bary[1] = v, bary[2] = w2;
  for (int j = 0; j < 3; j++) point[j] = bary[0] * a[j] + bary[1] * b[j] + bary[2] * c[j];
  return t;

}

void tx_puncture_tracker_init(tx_puncture_tracker* t, double separation, double torn) {
  memset(t, 0, sizeof *t);
  t->separation = separation;
  t->torn = torn;
  t->next_side = 1;
  t->free = true;
  t->pierces = -1;
}

void tx_puncture_skin_pierces(tx_puncture_tracker* t, int pierces) {
  if (t->pierces >= 0 && pierces > t->pierces) t->pierced = true; // until a tear takes it (the two may come a publish apart)
  t->pierces = pierces;
}

bool tx_puncture_update(tx_puncture_tracker* t, const tx_skin_contact* c, const float* x, int nx, const int32_t* tri,
                        int ntri, tx_puncture_found* out) {
  double fn = sqrt(dot(c->f, c->f));
  bool touching = c->touching > 0 && fn > 0 && isfinite(fn);
  if (!touching) t->free = true; // the tip is clear of the skin: the next touch can make a puncture
  if (touching && t->free) {
    t->touched = true;
    memcpy(t->n, c->n, sizeof t->n);
    if (fn > t->peak_f) t->peak_f = fn, t->peak_depth = c->depth;
  }
  bool tore = c->torn > t->torn;
  if (isfinite(c->torn)) t->torn = c->torn;
  if (!tore || !t->pierced) return false;
  t->pierced = false;
  double bary[3], point[3];
  int row = tx_nearest_triangle(x, nx, tri, ntri, c->x, bary, point);
  if (row < 0) return false;
  if (t->any) {
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (point[k] - t->last[k]) * (point[k] - t->last[k]);
    if (d2 < t->separation * t->separation) { // the tear runs on at the last hole: the same puncture
      t->touched = false;
      t->peak_f = t->peak_depth = 0;
      return false;
    }
  }
  const int32_t* v = tri + 3 * row;
  double a[3], b[3], cc[3], ab[3], ac[3];
  corner(x, v[0], a), corner(x, v[1], b), corner(x, v[2], cc);
  for (int k = 0; k < 3; k++) ab[k] = b[k] - a[k], ac[k] = cc[k] - a[k];
  double normal[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
  // the side the tip came from: where the skin pushed it since it was clear,
  // else where it pushes it now (flaps still clinging), else the next one's
  const double* from = t->touched ? t->n : touching ? c->n : NULL;
  int side = !from ? t->next_side : dot(from, normal) >= 0 ? 1 : -1;
  if (side != t->next_side) { // through one membrane the tip goes in, then out: this tear is at the hole it made
    t->touched = false;
    t->peak_f = t->peak_depth = 0;
    return false;
  }
  t->next_side = -side;
  *out = (tx_puncture_found){.row = {.v = {v[0], v[1], v[2]}, .bary = {bary[0], bary[1], bary[2]}, .side = side},
                             .verts = {v[0], v[1], v[2]},
                             .triangle = row,
                             .point = {point[0], point[1], point[2]},
                             .force = t->peak_f,
                             .depth = t->peak_depth};
  t->any = true;
  memcpy(t->last, point, sizeof point);
  t->touched = false;
  t->free = false;
  t->peak_f = t->peak_depth = 0;
  return true;
}

double tx_height_above_sheet(const float* x, int nx, const double p[3]) {
  double best = INFINITY, y = 0, lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (int i = 0; i < nx; i++) {
    const float* q = x + 3 * i;
    if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
    double dx = p[0] - q[0], dz = p[2] - q[2], d2 = dx * dx + dz * dz;
    lo[0] = fmin(lo[0], q[0]), hi[0] = fmax(hi[0], q[0]), lo[1] = fmin(lo[1], q[2]), hi[1] = fmax(hi[1], q[2]);
    if (d2 < best) best = d2, y = q[1];
  }
  if (!(p[0] >= lo[0] && p[0] <= hi[0] && p[2] >= lo[1] && p[2] <= hi[1])) return INFINITY;
  return p[1] - y;
}

bool tx_sheet_grid_init(tx_sheet_grid* g, int cap) {
  *g = (tx_sheet_grid){.cap = cap > 0 ? cap : 0};
  g->start = malloc(sizeof(int32_t) * (size_t)(g->cap + 1));
  g->cursor = malloc(sizeof(int32_t) * (size_t)(g->cap + 1));
  g->order = malloc(sizeof(int32_t) * (size_t)(g->cap + 1));
  if (!g->start || !g->cursor || !g->order) return tx_sheet_grid_free(g), false;
  return true;
}

void tx_sheet_grid_free(tx_sheet_grid* g) {
  free(g->start), free(g->cursor), free(g->order);
  *g = (tx_sheet_grid){0};
}

static int cell_of(const tx_sheet_grid* g, double x, double z) {
  int i = (int)((x - g->lo[0]) / g->cell), j = (int)((z - g->lo[1]) / g->cell);
  i = i < 0 ? 0 : i >= g->cols ? g->cols - 1 : i;
  j = j < 0 ? 0 : j >= g->rows ? g->rows - 1 : j;
  return j * g->cols + i;
}

void tx_sheet_grid_build(tx_sheet_grid* g, const float* x, int nx) {
  g->n = 0;
  if (nx > g->cap) return;
  g->lo[0] = g->lo[1] = INFINITY, g->hi[0] = g->hi[1] = -INFINITY;
  for (int i = 0; i < nx; i++) {
    const float* q = x + 3 * i;
    if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
    g->lo[0] = fmin(g->lo[0], q[0]), g->hi[0] = fmax(g->hi[0], q[0]);
    g->lo[1] = fmin(g->lo[1], q[2]), g->hi[1] = fmax(g->hi[1], q[2]);
    g->n++;
  }
  if (g->n == 0) return;
  // about two particles a cell, and never more cells than room
  double w = g->hi[0] - g->lo[0], h = g->hi[1] - g->lo[1];
  g->cell = fmax(sqrt(w * h * 2 / g->n), fmax(w, h) / g->cap + 1e-9);
  for (;;) {
    g->cols = (int)(w / g->cell) + 1, g->rows = (int)(h / g->cell) + 1;
    if ((long)g->cols * g->rows <= g->cap) break;
    g->cell *= 1.25;
  }
  int cells = g->cols * g->rows;
  for (int c = 0; c <= cells; c++) g->start[c] = 0;
  for (int i = 0; i < nx; i++) {
    const float* q = x + 3 * i;
    if (isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2])) g->start[cell_of(g, q[0], q[2]) + 1]++;
  }
  for (int c = 0; c < cells; c++) g->start[c + 1] += g->start[c], g->cursor[c] = g->start[c];
  for (int i = 0; i < nx; i++) {
    const float* q = x + 3 * i;
    if (isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2])) g->order[g->cursor[cell_of(g, q[0], q[2])]++] = i;
  }
}

double tx_sheet_height(const tx_sheet_grid* g, const float* x, const double p[3]) {
  if (g->n == 0 || !(p[0] >= g->lo[0] && p[0] <= g->hi[0] && p[2] >= g->lo[1] && p[2] <= g->hi[1])) return INFINITY;
  int home = cell_of(g, p[0], p[2]), ci = home % g->cols, cj = home / g->cols;
  double best = INFINITY, y = 0;
  int best_i = -1;
  // rings of cells about p's: a particle in ring r + 1 is at least r cells away
  for (int r = 0; r <= g->cols + g->rows; r++) {
    for (int j = cj - r; j <= cj + r; j++) {
      if (j < 0 || j >= g->rows) continue;
      int step = (j == cj - r || j == cj + r) ? 1 : 2 * r;  // the ring's edge cells only
      for (int i = ci - r; i <= ci + r; i += step > 0 ? step : 1) {
        if (i < 0 || i >= g->cols) continue;
        int c = j * g->cols + i;
        for (int k = g->start[c]; k < g->start[c + 1]; k++) {
          int32_t n = g->order[k];
          const float* q = x + 3 * n;
          double dx = p[0] - q[0], dz = p[2] - q[2], d2 = dx * dx + dz * dz;
          if (d2 < best || (d2 == best && n < best_i)) best = d2, y = q[1], best_i = n;  // ties: the lowest number, as the scan
        }
      }
    }
    if (best_i >= 0 && best < (r * g->cell) * (r * g->cell)) break;
  }
  return p[1] - y;
}
