// Grasper picking (controllers/organs/picking.h) on a small soft body, the
// hemisphere of test_fem (R = 2 cm, base fixed), its drawn surface its own
// boundary (each vertex a node, as the band's will be) or a triangle
// embedded in a tetrahedron (as the organs draw theirs): closing jaws pick
// the triangles at the pole and hold their nodes; lifted 5 mm the picked
// nodes are at the jaws to 1e-6 m, their neighbours part of the way, and the
// body pulls the jaws back towards its rest; turned, the nodes turn with
// the jaws; opened, the nodes are let go and the body springs back; a grasp
// and a release event once each, in order; jaws closed from the start or on
// nothing pick nothing; two hands pick at once, each its own nodes; an
// update allocates nothing.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/organs/picking.h"
#include "model/error.h"
#include "studies/experiments/organ_hemisphere.h"

#include "tests/alloc_count.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double R = 0.02;

typedef struct body {
  tx_hemisphere_mesh m;
  tx_fem* fem;
  int32_t* tri;  // boundary triangles
  int nt;
  int32_t* node; // identity: each vertex is its node
  double* x;     // positions now
  int frame_steps;
} body;

static int cmp3(const void* a, const void* b) { return memcmp(a, b, 3 * sizeof(int32_t)); }
static int cmp_int(const void* a, const void* b) { return *(const int32_t*)a - *(const int32_t*)b; }

// the tetrahedra's faces that only one tetrahedron has
static void boundary(body* B) {
  const int nf = 4 * B->m.ne;
  int32_t(*f)[4] = malloc(sizeof *f * (size_t)nf); // sorted nodes, then the face's own order is not needed
  for (int e = 0; e < B->m.ne; e++)
    for (int k = 0; k < 4; k++) {
      int32_t* g = f[4 * e + k];
      for (int i = 0, j = 0; i < 4; i++)
        if (i != k) g[j++] = B->m.e[4 * e + i];
      qsort(g, 3, sizeof(int32_t), cmp_int);
      g[3] = 0;
    }
  qsort(f, (size_t)nf, sizeof *f, cmp3);
  B->tri = malloc(sizeof(int32_t) * 3 * (size_t)nf);
  B->nt = 0;
  for (int i = 0; i < nf;) {
    int j = i + 1;
    while (j < nf && cmp3(f[i], f[j]) == 0) j++;
    if (j - i == 1) memcpy(B->tri + 3 * B->nt++, f[i], 3 * sizeof(int32_t));
    i = j;
  }
  free(f);
}

static void make(body* B, int cells) {
  assert_true(tx_hemisphere_build(R, cells, &B->m));
  tx_fem_def d = tx_fem_def_default();
  d.model = TX_FEM_COROTATED;
  d.mass_scaling = true;
  d.damping = 800; // quasi-static, as test_fem presses it
  B->fem = tx_fem_create(&d, B->m.v, B->m.nv, B->m.e, B->m.ne);
  assert_non_null(B->fem);
  for (int i = 0; i < B->m.nv; i++)
    if (B->m.base[i]) tx_fem_fix(B->fem, i);
  boundary(B);
  B->node = malloc(sizeof(int32_t) * (size_t)B->m.nv);
  for (int i = 0; i < B->m.nv; i++) B->node[i] = i;
  B->x = malloc(sizeof(double) * 3 * (size_t)B->m.nv);
  tx_fem_positions(B->fem, B->x);
  B->frame_steps = (int)(0.03 / tx_fem_dt(B->fem)); // a frame long enough to settle in
}

static void unmake(body* B) {
  tx_fem_destroy(B->fem);
  tx_hemisphere_free(&B->m);
  free(B->tri), free(B->node), free(B->x);
}

static tx_pick_surface own_surface(const body* B) { return (tx_pick_surface){B->m.nv, B->nt, B->tri, 1, B->node, NULL}; }

static const tx_pick_def jaws_def = {.length = 0.02, .reach = 0.003, .closed = 0.1, .open = 0.2};

// jaws along the world's x, the pole half way along them
static tx_instrument_pose jaws_at(double dy, double jaw) {
  return (tx_instrument_pose){.pos = {-0.01, R + dy, 0}, .quat = {1, 0, 0, 0}, .jaw = jaw};
}

