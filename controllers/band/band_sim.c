// The band: two FEM parts, four ODE bodies, a double-ball joint, a latch.
// See band_sim.h and docs/lagb.md ("The band").
#include "band_sim.h"

#include "../organs/bullet/fem.h"
#include "../../model/error.h"

#include <ode/ode.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct hold {
  dBodyID body;
  int part;
  int n;          // nodes it carries
  int* node;      // (n)
  double* local;  // (n x 3) m, each node in the body's frame
  double force[3];  // N, the pull set by tx_band_set_force
  bool driven;
  double from[3], to[3];  // m, a driven body's move over this step
  double saved[13];       // position, quaternion, linear and angular velocity
} hold;

typedef struct band_part {
  tx_fem* fem;
  int nv, nf;
  double* rest;    // (nv x 3) m
  double* pos;     // (nv x 3) m, scratch
  int32_t* face;   // (nf x 3)
  int per;         // nodes of a cross-section: those of the first (the sweep's node order); 0 if they do not tile nv
} band_part;

struct tx_band {
  tx_band_def def;
  band_part p[TX_BAND_PARTS];
  hold h[TX_BAND_BODIES];
  dWorldID world;
  dJointID joint, latch;
  double rest;             // m, the joint's length
  double buckle_local[3];  // the opening's centre in the buckle body's frame
  double axis_local[3];    // its insertion axis there
  double tip_side;         // the tip's signed distance along the axis after the last substep
  bool locked, saved_locked;
  bool fresh;              // restored: the parts' reaction of the failed step is not applied
  int substeps;
  double h_sub;            // s
  double dt_stable;        // s, the largest stable explicit step of both parts
};

tx_band_def tx_band_def_default(void) {
  // sources: docs/lagb.md, "The band"
  tx_band_def d = {.part = {{.young = 5e6, .poisson = 0.3, .density = 1100, .damping = 60},
                            {.young = 1e6, .poisson = 0.3, .density = 1100, .damping = 2}},
                   .body_mass = 0.002,
                   .step = 1.0 / 60,
                   .max_substep = 2.5e-5,
                   .buckle_offset = 0.006,
                   .buckle_radius = 0.006,
                   .gravity = {0, 0, 0},
                   .max_speed = 50,
                   .erp = 0.2,
                   .cfm = 1e-10,
                   .rotation = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  return d;
}

static bool is_rotation(const double r[3][3]) {
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double dot = r[i][0] * r[j][0] + r[i][1] * r[j][1] + r[i][2] * r[j][2];
      if (!(fabs(dot - (i == j)) < 1e-9)) return false;
    }
  double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
               r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
  return det > 0;
}

// the assets into the scene: x' = origin + R x (a rotation keeps every
// tetrahedron's orientation, and the buckle and the bodies follow the nodes)
static void place(const tx_band_def* d, double* x, int n) {
  for (int i = 0; i < n; i++) {
    double* p = x + 3 * i;
    double q[3];
    for (int a = 0; a < 3; a++) q[a] = d->origin[a] + d->rotation[a][0] * p[0] + d->rotation[a][1] * p[1] + d->rotation[a][2] * p[2];
    memcpy(p, q, sizeof q);
  }
}

static const char* const part_name[TX_BAND_PARTS] = {"band_ring", "band_tube"};

