// The tool tip against closed surfaces with known answers: a geodesic sphere
// (inscribed in a sphere of radius R and circumscribing one of radius R_in, so
// the signed distance of any point at D from the centre lies in
// [D - R, D - R_in], and its normal is radial within the facets' angle), a
// thin box (the far side never pushes), and the committed liver against a
// brute-force search. The force points out and grows with depth, a refit
// carries the contact, the physics' reaction is carried as collision.hip's
// mechanics mode does, and nothing allocates.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/collision/organ.h"
#include "controllers/thread/segment.h"
#include "model/error.h"
#include "tests/controllers/collision/organ_shapes.h"

#include <tactus/components.h>
#include <tactus/config.h>
#if TX_WITH_ASSIMP
#include "controllers/instruments/mesh_io.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/alloc_count.h"

#define R 0.05   // m, the sphere: liver-sized
#define TIP 2.5e-3
static const double O[3] = {0.01, -R, 0.02}; // its top near the origin

typedef struct fixture {
  shape s;
  tx_tri_bvh b;
  double r_in; // m, the nearest a facet comes to the centre
} fixture;

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static fixture* make(shape s) {
  fixture* f = calloc(1, sizeof *f);
  assert_non_null(f);
  f->s = s;
  assert_true(shape_volume(&s) > 0); // wound outwards
  assert_int_equal(tx_tri_bvh_init(&f->b, s.ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&f->b, s.x, s.nx, s.tri, s.ntri), 0);
  f->r_in = INFINITY;
  for (uint32_t t = 0; t < s.ntri; t++) { // distance from O to each facet's plane
    double v[3][3];
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) v[k][a] = s.x[3 * s.tri[3 * t + k] + a] - O[a];
    double e1[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
    double e2[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double d = dot3(n, v[0]) / sqrt(dot3(n, n));
    if (d < f->r_in) f->r_in = d;
  }
  return f;
}

static fixture* sphere(int level) { return make(ico_sphere(level, R, O)); }

static void drop(fixture* f) {
  tx_tri_bvh_free(&f->b);
  shape_free(&f->s);
  free(f);
}

// the point at distance dist from O along the unit direction u
static void along(const double u[3], double dist, double c[3]) {
  for (int a = 0; a < 3; a++) c[a] = O[a] + dist * u[a];
}

static void unit(double u[3]) {
  double l = sqrt(dot3(u, u));
  for (int a = 0; a < 3; a++) u[a] /= l;
}

// brute force: the nearest distance from c to any triangle
static double brute(const shape* s, const double c[3]) {
  double best = INFINITY;
  for (uint32_t t = 0; t < s->ntri; t++) {
    double v[3][3], q[3];
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) v[k][a] = s->x[3 * s->tri[3 * t + k] + a];
    tx_tri_closest_point(c, v[0], v[1], v[2], q, NULL);
    double d[3] = {c[0] - q[0], c[1] - q[1], c[2] - q[2]};
    if (sqrt(dot3(d, d)) < best) best = sqrt(dot3(d, d));
  }
  return best;
}

static void test_nearest_on_a_sphere(void** state) {
  (void)state;
  fixture* f = sphere(4);
  assert_int_equal(f->s.ntri, 5120);
  assert_true(R - f->r_in < 1e-4 && R - f->r_in > 0); // the facets' sagitta: the closed form's tolerance
  srand(7);
  for (int i = 0; i < 400; i++) {
    double u[3] = {rand() / (double)RAND_MAX - 0.5, rand() / (double)RAND_MAX - 0.5, rand() / (double)RAND_MAX - 0.5};
    unit(u);
    double dist = R + (rand() / (double)RAND_MAX - 0.5) * 0.03; // 15 mm inside to 15 mm outside
    double c[3];
    along(u, dist, c);
    tx_organ_near n;
    assert_true(tx_organ_nearest(&f->b, f->s.x, c, 0.02, NULL, &n));
    // the closed form: the polyhedron lies between the spheres R_in and R
    assert_true(n.s >= dist - R - 1e-7 && n.s <= dist - f->r_in + 1e-7);
    // the BVH finds the true nearest
    assert_true(fabs(fabs(n.s) - brute(&f->s, c)) < 1e-9);
    // the outward direction is radial within the facets' angle (a few degrees)
    if (fabs(n.s) > 1e-3) assert_true(dot3(n.n, u) > 0.995);
  }
  // nothing within a range that does not reach the surface
  double c[3], u[3] = {0, 1, 0};
  tx_organ_near n;
  along(u, R + 0.01, c);
  assert_false(tx_organ_nearest(&f->b, f->s.x, c, 0.009, NULL, &n));
  assert_true(tx_organ_nearest(&f->b, f->s.x, c, 0.011, NULL, &n));
  drop(f);
}

