// The thread's contacts: the broadphase's self contacts against every pair tested
// by brute force, two crossing strands pushed to 2 r apart, the thread
// draped on a capsule and on a triangle patch, and the 1 m/s sweeps: the head
// drags the thread around a 0.5 mm thread (a capsule, then a pinned strand of
// the thread itself) and around the edge of a skin patch, and no node or
// cylinder ever passes through.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/physics/skin_grid.h"
#include "controllers/thread/segment.h"
#include "controllers/thread/thread.h"
#include "model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static double frand(void) { return rand() / (double)RAND_MAX * 2 - 1; }

static double min_self_distance(const tx_thread* t, int skip) {
  int n = tx_thread_node_count(t);
  double best = INFINITY;
  for (int i = 0; i + 1 < n; i++)
    for (int j = i + skip + 1; j + 1 < n; j++) {
      tx_seg_closest c;
      tx_seg_closest_points(tx_thread_position(t, i), tx_thread_position(t, i + 1), tx_thread_position(t, j),
                            tx_thread_position(t, j + 1), &c);
      if (c.dist < best) best = c.dist;
    }
  return best;
}

// a random walk of rest-length steps crumpled into a 12 mm box: every
// cylinder the broadphase marks touching is one that brute force finds within
// 2 r (and none is missed). A compliant rod with no gravity does not move
// before the marks are taken.
static void test_broadphase_finds_every_touching_pair(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 400;
  d.length = 0.4; // l0 = 1 mm
  d.radius = 0.00025;
  d.gravity = 0;
  d.youngs_modulus = 1e-6;
  d.iterations = 1;
  d.max_substeps = 1; // the marks of one substep, at these positions
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double* x = malloc(sizeof(double) * 3 * d.nodes);
  assert_non_null(x);
  srand(3);
  memset(x, 0, sizeof(double) * 3);
  for (int i = 1; i < d.nodes; i++) {
    double u[3], l;
    do {
      for (int a = 0; a < 3; a++) u[a] = frand();
      l = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    } while (l > 1 || l < 0.1);
    for (int a = 0; a < 3; a++) {
      x[3 * i + a] = x[3 * i - 3 + a] + 0.001 * u[a] / l;
      if (fabs(x[3 * i + a]) > 0.006) x[3 * i + a] = x[3 * i - 3 + a] - 0.001 * u[a] / l; // reflect
    }
  }
  assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
  uint8_t* want = calloc(d.nodes, 1);
  assert_non_null(want);
  int pairs = 0;
  for (int i = 0; i + 1 < d.nodes; i++)
    for (int j = i + 2; j + 1 < d.nodes; j++) {
      tx_seg_closest c;
      tx_seg_closest_points(x + 3 * i, x + 3 * i + 3, x + 3 * j, x + 3 * j + 3, &c);
      if (c.dist < 2 * d.radius * 1.01) want[i] = want[j] = 1, pairs++;
    }
  assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  const uint8_t* got = tx_thread_colliding(t);
  int marked = 0;
  tx_thread_contacts c;
  tx_thread_last_contacts(t, &c);
  for (int i = 0; i + 1 < d.nodes; i++) {
    if (got[i] != want[i]) print_message("cylinder %d: %d, brute force %d (%d substeps)\n", i, got[i], want[i], c.substeps);
    assert_int_equal(got[i], want[i]);
    marked += got[i];
  }
  print_message("%d touching pairs, %d cylinders marked; the broadphase proposed %d pairs of %d\n", pairs, marked,
                c.broad_pairs, (d.nodes - 1) * (d.nodes - 2) / 2);
  assert_true(pairs > 20);
  // even crumpled this tight, the broadphase proposes fewer than half of all pairs
  assert_true(c.broad_pairs < (d.nodes - 1) * (d.nodes - 2) / 4);
  free(want);
  free(x);
  tx_thread_destroy(t);
  // a thread lying straight: a few pairs per cylinder, not N of them
  d.nodes = 2000;
  d.length = 2;
  t = tx_thread_create(&d);
  assert_non_null(t);
  assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  tx_thread_last_contacts(t, &c);
  print_message("straight, %d nodes: the broadphase proposed %d pairs\n", d.nodes, c.broad_pairs);
  assert_true(c.broad_pairs < 8 * d.nodes);
  tx_thread_destroy(t);
}

