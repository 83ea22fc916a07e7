// Removal of tetrahedra (controllers/organs/removal.h, and tx_fem_remove_tet
// in bullet/fem.h) on structured blocks: the block mesh is positive and
// fills its box; a surface made of the boundary faces is closed, and each
// kind of defect is counted; removing tetrahedra one by one at random keeps
// the boundary equal to the live tetrahedra's (found afresh each time),
// closed, outward (its enclosed volume is theirs) and the body finite and
// uninverted, in both models; a node left in no tetrahedron stops moving and
// stops being kinematic; removal allocates nothing.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/organs/bullet/fem.h"
#include "controllers/organs/removal.h"

#include "tests/alloc_count.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct block {
  double* x;
  int* tet;
  int nv, ne;
} block;

static block make_block(int nx, int ny, int nz, double h) {
  block b;
  assert_true(tx_block_mesh(nx, ny, nz, h, &b.x, &b.nv, &b.tet, &b.ne));
  return b;
}

static double vol6(const double* a, const double* b, const double* c, const double* d) {
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = d[k] - a[k];
  return u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

// the volume a closed outward surface encloses, from the origin's cones
static double enclosed(const int* f, int nf, const double* x) {
  const double o[3] = {0, 0, 0};
  double v = 0;
  for (int i = 0; i < nf; i++) v += vol6(o, x + 3 * f[3 * i], x + 3 * f[3 * i + 1], x + 3 * f[3 * i + 2]) / 6;
  return v;
}

static void test_block_mesh(void** state) {
  (void)state;
  block b = make_block(3, 2, 4, 0.01);
  assert_int_equal(b.nv, 4 * 3 * 5);
  assert_int_equal(b.ne, 6 * 24);
  double total = 0;
  for (int e = 0; e < b.ne; e++) {
    const int* t = b.tet + 4 * e;
    double v = vol6(b.x + 3 * t[0], b.x + 3 * t[1], b.x + 3 * t[2], b.x + 3 * t[3]) / 6;
    assert_true(v > 0);
    total += v;
  }
  assert_true(fabs(total - 24e-6) < 1e-15);
  // its boundary (Bullet's body builds it) is the box's: 2 triangles a square
  tx_fem_def d = tx_fem_def_default();
  tx_fem* f = tx_fem_create(&d, b.x, b.nv, b.tet, b.ne);
  assert_non_null(f);
  int nf;
  const int* hull = tx_fem_hull(f, &nf);
  assert_int_equal(nf, 4 * (3 * 2 + 2 * 4 + 3 * 4));
  assert_true(fabs(enclosed(hull, nf, b.x) - 24e-6) < 1e-15);
  tx_fem_destroy(f);
  double* x;
  int* t;
  int nv, ne;
  assert_false(tx_block_mesh(0, 1, 1, 0.01, &x, &nv, &t, &ne));
  assert_false(tx_block_mesh(1, 1, 1, -1, &x, &nv, &t, &ne));
  free(b.x), free(b.tet);
}

static void test_surface_check(void** state) {
  (void)state;
  block b = make_block(2, 2, 2, 0.01);
  tx_fem_def d = tx_fem_def_default();
  tx_fem* f = tx_fem_create(&d, b.x, b.nv, b.tet, b.ne);
  int nf;
  const int* hull = tx_fem_hull(f, &nf);
  int32_t *row_of = malloc(sizeof(int32_t) * (size_t)b.nv), *node_of = malloc(sizeof(int32_t) * (size_t)b.nv);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * (size_t)(nf + 1));
  uint64_t* keys = malloc(sizeof(uint64_t) * 3 * (size_t)(nf + 1));
  int32_t* seen = malloc(sizeof(int32_t) * (size_t)b.nv);
  for (int i = 0; i < b.nv; i++) row_of[i] = -1;
  int rows = tx_compact_surface(hull, nf, row_of, node_of, tri);
  assert_int_equal(rows, b.nv - 1); // every node but the centre
  for (int i = 0; i < b.nv; i++) assert_int_equal(row_of[i], -1);
  for (int i = 0; i < 3 * nf; i++) assert_int_equal(node_of[tri[i]], hull[i]);
  tx_surface_report r;
  assert_true(tx_surface_check(tri, nf, rows, node_of, b.nv, keys, seen, &r));
  assert_int_equal(r.edges, 3 * nf / 2);
  assert_int_equal(r.nonmanifold_edges, 0);
  assert_int_equal(rows - r.edges + nf, 2); // a sphere's Euler characteristic
  // a face left out: its three edges open
  assert_false(tx_surface_check(tri + 3, nf - 1, rows, node_of, b.nv, keys, seen, &r));
  assert_int_equal(r.open_edges, 3);
  // a face turned over: its edges run twice one way
  int32_t w = tri[1];
  tri[1] = tri[2], tri[2] = w;
  assert_false(tx_surface_check(tri, nf, rows, node_of, b.nv, keys, seen, &r));
  assert_int_equal(r.open_edges, 3);
  tri[2] = tri[1], tri[1] = w;
  // a row nobody names, a row past the end, a doubled node, a degenerate face
  assert_false(tx_surface_check(tri, nf, rows + 1, NULL, 0, keys, seen, &r));
  assert_int_equal(r.unreferenced, 1);
  tri[3 * nf] = 0, tri[3 * nf + 1] = 1, tri[3 * nf + 2] = rows;
  assert_false(tx_surface_check(tri, nf + 1, rows, NULL, 0, keys, seen, &r));
  assert_int_equal(r.out_of_range, 1);
  int32_t keep = node_of[1];
  node_of[1] = node_of[0];
  assert_false(tx_surface_check(tri, nf, rows, node_of, b.nv, keys, seen, &r));
  assert_int_equal(r.doubled, 1);
  node_of[1] = keep;
  keep = tri[0];
  tri[0] = tri[1];
  assert_false(tx_surface_check(tri, nf, rows, node_of, b.nv, keys, seen, &r));
  assert_int_equal(r.degenerate, 1);
  tri[0] = keep;
  assert_true(tx_surface_check(tri, nf, rows, node_of, b.nv, keys, seen, &r));
  free(row_of), free(node_of), free(tri), free(keys), free(seen);
  tx_fem_destroy(f);
  free(b.x), free(b.tet);
}

