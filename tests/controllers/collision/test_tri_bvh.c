// The triangle BVH: ray hits against brute force on a flat and a dented skin,
// refit against rebuild, bad triangle sets refused, and the cost of a query
// (nodes visited) that stays put while the mesh grows a hundredfold.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/physics/skin_grid.h"
#include "studies/experiments/skin_dent.h"
#include "controllers/collision/tri_bvh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct mesh {
  uint32_t n, ntri;
  float* x;
  int32_t* tri;
} mesh;

static mesh make(uint32_t n, double spacing) {
  mesh m = {n, 0, malloc(sizeof(float) * 3 * n * n), malloc(sizeof(int32_t) * 6 * (n - 1) * (n - 1))};
  assert_non_null(m.x);
  assert_non_null(m.tri);
  m.ntri = tx_skin_grid((int)n, (int)n, spacing, spacing, (double[3]){0, 0, 0}, m.x, m.tri);
  return m;
}

static void drop(mesh* m) {
  free(m->x);
  free(m->tri);
}

// nearest hit over every triangle: what the tree must agree with
static double brute(const mesh* m, const double o[3], const double d[3], double tmax) {
  tx_tri_bvh one;
  double best = -1;
  assert_int_equal(tx_tri_bvh_init(&one, 1), 0);
  for (uint32_t i = 0; i < m->ntri; i++) {
    assert_int_equal(tx_tri_bvh_build(&one, m->x, m->n * m->n, m->tri + 3 * i, 1), 0);
    tx_ray_hit h;
    if (tx_tri_bvh_ray(&one, m->x, o, d, tmax, &h) && (best < 0 || h.t < best)) best = h.t;
  }
  tx_tri_bvh_free(&one);
  return best;
}

static void compare_rays(tx_tri_bvh* b, const mesh* m) {
  srand(7);
  for (int i = 0; i < 200; i++) {
    double o[3] = {(rand() / (double)RAND_MAX - 0.5) * 0.02, (rand() / (double)RAND_MAX - 0.5) * 0.01,
                   (rand() / (double)RAND_MAX - 0.5) * 0.02};
    double d[3] = {rand() / (double)RAND_MAX - 0.5, rand() / (double)RAND_MAX - 0.5, rand() / (double)RAND_MAX - 0.5};
    double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int a = 0; a < 3; a++) d[a] /= l;
    tx_ray_hit h;
    double want = brute(m, o, d, 0.02);
    bool got = tx_tri_bvh_ray(b, m->x, o, d, 0.02, &h);
    assert_int_equal(got, want >= 0);
    if (got) assert_true(fabs(h.t - want) < 1e-9);
  }
}

static void test_hits_match_brute_force_flat_and_dented(void** state) {
  (void)state;
  mesh m = make(21, 0.001);
  tx_tri_bvh b;
  assert_int_equal(tx_tri_bvh_init(&b, m.ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&b, m.x, m.n * m.n, m.tri, m.ntri), 0);
  compare_rays(&b, &m);
  // the same tree refitted to a dented skin answers as a brute force on it
  tx_skin_dent(m.x, m.n * m.n, (double[3]){0.001, 0, -0.002}, 0.003, 0.003);
  tx_tri_bvh_refit(&b, m.x);
  compare_rays(&b, &m);
  // a straight-down ray onto the dent's centre meets it at the dent's depth
  tx_ray_hit h;
  assert_true(tx_tri_bvh_ray(&b, m.x, (double[3]){0.001, 0.01, -0.002}, (double[3]){0, -1, 0}, 1, &h));
  assert_true(fabs(h.t - 0.013) < 1e-6);
  assert_true(h.n[1] > 0.8); // the grid's winding faces up; the dent tilts it a little
  tx_tri_bvh_free(&b);
  drop(&m);
}

// a refit spread over several calls, on a copy of the tree, ends where one whole refit does
static void test_split_refit_on_a_copy(void** state) {
  (void)state;
  mesh m = make(31, 0.001);
  tx_tri_bvh a, b;
  assert_int_equal(tx_tri_bvh_init(&a, m.ntri), 0);
  assert_int_equal(tx_tri_bvh_init(&b, m.ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&a, m.x, m.n * m.n, m.tri, m.ntri), 0);
  assert_int_equal(tx_tri_bvh_copy(&b, &a), 0);
  assert_true(tx_tri_bvh_same(&b, m.tri, m.ntri));
  tx_skin_dent(m.x, m.n * m.n, (double[3]){0.002, 0, 0.001}, 0.004, 0.004);
  tx_tri_bvh_refit(&a, m.x);
  for (uint32_t to = b.nnodes; to > 0;) { // in slices of 97 nodes, last first
    uint32_t from = to > 97 ? to - 97 : 0;
    tx_tri_bvh_refit_nodes(&b, m.x, from, to);
    to = from;
  }
  assert_int_equal(a.nnodes, b.nnodes);
  assert_memory_equal(a.nodes, b.nodes, a.nnodes * sizeof *a.nodes);
  tx_tri_bvh_free(&a);
  tx_tri_bvh_free(&b);
  drop(&m);
}