// two strands of one thread cross 0.2 mm apart (a 0.5 mm thread): after a
// step they are 2 r apart, and the crossing cylinders are marked
static void test_crossing_strands_are_pushed_apart(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = 28;
    d.length = 0.027;
    d.gravity = 0;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    // a leg along x at y = 0, a connector, and a leg along z 0.2 mm above
    // the first, crossing it at the origin
    double x[28 * 3];
    for (int i = 0; i <= 10; i++) x[3 * i] = -0.005 + 0.001 * i, x[3 * i + 1] = 0, x[3 * i + 2] = 0;
    for (int i = 11; i <= 17; i++) {
      double f = (i - 10) / 7.0;
      x[3 * i] = 0.005 * (1 - f), x[3 * i + 1] = 0.0002 * f, x[3 * i + 2] = -0.005 * f;
    }
    for (int i = 18; i < 28; i++) x[3 * i] = 0, x[3 * i + 1] = 0.0002, x[3 * i + 2] = -0.005 + 0.001 * (i - 17);
    assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
    tx_thread_set_head(t, x);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    const uint8_t* col = tx_thread_colliding(t);
    int marked = 0;
    for (int i = 0; i < 27; i++) marked += col[i];
    double dmin = min_self_distance(t, 1);
    print_message("%s: closest cylinders %.4g mm apart (2 r = 0.5 mm), %d marked\n", model ? "rod" : "ftl", dmin * 1e3,
                  marked);
    assert_true(marked >= 2);
    assert_true(dmin > 2 * d.radius * 0.98);
    tx_thread_destroy(t);
  }
}

// the rod falls onto a capsule across its middle and drapes over it, never
// nearer than r + R
static void test_rod_drapes_over_a_capsule(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 41;
  d.length = 0.04;
  d.head[0] = -0.02, d.head[1] = 0.002;
  d.youngs_modulus = 2e5; // bends within a few mm under its weight
  d.damping = 5;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  assert_int_equal(tx_thread_unpin(t, 0), TX_THREAD_BAD); // the head stays pinned
  tx_thread_capsule cap = {{0, 0, -0.01}, {0, 0, 0.01}, 0.001};
  assert_int_equal(tx_thread_set_capsules(t, &cap, 1), TX_THREAD_OK);
  // the head held 2 cm to one side; the rest falls across the capsule
  double closest = INFINITY;
  int hits = 0;
  for (int k = 0; k < 500; k++) {
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    tx_thread_contacts c;
    tx_thread_last_contacts(t, &c);
    hits += c.shape_hits;
    for (int i = 0; i < 40; i++) {
      tx_seg_closest cl;
      tx_seg_closest_points(tx_thread_position(t, i), tx_thread_position(t, i + 1), cap.a, cap.b, &cl);
      if (cl.dist < closest) closest = cl.dist;
    }
  }
  print_message("capsule: closest %.4g mm (r + R = 1.25 mm), %d contacts\n", closest * 1e3, hits);
  assert_true(hits > 0);
  assert_true(closest > (d.radius + cap.radius) * 0.99);
  // the part beyond the capsule hangs below it
  assert_true(tx_thread_position(t, 40)[1] < -0.002);
  tx_thread_destroy(t);
}

// the total angle the thread turns around the z axis, from its tail to its
// head (each node's angle in the x y plane)
static double winding(const tx_thread* t, int from, int to) {
  double sum = 0;
  for (int i = to; i > from; i--) {
    const double *a = tx_thread_position(t, i), *b = tx_thread_position(t, i - 1);
    double da = atan2(b[1], b[0]) - atan2(a[1], a[0]);
    while (da > PI) da -= 2 * PI;
    while (da < -PI) da += 2 * PI;
    sum += da;
  }
  return sum;
}