// TetGen .node (3-D, from 0, one boundary marker) and .ele (4 nodes)
static int read_part(const char* dir, int which, double** x, int** mark, int* nx, int** t, int* nt) {
  char path[4200];
  snprintf(path, sizeof path, "%s/%s.node", dir, part_name[which]);
  FILE* f = fopen(path, "r");
  if (!f) return tx_set_error("%s: cannot be read", path), -1;
  int n, dim, na, nb;
  if (fscanf(f, "%d %d %d %d", &n, &dim, &na, &nb) != 4 || n < 8 || n > 1000000 || dim != 3 || na != 0 || nb != 1)
    return fclose(f), tx_set_error("%s: not a band part's .node file (3-D points with one marker)", path), -1;
  *x = malloc(sizeof(double) * 3 * (size_t)n);
  *mark = malloc(sizeof(int) * (size_t)n);
  if (!*x || !*mark) return fclose(f), tx_set_error("out of memory"), -1;
  for (int i = 0; i < n; i++) {
    int id;
    double* p = *x + 3 * i;
    if (fscanf(f, "%d %lf %lf %lf %d", &id, p, p + 1, p + 2, *mark + i) != 5 || id != i || !isfinite(p[0] + p[1] + p[2]))
      return fclose(f), tx_set_error("%s: node %d: malformed line", path, i), -1;
  }
  fclose(f);
  *nx = n;
  snprintf(path, sizeof path, "%s/%s.ele", dir, part_name[which]);
  f = fopen(path, "r");
  if (!f) return tx_set_error("%s: cannot be read", path), -1;
  int per;
  if (fscanf(f, "%d %d %d", &n, &per, &na) != 3 || n < 1 || n > 4000000 || per != 4 || na != 0)
    return fclose(f), tx_set_error("%s: not a TetGen .ele file of 4-node tetrahedra", path), -1;
  *t = malloc(sizeof(int) * 4 * (size_t)n);
  if (!*t) return fclose(f), tx_set_error("out of memory"), -1;
  for (int i = 0; i < n; i++) {
    int id, *e = *t + 4 * i;
    if (fscanf(f, "%d %d %d %d %d", &id, e, e + 1, e + 2, e + 3) != 5 || id != i)
      return fclose(f), tx_set_error("%s: tetrahedron %d: malformed line", path, i), -1;
    for (int k = 0; k < 4; k++)
      if (e[k] < 0 || e[k] >= *nx) return fclose(f), tx_set_error("%s: tetrahedron %d names a node that is not there", path, i), -1;
  }
  fclose(f);
  *nt = n;
  return 0;
}

static double tet_volume(const double* a, const double* b, const double* c, const double* e) {
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
         w[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) + u[2] * (v[0] * w[1] - v[1] * w[0])) / 6;
}

static int cmp_face(const void* a, const void* b) {
  const int *p = a, *q = b;
  for (int k = 0; k < 3; k++)
    if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
  return 0;
}

// the faces of one tetrahedron only, turned outward
static int boundary(band_part* p, const int* t, int nt) {
  int* key = malloc(sizeof(int) * 5 * 4 * (size_t)nt); // sorted face, the tetrahedron, the face's index in it
  if (!key) return tx_set_error("out of memory"), -1;
  for (int e = 0; e < nt; e++)
    for (int k = 0; k < 4; k++) {
      int* q = key + 5 * (4 * e + k);
      int f[3] = {t[4 * e + (k + 1) % 4], t[4 * e + (k + 2) % 4], t[4 * e + (k + 3) % 4]};
      for (int i = 0; i < 2; i++) // sort three
        for (int j = 0; j < 2 - i; j++)
          if (f[j] > f[j + 1]) {
            int s = f[j];
            f[j] = f[j + 1], f[j + 1] = s;
          }
      q[0] = f[0], q[1] = f[1], q[2] = f[2], q[3] = e, q[4] = k;
    }
  qsort(key, 4 * (size_t)nt, sizeof(int) * 5, cmp_face);
  p->face = malloc(sizeof(int32_t) * 3 * 4 * (size_t)nt);
  if (!p->face) return free(key), tx_set_error("out of memory"), -1;
  int nf = 0;
  for (int i = 0; i < 4 * nt; i++) {
    const int* q = key + 5 * i;
    bool twin = (i + 1 < 4 * nt && cmp_face(q, q + 5) == 0) || (i > 0 && cmp_face(q, q - 5) == 0);
    if (twin) continue;
    int a = q[0], b = q[1], c = q[2], o = t[4 * q[3] + q[4]];
    if (tet_volume(p->rest + 3 * a, p->rest + 3 * b, p->rest + 3 * c, p->rest + 3 * o) > 0) {
      int s = b;
      b = c, c = s;
    }
    int32_t* f = p->face + 3 * nf++;
    f[0] = a, f[1] = b, f[2] = c;
  }
  free(key);
  p->nf = nf;
  return 0;
}

static void centroid(const band_part* p, const int* mark, int m, double c[3], int* count) {
  c[0] = c[1] = c[2] = 0;
  int n = 0;
  for (int i = 0; i < p->nv; i++)
    if (mark[i] == m) {
      for (int a = 0; a < 3; a++) c[a] += p->rest[3 * i + a];
      n++;
    }
  for (int a = 0; a < 3; a++) c[a] /= n > 0 ? n : 1;
  *count = n;
}