// torn triangles (rows gone, the rest in order) emptied in place answer as a tree built
// on what is left; a reordered array is refused
static void test_removed_triangles(void** state) {
  (void)state;
  mesh m = make(21, 0.001);
  tx_tri_bvh b;
  assert_int_equal(tx_tri_bvh_init(&b, m.ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&b, m.x, m.n * m.n, m.tri, m.ntri), 0);
  for (int round = 0; round < 2; round++) { // two tears in a row
    uint32_t kept = 0;
    for (uint32_t t = 0; t < m.ntri; t++)
      if (t % (5 + round) != 2) memmove(m.tri + 3 * kept++, m.tri + 3 * t, 3 * sizeof *m.tri);
    m.ntri = kept;
    assert_int_equal(tx_tri_bvh_remove(&b, m.tri, m.ntri), 0);
    assert_true(tx_tri_bvh_same(&b, m.tri, m.ntri));
    tx_skin_dent(m.x, m.n * m.n, (double[3]){0, 0, 0}, 0.001, 0.003);
    tx_tri_bvh_refit(&b, m.x);
    compare_rays(&b, &m);
  }
  int32_t swapped[6];
  memcpy(swapped, m.tri + 3, 3 * sizeof *m.tri);
  memcpy(swapped + 3, m.tri, 3 * sizeof *m.tri);
  assert_int_equal(tx_tri_bvh_remove(&b, swapped, 2), -1);
  tx_tri_bvh_free(&b);
  drop(&m);
}

static void test_bad_sets_refused(void** state) {
  (void)state;
  mesh m = make(5, 0.001);
  tx_tri_bvh b;
  assert_int_equal(tx_tri_bvh_init(&b, 4), 0);
  assert_int_equal(tx_tri_bvh_build(&b, m.x, 25, m.tri, m.ntri), -1); // more than its capacity
  int32_t bad[3] = {0, 1, 25};
  assert_int_equal(tx_tri_bvh_build(&b, m.x, 25, bad, 1), -1); // a vertex past the particles
  bad[2] = -1;
  assert_int_equal(tx_tri_bvh_build(&b, m.x, 25, bad, 1), -1);
  tx_tri_bvh_free(&b);
  drop(&m);
}

// nodes one query visits: a fan of 98 short rays from just above the middle
static uint64_t query_nodes(uint32_t n) {
  mesh m = make(n, 0.001);
  tx_tri_bvh b;
  assert_int_equal(tx_tri_bvh_init(&b, m.ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&b, m.x, n * n, m.tri, m.ntri), 0);
  b.visited = 0;
  int hits = 0;
  for (int i = -2; i <= 2; i++)
    for (int j = -2; j <= 2; j++)
      for (int k = -2; k <= 2; k++) {
        if (abs(i) != 2 && abs(j) != 2 && abs(k) != 2) continue;
        double l = sqrt((double)(i * i + j * j + k * k)), d[3] = {i / l, j / l, k / l};
        tx_ray_hit h;
        hits += tx_tri_bvh_ray(&b, m.x, (double[3]){0.0003, 0.002, 0.0002}, d, 0.003, &h);
      }
  assert_true(hits > 0);
  uint64_t v = b.visited;
  tx_tri_bvh_free(&b);
  drop(&m);
  return v;
}

static void test_query_cost_independent_of_far_triangles(void** state) {
  (void)state;
  uint64_t small = query_nodes(21);  // 800 triangles
  uint64_t large = query_nodes(201); // 80000 triangles
  // a hundred times the triangles, only a few more levels of tree to descend
  assert_true(large < 3 * small);
  assert_true(large < 98 * 64); // and far below visiting even one node per triangle
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_hits_match_brute_force_flat_and_dented),
      cmocka_unit_test(test_split_refit_on_a_copy),
      cmocka_unit_test(test_removed_triangles),
      cmocka_unit_test(test_bad_sets_refused),
      cmocka_unit_test(test_query_cost_independent_of_far_triangles),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
