// Knots in the thread: the papers' contact rule and the Gauss-code classifier
// (knot.h).
#include "knot.h"

#include "segment.h"
#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TX_KNOT_VIEWS 32
#define CLOSURE 24 // points of the closing path

tx_knot_rule tx_knot_rule_papers(void) { return (tx_knot_rule){10, 4, 5}; }

const char* tx_knot_class_name(tx_knot_class c) {
  switch (c) {
  case TX_KNOT_UNKNOT: return "unknot";
  case TX_KNOT_TREFOIL: return "trefoil";
  case TX_KNOT_SQUARE: return "square";
  case TX_KNOT_GRANNY: return "granny";
  default: return "other";
  }
}

int tx_knot_contacts(const double* x, int n, double radius, int min_gap, uint8_t* out) {
  int nseg = n - 1, marked = 0;
  memset(out, 0, (size_t)(nseg > 0 ? nseg : 0));
  double touch = 2 * radius * 1.01;
  for (int i = 0; i < nseg; i++)
    for (int j = i + min_gap + 1; j < nseg; j++) {
      tx_seg_closest c;
      tx_seg_closest_points(x + 3 * i, x + 3 * i + 3, x + 3 * j, x + 3 * j + 3, &c);
      if (c.dist < touch) {
        marked += !out[i] + !out[j];
        out[i] = out[j] = 1;
      }
    }
  return marked;
}

bool tx_knot_papers_rule(const uint8_t* colliding, int nseg, const tx_knot_rule* rule, tx_knot_papers* out) {
  memset(out, 0, sizeof *out);
  out->first = out->last = -1;
  int prev_end = -1000000000, first = -1, last = -1, blocks = 0;
  bool separated = false;
  for (int i = 0; i < nseg; i++) out->colliding += colliding[i] != 0;
  for (int i = 0; i < nseg;) {
    if (!colliding[i]) {
      i++;
      continue;
    }
    int j = i;
    while (j < nseg && colliding[j]) j++;
    if (j - i >= rule->min_block) { // a block [i, j)
      if (blocks > 0 && i - prev_end >= rule->min_gap) separated = true;
      if (first < 0) first = i;
      last = j - 1;
      prev_end = j;
      blocks++;
    }
    i = j;
  }
  out->blocks = blocks;
  out->knot = out->colliding >= rule->min_colliding && blocks >= 2 && separated;
  if (out->knot) out->first = first, out->last = last;
  return out->knot;
}

// ---------------------------------------------------------------------------
// the classifier

typedef struct entry {
  double s;  // where along the curve (segment index + parameter)
  int id;    // the crossing
  int over;  // 1 where this strand passes over
} entry;

struct tx_knot_work {
  int max_nodes, cap; // nodes; crossings
  double* c;          // (max_nodes + CLOSURE) x 3, the closed curve
  double* p;          // (max_nodes + CLOSURE) x 2, its projection
  double* h;          // (max_nodes + CLOSURE), heights
  entry* code;        // (2 cap)
  int* sign;          // (cap)
};

tx_knot_work* tx_knot_work_create(int max_nodes) {
  tx_knot_work* w = calloc(1, sizeof *w);
  if (!w) return NULL;
  w->max_nodes = max_nodes;
  w->cap = 4 * (max_nodes + CLOSURE) + 64;
  w->c = malloc(sizeof(double) * 3 * (max_nodes + CLOSURE));
  w->p = malloc(sizeof(double) * 2 * (max_nodes + CLOSURE));
  w->h = malloc(sizeof(double) * (max_nodes + CLOSURE));
  w->code = malloc(sizeof(entry) * 2 * w->cap);
  w->sign = malloc(sizeof(int) * w->cap);
  if (!w->c || !w->p || !w->h || !w->code || !w->sign) {
    tx_knot_work_destroy(w);
    return NULL;
  }
  return w;
}

void tx_knot_work_destroy(tx_knot_work* w) {
  if (!w) return;
  free(w->c);
  free(w->p);
  free(w->h);
  free(w->code);
  free(w->sign);
  free(w);
}

static int cmp_entry(const void* a, const void* b) {
  double d = ((const entry*)a)->s - ((const entry*)b)->s;
  return d < 0 ? -1 : d > 0 ? 1 : 0;
}

// removes the entries of crossings a and b (b may equal a) from the code
static int drop(entry* code, int m, int a, int b) {
  int k = 0;
  for (int i = 0; i < m; i++)
    if (code[i].id != a && code[i].id != b) code[k++] = code[i];
  return k;
}

