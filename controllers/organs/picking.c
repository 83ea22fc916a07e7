// Grasper picking on tetrahedral soft bodies (picking.h): the LAGB paper's
// "all colliding triangles are flagged as picked by that instrument ...
// kinematically controlled ... following the displacements of the handle at
// the beginning of every simulation frame ... nodes adjacent to flagged
// triangles ... follow"; here the jaws' segment stands for the closed jaws,
// and the nodes that carry a picked triangle's vertices are the ones moved.
#include "picking.h"

#include "../rotation.h"

#include "../../model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// a carrier node whose weight is below this moves its vertex by nothing
#define TX_PICK_WEIGHT_MIN 1e-4

typedef struct pick_body {
  tx_fem* fem;
  tx_pick_surface s;
  int nodes;
  int8_t* holder;    // (nodes) the hand holding each node, -1 none
  double* offset;    // (nodes x 3) m, a held node in its jaws' frame at the grasp
  int8_t* tri_hand;  // (s.nt) the hand that picked each triangle, -1 none
} pick_body;

typedef struct held {
  int32_t body, node;
} held;

struct tx_picking {
  tx_pick_def d;
  int hands;
  pick_body body[TX_PICK_BODIES_MAX];
  int bodies;
  held* list;  // the held nodes of every hand, packed
  int nlist, cap;
  double* vx;  // (largest nv x 3) m, a surface's vertices at a grasp
  int vcap;
  bool armed[TX_PICK_HANDS_MAX];    // the jaws were open since they last closed
  bool holding[TX_PICK_HANDS_MAX];  // a grasp took something, not yet released
  int nodes[TX_PICK_HANDS_MAX], tris[TX_PICK_HANDS_MAX];
  tx_instrument_pose taken[TX_PICK_HANDS_MAX];  // the jaws at each hand's grasp
  double carried[TX_PICK_HANDS_MAX];            // m, how far the jaws put a held node from where they took it
};

tx_picking* tx_picking_create(const tx_pick_def* d, int hands) {
  if (hands < 1 || hands > TX_PICK_HANDS_MAX) {
    tx_set_error("picking: %d hands, expected 1 to %d", hands, TX_PICK_HANDS_MAX);
    return NULL;
  }
  if (!(d->length > 0) || !(d->reach >= 0) || !(d->closed >= 0) || !(d->open > d->closed) || !isfinite(d->length + d->reach + d->open)) {
    tx_set_error("picking: jaws of length %g m, reach %g m, closed at %g rad and open at %g rad: expected a positive "
                 "length, a reach >= 0 and open above closed",
                 d->length, d->reach, d->closed, d->open);
    return NULL;
  }
  tx_picking* p = calloc(1, sizeof *p);
  if (!p) {
    tx_set_error("picking: out of memory");
    return NULL;
  }
  p->d = *d;
  p->hands = hands;
  return p;
}

void tx_picking_destroy(tx_picking* p) {
  if (!p) return;
  for (int b = 0; b < p->bodies; b++) free(p->body[b].holder), free(p->body[b].offset), free(p->body[b].tri_hand);
  free(p->list);
  free(p->vx);
  free(p);
}