static tx_organ_tip_def tip_def(void) {
  tx_organ_tip_def d = tx_organ_tip_def_default();
  d.radius = TIP;
  assert_int_equal(tx_organ_tip_def_check(&d), 0);
  return d;
}

static void test_def_checked(void** state) {
  (void)state;
  tx_organ_tip_def d = tx_organ_tip_def_default();
  assert_int_equal(tx_organ_tip_def_check(&d), 0);
  d.radius = 0;
  assert_int_equal(tx_organ_tip_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "radius"));
  d = tx_organ_tip_def_default();
  d.depth_max = NAN;
  assert_int_equal(tx_organ_tip_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "depth_max"));
}

// a tip lowered onto the sphere along u: the force points out (radially) and grows with depth
static void test_force_points_out_and_grows(void** state) {
  (void)state;
  fixture* f = sphere(4);
  tx_organ_tip_def d = tip_def();
  tx_organ_side side;
  tx_organ_side_reset(&side);
  double u[3] = {0.3, 1, -0.2};
  unit(u);
  const double k = 200;
  double last = 0;
  int onsets = 0;
  for (int i = 0; i <= 60; i++) { // from 5 mm clear of the sphere to 10 mm into it, 0.25 mm a step
    double dist = R + TIP + 5e-3 - 2.5e-4 * i, c[3];
    along(u, dist, c);
    tx_organ_touch t;
    tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
    onsets += t.onset;
    tx_organ_force_out o;
    tx_organ_force(&t, 1, NULL, k, d.depth_max, c, &o);
    // depth = r - s with s in [dist - R, dist - R_in]
    double lo = TIP - (dist - f->r_in), hi = TIP - (dist - R);
    if (hi < 0) { // clear of the sphere
      assert_false(t.on);
      assert_true(o.kind == TX_ORGAN_FORCE_NONE && o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
      continue;
    }
    if (lo <= 0) continue; // the facets decide
    assert_true(t.on);
    assert_true(t.depth >= lo - 1e-7 && t.depth <= hi + 1e-7);
    assert_true(o.kind == TX_ORGAN_FORCE_PENALTY);
    double fn = sqrt(dot3(o.f, o.f));
    assert_true(fabs(fn - k * t.depth) < 1e-9);
    assert_true(dot3(o.f, u) > 0.995 * fn); // out of the surface
    assert_true(fn > last);                 // grows with depth
    last = fn;
    // K = -k n n^T: a move along n changes F by -k per metre
    double kn[3] = {0, 0, 0};
    for (int e = 0; e < 3; e++)
      for (int a = 0; a < 3; a++) kn[e] += o.k[3 * e + a] * t.n[a];
    for (int e = 0; e < 3; e++) assert_true(fabs(kn[e] + k * t.n[e]) < 1e-9);
  }
  assert_int_equal(onsets, 1);
  assert_true(last > k * 9e-3); // about 10 mm in at the end (the centre 7.5 mm inside)
  drop(f);
}

// a tip that starts inside, or that the surface moved over, is pushed by nothing;
// once out and back in, it is
static void test_inside_unentered_gets_nothing(void** state) {
  (void)state;
  fixture* f = sphere(3);
  tx_organ_tip_def d = tip_def();
  tx_organ_side side;
  tx_organ_side_reset(&side);
  double u[3] = {0, 1, 0}, c[3];
  tx_organ_touch t;
  // from 5 mm inside, out through the surface
  for (int i = 0; i <= 40; i++) {
    along(u, R - 5e-3 + 2.5e-4 * i, c);
    tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
    double s = brute(&f->s, c);
    if (c[1] < -3e-4) { // still inside: the centre is under the top facets (sagitta 0.23 mm)
      assert_false(t.on);
      tx_organ_force_out o;
      tx_organ_force(&t, 1, NULL, 100, d.depth_max, c, &o);
      assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
      if (s < TIP) assert_true(t.inside);
    }
  }
  // now 5 mm above: clear. Lowered again, it touches from outside
  assert_false(side.on);
  along(u, R + 1e-3, c);
  tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
  assert_true(t.on && t.onset && t.depth > 1e-3 && t.n[1] > 0.99);
  drop(f);
}

// a thin box (4 mm) pressed from above: past its middle, and past its bottom,
// the tip is still pushed up, out the way it came in, never down through the
// far side; deeper than depth_max the organ gave way (and the tip, then under
// it, meets its underside from outside). A tip inside the box
// that did not enter it gets nothing until its centre is out
static void test_thin_organ_is_one_sided(void** state) {
  (void)state;
  fixture* f = make(box((double[3]){-0.02, -4e-3, -0.02}, (double[3]){0.02, 0, 0.02}));
  tx_organ_tip_def d = tip_def();
  d.depth_max = 8e-3;
  tx_organ_side side;
  tx_organ_side_reset(&side);
  tx_organ_touch t;
  bool gave = false;
  for (int i = 0; i <= 60; i++) { // the centre from y = 5 mm down to y = -10 mm (off the boundaries by 10 um)
    double c[3] = {1e-3, 5e-3 + 1e-5 - 2.5e-4 * i, 2e-3};
    tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
    double want = TIP - c[1]; // depth below the top face
    if (want <= 0) {
      assert_false(t.on);
    } else if (want <= d.depth_max) {
      assert_true(t.on);
      assert_true(fabs(t.depth - want) < 1e-6);
      assert_true(t.n[1] > 0.999); // up, also past the middle (y < -2 mm) and under the bottom (y < -4 mm)
      assert_false(gave);
    } else {
      gave |= t.gave_way;
      // through: only the box's underside, from outside below it, pushes (down, away)
      if (t.on) assert_true(t.n[1] < -0.999 && c[1] < -4e-3 && gave);
    }
  }
  assert_true(gave);
  // from inside, not entered, up through the top face
  tx_organ_side_reset(&side);
  for (int i = 0; i <= 40; i++) {
    double c[3] = {1e-3, -3e-3 + 1e-5 + 2.5e-4 * i, 2e-3};
    tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
    tx_organ_force_out o;
    tx_organ_force(&t, 1, NULL, 100, d.depth_max, c, &o);
    if (c[1] < 0) { // inside
      assert_false(t.on);
      assert_true(t.inside);
      assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
    } else if (c[1] < TIP) { // out, and touching the top from above
      assert_true(t.on);
      assert_true(fabs(o.f[1] - 100 * (TIP - c[1])) < 1e-6);
    }
  }
  drop(f);
}

// a hand faster than the tip's radius per query: the move crossed the surface from outside
static void test_fast_entry_is_caught(void** state) {
  (void)state;
  fixture* f = sphere(3);
  tx_organ_tip_def d = tip_def();
  tx_organ_side side;
  tx_organ_side_reset(&side);
  double u[3] = {0, 0, 1}, c[3];
  tx_organ_touch t;
  along(u, R + 0.01, c);
  tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
  assert_false(t.on);
  along(u, R - 5e-3, c); // 15 mm in one query, the centre 5 mm inside
  tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
  assert_true(t.on && t.onset);
  assert_true(t.n[2] > 0.99);
  assert_true(t.depth > TIP + 4.5e-3 && t.depth < TIP + 5.1e-3);
  drop(f);
}

// the surface moves by 1 mm toward the tip at a publish: after the refit the depth is 1 mm more
static void test_refit_moves_the_contact(void** state) {
  (void)state;
  fixture* f = sphere(4);
  tx_organ_tip_def d = tip_def();
  tx_organ_side side;
  tx_organ_side_reset(&side);
  double u[3] = {0, 1, 0}, c[3];
  along(u, R + 1e-3, c);
  tx_organ_touch t0, t1;
  tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t0);
  assert_true(t0.on);
  float* moved = malloc(sizeof(float) * 3 * f->s.nx);
  memcpy(moved, f->s.x, sizeof(float) * 3 * f->s.nx);
  for (uint32_t i = 0; i < f->s.nx; i++) moved[3 * i + 1] += 1e-3f;
  assert_true(tx_tri_bvh_same(&f->b, f->s.tri, f->s.ntri));
  tx_tri_bvh_refit(&f->b, moved);
  tx_organ_tip(&side, &d, &f->b, moved, c, &t1);
  assert_true(t1.on);
  assert_true(fabs(t1.depth - t0.depth - 1e-3) < 2e-6);
  // and away by 6 mm: clear of r + hold, the contact ends
  for (uint32_t i = 0; i < f->s.nx; i++) moved[3 * i + 1] -= 7e-3f;
  tx_tri_bvh_refit(&f->b, moved);
  tx_organ_tip(&side, &d, &f->b, moved, c, &t1);
  assert_false(t1.on);
  free(moved);
  drop(f);
}

