// physics.organs: the LAGB paper's organs. The liver and the stomach are
// tetrahedral soft bodies (bullet/fem.h) held where the anatomy holds them,
// the spleen is rigid; a tool sphere that follows a pose pushes them. Each
// step publishes the drawn surfaces (embedded in the tetrahedra, as the
// paper's PhysX soft bodies draw theirs) and the organs' reaction on the
// tool. A numerical fault is counted and the organs go back to their last
// good state, so the model never holds a NaN.
#include "organs_controller.h"

#include "bullet/fem.h"
#include "picking.h" // grasper picking
#include "removal.h"

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { LIVER, STOMACH, SOFT };

typedef struct surface {
  int nv, nt;
  float* x;     // (nv x 3) m
  int32_t* tri; // (nt x 3)
} surface;

typedef struct organ {
  tx_fem* fem;
  int nodes;
  double* pos;   // (nodes x 3) m, scratch for the positions
  double* rest;  // (nodes x 3) m, the nodes as loaded
  surface s;     // the drawn surface
  int32_t* tet;  // (s.nv x 4) the nodes of the tetrahedron each surface vertex is embedded in
  float* w;      // (s.nv x 4) its barycentric weights there
  tx_port x, tri;
  // removal (cautery's burns): once cut, the organ is drawn by its live tetrahedra's boundary
  int tets;        // tetrahedra as loaded
  bool cut;        // has lost a tetrahedron
  int32_t* row_of; // (nodes) scratch of tx_cut_surface, all -1
  tx_port node;    // ORGAN.surface_node
} organ;

typedef struct organs {
  organ soft[SOFT];
  surface spleen;
  tx_port spleen_x, spleen_tri;
  double tool_r;
  int substeps;
  tx_port pose, contact;
  double prev_f, prev_w, k;
  tx_warning fault, bad_pose;
  tx_result fault_result, p50_result, p99_result, added_result, substeps_result, moved_result, force_result;
  double max_moved, max_force; // m, N: the largest node displacement from rest, the largest force on the tool
  long faults;
  tx_hist steps; // ns
  // grasper picking (picking.c): NULL when no grasp poses are given
  tx_pick_ctl* pick;
  // removal
  tx_port burns;            // TX_EVENT_BURN listened to, or none
  tx_warning burn_refused;  // an event naming no organ, no tetrahedron, or one removed already
  tx_result removed_result; // tetrahedra removed
  long removed;
} organs;

static const char* const names[SOFT] = {"liver", "stomach"};

// E, nu, density: see docs/lagb.md for the sources
static const tx_param_def params[] = {
    {"mode", TX_PARAM_STR, NULL, 0, 0, 0, "fem", "\"fem\": Bullet's FEM deformables; \"links\": its classic soft body"},
    {"model", TX_PARAM_STR, NULL, 0, 0, 0, "neohookean", "fem mode: \"neohookean\" or \"corotated\" (about 4 times slower: a polar decomposition per tetrahedron and substep)"},
    {"assets", TX_PARAM_STR, NULL, 0, 0, 0, "lagb",
     "folder of ORGAN.node/.ele/.obj: a name in assets/ or a path (with a /)"},
    {"liver_young_pa", TX_PARAM_NUM, "Pa", 100, 1e7, 5000, NULL, "liver's Young's modulus (transient elastography)"},
    {"stomach_young_pa", TX_PARAM_NUM, "Pa", 100, 1e7, 10000, NULL, "stomach's Young's modulus"},
    {"poisson", TX_PARAM_NUM, "1", 0, 0.49, 0.45, NULL, "Poisson's ratio of both (nearly incompressible)"},
    {"liver_density", TX_PARAM_NUM, "kg/m^3", 100, 1e5, 1060, NULL, "liver's density (ICRU 46)"},
    {"stomach_density", TX_PARAM_NUM, "kg/m^3", 100, 1e5, 1050, NULL, "stomach's density (ICRU 46)"},
    {"damping", TX_PARAM_NUM, "1/s", 0, 1e4, 5, NULL, "decay rate of node velocities"},
    {"gravity", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL,
     "9.81 m/s^2 along -y (supine, y anterior); off: the organs' rest shape is taken as already carrying their "
     "weight, borne in the body by tissue this model does not have"},
    {"attach_m", TX_PARAM_NUM, "m", 0.001, 0.05, 0.01, NULL,
     "nodes this close to the organs' cranial ends (diaphragm, oesophagus), the stomach's right end (duodenum) "
     "and their posterior faces (the posterior wall) are held"},
    {"max_substep_s", TX_PARAM_NUM, "s", 1e-6, 0.05, 1e-3, NULL,
     "a step is split into substeps of at most this; fem: thinner elements are made heavier to be stable at it"},
    {"iterations", TX_PARAM_INT, "1", 1, 100, 1, NULL, "links mode: position iterations per substep"},
    {"link_stiffness", TX_PARAM_NUM, "1", 1e-4, 1, 0.005, NULL,
     "links mode: Bullet's kLST; with 1 ms substeps and 1 iteration, 0.005 gives the liver about the fem mode's "
     "force at 5 to 10 mm (its stiffness is set by kLST, the iterations and the substep, not by E)"},
    {"volume_stiffness", TX_PARAM_NUM, "1", 0, 10, 1, NULL, "links mode: Bullet's kVC"},
    {"max_speed", TX_PARAM_NUM, "m/s", 0.01, 1e4, 20, NULL, "a faster node is a blow-up"},
    {"tool_radius_m", TX_PARAM_NUM, "m", 0, 0.05, 0.005, NULL, "the tool's tip sphere; 0: no tool"},
    {"pose", TX_PARAM_STR, NULL, 0, 0, 0, "device0.pose", "the pose the tool follows (tx_pose)"},
    // grasper picking (picking.h)
    TX_PICK_PARAMS,
    {"burn_events", TX_PARAM_STR, NULL, 0, 0, 0, "",
     "the stream of TX_EVENT_BURN events (physics.cautery's events) whose tetrahedra are removed; \"\": none"},
};