int tx_picking_add(tx_picking* p, tx_fem* fem, const tx_pick_surface* s) {
  if (p->bodies == TX_PICK_BODIES_MAX) return tx_set_error("picking: more than %d bodies", TX_PICK_BODIES_MAX), -1;
  const int n = tx_fem_node_count(fem);
  if (s->per < 1 || s->per > 4 || (!s->w && s->per != 1) || s->nv < 1 || s->nt < 0)
    return tx_set_error("picking: a surface of %d vertices carried by %d nodes each%s", s->nv, s->per,
                        s->w ? "" : " without weights"),
           -1;
  for (int i = 0; i < s->nv * s->per; i++)
    if (s->node[i] < 0 || s->node[i] >= n)
      return tx_set_error("picking: surface vertex %d is carried by node %d of %d", i / s->per, s->node[i], n), -1;
  for (int i = 0; i < 3 * s->nt; i++)
    if (s->tri[i] < 0 || s->tri[i] >= s->nv)
      return tx_set_error("picking: triangle %d names vertex %d of %d", i / 3, s->tri[i], s->nv), -1;
  pick_body* b = &p->body[p->bodies];
  b->holder = malloc((size_t)n);
  b->offset = calloc(3 * (size_t)n, sizeof(double));
  b->tri_hand = malloc((size_t)s->nt + 1);
  held* list = realloc(p->list, sizeof(held) * (size_t)(p->cap + n));
  if (list) p->list = list;
  double* vx = s->nv > p->vcap ? realloc(p->vx, sizeof(double) * 3 * (size_t)s->nv) : p->vx;
  if (vx) p->vx = vx, p->vcap = s->nv > p->vcap ? s->nv : p->vcap;
  if (!b->holder || !b->offset || !b->tri_hand || !list || !vx) {
    free(b->holder), free(b->offset), free(b->tri_hand);
    memset(b, 0, sizeof *b);
    return tx_set_error("picking: out of memory"), -1;
  }
  memset(b->holder, -1, (size_t)n);
  memset(b->tri_hand, -1, (size_t)s->nt + 1);
  b->fem = fem, b->s = *s, b->nodes = n;
  p->cap += n;  // each node is held by one hand at most
  return p->bodies++;
}

// --- geometry ----------------------------------------------------------------------

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void sub(const double a[3], const double b[3], double out[3]) {
  for (int k = 0; k < 3; k++) out[k] = a[k] - b[k];
}
static double dist2(const double a[3], const double b[3]) {
  double d[3];
  sub(a, b, d);
  return dot(d, d);
}

// the point of triangle abc closest to p (Ericson, Real-Time Collision Detection, 5.1.5)
static void closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3], double out[3]) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  sub(b, a, ab), sub(c, a, ac), sub(p, a, ap);
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return (void)memcpy(out, a, 3 * sizeof(double));
  sub(p, b, bp);
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return (void)memcpy(out, b, 3 * sizeof(double));
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double v = d1 / (d1 - d3);
    for (int k = 0; k < 3; k++) out[k] = a[k] + v * ab[k];
    return;
  }
  sub(p, c, cp);
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return (void)memcpy(out, c, 3 * sizeof(double));
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double w = d2 / (d2 - d6);
    for (int k = 0; k < 3; k++) out[k] = a[k] + w * ac[k];
    return;
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (int k = 0; k < 3; k++) out[k] = b[k] + w * (c[k] - b[k]);
    return;
  }
  double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
  for (int k = 0; k < 3; k++) out[k] = a[k] + ab[k] * v + ac[k] * w;
}

static double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }

// the closest points of segments p1q1 and p2q2 (Ericson 5.1.9); their squared distance
static double closest_segments(const double p1[3], const double q1[3], const double p2[3], const double q2[3], double c1[3],
                               double c2[3]) {
  double d1[3], d2[3], r[3];
  sub(q1, p1, d1), sub(q2, p2, d2), sub(p1, p2, r);
  double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), s, t;
  if (a <= 1e-30 && e <= 1e-30) s = t = 0;
  else if (a <= 1e-30) s = 0, t = clamp01(f / e);
  else {
    double c = dot(d1, r);
    if (e <= 1e-30) t = 0, s = clamp01(-c / a);
    else {
      double b = dot(d1, d2), den = a * e - b * b;
      s = den > 0 ? clamp01((b * f - c * e) / den) : 0;
      t = (b * s + f) / e;
      if (t < 0) t = 0, s = clamp01(-c / a);
      else if (t > 1) t = 1, s = clamp01((b - c) / a);
    }
  }
  for (int k = 0; k < 3; k++) c1[k] = p1[k] + d1[k] * s, c2[k] = p2[k] + d2[k] * t;
  return dist2(c1, c2);
}

