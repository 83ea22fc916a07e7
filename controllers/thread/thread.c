// The suture thread: follow-the-leader or an XPBD rod, with contacts
// (thread.h says what each model does).
#include "thread.h"

#include "segment.h"
#include "../collision/tri_bvh.h"
#include "../range_check.h"
#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define BVH_STACK 128
// a bend solve moves no node of two crossing cylinders (their axes at more
// than about 45 degrees) towards the other by more than this fraction of r
#define BEND_CAP 0.05
#define CROSSING_SIN 0.7
#define CROSSING_NEAR 2.2 // cylinders within this many r (2 r: touching)

typedef struct pair {
  int32_t i, j; // cylinders i < j
  double d0;    // m, their distance when listed
} pair;

typedef struct thread_mesh {
  const float* x;            // the caller's arrays
  const int32_t* tri;
  uint32_t nx, ntri, max;
  double thickness;          // m
  tx_tri_bvh bvh;
  bool have_bvh;
} thread_mesh;

struct tx_thread {
  tx_thread_def def;
  int n, nseg, skip;
  double l0, lmax;           // rest and capped segment length, m
  double alpha_d, alpha_b;   // compliances of the distance (m/N) and bending (1/(N m)) constraints
  double* x;                 // (n x 3) positions, m
  double* x0;                // (n x 3) at the start of the substep
  double* v;                 // (n x 3) velocities, m/s
  double* xs;                // (n x 3) at the start of the step, for a fault
  double* vs;                // (n x 3)
  double* v0;                // (n x 3) at the start of the substep
  double* w;                 // (n) inverse masses, 1/kg; 0 for pinned nodes
  double* wf;                // (n) inverse masses of the nodes when free
  double* lam;               // (4 nseg) XPBD multipliers: the distances, then 3 per bend
  double* band;              // (2 nseg) the distances' tridiagonal system, then its Cholesky factor
  double* bend;              // (3 nseg) the bends' pentadiagonal system, then its factor
  double* rhs;               // (3 nseg)
  double* dir;               // (nseg x 3) unit segment directions, x[i] - x[i+1]
  uint8_t* pinned;           // (n)
  uint8_t* severed;          // (nseg) cut links: no distance, no bend across, no contacts
  int first_cut;             // the lowest severed link: the head's piece is nodes 0..first_cut (nseg: none)
  int cuts;
  // punctures: points the thread passes through, in order
  double* punct;             // (max_punctures x 3) where they are, m
  double* arc;               // (max_punctures) the arc length from the head of the thread's point held at each, m
  int npunct;                // points given
  int passed;                // the first this many are passed by the head: the thread runs through them
  int out;                   // but the first this many of those: the thread was pulled out of them (its end through)
  int slid;                  // punctures the thread slid through in the last step
  int8_t* pside;             // (max_punctures) +1: the needle entered the skin there, -1: it came out, 0: not said
  uint8_t* near_punct;       // (n) nodes near a passed puncture or in a bite (entry to exit): no skin contact there
  double* arc_step;          // (max_punctures) arc at the start of the step
  double* arc_sub;           // (max_punctures) and of the substep, for a substep taken again
  uint8_t* slides;           // (max_punctures) rod: 1 where the thread slides through the puncture this substep
  double* pin;               // (n x 3) where pinned nodes are held, m (a held node: in this substep)
  uint8_t* held;             // (n) grasped: 1 pinned by the grasp, 2 pinned before it (a release keeps that pin)
  double* hold_from;         // (n x 3) a held node's place at the start of the step, m
  double* hold_to;           // (n x 3) and at its end
  int nheld;                 // nodes held
  int last_pin;              // the highest pinned node (0: the head alone)
  double taut_excess;        // m, ftl drawn taut through its punctures (ftl_taut): the path's length over the thread's; -1: not
  bool taut;                 // ftl_taut laid it along its path last time
  double head_from[3], head_to[3];
  // the self-contact broadphase: sort and sweep of the cylinders' boxes
  // along one axis, the order kept from substep to substep
  double* box;               // (nseg x 6) each cylinder's box, lo then hi, grown by half the reach
  int32_t* order;            // (nseg) cylinders by their box's low end on the sweep axis
  int32_t* order_tmp;        // (nseg) a merge sort's buffer
  double* key;               // (nseg) the low ends, in that order
  double* xb;                // (n x 3) the positions the pairs were listed at
  int axis;                  // the sweep axis; -1: order not sorted yet
  pair* pairs;               // candidate pairs of the substep
  // the rod's continuous check of a substep (self contacts): the cylinders'
  // boxes swept from x0 to x, sorted and swept as above, in their own order
  double* sbox;              // (nseg x 6)
  double* sb01;              // (nseg x 12) each cylinder's box at x0, then at x
  double* smove;             // (nseg) the larger of its two nodes' moves, m
  int32_t* sorder;           // (nseg)
  double* skey;              // (nseg)
  int saxis;
  int sub_hint;              // rod: substeps the last steps needed (the next step starts from it)
  int npairs, pair_cap;
  uint8_t* colliding;        // (nseg)
  tx_thread_capsule* caps;
  int ncaps;
  // triangle meshes: slot 0 the skin (tx_thread_set_mesh), slots 1.. the
  // rigid meshes (tx_thread_set_rigid_mesh); cur: the one being solved
  thread_mesh* meshes;       // (1 + max_meshes)
  int nslots;
  thread_mesh* cur;
  uint32_t mntri;            // the skin's triangles (0: no skin)
  bool any_mesh;             // some slot has triangles
  bool move_first;           // edge contacts may move a cylinder's first node
  double probe;              // m, the nearest triangle found by a query
  tx_thread_contacts last;
  double head_force[3];      // N, the rod's constraints on the head in the last substep
  int faults;
  // the rod's bends near crossings (rod_solve, limit_energy)
  double* dxb;               // (n x 3) the bends' move of each node in one solve, m
  double* bscale;            // (n) the fraction of it each node takes
  bool capped;               // some bend move was cut in this substep
  bool thrown;               // and some would have carried two crossing strands through each other
  double e_sub;              // J, kinetic, bending and gravity's energy at the start of the substep
};

// ---------------------------------------------------------------------------
// small vector helpers

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double dist3_sq(const double a[3], const double b[3]) {
  double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return dot3(d, d);
}
static double dist3(const double a[3], const double b[3]) {
  double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return sqrt(dot3(d, d));
}

// ---------------------------------------------------------------------------
// definition

tx_thread_def tx_thread_def_default(void) {
  tx_thread_def d;
  memset(&d, 0, sizeof d);
  d.nodes = 64;
  d.radius = 0.00025;
  d.length = 0.2;
  d.model = TX_THREAD_FTL;
  d.direction[0] = 1;
  d.pin_tail = false;
  d.self_collision = true;
  d.slack = false;
  d.youngs_modulus = 2e9;
  d.bend_factor = 1;
  d.density = 1140;
  d.gravity = 9.81;
  d.damping = 1;
  d.iterations = 2;
  d.max_substep = 1e-3;
  d.max_substeps = 64;
  d.max_stretch = 0.05;
  d.max_shapes = 16;
  d.max_triangles = 0;
  d.max_meshes = 0;
  d.max_mesh_triangles = 0;
  d.max_punctures = 16;
  d.puncture_friction = 0;
  d.puncture_capture = 0.001;
  d.self_friction = 0;
  return d;
}

static int range(const char* name, double v, double lo, bool open_lo, double hi, bool open_hi, const char* units) {
  return tx_check_range("thread", name, v, lo, open_lo, hi, open_hi, units);
}

int tx_thread_def_check(const tx_thread_def* d) {
  static const char* const head_name[3] = {"head[0]", "head[1]", "head[2]"};
  static const char* const dir_name[3] = {"direction[0]", "direction[1]", "direction[2]"};
  if (tx_check_count("thread", "nodes", d->nodes, 2, 100000)) return -1;
  if (range("radius", d->radius, 0, true, 0.01, false, "m")) return -1;
  if (range("length", d->length, 0, true, 10, false, "m")) return -1;
  if (d->model != TX_THREAD_FTL && d->model != TX_THREAD_ROD)
    return tx_check_fail("thread: model = %d, must be ftl (0) or rod (1)", (int)d->model);
  for (int a = 0; a < 3; a++) {
    if (range(head_name[a], d->head[a], -10, false, 10, false, "m")) return -1;
    if (range(dir_name[a], d->direction[a], -1e6, false, 1e6, false, "")) return -1;
  }
  if (dot3(d->direction, d->direction) < 1e-24) return tx_check_fail("thread: direction = (0, 0, 0), must not be zero");
  if (range("youngs_modulus", d->youngs_modulus, 0, true, 1e16, false, "Pa")) return -1;
  if (range("bend_factor", d->bend_factor, 0, false, 1, false, "")) return -1;
  if (range("density", d->density, 0, true, 1e5, false, "kg/m^3")) return -1;
  if (range("gravity", d->gravity, 0, false, 100, false, "m/s^2")) return -1;
  if (range("damping", d->damping, 0, false, 1e4, false, "1/s")) return -1;
  if (tx_check_count("thread", "iterations", d->iterations, 1, 1000)) return -1;
  if (range("max_substep", d->max_substep, 1e-7, false, 0.1, false, "s")) return -1;
  if (tx_check_count("thread", "max_substeps", d->max_substeps, 1, 10000)) return -1;
  if (range("max_stretch", d->max_stretch, 0, false, 1, false, "")) return -1;
  if (tx_check_count("thread", "max_shapes", d->max_shapes, 0, 4096)) return -1;
  if (tx_check_count("thread", "max_triangles", d->max_triangles, 0, 10000000)) return -1;
  if (tx_check_count("thread", "max_meshes", d->max_meshes, 0, TX_THREAD_MAX_MESHES)) return -1;
  if (tx_check_count("thread", "max_mesh_triangles", d->max_mesh_triangles, 0, 10000000)) return -1;
  if (tx_check_count("thread", "max_punctures", d->max_punctures, 0, 1024)) return -1;
  if (range("puncture_friction", d->puncture_friction, 0, false, 100, false, "N")) return -1;
  if (range("puncture_capture", d->puncture_capture, 0, true, 0.1, false, "m")) return -1;
  if (range("self_friction", d->self_friction, 0, false, 10, false, "")) return -1;
  return 0;
}

// ---------------------------------------------------------------------------
// creation

static void update_last_pin(tx_thread* t) {
  for (int i = 0; i < t->n; i++) t->w[i] = t->pinned[i] ? 0 : t->wf[i];
  t->last_pin = 0;
  t->taut_excess = -1;
  for (int i = t->n - 1; i > 0; i--)
    if (t->pinned[i]) {
      t->last_pin = i;
      break;
    }
}