// --- reading the assets -------------------------------------------------------

static int read_fail(tx_setup* s, const char* path, const char* what) {
  return tx_setup_fail(s, "assets", "%s: %s", path, what);
}

// TetGen's .node (3-D, zero-based) into x (n x 3), .ele (4 nodes) into t
static int read_tetgen(tx_setup* s, const char* base, double** x, int* nx, int** t, int* nt) {
  char path[4096];
  if (snprintf(path, sizeof path, "%s.node", base) >= (int)sizeof path) return read_fail(s, base, "path too long");
  FILE* f = fopen(path, "r");
  if (!f) return read_fail(s, path, "cannot be read");
  int n, dim, na, nb;
  if (fscanf(f, "%d %d %d %d", &n, &dim, &na, &nb) != 4 || n < 4 || n > 1000000 || dim != 3 || na != 0) {
    fclose(f);
    return read_fail(s, path, "not a TetGen .node file of 3-D points");
  }
  *x = malloc(sizeof(double) * 3 * (size_t)n);
  if (!*x) return fclose(f), -1;
  for (int i = 0; i < n; i++) {
    int id;
    double *p = *x + 3 * i, mark;
    if (fscanf(f, "%d %lf %lf %lf", &id, p, p + 1, p + 2) != 4 || id != i || (nb && fscanf(f, "%lf", &mark) != 1)) {
      fclose(f);
      return read_fail(s, path, "a node line is malformed (zero-based numbering expected)");
    }
  }
  fclose(f);
  *nx = n;
  if (snprintf(path, sizeof path, "%s.ele", base) >= (int)sizeof path) return read_fail(s, base, "path too long");
  f = fopen(path, "r");
  if (!f) return read_fail(s, path, "cannot be read");
  int per;
  if (fscanf(f, "%d %d %d", &n, &per, &na) != 3 || n < 1 || n > 4000000 || per != 4) {
    fclose(f);
    return read_fail(s, path, "not a TetGen .ele file of 4-node tetrahedra");
  }
  *t = malloc(sizeof(int) * 4 * (size_t)n);
  if (!*t) return fclose(f), -1;
  for (int i = 0; i < n; i++) {
    int id, *e = *t + 4 * i;
    if (fscanf(f, "%d %d %d %d %d", &id, e, e + 1, e + 2, e + 3) != 5 || id != i) {
      fclose(f);
      return read_fail(s, path, "a tetrahedron line is malformed");
    }
    for (int k = 0; k < na; k++) {
      double a;
      if (fscanf(f, "%lf", &a) != 1) return fclose(f), read_fail(s, path, "a tetrahedron line is malformed");
    }
    for (int k = 0; k < 4; k++)
      if (e[k] < 0 || e[k] >= *nx) return fclose(f), read_fail(s, path, "a tetrahedron names a node that is not there");
  }
  fclose(f);
  *nt = n;
  return 0;
}