// a body carrying a part's nodes of marker m, at their centroid
static int make_hold(tx_band* b, int which, int part_i, const int* mark, int m) {
  hold* h = &b->h[which];
  band_part* p = &b->p[part_i];
  double c[3];
  centroid(p, mark, m, c, &h->n);
  if (h->n < 3) return tx_set_error("%s: fewer than 3 nodes carry marker %d (an end of the part)", part_name[part_i], m), -1;
  h->part = part_i;
  h->node = malloc(sizeof(int) * (size_t)h->n);
  h->local = malloc(sizeof(double) * 3 * (size_t)h->n);
  if (!h->node || !h->local) return tx_set_error("out of memory"), -1;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  int k = 0;
  for (int i = 0; i < p->nv; i++)
    if (mark[i] == m) {
      h->node[k] = i;
      for (int a = 0; a < 3; a++) {
        h->local[3 * k + a] = p->rest[3 * i + a] - c[a];
        lo[a] = fmin(lo[a], p->rest[3 * i + a]), hi[a] = fmax(hi[a], p->rest[3 * i + a]);
      }
      tx_fem_set_kinematic(p->fem, i, p->rest + 3 * i);
      k++;
    }
  h->body = dBodyCreate(b->world);
  dMass mass;
  dMassSetBoxTotal(&mass, b->def.body_mass, fmax(hi[0] - lo[0], 1e-3), fmax(hi[1] - lo[1], 1e-3), fmax(hi[2] - lo[2], 1e-3));
  dBodySetMass(h->body, &mass);
  dBodySetPosition(h->body, c[0], c[1], c[2]);
  return 0;
}

// the part's nodes next to those of marker m (the section beside the end)
// give the end's direction: the tangent out of the part at that end
static void end_tangent(const band_part* p, const int* mark, int m, double t[3]) {
  double c[3], near[3] = {0, 0, 0};
  int n;
  centroid(p, mark, m, c, &n);
  // the n interior nodes nearest the end's centroid: the smallest radius holding n of them, by bisection
  double lo = 0, hi = 1;
  for (int it = 0; it < 60; it++) {
    double r = (lo + hi) / 2;
    int k = 0;
    for (int i = 0; i < p->nv; i++)
      if (mark[i] == 0) {
        const double* q = p->rest + 3 * i;
        k += (q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) + (q[2] - c[2]) * (q[2] - c[2]) <= r * r;
      }
    if (k >= n) hi = r;
    else lo = r;
  }
  const double cut = hi;
  int k = 0;
  for (int i = 0; i < p->nv; i++)
    if (mark[i] == 0) {
      const double* q = p->rest + 3 * i;
      if ((q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) + (q[2] - c[2]) * (q[2] - c[2]) <= cut * cut) {
        for (int a = 0; a < 3; a++) near[a] += q[a];
        k++;
      }
    }
  double len = 0;
  for (int a = 0; a < 3; a++) t[a] = c[a] - near[a] / (k > 0 ? k : 1), len += t[a] * t[a];
  len = sqrt(len);
  for (int a = 0; a < 3; a++) t[a] /= len > 0 ? len : 1;
}

static void body_point(dBodyID body, const double local[3], double out[3]) {
  dVector3 w;
  dBodyGetRelPointPos(body, local[0], local[1], local[2], w);
  out[0] = w[0], out[1] = w[1], out[2] = w[2];
}

