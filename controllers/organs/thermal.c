// Heat in a tetrahedral organ: Pennes' bioheat equation on linear
// tetrahedra, lumped mass, explicit Euler (thermal.h says why).
#include "thermal.h"

#include "../../model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct tx_thermal {
  int n;
  tx_tissue tissue;
  tx_arrhenius arr;
  bool damage_on;
  double dt, h; // the step and its substep, s
  int substeps;
  double stable_dt;
  double *t, *tn;     // K (n): now, next
  double* omega;      // (n)
  double* vol;        // m^3 (n): the lumped volume
  double* inv_mass;   // 1 / (rho c V) (n), 0 where held
  double* perf;       // w_b rho_b c_b V (n), W/K
  double* q;          // W (n): the source
  double cap, boiled; // K (0: none), J
  bool* reached;      // (n)
  double band;        // K: nodes within it of T_a whose neighbours are too are left alone (0: every node steps)
  int *list, *next;   // (n): the nodes stepped, and the next substep's being built
  int nlist;
  unsigned* mark;     // (n): == stamp when in next
  unsigned stamp;
  bool rescan;        // the whole field changed: find the band anew
  int* src;           // (n): the nodes the source heats
  int nsrc;
  double time, rest_rate; // s stepped; 1/s, the damage rate at T_a
  bool source_on;
  double power, energy;
  int *row, *col;     // the conductances between neighbours, CSR (n + 1, row[n])
  double* cond;       // W/K: -K_ij, heat flows along it from the hotter node
  double* x;          // (n x 3) m, for the source
  int* tets_at;       // (n) live tetrahedra at each node (tx_thermal_remove); 0: out of the solve
  double lmax;        // 1/s, Gershgorin's bound on M^-1 (K + P): sets the substeps
};

double tx_perfusion_coefficient(double ml_min_kg, double tissue_rho) {
  // m^3 of blood per second and m^3 of tissue, times the blood's rho c
  return ml_min_kg * 1e-6 / 60.0 * tissue_rho * 1050.0 * 3617.0;
}

tx_tissue tx_tissue_liver(void) {
  return (tx_tissue){.k = 0.52, .rho = 1079, .c = 3540, .perfusion = tx_perfusion_coefficient(860, 1079),
                     .t_arterial = TX_BODY_TEMPERATURE_K};
}

tx_tissue tx_tissue_stomach(void) {
  return (tx_tissue){.k = 0.53, .rho = 1088, .c = 3690, .perfusion = tx_perfusion_coefficient(479, 1088),
                     .t_arterial = TX_BODY_TEMPERATURE_K};
}

tx_arrhenius tx_arrhenius_liver(void) { return (tx_arrhenius){.a = 7.39e39, .ea = 2.577e5}; }

double tx_arrhenius_rate(const tx_arrhenius* d, double t_k) {
  return t_k > 0 ? d->a * exp(-d->ea / (TX_GAS_CONSTANT * t_k)) : 0;
}

static double det3(const double m[3][3]) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// J (columns the edges from node 0) and its determinant (6 V)
static double edges(const double* x, const int* t, double j[3][3]) {
  const double* a = x + 3 * t[0];
  for (int c = 0; c < 3; c++)
    for (int r = 0; r < 3; r++) j[r][c] = x[3 * t[c + 1] + r] - a[r];
  return det3(j);
}

bool tx_tet_barycentric(const double* x, const int* tet, int e, const double p[3], double w[4]) {
  double j[3][3];
  const int* t = tet + 4 * e;
  double det = edges(x, t, j);
  if (!(fabs(det) > 0)) return false;
  const double* a = x + 3 * t[0];
  double l[3];
  for (int k = 0; k < 3; k++) { // Cramer
    double m[3][3];
    memcpy(m, j, sizeof m);
    for (int r = 0; r < 3; r++) m[r][k] = p[r] - a[r];
    l[k] = det3(m) / det;
  }
  w[0] = 1 - l[0] - l[1] - l[2], w[1] = l[0], w[2] = l[1], w[3] = l[2];
  return true;
}