// one physics frame: hand h's jaws, then the body steps
static bool frame(tx_picking* p, body* B, int h, const tx_instrument_pose* j, tx_event* e) {
  const double* pos[1] = {B->x};
  bool sent = tx_picking_update(p, h, j, pos, e);
  assert_true(tx_fem_step(B->fem, B->frame_steps));
  tx_fem_positions(B->fem, B->x);
  return sent;
}

static double dist(const double* a, const double* b) { return sqrt(pow(a[0] - b[0], 2) + pow(a[1] - b[1], 2) + pow(a[2] - b[2], 2)); }

static void test_grasp_lift_release(void** state) {
  (void)state;
  body B;
  make(&B, 2);
  tx_pick_surface s = own_surface(&B);
  tx_picking* p = tx_picking_create(&jaws_def, 1);
  assert_non_null(p);
  assert_int_equal(tx_picking_add(p, B.fem, &s), 0);
  tx_event ev[8];
  int n = 0;
  // closed from the start: no grasp
  tx_instrument_pose j = jaws_at(0, 0);
  for (int k = 0; k < 2; k++)
    if (frame(p, &B, 0, &j, &ev[n])) n++;
  assert_int_equal(n, 0);
  assert_int_equal(tx_picking_nodes(p, 0), 0);
  // opened, then closed on the pole
  j = jaws_at(0, 0.5);
  if (frame(p, &B, 0, &j, &ev[n])) n++;
  j = jaws_at(0, 0.05);
  if (frame(p, &B, 0, &j, &ev[n])) n++;
  assert_int_equal(n, 1);
  assert_int_equal(ev[0].kind, TX_EVENT_GRASP);
  assert_int_equal(ev[0].source, 0);
  assert_true(fabs(ev[0].grasp.jaw - 0.05) < 1e-12);
  const double pole[3] = {0, R, 0};
  assert_true(dist(ev[0].grasp.point, pole) < 0.003);
  const int held = tx_picking_nodes(p, 0), tris = tx_picking_triangles(p, 0);
  print_message("  grasp at (%.2f, %.2f, %.2f) mm: %d triangles, %d nodes\n", ev[0].grasp.point[0] * 1e3, ev[0].grasp.point[1] * 1e3,
                ev[0].grasp.point[2] * 1e3, tris, held);
  assert_true(held >= 3 && tris >= 1);
  assert_int_equal(tx_picking_holder(p, 0, B.m.pole), 0);
  int counted = 0;
  for (int i = 0; i < B.m.nv; i++) {
    if (tx_picking_holder(p, 0, i) != 0) {
      assert_false(tx_fem_is_kinematic(B.fem, i));
      continue;
    }
    counted++;
    assert_true(tx_fem_is_kinematic(B.fem, i));
    assert_false(B.m.base[i]); // fixed nodes are never taken
  }
  assert_int_equal(counted, held);
  for (int t = 0; t < B.nt; t++) // each picked triangle's nodes are held
    if (tx_picking_triangle_holder(p, 0, t) == 0)
      for (int c = 0; c < 3; c++) assert_int_equal(tx_picking_holder(p, 0, B.tri[3 * t + c]), 0);

  // lifted 2.5 mm and held, then 5 mm and held; closed again on the way: nothing new
  double half[3];
  for (int k = 1; k <= 14; k++) {
    j = jaws_at(k < 5 ? 0.0005 * k : k < 8 ? 0.0025 : k < 10 ? 0.0025 + 0.00125 * (k - 7) : 0.005, k == 3 ? 0 : 0.05);
    if (frame(p, &B, 0, &j, &ev[n])) n++;
    if (k == 7) tx_picking_force(p, 0, half);
  }
  assert_int_equal(n, 1);
  double worst = 0, part = 0;
  int followed = 0;
  for (int i = 0; i < B.m.nv; i++) {
    const double* x = B.x + 3 * i;
    const double* r = B.m.v + 3 * i;
    if (tx_picking_holder(p, 0, i) == 0) {
      const double want[3] = {r[0], r[1] + 0.005, r[2]};
      worst = fmax(worst, dist(x, want));
    } else if (!B.m.base[i]) {
      double up = x[1] - r[1];
      assert_true(up < 0.005);           // nobody past the jaws
      if (up > 1e-4) followed++, part = fmax(part, up);
    }
  }
  double f[3];
  tx_picking_force(p, 0, f);
  print_message("  lifted 5 mm: picked nodes within %.2g m of the jaws; %d neighbours followed, up to %.2f mm; pull "
                "(%.4f, %.4f, %.4f) N\n",
                worst, followed, part * 1e3, f[0], f[1], f[2]);
  assert_true(worst < 1e-6);
  assert_true(fabs(tx_picking_carried(p, 0) - 0.005) < 1e-12); // how far the jaws carried what they hold
  assert_true(followed >= 3 && part > 0.001 && part < 0.0049);
  assert_true(f[1] < 0);                                           // towards the rest
  assert_true(fabs(f[0]) < 0.2 * -f[1] && fabs(f[2]) < 0.2 * -f[1]); // mostly straight back down
  // at rest both times (quasi-static): about linear in the lift, as a small strain is
  print_message("  pull at 2.5 mm %.4f N: ratio %.3f\n", half[1], f[1] / half[1]);
  assert_true(fabs(f[1] / half[1] - 2) < 0.2);

  // turned 0.3 rad about z at the pivot: the nodes turn with the jaws
  const double a = 0.3;
  j.quat[0] = cos(a / 2), j.quat[3] = sin(a / 2);
  if (frame(p, &B, 0, &j, &ev[n])) n++;
  worst = 0;
  for (int i = 0; i < B.m.nv; i++) {
    if (tx_picking_holder(p, 0, i) != 0) continue;
    const double* r = B.m.v + 3 * i;
    double rel[2] = {r[0] - j.pos[0], r[1] + 0.005 - j.pos[1]};
    const double want[3] = {j.pos[0] + cos(a) * rel[0] - sin(a) * rel[1], j.pos[1] + sin(a) * rel[0] + cos(a) * rel[1], r[2]};
    worst = fmax(worst, dist(B.x + 3 * i, want));
  }
  print_message("  turned 0.3 rad: within %.2g m\n", worst);
  assert_true(worst < 1e-6);
  j.quat[0] = 1, j.quat[3] = 0;
  if (frame(p, &B, 0, &j, &ev[n])) n++;

  // opened: released, and the body springs back
  j.jaw = 0.3;
  if (frame(p, &B, 0, &j, &ev[n])) n++;
  assert_int_equal(n, 2);
  assert_int_equal(ev[1].kind, TX_EVENT_RELEASE);
  assert_int_equal(ev[1].source, 0);
  assert_int_equal(tx_picking_nodes(p, 0), 0);
  for (int i = 0; i < B.m.nv; i++) assert_false(tx_fem_is_kinematic(B.fem, i));
  for (int t = 0; t < B.nt; t++) assert_int_equal(tx_picking_triangle_holder(p, 0, t), -1);
  for (int k = 0; k < 10; k++)
    if (frame(p, &B, 0, &j, &ev[n])) n++;
  double back = 0;
  for (int i = 0; i < B.m.nv; i++) back = fmax(back, dist(B.x + 3 * i, B.m.v + 3 * i));
  print_message("  released: 0.3 s later every node within %.3f mm of its rest\n", back * 1e3);
  assert_true(back < 2e-4);
  assert_int_equal(n, 2);

  // closed 3 cm above the body: no triangle in reach, no grasp
  j = jaws_at(0.03, 0.05);
  if (frame(p, &B, 0, &j, &ev[n])) n++;
  assert_int_equal(n, 2);
  assert_int_equal(tx_picking_nodes(p, 0), 0);
  // a pose that is not finite changes nothing
  j.pos[0] = NAN;
  assert_false(tx_picking_update(p, 0, &j, (const double* const[]){B.x}, &ev[n]));
  assert_false(tx_picking_update(p, 0, NULL, (const double* const[]){B.x}, &ev[n]));
  tx_picking_destroy(p);
  unmake(&B);
}