tx_band* tx_band_create(const tx_band_def* d, const char* dir) {
  for (int i = 0; i < TX_BAND_PARTS; i++) {
    const tx_band_material* m = &d->part[i];
    if (!(m->young > 0 && m->poisson >= 0 && m->poisson < 0.5 && m->density > 0 && m->damping >= 0))
      return tx_set_error("%s: a material needs E > 0, 0 <= nu < 0.5, a density > 0, damping >= 0", part_name[i]), NULL;
  }
  if (!(d->body_mass > 0) || !(d->buckle_radius > 0) || !(d->max_substep >= 0) || !(d->step > 0 && d->step <= 1))
    return tx_set_error("the bodies' mass, the buckle's radius and the step (at most 1 s) must be > 0, the substep >= 0"), NULL;
  if (!is_rotation(d->rotation) || !isfinite(d->origin[0] + d->origin[1] + d->origin[2]))
    return tx_set_error("the band's placement needs a finite origin and a rotation (orthonormal, determinant 1)"), NULL;
  if (!dInitODE2(0) || !dAllocateODEDataForThread(dAllocateMaskAll)) return tx_set_error("ODE cannot be started"), NULL;
  tx_band* b = calloc(1, sizeof *b);
  if (!b) return dCloseODE(), tx_set_error("out of memory"), NULL;
  b->def = *d;
  b->world = dWorldCreate();
  dWorldSetGravity(b->world, d->gravity[0], d->gravity[1], d->gravity[2]);
  dWorldSetERP(b->world, d->erp);
  dWorldSetCFM(b->world, d->cfm);
  int* mark[TX_BAND_PARTS] = {NULL, NULL};
  int* tets[TX_BAND_PARTS] = {NULL, NULL};
  int ntet[TX_BAND_PARTS] = {0, 0};
  int rc = 0;
  // the parts, first at their own stable steps, then both at the smaller
  double h = INFINITY;
  for (int i = 0; i < TX_BAND_PARTS && rc == 0; i++) {
    band_part* p = &b->p[i];
    rc = read_part(dir, i, &p->rest, &mark[i], &p->nv, &tets[i], &ntet[i]);
    if (rc == 0) {
      place(d, p->rest, p->nv);
      for (int k = 0; k < p->nv; k++) p->per += mark[i][k] == 1;
      if (p->per < 1 || p->nv % p->per != 0) p->per = 0;
    }
    if (rc == 0) {
      tx_fem_def f = tx_fem_def_default();
      f.model = TX_FEM_NEOHOOKEAN;
      f.young = d->part[i].young, f.poisson = d->part[i].poisson, f.density = d->part[i].density;
      f.dt = 0;
      tx_fem* probe = tx_fem_create(&f, p->rest, p->nv, tets[i], ntet[i]);
      if (!probe) rc = (tx_error_prefix("%s/%s", dir, part_name[i]), -1);
      else h = fmin(h, tx_fem_dt(probe)), tx_fem_destroy(probe);
    }
    if (rc == 0) rc = boundary(p, tets[i], ntet[i]);
  }
  if (rc == 0) {
    b->dt_stable = h;
    if (d->max_substep > 0) h = d->max_substep; // the FEM's estimate is safe by a factor of about 3
    b->substeps = (int)ceil(d->step / h - 1e-9);
    if (b->substeps < 1) b->substeps = 1;
    h = b->h_sub = d->step / b->substeps;
    for (int i = 0; i < TX_BAND_PARTS && rc == 0; i++) {
      band_part* p = &b->p[i];
      tx_fem_def f = tx_fem_def_default();
      f.model = TX_FEM_NEOHOOKEAN;
      f.young = d->part[i].young, f.poisson = d->part[i].poisson, f.density = d->part[i].density;
      f.damping = d->part[i].damping, f.dt = h, f.max_speed = d->max_speed;
      f.nodal_pressure = false; // silicone at nu = 0.3 does not lock; the averaging would double the step's cost
      for (int a = 0; a < 3; a++) f.gravity[a] = d->gravity[a];
      p->fem = tx_fem_create(&f, p->rest, p->nv, tets[i], ntet[i]);
      p->pos = malloc(sizeof(double) * 3 * (size_t)p->nv);
      if (!p->fem) rc = (tx_error_prefix("%s/%s", dir, part_name[i]), -1);
      else if (!tx_fem_set_capsules(p->fem, d->obstacle[0], d->obstacles))
        rc = (tx_set_error("an obstacle needs a radius above 0 and finite ends, %d at most", TX_BAND_OBSTACLES_MAX), -1);
      else if (!p->pos) rc = (tx_set_error("out of memory"), -1);
    }
  }
  if (rc == 0) rc = make_hold(b, TX_BAND_RING_TAIL, TX_BAND_RING, mark[TX_BAND_RING], 1);
  if (rc == 0) rc = make_hold(b, TX_BAND_BUCKLE, TX_BAND_RING, mark[TX_BAND_RING], 2);
  if (rc == 0) rc = make_hold(b, TX_BAND_TUBE_HEAD, TX_BAND_TUBE, mark[TX_BAND_TUBE], 1);
  if (rc == 0) rc = make_hold(b, TX_BAND_TUBE_TIP, TX_BAND_TUBE, mark[TX_BAND_TUBE], 2);
  if (rc == 0) {
    const dReal *pa = dBodyGetPosition(b->h[TX_BAND_RING_TAIL].body), *pb = dBodyGetPosition(b->h[TX_BAND_TUBE_HEAD].body);
    b->rest = sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) + (pa[2] - pb[2]) * (pa[2] - pb[2]));
    if (!(b->rest > 1e-5)) rc = (tx_set_error("%s: the tube starts where the ring ends: no room for the distance joint", dir), -1);
  }
  if (rc == 0) {
    b->joint = dJointCreateDBall(b->world, 0);
    dJointAttach(b->joint, b->h[TX_BAND_RING_TAIL].body, b->h[TX_BAND_TUBE_HEAD].body);
    const dReal *pa = dBodyGetPosition(b->h[TX_BAND_RING_TAIL].body), *pb = dBodyGetPosition(b->h[TX_BAND_TUBE_HEAD].body);
    dJointSetDBallAnchor1(b->joint, pa[0], pa[1], pa[2]);
    dJointSetDBallAnchor2(b->joint, pb[0], pb[1], pb[2]);
    dJointSetDBallDistance(b->joint, b->rest);
    // the opening: beyond the ring's head along its tangent; the tube goes in against it
    double t[3], c[3];
    int n;
    end_tangent(&b->p[TX_BAND_RING], mark[TX_BAND_RING], 2, t);
    centroid(&b->p[TX_BAND_RING], mark[TX_BAND_RING], 2, c, &n);
    const dReal* pc = dBodyGetPosition(b->h[TX_BAND_BUCKLE].body);
    for (int a = 0; a < 3; a++) b->buckle_local[a] = c[a] + t[a] * d->buckle_offset - pc[a], b->axis_local[a] = -t[a];
    double bc[3], ax[3];
    tx_band_buckle(b, bc, ax);
    const dReal* tip = dBodyGetPosition(b->h[TX_BAND_TUBE_TIP].body);
    b->tip_side = (tip[0] - bc[0]) * ax[0] + (tip[1] - bc[1]) * ax[1] + (tip[2] - bc[2]) * ax[2];
    tx_band_save(b);
  }
  for (int i = 0; i < TX_BAND_PARTS; i++) free(mark[i]), free(tets[i]);
  if (rc) {
    tx_band_destroy(b);
    return NULL;
  }
  return b;
}