// a triangle OBJ (v and f lines; f may carry /vt/vn, which are ignored)
static int read_obj(tx_setup* s, const char* path, surface* out) {
  FILE* f = fopen(path, "r");
  if (!f) return read_fail(s, path, "cannot be read");
  char line[512];
  int nv = 0, nt = 0;
  while (fgets(line, sizeof line, f)) nv += line[0] == 'v' && line[1] == ' ', nt += line[0] == 'f' && line[1] == ' ';
  if (nv < 3 || nt < 1) return fclose(f), read_fail(s, path, "no triangles in it");
  out->x = malloc(sizeof(float) * 3 * (size_t)nv);
  out->tri = malloc(sizeof(int32_t) * 3 * (size_t)nt);
  if (!out->x || !out->tri) return fclose(f), -1;
  rewind(f);
  int iv = 0, it = 0;
  while (fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ') {
      float* p = out->x + 3 * iv++;
      if (sscanf(line + 2, "%f %f %f", p, p + 1, p + 2) != 3) return fclose(f), read_fail(s, path, "a vertex line is malformed");
    } else if (line[0] == 'f' && line[1] == ' ') {
      int a, b, c;
      char* q = line + 2;
      int* dst[3] = {&a, &b, &c};
      for (int k = 0; k < 3; k++) {
        char* end;
        long v = strtol(q, &end, 10);
        if (end == q) return fclose(f), read_fail(s, path, "a face is not a triangle of vertex numbers");
        *dst[k] = (int)v;
        q = end;
        while (*q && *q != ' ' && *q != '\t') q++;
      }
      if (a < 1 || b < 1 || c < 1 || a > nv || b > nv || c > nv) return fclose(f), read_fail(s, path, "a face names a vertex that is not there");
      int32_t* t = out->tri + 3 * it++;
      t[0] = a - 1, t[1] = b - 1, t[2] = c - 1;
    }
  }
  fclose(f);
  out->nv = nv, out->nt = nt;
  return 0;
}

// each surface vertex in the tetrahedron where its barycentric weights are
// least negative (inside where it is inside the tetrahedra; the surface and
// the tetrahedra's coarser hull differ by a fraction of an element)
static int embed(organ* o, const double* x, const int* t, int nt) {
  o->tet = malloc(sizeof(int32_t) * 4 * (size_t)o->s.nv);
  o->w = malloc(sizeof(float) * 4 * (size_t)o->s.nv);
  if (!o->tet || !o->w) return -1;
  for (int v = 0; v < o->s.nv; v++) {
    const float* p = o->s.x + 3 * v;
    double best = -INFINITY, bw[4] = {1, 0, 0, 0};
    int bt = 0;
    for (int e = 0; e < nt; e++) {
      const double *a = x + 3 * t[4 * e], *b = x + 3 * t[4 * e + 1], *c = x + 3 * t[4 * e + 2], *d = x + 3 * t[4 * e + 3];
      // quick reject: farther from a than the sum of a's edges and the best miss allows
      double m[3][3] = {{b[0] - a[0], c[0] - a[0], d[0] - a[0]}, {b[1] - a[1], c[1] - a[1], d[1] - a[1]},
                        {b[2] - a[2], c[2] - a[2], d[2] - a[2]}};
      double r[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
      double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                   m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
      if (!(fabs(det) > 0)) continue;
      double l[3];
      for (int k = 0; k < 3; k++) { // Cramer
        double n[3][3];
        memcpy(n, m, sizeof n);
        for (int i = 0; i < 3; i++) n[i][k] = r[i];
        l[k] = (n[0][0] * (n[1][1] * n[2][2] - n[1][2] * n[2][1]) - n[0][1] * (n[1][0] * n[2][2] - n[1][2] * n[2][0]) +
                n[0][2] * (n[1][0] * n[2][1] - n[1][1] * n[2][0])) /
               det;
      }
      double w[4] = {1 - l[0] - l[1] - l[2], l[0], l[1], l[2]};
      double lo = fmin(fmin(w[0], w[1]), fmin(w[2], w[3]));
      if (lo > best) {
        best = lo, bt = e;
        memcpy(bw, w, sizeof bw);
      }
    }
    for (int k = 0; k < 4; k++) o->tet[4 * v + k] = t[4 * bt + k], o->w[4 * v + k] = (float)bw[k];
  }
  return 0;
}

// the nodes the anatomy holds: the liver's cranial end (the diaphragm), the
// stomach's cranial end (the oesophagus, cut where the phantom ends) and its
// right end (the duodenum); and, the patient supine, both organs' posterior
// faces, which rest on the posterior abdominal wall (without them a 5 kPa
// liver hung from its top sags by centimetres)
static int attach(tx_fem* f, const double* x, int n, int which, double band) {
  double hi[3] = {-INFINITY, -INFINITY, -INFINITY}, lo[3] = {INFINITY, INFINITY, INFINITY};
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++) hi[a] = fmax(hi[a], x[3 * i + a]), lo[a] = fmin(lo[a], x[3 * i + a]);
  int held = 0;
  for (int i = 0; i < n; i++) {
    bool hold = x[3 * i + 2] > hi[2] - band || x[3 * i + 1] < lo[1] + band || (which == STOMACH && x[3 * i] > hi[0] - band);
    if (hold) tx_fem_fix(f, i), held++;
  }
  return held;
}