// the head sweeps at 1 m/s under an obstacle on the z axis while the thread
// is held above it (a pinned node at (0, 2 cm, 0)): the thread must wrap
// around the obstacle, turning by about +236 degrees; passing through it
// would turn by -124 degrees. A crossing is a jump of the winding by 2 pi.
static int sweep(tx_thread* t, int anchor, double* final_winding) {
  double head[3] = {-0.015, -0.01, 0};
  double prev = winding(t, 0, anchor);
  int crossings = 0;
  for (int k = 0; k < 60; k++) {
    if (k < 30) head[0] += 0.001; // 1 mm a step at 1 kHz: 1 m/s
    assert_int_equal(tx_thread_set_head(t, head), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    double w = winding(t, 0, anchor);
    if (fabs(w - prev) > PI) crossings++;
    prev = w;
  }
  *final_winding = prev;
  return crossings;
}

// head (-1.5, -1) cm up to (-1.5, 2) cm, then along to the anchor (0, 2) cm: 45 mm
static void free_leg(double* x) {
  for (int i = 0; i <= 45; i++) {
    if (i <= 30)
      x[3 * i] = -0.015, x[3 * i + 1] = -0.01 + 0.001 * i;
    else
      x[3 * i] = -0.015 + 0.001 * (i - 30), x[3 * i + 1] = 0.02;
    x[3 * i + 2] = 0;
  }
}

static void test_sweep_around_a_capsule_thread(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = 46;
    d.length = 0.045;
    d.pin_tail = true;
    d.gravity = 0;
    d.iterations = model ? 4 : 20;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    double x[46 * 3];
    free_leg(x);
    assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
    tx_thread_capsule cap = {{0, 0, -0.02}, {0, 0, 0.02}, 0.00025}; // a 0.5 mm thread
    tx_thread_set_capsules(t, &cap, 1);
    double w;
    int crossings = sweep(t, 45, &w);
    print_message("%s around a 0.5 mm capsule: %d crossings, winding %.0f degrees\n", model ? "rod" : "ftl", crossings,
                  w * 180 / PI);
    assert_int_equal(crossings, 0);
    assert_true(w > 3.5); // wrapped: ~236 degrees
    tx_thread_destroy(t);
  }
}

// the same sweep where the obstacle is the thread itself: its far part runs
// from the anchor up along z and back down the z axis, pinned there
static void test_sweep_around_its_own_strand(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    int n = 46 + 30 + 20 + 50;
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = n;
    d.length = 0.001 * (n - 1);
    d.gravity = 0;
    d.iterations = model ? 4 : 20;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    double* x = malloc(sizeof(double) * 3 * n);
    assert_non_null(x);
    free_leg(x);
    int i = 46;
    for (int k = 1; k <= 30; k++, i++) x[3 * i] = 0, x[3 * i + 1] = 0.02, x[3 * i + 2] = 0.001 * k;
    for (int k = 1; k <= 20; k++, i++) x[3 * i] = 0, x[3 * i + 1] = 0.02 - 0.001 * k, x[3 * i + 2] = 0.03;
    for (int k = 1; k <= 50; k++, i++) x[3 * i] = 0, x[3 * i + 1] = 0, x[3 * i + 2] = 0.03 - 0.001 * k;
    assert_int_equal(i, n);
    assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
    for (int k = 45; k < n; k++) assert_int_equal(tx_thread_pin(t, k, x + 3 * k), TX_THREAD_OK);
    double w;
    int crossings = sweep(t, 45, &w);
    print_message("%s around its own 0.5 mm strand: %d crossings, winding %.0f degrees\n", model ? "rod" : "ftl",
                  crossings, w * 180 / PI);
    assert_int_equal(crossings, 0);
    assert_true(w > 3.5);
    free(x);
    tx_thread_destroy(t);
  }
}