void tx_band_destroy(tx_band* b) {
  if (!b) return;
  for (int i = 0; i < TX_BAND_PARTS; i++) {
    tx_fem_destroy(b->p[i].fem);
    free(b->p[i].rest);
    free(b->p[i].pos);
    free(b->p[i].face);
  }
  for (int i = 0; i < TX_BAND_BODIES; i++) free(b->h[i].node), free(b->h[i].local);
  dWorldDestroy(b->world);
  dCloseODE();
  free(b);
}

void tx_band_set_force(tx_band* b, int body, const double f[3]) {
  if (body < 0 || body >= TX_BAND_BODIES || !isfinite(f[0] + f[1] + f[2])) return;
  for (int a = 0; a < 3; a++) b->h[body].force[a] = f[a];
}

void tx_band_drive(tx_band* b, int body, const double p[3]) {
  if (body < 0 || body >= TX_BAND_BODIES || !isfinite(p[0] + p[1] + p[2])) return;
  hold* h = &b->h[body];
  const dReal* x = dBodyGetPosition(h->body);
  if (!h->driven) dBodySetKinematic(h->body), dBodySetAngularVel(h->body, 0, 0, 0);
  h->driven = true;
  for (int a = 0; a < 3; a++) h->from[a] = x[a], h->to[a] = p[a];
}

void tx_band_free(tx_band* b, int body) {
  if (body < 0 || body >= TX_BAND_BODIES || !b->h[body].driven) return;
  b->h[body].driven = false;
  dBodySetDynamic(b->h[body].body);
}