static int load_organ(tx_setup* s, organs* g, int which, const char* dir, const tx_fem_def* d, double band) {
  organ* o = &g->soft[which];
  char base[4096], path[4200];
  if (snprintf(base, sizeof base, "%s/%s", dir, names[which]) >= (int)sizeof base) return tx_setup_fail(s, "assets", "path too long");
  double* x = NULL;
  int *t = NULL, nx = 0, nt = 0;
  int rc = read_tetgen(s, base, &x, &nx, &t, &nt);
  if (rc == 0) {
    if (snprintf(path, sizeof path, "%s.obj", base) >= (int)sizeof path) rc = read_fail(s, base, "path too long");
    else rc = read_obj(s, path, &o->s);
  }
  if (rc == 0) {
    o->fem = tx_fem_create(d, x, nx, t, nt);
    if (!o->fem) rc = tx_setup_fail(s, "assets", "%s: %s", base, tx_error());
  }
  if (rc == 0 && attach(o->fem, x, nx, which, band) == 0) rc = tx_setup_fail(s, "attach_m", "holds no node of the %s", names[which]);
  if (rc == 0) rc = embed(o, x, t, nt);
  if (rc == 0) {
    o->tets = nt;
    o->row_of = malloc(sizeof(int32_t) * (size_t)nx);
    if (!o->row_of) rc = -1;
    for (int i = 0; rc == 0 && i < nx; i++) o->row_of[i] = -1;
  }
  if (rc == 0) {
    o->nodes = nx;
    o->pos = malloc(sizeof(double) * 3 * (size_t)nx);
    o->rest = x;
    x = NULL;
    if (!o->pos) rc = -1;
  }
  free(x);
  free(t);
  return rc;
}

// --- the controller ----------------------------------------------------------------