// the barycentric gradients of tetrahedron t (4 x 3, 1/m) and its volume;
// false when it is flatter than the coordinates' rounding (no gradient)
static bool gradients(const double* x, const int* t, double g[4][3], double* vol) {
  double j[3][3];
  double det = edges(x, t, j);
  *vol = fabs(det) / 6;
  double span = 0;
  for (int c = 0; c < 3; c++) span = fmax(span, sqrt(j[0][c] * j[0][c] + j[1][c] * j[1][c] + j[2][c] * j[2][c]));
  if (!(fabs(det) > 1e-9 * span * span * span) || !isfinite(det)) return false;
  // rows of J^-1, and minus their sum
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) {
      int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      g[c + 1][r] = (j[r1][c1] * j[r2][c2] - j[r1][c2] * j[r2][c1]) / det; // (J^-1)[c][r] = cofactor(r, c) / det
    }
  for (int a = 0; a < 3; a++) g[0][a] = -(g[1][a] + g[2][a] + g[3][a]);
  return true;
}

void tx_thermal_destroy(tx_thermal* h) {
  if (!h) return;
  free(h->t), free(h->tn), free(h->omega), free(h->vol), free(h->inv_mass), free(h->perf), free(h->q);
  free(h->reached), free(h->list), free(h->next), free(h->mark), free(h->src), free(h->row), free(h->col), free(h->cond), free(h->x);
  free(h->tets_at);
  free(h);
}

static tx_thermal* fail(tx_thermal* h, int* scratch) {
  free(scratch);
  tx_thermal_destroy(h);
  return NULL;
}

