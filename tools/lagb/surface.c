// Organ surfaces by GTS marching cubes and decimation (see surface.h).
#include "tools/lagb/surface.h"

#include "model/error.h"

#include <gts.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { PAD = 3 };  // empty voxels around the organ, so its surface closes

typedef struct grid {
  int n[3];      // region size, voxels
  float* f;      // the smoothed mask (n[0] x n[1] x n[2]), 0 outside, 1 inside
} grid;

// GTS asks for one z slice at a time: a[x][y]
static void slice(gdouble** a, GtsCartesianGrid g, guint k, gpointer data) {
  const grid* gr = data;
  const float* s = gr->f + (size_t)k * gr->n[0] * gr->n[1];
  for (int x = 0; x < gr->n[0]; x++)
    for (int y = 0; y < gr->n[1]; y++) a[x][y] = s[(size_t)y * gr->n[0] + x];
}

// binomial [1 4 6 4 1]/16 along each axis: takes the stair steps off the
// voxel mask without moving its 0.5 level by more than a fraction of a voxel
static void smooth(grid* g, float* tmp) {
  const float w[5] = {1 / 16.f, 4 / 16.f, 6 / 16.f, 4 / 16.f, 1 / 16.f};
  size_t stride[3] = {1, (size_t)g->n[0], (size_t)g->n[0] * g->n[1]};
  size_t total = stride[2] * g->n[2];
  for (int axis = 0; axis < 3; axis++) {
    for (size_t i = 0; i < total; i++) {
      int c = (int)(i / stride[axis] % (size_t)g->n[axis]);
      float s = 0;
      for (int k = -2; k <= 2; k++)
        if (c + k >= 0 && c + k < g->n[axis]) s += w[k + 2] * g->f[(size_t)((ptrdiff_t)i + k * (ptrdiff_t)stride[axis])];
      tmp[i] = s;
    }
    memcpy(g->f, tmp, total * sizeof(float));
  }
}

static void count_faces(gpointer item, gpointer data) {
  GtsSurface* s = item;
  guint n = gts_surface_face_number(s);
  guint* best = data;
  if (n > best[0]) best[0] = n;
}

static gint number_vertex(gpointer item, gpointer data) {
  GtsVertex* v = item;
  tx_trimesh* m = data;
  GTS_OBJECT(v)->reserved = GINT_TO_POINTER(m->nv + 1);
  m->v[3 * m->nv] = GTS_POINT(v)->x, m->v[3 * m->nv + 1] = GTS_POINT(v)->y, m->v[3 * m->nv + 2] = GTS_POINT(v)->z;
  m->nv++;
  return 0;
}

static gint take_face(gpointer item, gpointer data) {
  GtsTriangle* t = item;
  tx_trimesh* m = data;
  GtsVertex *a, *b, *c;
  gts_triangle_vertices(t, &a, &b, &c);
  int* o = m->t + 3 * m->nt++;
  o[0] = GPOINTER_TO_INT(GTS_OBJECT(a)->reserved) - 1;
  o[1] = GPOINTER_TO_INT(GTS_OBJECT(b)->reserved) - 1;
  o[2] = GPOINTER_TO_INT(GTS_OBJECT(c)->reserved) - 1;
  return 0;
}

static gint clear_reserved(gpointer item, gpointer data) {
  GTS_OBJECT(item)->reserved = NULL;
  return 0;
}

static gint revert(gpointer item, gpointer data) {
  gts_triangle_revert(item);
  return 0;
}

// GTS orders its edge collapses by cost in a heap filled in the order of a
// hash table of pointers: equal costs (a smooth mask on a grid has many)
// would collapse in an order that changes from run to run. A tiny term from
// the edge's midpoint makes every cost distinct, and the output reproducible.
static gdouble cost(gpointer item, gpointer data) {
  GtsEdge* e = item;
  GtsPoint *a = GTS_POINT(GTS_SEGMENT(e)->v1), *b = GTS_POINT(GTS_SEGMENT(e)->v2);
  double h = sin(12.9898 * (a->x + b->x) + 78.233 * (a->y + b->y) + 37.719 * (a->z + b->z)) * 43758.5453;
  h -= floor(h);
  gdouble c = gts_volume_optimized_cost(e, data);
  return c * (1 + 1e-9 * h) + 1e-30 * h;
}