// the squared distance between segment pq and triangle abc, and the
// triangle's point nearest the segment
static double segment_triangle(const double p[3], const double q[3], const double* v[3], double on_tri[3]) {
  // the segment crossing the triangle: distance 0 (Moller-Trumbore on the segment)
  double e1[3], e2[3], d[3], h[3], s[3], qv[3];
  sub(v[1], v[0], e1), sub(v[2], v[0], e2), sub(q, p, d);
  h[0] = d[1] * e2[2] - d[2] * e2[1], h[1] = d[2] * e2[0] - d[0] * e2[2], h[2] = d[0] * e2[1] - d[1] * e2[0];
  double det = dot(e1, h);
  if (fabs(det) > 1e-30) {
    sub(p, v[0], s);
    double u = dot(s, h) / det;
    qv[0] = s[1] * e1[2] - s[2] * e1[1], qv[1] = s[2] * e1[0] - s[0] * e1[2], qv[2] = s[0] * e1[1] - s[1] * e1[0];
    double w = dot(d, qv) / det, t = dot(e2, qv) / det;
    if (u >= 0 && w >= 0 && u + w <= 1 && t >= 0 && t <= 1) {
      for (int k = 0; k < 3; k++) on_tri[k] = p[k] + t * d[k];
      return 0;
    }
  }
  // else the nearest of: each end to the triangle, the segment to each edge
  double best = INFINITY, c[3], c2[3];
  const double* ends[2] = {p, q};
  for (int i = 0; i < 2; i++) {
    closest_on_triangle(ends[i], v[0], v[1], v[2], c);
    double d2 = dist2(ends[i], c);
    if (d2 < best) best = d2, memcpy(on_tri, c, sizeof c);
  }
  for (int i = 0; i < 3; i++) {
    double d2 = closest_segments(p, q, v[i], v[(i + 1) % 3], c, c2);
    if (d2 < best) best = d2, memcpy(on_tri, c2, sizeof c2);
  }
  return best;
}

// --- grasp and release -------------------------------------------------------------

static void vertices(const tx_picking* p, const pick_body* b, const double* pos) {
  const tx_pick_surface* s = &b->s;
  for (int v = 0; v < s->nv; v++)
    for (int a = 0; a < 3; a++) {
      double x = 0;
      for (int k = 0; k < s->per; k++) x += (s->w ? s->w[s->per * v + k] : 1) * pos[3 * s->node[s->per * v + k] + a];
      p->vx[3 * v + a] = x;
    }
}

// hand h's jaws closed: the triangles within reach of the jaws' segment, and
// the free nodes carrying them; returns the triangles picked (point: their
// nearest points' mean), 0 when they carry no free node
static int grasp(tx_picking* p, int h, const tx_instrument_pose* j, const double* const* pos, double point[3]) {
  double tip[3], ahead[3] = {p->d.length, 0, 0};
  tx_quat_rotate(j->quat, false, ahead, tip);
  for (int a = 0; a < 3; a++) tip[a] += j->pos[a];
  const double r2 = p->d.reach * p->d.reach;
  int tris = 0;
  point[0] = point[1] = point[2] = 0;
  for (int bi = 0; bi < p->bodies; bi++) {
    pick_body* b = &p->body[bi];
    const tx_pick_surface* s = &b->s;
    vertices(p, b, pos[bi]);
    for (int t = 0; t < s->nt; t++) {
      if (b->tri_hand[t] >= 0) continue;  // the other hand's
      const double* v[3] = {p->vx + 3 * s->tri[3 * t], p->vx + 3 * s->tri[3 * t + 1], p->vx + 3 * s->tri[3 * t + 2]};
      double on[3] = {0, 0, 0};
      if (!(segment_triangle(j->pos, tip, v, on) <= r2)) continue;
      b->tri_hand[t] = (int8_t)h;
      tris++;
      for (int a = 0; a < 3; a++) point[a] += on[a];
      for (int c = 0; c < 3; c++) {
        const int vert = s->tri[3 * t + c];
        for (int k = 0; k < s->per; k++) {
          const int n = s->node[s->per * vert + k];
          if (s->w && fabs(s->w[s->per * vert + k]) < TX_PICK_WEIGHT_MIN) continue;
          if (b->holder[n] >= 0) continue;  // held already (this hand's, or the other's)
          if (tx_fem_is_kinematic(b->fem, n)) continue;  // carried by something else (a rigid body it is bolted to)
          const double* x = pos[bi] + 3 * n;
          tx_fem_set_kinematic(b->fem, n, x);
          if (!tx_fem_is_kinematic(b->fem, n)) continue;  // fixed: it stays where the anatomy holds it
          double rel[3];
          sub(x, j->pos, rel);
          tx_quat_rotate(j->quat, true, rel, b->offset + 3 * n);
          b->holder[n] = (int8_t)h;
          p->list[p->nlist++] = (held){bi, n};
          p->nodes[h]++;
        }
      }
    }
  }
  if (p->nodes[h] == 0) { // all held by the other hand or by the anatomy: nothing to carry, no grasp
    for (int bi = 0; bi < p->bodies; bi++)
      for (int t = 0; t < p->body[bi].s.nt; t++)
        if (p->body[bi].tri_hand[t] == h) p->body[bi].tri_hand[t] = -1;
    return 0;
  }
  for (int a = 0; a < 3; a++) point[a] /= tris;
  p->tris[h] = tris;
  return tris;
}