// The pull against a closed form: one tetrahedron, its base (0,0,0),
// (a,0,0), (0,a,0) fixed, its apex (0,0,h) picked and lifted d along z.
// Its displacement gradient is d/h along zz alone, so the corotated force
// (R = I for this symmetric stretch) gives P_zz = (lambda + 2 mu) d/h
// exactly, and the body's force on the apex is -V P grad N_apex =
// -(a^2 / (6 h)) (lambda + 2 mu) d along z, at any d. Jaws closed on the
// base alone hold nothing: its nodes are fixed.
static void test_pull_closed_form(void** state) {
  (void)state;
  const double a = 0.01, h = 0.01, d = 0.001;
  const double v[] = {0, 0, 0, a, 0, 0, 0, a, 0, 0, 0, h};
  const int e[] = {0, 1, 2, 3};
  tx_fem_def def = tx_fem_def_default();
  def.model = TX_FEM_COROTATED;
  tx_fem* fem = tx_fem_create(&def, v, 4, e, 1);
  if (!fem) { // TetGen's orientation is the other one
    const int flipped[] = {0, 2, 1, 3};
    fem = tx_fem_create(&def, v, 4, flipped, 1);
  }
  assert_non_null(fem);
  for (int i = 0; i < 3; i++) tx_fem_fix(fem, i);
  const int32_t tri[] = {0, 1, 3, 1, 2, 3, 2, 0, 3, 0, 2, 1}, node[] = {0, 1, 2, 3};
  tx_pick_surface s = {4, 4, tri, 1, node, NULL};
  const tx_pick_def def_jaws = {.length = 0.01, .reach = 0.0005, .closed = 0.1, .open = 0.2};
  tx_picking* p = tx_picking_create(&def_jaws, 1);
  assert_int_equal(tx_picking_add(p, fem, &s), 0);
  double x[12];
  memcpy(x, v, sizeof x);
  const double* pos[1] = {x};
  // closed on the base alone (1 mm of jaws lying on it, a quarter in): its nodes are fixed, no grasp
  tx_instrument_pose j = {.pos = {a / 4, a / 4, 0}, .quat = {1, 0, 0, 0}, .jaw = 0.5};
  tx_event ev;
  const tx_pick_def base_jaws = {.length = 0.001, .reach = 0.0001, .closed = 0.1, .open = 0.2};
  tx_picking* q = tx_picking_create(&base_jaws, 1);
  assert_int_equal(tx_picking_add(q, fem, &s), 0);
  assert_false(tx_picking_update(q, 0, &j, pos, &ev));
  j.jaw = 0;
  assert_false(tx_picking_update(q, 0, &j, pos, &ev));
  assert_int_equal(tx_picking_nodes(q, 0), 0);
  assert_int_equal(tx_picking_triangle_holder(q, 0, 3), -1); // and the base is not left flagged
  tx_picking_destroy(q);
  // closed across the apex
  j = (tx_instrument_pose){.pos = {-0.005, 0, h}, .quat = {1, 0, 0, 0}, .jaw = 0.5};
  tx_picking_update(p, 0, &j, pos, &ev);
  j.jaw = 0;
  assert_true(tx_picking_update(p, 0, &j, pos, &ev));
  assert_int_equal(tx_picking_nodes(p, 0), 1); // the apex: the base is fixed
  j.pos[2] += d;
  tx_picking_update(p, 0, &j, pos, &ev);
  assert_true(tx_fem_step(fem, 1));
  tx_fem_positions(fem, x);
  assert_true(fabs(x[11] - (h + d)) < 1e-7);
  double f[3];
  tx_picking_force(p, 0, f);
  const double nu = def.poisson, lambda = def.young * nu / ((1 + nu) * (1 - 2 * nu)), mu = def.young / (2 * (1 + nu));
  const double want = -(a * a / (6 * h)) * (lambda + 2 * mu) * d;
  print_message("  one tetrahedron, apex lifted %.0f mm: pull (%.3g, %.3g, %.6f) N, closed form %.6f N\n", d * 1e3, f[0],
                f[1], f[2], want);
  assert_true(fabs(f[2] / want - 1) < 1e-4);
  assert_true(fabs(f[0]) < 1e-6 * fabs(want) + 1e-9 && fabs(f[1]) < 1e-6 * fabs(want) + 1e-9);
  tx_picking_destroy(p);
  tx_fem_destroy(fem);
}