tx_thread* tx_thread_create(const tx_thread_def* def) {
  if (tx_thread_def_check(def)) return NULL;
  tx_thread* t = calloc(1, sizeof *t);
  if (!t) goto oom;
  t->def = *def;
  int n = def->nodes, nseg = n - 1;
  t->n = n;
  t->nseg = nseg;
  t->l0 = def->length / nseg;
  t->lmax = t->l0 * (1 + def->max_stretch);
  // cylinders that share a node always touch; so may those a fold of less
  // than 2 r apart (a segment shorter than the diameter): such pairs are not contacts
  t->skip = 1;
  while (t->skip * t->l0 < 2 * def->radius && t->skip < nseg) t->skip++;
  double area = PI * def->radius * def->radius, inertia = PI * pow(def->radius, 4) / 4;
  t->alpha_d = t->l0 / (def->youngs_modulus * area);
  t->alpha_b = def->bend_factor > 0 ? pow(t->l0, 3) / (def->bend_factor * def->youngs_modulus * inertia) : INFINITY;
  t->pair_cap = 16 * nseg + 64;
  t->x = malloc(sizeof(double) * 3 * n);
  t->x0 = malloc(sizeof(double) * 3 * n);
  t->v = calloc(3 * (size_t)n, sizeof(double));
  t->xs = malloc(sizeof(double) * 3 * n);
  t->vs = malloc(sizeof(double) * 3 * n);
  t->v0 = malloc(sizeof(double) * 3 * n);
  t->w = malloc(sizeof(double) * n);
  t->wf = malloc(sizeof(double) * n);
  t->lam = malloc(sizeof(double) * 4 * nseg);
  t->band = malloc(sizeof(double) * 2 * nseg);
  t->bend = malloc(sizeof(double) * 3 * nseg);
  t->rhs = malloc(sizeof(double) * 3 * nseg);
  t->dir = malloc(sizeof(double) * 3 * nseg);
  t->pinned = calloc((size_t)n, 1);
  t->severed = calloc((size_t)nseg, 1);
  t->first_cut = nseg;
  t->punct = malloc(sizeof(double) * 3 * (def->max_punctures + 1));
  t->arc = malloc(sizeof(double) * (def->max_punctures + 1));
  t->near_punct = calloc((size_t)n, 1);
  t->pside = calloc((size_t)def->max_punctures + 1, 1);
  t->arc_step = malloc(sizeof(double) * (def->max_punctures + 1));
  t->arc_sub = malloc(sizeof(double) * (def->max_punctures + 1));
  t->slides = calloc((size_t)def->max_punctures + 1, 1);
  t->pin = calloc(3 * (size_t)n, sizeof(double));
  t->held = calloc((size_t)n, 1);
  t->hold_from = calloc(3 * (size_t)n, sizeof(double));
  t->hold_to = calloc(3 * (size_t)n, sizeof(double));
  t->box = malloc(sizeof(double) * 6 * nseg);
  t->order = malloc(sizeof(int32_t) * nseg);
  t->order_tmp = malloc(sizeof(int32_t) * nseg);
  t->key = malloc(sizeof(double) * nseg);
  t->xb = malloc(sizeof(double) * 3 * n);
  t->axis = -1;
  t->sbox = malloc(sizeof(double) * 6 * nseg);
  t->sb01 = malloc(sizeof(double) * 12 * nseg);
  t->smove = malloc(sizeof(double) * nseg);
  t->sorder = malloc(sizeof(int32_t) * nseg);
  t->skey = malloc(sizeof(double) * nseg);
  t->saxis = -1;
  t->sub_hint = 1;
  t->pairs = malloc(sizeof(pair) * t->pair_cap);
  t->colliding = calloc((size_t)nseg, 1);
  t->caps = malloc(sizeof(tx_thread_capsule) * (def->max_shapes + 1));
  t->dxb = malloc(sizeof(double) * 3 * n);
  t->bscale = malloc(sizeof(double) * n);
  if (!t->x || !t->x0 || !t->v || !t->xs || !t->vs || !t->v0 || !t->w || !t->wf || !t->lam || !t->band || !t->bend || !t->rhs || !t->dir || !t->pinned || !t->severed || !t->punct || !t->arc || !t->near_punct || !t->pside || !t->arc_step || !t->arc_sub || !t->slides || !t->pin || !t->held || !t->hold_from || !t->hold_to || !t->box ||
      !t->order || !t->order_tmp || !t->key || !t->xb || !t->sbox || !t->sb01 || !t->smove || !t->sorder || !t->skey || !t->pairs || !t->colliding || !t->caps || !t->dxb || !t->bscale)
    goto oom;
  t->nslots = 1 + def->max_meshes;
  t->meshes = calloc((size_t)t->nslots, sizeof(thread_mesh));
  if (!t->meshes) goto oom;
  for (int k = 0; k < t->nslots; k++) {
    thread_mesh* m = &t->meshes[k];
    m->max = (uint32_t)(k == 0 ? def->max_triangles : def->max_mesh_triangles);
    if (m->max > 0) {
      if (tx_tri_bvh_init(&m->bvh, m->max)) goto oom;
      m->have_bvh = true;
    }
  }
  t->cur = &t->meshes[0];
  // masses: each segment's mass rho A l0 shared by its two nodes
  double m = def->density * area * t->l0;
  for (int i = 0; i < n; i++) t->wf[i] = (i == 0 || i == n - 1) ? 2 / m : 1 / m;
  double dl = sqrt(dot3(def->direction, def->direction));
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++) t->x[3 * i + a] = def->head[a] + def->direction[a] / dl * t->l0 * i;
  for (int a = 0; a < 3; a++) t->head_from[a] = t->head_to[a] = def->head[a];
  for (int i = 0; i < nseg; i++) t->order[i] = t->sorder[i] = i;
  t->pinned[0] = 1;
  memcpy(t->pin, t->x, sizeof(double) * 3);
  if (def->pin_tail) {
    t->pinned[n - 1] = 1;
    memcpy(t->pin + 3 * (n - 1), t->x + 3 * (n - 1), sizeof(double) * 3);
  }
  update_last_pin(t);
  return t;
oom:
  tx_set_error("thread: out of memory for %d nodes", def->nodes);
  tx_thread_destroy(t);
  return NULL;
}

void tx_thread_destroy(tx_thread* t) {
  if (!t) return;
  free(t->x);
  free(t->x0);
  free(t->v);
  free(t->xs);
  free(t->vs);
  free(t->v0);
  free(t->w);
  free(t->wf);
  free(t->lam);
  free(t->band);
  free(t->bend);
  free(t->rhs);
  free(t->dir);
  free(t->pinned);
  free(t->severed);
  free(t->punct);
  free(t->arc);
  free(t->near_punct);
  free(t->pside);
  free(t->arc_step);
  free(t->arc_sub);
  free(t->slides);
  free(t->pin);
  free(t->held);
  free(t->hold_from);
  free(t->hold_to);
  free(t->box);
  free(t->order);
  free(t->order_tmp);
  free(t->key);
  free(t->xb);
  free(t->sbox);
  free(t->sb01);
  free(t->smove);
  free(t->sorder);
  free(t->skey);
  free(t->pairs);
  free(t->colliding);
  free(t->caps);
  free(t->dxb);
  free(t->bscale);
  for (int k = 0; t->meshes && k < t->nslots; k++)
    if (t->meshes[k].have_bvh) tx_tri_bvh_free(&t->meshes[k].bvh);
  free(t->meshes);
  free(t);
}

const tx_thread_def* tx_thread_get_def(const tx_thread* t) { return &t->def; }
double tx_thread_rest_segment(const tx_thread* t) { return t->l0; }
int tx_thread_node_count(const tx_thread* t) { return t->n; }
void tx_thread_positions(const tx_thread* t, double* out) { memcpy(out, t->x, sizeof(double) * 3 * t->n); }
const double* tx_thread_position(const tx_thread* t, int i) { return t->x + 3 * i; }
const uint8_t* tx_thread_colliding(const tx_thread* t) { return t->colliding; }
int tx_thread_faults(const tx_thread* t) { return t->faults; }
void tx_thread_last_contacts(const tx_thread* t, tx_thread_contacts* out) { *out = t->last; }
void tx_thread_head_force(const tx_thread* t, double out[3]) { memcpy(out, t->head_force, sizeof t->head_force); }
// ftl: how far the head's piece (nodes 0..first_cut) is longer than at rest,
// the length running on from the tail to its pin when the tail is pinned and
// the thread uncut (m; <= 0: not taut), and the sum of its segments from the
// head towards its end
static double ftl_excess(const tx_thread* t, double sum[3]) {
  int n = t->n, end = t->first_cut;
  const double* h = t->x;
  const double* tail = t->x + 3 * end;
  const bool to_pin = end == n - 1 && t->pinned[n - 1];
  const double* far = to_pin ? t->pin + 3 * (n - 1) : tail;
  for (int a = 0; a < 3; a++) sum[a] = far[a] - h[a];
  // drawn taut through punctures, its links lie along the path (chords across
  // the bends): the stretch is the path's length over the thread's
  if (t->def.model == TX_THREAD_FTL && t->taut_excess >= 0) return t->taut_excess;
  double len = 0, rest = t->l0 * end;
  for (int i = 0; i < end; i++) len += dist3(t->x + 3 * i, t->x + 3 * i + 3);
  if (to_pin) len += dist3(far, tail);
  return len - rest;
}

void tx_thread_tension(const tx_thread* t, double stiffness, double max_force, double f[3], double K[9]) {
  const double* h = t->x;
  double sum[3];
  double excess = ftl_excess(t, sum);
  double ls = sqrt(dot3(sum, sum));
  memset(K, 0, sizeof(double) * 9);
  for (int a = 0; a < 3; a++) f[a] = 0;
  if (t->def.model == TX_THREAD_ROD) {
    memcpy(f, t->head_force, sizeof t->head_force);
  } else {
    if (ls > 0 && excess > 0) {
      double mag = stiffness * excess;
      for (int a = 0; a < 3; a++) {
        f[a] = mag * sum[a] / ls;
        for (int b = 0; b < 3; b++) K[3 * a + b] = -stiffness * sum[a] * sum[b] / (ls * ls);
      }
    }
  }
  // the hand feels the friction of each puncture the thread slid through,
  // towards the first it runs through (the rod's constraints carry only what the friction
  // held before it slid: a light thread drawn through moves on at once)
  if (t->slid > 0 && t->passed > 0) {
    const double* p = t->punct + 3 * (t->out < t->passed ? t->out : t->passed - 1); // or the one just left
    double d[3], dl;
    for (int a = 0; a < 3; a++) d[a] = p[a] - h[a];
    dl = sqrt(dot3(d, d));
    if (dl > 0)
      for (int a = 0; a < 3; a++) f[a] += t->def.puncture_friction * t->slid * d[a] / dl;
  }
  double fm = sqrt(dot3(f, f));
  double scale = fm > max_force ? max_force / fm : 1;
  for (int a = 0; a < 3; a++) f[a] = isfinite(f[a]) ? f[a] * scale : 0;
  for (int a = 0; a < 9; a++) K[a] = isfinite(K[a]) ? K[a] : 0;
}

bool tx_thread_pin_of(const tx_thread* t, int i, double out[3]) {
  if (i < 0 || i >= t->n || !t->pinned[i]) return false;
  memcpy(out, t->pin + 3 * i, sizeof(double) * 3);
  return true;
}

double tx_thread_current_length(const tx_thread* t) {
  double s = 0;
  for (int i = 0; i < t->nseg; i++)
    if (!t->severed[i]) s += dist3(t->x + 3 * i, t->x + 3 * i + 3);
  return s;
}

double tx_thread_max_strain(const tx_thread* t) {
  double m = -1;
  for (int i = 0; i < t->nseg; i++) {
    if (t->severed[i]) continue;
    double e = dist3(t->x + 3 * i, t->x + 3 * i + 3) / t->l0 - 1;
    if (e > m) m = e;
  }
  return m;
}

// ---------------------------------------------------------------------------
// inputs

static int check_point(const char* what, const double p[3]) {
  for (int a = 0; a < 3; a++)
    if (!isfinite(p[a]) || fabs(p[a]) > 10)
      return tx_check_fail("thread: %s[%d] = %g m, must be finite and in [-10, 10]", what, a, p[a]);
  return 0;
}