tx_thermal* tx_thermal_create(const double* x, int n, const int* tet, int ntet, const tx_tissue* ts,
                              const tx_arrhenius* d, double dt) {
  if (n < 4 || ntet < 1) return tx_set_error("thermal: %d nodes and %d tetrahedra: too few", n, ntet), NULL;
  if (!(ts->k > 0 && ts->rho > 0 && ts->c > 0 && ts->perfusion >= 0 && ts->t_arterial > 0 && isfinite(ts->k + ts->rho + ts->c + ts->perfusion + ts->t_arterial)))
    return tx_set_error("thermal: k, rho, c and T_a must be positive, the perfusion not negative"), NULL;
  if (!(dt > 0 && isfinite(dt))) return tx_set_error("thermal: the step %g s is not positive", dt), NULL;
  tx_thermal* h = calloc(1, sizeof *h);
  if (!h) return tx_set_error("thermal: out of memory"), NULL;
  h->n = n, h->tissue = *ts, h->dt = dt;
  if (d) h->arr = *d, h->damage_on = true, h->rest_rate = tx_arrhenius_rate(d, ts->t_arterial);
  size_t sz = sizeof(double) * (size_t)n;
  h->t = malloc(sz), h->tn = malloc(sz), h->omega = calloc((size_t)n, sizeof(double)), h->vol = calloc((size_t)n, sizeof(double));
  h->inv_mass = malloc(sz), h->perf = malloc(sz), h->q = calloc((size_t)n, sizeof(double)), h->x = malloc(3 * sz);
  h->row = calloc((size_t)n + 1, sizeof(int));
  h->reached = calloc((size_t)n, sizeof(bool));
  h->list = malloc(sizeof(int) * (size_t)n), h->next = malloc(sizeof(int) * (size_t)n);
  h->mark = calloc((size_t)n, sizeof(unsigned)), h->src = malloc(sizeof(int) * (size_t)n);
  h->tets_at = calloc((size_t)n, sizeof(int));
  if (!h->tets_at || !h->list || !h->next || !h->mark || !h->src || !h->reached || !h->t || !h->tn || !h->omega || !h->vol || !h->inv_mass || !h->perf || !h->q || !h->x || !h->row)
    return tx_set_error("thermal: out of memory"), fail(h, NULL);
  memcpy(h->x, x, 3 * sz);

  // every tetrahedron adds 3 neighbours to each of its nodes (merged below)
  double scale = 0;
  for (int e = 0; e < ntet; e++)
    for (int k = 0; k < 4; k++) {
      int v = tet[4 * e + k];
      if (v < 0 || v >= n) return tx_set_error("thermal: tetrahedron %d names node %d of %d", e, v, n), fail(h, NULL);
      h->row[v + 1] += 3;
      h->tets_at[v]++;
      for (int a = 0; a < 3; a++) scale = fmax(scale, fabs(x[3 * v + a]));
    }
  for (int i = 0; i < n; i++) h->row[i + 1] += h->row[i];
  int* fill = malloc(sizeof(int) * (size_t)n);
  h->col = malloc(sizeof(int) * (size_t)h->row[n] + 1);
  h->cond = malloc(sizeof(double) * (size_t)h->row[n] + 1);
  if (!fill || !h->col || !h->cond) return tx_set_error("thermal: out of memory"), fail(h, fill);
  memcpy(fill, h->row, sizeof(int) * (size_t)n);
  for (int e = 0; e < ntet; e++) {
    const int* t = tet + 4 * e;
    double g[4][3], vol;
    if (!gradients(x, t, g, &vol)) return tx_set_error("thermal: tetrahedron %d is degenerate", e), fail(h, fill);
    for (int a = 0; a < 4; a++) {
      h->vol[t[a]] += vol / 4;
      for (int b = 0; b < 4; b++) {
        if (b == a) continue;
        double kab = ts->k * vol * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
        h->col[fill[t[a]]] = t[b], h->cond[fill[t[a]]++] = -kab;
      }
    }
  }
  free(fill);
  // each row sorted by neighbour, the duplicates merged, packed in place
  int out = 0;
  for (int i = 0; i < n; i++) {
    int lo = h->row[i], hi = h->row[i + 1];
    for (int a = lo + 1; a < hi; a++) { // insertion sort: rows are a few dozen long
      int c = h->col[a];
      double v = h->cond[a];
      int b = a - 1;
      for (; b >= lo && h->col[b] > c; b--) h->col[b + 1] = h->col[b], h->cond[b + 1] = h->cond[b];
      h->col[b + 1] = c, h->cond[b + 1] = v;
    }
    h->row[i] = out;
    for (int a = lo; a < hi; a++) {
      if (out > h->row[i] && h->col[out - 1] == h->col[a]) h->cond[out - 1] += h->cond[a];
      else h->col[out] = h->col[a], h->cond[out++] = h->cond[a];
    }
  }
  h->row[n] = out;

  // lumped mass and perfusion; Gershgorin on M^-1 (K + P)
  double lmax = 0;
  for (int i = 0; i < n; i++) {
    if (!(h->vol[i] > 0)) return tx_set_error("thermal: node %d is in no tetrahedron", i), fail(h, NULL);
    h->inv_mass[i] = 1 / (ts->rho * ts->c * h->vol[i]);
    h->perf[i] = ts->perfusion * h->vol[i];
    double diag = 0, off = 0;
    for (int a = h->row[i]; a < h->row[i + 1]; a++) diag += h->cond[a], off += fabs(h->cond[a]);
    lmax = fmax(lmax, (fabs(diag) + off + h->perf[i]) * h->inv_mass[i]);
  }
  h->lmax = lmax;
  h->stable_dt = 0.9 * 2 / lmax;
  h->substeps = (int)ceil(dt / h->stable_dt - 1e-12);
  if (h->substeps < 1) h->substeps = 1;
  if (h->substeps > 100000) return tx_set_error("thermal: a step of %g s needs %d substeps of at most %g s", dt, h->substeps, h->stable_dt), fail(h, NULL);
  h->h = dt / h->substeps;
  tx_thermal_reset(h);
  return h;
}

void tx_thermal_fix(tx_thermal* h, int node) {
  if (node >= 0 && node < h->n) h->inv_mass[node] = 0, h->t[node] = h->tn[node] = h->tissue.t_arterial;
}