// hand 0 at the pole, hand 1 on the side (jaws along z, at 45 degrees), 4
// mm jaws on the 4-cell hemisphere: each holds its own nodes and pulls them
// its way
static void test_two_hands(void** state) {
  (void)state;
  body B;
  make(&B, 4);
  tx_pick_surface s = own_surface(&B);
  const tx_pick_def short_jaws = {.length = 0.004, .reach = 0.001, .closed = 0.1, .open = 0.2};
  tx_picking* p = tx_picking_create(&short_jaws, 2);
  assert_non_null(p);
  assert_int_equal(tx_picking_add(p, B.fem, &s), 0);
  const double c = R * sqrt(0.5);
  // the side node nearest (c, c, 0)
  int side = 0;
  for (int i = 0; i < B.m.nv; i++)
    if (dist(B.m.v + 3 * i, (const double[]){c, c, 0}) < dist(B.m.v + 3 * side, (const double[]){c, c, 0})) side = i;
  const double* sp = B.m.v + 3 * side;
  tx_instrument_pose j0 = {.pos = {-0.002, R, 0}, .quat = {1, 0, 0, 0}, .jaw = 0.5},
                     j1 = {.pos = {sp[0], sp[1], sp[2] - 0.002}, .quat = {sqrt(0.5), 0, -sqrt(0.5), 0}, .jaw = 0.5};
  tx_event e;
  const double* pos[1] = {B.x};
  int events = 0;
  for (int k = 0; k < 2; k++) {
    events += tx_picking_update(p, 0, &j0, pos, &e);
    events += tx_picking_update(p, 1, &j1, pos, &e);
    j0.jaw = j1.jaw = 0.05;
  }
  assert_int_equal(events, 2);
  int n0 = tx_picking_nodes(p, 0), n1 = tx_picking_nodes(p, 1);
  print_message("  hand 0 holds %d nodes, hand 1 %d\n", n0, n1);
  assert_true(n0 >= 3 && n1 >= 3);
  assert_int_equal(tx_picking_holder(p, 0, B.m.pole), 0);
  assert_int_equal(tx_picking_holder(p, 0, side), 1);
  // hand 0 up 3 mm, hand 1 out along +x 3 mm
  j0.pos[1] += 0.003, j1.pos[0] += 0.003;
  for (int k = 0; k < 3; k++) {
    tx_picking_update(p, 0, &j0, pos, &e);
    tx_picking_update(p, 1, &j1, pos, &e);
    assert_true(tx_fem_step(B.fem, B.frame_steps));
    tx_fem_positions(B.fem, B.x);
  }
  assert_true(fabs(B.x[3 * B.m.pole + 1] - (R + 0.003)) < 1e-6);
  assert_true(fabs(B.x[3 * side] - (sp[0] + 0.003)) < 1e-6);
  double f0[3], f1[3];
  tx_picking_force(p, 0, f0);
  tx_picking_force(p, 1, f1);
  print_message("  pulls: hand 0 (%.4f, %.4f, %.4f) N, hand 1 (%.4f, %.4f, %.4f) N\n", f0[0], f0[1], f0[2], f1[0], f1[1], f1[2]);
  assert_true(f0[1] < 0 && f1[0] < 0); // each back towards the rest
  // hand 1 opens: only its nodes go
  j1.jaw = 0.5;
  assert_true(tx_picking_update(p, 1, &j1, pos, &e) && e.kind == TX_EVENT_RELEASE && e.source == 1);
  assert_int_equal(tx_picking_nodes(p, 0), n0);
  assert_int_equal(tx_picking_nodes(p, 1), 0);
  assert_false(tx_fem_is_kinematic(B.fem, side));
  assert_true(tx_fem_is_kinematic(B.fem, B.m.pole));
  tx_picking_release(p, -1);
  assert_false(tx_fem_is_kinematic(B.fem, B.m.pole));
  tx_picking_destroy(p);
  unmake(&B);
}