void tx_picking_release(tx_picking* p, int h) {
  int kept = 0;
  for (int i = 0; i < p->nlist; i++) {
    held e = p->list[i];
    pick_body* b = &p->body[e.body];
    if (h >= 0 && b->holder[e.node] != h) {
      p->list[kept++] = e;
      continue;
    }
    b->holder[e.node] = -1;
    tx_fem_release(b->fem, e.node);
  }
  p->nlist = kept;
  for (int bi = 0; bi < p->bodies; bi++)
    for (int t = 0; t < p->body[bi].s.nt; t++)
      if (h < 0 || p->body[bi].tri_hand[t] == h) p->body[bi].tri_hand[t] = -1;
  for (int k = 0; k < p->hands; k++)
    if (h < 0 || k == h) p->nodes[k] = p->tris[k] = 0, p->holding[k] = false, p->carried[k] = 0;
}

static bool jaws_finite(const tx_instrument_pose* j) {
  double qq = j->quat[0] * j->quat[0] + j->quat[1] * j->quat[1] + j->quat[2] * j->quat[2] + j->quat[3] * j->quat[3];
  return isfinite(j->pos[0] + j->pos[1] + j->pos[2] + j->jaw) && qq > 0.5 && qq < 2;
}

bool tx_picking_update(tx_picking* p, int h, const tx_instrument_pose* jaws, const double* const* pos, tx_event* e) {
  if (h < 0 || h >= p->hands || !jaws || !jaws_finite(jaws)) return false;
  tx_instrument_pose j = *jaws;
  const double qn = sqrt(j.quat[0] * j.quat[0] + j.quat[1] * j.quat[1] + j.quat[2] * j.quat[2] + j.quat[3] * j.quat[3]);
  for (int a = 0; a < 4; a++) j.quat[a] /= qn;
  bool sent = false;
  if (j.jaw >= p->d.open) {
    if (p->holding[h]) {
      tx_picking_release(p, h);
      *e = (tx_event){.kind = TX_EVENT_RELEASE, .source = (uint32_t)h};
      sent = true;
    }
    p->armed[h] = true;
  } else if (j.jaw <= p->d.closed && p->armed[h]) {
    p->armed[h] = false;
    double point[3];
    if (grasp(p, h, &j, pos, point) > 0) {
      p->holding[h] = true;
      p->taken[h] = j;
      *e = (tx_event){.kind = TX_EVENT_GRASP, .source = (uint32_t)h};
      memcpy(e->grasp.point, point, sizeof point);
      e->grasp.jaw = j.jaw;
      e->grasp.force = 0;
      sent = true;
    }
  }
  // every node this hand holds where its offset in the jaws' frame puts it
  p->carried[h] = 0;
  for (int i = 0; i < p->nlist && p->holding[h]; i++) {
    pick_body* b = &p->body[p->list[i].body];
    const int n = p->list[i].node;
    if (b->holder[n] != h) continue;
    double x[3], x0[3];
    tx_quat_rotate(j.quat, false, b->offset + 3 * n, x);
    tx_quat_rotate(p->taken[h].quat, false, b->offset + 3 * n, x0);
    for (int a = 0; a < 3; a++) x[a] += j.pos[a], x0[a] += p->taken[h].pos[a];
    tx_fem_set_kinematic_over(b->fem, n, x, p->d.substeps);
    p->carried[h] = fmax(p->carried[h], sqrt(dist2(x, x0)));
  }
  return sent;
}