void tx_band_buckle(const tx_band* b, double c[3], double axis[3]) {
  dBodyID body = b->h[TX_BAND_BUCKLE].body;
  body_point(body, b->buckle_local, c);
  dVector3 w;
  dBodyVectorToWorld(body, b->axis_local[0], b->axis_local[1], b->axis_local[2], w);
  axis[0] = w[0], axis[1] = w[1], axis[2] = w[2];
}

// the tip crossed the opening's plane, going in, within its radius: latched
static void check_latch(tx_band* b) {
  double c[3], ax[3];
  tx_band_buckle(b, c, ax);
  const dReal* tip = dBodyGetPosition(b->h[TX_BAND_TUBE_TIP].body);
  double r[3] = {tip[0] - c[0], tip[1] - c[1], tip[2] - c[2]};
  double side = r[0] * ax[0] + r[1] * ax[1] + r[2] * ax[2];
  double radial2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] - side * side;
  if (!b->locked && b->tip_side < 0 && side >= 0 && radial2 < b->def.buckle_radius * b->def.buckle_radius) {
    b->locked = true;
    b->latch = dJointCreateFixed(b->world, 0);
    dJointAttach(b->latch, b->h[TX_BAND_TUBE_TIP].body, b->h[TX_BAND_BUCKLE].body);
    dJointSetFixed(b->latch);
  }
  b->tip_side = side;
}

bool tx_band_step(tx_band* b) {
  dAllocateODEDataForThread(dAllocateMaskAll); // the stepping thread need not be the creating one
  const int n = b->substeps;
  const double h = b->h_sub;
  for (int k = 0; k < n; k++) {
    for (int i = 0; i < TX_BAND_BODIES; i++) {
      hold* ho = &b->h[i];
      if (ho->driven) {
        double p[3];
        for (int a = 0; a < 3; a++) p[a] = ho->from[a] + (ho->to[a] - ho->from[a]) * (k + 1) / n;
        const dReal* x = dBodyGetPosition(ho->body);
        dBodySetLinearVel(ho->body, (p[0] - x[0]) / h, (p[1] - x[1]) / h, (p[2] - x[2]) / h);
      }
    }
    // the soft parts' ends where their bodies carry them over this substep:
    // the bodies are stepped first, and the parts follow
    for (int i = 0; i < TX_BAND_BODIES; i++) {
      hold* ho = &b->h[i];
      if (ho->driven) continue;
      dBodyAddForce(ho->body, ho->force[0], ho->force[1], ho->force[2]);
    }
    // the parts' reaction of the last substep loads the bodies
    for (int i = 0; i < TX_BAND_BODIES && !(b->fresh && k == 0); i++) {
      hold* ho = &b->h[i];
      if (ho->driven) continue;
      for (int j = 0; j < ho->n; j++) {
        double f[3], q[3];
        if (!tx_fem_kinematic_force(b->p[ho->part].fem, ho->node[j], f)) continue;
        body_point(ho->body, ho->local + 3 * j, q);
        dBodyAddForceAtPos(ho->body, f[0], f[1], f[2], q[0], q[1], q[2]);
      }
    }
    dWorldStep(b->world, h);
    for (int i = 0; i < TX_BAND_BODIES; i++) {
      hold* ho = &b->h[i];
      for (int j = 0; j < ho->n; j++) {
        double q[3];
        body_point(ho->body, ho->local + 3 * j, q);
        tx_fem_set_kinematic(b->p[ho->part].fem, ho->node[j], q);
      }
    }
    for (int i = 0; i < TX_BAND_PARTS; i++)
      if (!tx_fem_step(b->p[i].fem, 1)) return false;
    for (int i = 0; i < TX_BAND_BODIES; i++) {
      const dReal* x = dBodyGetPosition(b->h[i].body);
      if (!isfinite(x[0] + x[1] + x[2])) return false;
    }
    check_latch(b);
  }
  for (int i = 0; i < TX_BAND_BODIES; i++) // a driven body stays where it was taken until driven again
    if (b->h[i].driven)
      for (int a = 0; a < 3; a++) b->h[i].from[a] = b->h[i].to[a];
  b->fresh = false;
  return true;
}