// Reidemeister I and II on the cyclic Gauss code until neither applies
static int simplify(entry* code, int m) {
  for (bool changed = true; changed && m > 0;) {
    changed = false;
    for (int i = 0; i < m && !changed; i++) { // I: a crossing met twice in a row
      int j = (i + 1) % m;
      if (m >= 2 && code[i].id == code[j].id) {
        m = drop(code, m, code[i].id, code[i].id);
        changed = true;
      }
    }
    for (int i = 0; i < m && !changed; i++) { // II: a bigon
      int j = (i + 1) % m;
      int a = code[i].id, b = code[j].id;
      if (a == b || code[i].over != code[j].over) continue;
      for (int k = 0; k < m; k++) {
        int l = (k + 1) % m;
        if (k == i) continue;
        bool same = (code[k].id == a && code[l].id == b) || (code[k].id == b && code[l].id == a);
        if (same && code[k].over == code[l].over && code[k].over != code[i].over) {
          m = drop(code, m, a, b);
          changed = true;
          break;
        }
      }
    }
  }
  return m;
}

// the crossings of the closed polygon x (n points) seen along d.
// Returns the entry count (2 per crossing), or -1 when over capacity.
static int gauss_code(tx_knot_work* w, const double* x, int n, const double d[3]) {
  // a basis of the view plane: e1, e2 with e1 x e2 = d
  double e1[3], e2[3];
  double ref[3] = {fabs(d[0]) < 0.9 ? 1 : 0, fabs(d[0]) < 0.9 ? 0 : 1, 0};
  double dr = ref[0] * d[0] + ref[1] * d[1] + ref[2] * d[2];
  for (int a = 0; a < 3; a++) e1[a] = ref[a] - dr * d[a];
  double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (int a = 0; a < 3; a++) e1[a] /= l;
  e2[0] = d[1] * e1[2] - d[2] * e1[1];
  e2[1] = d[2] * e1[0] - d[0] * e1[2];
  e2[2] = d[0] * e1[1] - d[1] * e1[0];
  for (int i = 0; i < n; i++) {
    const double* q = x + 3 * i;
    w->p[2 * i] = q[0] * e1[0] + q[1] * e1[1] + q[2] * e1[2];
    w->p[2 * i + 1] = q[0] * e2[0] + q[1] * e2[1] + q[2] * e2[2];
    w->h[i] = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
  }
  // segment k joins point k to point k + 1, and segment n - 1 point n - 1 to point 0
  int nsegs = n, m = 0, id = 0;
  for (int a = 0; a < nsegs; a++)
    for (int b = a + 2; b < nsegs; b++) {
      if (a == 0 && b == nsegs - 1) continue; // they share node 0
      int a1 = (a + 1) % n, b1 = (b + 1) % n;
      double ax = w->p[2 * a], ay = w->p[2 * a + 1], ux = w->p[2 * a1] - ax, uy = w->p[2 * a1 + 1] - ay;
      double bx = w->p[2 * b], by = w->p[2 * b + 1], vx = w->p[2 * b1] - bx, vy = w->p[2 * b1 + 1] - by;
      double den = ux * vy - uy * vx;
      // parallel in the projection (a strand along the closure, say): no crossing
      if (fabs(den) <= 1e-9 * sqrt((ux * ux + uy * uy) * (vx * vx + vy * vy))) continue;
      double rx = bx - ax, ry = by - ay;
      double t = (rx * vy - ry * vx) / den, s = (rx * uy - ry * ux) / den;
      if (t < 0 || t >= 1 || s < 0 || s >= 1) continue;
      double ha = w->h[a] + t * (w->h[a1] - w->h[a]);
      double hb = w->h[b] + s * (w->h[b1] - w->h[b]);
      if (id >= w->cap) return -1;
      int a_over = ha > hb;
      // the sign: the over strand's direction crossed with the under's, seen from +d
      double cr = a_over ? ux * vy - uy * vx : vx * uy - vy * ux;
      w->sign[id] = cr > 0 ? 1 : -1;
      w->code[m++] = (entry){a + t, id, a_over};
      w->code[m++] = (entry){b + s, id, !a_over};
      id++;
    }
  qsort(w->code, (size_t)m, sizeof(entry), cmp_entry);
  return m;
}