static int configure(tx_setup* s, void** self) {
  organs* g = calloc(1, sizeof *g);
  if (!g) return -1;
  *self = g;
  double rate = tx_setup_rate_in(s, TX_ORGANS_RATE_MIN_HZ, TX_ORGANS_RATE_MAX_HZ);
  if (!rate) return -1;
  const char *mode = tx_table_str(s, "mode"), *model = tx_table_str(s, "model"), *assets = tx_table_str(s, "assets"),
             *pose = tx_table_str(s, "pose");
  if (!mode || !model || !assets || !pose) return -1;
  tx_fem_def d = tx_fem_def_default();
  if (strcmp(mode, "links") == 0) d.model = TX_FEM_LINKS;
  else if (strcmp(mode, "fem") != 0) return tx_setup_fail(s, "mode", "expected \"fem\" or \"links\", got \"%s\"", mode);
  else if (strcmp(model, "corotated") == 0) d.model = TX_FEM_COROTATED;
  else if (strcmp(model, "neohookean") == 0) d.model = TX_FEM_NEOHOOKEAN;
  else return tx_setup_fail(s, "model", "expected \"corotated\" or \"neohookean\", got \"%s\"", model);
  double max_sub = tx_table_num(s, "max_substep_s");
  g->substeps = (int)ceil(1.0 / rate / max_sub - 1e-9);
  d.dt = 1.0 / rate / g->substeps;
  d.mass_scaling = true;
  d.poisson = tx_table_num(s, "poisson");
  d.damping = tx_table_num(s, "damping");
  d.iterations = (int)tx_table_int(s, "iterations");
  d.link_stiffness = tx_table_num(s, "link_stiffness");
  d.volume_stiffness = tx_table_num(s, "volume_stiffness");
  d.max_speed = tx_table_num(s, "max_speed");
  if (tx_table_bool(s, "gravity")) d.gravity[1] = -9.81;
  g->tool_r = tx_table_num(s, "tool_radius_m");
  double band = tx_table_num(s, "attach_m");

  char dir[4096];
  int len = strchr(assets, '/') ? snprintf(dir, sizeof dir, "%s", assets) : snprintf(dir, sizeof dir, "%s/%s", TX_ASSET_DIR, assets);
  if (len >= (int)sizeof dir - 64) return tx_setup_fail(s, "assets", "%s: path too long", assets);
  const double young[SOFT] = {tx_table_num(s, "liver_young_pa"), tx_table_num(s, "stomach_young_pa")};
  const double density[SOFT] = {tx_table_num(s, "liver_density"), tx_table_num(s, "stomach_density")};
  for (int i = 0; i < SOFT; i++) {
    d.young = young[i], d.density = density[i];
    int rc = load_organ(s, g, i, dir, &d, band);
    if (rc) return rc;
  }
  char path[4200];
  if (snprintf(path, sizeof path, "%s/spleen.obj", dir) >= (int)sizeof path) return tx_setup_fail(s, "assets", "path too long");
  int rc = read_obj(s, path, &g->spleen);
  if (rc) return rc;

  for (int i = 0; i < SOFT; i++) {
    char key[64];
    snprintf(key, sizeof key, "%s.x", names[i]);
    // room for the drawn surface, or for the live tetrahedra's boundary once cut
    organ* o = &g->soft[i];
    uint32_t rows = (uint32_t)(o->s.nv > o->nodes ? o->s.nv : o->nodes), tris = (uint32_t)(o->s.nt > 4 * o->tets ? o->s.nt : 4 * o->tets);
    o->x = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_vertex, rows));
    snprintf(key, sizeof key, "%s.tri", names[i]);
    o->tri = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_triangle, tris));
    snprintf(key, sizeof key, "%s.surface_node", names[i]);
    o->node = tx_setup_write(s, &TX_COMPONENT_OF(key, tx_surface_node, rows));
  }
  g->spleen_x = tx_setup_write(s, &TX_COMPONENT_OF("spleen.x", tx_vertex, (uint32_t)g->spleen.nv));
  g->spleen_tri = tx_setup_write(s, &TX_COMPONENT_OF("spleen.tri", tx_triangle, (uint32_t)g->spleen.nt));
  g->contact = tx_setup_write(s, &TX_COMPONENT_OF("organs.contact", tx_skin_contact, 1));
  if (g->tool_r > 0) g->pose = TX_READ_OF(s, pose, tx_pose);
  g->fault = tx_setup_warning(s, "numerical_fault");
  g->bad_pose = tx_setup_warning(s, "bad_pose");
  g->fault_result = tx_setup_result(s, "faults");
  g->p50_result = tx_setup_result(s, "step_p50_ms");
  g->p99_result = tx_setup_result(s, "step_p99_ms");
  g->added_result = tx_setup_result(s, "added_mass");
  g->substeps_result = tx_setup_result(s, "substeps");
  g->moved_result = tx_setup_result(s, "max_displacement_m");
  g->force_result = tx_setup_result(s, "max_force_n");
  // removal
  const char* burns = tx_table_str(s, "burn_events");
  if (!burns) return -1;
  if (burns[0]) g->burns = tx_setup_listen(s, burns);
  g->burn_refused = tx_setup_warning(s, "burn_refused");
  g->removed_result = tx_setup_result(s, "removed_tets");
  tx_hist_clear(&g->steps);

  // grasper picking: both soft organs, their drawn surfaces carried by the tetrahedra they lie in
  {
    tx_fem* fem[SOFT];
    tx_pick_surface surf[SOFT];
    for (int i = 0; i < SOFT; i++) {
      const organ* o = &g->soft[i];
      fem[i] = o->fem;
      surf[i] = (tx_pick_surface){o->s.nv, o->s.nt, o->s.tri, 4, o->tet, o->w};
    }
    if (tx_pick_configure(s, "organs", SOFT, fem, surf, &g->pick)) return -1;
  }
  return 0;
}