// the physics' reaction, carried from x to c along its direction: F = f - k ((c - x) . n) n,
// K = -k n n^T; never a pull; nothing without a geometric contact; past depth_max it holds
static void test_reaction_is_carried(void** state) {
  (void)state;
  tx_organ_touch t = {.on = true, .depth = 1e-3, .n = {0, 1, 0}};
  tx_skin_contact r = {.f = {0, 0.5, 0}, .x = {0, 0.001, 0}, .n = {0, 1, 0}, .k = 150, .depth = 4e-3, .touching = 1};
  tx_organ_force_out o;
  double c[3] = {2e-4, -0.001, 0}; // 2 mm deeper than where the physics computed f
  tx_organ_force(&t, 1, &r, 100, 0.02, c, &o);
  assert_true(o.kind == TX_ORGAN_FORCE_REACTION);
  assert_true(fabs(o.f[1] - (0.5 + 150 * 2e-3)) < 1e-12 && o.f[0] == 0 && o.f[2] == 0);
  assert_true(fabs(o.k[4] + 150) < 1e-12 && o.k[0] == 0 && o.k[8] == 0);
  c[1] = 0.01; // backed out 9 mm: the carried force would pull
  tx_organ_force(&t, 1, &r, 100, 0.02, c, &o);
  assert_true(o.kind == TX_ORGAN_FORCE_NONE && o.f[1] == 0);
  c[1] = -0.05; // 51 mm deeper: held at depth_max, K = 0
  tx_organ_force(&t, 1, &r, 100, 0.02, c, &o);
  assert_true(fabs(o.f[1] - (0.5 + 150 * 0.02)) < 1e-12 && o.k[4] == 0);
  // the physics not touching yet: the penalty
  r.touching = 0;
  c[1] = -0.001;
  tx_organ_force(&t, 1, &r, 100, 0.02, c, &o);
  assert_true(o.kind == TX_ORGAN_FORCE_PENALTY && fabs(o.f[1] - 0.1) < 1e-12);
  // no geometric contact: nothing, whatever the physics says
  r.touching = 1;
  t.on = false;
  tx_organ_force(&t, 1, &r, 100, 0.02, c, &o);
  assert_true(o.kind == TX_ORGAN_FORCE_NONE && o.f[1] == 0);
  // two organs touching, no reaction: the penalties add
  tx_organ_touch two[2] = {{.on = true, .depth = 1e-3, .n = {0, 1, 0}}, {.on = true, .depth = 2e-3, .n = {1, 0, 0}}};
  tx_organ_force(two, 2, NULL, 100, 0.02, c, &o);
  assert_true(fabs(o.f[0] - 0.2) < 1e-12 && fabs(o.f[1] - 0.1) < 1e-12);
  assert_true(fabs(o.k[0] + 100) < 1e-12 && fabs(o.k[4] + 100) < 1e-12);
}