tx_thread_status tx_thread_set_head(tx_thread* t, const double pos[3]) {
  if (check_point("head", pos)) return TX_THREAD_BAD;
  memcpy(t->head_to, pos, sizeof(double) * 3);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_pin(tx_thread* t, int i, const double pos[3]) {
  if (i <= 0 || i >= t->n) {
    tx_set_error("thread: pin node %d, must be in [1, %d]", i, t->n - 1);
    return TX_THREAD_BAD;
  }
  if (check_point("pin", pos)) return TX_THREAD_BAD;
  t->pinned[i] = 1;
  t->nheld -= t->held[i] != 0;
  t->held[i] = 0; // a plain pin now
  memcpy(t->pin + 3 * i, pos, sizeof(double) * 3);
  memcpy(t->x + 3 * i, pos, sizeof(double) * 3);
  memset(t->v + 3 * i, 0, sizeof(double) * 3);
  update_last_pin(t);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_unpin(tx_thread* t, int i) {
  if (i <= 0 || i >= t->n) {
    tx_set_error("thread: unpin node %d, must be in [1, %d]", i, t->n - 1);
    return TX_THREAD_BAD;
  }
  t->pinned[i] = 0;
  t->nheld -= t->held[i] != 0;
  t->held[i] = 0;
  update_last_pin(t);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_hold(tx_thread* t, int i, const double pos[3]) {
  if (i <= 0 || i >= t->n) {
    tx_set_error("thread: hold node %d, must be in [1, %d]", i, t->n - 1);
    return TX_THREAD_BAD;
  }
  if (check_point("hold", pos)) return TX_THREAD_BAD;
  if (!t->held[i]) { // from where it is now
    t->held[i] = t->pinned[i] ? 2 : 1;
    t->nheld++;
    t->pinned[i] = 1;
    memcpy(t->pin + 3 * i, t->x + 3 * i, sizeof(double) * 3);
    memcpy(t->hold_from + 3 * i, t->x + 3 * i, sizeof(double) * 3);
    update_last_pin(t);
  }
  memcpy(t->hold_to + 3 * i, pos, sizeof(double) * 3);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_release(tx_thread* t, int i) {
  if (i <= 0 || i >= t->n) {
    tx_set_error("thread: release node %d, must be in [1, %d]", i, t->n - 1);
    return TX_THREAD_BAD;
  }
  if (!t->held[i]) return TX_THREAD_OK;
  if (t->held[i] == 1) t->pinned[i] = 0;
  t->held[i] = 0;
  t->nheld--;
  update_last_pin(t);
  return TX_THREAD_OK;
}

bool tx_thread_is_held(const tx_thread* t, int i) { return i >= 0 && i < t->n && t->held[i]; }

tx_thread_status tx_thread_set_positions(tx_thread* t, const double* x) {
  for (int i = 0; i < 3 * t->n; i++)
    if (!isfinite(x[i]) || fabs(x[i]) > 10) {
      tx_set_error("thread: positions[%d][%d] = %g m, must be finite and in [-10, 10]", i / 3, i % 3, x[i]);
      return TX_THREAD_BAD;
    }
  memcpy(t->x, x, sizeof(double) * 3 * t->n);
  memset(t->v, 0, sizeof(double) * 3 * t->n);
  for (int i = 0; i < t->n; i++)
    if (t->pinned[i]) memcpy(t->pin + 3 * i, x + 3 * i, sizeof(double) * 3);
  for (int i = 0; i < t->n; i++)
    if (t->held[i]) {
      memcpy(t->hold_from + 3 * i, x + 3 * i, sizeof(double) * 3);
      memcpy(t->hold_to + 3 * i, x + 3 * i, sizeof(double) * 3);
    }
  memcpy(t->head_from, x, sizeof(double) * 3);
  memcpy(t->head_to, x, sizeof(double) * 3);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_set_capsules(tx_thread* t, const tx_thread_capsule* caps, int n) {
  if (n < 0 || n > t->def.max_shapes) {
    tx_set_error("thread: %d capsules, must be in [0, %d] (max_shapes)", n, t->def.max_shapes);
    return TX_THREAD_BAD;
  }
  for (int k = 0; k < n; k++) {
    if (check_point("capsule a", caps[k].a) || check_point("capsule b", caps[k].b)) return TX_THREAD_BAD;
    if (range("capsule radius", caps[k].radius, 0, false, 1, false, "m")) return TX_THREAD_BAD;
  }
  if (n) memcpy(t->caps, caps, sizeof *caps * n);
  t->ncaps = n;
  return TX_THREAD_OK;
}

int tx_thread_cut(tx_thread* t, int seg) {
  if (seg < 0 || seg >= t->nseg) {
    tx_set_error("thread: cut link %d, must be in [0, %d]", seg, t->nseg - 1);
    return -1;
  }
  if (t->severed[seg]) return 0;
  t->severed[seg] = 1;
  t->cuts++;
  if (seg < t->first_cut) t->first_cut = seg;
  // the two new ends lose half a link's mass: each node carries half of each
  // link it still has (a node left alone keeps half a link's)
  double m = t->def.density * PI * t->def.radius * t->def.radius * t->l0;
  for (int i = seg; i <= seg + 1; i++) {
    int links = (i > 0 && !t->severed[i - 1]) + (i < t->nseg && !t->severed[i]);
    t->wf[i] = 2 / (m * (links > 0 ? links : 1));
  }
  update_last_pin(t);
  return 1;
}

const uint8_t* tx_thread_severed(const tx_thread* t) { return t->severed; }
int tx_thread_cut_count(const tx_thread* t) { return t->cuts; }
int tx_thread_head_piece_end(const tx_thread* t) { return t->first_cut; }

// the point of link i nearest p: its fraction along the link in u, the point
// in q; returns its squared distance
static double link_nearest(const tx_thread* t, int i, const double p[3], double* u, double q[3]) {
  const double *a = t->x + 3 * i, *b = a + 3;
  double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  double ee = dot3(e, e), s = ee > 0 ? fmin(1, fmax(0, dot3(ap, e) / ee)) : 0;
  for (int c = 0; c < 3; c++) q[c] = a[c] + s * e[c];
  *u = s;
  return dist3_sq(p, q);
}

int tx_thread_nearest_link(const tx_thread* t, const double p[3], double at[3]) {
  int best = -1;
  double bd = INFINITY;
  for (int i = 0; i < t->nseg; i++) {
    if (t->severed[i]) continue;
    double u, q[3], d2 = link_nearest(t, i, p, &u, q);
    if (d2 < bd) {
      bd = d2, best = i;
      if (at) memcpy(at, q, sizeof q);
    }
  }
  return best;
}

tx_thread_status tx_thread_set_punctures(tx_thread* t, const double* p, const double* side, int n) {
  if (n < 0 || n > t->def.max_punctures) {
    tx_set_error("thread: %d punctures, must be in [0, %d] (max_punctures)", n, t->def.max_punctures);
    return TX_THREAD_BAD;
  }
  for (int k = 0; k < n; k++) {
    if (check_point("puncture", p + 3 * k)) return TX_THREAD_BAD;
    if (side && side[k] != 1 && side[k] != -1 && side[k] != 0) {
      tx_set_error("thread: puncture %d's side is %g, must be +1 (entry), -1 (exit) or 0", k, side[k]);
      return TX_THREAD_BAD;
    }
  }
  if (n) memcpy(t->punct, p, sizeof(double) * 3 * n);
  for (int k = 0; k <= t->def.max_punctures; k++) t->pside[k] = (int8_t)(side && k < n ? side[k] : 0);
  t->npunct = n;
  if (t->passed > n) t->passed = n; // a list that shrank: those past its end are gone
  if (t->out > t->passed) t->out = t->passed;
  return TX_THREAD_OK;
}

int tx_thread_punctures_passed(const tx_thread* t) { return t->passed; }
int tx_thread_punctures_slid(const tx_thread* t) { return t->slid; }
double tx_thread_puncture_arc(const tx_thread* t, int k) { return k >= t->out && k < t->passed ? t->arc[k] : -1; }
int tx_thread_punctures_out(const tx_thread* t) { return t->out; }

static void note_meshes(tx_thread* t) {
  t->mntri = t->meshes[0].ntri;
  t->any_mesh = false;
  for (int k = 0; k < t->nslots; k++) t->any_mesh |= t->meshes[k].ntri > 0;
}

static tx_thread_status set_slot(tx_thread* t, thread_mesh* m, const char* room, const float* x, uint32_t nx,
                                 const int32_t* tri, uint32_t ntri, double thickness) {
  if (ntri == 0) {
    m->ntri = 0;
    note_meshes(t);
    return TX_THREAD_OK;
  }
  if (!m->have_bvh || ntri > m->max) {
    tx_set_error("thread: %u mesh triangles, more than %s = %u", ntri, room, m->max);
    return TX_THREAD_BAD;
  }
  if (range("thickness", thickness, 0, false, 0.02, false, "m")) return TX_THREAD_BAD;
  bool same = m->ntri == ntri && m->nx == nx && tx_tri_bvh_same(&m->bvh, tri, ntri);
  if (same) {
    tx_tri_bvh_refit(&m->bvh, x);
  } else if (tx_tri_bvh_build(&m->bvh, x, nx, tri, ntri)) {
    tx_set_error("thread: mesh triangle index outside [0, %u)", nx);
    m->ntri = 0;
    note_meshes(t);
    return TX_THREAD_BAD;
  }
  m->x = x;
  m->tri = tri;
  m->nx = nx;
  m->ntri = ntri;
  m->thickness = thickness;
  note_meshes(t);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_set_mesh(tx_thread* t, const float* x, uint32_t nx, const int32_t* tri, uint32_t ntri,
                                    double thickness) {
  return set_slot(t, &t->meshes[0], "max_triangles", x, nx, tri, ntri, thickness);
}

tx_thread_status tx_thread_set_rigid_mesh(tx_thread* t, int k, const float* x, uint32_t nx, const int32_t* tri,
                                          uint32_t ntri) {
  if (k < 0 || k >= t->def.max_meshes) {
    tx_set_error("thread: rigid mesh %d, must be in [0, max_meshes = %d)", k, t->def.max_meshes);
    return TX_THREAD_BAD;
  }
  return set_slot(t, &t->meshes[1 + k], "max_mesh_triangles", x, nx, tri, ntri, 0);
}

// ---------------------------------------------------------------------------
// contacts

// cylinder i against cylinder j: pushes them to 2 r apart (positions
// weighted by the closest points' parameters and inverse masses)
static void solve_self_pair(tx_thread* t, int i, int j) {
  double* x = t->x;
  tx_seg_closest c;
  tx_seg_closest_points(x + 3 * i, x + 3 * i + 3, x + 3 * j, x + 3 * j + 3, &c);
  double d2r = 2 * t->def.radius;
  if (c.dist >= d2r) return;
  double n[3];
  if (c.dist > 1e-12 * d2r) {
    for (int a = 0; a < 3; a++) n[a] = (c.a[a] - c.b[a]) / c.dist;
  } else {
    // crossing exactly: the side they were on at the start of the substep
    tx_seg_closest c0;
    tx_seg_closest_points(t->x0 + 3 * i, t->x0 + 3 * i + 3, t->x0 + 3 * j, t->x0 + 3 * j + 3, &c0);
    if (c0.dist > 0) {
      for (int a = 0; a < 3; a++) n[a] = (c0.a[a] - c0.b[a]) / c0.dist;
    } else {
      n[0] = 0, n[1] = 1, n[2] = 0;
    }
  }
  double wi = t->w[i] * (1 - c.t), wi1 = t->w[i + 1] * c.t, wj = t->w[j] * (1 - c.s), wj1 = t->w[j + 1] * c.s;
  double den = wi * (1 - c.t) + wi1 * c.t + wj * (1 - c.s) + wj1 * c.s;
  if (den <= 0) return;
  double depth = d2r - c.dist, dl = depth / den, f[3];
  for (int a = 0; a < 3; a++) f[a] = dl * n[a];
  // Coulomb friction (rod), position-based (Macklin et al. 2014): the
  // contact points' relative move across n since the start of the substep
  // is undone while it is within mu times the depth pushed out (sticking),
  // and cut by that much when beyond (sliding)
  double mu = t->def.self_friction;
  if (mu > 0 && t->def.model == TX_THREAD_ROD) {
    const double* y = t->x0;
    double rel[3], rn = 0;
    for (int a = 0; a < 3; a++) {
      double pa = x[3 * i + a] + c.t * (x[3 * i + 3 + a] - x[3 * i + a]) - (y[3 * i + a] + c.t * (y[3 * i + 3 + a] - y[3 * i + a]));
      double pb = x[3 * j + a] + c.s * (x[3 * j + 3 + a] - x[3 * j + a]) - (y[3 * j + a] + c.s * (y[3 * j + 3 + a] - y[3 * j + a]));
      rel[a] = pa - pb;
      rn += rel[a] * n[a];
    }
    double tl = 0;
    for (int a = 0; a < 3; a++) {
      rel[a] -= rn * n[a];
      tl += rel[a] * rel[a];
    }
    tl = sqrt(tl);
    if (tl > 0) {
      double k = tl <= mu * depth ? 1 : mu * depth / tl;
      for (int a = 0; a < 3; a++) f[a] -= k * rel[a] / den;
    }
  }
  for (int a = 0; a < 3; a++) {
    x[3 * i + a] += wi * f[a];
    x[3 * i + 3 + a] += wi1 * f[a];
    x[3 * j + a] -= wj * f[a];
    x[3 * j + 3 + a] -= wj1 * f[a];
  }
}

// sorts order by the boxes' low ends on the axis: insertion sort, near
// linear on the last substep's order; a merge sort (no allocation: its
// buffer is the thread's) when the axis changed or the order is far off
static void sort_boxes_in(tx_thread* t, const double* box, int32_t* o, double* key, int* cur, int axis) {
  int n = t->nseg;
  long budget = *cur == axis ? 8L * n + 64 : 0;
  *cur = axis;
  for (int p = 1; p < n && budget > 0; p++) {
    int32_t it = o[p];
    double k = box[6 * it + axis];
    int q = p;
    while (q > 0 && box[6 * o[q - 1] + axis] > k && budget-- > 0) {
      o[q] = o[q - 1];
      q--;
    }
    o[q] = it;
  }
  if (budget <= 0) {
    int32_t *src = o, *dst = t->order_tmp;
    for (int wdt = 1; wdt < n; wdt *= 2) {
      for (int lo = 0; lo < n; lo += 2 * wdt) {
        int mid = lo + wdt < n ? lo + wdt : n, hi = lo + 2 * wdt < n ? lo + 2 * wdt : n;
        int i = lo, j = mid, k = lo;
        while (i < mid && j < hi) dst[k++] = box[6 * src[j] + axis] < box[6 * src[i] + axis] ? src[j++] : src[i++];
        while (i < mid) dst[k++] = src[i++];
        while (j < hi) dst[k++] = src[j++];
      }
      int32_t* sw = src;
      src = dst, dst = sw;
    }
    if (src != o) memcpy(o, src, sizeof(int32_t) * n);
  }
  for (int p = 0; p < n; p++) key[p] = box[6 * o[p] + axis];
}

static void sort_boxes(tx_thread* t, int axis) { sort_boxes_in(t, t->box, t->order, t->key, &t->axis, axis); }

// the candidate pairs of the substep: cylinders whose boxes, grown by the
// contact distance and a margin, overlap (sort and sweep along the axis of
// the thread's longest extent), so that every pair that can come within 2 r
// during the substep is listed once
static void broadphase(tx_thread* t, double margin) {
  const double* x = t->x;
  int nseg = t->nseg;
  double reach = 2 * t->def.radius + margin, g = 0.5 * reach;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i < nseg; i++) {
    const double *p = x + 3 * i, *q = p + 3;
    double* b = t->box + 6 * i;
    for (int a = 0; a < 3; a++) {
      double l = p[a] < q[a] ? p[a] : q[a], h = p[a] < q[a] ? q[a] : p[a];
      b[a] = l - g, b[a + 3] = h + g;
      if (l < lo[a]) lo[a] = l;
      if (h > hi[a]) hi[a] = h;
    }
  }
  // the axis of the longest extent; kept unless another is clearly longer
  // (a change costs a full sort)
  int axis = t->axis < 0 ? 0 : t->axis;
  for (int a = 0; a < 3; a++)
    if (hi[a] - lo[a] > 1.25 * (hi[axis] - lo[axis])) axis = a;
  if (t->axis < 0)
    for (int a = 0; a < 3; a++)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  sort_boxes(t, axis);
  int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  t->npairs = 0;
  memcpy(t->xb, x, sizeof(double) * 3 * t->n);
  for (int p = 0; p < nseg; p++) {
    int i = t->order[p];
    if (t->severed[i]) continue;
    const double* bi = t->box + 6 * i;
    double end = bi[axis + 3];
    for (int q = p + 1; q < nseg && t->key[q] <= end; q++) {
      int j = t->order[q];
      const double* bj = t->box + 6 * j;
      if (bj[a1] > bi[a1 + 3] || bi[a1] > bj[a1 + 3] || bj[a2] > bi[a2 + 3] || bi[a2] > bj[a2 + 3]) continue;
      int lo_i = i < j ? i : j, hi_j = i < j ? j : i;
      if (hi_j <= lo_i + t->skip || t->severed[j]) continue;
      t->last.broad_pairs++;
      tx_seg_closest cl;
      tx_seg_closest_points(x + 3 * lo_i, x + 3 * lo_i + 3, x + 3 * hi_j, x + 3 * hi_j + 3, &cl);
      if (cl.dist >= reach) continue;
      if (t->npairs < t->pair_cap) t->pairs[t->npairs++] = (pair){lo_i, hi_j, cl.dist};
      // held apart at exactly 2 r, touching cylinders stay marked
      if (cl.dist < 2 * t->def.radius * 1.01) {
        t->last.self_pairs++;
        t->colliding[lo_i] = t->colliding[hi_j] = 1;
      }
    }
  }
}

// a pair listed d0 apart is still at least d0 - 2 D apart when no node
// moved more than D since: such pairs, most of those a few cylinders apart
// along the thread, are skipped without their closest points
static void solve_self(tx_thread* t) {
  double m2 = 0;
  for (int i = 0; i < t->n; i++) {
    double s = dist3_sq(t->x + 3 * i, t->xb + 3 * i);
    if (s > m2) m2 = s;
  }
  double far = 2 * t->def.radius + 2 * sqrt(m2);
  for (int k = 0; k < t->npairs; k++)
    if (t->pairs[k].d0 < far) solve_self_pair(t, t->pairs[k].i, t->pairs[k].j);
}

// min and max written out: fmin and fmax are library calls here (NaN rules)
static double mn(double a, double b) { return a < b ? a : b; }
static double mx(double a, double b) { return a < b ? b : a; }

// the distance of two axis-aligned boxes (lo then hi), a lower bound of the
// distance of anything in one to anything in the other
static double box_gap(const double* a, const double* b) {
  double s = 0;
  for (int k = 0; k < 3; k++) {
    double g = mx(a[k] - b[k + 3], b[k] - a[k + 3]);
    if (g > 0) s += g * g;
  }
  return sqrt(s);
}

static void seg_box(const double* p, const double* q, double* b) {
  for (int a = 0; a < 3; a++) b[a] = mn(p[a], q[a]), b[a + 3] = mx(p[a], q[a]);
}

// continuous collision (rod): whether the substep, its nodes moving in a
// straight line from x0 to x, kept every two cylinders' centrelines apart.
// Along that motion a point of cylinder i less a point of cylinder j moves
// by an affine function of the two parameters, at most M, the largest of
// the four node pairs' relative moves; so their distance D(s) >= D0 - s M
// and >= D1 - (1 - s) M, and min D >= (D0 + D1 - M) / 2. A substep is
// kept when, for every pair whose swept boxes come within reach, that
// bound and the end distance D1 are at least half of min(r, D0): two
// cylinders apart stay r / 2 apart, two already pressed together (a pulled
// knot) get no more than twice as deep. This bounds the cylinders' motion
// relative to each other, not every node's own move: a loop swinging fast
// as a whole takes one substep. Box gaps bound D0 and D1 from below, so most
// pairs are settled without their closest points.
static bool self_substep_ok(tx_thread* t) {
  const double *x = t->x, *y = t->x0;
  int nseg = t->nseg;
  double r = t->def.radius, half = 0.5 * r, g = 0.25 * r;
  double mprev = dist3(x, y);
  for (int i = 0; i < nseg; i++) {
    double *b = t->sbox + 6 * i, *b01 = t->sb01 + 12 * i;
    seg_box(y + 3 * i, y + 3 * i + 3, b01);
    seg_box(x + 3 * i, x + 3 * i + 3, b01 + 6);
    for (int a = 0; a < 3; a++) b[a] = mn(b01[a], b01[6 + a]) - g, b[a + 3] = mx(b01[3 + a], b01[9 + a]) + g;
    double m = dist3(x + 3 * i + 3, y + 3 * i + 3);
    t->smove[i] = mx(mprev, m);
    mprev = m;
  }
  int axis = t->axis < 0 ? 0 : t->axis;
  sort_boxes_in(t, t->sbox, t->sorder, t->skey, &t->saxis, axis);
  int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  for (int p = 0; p < nseg; p++) {
    int i = t->sorder[p];
    if (t->severed[i]) continue;
    const double* bi = t->sbox + 6 * i;
    double end = bi[axis + 3];
    for (int q = p + 1; q < nseg && t->skey[q] <= end; q++) {
      int j = t->sorder[q];
      const double* bj = t->sbox + 6 * j;
      if (bj[a1] > bi[a1 + 3] || bi[a1] > bj[a1 + 3] || bj[a2] > bi[a2 + 3] || bi[a2] > bj[a2 + 3]) continue;
      int lo = i < j ? i : j, hi = i < j ? j : i;
      if (hi <= lo + t->skip || t->severed[j]) continue;
      const double *l01 = t->sb01 + 12 * lo, *h01 = t->sb01 + 12 * hi;
      double d0 = box_gap(l01, h01), d1 = box_gap(l01 + 6, h01 + 6); // <= D0, D1
      if (d1 >= half && d0 + d1 - (t->smove[lo] + t->smove[hi]) >= 2 * half) continue; // the thresholds are <= r / 2
      double m2 = 0; // M: the largest relative move of a node of lo and one of hi
      for (int u = lo; u <= lo + 1; u++)
        for (int v = hi; v <= hi + 1; v++) {
          double e[3];
          for (int a = 0; a < 3; a++) e[a] = (x[3 * u + a] - y[3 * u + a]) - (x[3 * v + a] - y[3 * v + a]);
          double s = dot3(e, e);
          if (s > m2) m2 = s;
        }
      double M = sqrt(m2);
      if (d1 >= half && d0 + d1 - M >= 2 * half) continue;
      tx_seg_closest c;
      tx_seg_closest_points(y + 3 * lo, y + 3 * lo + 3, y + 3 * hi, y + 3 * hi + 3, &c);
      d0 = c.dist;
      tx_seg_closest_points(x + 3 * lo, x + 3 * lo + 3, x + 3 * hi, x + 3 * hi + 3, &c);
      d1 = c.dist;
      double need = 0.5 * fmin(r, d0);
      if (d1 < need || d0 + d1 - M < 2 * need) return false;
    }
  }
  return true;
}

// A contact at fraction t of a link moves its two nodes by g / den of the
// depth, g = w (1 - t) and w t: the point at t then moves the depth whole.
// With one node pinned (the head at the swage, a node in the jaws) the other
// needs a lever of 1 / t, unbounded as the contact nears the pin (a node
// thrown metres in a step). No node moves more than the depth: near a pin
// the link only turns part of the way out each pass (the iterations and the
// next substeps finish it), and a contact right at a pin cannot throw it.
static double bounded_lever(double g, double den) { return fmin(g / den, 1); }

// every cylinder against every capsule: the thread moves out to r + R
static void solve_capsules(tx_thread* t) {
  double* x = t->x;
  for (int k = 0; k < t->ncaps; k++) {
    const tx_thread_capsule* cp = &t->caps[k];
    double reach = t->def.radius + cp->radius;
    for (int i = 0; i < t->nseg; i++) {
      if (t->severed[i]) continue;
      tx_seg_closest c;
      tx_seg_closest_points(x + 3 * i, x + 3 * i + 3, cp->a, cp->b, &c);
      if (c.dist >= reach) continue;
      double n[3];
      if (c.dist > 1e-12 * reach) {
        for (int a = 0; a < 3; a++) n[a] = (c.a[a] - c.b[a]) / c.dist;
      } else {
        tx_seg_closest c0;
        tx_seg_closest_points(t->x0 + 3 * i, t->x0 + 3 * i + 3, cp->a, cp->b, &c0);
        if (c0.dist > 0)
          for (int a = 0; a < 3; a++) n[a] = (c0.a[a] - c0.b[a]) / c0.dist;
        else
          n[0] = 0, n[1] = 1, n[2] = 0;
      }
      double wi = t->w[i] * (1 - c.t), wi1 = t->w[i + 1] * c.t;
      double den = wi * (1 - c.t) + wi1 * c.t;
      if (den <= 0) continue;
      double depth = reach - c.dist, ka = bounded_lever(wi, den), kb = bounded_lever(wi1, den);
      for (int a = 0; a < 3; a++) {
        x[3 * i + a] += ka * depth * n[a];
        x[3 * i + 3 + a] += kb * depth * n[a];
      }
      t->last.shape_hits++;
    }
  }
}

// the mesh triangles whose boxes meet [lo, hi]: calls fn on each (its 3 corners)
typedef void (*tri_fn)(tx_thread* t, int i, const double v[3][3]);

static void for_triangles_near(tx_thread* t, const float lo[3], const float hi[3], int i, tri_fn fn) {
  const tx_tri_bvh* b = &t->cur->bvh;
  if (b->nnodes == 0) return;
  uint32_t stack[BVH_STACK];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const tx_bvh_node* nd = &b->nodes[stack[--top]];
    if (nd->lo[0] > hi[0] || nd->hi[0] < lo[0] || nd->lo[1] > hi[1] || nd->hi[1] < lo[1] || nd->lo[2] > hi[2] ||
        nd->hi[2] < lo[2])
      continue;
    if (nd->count == 0) {
      if (top + 2 <= BVH_STACK) {
        stack[top++] = nd->first;
        stack[top++] = (uint32_t)(nd - b->nodes) + 1;
      }
      continue;
    }
    for (uint32_t sl = nd->first; sl < nd->first + nd->count; sl++) {
      if (b->order[sl] == UINT32_MAX) continue;
      const int32_t* tv = b->tri + 3 * sl;
      double v[3][3];
      for (int c = 0; c < 3; c++)
        for (int a = 0; a < 3; a++) v[c][a] = t->cur->x[3 * tv[c] + a];
      fn(t, i, v);
    }
  }
}

// node i against one triangle near its move from x0 to x in this substep:
// a move across the triangle goes back to the side it came from (continuous),
// and a node nearer than r + thickness / 2 is pushed out to that distance
static void node_triangle(tx_thread* t, int i, const double v[3][3]) {
  double* p = t->x + 3 * i;
  const double* p0 = t->x0 + 3 * i;
  double reach = t->def.radius + 0.5 * t->cur->thickness;
  double e1[3], e2[3], nrm[3];
  for (int a = 0; a < 3; a++) {
    e1[a] = v[1][a] - v[0][a];
    e2[a] = v[2][a] - v[0][a];
  }
  nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
  nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
  nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
  double nl = sqrt(dot3(nrm, nrm));
  if (nl <= 0) return;
  for (int a = 0; a < 3; a++) nrm[a] /= nl;
  double rel0[3] = {p0[0] - v[0][0], p0[1] - v[0][1], p0[2] - v[0][2]};
  double side = dot3(nrm, rel0) >= 0 ? 1 : -1;
  double tc;
  if (tx_seg_tri_cross(p0, p, v[0], v[1], v[2], &tc)) {
    // crossed the face: back to the crossing point, out on its own side
    for (int a = 0; a < 3; a++) p[a] = p0[a] + tc * (p[a] - p0[a]) + side * reach * nrm[a];
    t->last.mesh_hits++;
  }
  double cp[3], bary[3];
  tx_tri_closest_point(p, v[0], v[1], v[2], cp, bary);
  double d[3] = {p[0] - cp[0], p[1] - cp[1], p[2] - cp[2]};
  double dl = sqrt(dot3(d, d));
  if (dl >= reach) return;
  bool inside = bary[0] > 0 && bary[1] > 0 && bary[2] > 0;
  if (inside || dl <= 1e-12 * reach) {
    // over the face the side it came from decides the way out
    for (int a = 0; a < 3; a++) p[a] = cp[a] + side * reach * nrm[a];
  } else {
    for (int a = 0; a < 3; a++) p[a] = cp[a] + d[a] / dl * reach;
  }
  t->last.mesh_hits++;
}

// node i against every triangle near its move (the box of x0 to x, grown by the reach)
static void solve_mesh_node(tx_thread* t, int i) {
  const double* p = t->x + 3 * i;
  const double* p0 = t->x0 + 3 * i;
  double reach = t->def.radius + 0.5 * t->cur->thickness;
  float lo[3], hi[3];
  for (int a = 0; a < 3; a++) {
    lo[a] = (float)(fmin(p[a], p0[a]) - reach) - 1e-6f;
    hi[a] = (float)(fmax(p[a], p0[a]) + reach) + 1e-6f;
  }
  for_triangles_near(t, lo, hi, i, node_triangle);
}

// the distance from p to the segment ab
static double point_edge_dist(const double p[3], const double a[3], const double b[3]) {
  double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ee = dot3(e, e), u = 0, q[3];
  if (ee > 0) u = fmin(1, fmax(0, (dot3(p, e) - dot3(a, e)) / ee));
  for (int k = 0; k < 3; k++) q[k] = a[k] + u * e[k];
  return dist3(p, q);
}

// cylinder i against the three edges of a triangle: a cylinder cannot pass
// across an edge (the skin's border, a fold), so its nodes cannot end up on
// two sides of the skin without going round it. The side is the one the
// cylinder was on at the start of the substep.
static void edge_contacts(tx_thread* t, int i, const double v[3][3]) {
  double reach = t->def.radius + 0.5 * t->cur->thickness;
  double* x = t->x;
  double wi = t->move_first ? t->w[i] : 0, wj = t->w[i + 1];
  for (int e = 0; e < 3; e++) {
    const double *va = v[e], *vb = v[(e + 1) % 3];
    tx_seg_closest c, c0;
    tx_seg_closest_points(x + 3 * i, x + 3 * i + 3, va, vb, &c);
    if (c.dist >= reach) continue;
    tx_seg_closest_points(t->x0 + 3 * i, t->x0 + 3 * i + 3, va, vb, &c0);
    double n[3], sep[3] = {c.a[0] - c.b[0], c.a[1] - c.b[1], c.a[2] - c.b[2]};
    double sep0[3] = {c0.a[0] - c0.b[0], c0.a[1] - c0.b[1], c0.a[2] - c0.b[2]};
    if (c0.dist > 0 && (c.dist <= 1e-12 * reach || dot3(sep, sep0) < 0)) {
      for (int a = 0; a < 3; a++) n[a] = sep0[a] / c0.dist;
    } else if (c.dist > 0) {
      for (int a = 0; a < 3; a++) n[a] = sep[a] / c.dist;
    } else {
      continue;
    }
    // a pin inside the edge's reach (the head in the needle's hole, a node
    // in jaws at the skin): no turn about it clears the link, and the pin
    // wins; pushing the free end would throw it on every pass
    if ((t->w[i] == 0) != (t->w[i + 1] == 0) && point_edge_dist(x + 3 * (t->w[i] == 0 ? i : i + 1), va, vb) < reach)
      continue;
    double ga = wi * (1 - c.t), gb = wj * c.t, den = ga * (1 - c.t) + gb * c.t;
    if (den <= 0) continue;
    // move A so that it sits reach from the edge along n, no node by more
    // than that (bounded_lever)
    double ka = bounded_lever(ga, den), kb = bounded_lever(gb, den);
    for (int a = 0; a < 3; a++) {
      double delta = n[a] * reach - sep[a];
      x[3 * i + a] += ka * delta;
      x[3 * i + 3 + a] += kb * delta;
    }
    t->last.mesh_hits++;
  }
}

static void solve_mesh_edges(tx_thread* t, int i) {
  double reach = t->def.radius + 0.5 * t->cur->thickness;
  float lo[3], hi[3];
  const double *p = t->x + 3 * i, *p0 = t->x0 + 3 * i;
  for (int a = 0; a < 3; a++) {
    lo[a] = (float)(fmin(fmin(p[a], p[a + 3]), fmin(p0[a], p0[a + 3])) - reach) - 1e-6f;
    hi[a] = (float)(fmax(fmax(p[a], p[a + 3]), fmax(p0[a], p0[a + 3])) + reach) + 1e-6f;
  }
  for_triangles_near(t, lo, hi, i, edge_contacts);
}

// the nearest distance from node i to a triangle, at most what it was
static void nearest_triangle(tx_thread* t, int i, const double v[3][3]) {
  double cp[3];
  tx_tri_closest_point(t->x + 3 * i, v[0], v[1], v[2], cp, NULL);
  double d = dist3(cp, t->x + 3 * i);
  if (d < t->probe) t->probe = d;
}

int tx_thread_fix_near_mesh(tx_thread* t, int first, int last, double limit) {
  if (first < 0 || last >= t->nseg || first > last) {
    tx_set_error("thread: fix cylinders %d to %d, must be within [0, %d]", first, last, t->nseg - 1);
    return -1;
  }
  if (range("fix limit", limit, 0, false, 1, false, "m")) return -1;
  if (t->mntri == 0) return 0;
  t->cur = &t->meshes[0]; // the skin
  t->probe = INFINITY;
  for (int i = first; i <= last + 1; i++) {
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
      lo[a] = (float)(t->x[3 * i + a] - limit) - 1e-6f;
      hi[a] = (float)(t->x[3 * i + a] + limit) + 1e-6f;
    }
    for_triangles_near(t, lo, hi, i, nearest_triangle);
  }
  if (!(t->probe <= limit)) return 0;
  for (int i = first; i <= last + 1; i++)
    if (i > 0) {
      t->pinned[i] = 1;
      t->nheld -= t->held[i] != 0;
      t->held[i] = 0; // fixed: no grasp moves it now
      memcpy(t->pin + 3 * i, t->x + 3 * i, sizeof(double) * 3);
      memset(t->v + 3 * i, 0, sizeof(double) * 3);
    }
  update_last_pin(t);
  return 1;
}

// the thread passes through the skin at a puncture: the nodes near one
// (near_punct) have no skin contact; the rigid meshes have no puncture
static void solve_mesh(tx_thread* t) {
  if (!t->any_mesh) return;
  for (int k = 0; k < t->nslots; k++) {
    t->cur = &t->meshes[k];
    if (t->cur->ntri == 0) continue;
    const uint8_t* skip = k == 0 ? t->near_punct : NULL;
    t->move_first = true;
    for (int i = 0; i < t->nseg; i++)
      if (!t->severed[i] && !(skip && (skip[i] || skip[i + 1]))) solve_mesh_edges(t, i);
    for (int i = 0; i < t->n; i++)
      if (!t->pinned[i] && !(skip && skip[i])) solve_mesh_node(t, i);
  }
}

// ---------------------------------------------------------------------------
// punctures: the thread slides through each point its head has passed.
// arc[k] is the thread's material coordinate held at puncture k: (i + u) l0
// for the point at fraction u of link i.

static void arc_link(const tx_thread* t, double arc, int* i, double* u) {
  double f = arc / t->l0;
  int k = (int)floor(f);
  if (k < 0) k = 0;
  if (k > t->nseg - 1) k = t->nseg - 1;
  *i = k;
  *u = fmin(1, fmax(0, f - k));
}

// the thread's direction from passed puncture k towards its head (step -1)
// or its tail (+1): to the next passed puncture that way when the thread
// reaches it first (the strand between two is straight), else to its first
// node at least STRAND_REACH and three links from the point (past the kink,
// which the routing puts at a node up to a link beyond it, and the bend the
// kinematic thread keeps next to it), else its last node that way before an
// end or a cut; false when there is none
#define STRAND_REACH 0.005 // m
static bool strand_direction(const tx_thread* t, int k, int step, double u[3]) {
  const double* p = t->punct + 3 * k;
  int i;
  double frac;
  arc_link(t, t->arc[k], &i, &frac);
  int next = k - step; // arcs fall from the first passed to the last
  bool has_next = next >= t->out && next < t->passed;
  const double* to = NULL;
  for (int j = step < 0 ? i : i + 1;; j += step) {
    if (has_next && (step < 0 ? j * t->l0 <= t->arc[next] : j * t->l0 >= t->arc[next])) {
      to = t->punct + 3 * next;
      break;
    }
    to = t->x + 3 * j;
    if (dist3(to, p) >= fmax(3 * t->l0, STRAND_REACH)) break;
    int link = step < 0 ? j - 1 : j;
    if (j + step < 0 || j + step >= t->n || t->severed[link]) break;
  }
  double d = dist3(to, p);
  if (!(d > 1e-9 * t->l0)) return false;
  for (int a = 0; a < 3; a++) u[a] = (to[a] - p[a]) / d;
  return true;
}

int tx_thread_puncture_loads(const tx_thread* t, double stiffness, double max_force, double* f, double* k_out) {
  const bool rod = t->def.model == TX_THREAD_ROD;
  // the tension the hand feels (the force model's, or the rod's force on its
  // head), the same all along through frictionless punctures, and the
  // strand's stiffness: ftl, its force model's; rod, E A over the head's piece
  double f0[3], K[9];
  tx_thread_tension(t, stiffness, max_force, f0, K);
  const double tension = sqrt(dot3(f0, f0));
  const double strand = rod ? t->l0 / t->alpha_d / (t->first_cut * t->l0) : stiffness;
  for (int k = 0; k < t->out; k++) f[3 * k] = f[3 * k + 1] = f[3 * k + 2] = k_out[k] = 0; // pulled out of: no load
  for (int k = t->out; k < t->passed; k++) {
    double* fk = f + 3 * k;
    fk[0] = fk[1] = fk[2] = 0;
    k_out[k] = 0;
    int i;
    double u, head_side[3] = {0, 0, 0}, tail_side[3] = {0, 0, 0};
    arc_link(t, t->arc[k], &i, &u);
    if (t->severed[i] || i >= t->first_cut || !(tension > 0)) continue; // a piece the head no longer pulls
    bool to_head = strand_direction(t, k, -1, head_side), to_tail = strand_direction(t, k, +1, tail_side);
    if (!to_tail) continue; // the thread's end at the point: it has slid out
    double dir[3];
    for (int a = 0; a < 3; a++) dir[a] = (to_head ? head_side[a] : 0) + tail_side[a];
    for (int a = 0; a < 3; a++) fk[a] = tension * dir[a];
    // the pull falls by the strand's stiffness times the path it shortens,
    // |dir| for a move along dir: k |dir|^2 along the pull
    k_out[k] = strand * dot3(dir, dir);
    if (!(isfinite(fk[0]) && isfinite(fk[1]) && isfinite(fk[2]) && isfinite(k_out[k]))) fk[0] = fk[1] = fk[2] = k_out[k] = 0;
  }
  return t->passed;
}

// the material coordinate of the thread's point nearest p among the whole
// links within `window` of the one at guess (a sliding thread moves less than
// a link a substep), those on a pinned node left out where free_only; guess
// itself when there is none
static double nearest_arc(const tx_thread* t, const double p[3], double guess, int window, bool free_only) {
  int c;
  double u, q[3], best = guess, bd = INFINITY;
  arc_link(t, guess, &c, &u);
  for (int i = c - window; i <= c + window; i++) {
    if (i < 0 || i >= t->nseg || t->severed[i] || (free_only && (t->w[i] == 0 || t->w[i + 1] == 0))) continue;
    double d2 = link_nearest(t, i, p, &u, q);
    if (d2 < bd) bd = d2, best = (i + u) * t->l0;
  }
  return best;
}

// a puncture is passed once the head has gone through it: the thread
// behind the head (not the head's end itself) comes within
// puncture_capture of it, the earlier ones first; the nodes near a passed
// one are marked
static void punctures_begin_substep(tx_thread* t) {
  while (t->passed < t->npunct) {
    const double* p = t->punct + 3 * t->passed;
    if (dist3(t->x, p) > t->def.puncture_capture + t->l0) break;
    double arc = nearest_arc(t, p, 0, 3, false);
    int i;
    double u, q[3];
    arc_link(t, arc, &i, &u);
    for (int c = 0; c < 3; c++) q[c] = t->x[3 * i + c] + u * (t->x[3 * i + 3 + c] - t->x[3 * i + c]);
    if (!(arc > 1e-9 * t->l0) || dist3(q, p) > t->def.puncture_capture) break;
    t->arc[t->passed++] = arc;
  }
  if (t->mntri == 0) return;
  memset(t->near_punct, 0, (size_t)t->n);
  int m = (int)ceil((t->meshes[0].thickness + 2 * t->def.radius) / t->l0) + 1;
  for (int k = t->out; k < t->passed; k++) {
    int c = (int)floor(t->arc[k] / t->l0);
    for (int i = c - m; i <= c + 1 + m; i++)
      if (i >= 0 && i < t->n) t->near_punct[i] = 1;
  }
  // a bite: the strand from an entry to the exit after it (nearer the head)
  // runs through the tissue, which the sheet stands for, not under it
  for (int k = t->out; k + 1 < t->passed; k++) {
    if (t->pside[k] <= 0 || t->pside[k + 1] >= 0) continue;
    int hi = (int)ceil(t->arc[k] / t->l0);
    for (int i = (int)floor(t->arc[k + 1] / t->l0); i <= hi; i++)
      if (i >= 0 && i < t->n) t->near_punct[i] = 1;
  }
}

// the thread's point at material coordinate s (m from the head)
static void point_at(const tx_thread* t, double s, double out[3]) {
  int i;
  double u;
  arc_link(t, s, &i, &u);
  for (int c = 0; c < 3; c++) out[c] = t->x[3 * i + c] + u * (t->x[3 * i + 3 + c] - t->x[3 * i + c]);
}

// the mean stretch of the thread between material coordinates s0 < s1
// (its polyline's length over s1 - s0, less 1); 0 for a strand shorter than a link
static double strand_stretch(const tx_thread* t, double s0, double s1) {
  if (s1 - s0 < t->l0) return 0;
  double p[3], q[3], len = 0;
  point_at(t, s0, p);
  for (int j = (int)floor(s0 / t->l0) + 1; j * t->l0 < s1; j++) {
    if (t->severed[j - 1]) return 0;
    len += dist3(p, t->x + 3 * j);
    memcpy(p, t->x + 3 * j, sizeof p);
  }
  point_at(t, s1, q);
  return (len + dist3(p, q)) / (s1 - s0) - 1;
}

// Coulomb friction at a puncture: it holds the thread while the tensions on
// its two sides differ by at most puncture_friction. The tensions are the
// elastic ones: each puncture slides this substep when the strands on
// either side of it (to the next puncture, the head or the thread's end)
// are stretched apart by more than the friction holds, puncture_friction /
// E A, and by more than SLIP_STRETCH of the stretch cap: the rod's links
// stray from rest by up to a per cent or two (contacts, the cap's passes),
// which no pull made; a nylon thread's friction of a few tenths of a newton
// is a stretch of 1e-3, below that. (An XPBD friction whose multiplier is
// kept within puncture_friction h^2 weighs the drift against the two light
// nodes' inertia alone: it held any drift, and a needle dragging the thread
// stretched the link through the puncture by 4.4 times its length.) The
// arcs fall from the first passed to the last.
#define SLIP_STRETCH 0.5
static void decide_slides(tx_thread* t) {
  const double ea = t->l0 / t->alpha_d; // N, E A
  const double slip = fmax(t->def.puncture_friction / ea, SLIP_STRETCH * (t->lmax / t->l0 - 1));
  for (int k = t->out; k < t->passed; k++) {
    double head = k + 1 < t->passed ? t->arc[k + 1] : 0, tail = k > t->out ? t->arc[k - 1] : t->nseg * t->l0;
    t->slides[k] = fabs(strand_stretch(t, head, t->arc[k]) - strand_stretch(t, t->arc[k], tail)) > slip;
  }
}

// whether putting the point at fraction u of link i (weight W) back by C
// would stretch it or a link beside it past the cap
static bool overstretches(const tx_thread* t, int i, double u, double W, const double C[3]) {
  double a[3], b[3], l2 = t->lmax * t->lmax;
  for (int c = 0; c < 3; c++) {
    a[c] = t->x[3 * i + c] - t->w[i] * (1 - u) / W * C[c];
    b[c] = t->x[3 * i + 3 + c] - t->w[i + 1] * u / W * C[c];
  }
  return dist3_sq(a, b) > l2 || (i >= 1 && !t->severed[i - 1] && dist3_sq(a, t->x + 3 * i - 3) > l2) ||
         (i + 2 < t->n && !t->severed[i + 1] && dist3_sq(b, t->x + 3 * i + 6) > l2);
}

// each passed puncture holds the thread's point at arc[k] on it, with
// stick and slip along the thread (decide_slides, from the stretch the
// substep starts with). In the iterations (friction true) the offset across
// the thread is undone, and the drift along it too where the puncture
// sticks; where it slides the point held moves on along the thread. At the
// end of the substep (friction false) a stuck point that would stretch its
// link past the cap by being put back slides instead, a sliding point is
// first moved to the thread's nearest point (the passes after the
// iterations draw the thread on), and then every point is put on its
// puncture whole: the thread never leaves one.
static void solve_punctures(tx_thread* t, bool friction) {
  for (int k = t->out; k < t->passed; k++) {
    const double* p = t->punct + 3 * k;
    int i;
    double u;
    arc_link(t, t->arc[k], &i, &u);
    if (t->severed[i]) continue;
    double *a = t->x + 3 * i, *b = a + 3;
    double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, le = sqrt(dot3(e, e)), C[3], tan[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++) {
      C[c] = a[c] + u * e[c] - p[c];
      if (le > 0) tan[c] = e[c] / le;
    }
    if (t->w[i] == 0 || t->w[i + 1] == 0) {
      // a link on a pinned node (the head) cannot move the point at u
      // without a lever of 1 / u: it turns about that node through the
      // puncture instead, the point held sliding to |p - pinned node|
      // along it (no friction on this link)
      bool first = t->w[i] == 0;
      double *o = first ? a : b, *m = first ? b : a, dp[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
      double dl = sqrt(dot3(dp, dp));
      if (t->w[first ? i + 1 : i] == 0 || dl <= 1e-12 * t->l0) continue;
      for (int c = 0; c < 3; c++) m[c] = o[c] + dp[c] / dl * le;
      if (dl <= le) t->arc[k] = (i + (first ? dl / le : 1 - dl / le)) * t->l0;
      else t->arc[k] = first ? (i + 1) * t->l0 : i * t->l0; // out of reach: the next link holds it
      continue;
    }
    double W = t->w[i] * (1 - u) * (1 - u) + t->w[i + 1] * u * u;
    if (!(W > 0)) continue;
    double ct = dot3(C, tan), corr[3];
    if (!friction) {
      if (!t->slides[k] && overstretches(t, i, u, W, C)) t->slides[k] = 1; // held, it would stretch past the cap: it slides
      double moved = t->slides[k] ? nearest_arc(t, p, t->arc[k], 1, true) : t->arc[k];
      if (moved != t->arc[k]) { // held where the thread now is nearest, on a link with both ends free
        t->arc[k] = moved;
        arc_link(t, moved, &i, &u);
        a = t->x + 3 * i, b = a + 3;
        W = t->w[i] * (1 - u) * (1 - u) + t->w[i + 1] * u * u;
        if (!(W > 0)) continue;
        for (int c = 0; c < 3; c++) C[c] = a[c] + u * (b[c] - a[c]) - p[c];
      }
      memcpy(corr, C, sizeof corr); // the held point onto the puncture, whole
    } else if (t->slides[k]) { // across only: the point held moves on with the thread
      for (int c = 0; c < 3; c++) corr[c] = C[c] - ct * tan[c];
      t->arc[k] = fmin(t->nseg * t->l0, fmax(0, t->arc[k] - ct));
    } else {
      memcpy(corr, C, sizeof corr); // stuck
    }
    for (int c = 0; c < 3; c++) {
      a[c] -= t->w[i] * (1 - u) / W * corr[c];
      b[c] -= t->w[i + 1] * u / W * corr[c];
    }
  }
}

// a free tail drawn through the first puncture it runs through (the point
// held at its end) has left it: the thread runs through the rest
static void pull_out(tx_thread* t) {
  if (t->pinned[t->n - 1]) return;
  while (t->out < t->passed && t->arc[t->out] >= (t->nseg - 1e-9) * t->l0) t->out++;
}

// ---------------------------------------------------------------------------
// the two models

// each free node at l0 from the node before it, on the line to where it is;
// a node that sits on its leader keeps the direction of the segment before
static void place_after(tx_thread* t, int i, int from, double len) {
  double* p = t->x + 3 * i;
  const double* q = t->x + 3 * from;
  double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
  double l = sqrt(dot3(d, d));
  if (l <= 1e-12 * t->l0) {
    int k = 2 * from - i; // the node beyond the leader
    if (k >= 0 && k < t->n) {
      for (int a = 0; a < 3; a++) d[a] = q[a] - t->x[3 * k + a];
    } else {
      memcpy(d, t->def.direction, sizeof d);
      if (i < from)
        for (int a = 0; a < 3; a++) d[a] = -d[a];
    }
    l = sqrt(dot3(d, d));
    if (l <= 0) d[0] = 1, d[1] = d[2] = 0, l = 1;
  }
  for (int a = 0; a < 3; a++) p[a] = q[a] + d[a] / l * len;
}

// against a mesh each node is also kept on its side of it (the continuous
// test from where it was at the start of the substep): where the two
// disagree, not crossing the skin wins over the exact length
// with slack a node is placed only when pulled: its leader is more than l0 away
static void follow(tx_thread* t, int i, int from) {
  if (!t->def.slack || dist3(t->x + 3 * i, t->x + 3 * from) > t->l0) place_after(t, i, from, t->l0);
}

// a piece behind a cut follows its own first node (the cut end), which
// nothing pulls: it stays where it is unless a contact or a pin moves it
//
// Through punctures the thread is routed: the link that holds puncture k's
// point (arc[k]) is put through it, its far node on the line from its near
// node through the point; when the point is more than l0 away the node goes
// straight towards it and the point held moves on to the next link. So the
// thread passes through every passed puncture exactly, keeps its length and
// slides through as the head pulls it.
// node i a link from node `from` on the line from it through p (a puncture's
// point), or after it as the thread runs when `from` is on p; returns their
// distance |x_from - p| (beyond a link: p is out of the link's reach)
static double place_through_at(tx_thread* t, int i, int from, const double p[3], double len) {
  const double* l = t->x + 3 * from;
  double d = dist3(l, p);
  if (d > 1e-9 * t->l0) {
    for (int c = 0; c < 3; c++) t->x[3 * i + c] = l[c] + (p[c] - l[c]) / d * len;
  } else {
    place_after(t, i, from, len);
  }
  return d;
}
static double place_through(tx_thread* t, int i, int from, const double p[3]) {
  return place_through_at(t, i, from, p, t->l0);
}

static void ftl_forward(tx_thread* t) {
  // the last passed is the nearest the head along the thread: route from it back
  int k = t->passed - 1;
  for (int i = 1; i < t->n; i++) {
    if (t->held[i]) { // in the jaws, exactly: the thread behind follows it
      memcpy(t->x + 3 * i, t->pin + 3 * i, sizeof(double) * 3);
      // a puncture on the link into the jaws stays on it: both its ends are placed
      while (k >= t->out && t->arc[k] <= i * t->l0 * (1 + 1e-12)) k--;
      continue;
    }
    if (t->severed[i - 1]) continue;
    if (k >= t->out && t->arc[k] <= i * t->l0 * (1 + 1e-12)) {
      double d = place_through(t, i, i - 1, t->punct + 3 * k);
      if (d <= t->l0) {
        t->arc[k--] = (i - 1) * t->l0 + d;
      } else {
        t->arc[k] = i * t->l0;
      }
    } else {
      follow(t, i, i - 1);
    }
    for (int m = 0; m < t->nslots && t->any_mesh; m++) {
      t->cur = &t->meshes[m];
      if (t->cur->ntri == 0 || (m == 0 && (t->near_punct[i] || t->near_punct[i - 1]))) continue;
      t->move_first = false; // the leader is placed: only this node moves
      solve_mesh_edges(t, i - 1);
      solve_mesh_node(t, i);
    }
  }
}

// The pass back from the last pin towards the head, routed through the
// punctures as the forward pass is, from the tail's side: the link that holds
// a puncture's point puts its head-side node on the line from its tail-side
// node through the point; out of reach, the point held moves on towards the
// head (the pin draws the thread back through it). Without this, a pass that
// simply followed the pin would pull the thread off its punctures, and the
// next forward pass would slide it on through them: step by step a thread
// whose tail is pinned slid out of its stitch.
static void ftl_backward(tx_thread* t) {
  int k = t->out; // the first passed lies the furthest along the thread: met first from the tail
  while (k < t->passed && t->arc[k] > t->last_pin * t->l0) k++;
  for (int i = t->last_pin; i > 0; i--) {
    if (t->pinned[i]) {
      memcpy(t->x + 3 * i, t->pin + 3 * i, sizeof(double) * 3);
      while (k < t->passed && t->arc[k] >= i * t->l0 * (1 - 1e-12)) k++; // on the pinned node's far side
      continue;
    }
    if (t->severed[i]) continue;
    if (k < t->passed && t->arc[k] >= i * t->l0 * (1 - 1e-12)) {
      double d = place_through(t, i, i + 1, t->punct + 3 * k);
      if (d <= t->l0) {
        t->arc[k++] = (i + 1) * t->l0 - d;
      } else {
        t->arc[k] = i * t->l0;
      }
    } else {
      follow(t, i, i + 1);
    }
  }
}

// A thread whose tail is pinned, drawn through its punctures until it is
// taut, lies straight from the head through each puncture to the pin; the
// kinematic passes cannot find that state (an inextensible chain between two
// fixed ends over a longer path: each pass slides it through the punctures
// its own way, and the slack it keeps lands where they leave it). So the
// straight path head -> punctures -> pin decides: at least the thread's
// length, the nodes are laid evenly along it from the head to the pin, and
// its excess over the length is the stretch of the force model (tension (length
// - rest) x stiffness, the same all along, as through frictionless
// punctures); shorter, the thread is slack (no stretch) and the passes place
// it. Not with held nodes or a cut (other paths): taut_excess -1.
//
// The passes do not settle near that state either: with the path a few per
// cent short of the thread they leave the slack as one link stretched to the
// pin, placed anew each substep, and the nodes jumping by more than r made
// the step take every substep it may (30 ms a step at 1 kHz with the tail held
// in the suturing scenario). So the nodes are laid along the path once it is
// within TX_THREAD_TAUT_SLACK of the length (the links that much short: the
// slack a nearly straight thread has, unstretched), and stay so until it is a
// diameter shorter than that, so that the skin's give at the boundary does
// not switch it back and forth.
#define TX_THREAD_TAUT_POINTS 1026 // the head, max_punctures (at most 1024) and the pin
#define TX_THREAD_TAUT_SLACK 0.05  // of the length
static bool ftl_taut(tx_thread* t) {
  if (t->last_pin != t->n - 1 || t->nheld > 0 || t->first_cut < t->nseg || t->passed == t->out) return t->taut = false;
  for (int i = 1; i < t->n - 1; i++)
    if (t->pinned[i]) return t->taut = false;
  const double* way[TX_THREAD_TAUT_POINTS];
  int m = 0;
  way[m++] = t->x; // the head, then the punctures from the last passed (nearest the head) to the first, then the pin
  for (int k = t->passed - 1; k >= t->out && m < TX_THREAD_TAUT_POINTS - 1; k--) way[m++] = t->punct + 3 * k;
  if (m != t->passed - t->out + 1) return t->taut = false;
  way[m++] = t->pin + 3 * (t->n - 1);
  double total = 0;
  for (int j = 0; j + 1 < m; j++) total += dist3(way[j], way[j + 1]);
  const double length = t->nseg * t->l0;
  const double lay = (1 - TX_THREAD_TAUT_SLACK) * length;
  if (total < (t->taut ? lay - 2 * t->def.radius : lay)) { // slack: the passes place it, unstretched
    t->taut_excess = 0;
    return t->taut = false;
  }
  t->taut = true;
  // the nodes evenly along the path, the links alike (a link across a bend
  // is a chord), the last at the pin
  double start = 0; // the path's length up to way[j]
  int j = 0;
  for (int i = 1; i < t->n; i++) {
    double s = i * total / t->nseg, len = dist3(way[j], way[j + 1]);
    while (j + 2 < m && s > start + len) start += len, j++, len = dist3(way[j], way[j + 1]);
    double f = len > 0 ? (s - start) / len : 0;
    for (int a = 0; a < 3; a++) t->x[3 * i + a] = way[j][a] + f * (way[j + 1][a] - way[j][a]);
  }
  t->taut_excess = fmax(0, total - length);
  // each puncture's point held: its distance from the head along the path
  double d = 0;
  for (int k = t->passed - 1, q = 0; k >= t->out; k--, q++) {
    d += dist3(way[q], way[q + 1]);
    t->arc[k] = fmin(d * length / total, length); // along the thread, as its nodes are laid
  }
  return true;
}

// FABRIK towards the pins behind the head, the last pass from the head
static void ftl_solve(tx_thread* t) {
  t->taut_excess = -1;
  if (ftl_taut(t)) return;
  ftl_forward(t);
  if (t->last_pin == 0) return;
  for (int it = 0; it < t->def.iterations; it++) {
    ftl_backward(t);
    ftl_forward(t);
  }
}

static void ftl_substep(tx_thread* t, double h, double margin) {
  ftl_solve(t);
  if (t->def.self_collision && t->nseg > t->skip + 1) {
    broadphase(t, margin);
    for (int it = 0; it < t->def.iterations; it++) {
      solve_self(t);
      ftl_solve(t);
    }
  }
  // the kinematic thread follows around shapes: push out, follow again
  for (int it = 0; it < 2 && (t->ncaps || t->any_mesh); it++) {
    solve_capsules(t);
    solve_mesh(t);
    ftl_solve(t);
  }
  for (int i = 0; i < 3 * t->n; i++) t->v[i] = (t->x[i] - t->x0[i]) / h;
}

// node i at lmax from node `from` (a neighbour), its link over lmax; when the
// link holds passed puncture k (k >= 0), on the line from `from` through
// its point, which the link then holds at its distance from `from` (out of
// the link's reach, the next link on holds it): drawing the node straight
// towards `from` would cut the corner the thread turns at the puncture, and
// putting the point back on it would stretch the links again
static void cap_node(tx_thread* t, int i, int from, int k) {
  if (k < 0) {
    place_after(t, i, from, t->lmax);
    return;
  }
  double d = place_through_at(t, i, from, t->punct + 3 * k, t->lmax);
  double u = fmin(1, d / t->lmax); // the point's fraction of the link from `from`
  t->arc[k] = (i > from ? from + u : from - u) * t->l0;
}

// the cap from the head along the thread
static void cap_forward(tx_thread* t) {
  double l2 = t->lmax * t->lmax; // squared: no root per segment and pass
  int k = t->passed - 1;         // the last passed lies the nearest the head
  for (int i = 1; i < t->n; i++) {
    while (k >= t->out && t->arc[k] < (i - 1) * t->l0) k--;
    if (!t->pinned[i] && !t->severed[i - 1] && dist3_sq(t->x + 3 * i, t->x + 3 * i - 3) > l2)
      cap_node(t, i, i - 1, k >= t->out && t->arc[k] <= i * t->l0 ? k : -1);
  }
}

// and back from the last pin
static void cap_backward(tx_thread* t) {
  double l2 = t->lmax * t->lmax;
  int k = t->out; // the first passed lies the furthest along the thread: met first from the tail
  for (int i = t->last_pin - 1; i > 0; i--) {
    while (k < t->passed && t->arc[k] > (i + 1) * t->l0) k++;
    if (!t->pinned[i] && !t->severed[i] && dist3_sq(t->x + 3 * i, t->x + 3 * i + 3) > l2)
      cap_node(t, i, i + 1, k < t->passed && t->arc[k] >= i * t->l0 ? k : -1);
  }
}

// no segment longer than lmax: from the head along the thread, then back
// from the last pin, through the punctures as they lie
static void cap_stretch(tx_thread* t) {
  for (int pass = 0; pass < 2; pass++) {
    cap_forward(t);
    if (t->last_pin == 0) break;
    cap_backward(t);
  }
  cap_forward(t);
}

// LDL^T of the symmetric banded systems in place, written out for the two
// bandwidths (a generic band loop cost a third of a rod step; no square
// root): row r holds A(r, r), A(r, r - 1) [, A(r, r - 2)] at r w, then
// 1 / D(r) and L's unit lower entries (the solves multiply: a chain of
// divisions is slow)
static double inv_pivot(double d) { return 1 / (d > 1e-300 ? d : 1e-300); }

// pentadiagonal (w = 3)
static void penta_factor(double* A, int rows) {
  double d1 = 0, d2 = 0; // D(r - 1), D(r - 2)
  for (int r = 0; r < rows; r++) {
    double* R = A + 3 * r;
    double l2 = 0, l1 = 0;
    if (r >= 2) l2 = R[2] = R[2] * A[3 * (r - 2)];
    if (r >= 1) l1 = R[1] = (R[1] - l2 * A[3 * (r - 1) + 1] * d2) * A[3 * (r - 1)];
    double d = R[0] - l1 * l1 * d1 - l2 * l2 * d2;
    d = d > 1e-300 ? d : 1e-300;
    R[0] = inv_pivot(d);
    d2 = d1, d1 = d;
  }
}

// solves L D L^T y = b for three right-hand sides at once, y (rows x 3)
// interleaved: three independent chains keep the pipeline busy
static void penta_solve3(const double* L, int rows, double* y) {
  for (int r = 1; r < rows; r++) {
    const double* R = L + 3 * r;
    double* yr = y + 3 * r;
    yr[0] -= R[1] * yr[-3], yr[1] -= R[1] * yr[-2], yr[2] -= R[1] * yr[-1];
    if (r >= 2) yr[0] -= R[2] * yr[-6], yr[1] -= R[2] * yr[-5], yr[2] -= R[2] * yr[-4];
  }
  for (int r = rows - 1; r >= 0; r--) {
    double* yr = y + 3 * r;
    double d = L[3 * r];
    double s0 = yr[0] * d, s1 = yr[1] * d, s2 = yr[2] * d;
    if (r + 1 < rows) {
      double l = L[3 * (r + 1) + 1];
      s0 -= l * yr[3], s1 -= l * yr[4], s2 -= l * yr[5];
    }
    if (r + 2 < rows) {
      double l = L[3 * (r + 2) + 2];
      s0 -= l * yr[6], s1 -= l * yr[7], s2 -= l * yr[8];
    }
    yr[0] = s0, yr[1] = s1, yr[2] = s2;
  }
}

// tridiagonal (w = 2): factors and solves in one forward and one backward pass
static void tri_factor_solve(double* A, int rows, double* y) {
  double d1 = 0; // D(r - 1)
  for (int r = 0; r < rows; r++) {
    double* R = A + 2 * r;
    double l1 = 0;
    if (r >= 1) {
      l1 = R[1] = R[1] * A[2 * (r - 1)];
      y[r] -= l1 * y[r - 1];
    }
    double d = R[0] - l1 * l1 * d1;
    d = d > 1e-300 ? d : 1e-300;
    R[0] = inv_pivot(d);
    d1 = d;
  }
  for (int r = rows - 1; r >= 0; r--) {
    y[r] *= A[2 * r];
    if (r + 1 < rows) y[r] -= A[2 * (r + 1) + 1] * y[r + 1];
  }
}

// the bends' system depends on the masses and h alone: factored once a substep
static void bend_factor(tx_thread* t, double h) {
  int nb = t->n - 2;
  const double* w = t->w;
  double ab = t->alpha_b / (h * h);
  double* B = t->bend;
  const uint8_t* cut = t->severed;
  for (int k = 0; k < nb; k++) {
    int i = k + 1;
    B[k * 3] = w[i - 1] + 4 * w[i] + w[i + 1] + ab;
    B[k * 3 + 1] = k >= 1 ? -2 * w[i - 1] - 2 * w[i] : 0;
    B[k * 3 + 2] = k >= 2 ? w[i - 1] : 0;
  }
  // a bend across a cut (node i with link i - 1 or i severed) is no
  // constraint: its row is the identity, uncoupled, and its rhs 0
  if (t->cuts)
    for (int k = 0; k < nb; k++)
      if (cut[k] || cut[k + 1]) {
        B[k * 3] = 1, B[k * 3 + 1] = B[k * 3 + 2] = 0;
        if (k + 1 < nb) B[(k + 1) * 3 + 1] = 0;
        if (k + 2 < nb) B[(k + 2) * 3 + 2] = 0;
      }
  if (nb > 0 && isfinite(ab)) penta_factor(B, nb);
}

// The bends' solve takes every bend to rest at once (a nylon bend is stiff
// against a node's mass at any substep: alpha / h^2 << w), and the linear
// second difference gets there partly by drawing the nodes together; in a
// tight knot that move (millimetres in a substep) carries strands through
// the strands they cross, and the contacts, solved after, push them out on
// the wrong side: the knot flies open. Here, with y the bends' multipliers,
// a node of two crossing cylinders within 3 r of each other takes no more
// of the move than brings them BEND_CAP r closer (the iterations and the
// next substeps take the rest, the contacts between them); the other nodes
// take it whole. Parallel neighbours (a hairpin's legs) are left to the
// contacts: their strands cannot pass through each other into a different
// knot. Returns whether some node's move was cut (the moves are then applied
// here, with the multipliers each bend took).
static bool cap_bends(tx_thread* t, const double* y) {
  int n = t->n, nb = n - 2;
  const double* w = t->w;
  double *x = t->x, *dx = t->dxb;
  double r = t->def.radius, cap = BEND_CAP * r, m2 = 0;
  for (int j = 0; j < n; j++) {
    for (int c = 0; c < 3; c++)
      dx[3 * j + c] = w[j] * ((j >= 2 ? y[3 * (j - 2) + c] : 0) - 2 * (j >= 1 && j - 1 < nb ? y[3 * (j - 1) + c] : 0) +
                              (j < nb ? y[3 * j + c] : 0));
    double s = dot3(dx + 3 * j, dx + 3 * j);
    if (s > m2) m2 = s;
  }
  if (m2 <= cap * cap) return false;
  // a pair listed d0 apart is at least d0 - 2 D apart now (D: the largest move since)
  double moved = 0;
  for (int i = 0; i < n; i++) moved = fmax(moved, dist3_sq(x + 3 * i, t->xb + 3 * i));
  double near = CROSSING_NEAR * r, far = near + 2 * sqrt(moved);
  bool cut = false;
  for (int p = 0; p < t->npairs; p++) {
    if (t->pairs[p].d0 > far) continue;
    int i = t->pairs[p].i, j = t->pairs[p].j;
    const double *a0 = x + 3 * i, *a1 = a0 + 3, *b0 = x + 3 * j, *b1 = b0 + 3;
    double ei[3] = {a1[0] - a0[0], a1[1] - a0[1], a1[2] - a0[2]}, ej[3] = {b1[0] - b0[0], b1[1] - b0[1], b1[2] - b0[2]};
    double cr[3] = {ei[1] * ej[2] - ei[2] * ej[1], ei[2] * ej[0] - ei[0] * ej[2], ei[0] * ej[1] - ei[1] * ej[0]};
    if (dot3(cr, cr) < CROSSING_SIN * CROSSING_SIN * dot3(ei, ei) * dot3(ej, ej)) continue;
    tx_seg_closest cl;
    tx_seg_closest_points(a0, a1, b0, b1, &cl);
    if (cl.dist > near || cl.dist <= 0) continue;
    double ap = 0; // how much closer the bends' move brings the closest points
    for (int c = 0; c < 3; c++) {
      double da = (1 - cl.t) * dx[3 * i + c] + cl.t * dx[3 * i + 3 + c];
      double db = (1 - cl.s) * dx[3 * j + c] + cl.s * dx[3 * j + 3 + c];
      ap -= (da - db) * (cl.a[c] - cl.b[c]) / cl.dist;
    }
    if (ap <= cap) continue;
    if (ap > 2 * r) t->thrown = true; // the bends alone would carry the strands through each other
    if (!cut)
      for (int k = 0; k < n; k++) t->bscale[k] = 1;
    cut = true;
    double f = cap / ap;
    int nd[4] = {i, i + 1, j, j + 1};
    for (int q = 0; q < 4; q++)
      if (t->bscale[nd[q]] > f) t->bscale[nd[q]] = f;
  }
  if (!cut) return false;
  for (int j = 0; j < n; j++)
    for (int c = 0; c < 3; c++) x[3 * j + c] += t->bscale[j] * dx[3 * j + c];
  double* lam_b = t->lam + t->nseg;
  for (int k = 0; k < nb; k++) {
    double f = fmin(t->bscale[k], fmin(t->bscale[k + 1], t->bscale[k + 2]));
    for (int c = 0; c < 3; c++) lam_b[3 * k + c] += f * y[3 * k + c];
  }
  return true;
}

// one XPBD iteration, the bends then the distances, each group solved
// exactly: (J W J^T + alpha / h^2) dlambda = -(C + alpha / h^2 lambda).
// The bends' gradients are constant (1, -2, 1 on each axis), so their
// system is one pentadiagonal matrix for the three axes; the distances'
// is tridiagonal. A stiff rod converges in a few iterations where
// Gauss-Seidel sweeps would need O(N^2); bends and stretch barely couple
// (one moves across the rod, the other along it), so alternating the two
// exact solves converges fast.
static void rod_solve(tx_thread* t, double h, bool self) {
  int n = t->n, nseg = t->nseg, nb = n - 2;
  double* x = t->x;
  const double* w = t->w;
  double ad = t->alpha_d / (h * h), ab = t->alpha_b / (h * h);
  double* A = t->band;
  double* y = t->rhs;
  double* lam_d = t->lam;
  double* lam_b = t->lam + nseg; // 3 per bend
  if (nb > 0 && isfinite(ab)) {
    // bend k (node k + 1): rows k, k + 1, k + 2 share nodes
    for (int k = 0; k < nb; k++) {
      int i = k + 1;
      for (int c = 0; c < 3; c++)
        y[3 * k + c] = -(x[3 * i - 3 + c] - 2 * x[3 * i + c] + x[3 * i + 3 + c]) - ab * lam_b[3 * k + c];
      if (t->severed[k] || t->severed[k + 1]) y[3 * k] = y[3 * k + 1] = y[3 * k + 2] = 0;
    }
    penta_solve3(t->bend, nb, y);
    if (self && t->npairs && cap_bends(t, y)) {
      t->capped = true;
    } else
    for (int k = 0; k < nb; k++) {
      int i = k + 1;
      for (int c = 0; c < 3; c++) {
        double dl = y[3 * k + c];
        lam_b[3 * k + c] += dl;
        x[3 * i - 3 + c] += w[i - 1] * dl;
        x[3 * i + c] -= 2 * w[i] * dl;
        x[3 * i + 3 + c] += w[i + 1] * dl;
      }
    }
  }
  // distances: segment k's gradient is +u_k at node k and -u_k at node k + 1
  double* u = t->dir;
  for (int k = 0; k < nseg; k++) {
    double e[3] = {x[3 * k] - x[3 * k + 3], x[3 * k + 1] - x[3 * k + 4], x[3 * k + 2] - x[3 * k + 5]};
    double l = sqrt(dot3(e, e));
    if (l > 1e-12 * t->l0) {
      for (int a = 0; a < 3; a++) u[3 * k + a] = e[a] / l;
    } else { // coincident nodes: open the segment along the one before it (or the thread's first direction)
      double f[3] = {-t->def.direction[0], -t->def.direction[1], -t->def.direction[2]};
      if (k > 0 && dot3(u + 3 * k - 3, u + 3 * k - 3) > 0.5) memcpy(f, u + 3 * k - 3, sizeof f);
      double lf = sqrt(dot3(f, f));
      for (int a = 0; a < 3; a++) u[3 * k + a] = f[a] / lf;
    }
    y[k] = -(l - t->l0) - ad * lam_d[k];
    A[k * 2] = (w[k] + w[k + 1]) + ad;
    A[k * 2 + 1] = k >= 1 && !t->severed[k - 1] ? -w[k] * dot3(u + 3 * k - 3, u + 3 * k) : 0;
    if (t->severed[k]) y[k] = 0, A[k * 2] = 1, A[k * 2 + 1] = 0; // a cut link: no constraint, uncoupled
  }
  tri_factor_solve(A, nseg, y);
  for (int k = 0; k < nseg; k++) {
    lam_d[k] += y[k];
    for (int a = 0; a < 3; a++) {
      x[3 * k + a] += w[k] * u[3 * k + a] * y[k];
      x[3 * k + 3 + a] -= w[k + 1] * u[3 * k + a] * y[k];
    }
  }
}

// the rod's kinetic (free nodes), bending and gravity's energy, J
static double rod_energy(const tx_thread* t) {
  int n = t->n;
  const double *x = t->x, *v = t->v;
  double e = 0;
  for (int i = 0; i < n; i++) {
    double m = 1 / t->wf[i];
    e += m * t->def.gravity * x[3 * i + 1];
    if (t->w[i] > 0) e += 0.5 * m * dot3(v + 3 * i, v + 3 * i);
  }
  if (isfinite(t->alpha_b))
    for (int i = 1; i + 1 < n; i++) {
      if (t->severed[i - 1] || t->severed[i]) continue;
      double d2 = 0;
      for (int a = 0; a < 3; a++) {
        double q = x[3 * i - 3 + a] - 2 * x[3 * i + a] + x[3 * i + 3 + a];
        d2 += q * q;
      }
      e += 0.5 * d2 / t->alpha_b;
    }
  return e;
}

// after a substep whose bends were cut near crossings: the velocities,
// (x - x0) / h, gain no more kinetic energy than the bends and gravity
// released. Without it the strands pushed back by the contacts leave with
// the speed of the whole move (tens of m/s in a 1 mm knot) and the next
// substep's prediction carries them through each other.
static void limit_energy(tx_thread* t) {
  double e1 = rod_energy(t), over = e1 - t->e_sub, k1 = 0;
  if (!(over > 0)) return;
  for (int i = 0; i < t->n; i++)
    if (t->w[i] > 0) k1 += 0.5 / t->wf[i] * dot3(t->v + 3 * i, t->v + 3 * i);
  if (!(k1 > 0)) return;
  double f = k1 > over ? sqrt((k1 - over) / k1) : 0;
  for (int i = 0; i < t->n; i++)
    if (t->w[i] > 0)
      for (int a = 0; a < 3; a++) t->v[3 * i + a] *= f;
}

#define FINAL_ROUNDS 3
static void rod_substep(tx_thread* t, double h, double margin) {
  const tx_thread_def* d = &t->def;
  int n = t->n, nseg = t->nseg;
  double* x = t->x;
  double* v = t->v;
  double decay = exp(-d->damping * h);
  t->capped = false;
  t->thrown = false;
  if (d->self_collision && isfinite(t->alpha_b)) t->e_sub = rod_energy(t); // only cap_bends needs it
  if (t->passed) decide_slides(t); // from the stretch the substep starts with
  for (int i = 0; i < n; i++) {
    if (t->pinned[i]) continue;
    v[3 * i + 1] -= d->gravity * h;
    for (int a = 0; a < 3; a++) {
      v[3 * i + a] *= decay;
      x[3 * i + a] += v[3 * i + a] * h;
    }
  }
  memset(t->lam, 0, sizeof(double) * 4 * nseg);
  bool self = d->self_collision && nseg > t->skip + 1;
  if (self) broadphase(t, margin);
  bend_factor(t, h);
  for (int it = 0; it < d->iterations; it++) {
    rod_solve(t, h, self);
    solve_capsules(t);
    if (self) solve_self(t);
    if (t->passed) solve_punctures(t, true);
  }
  cap_stretch(t);
  // a node moved by one cylinder's push can go back into its neighbour's
  // capsule: a second pass settles the pair; the rigid shapes last, as a
  // thread's own push must not drive it into one
  for (int pass = 0; pass < 2; pass++) {
    if (self) solve_self(t);
    solve_capsules(t);
  }
  // the cap again: pushes in a crowded knot can stretch a segment; shortening
  // towards the leader barely opens a contact again. The cap and the rigid
  // contacts take turns (whichever moves a node last wins): a node the skin
  // pushes out of a crease after the cap stretched its links by 0.34 in the
  // instrument tie, 0.09 after three turns (0.08 after six)
  for (int round = 0; round < FINAL_ROUNDS; round++) {
    cap_stretch(t);
    solve_capsules(t);
    solve_mesh(t);
  }
  pull_out(t); // a tail drawn through to its end is not held back by the last pass
  for (int pass = 0; pass < 2 && t->passed; pass++) solve_punctures(t, false); // never leaves one
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++)
      v[3 * i + a] = t->pinned[i] && !t->held[i] ? 0 : (x[3 * i + a] - t->x0[3 * i + a]) / h; // a held node lets go at the jaws' speed
  if (t->thrown) limit_energy(t);
  // the force the constraints put on the (pinned) head: gradient x lambda /
  // h^2 of the first distance and of the bend at node 1 (its coefficient at node 0 is 1)
  for (int a = 0; a < 3; a++) {
    t->head_force[a] = t->dir[a] * t->lam[0] / (h * h);
    if (n > 2) t->head_force[a] += t->lam[nseg + a] / (h * h);
  }
}

tx_thread_status tx_thread_set_model(tx_thread* t, tx_thread_model model) {
  if (model != TX_THREAD_FTL && model != TX_THREAD_ROD) {
    tx_set_error("thread: model = %d, must be ftl (0) or rod (1)", (int)model);
    return TX_THREAD_BAD;
  }
  t->def.model = model;
  memset(t->v, 0, sizeof(double) * 3 * t->n);
  return TX_THREAD_OK;
}

tx_thread_status tx_thread_step(tx_thread* t, double dt) {
  if (!(dt > 0 && dt <= 1)) {
    tx_set_error("thread: dt = %g s, must be in (0, 1]", dt);
    return TX_THREAD_BAD;
  }
  const tx_thread_def* d = &t->def;
  int n = t->n;
  memcpy(t->xs, t->x, sizeof(double) * 3 * n);
  memcpy(t->vs, t->v, sizeof(double) * 3 * n);
  memset(t->colliding, 0, (size_t)t->nseg);
  memset(&t->last, 0, sizeof t->last);
  int passed0 = t->passed, out0 = t->out;
  if (passed0) memcpy(t->arc_step, t->arc, sizeof(double) * passed0);
  // substeps: the head and, by their last velocities, the nodes move no
  // more than 3 r / 4 in one
  double move = dist3(t->head_from, t->head_to), held_move = 0;
  for (int i = 1; i < n && t->nheld; i++)
    if (t->held[i]) held_move = fmax(held_move, dist3(t->hold_from + 3 * i, t->hold_to + 3 * i));
  if (held_move > move) move = held_move;
  // the rod with no shapes and no mesh (self contacts alone) checks each
  // substep continuously (self_substep_ok) instead of bounding every node's
  // move: it starts from the substeps the last step needed
  bool ccd = d->model == TX_THREAD_ROD && t->ncaps == 0 && !t->any_mesh;
  bool self = d->self_collision && t->nseg > t->skip + 1;
  if (d->model == TX_THREAD_ROD && !ccd) {
    double vmax2 = 0;
    for (int i = 0; i < n; i++) {
      double s = dot3(t->v + 3 * i, t->v + 3 * i);
      if (s > vmax2) vmax2 = s;
    }
    double vm = (sqrt(vmax2) + d->gravity * dt) * dt;
    if (vm > move) move = vm;
  }
  double sub = ceil(dt / d->max_substep - 1e-9);
  double need = ceil(move / (0.75 * d->radius));
  if (need > sub) sub = need;
  if (ccd && t->sub_hint > sub) sub = t->sub_hint;
  if (sub < 1) sub = 1;
  if (sub > d->max_substeps) sub = d->max_substeps;
  double h = dt / sub, hmin = dt / d->max_substeps, tau = 0, hkept = h;
  int ns = 0;
  // a substep in which a free node moved more than 0.9 r (a kink springing
  // back, a whip) is taken again at half the length, down to dt /
  // max_substeps: two cylinders 2 r apart that each move less than r cannot
  // pass through each other, and the contacts' margin of 2 r covers them
  while (tau < dt * (1 - 1e-12)) {
    if (h > dt - tau) h = dt - tau;
    double f = (tau + h) / dt;
    memcpy(t->x0, t->x, sizeof(double) * 3 * n);
    memcpy(t->v0, t->v, sizeof(double) * 3 * n);
    int passed_sub = t->passed, out_sub = t->out;
    if (passed_sub) memcpy(t->arc_sub, t->arc, sizeof(double) * passed_sub);
    for (int a = 0; a < 3; a++) t->x[a] = t->head_from[a] + f * (t->head_to[a] - t->head_from[a]);
    for (int i = 1; i < n; i++) {
      if (t->held[i]) // a held node moves in a straight line over the step, as the head
        for (int a = 0; a < 3; a++) t->pin[3 * i + a] = t->hold_from[3 * i + a] + f * (t->hold_to[3 * i + a] - t->hold_from[3 * i + a]);
      if (t->pinned[i]) memcpy(t->x + 3 * i, t->pin + 3 * i, sizeof(double) * 3);
    }
    if (t->npunct) punctures_begin_substep(t);
    double margin = 2 * d->radius + fmax(dist3(t->x, t->x0), held_move * h / dt);
    if (d->model == TX_THREAD_FTL)
      ftl_substep(t, h, margin);
    else
      rod_substep(t, h, margin);
    pull_out(t);
    ns++;
    bool again = false;
    if (h > hmin * (1 + 1e-9) && ns < 4 * d->max_substeps) {
      if (ccd) {
        again = self && !self_substep_ok(t);
      } else {
        double far2 = 0;
        for (int i = 1; i < n; i++) {
          double e[3] = {t->x[3 * i] - t->x0[3 * i], t->x[3 * i + 1] - t->x0[3 * i + 1], t->x[3 * i + 2] - t->x0[3 * i + 2]};
          double s = dot3(e, e);
          if (s > far2 && !t->pinned[i]) far2 = s;
        }
        again = far2 > 0.81 * d->radius * d->radius;
      }
    }
    if (again) {
      memcpy(t->x, t->x0, sizeof(double) * 3 * n);
      memcpy(t->v, t->v0, sizeof(double) * 3 * n);
      t->passed = passed_sub, t->out = out_sub;
      if (passed_sub) memcpy(t->arc, t->arc_sub, sizeof(double) * passed_sub);
      h = fmax(0.5 * h, hmin);
      t->last.retries++;
      continue;
    }
    if (h < hkept) hkept = h;
    tau += h;
  }
  // the next step starts from the shortest substep this one kept, or one
  // substep fewer when none was taken again (the motion calming down)
  if (ccd) {
    int want = (int)ceil(dt / hkept - 1e-9);
    t->sub_hint = t->last.retries ? want : (t->sub_hint > 1 ? t->sub_hint - 1 : 1);
    if (t->sub_hint > d->max_substeps) t->sub_hint = d->max_substeps;
  }
  memcpy(t->head_from, t->head_to, sizeof(double) * 3);
  for (int i = 1; i < n && t->nheld; i++)
    if (t->held[i]) memcpy(t->hold_from + 3 * i, t->hold_to + 3 * i, sizeof(double) * 3);
  t->last.substeps = ns;
  t->slid = 0; // punctures the thread went on through (pulled, not pushed back)
  for (int k = out0; k < passed0 && k < t->out; k++) t->slid++; // pulled out through it
  for (int k = t->out; k < passed0; k++) t->slid += t->arc[k] > t->arc_step[k] + 1e-9 * t->l0;
  for (int i = 0; i < 3 * n; i++)
    if (!isfinite(t->x[i]) || !isfinite(t->v[i])) {
      memcpy(t->x, t->xs, sizeof(double) * 3 * n);
      memcpy(t->v, t->vs, sizeof(double) * 3 * n);
      t->passed = passed0, t->out = out0;
      if (passed0) memcpy(t->arc, t->arc_step, sizeof(double) * passed0);
      t->slid = 0;
      t->faults++;
      return TX_THREAD_FAULT;
    }
  return TX_THREAD_OK;
}