double tx_thermal_stable_dt(const tx_thermal* h) { return h->stable_dt; }
int tx_thermal_substeps(const tx_thermal* h) { return h->substeps; }
int tx_thermal_nodes(const tx_thermal* h) { return h->n; }
const double* tx_thermal_temperature(const tx_thermal* h) { return h->t; }
double* tx_thermal_temperature_mut(tx_thermal* h) {
  h->rescan = true;
  return h->t;
}
double tx_thermal_damage_rest(const tx_thermal* h) { return h->rest_rate * h->time; }
int tx_thermal_stepped(const tx_thermal* h) { return h->nlist; }

void tx_thermal_band(tx_thermal* h, double band_k) {
  h->band = band_k > 0 ? band_k : 0;
  h->rescan = true;
}
const double* tx_thermal_damage(const tx_thermal* h) { return h->omega; }
const double* tx_thermal_volume(const tx_thermal* h) { return h->vol; }
double tx_thermal_energy(const tx_thermal* h) { return h->energy; }

void tx_thermal_reset(tx_thermal* h) {
  for (int i = 0; i < h->n; i++) h->t[i] = h->tn[i] = h->tissue.t_arterial, h->omega[i] = 0, h->q[i] = 0;
  h->source_on = false, h->power = 0, h->energy = 0, h->boiled = 0, h->nsrc = 0, h->time = 0;
  h->rescan = true;
  memset(h->reached, 0, sizeof(bool) * (size_t)h->n);
}

void tx_thermal_cap(tx_thermal* h, double t_cap) { h->cap = t_cap > 0 ? t_cap : 0; }
double tx_thermal_boiled(const tx_thermal* h) { return h->boiled; }
const bool* tx_thermal_reached(const tx_thermal* h) { return h->reached; }

void tx_thermal_source(tx_thermal* h, const double c[3], double radius, double power) {
  h->source_on = power > 0 && radius > 0 && isfinite(power + radius + c[0] + c[1] + c[2]);
  if (!h->source_on) {
    for (int k = 0; k < h->nsrc; k++) h->q[h->src[k]] = 0;
    h->power = 0, h->nsrc = 0;
    return;
  }
  for (int k = 0; k < h->nsrc; k++) h->q[h->src[k]] = 0;
  h->nsrc = 0;
  double sum = 0, best = INFINITY, cut = 64 * radius * radius; // beyond 8 radii: below 1e-14
  int nearest = 0;
  for (int i = 0; i < h->n; i++) {
    const double* p = h->x + 3 * i;
    double d2 = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]);
    if (d2 < best && h->vol[i] > 0) best = d2, nearest = i; // removed tissue takes no heat
    if (d2 < cut) {
      h->q[i] = exp(-d2 / (2 * radius * radius)) * h->vol[i];
      if (h->q[i] > 0) sum += h->q[i], h->src[h->nsrc++] = i;
    }
  }
  if (sum > 0)
    for (int k = 0; k < h->nsrc; k++) h->q[h->src[k]] *= power / sum;
  else h->q[nearest] = power, h->src[h->nsrc++] = nearest; // narrower than the elements, far from every node
  h->power = power;
}

static void add(tx_thermal* h, int i, int* n) {
  if (h->mark[i] != h->stamp) h->mark[i] = h->stamp, h->next[(*n)++] = i;
}

// the nodes to step: those off T_a by more than the band or heated, and
// their neighbours; the rest (within the band, their neighbours too) stay
// as they are. Only stepped nodes change, so the hot ones are among the
// last list's, or the source's.
static void find_band(tx_thermal* h) {
  const double ta = h->tissue.t_arterial;
  if (++h->stamp == 0) { // wrapped: clear the marks
    memset(h->mark, 0, sizeof(unsigned) * (size_t)h->n);
    h->stamp = 1;
  }
  int n = 0;
  int count = h->rescan ? h->n : h->nlist;
  for (int k = 0; k < count + (h->source_on ? h->nsrc : 0); k++) {
    int i = k < count ? (h->rescan ? k : h->list[k]) : h->src[k - count];
    bool heated = h->source_on && h->q[i] > 0;
    if (!heated && !(fabs(h->t[i] - ta) > h->band)) continue;
    add(h, i, &n);
    for (int a = h->row[i]; a < h->row[i + 1]; a++) add(h, h->col[a], &n);
  }
  int* t = h->list;
  h->list = h->next, h->next = t, h->nlist = n;
  h->rescan = false;
}