// the thread closed far away: each end goes straight out from the centroid
// to a sphere ten times the thread's size, and an arc on that sphere joins
// them (through a third direction when the ends point apart). The same
// closed curve serves every view, as a knot's type needs; it is the knot of
// the thread when both ends point out of the tangle, as a knot's ends do.
static int close_curve(tx_knot_work* w, const double* x, int n) {
  double cen[3] = {0, 0, 0}, size = 0;
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++) cen[a] += x[3 * i + a] / n;
  for (int i = 0; i < n; i++) {
    double e = 0;
    for (int a = 0; a < 3; a++) e += pow(x[3 * i + a] - cen[a], 2);
    if (e > size) size = e;
  }
  double R = 10 * sqrt(size) + 1e-9;
  memcpy(w->c, x, sizeof(double) * 3 * n);
  double u[3], v[3], lu = 0, lv = 0; // out through the tail, and through the head
  for (int a = 0; a < 3; a++) {
    u[a] = x[3 * (n - 1) + a] - cen[a];
    v[a] = x[a] - cen[a];
    lu += u[a] * u[a];
    lv += v[a] * v[a];
  }
  lu = sqrt(lu), lv = sqrt(lv);
  for (int a = 0; a < 3; a++) {
    u[a] = lu > 0 ? u[a] / lu : (a == 0);
    v[a] = lv > 0 ? v[a] / lv : (a == 1);
  }
  // a middle direction for the arc: between the two, or across when they oppose
  double mid[3] = {u[0] + v[0], u[1] + v[1], u[2] + v[2]};
  double lm = sqrt(mid[0] * mid[0] + mid[1] * mid[1] + mid[2] * mid[2]);
  if (lm < 0.5) {
    double e[3] = {fabs(u[0]) < 0.6 ? 1 : 0, fabs(u[0]) < 0.6 ? 0 : 1, 0};
    mid[0] = u[1] * e[2] - u[2] * e[1];
    mid[1] = u[2] * e[0] - u[0] * e[2];
    mid[2] = u[0] * e[1] - u[1] * e[0];
    lm = sqrt(mid[0] * mid[0] + mid[1] * mid[1] + mid[2] * mid[2]);
  }
  for (int a = 0; a < 3; a++) mid[a] /= lm;
  int k = n;
  for (int j = 0; j < CLOSURE; j++) {
    double f = (double)j / (CLOSURE - 1), g[3];
    for (int a = 0; a < 3; a++) g[a] = f < 0.5 ? u[a] + 2 * f * (mid[a] - u[a]) : mid[a] + (2 * f - 1) * (v[a] - mid[a]);
    double lg = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    for (int a = 0; a < 3; a++) w->c[3 * k + a] = cen[a] + R * g[a] / lg;
    k++;
  }
  return k;
}

int tx_knot_classify(tx_knot_work* w, const double* x, int n, tx_knot_diagram* out) {
  if (n < 2 || n > w->max_nodes) {
    tx_set_error("knot: %d nodes, must be in [2, %d]", n, w->max_nodes);
    return -1;
  }
  int nc = close_curve(w, x, n);
  // 32 directions spread over a half sphere (a Fibonacci lattice), turned
  // off the axes so that shapes built on grids do not project edge-on
  int best = -1;
  memset(out, 0, sizeof *out);
  for (int k = 0; k < TX_KNOT_VIEWS; k++) {
    double z = 1 - (k + 0.5) / TX_KNOT_VIEWS, rho = sqrt(1 - z * z), phi = 2.39996322972865332 * k + 0.3;
    double d[3] = {rho * cos(phi), rho * sin(phi), z};
    int m = gauss_code(w, w->c, nc, d);
    if (m < 0) {
      tx_set_error("knot: more than %d crossings in a projection", w->cap);
      return -1;
    }
    int raw = m / 2;
    m = simplify(w->code, m);
    int left = m / 2;
    if (best >= 0 && left >= best) continue;
    best = left;
    out->crossings = left;
    out->raw = raw;
    out->writhe = 0;
    for (int i = 0; i < m; i++)
      if (w->code[i].over) out->writhe += w->sign[w->code[i].id];
  }
  int c = out->crossings, wr = abs(out->writhe);
  out->cls = c == 0                ? TX_KNOT_UNKNOT
             : c == 3 && wr == 3   ? TX_KNOT_TREFOIL
             : c == 6 && wr == 6   ? TX_KNOT_GRANNY
             : c == 6 && wr == 0   ? TX_KNOT_SQUARE
                                   : TX_KNOT_OTHER;
  return 0;
}