// a 2 x 2 cm skin patch (1 mm triangles) at y = 0; the head drags the thread
// at 1 m/s over it, past its edge and back underneath: no node ever goes from
// one side to the other inside the patch (0.5 mm clear of its border), and
// no cylinder joins nodes on both sides over it
static void test_sweep_around_a_skin_patch(void** state) {
  (void)state;
  float px[21 * 21 * 3];
  int32_t tri[2 * 20 * 20 * 3];
  uint32_t ntri = tx_skin_grid(21, 21, 0.001, 0.001, (double[3]){0, 0, 0}, px, tri);
  for (int model = 0; model < 2; model++) {
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = 31;
    d.length = 0.03;
    d.head[1] = 0.001;
    d.direction[0] = -1;
    d.max_triangles = (int)ntri;
    d.youngs_modulus = 2e7;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    assert_int_equal(tx_thread_set_mesh(t, px, 21 * 21, tri, ntri, 0), TX_THREAD_OK);
    double path[4][3] = {{0, 0.001, 0}, {0.0105, 0.001, 0}, {0.0105, -0.001, 0}, {-0.005, -0.001, 0}};
    double head[3] = {0, 0.001, 0}, prev[31 * 3], now[31 * 3];
    tx_thread_positions(t, prev);
    int crossings = 0, hits = 0, below = 0;
    for (int leg = 0; leg < 3; leg++) {
      double len = sqrt(pow(path[leg + 1][0] - path[leg][0], 2) + pow(path[leg + 1][1] - path[leg][1], 2));
      int steps = (int)lround(len / 0.001);
      for (int k = 1; k <= steps + (leg == 2 ? 30 : 0); k++) {
        double f = k > steps ? 1 : (double)k / steps;
        for (int a = 0; a < 3; a++) head[a] = path[leg][a] + f * (path[leg + 1][a] - path[leg][a]);
        assert_int_equal(tx_thread_set_head(t, head), TX_THREAD_OK);
        assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
        tx_thread_contacts c;
        tx_thread_last_contacts(t, &c);
        hits += c.mesh_hits;
        tx_thread_positions(t, now);
        for (int i = 0; i < 31; i++) {
          const double *a = prev + 3 * i, *b = now + 3 * i;
          bool inside = fabs(b[0]) < 0.0095 && fabs(b[2]) < 0.0095 && fabs(a[0]) < 0.0095 && fabs(a[2]) < 0.0095;
          if (inside && (a[1] > 0) != (b[1] > 0)) crossings++;
          // a cylinder through the patch: its nodes on two sides, over it
          if (i < 30) {
            const double* e = now + 3 * i + 3;
            bool over = fabs(b[0]) < 0.0095 && fabs(b[2]) < 0.0095 && fabs(e[0]) < 0.0095 && fabs(e[2]) < 0.0095;
            if (over && (b[1] > 0) != (e[1] > 0)) crossings++;
          }
        }
        memcpy(prev, now, sizeof prev);
      }
    }
    for (int i = 0; i < 31; i++) below += now[3 * i + 1] < 0;
    print_message("%s around a skin patch: %d crossings, %d contacts, %d of 31 nodes below at the end\n",
                  model ? "rod" : "ftl", crossings, hits, below);
    assert_int_equal(crossings, 0);
    assert_true(hits > 0);
    assert_true(below > 5); // the thread did follow the head around
    tx_thread_destroy(t);
  }
}

// a link whose head is pinned just past the patch's border, running back
// under it: the border edge touches the link at t = 0.05 of it. Pushed by the
// lever 1 / t that makes the contact point move the whole depth, node 1 was
// thrown metres in the instruments scenario (here 85 mm in a step in the rod,
// strain 40). Now no contact pass moves a node more than the depth.
static void test_pinned_link_on_a_skin_edge_is_bounded(void** state) {
  (void)state;
  float px[21 * 21 * 3];
  int32_t tri[2 * 20 * 20 * 3];
  uint32_t ntri = tx_skin_grid(21, 21, 0.001, 0.001, (double[3]){0, 0, 0}, px, tri);
  for (int model = 0; model < 2; model++) {
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = 3;
    d.length = 0.004; // l0 = 2 mm
    d.gravity = 0;
    d.max_triangles = (int)ntri;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    double thick = 0.001, reach = d.radius + thick / 2;
    assert_int_equal(tx_thread_set_mesh(t, px, 21 * 21, tri, ntri, thick), TX_THREAD_OK);
    double head[3] = {0.0101, -0.0001, 0.0003}, dir[3] = {-0.97, -0.243, 0}, x[9], y[9];
    double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1]);
    for (int i = 0; i < 3; i++)
      for (int a = 0; a < 3; a++) x[3 * i + a] = head[a] + dir[a] / dl * 0.002 * i;
    assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
    assert_int_equal(tx_thread_set_head(t, head), TX_THREAD_OK);
    double worst = 0, strain = 0;
    for (int k = 0; k < 20; k++) {
      tx_thread_positions(t, x);
      assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
      tx_thread_positions(t, y);
      for (int i = 0; i < 3; i++) {
        double m = 0;
        for (int a = 0; a < 3; a++) m += pow(y[3 * i + a] - x[3 * i + a], 2);
        m = sqrt(m);
        if (m > worst) worst = m;
      }
      if (tx_thread_max_strain(t) > strain) strain = tx_thread_max_strain(t);
    }
    tx_thread_contacts c;
    tx_thread_last_contacts(t, &c);
    print_message("%s: pinned link on the border edge: largest node move %.3g mm in a step (reach %.3g mm), "
                  "max strain %.3g\n", model ? "rod" : "ftl", worst * 1e3, reach * 1e3, strain);
    // unbounded (before): ftl 7.65 mm, rod 85.1 mm and strain 40.5. The head
    // lies within the reach of the edge, so no turn clears the link: each
    // contact pass (a few a substep) moves node 1 at most the depth
    if (model == TX_THREAD_ROD) {
      assert_true(worst < 0.01);
      assert_true(strain < 0.01);
    } else {
      assert_true(worst < 1.2 * reach);
      assert_true(strain < 1e-12);
    }
    tx_thread_destroy(t);
  }
}