// decimate: a closed surface of F triangles has 3F/2 edges. The cost is
// Lindstrom and Turk's (volume and boundary preserved); folds over 1 degree
// are refused.
static void coarsen(GtsSurface* s, int faces) {
  if ((int)gts_surface_face_number(s) <= faces) return;
  GtsVolumeOptimizedParams params = {0.5, 0.5, 1e-9};
  guint edges = (guint)(faces / 2 * 3);
  gts_surface_coarsen(s, cost, &params, (GtsCoarsenFunc)gts_volume_optimized_vertex, &params,
                      (GtsStopFunc)gts_coarsen_stop_number, &edges, M_PI / 180.0);
}

static const double* sort_v;  // qsort has no context argument
static int by_position(const void* a, const void* b) {
  const double *p = sort_v + 3 * *(const int*)a, *q = sort_v + 3 * *(const int*)b;
  for (int k = 0; k < 3; k++)
    if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
  return 0;
}
static int by_corners(const void* a, const void* b) {
  const int *p = a, *q = b;
  for (int k = 0; k < 3; k++)
    if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
  return 0;
}

// the surface out of GTS, numbered in a canonical order (vertices by
// position, triangles by their vertices), not in GTS's hash-table order
static bool from_gts(GtsSurface* s, tx_trimesh* out) {
  *out = (tx_trimesh){0};
  int nv = (int)gts_surface_vertex_number(s), nt = (int)gts_surface_face_number(s);
  out->v = malloc((size_t)nv * 3 * sizeof(double));
  out->t = malloc((size_t)nt * 3 * sizeof(int));
  int* order = malloc((size_t)(nv > 0 ? nv : 1) * sizeof(int));
  int* rank = malloc((size_t)(nv > 0 ? nv : 1) * sizeof(int));
  double* v = malloc((size_t)(nv > 0 ? nv : 1) * 3 * sizeof(double));
  if (!out->v || !out->t || !order || !rank || !v) {
    tx_trimesh_free(out);
    free(order), free(rank), free(v);
    tx_set_error("out of memory for a surface of %d triangles", nt);
    return false;
  }
  gts_surface_foreach_vertex(s, number_vertex, out);
  gts_surface_foreach_face(s, take_face, out);
  gts_surface_foreach_vertex(s, clear_reserved, NULL);
  for (int i = 0; i < nv; i++) order[i] = i;
  sort_v = out->v;
  qsort(order, (size_t)nv, sizeof(int), by_position);
  for (int i = 0; i < nv; i++) rank[order[i]] = i, memcpy(v + 3 * i, out->v + 3 * order[i], 3 * sizeof(double));
  memcpy(out->v, v, (size_t)nv * 3 * sizeof(double));
  for (int i = 0; i < nt; i++) {
    int* t = out->t + 3 * i;
    int a = rank[t[0]], b = rank[t[1]], c = rank[t[2]];
    // the smallest first, the orientation kept
    if (a < b && a < c) t[0] = a, t[1] = b, t[2] = c;
    else if (b < c) t[0] = b, t[1] = c, t[2] = a;
    else t[0] = c, t[1] = a, t[2] = b;
  }
  qsort(out->t, (size_t)nt, 3 * sizeof(int), by_corners);
  free(order), free(rank), free(v);
  return true;
}