void tx_band_save(tx_band* b) {
  for (int i = 0; i < TX_BAND_PARTS; i++) tx_fem_save(b->p[i].fem);
  for (int i = 0; i < TX_BAND_BODIES; i++) {
    dBodyID body = b->h[i].body;
    double* s = b->h[i].saved;
    const dReal *x = dBodyGetPosition(body), *q = dBodyGetQuaternion(body), *v = dBodyGetLinearVel(body),
                *w = dBodyGetAngularVel(body);
    for (int a = 0; a < 3; a++) s[a] = x[a], s[7 + a] = v[a], s[10 + a] = w[a];
    for (int a = 0; a < 4; a++) s[3 + a] = q[a];
  }
  b->saved_locked = b->locked;
}

void tx_band_restore(tx_band* b) {
  for (int i = 0; i < TX_BAND_PARTS; i++) tx_fem_restore(b->p[i].fem);
  for (int i = 0; i < TX_BAND_BODIES; i++) {
    dBodyID body = b->h[i].body;
    const double* s = b->h[i].saved;
    dQuaternion q = {s[3], s[4], s[5], s[6]};
    dBodySetPosition(body, s[0], s[1], s[2]);
    dBodySetQuaternion(body, q);
    dBodySetLinearVel(body, s[7], s[8], s[9]);
    dBodySetAngularVel(body, s[10], s[11], s[12]);
    if (b->h[i].driven)
      for (int a = 0; a < 3; a++) b->h[i].from[a] = b->h[i].to[a] = s[a];
  }
  b->fresh = true;
  // a latch made in the failed step is undone with it
  if (b->locked && !b->saved_locked) {
    dJointDestroy(b->latch);
    b->latch = 0;
    b->locked = false;
  }
  double c[3], ax[3];
  tx_band_buckle(b, c, ax);
  const dReal* tip = dBodyGetPosition(b->h[TX_BAND_TUBE_TIP].body);
  b->tip_side = (tip[0] - c[0]) * ax[0] + (tip[1] - c[1]) * ax[1] + (tip[2] - c[2]) * ax[2];
}

double tx_band_joint_length(const tx_band* b) {
  dVector3 p, q;
  dJointGetDBallAnchor1(b->joint, p);
  dJointGetDBallAnchor2(b->joint, q);
  return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

double tx_band_joint_rest(const tx_band* b) { return b->rest; }
bool tx_band_locked(const tx_band* b) { return b->locked; }
int tx_band_substeps(const tx_band* b) { return b->substeps; }
tx_fem* tx_band_fem(tx_band* b, int part) { return b->p[part].fem; }
double tx_band_substep(const tx_band* b) { return b->h_sub; }

void tx_band_body_position(const tx_band* b, int body, double p[3]) {
  p[0] = p[1] = p[2] = 0;
  if (body < 0 || body >= TX_BAND_BODIES) return;
  const dReal* x = dBodyGetPosition(b->h[body].body);
  p[0] = x[0], p[1] = x[1], p[2] = x[2];
}

int tx_band_nodes(const tx_band* b, int part) { return part >= 0 && part < TX_BAND_PARTS ? b->p[part].nv : 0; }
int tx_band_faces(const tx_band* b, int part) { return part >= 0 && part < TX_BAND_PARTS ? b->p[part].nf : 0; }
void tx_band_positions(const tx_band* b, int part, double* out) {
  if (part >= 0 && part < TX_BAND_PARTS) tx_fem_positions(b->p[part].fem, out);
}
const int32_t* tx_band_face_nodes(const tx_band* b, int part) {
  return part >= 0 && part < TX_BAND_PARTS ? b->p[part].face : NULL;
}
const double* tx_band_rest(const tx_band* b, int part) { return part >= 0 && part < TX_BAND_PARTS ? b->p[part].rest : NULL; }

int tx_band_sections(const tx_band* b, int part) {
  const band_part* p = &b->p[part];
  return p->per > 0 ? p->nv / p->per : 0;
}

void tx_band_section_centre(const tx_band* b, int part, int k, const double* pos, double c[3]) {
  const band_part* p = &b->p[part];
  c[0] = c[1] = c[2] = 0;
  for (int i = k * p->per; i < (k + 1) * p->per; i++)
    for (int a = 0; a < 3; a++) c[a] += pos[3 * i + a] / p->per;
}