// a piece of the thread falls at 2.4 m/s (2.4 mm a step, ten radii) onto
// the thread's own strand, pinned across its path: the head does not move,
// so only the continuous check of each substep (the pairs' relative moves)
// cuts the steps; the piece lands on the strand and never passes it. The
// piece is cut from the strand (one thread: nodes 0..20 the strand along z
// through the origin, pinned; nodes 21..60 the piece along x, 3 cm above).
static void test_rod_falling_onto_its_own_strand(void** state) {
  (void)state;
  enum { N = 61, S = 21 };
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = N;
  d.length = 0.001 * (N - 1);
  d.gravity = 100;
  d.damping = 0;
  d.bend_factor = 0.01; // limp: it drapes
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double x[3 * N];
  for (int i = 0; i < S; i++) x[3 * i] = 0, x[3 * i + 1] = 0, x[3 * i + 2] = 0.001 * (i - 10);
  for (int i = S; i < N; i++) x[3 * i] = 0.001 * (i - S - 19.5), x[3 * i + 1] = 0.03, x[3 * i + 2] = 0;
  assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
  for (int i = 1; i < S; i++) assert_int_equal(tx_thread_pin(t, i, x + 3 * i), TX_THREAD_OK);
  assert_int_equal(tx_thread_cut(t, S - 1), 1);
  // the piece's winding around the strand (the z axis), from its far end to
  // its cut end: about +68 degrees above it, up to about +340 as it wraps
  // over it (undamped, it then whips off it); a pass through the strand is
  // a jump by 360
  int landed = 0, most = 0, crossings = 0;
  double prev = winding(t, S, N - 1), wmax = prev;
  for (int k = 0; k < 60; k++) {
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    tx_thread_contacts c;
    tx_thread_last_contacts(t, &c);
    if (c.substeps > most) most = c.substeps;
    landed |= c.self_pairs > 0;
    double w = winding(t, S, N - 1);
    if (fabs(w - prev) > PI) crossings++;
    prev = w;
    wmax = fmax(wmax, w);
  }
  print_message("rod falling onto its own strand: %d crossings, wrapped to %.0f degrees, at most %d substeps a step\n",
                crossings, wmax * 180 / PI, most);
  assert_true(landed);
  assert_int_equal(crossings, 0);
  assert_true(wmax > 1.5 * PI); // it wrapped over the strand
  assert_true(most > 1);  // the check did cut the steps
  tx_thread_destroy(t);
}