void tx_picking_force(const tx_picking* p, int h, double f[3]) {
  f[0] = f[1] = f[2] = 0;
  for (int i = 0; i < p->nlist; i++) {
    const pick_body* b = &p->body[p->list[i].body];
    const int n = p->list[i].node;
    double g[3];
    if (b->holder[n] != h || !tx_fem_kinematic_force(b->fem, n, g)) continue;
    for (int a = 0; a < 3; a++) f[a] += g[a];
  }
}

double tx_picking_carried(const tx_picking* p, int h) { return h >= 0 && h < p->hands ? p->carried[h] : 0; }
int tx_picking_nodes(const tx_picking* p, int h) { return h >= 0 && h < p->hands ? p->nodes[h] : 0; }
int tx_picking_triangles(const tx_picking* p, int h) { return h >= 0 && h < p->hands ? p->tris[h] : 0; }
int tx_picking_holder(const tx_picking* p, int body, int node) {
  return body >= 0 && body < p->bodies && node >= 0 && node < p->body[body].nodes ? p->body[body].holder[node] : -1;
}
int tx_picking_triangle_holder(const tx_picking* p, int body, int tri) {
  return body >= 0 && body < p->bodies && tri >= 0 && tri < p->body[body].s.nt ? p->body[body].tri_hand[tri] : -1;
}

// --- the controller's part ------------------------------------------------------

struct tx_pick_ctl {
  tx_picking* p;
  int hands;
  tx_port jaws[TX_PICK_HANDS_MAX];  // read: each hand's tx_instrument_pose
  tx_port out, events;              // written: PREFIX.grasp; emitted: PREFIX.events
  double at[TX_PICK_HANDS_MAX][3];  // m, each hand's pivot, as last read (0 before its first pose)
  long grasps, releases;
  int nodes_max;
  double force_max, carried_max;
  tx_result grasps_result, releases_result, nodes_result, force_result, carried_result;
  tx_warning bad_jaws;
};

int tx_pick_configure(tx_setup* s, const char* prefix, int bodies, tx_fem* const* fem, const tx_pick_surface* surf,
                      tx_pick_ctl** out) {
  *out = NULL;
  const char* names[TX_PICK_HANDS_MAX];
  int hands = tx_table_strs(s, "grasp", names, TX_PICK_HANDS_MAX);
  tx_pick_def d = {tx_table_num(s, "grasp_length_m"), tx_table_num(s, "grasp_reach_m"), tx_table_num(s, "grasp_closed_rad"),
                   tx_table_num(s, "grasp_open_rad"), 0};
  if (hands < 0) return -1;
  if (!(d.open > d.closed))
    return tx_setup_fail(s, "grasp_open_rad", "%g rad: must be above grasp_closed_rad (%g rad)", d.open, d.closed);
  for (int h = 0; h < hands; h++) {
    if (!names[h] || !*names[h]) return tx_setup_fail(s, "grasp", "entry %d is empty", h);
    for (int g = 0; g < h; g++)
      if (strcmp(names[g], names[h]) == 0) return tx_setup_fail(s, "grasp", "'%s' is named twice", names[h]);
  }
  if (hands == 0) return 0;
  tx_pick_ctl* k = calloc(1, sizeof *k);
  if (!k) return tx_setup_fail(s, "grasp", "out of memory");
  k->p = tx_picking_create(&d, hands);
  for (int b = 0; b < bodies && k->p; b++)
    if (tx_picking_add(k->p, fem[b], &surf[b]) < 0) tx_picking_destroy(k->p), k->p = NULL;
  if (!k->p) {
    free(k);
    return tx_setup_fail(s, "grasp", "%s", tx_error());
  }
  *out = k;
  k->hands = hands;
  for (int h = 0; h < hands; h++) k->jaws[h] = TX_READ_OF(s, names[h], tx_instrument_pose);
  char name[128];
  snprintf(name, sizeof name, "%s.grasp", prefix);
  k->out = tx_setup_write(s, &TX_COMPONENT_OF(name, tx_organ_grasp, (uint32_t)hands));
  snprintf(name, sizeof name, "%s.events", prefix);
  k->events = tx_setup_emit(s, name, 64);
  k->grasps_result = tx_setup_result(s, "grasps");
  k->releases_result = tx_setup_result(s, "grasp_releases");
  k->nodes_result = tx_setup_result(s, "grasp_nodes_max");
  k->force_result = tx_setup_result(s, "grasp_force_max_n");
  k->carried_result = tx_setup_result(s, "grasp_carried_max_m");
  k->bad_jaws = tx_setup_warning(s, "bad_jaws");
  return 0;
}