static void remove_at_random(tx_fem_model model) {
  block b = make_block(3, 3, 3, 0.01);
  tx_fem_def d = tx_fem_def_default();
  d.model = model, d.damping = 50, d.gravity[1] = -9.81, d.mass_scaling = model != TX_FEM_LINKS;
  if (model == TX_FEM_LINKS) d.dt = 1e-3;
  tx_fem* f = tx_fem_create(&d, b.x, b.nv, b.tet, b.ne);
  assert_non_null(f);
  for (int i = 0; i < b.nv; i++)
    if (b.x[3 * i + 1] < 1e-9) tx_fem_fix(f, i);
  int* order = malloc(sizeof(int) * (size_t)b.ne);
  for (int e = 0; e < b.ne; e++) order[e] = e;
  uint64_t s = 12345;
  for (int e = b.ne - 1; e > 0; e--) {
    s = s * 6364136223846793005u + 1442695040888963407u;
    int j = (int)((s >> 33) % (uint64_t)(e + 1)), w = order[e];
    order[e] = order[j], order[j] = w;
  }
  int32_t *row_of = malloc(sizeof(int32_t) * (size_t)b.nv), *node_of = malloc(sizeof(int32_t) * (size_t)b.nv);
  int32_t* tri = malloc(sizeof(int32_t) * 12 * (size_t)b.ne);
  uint64_t* keys = malloc(sizeof(uint64_t) * 12 * (size_t)b.ne);
  int32_t* seen = malloc(sizeof(int32_t) * (size_t)b.nv);
  double* x = malloc(sizeof(double) * 3 * (size_t)b.nv);
  for (int i = 0; i < b.nv; i++) row_of[i] = -1;
  int nonmanifold = 0;
  for (int r = 0; r < b.ne; r++) {
    int e = order[r];
    bool last = r == b.ne - 1;
    assert_true(tx_fem_remove_tet(f, e) == !last); // the last one stays
    assert_false(tx_fem_remove_tet(f, e) && !last);
    assert_int_equal(tx_fem_live_tet_count(f), last ? 1 : b.ne - r - 1);
    assert_true(tx_fem_step(f, 5));
    // the boundary: the live tetrahedra's, closed and outward
    assert_true(tx_fem_hull_is_live_boundary(f));
    int nf;
    const int* hull = tx_fem_hull(f, &nf);
    double live = 0;
    for (int t = 0; t < b.ne; t++)
      if (tx_fem_tet_live(f, t)) live += vol6(b.x + 3 * b.tet[4 * t], b.x + 3 * b.tet[4 * t + 1], b.x + 3 * b.tet[4 * t + 2], b.x + 3 * b.tet[4 * t + 3]) / 6;
    assert_true(fabs(enclosed(hull, nf, b.x) - live) < 1e-12);
    int rows = tx_compact_surface(hull, nf, row_of, node_of, tri);
    tx_surface_report rep;
    assert_true(tx_surface_check(tri, nf, rows, node_of, b.nv, keys, seen, &rep));
    nonmanifold += rep.nonmanifold_edges > 0;
    for (int i = 0; i < rows; i++) assert_true(tx_fem_node_live(f, node_of[i]));
    // finite, nothing inverted
    tx_fem_positions(f, x);
    for (int i = 0; i < 3 * b.nv; i++) assert_true(isfinite(x[i]));
    for (int t = 0; t < b.ne; t++)
      if (tx_fem_tet_live(f, t)) assert_true(tx_fem_tet_volume(f, t) > 0);
      else assert_true(tx_fem_tet_volume(f, t) == 0);
  }
  print_message("  %s: %d removals, the boundary checked after each; %d of them with tetrahedra meeting at an edge only\n",
                model == TX_FEM_LINKS ? "links" : "fem", b.ne - 1, nonmanifold);
  assert_false(tx_fem_remove_tet(f, -1));
  assert_false(tx_fem_remove_tet(f, b.ne));
  free(order), free(row_of), free(node_of), free(tri), free(keys), free(seen), free(x);
  tx_fem_destroy(f);
  free(b.x), free(b.tet);
}