// a closed oriented surface as GTS holds it: each triangle from its edges
// ab, bc, ca keeps the order a, b, c
static GtsSurface* to_gts(const tx_trimesh* m) {
  GtsSurface* s = gts_surface_new(gts_surface_class(), gts_face_class(), gts_edge_class(), gts_vertex_class());
  GtsVertex** vs = malloc((size_t)m->nv * sizeof(GtsVertex*));
  if (!vs) {
    gts_object_destroy(GTS_OBJECT(s));
    return NULL;
  }
  for (int i = 0; i < m->nv; i++) vs[i] = gts_vertex_new(gts_vertex_class(), m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
  for (int i = 0; i < m->nt; i++) {
    GtsEdge* e[3];
    for (int k = 0; k < 3; k++) {
      GtsVertex *a = vs[m->t[3 * i + k]], *b = vs[m->t[3 * i + (k + 1) % 3]];
      GtsSegment* seg = gts_vertices_are_connected(a, b);
      e[k] = seg ? GTS_EDGE(seg) : gts_edge_new(gts_edge_class(), a, b);
    }
    gts_surface_add_face(s, gts_face_new(gts_face_class(), e[0], e[1], e[2]));
  }
  // a vertex no triangle uses belongs to no surface
  for (int i = 0; i < m->nv; i++)
    if (!vs[i]->segments) gts_object_destroy(GTS_OBJECT(vs[i]));
  free(vs);
  return s;
}

static bool inside(const tx_lagb_volume* v, const bool* in, int x, int y, int z) {
  if (x < 0 || y < 0 || z < 0 || x >= v->n[0] || y >= v->n[1] || z >= v->n[2]) return false;
  return in[v->label[((int64_t)z * v->n[1] + y) * v->n[0] + x]];
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

bool tx_lagb_surface(const tx_lagb_volume* v, const tx_lagb_surface_def* d, tx_trimesh* out,
                     tx_lagb_surface_stats* st) {
  *out = (tx_trimesh){0};
  *st = (tx_lagb_surface_stats){0};
  double t0 = now();
  if (d->faces < 4 || d->faces % 2) {
    tx_set_error("faces = %d: a closed surface has an even number of triangles, at least 4", d->faces);
    return false;
  }
  // the organ's bounding box in voxels
  bool in[65536] = {false};
  for (int i = 0; i < d->nlabels; i++) in[d->labels[i]] = true;
  int lo[3] = {v->n[0], v->n[1], v->n[2]}, hi[3] = {-1, -1, -1};
  for (int z = 0; z < v->n[2]; z++)
    for (int y = 0; y < v->n[1]; y++)
      for (int x = 0; x < v->n[0]; x++)
        if (in[v->label[((int64_t)z * v->n[1] + y) * v->n[0] + x]]) {
          int p[3] = {x, y, z};
          for (int k = 0; k < 3; k++) lo[k] = p[k] < lo[k] ? p[k] : lo[k], hi[k] = p[k] > hi[k] ? p[k] : hi[k];
          st->voxels++;
        }
  if (st->voxels == 0) {
    tx_set_error("label %d is not present", d->labels[0]);
    return false;
  }
  // a big smooth organ at a small target (the peritoneum) would give marching
  // cubes far more triangles than it keeps, and decimation costs per
  // triangle: average its mask over f x f x f blocks first, f chosen so that
  // marching cubes gives about 20 times the target (2.5 triangles per voxel
  // face on the boundary, measured)
  int64_t faces_out = 0;
  for (int z = lo[2]; z <= hi[2] + 1; z++)
    for (int y = lo[1]; y <= hi[1] + 1; y++)
      for (int x = lo[0]; x <= hi[0] + 1; x++) {
        bool here = inside(v, in, x, y, z);
        faces_out += here != inside(v, in, x - 1, y, z);
        faces_out += here != inside(v, in, x, y - 1, z);
        faces_out += here != inside(v, in, x, y, z - 1);
      }
  int f = (int)ceil(sqrt(2.5 * (double)faces_out / (20.0 * d->faces)));
  f = f < 1 ? 1 : f > 8 ? 8 : f;
  st->block = f;
  // the padded region and its mask
  grid g;
  for (int k = 0; k < 3; k++) g.n[k] = (hi[k] - lo[k] + f) / f + 2 * PAD;
  size_t total = (size_t)g.n[0] * g.n[1] * g.n[2];
  g.f = calloc(total, sizeof(float));
  float* tmp = malloc(total * sizeof(float));
  if (!g.f || !tmp) {
    free(g.f), free(tmp);
    tx_set_error("out of memory for a region of %d x %d x %d voxels", g.n[0], g.n[1], g.n[2]);
    return false;
  }
  float w = 1.0f / (float)(f * f * f);
  for (int z = lo[2]; z <= hi[2]; z++)
    for (int y = lo[1]; y <= hi[1]; y++)
      for (int x = lo[0]; x <= hi[0]; x++)
        if (in[v->label[((int64_t)z * v->n[1] + y) * v->n[0] + x]])
          g.f[((size_t)((z - lo[2]) / f + PAD) * g.n[1] + ((y - lo[1]) / f + PAD)) * g.n[0] + ((x - lo[0]) / f + PAD)] += w;
  smooth(&g, tmp);
  free(tmp);
  // marching cubes at the half level, or just off it: the smoothed mask holds
  // sums of powers of two and takes 0.5 exactly at grid points, where
  // marching cubes would put several vertices at one place and leave
  // triangles of no area; the level used is no float, so no value equals it
  GtsSurface* s = gts_surface_new(gts_surface_class(), gts_face_class(), gts_edge_class(), gts_vertex_class());
  // a block's centre: its first voxel's centre and (f - 1) / 2 voxels on
  double c[3];
  for (int k = 0; k < 3; k++) c[k] = v->origin[k] + (lo[k] + 0.5 * (f - 1) - PAD * f) * v->spacing[k];
  GtsCartesianGrid cg = {(guint)g.n[0], (guint)g.n[1], (guint)g.n[2], c[0], f * v->spacing[0],
                         c[1], f * v->spacing[1], c[2], f * v->spacing[2]};
  gts_isosurface_cartesian(s, cg, slice, &g, 0.5 + 1e-4 * M_SQRT2);
  free(g.f);
  st->mc_faces = (int)gts_surface_face_number(s);
  // keep the largest piece: a segmentation's specks are not the organ
  GSList* parts = gts_surface_split(s);
  guint best[1] = {0};
  g_slist_foreach(parts, count_faces, best);
  GtsSurface* keep = NULL;
  for (GSList* i = parts; i; i = i->next) {
    GtsSurface* p = i->data;
    if (!keep && gts_surface_face_number(p) == best[0]) keep = p;
    else st->dropped++;
  }
  for (GSList* i = parts; i; i = i->next)
    if (i->data != keep) gts_object_destroy(i->data);
  g_slist_free(parts);
  gts_object_destroy(GTS_OBJECT(s));
  if (!keep || !gts_surface_is_closed(keep) || !gts_surface_is_manifold(keep)) {
    if (keep) gts_object_destroy(GTS_OBJECT(keep));
    tx_set_error("marching cubes gave no closed manifold surface");
    return false;
  }
  if (gts_surface_volume(keep) < 0) gts_surface_foreach_face(keep, (GtsFunc)revert, NULL);
  coarsen(keep, d->faces);
  bool ok = from_gts(keep, out);
  gts_object_destroy(GTS_OBJECT(keep));
  st->seconds = now() - t0;
  return ok;
}

enum { MAX_RUNS = 8 };

bool tx_lagb_tets(const tx_trimesh* surface, int target, const char* prefix, const char* tetgen,
                  tx_lagb_tet_stats* st) {
  *st = (tx_lagb_tet_stats){0};
  double t0 = now();
  if (target < 4) {
    tx_set_error("tets = %d: ask for at least 4", target);
    return false;
  }
  const char* sw = "-pYq1.6/10zQ";
  snprintf(st->switches, sizeof st->switches, "%s", sw);
  // the count goes about as the triangles of the boundary: scale them by
  // target / count until within 5 %, keeping the nearest run's files
  int faces = surface->nt, best = -1, last = -1;
  tx_trimesh best_hull = {0};
  bool ok = true;
  for (int run = 0; run < MAX_RUNS && ok; run++) {
    // built afresh each time: a copy would follow a hash table's order
    GtsSurface* s = to_gts(surface);
    if (!s) {
      tx_set_error("out of memory for a surface of %d triangles", surface->nt);
      ok = false;
      break;
    }
    coarsen(s, faces);
    tx_trimesh hull;
    ok = from_gts(s, &hull);
    gts_object_destroy(GTS_OBJECT(s));
    if (!ok) break;
    int n;
    ok = tx_lagb_tetgen(&hull, prefix, sw, tetgen, &n);
    if (!ok) {
      tx_trimesh_free(&hull);
      break;
    }
    st->runs++;
    last = n;
    if (best < 0 || abs(n - target) < abs(best - target)) {
      best = n;
      tx_trimesh_free(&best_hull);
      best_hull = hull;
    } else {
      tx_trimesh_free(&hull);
    }
    if (abs(n - target) <= target / 20 || (n < target && faces >= surface->nt)) break;
    int next = (int)((double)faces * target / n) & ~1;
    next = next > surface->nt ? surface->nt : next < 8 ? 8 : next;
    if (next == faces) break;
    faces = next;
  }
  // the files on disk are the last run's: make them the best one's
  if (ok && last != best) ok = tx_lagb_tetgen(&best_hull, prefix, sw, tetgen, &last);
  if (ok) st->tets = best, st->hull_faces = best_hull.nt;
  tx_trimesh_free(&best_hull);
  st->seconds = now() - t0;
  return ok;
}