static void publish(tx_ctx* c, tx_pick_ctl* k, bool ok) {
  tx_organ_grasp* rows = tx_write(c, k->out);
  for (int h = 0; h < k->hands; h++) {
    tx_organ_grasp* r = &rows[h];
    memset(r, 0, sizeof *r);
    memcpy(r->x, k->at[h], sizeof r->x);
    r->nodes = tx_picking_nodes(k->p, h);
    r->triangles = tx_picking_triangles(k->p, h);
    if (ok) tx_picking_force(k->p, h, r->f);
    double f = sqrt(dot(r->f, r->f));
    if (!isfinite(f)) memset(r->f, 0, sizeof r->f), f = 0;
    if (f > k->force_max) k->force_max = f;
  }
}

void tx_pick_init(tx_ctx* c, tx_pick_ctl* k) {
  if (!k) return;
  tx_picking_release(k->p, -1);
  for (int h = 0; h < k->hands; h++) k->p->armed[h] = false, k->at[h][0] = k->at[h][1] = k->at[h][2] = 0;
  k->grasps = k->releases = k->nodes_max = 0;
  k->force_max = k->carried_max = 0;
  publish(c, k, false);
}

void tx_pick_before(tx_ctx* c, tx_pick_ctl* k, const double* const* pos) {
  if (!k) return;
  for (int h = 0; h < k->hands; h++) {
    tx_snapshot j = tx_read(c, k->jaws[h]);
    if (j.seq == 0) continue;  // nothing published yet: the jaws wait
    const tx_instrument_pose* jp = j.data;
    if (!jaws_finite(jp)) {
      tx_warn(c, k->bad_jaws);  // what the hand holds stays where it is
      continue;
    }
    memcpy(k->at[h], jp->pos, sizeof k->at[h]);
    tx_event e;
    const bool sent = tx_picking_update(k->p, h, jp, pos, &e);
    k->carried_max = fmax(k->carried_max, tx_picking_carried(k->p, h));
    if (!sent) continue;
    if (e.kind == TX_EVENT_GRASP) k->grasps++;
    else k->releases++;
    tx_emit(c, k->events, &e);
    int n = tx_picking_nodes(k->p, h);
    if (n > k->nodes_max) k->nodes_max = n;
  }
}

void tx_pick_after(tx_ctx* c, tx_pick_ctl* k, bool ok) {
  if (k) publish(c, k, ok);
}

void tx_pick_finish(tx_ctx* c, tx_pick_ctl* k) {
  if (!k) return;
  tx_set_result(c, k->grasps_result, (double)k->grasps);
  tx_set_result(c, k->releases_result, (double)k->releases);
  tx_set_result(c, k->nodes_result, k->nodes_max);
  tx_set_result(c, k->force_result, k->force_max);
  tx_set_result(c, k->carried_result, k->carried_max);
}

void tx_pick_free(tx_pick_ctl* k) {
  if (!k) return;
  tx_picking_destroy(k->p);
  free(k);
}