static void test_query_and_refit_allocate_nothing(void** state) {
  (void)state;
  fixture* f = sphere(4);
  tx_organ_tip_def d = tip_def();
  tx_organ_side side;
  tx_organ_side_reset(&side);
  tx_skin_contact r = {.f = {0, 0.5, 0}, .x = {0, 0.001, 0}, .n = {0, 1, 0}, .k = 150, .touching = 1};
  double u[3] = {0, 1, 0};
  counting = 1;
  for (int i = 0; i < 100; i++) {
    double c[3];
    along(u, R + 3e-3 - 1e-4 * i, c);
    tx_organ_touch t;
    tx_organ_tip(&side, &d, &f->b, f->s.x, c, &t);
    tx_organ_force_out o;
    tx_organ_force(&t, 1, i % 2 ? &r : NULL, 100, d.depth_max, c, &o);
    if (i % 10 == 0) tx_tri_bvh_refit(&f->b, f->s.x);
  }
  counting = 0;
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
  drop(f);
}

// the committed liver: the BVH's nearest point is the brute-force one, and the
// side agrees with the winding number (inside: 1, outside: 0)
static void test_committed_liver(void** state) {
  (void)state;
#if TX_WITH_ASSIMP
  tx_mesh m;
  assert_true(tx_mesh_load(TX_SOURCE_DIR "/assets/lagb/liver.obj", &m));
  shape s = {malloc(sizeof(float) * 3 * m.nvertices), malloc(sizeof(int32_t) * 3 * m.ntriangles),
             (uint32_t)m.nvertices, (uint32_t)m.ntriangles};
  for (int i = 0; i < 3 * m.nvertices; i++) s.x[i] = (float)m.vertices[i];
  for (int i = 0; i < 3 * m.ntriangles; i++) s.tri[i] = m.triangles[i];
  tx_mesh_free(&m);
  assert_int_equal(s.ntri, 2484);
  tx_tri_bvh b;
  assert_int_equal(tx_tri_bvh_init(&b, s.ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&b, s.x, s.nx, s.tri, s.ntri), 0);
  srand(11);
  int checked = 0, inside = 0;
  for (int i = 0; i < 300; i++) {
    // near a random vertex, up to 1 cm off
    const float* v = s.x + 3 * (rand() % s.nx);
    double c[3];
    for (int a = 0; a < 3; a++) c[a] = v[a] + (rand() / (double)RAND_MAX - 0.5) * 0.02;
    tx_organ_near n;
    if (!tx_organ_nearest(&b, s.x, c, 0.02, NULL, &n)) continue;
    assert_true(fabs(fabs(n.s) - brute(&s, c)) < 1e-9);
    // the winding number by the solid angles (van Oosterom and Strackee)
    double w = 0;
    for (uint32_t t = 0; t < s.ntri; t++) {
      double p[3][3], l[3];
      for (int k = 0; k < 3; k++) {
        for (int a = 0; a < 3; a++) p[k][a] = s.x[3 * s.tri[3 * t + k] + a] - c[a];
        l[k] = sqrt(dot3(p[k], p[k]));
      }
      double cr[3] = {p[1][1] * p[2][2] - p[1][2] * p[2][1], p[1][2] * p[2][0] - p[1][0] * p[2][2],
                      p[1][0] * p[2][1] - p[1][1] * p[2][0]};
      double num = dot3(p[0], cr);
      double den = l[0] * l[1] * l[2] + dot3(p[0], p[1]) * l[2] + dot3(p[0], p[2]) * l[1] + dot3(p[1], p[2]) * l[0];
      w += 2 * atan2(num, den);
    }
    w /= 4 * M_PI;
    if (fabs(n.s) < 1e-6) continue; // on the surface: either side
    assert_true(n.s < 0 ? fabs(w - 1) < 1e-3 : fabs(w) < 1e-3);
    inside += n.s < 0;
    checked++;
  }
  assert_true(checked > 250 && inside > 50 && inside < checked - 50);
  tx_tri_bvh_free(&b);
  shape_free(&s);
#else
  skip();
#endif
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_nearest_on_a_sphere),
      cmocka_unit_test(test_def_checked),
      cmocka_unit_test(test_force_points_out_and_grows),
      cmocka_unit_test(test_inside_unentered_gets_nothing),
      cmocka_unit_test(test_thin_organ_is_one_sided),
      cmocka_unit_test(test_fast_entry_is_caught),
      cmocka_unit_test(test_refit_moves_the_contact),
      cmocka_unit_test(test_reaction_is_carried),
      cmocka_unit_test(test_query_and_refit_allocate_nothing),
      cmocka_unit_test(test_committed_liver),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