// a box's surface, 8 corners and 12 triangles (outward by the right-hand rule)
static void box_mesh(const double lo[3], const double hi[3], float x[24], int32_t tri[36]) {
  for (int c = 0; c < 8; c++)
    for (int a = 0; a < 3; a++) x[3 * c + a] = (float)((c >> a & 1) ? hi[a] : lo[a]);
  static const int32_t f[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  memcpy(tri, f, sizeof f);
}

// node p's distance from the box, negative inside it (its depth)
static double box_clearance(const double* p, const double lo[3], const double hi[3]) {
  double out = 0, depth = INFINITY;
  for (int a = 0; a < 3; a++) {
    double g = fmax(lo[a] - p[a], p[a] - hi[a]);
    if (g > 0) out += g * g;
    depth = fmin(depth, -g);
  }
  return out > 0 ? sqrt(out) : -depth;
}

// the rod falls across a rigid box (a closed triangle mesh given as a rigid
// mesh, not the skin): it drapes over it, every node at least r off the box,
// the part beyond hangs down its side;
// without the mesh it falls through
static void test_rod_drapes_over_a_rigid_mesh(void** state) {
  (void)state;
  const double lo[3] = {-0.004, -0.004, -0.01}, hi[3] = {0.004, 0, 0.01};
  float bx[24];
  int32_t bt[36];
  box_mesh(lo, hi, bx, bt);
  for (int listed = 1; listed >= 0; listed--) {
    tx_thread_def d = tx_thread_def_default();
    d.model = TX_THREAD_ROD;
    d.nodes = 41;
    d.length = 0.04;
    d.head[0] = -0.02, d.head[1] = 0.002;
    d.youngs_modulus = 2e5;
    d.damping = 5;
    d.max_meshes = 2;
    d.max_mesh_triangles = 12;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    if (listed) assert_int_equal(tx_thread_set_rigid_mesh(t, 1, bx, 8, bt, 12), TX_THREAD_OK);
    double nearest = INFINITY;
    int hits = 0;
    for (int k = 0; k < 500; k++) {
      assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
      tx_thread_contacts c;
      tx_thread_last_contacts(t, &c);
      hits += c.mesh_hits;
      for (int i = 0; i < 41; i++) nearest = fmin(nearest, box_clearance(tx_thread_position(t, i), lo, hi));
    }
    print_message("rigid box %s: %d contacts, nearest node %.3g mm from it (r = 0.25 mm); node 20 at y %.2f mm, "
                  "node 40 at y %.2f mm\n", listed ? "listed" : "not listed", hits, nearest * 1e3,
                  tx_thread_position(t, 20)[1] * 1e3, tx_thread_position(t, 40)[1] * 1e3);
    if (listed) {
      assert_true(hits > 0);
      assert_true(nearest >= 0.99 * d.radius);
      assert_true(tx_thread_position(t, 20)[1] > 0);      // on the top face
      assert_true(tx_thread_position(t, 40)[1] < -0.002); // down its far side
    } else {
      assert_int_equal(hits, 0);
      assert_true(nearest < -0.001); // through it
    }
    tx_thread_destroy(t);
  }
  // slots and room
  tx_thread_def d = tx_thread_def_default();
  d.max_meshes = 1;
  d.max_mesh_triangles = 11;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  assert_int_equal(tx_thread_set_rigid_mesh(t, 1, bx, 8, bt, 12), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "max_meshes"));
  assert_int_equal(tx_thread_set_rigid_mesh(t, 0, bx, 8, bt, 12), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "max_mesh_triangles"));
  assert_int_equal(tx_thread_set_rigid_mesh(t, 0, bx, 7, bt, 11), TX_THREAD_BAD); // corner 7 is no vertex
  assert_int_equal(tx_thread_set_rigid_mesh(t, 0, bx, 8, bt, 11), TX_THREAD_OK);
  assert_int_equal(tx_thread_set_rigid_mesh(t, 0, bx, 8, bt, 0), TX_THREAD_OK);
  tx_thread_destroy(t);
  d.max_meshes = TX_THREAD_MAX_MESHES + 1;
  assert_null(tx_thread_create(&d));
  assert_non_null(strstr(tx_error(), "max_meshes"));
}

static void test_bad_shapes_and_mesh_refused(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.max_shapes = 1;
  d.max_triangles = 2;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  tx_thread_capsule caps[2] = {{{0, 0, 0}, {0, 0, 0}, 0.001}, {{0, 0, 0}, {0, 0, 0}, 0.001}};
  assert_int_equal(tx_thread_set_capsules(t, caps, 2), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "max_shapes"));
  caps[0].radius = NAN;
  assert_int_equal(tx_thread_set_capsules(t, caps, 1), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "radius"));
  float x[9] = {0, 0, 0, 1, 0, 0, 0, 0, 1};
  int32_t tri[6] = {0, 1, 2, 0, 2, 5};
  assert_int_equal(tx_thread_set_mesh(t, x, 3, tri, 2, 0), TX_THREAD_BAD);
  assert_int_equal(tx_thread_set_mesh(t, x, 3, tri, 3, 0), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "max_triangles"));
  assert_int_equal(tx_thread_set_mesh(t, x, 3, tri, 1, -1), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "thickness"));
  assert_int_equal(tx_thread_set_mesh(t, x, 3, tri, 1, 0), TX_THREAD_OK);
  tx_thread_destroy(t);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_broadphase_finds_every_touching_pair),
      cmocka_unit_test(test_crossing_strands_are_pushed_apart),
      cmocka_unit_test(test_rod_drapes_over_a_capsule),
      cmocka_unit_test(test_sweep_around_a_capsule_thread),
      cmocka_unit_test(test_sweep_around_its_own_strand),
      cmocka_unit_test(test_sweep_around_a_skin_patch),
      cmocka_unit_test(test_pinned_link_on_a_skin_edge_is_bounded),
      cmocka_unit_test(test_rod_falling_onto_its_own_strand),
      cmocka_unit_test(test_rod_drapes_over_a_rigid_mesh),
      cmocka_unit_test(test_bad_shapes_and_mesh_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