void tx_thermal_step(tx_thermal* h) {
  const double ta = h->tissue.t_arterial, dt = h->h;
  double *t = h->t, *tn = h->tn;
  for (int s = 0; s < h->substeps; s++) {
    if (h->band > 0) find_band(h);
    else if (h->nlist != h->n) {
      for (int i = 0; i < h->n; i++) h->list[i] = i;
      h->nlist = h->n;
    }
    for (int k = 0; k < h->nlist; k++) {
      int i = h->list[k];
      double flow = h->source_on ? h->q[i] : 0;
      flow -= h->perf[i] * (t[i] - ta);
      for (int a = h->row[i]; a < h->row[i + 1]; a++) flow += h->cond[a] * (t[h->col[a]] - t[i]);
      tn[i] = t[i] + dt * flow * h->inv_mass[i];
      if (h->cap > 0 && tn[i] > h->cap && h->inv_mass[i] > 0) {
        h->boiled += (tn[i] - h->cap) / h->inv_mass[i];
        tn[i] = h->cap, h->reached[i] = true;
      }
    }
    for (int k = 0; k < h->nlist; k++) {
      int i = h->list[k];
      if (h->damage_on) h->omega[i] += dt * (tx_arrhenius_rate(&h->arr, t[i]) - h->rest_rate);
      t[i] = tn[i];
    }
  }
  if (h->source_on) h->energy += h->power * h->dt;
  h->time += h->dt;
}

void tx_thermal_embed(const double* x, const int* tet, int ntet, const float* points, int np, int* out_tet, float* out_w,
                      int* out_e) {
  for (int v = 0; v < np; v++) {
    const double p[3] = {points[3 * v], points[3 * v + 1], points[3 * v + 2]};
    double best = -INFINITY, bw[4] = {1, 0, 0, 0}, w[4];
    int bt = 0;
    for (int e = 0; e < ntet; e++) {
      if (!tx_tet_barycentric(x, tet, e, p, w)) continue;
      double lo = fmin(fmin(w[0], w[1]), fmin(w[2], w[3]));
      if (lo > best) best = lo, bt = e, memcpy(bw, w, sizeof bw);
      if (lo >= 0) break; // inside
    }
    for (int k = 0; k < 4; k++) out_tet[4 * v + k] = tet[4 * bt + k], out_w[4 * v + k] = (float)bw[k];
    if (out_e) out_e[v] = bt;
  }
}

int tx_thermal_embed_child(const double* x, const int* tet, int e, const float* point, int* out_tet, float* out_w) {
  const double p[3] = {point[0], point[1], point[2]};
  double best = -INFINITY, bw[4] = {1, 0, 0, 0}, w[4];
  int bt = 8 * e;
  for (int c = 8 * e; c < 8 * e + 8; c++) {
    if (!tx_tet_barycentric(x, tet, c, p, w)) continue;
    double lo = fmin(fmin(w[0], w[1]), fmin(w[2], w[3]));
    if (lo > best) best = lo, bt = c, memcpy(bw, w, sizeof bw);
  }
  for (int k = 0; k < 4; k++) out_tet[k] = tet[4 * bt + k], out_w[k] = (float)bw[k];
  return bt;
}

typedef struct edge {
  int a, b; // a < b
} edge;

static int edge_cmp(const void* p, const void* q) {
  const edge *e = p, *f = q;
  return e->a != f->a ? (e->a > f->a) - (e->a < f->a) : (e->b > f->b) - (e->b < f->b);
}

static int midpoint(const edge* edges, int ne, int n, int a, int b) {
  edge key = {a < b ? a : b, a < b ? b : a};
  const edge* e = bsearch(&key, edges, (size_t)ne, sizeof key, edge_cmp);
  return n + (int)(e - edges);
}