// The organs' reaction on the tool and its tangent stiffness k = d|f|/dw.
// A sphere pressed into an elastic body pushes back as |f| ~ w^p, p = 3/2
// (Hertz) on a half space, toward 1 where the body is thin, so k = p |f| / w
// lies in [|f|/w, 2|f|/w]; the secant between two steps in contact picks p.
static void publish_contact(tx_ctx* c, organs* g, const tx_pose* pose) {
  tx_skin_contact* out = tx_write(c, g->contact);
  memset(out, 0, sizeof *out);
  double fsum[3] = {0, 0, 0}, w = 0;
  int touched = 0;
  for (int i = 0; i < SOFT; i++) {
    tx_fem_tool_info t;
    tx_fem_tool(g->soft[i].fem, &t);
    for (int a = 0; a < 3; a++) fsum[a] += t.f[a];
    w = fmax(w, t.depth);
    touched += t.faces;
  }
  if (pose)
    for (int a = 0; a < 3; a++) out->x[a] = pose->pos[a];
  double f = sqrt(fsum[0] * fsum[0] + fsum[1] * fsum[1] + fsum[2] * fsum[2]);
  if (touched == 0 || !(f > 0) || !isfinite(f) || !isfinite(w)) {
    g->prev_f = g->prev_w = g->k = 0;
    return;
  }
  for (int a = 0; a < 3; a++) out->f[a] = fsum[a], out->n[a] = fsum[a] / f;
  g->max_force = fmax(g->max_force, f);
  out->depth = w;
  out->touching = 1;
  if (w > 1e-7) {
    double lo = f / w, hi = 2 * f / w, kk = g->k;
    if (g->prev_w > 0 && fabs(w - g->prev_w) > 1e-6) kk = (f - g->prev_f) / (w - g->prev_w);
    g->k = kk < lo ? lo : kk > hi ? hi : kk;
  }
  out->k = g->k;
  g->prev_f = f, g->prev_w = w;
}

static void publish(tx_ctx* c, organs* g, const tx_pose* pose) {
  for (int i = 0; i < SOFT; i++) {
    organ* o = &g->soft[i];
    tx_fem_positions(o->fem, o->pos);
    for (int v = 0; v < o->nodes; v++) {
      const double *p = o->pos + 3 * v, *r = o->rest + 3 * v;
      double d2 = (p[0] - r[0]) * (p[0] - r[0]) + (p[1] - r[1]) * (p[1] - r[1]) + (p[2] - r[2]) * (p[2] - r[2]);
      if (d2 > g->max_moved * g->max_moved) g->max_moved = sqrt(d2);
    }
    float* x = ((tx_vertex*)tx_write(c, o->x))->x;
    int32_t* node = &((tx_surface_node*)tx_write(c, o->node))->node;
    if (o->cut) { // removal: the live tetrahedra's boundary, one row a node
      int nf;
      const int* hull = tx_fem_hull(o->fem, &nf);
      int rows = tx_cut_surface(hull, nf, o->pos, o->row_of, node, x, ((tx_triangle*)tx_write(c, o->tri))->v);
      tx_write_rows(c, o->x, (uint32_t)rows), tx_write_rows(c, o->node, (uint32_t)rows), tx_write_rows(c, o->tri, (uint32_t)nf);
      continue;
    }
    for (int v = 0; v < o->s.nv; v++) {
      node[v] = -1;
      for (int a = 0; a < 3; a++) {
        double p = 0;
        for (int k = 0; k < 4; k++) p += o->w[4 * v + k] * o->pos[3 * o->tet[4 * v + k] + a];
        x[3 * v + a] = (float)p;
      }
    }
    memcpy(((tx_triangle*)tx_write(c, o->tri))->v, o->s.tri, sizeof(int32_t) * 3 * (size_t)o->s.nt);
    tx_write_rows(c, o->x, (uint32_t)o->s.nv), tx_write_rows(c, o->node, (uint32_t)o->s.nv), tx_write_rows(c, o->tri, (uint32_t)o->s.nt);
  }
  memcpy(((tx_vertex*)tx_write(c, g->spleen_x))->x, g->spleen.x, sizeof(float) * 3 * (size_t)g->spleen.nv);
  memcpy(((tx_triangle*)tx_write(c, g->spleen_tri))->v, g->spleen.tri, sizeof(int32_t) * 3 * (size_t)g->spleen.nt);
  publish_contact(c, g, pose);
}