// a drawn triangle embedded in the pole's tetrahedron (the organs' way): the
// nodes that carry its vertices are held, the one that carries nothing is not
static void test_embedded_surface(void** state) {
  (void)state;
  body B;
  make(&B, 2);
  int e = -1, k = -1;
  for (int t = 0; t < B.m.ne && e < 0; t++)
    for (int i = 0; i < 4; i++)
      if (B.m.e[4 * t + i] == B.m.pole) e = t, k = i;
  assert_true(e >= 0);
  const int* t4 = B.m.e + 4 * e;
  const int o1 = (k + 1) % 4, o2 = (k + 2) % 4, o3 = (k + 3) % 4;
  int32_t node[3 * 4];
  float w[3 * 4] = {0};
  for (int v = 0; v < 3; v++)
    for (int i = 0; i < 4; i++) node[4 * v + i] = t4[i];
  w[4 * 0 + k] = 1;                      // the pole itself
  w[4 * 1 + k] = 0.5f, w[4 * 1 + o1] = 0.5f; // half way to the second node
  w[4 * 2 + k] = 0.5f, w[4 * 2 + o2] = 0.5f; // half way to the third
  const int32_t tri[3] = {0, 1, 2};
  tx_pick_surface s = {3, 1, tri, 4, node, w};
  tx_picking* p = tx_picking_create(&jaws_def, 1);
  assert_int_equal(tx_picking_add(p, B.fem, &s), 0);
  tx_instrument_pose j = jaws_at(0, 0.5);
  tx_event ev;
  const double* pos[1] = {B.x};
  assert_false(tx_picking_update(p, 0, &j, pos, &ev));
  j.jaw = 0;
  assert_true(tx_picking_update(p, 0, &j, pos, &ev) && ev.kind == TX_EVENT_GRASP);
  assert_int_equal(tx_picking_nodes(p, 0), 3);
  assert_int_equal(tx_picking_holder(p, 0, t4[k]), 0);
  assert_int_equal(tx_picking_holder(p, 0, t4[o1]), 0);
  assert_int_equal(tx_picking_holder(p, 0, t4[o2]), 0);
  assert_int_equal(tx_picking_holder(p, 0, t4[o3]), -1);
  // the grasp point: on the triangle, nearest the jaws' line (through the pole)
  assert_true(dist(ev.grasp.point, B.m.v + 3 * B.m.pole) < 1e-9);
  tx_picking_destroy(p);

  // refused: a row out of range, weights missing, a bad jaw definition, too many hands
  int32_t bad = B.m.nv;
  tx_pick_surface s2 = {1, 0, tri, 1, &bad, NULL};
  p = tx_picking_create(&jaws_def, 1);
  assert_int_equal(tx_picking_add(p, B.fem, &s2), -1);
  print_message("  %s\n", tx_error());
  assert_non_null(strstr(tx_error(), "node"));
  s2 = (tx_pick_surface){3, 1, tri, 4, node, NULL};
  assert_int_equal(tx_picking_add(p, B.fem, &s2), -1);
  tx_picking_destroy(p);
  tx_pick_def d = jaws_def;
  d.open = d.closed;
  assert_null(tx_picking_create(&d, 1));
  assert_null(tx_picking_create(&jaws_def, TX_PICK_HANDS_MAX + 1));
  unmake(&B);
}

// grasp, carry and release allocate nothing
static void test_update_allocates_nothing(void** state) {
  (void)state;
  body B;
  make(&B, 2);
  tx_pick_surface s = own_surface(&B);
  tx_picking* p = tx_picking_create(&jaws_def, 2);
  assert_int_equal(tx_picking_add(p, B.fem, &s), 0);
  const double* pos[1] = {B.x};
  tx_event e;
  double f[3];
  const double jaw[] = {0.5, 0.05, 0.05, 0.05, 0.5};
  counting = 1;
  allocations = 0;
  for (int k = 0; k < 5; k++) {
    tx_instrument_pose j = jaws_at(0.001 * k, jaw[k]);
    tx_picking_update(p, 0, &j, pos, &e);
    tx_picking_force(p, 0, f);
  }
  counting = 0;
  print_message("  %ld allocations in a grasp, carry and release\n", (long)allocations);
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
  tx_picking_destroy(p);
  unmake(&B);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_grasp_lift_release),
      cmocka_unit_test(test_pull_closed_form),
      cmocka_unit_test(test_two_hands),
      cmocka_unit_test(test_embedded_surface),
      cmocka_unit_test(test_update_allocates_nothing),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