bool tx_tet_refine(const double* x, int n, const int* tet, int ntet, double** x2, int* n2, int** tet2, int* ntet2) {
  static const int pair[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  edge* edges = malloc(sizeof(edge) * 6 * (size_t)ntet);
  *x2 = NULL, *tet2 = NULL;
  if (!edges) return tx_set_error("thermal: out of memory"), false;
  for (int e = 0; e < ntet; e++)
    for (int k = 0; k < 6; k++) {
      int a = tet[4 * e + pair[k][0]], b = tet[4 * e + pair[k][1]];
      edges[6 * e + k] = (edge){a < b ? a : b, a < b ? b : a};
    }
  qsort(edges, 6 * (size_t)ntet, sizeof(edge), edge_cmp);
  int ne = 0;
  for (int i = 0; i < 6 * ntet; i++)
    if (ne == 0 || edge_cmp(&edges[ne - 1], &edges[i]) != 0) edges[ne++] = edges[i];
  *n2 = n + ne, *ntet2 = 8 * ntet;
  *x2 = malloc(sizeof(double) * 3 * (size_t)*n2);
  *tet2 = malloc(sizeof(int) * 4 * (size_t)*ntet2);
  if (!*x2 || !*tet2) {
    free(edges), free(*x2), free(*tet2);
    *x2 = NULL, *tet2 = NULL;
    return tx_set_error("thermal: out of memory"), false;
  }
  memcpy(*x2, x, sizeof(double) * 3 * (size_t)n);
  for (int i = 0; i < ne; i++)
    for (int a = 0; a < 3; a++) (*x2)[3 * (n + i) + a] = 0.5 * (x[3 * edges[i].a + a] + x[3 * edges[i].b + a]);
  for (int e = 0; e < ntet; e++) {
    const int* t = tet + 4 * e;
    int m[6]; // ab ac ad bc bd cd
    for (int k = 0; k < 6; k++) m[k] = midpoint(edges, ne, n, t[pair[k][0]], t[pair[k][1]]);
    int* c = *tet2 + 32 * e;
    const int corner[4][4] = {{t[0], m[0], m[1], m[2]}, {m[0], t[1], m[3], m[4]}, {m[1], m[3], t[2], m[5]}, {m[2], m[4], m[5], t[3]}};
    memcpy(c, corner, sizeof corner);
    // the octahedron around its shortest diagonal: ab-cd, ac-bd or ad-bc,
    // with the other four midpoints in their ring
    static const int diag[3][2] = {{0, 5}, {1, 4}, {2, 3}};
    static const int ring[3][4] = {{1, 2, 4, 3}, {0, 2, 5, 3}, {0, 1, 5, 4}};
    int best = 0;
    double len[3];
    for (int d = 0; d < 3; d++) {
      const double *p = *x2 + 3 * m[diag[d][0]], *q = *x2 + 3 * m[diag[d][1]];
      len[d] = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
      if (len[d] < len[best]) best = d;
    }
    for (int k = 0; k < 4; k++) {
      int* o = c + 16 + 4 * k;
      o[0] = m[diag[best][0]], o[1] = m[diag[best][1]], o[2] = m[ring[best][k]], o[3] = m[ring[best][(k + 1) % 4]];
    }
  }
  free(edges);
  return true;
}

static bool read_fail(FILE* f, const char* path, const char* what) {
  if (f) fclose(f);
  tx_set_error("%s: %s", path, what);
  return false;
}

bool tx_tetgen_read(const char* base, double** x, int* n, int** tet, int* ntet) {
  *x = NULL, *tet = NULL;
  char path[4200];
  if (snprintf(path, sizeof path, "%s.node", base) >= (int)sizeof path) return read_fail(NULL, base, "path too long");
  FILE* f = fopen(path, "r");
  if (!f) return read_fail(NULL, path, "cannot be read");
  int nn, dim, na, nb;
  if (fscanf(f, "%d %d %d %d", &nn, &dim, &na, &nb) != 4 || nn < 4 || nn > 1000000 || dim != 3 || na != 0)
    return read_fail(f, path, "not a TetGen .node file of 3-D points");
  *x = malloc(sizeof(double) * 3 * (size_t)nn);
  if (!*x) return read_fail(f, path, "out of memory");
  for (int i = 0; i < nn; i++) {
    int id;
    double *p = *x + 3 * i, mark;
    if (fscanf(f, "%d %lf %lf %lf", &id, p, p + 1, p + 2) != 4 || id != i || (nb && fscanf(f, "%lf", &mark) != 1) ||
        !isfinite(p[0] + p[1] + p[2]))
      return free(*x), *x = NULL, read_fail(f, path, "a node line is malformed (zero-based numbering expected)");
  }
  fclose(f);
  *n = nn;
  if (snprintf(path, sizeof path, "%s.ele", base) >= (int)sizeof path) return free(*x), *x = NULL, read_fail(NULL, base, "path too long");
  f = fopen(path, "r");
  if (!f) return free(*x), *x = NULL, read_fail(NULL, path, "cannot be read");
  int ne, per;
  if (fscanf(f, "%d %d %d", &ne, &per, &na) != 3 || ne < 1 || ne > 4000000 || per != 4)
    return free(*x), *x = NULL, read_fail(f, path, "not a TetGen .ele file of 4-node tetrahedra");
  *tet = malloc(sizeof(int) * 4 * (size_t)ne);
  if (!*tet) return free(*x), *x = NULL, read_fail(f, path, "out of memory");
  for (int i = 0; i < ne; i++) {
    int id, *e = *tet + 4 * i;
    bool ok = fscanf(f, "%d %d %d %d %d", &id, e, e + 1, e + 2, e + 3) == 5 && id == i;
    for (int k = 0; ok && k < na; k++) {
      double a;
      ok = fscanf(f, "%lf", &a) == 1;
    }
    for (int k = 0; ok && k < 4; k++) ok = e[k] >= 0 && e[k] < nn;
    if (!ok) return free(*x), free(*tet), *x = NULL, *tet = NULL, read_fail(f, path, "a tetrahedron line is malformed or names a node that is not there");
  }
  fclose(f);
  *ntet = ne;
  return true;
}

bool tx_obj_read(const char* path, float** x, int* nv, int** tri, int* nt) {
  *x = NULL, *tri = NULL;
  FILE* f = fopen(path, "r");
  if (!f) return read_fail(NULL, path, "cannot be read");
  char line[512];
  int v = 0, t = 0;
  while (fgets(line, sizeof line, f)) v += line[0] == 'v' && line[1] == ' ', t += line[0] == 'f' && line[1] == ' ';
  if (v < 3 || t < 1) return read_fail(f, path, "no triangles in it");
  *x = malloc(sizeof(float) * 3 * (size_t)v);
  *tri = malloc(sizeof(int) * 3 * (size_t)t);
  if (!*x || !*tri) return free(*x), free(*tri), *x = NULL, *tri = NULL, read_fail(f, path, "out of memory");
  rewind(f);
  int iv = 0, it = 0;
  const char* bad = NULL;
  while (!bad && fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ') {
      float* p = *x + 3 * iv++;
      if (sscanf(line + 2, "%f %f %f", p, p + 1, p + 2) != 3) bad = "a vertex line is malformed";
    } else if (line[0] == 'f' && line[1] == ' ') {
      int* q = *tri + 3 * it++;
      char* s = line + 2;
      for (int k = 0; k < 3 && !bad; k++) {
        char* end;
        long a = strtol(s, &end, 10);
        if (end == s) bad = "a face is not a triangle of vertex numbers";
        else if (a < 1 || a > v) bad = "a face names a vertex that is not there";
        q[k] = (int)a - 1;
        s = end;
        while (*s && *s != ' ' && *s != '\t') s++;
      }
    }
  }
  if (bad) return free(*x), free(*tri), *x = NULL, *tri = NULL, read_fail(f, path, bad);
  fclose(f);
  *nv = v, *nt = t;
  return true;
}