// removal: the tetrahedra the cautery vaporised leave their organ's body
static void take_burns(tx_ctx* c, organs* g) {
  tx_event e;
  while (g->burns.id && tx_next_event(c, g->burns, &e)) {
    if (e.kind != TX_EVENT_BURN) continue;
    double which = e.burn.organ;
    organ* o = which == 0 || which == 1 ? &g->soft[(int)which] : NULL;
    if (!o || !tx_fem_remove_tet(o->fem, (int)e.source)) {
      tx_warn(c, g->burn_refused);
      continue;
    }
    o->cut = true, g->removed++;
  }
}

static int init(tx_ctx* c, void* self) {
  organs* g = self;
  publish(c, g, NULL); // the organs at rest, at time 0
  tx_pick_init(c, g->pick);
  return 0;
}

static void step(tx_ctx* c, void* self) {
  organs* g = self;
  struct timespec t0, t1;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t0); // the step's CPU time on its one core
  const tx_pose* pose = NULL;
  if (g->pose.id) {
    tx_snapshot p = tx_read(c, g->pose);
    if (p.seq > 0) { // nothing published yet: the tool waits
      pose = p.data;
      if (!isfinite(pose->pos[0] + pose->pos[1] + pose->pos[2])) {
        tx_warn(c, g->bad_pose);
        pose = NULL;
      }
    }
  }
  take_burns(c, g);
  // grasper picking: the jaws grasp or release on the organs as the last step left them
  if (g->pick) {
    const double* pos[SOFT];
    for (int i = 0; i < SOFT; i++) pos[i] = g->soft[i].pos;
    tx_pick_before(c, g->pick, pos);
  }
  bool ok = true;
  for (int i = 0; i < SOFT && ok; i++) {
    tx_fem_set_tool(g->soft[i].fem, pose ? pose->pos : (const double[3]){0, 0, 0}, pose ? g->tool_r : 0);
    ok = tx_fem_step(g->soft[i].fem, g->substeps);
  }
  if (ok)
    for (int i = 0; i < SOFT; i++) tx_fem_save(g->soft[i].fem);
  else { // both organs back to where they were after the last good step
    tx_warn(c, g->fault);
    g->faults++;
    for (int i = 0; i < SOFT; i++) tx_fem_restore(g->soft[i].fem);
  }
  publish(c, g, pose);
  tx_pick_after(c, g->pick, ok); // the organs' pull on the jaws
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t1);
  tx_hist_add(&g->steps, (int64_t)(t1.tv_sec - t0.tv_sec) * 1000000000 + (t1.tv_nsec - t0.tv_nsec));
}

static void finish(tx_ctx* c, void* self) {
  organs* g = self;
  tx_percentiles p = tx_hist_percentiles(&g->steps);
  tx_set_result(c, g->fault_result, (double)g->faults);
  tx_set_result(c, g->p50_result, p.p50 * 1e-6);
  tx_set_result(c, g->p99_result, p.p99 * 1e-6);
  double added = 0;
  for (int i = 0; i < SOFT; i++) added = fmax(added, tx_fem_added_mass(g->soft[i].fem));
  tx_set_result(c, g->added_result, added);
  tx_set_result(c, g->substeps_result, g->substeps);
  tx_set_result(c, g->moved_result, g->max_moved);
  tx_set_result(c, g->force_result, g->max_force);
  tx_pick_finish(c, g->pick);
  tx_set_result(c, g->removed_result, (double)g->removed);
}

static void fini(void* self) {
  organs* g = self;
  if (!g) return;
  for (int i = 0; i < SOFT; i++) {
    organ* o = &g->soft[i];
    tx_fem_destroy(o->fem);
    free(o->pos);
    free(o->rest);
    free(o->s.x);
    free(o->s.tri);
    free(o->tet);
    free(o->w);
    free(o->row_of);
  }
  free(g->spleen.x);
  free(g->spleen.tri);
  tx_pick_free(g->pick);
  free(g);
}

const tx_controller_class tx_physics_organs = {
    .type = "physics.organs",
    .summary = "LAGB organs on Bullet: soft liver and stomach (fem or links), rigid spleen, a tool sphere; writes "
               "liver.x/.tri, stomach.x/.tri, spleen.x/.tri, organs.contact",
    .configure = configure,
    .init = init,
    .step = step,
    .finish = finish,
    .fini = fini,
    .params = params,
    .nparams = TX_PARAMS_COUNT(params),
};