static void test_remove_fem(void** state) {
  (void)state;
  remove_at_random(TX_FEM_NEOHOOKEAN);
}
static void test_remove_links(void** state) {
  (void)state;
  remove_at_random(TX_FEM_LINKS);
}

// a block held at its base, under gravity: every tetrahedron at the top
// layer's nodes removed, those nodes leave the solve (they stay where they
// were, a kinematic one is let go) while the rest sags under its weight;
// removing allocates nothing
static void test_removed_nodes_stop(void** state) {
  (void)state;
  tx_fem_model models[] = {TX_FEM_COROTATED, TX_FEM_LINKS};
  for (int mi = 0; mi < 2; mi++) {
    block b = make_block(2, 3, 2, 0.01);
    tx_fem_def d = tx_fem_def_default();
    d.model = models[mi], d.damping = 20, d.gravity[1] = -9.81, d.mass_scaling = mi == 0;
    if (mi == 1) d.dt = 1e-3;
    tx_fem* f = tx_fem_create(&d, b.x, b.nv, b.tet, b.ne);
    for (int i = 0; i < b.nv; i++)
      if (b.x[3 * i + 1] < 1e-9) tx_fem_fix(f, i);
    int top = -1;
    for (int i = 0; i < b.nv; i++)
      if (b.x[3 * i + 1] > 0.03 - 1e-9) top = i;
    double p[3] = {b.x[3 * top], b.x[3 * top + 1], b.x[3 * top + 2]};
    tx_fem_set_kinematic(f, top, p);
    assert_true(tx_fem_is_kinematic(f, top));
    long allocs = 0;
    for (int e = 0; e < b.ne; e++) {
      bool up = false;
      for (int k = 0; k < 4; k++) up = up || b.x[3 * b.tet[4 * e + k] + 1] > 0.03 - 1e-9;
      if (!up) continue;
      counting = 1, allocations = 0;
      assert_true(tx_fem_remove_tet(f, e));
      counting = 0, allocs += allocations;
    }
#ifndef TX_NO_ALLOC_COUNT
    assert_int_equal(allocs, 0);
#endif
    assert_false(tx_fem_is_kinematic(f, top));
    double *x = malloc(sizeof(double) * 3 * (size_t)b.nv), *x0 = malloc(sizeof(double) * 3 * (size_t)b.nv);
    tx_fem_positions(f, x0);
    assert_true(tx_fem_step(f, mi == 0 ? 2000 : 300));
    tx_fem_positions(f, x);
    double sag = 0;
    for (int i = 0; i < b.nv; i++) {
      bool gone = b.x[3 * i + 1] > 0.03 - 1e-9;
      assert_true(tx_fem_node_live(f, i) == !gone);
      for (int a = 0; a < 3; a++)
        if (gone) assert_true(x[3 * i + a] == x0[3 * i + a]);
      sag = fmax(sag, b.x[3 * i + 1] - x[3 * i + 1]);
    }
    print_message("  %s: the block's top layer removed, %d tetrahedra left, sagging %.3g mm\n", mi == 0 ? "fem" : "links",
                  tx_fem_live_tet_count(f), sag * 1e3);
    assert_true(sag > 1e-7);
    for (int t = 0; t < b.ne; t++)
      if (tx_fem_tet_live(f, t)) assert_true(tx_fem_tet_volume(f, t) > 0);
    free(x), free(x0);
    tx_fem_destroy(f);
    free(b.x), free(b.tet);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_block_mesh),  cmocka_unit_test(test_surface_check),      cmocka_unit_test(test_remove_fem),
      cmocka_unit_test(test_remove_links), cmocka_unit_test(test_removed_nodes_stop),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