bool tx_thermal_refine_embed(const double* x, int n, const int* tet, int ntet, int levels, const float* points, int np,
                             double** xf, int* nf, int** tetf, int* ntetf, int* out_tet, float* out_w) {
  int* e = malloc(sizeof(int) * (size_t)(np > 0 ? np : 1));
  double* cx = malloc(sizeof(double) * 3 * (size_t)n);
  int* ct = malloc(sizeof(int) * 4 * (size_t)ntet);
  if (!e || !cx || !ct) return free(e), free(cx), free(ct), tx_set_error("thermal: out of memory"), false;
  memcpy(cx, x, sizeof(double) * 3 * (size_t)n), memcpy(ct, tet, sizeof(int) * 4 * (size_t)ntet);
  tx_thermal_embed(cx, ct, ntet, points, np, out_tet, out_w, e);
  for (int l = 0; l < levels; l++) {
    double* rx;
    int rn, *rt, rnt;
    if (!tx_tet_refine(cx, n, ct, ntet, &rx, &rn, &rt, &rnt)) return free(e), free(cx), free(ct), false;
    free(cx), free(ct);
    cx = rx, ct = rt, n = rn, ntet = rnt;
    for (int v = 0; v < np; v++) e[v] = tx_thermal_embed_child(cx, ct, e[v], points + 3 * v, out_tet + 4 * v, out_w + 4 * v);
  }
  free(e);
  *xf = cx, *nf = n, *tetf = ct, *ntetf = ntet;
  return true;
}

// the conductance from i to j in i's row, or NULL
static double* conductance(tx_thermal* h, int i, int j) {
  for (int a = h->row[i]; a < h->row[i + 1]; a++)
    if (h->col[a] == j) return &h->cond[a];
  return NULL;
}

bool tx_thermal_remove(tx_thermal* h, const int t[4]) {
  for (int a = 0; a < 4; a++)
    if (t[a] < 0 || t[a] >= h->n || h->tets_at[t[a]] <= 0) return false;
  double g[4][3], vol;
  if (!gradients(h->x, t, g, &vol)) return false;
  // its conductances, volume, heat capacity and perfusion go
  for (int a = 0; a < 4; a++) {
    for (int b = 0; b < 4; b++) {
      double* c = b == a ? NULL : conductance(h, t[a], t[b]);
      if (c) *c += h->tissue.k * vol * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
    }
    h->vol[t[a]] -= vol / 4;
  }
  for (int a = 0; a < 4; a++) {
    int i = t[a];
    if (--h->tets_at[i] == 0) {
      // out of the solve: no volume, no heat, no conductance either way (not
      // the rounding left by the subtractions), at T_a so the band passes it by
      for (int b = h->row[i]; b < h->row[i + 1]; b++) {
        h->cond[b] = 0;
        double* back = conductance(h, h->col[b], i);
        if (back) *back = 0;
      }
      h->vol[i] = 0, h->inv_mass[i] = 0, h->perf[i] = 0, h->q[i] = 0;
      h->t[i] = h->tn[i] = h->tissue.t_arterial;
      continue;
    }
    if (!(h->vol[i] > 0)) h->vol[i] = 1e-30;
    if (h->inv_mass[i] > 0) h->inv_mass[i] = 1 / (h->tissue.rho * h->tissue.c * h->vol[i]);
    h->perf[i] = h->tissue.perfusion * h->vol[i];
    // a node left with a sliver may need a shorter substep
    double diag = 0, off = 0;
    for (int b = h->row[i]; b < h->row[i + 1]; b++) diag += h->cond[b], off += fabs(h->cond[b]);
    double l = (fabs(diag) + off + h->perf[i]) * h->inv_mass[i];
    if (l > h->lmax) {
      h->lmax = l;
      h->stable_dt = 0.9 * 2 / l;
      int sub = (int)ceil(h->dt / h->stable_dt - 1e-12);
      h->substeps = sub < 1 ? 1 : sub > 100000 ? 100000 : sub;
      h->h = h->dt / h->substeps;
    }
  }
  h->rescan = true;
  return true;
}

bool tx_thermal_node_live(const tx_thermal* h, int node) { return node >= 0 && node < h->n && h->tets_at[node] > 0; }
const double* tx_thermal_positions(const tx_thermal* h) { return h->x; }
