// The organ-hemisphere pieces on answers known in closed form: the mesh's
// counts, its base, pole and sphere, every tetrahedron positive, each inner
// face shared by two tetrahedra and the boundary closed, and its volume
// converging to 2/3 pi R^3 at second order; Hertz's force at the numbers of
// its formula; Richardson's order and limit on f(h) = 1 + 3 h^2.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "studies/experiments/organ_hemisphere.h"

#include <tactus/model.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double tet_volume(const tx_hemisphere_mesh* m, int t) {
  const int* e = m->e + 4 * t;
  const double *a = m->v + 3 * e[0], *b = m->v + 3 * e[1], *c = m->v + 3 * e[2], *d = m->v + 3 * e[3];
  double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
         ad[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (ab[0] * (ac[1] * ad[2] - ac[2] * ad[1]) + ab[1] * (ac[2] * ad[0] - ac[0] * ad[2]) +
          ab[2] * (ac[0] * ad[1] - ac[1] * ad[0])) /
         6.0;
}

static double volume(const tx_hemisphere_mesh* m) {
  double v = 0;
  for (int t = 0; t < m->ne; t++) v += tet_volume(m, t);
  return v;
}

static void test_counts_base_pole_sphere(void** state) {
  (void)state;
  const double R = 0.02;
  for (int n = 1; n <= 4; n++) {
    tx_hemisphere_mesh m;
    assert_true(tx_hemisphere_build(R, n, &m));
    assert_int_equal(m.nv, (2 * n + 1) * (2 * n + 1) * (n + 1));
    assert_int_equal(m.ne, 24 * n * n * n);
    assert_true(fabs(m.v[3 * m.pole]) < 1e-15 && fabs(m.v[3 * m.pole + 1] - R) < 1e-15 &&
                fabs(m.v[3 * m.pole + 2]) < 1e-15);
    int base = 0, on_sphere = 0;
    for (int i = 0; i < m.nv; i++) {
      const double* p = m.v + 3 * i;
      double r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      assert_true(r <= R * (1 + 1e-12));
      if (m.base[i]) {
        base++;
        assert_true(p[1] == 0);
      }
      on_sphere += fabs(r - R) < 1e-12 * R;
    }
    assert_int_equal(base, (2 * n + 1) * (2 * n + 1));
    // the cube's top and four sides, less the base rim counted twice: all on the sphere
    int top = (2 * n + 1) * (2 * n + 1), sides = 4 * 2 * n * n;
    assert_int_equal(on_sphere, top + sides);
    for (int t = 0; t < m.ne; t++) assert_true(tet_volume(&m, t) > 0);
    tx_hemisphere_free(&m);
  }
}

// each face as its sorted nodes; inner faces twice, boundary faces once
static int cmp3(const void* a, const void* b) {
  const int *p = a, *q = b;
  for (int k = 0; k < 3; k++)
    if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
  return 0;
}

static void test_conforming(void** state) {
  (void)state;
  tx_hemisphere_mesh m;
  assert_true(tx_hemisphere_build(1.0, 3, &m));
  int* f = malloc((size_t)m.ne * 4 * 3 * sizeof(int));
  assert_non_null(f);
  static const int opp[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (int t = 0; t < m.ne; t++)
    for (int s = 0; s < 4; s++) {
      int* g = f + 3 * (4 * t + s);
      for (int k = 0; k < 3; k++) g[k] = m.e[4 * t + opp[s][k]];
      // the three nodes in order
      if (g[0] > g[1]) { int x = g[0]; g[0] = g[1]; g[1] = x; }
      if (g[1] > g[2]) { int x = g[1]; g[1] = g[2]; g[2] = x; }
      if (g[0] > g[1]) { int x = g[0]; g[0] = g[1]; g[1] = x; }
    }
  qsort(f, (size_t)m.ne * 4, 3 * sizeof(int), cmp3);
  int once = 0, twice = 0;
  for (int i = 0; i < m.ne * 4;) {
    int j = i;
    while (j < m.ne * 4 && cmp3(f + 3 * i, f + 3 * j) == 0) j++;
    assert_true(j - i <= 2);
    if (j - i == 1) once++;
    else twice++;
    i = j;
  }
  // the boundary: 2 triangles per cell face on the cube's top, four sides and base
  int n = 3, cells = 4 * n * n + 4 * 2 * n * n + 4 * n * n;
  assert_int_equal(once, 2 * cells);
  assert_int_equal(once + 2 * twice, 4 * m.ne);
  free(f);
  tx_hemisphere_free(&m);
}

static void test_volume_converges(void** state) {
  (void)state;
  const double R = 0.02, exact = 2.0 / 3.0 * M_PI * R * R * R;
  double v[3];
  const int ns[3] = {4, 8, 16};
  for (int l = 0; l < 3; l++) {
    tx_hemisphere_mesh m;
    assert_true(tx_hemisphere_build(R, ns[l], &m));
    v[l] = volume(&m);
    tx_hemisphere_free(&m);
  }
  // chords below the sphere: too small, less so at each refinement
  assert_true(v[0] < v[1] && v[1] < v[2] && v[2] < exact);
  assert_true((exact - v[1]) / exact < 0.01);
  double p = tx_observed_order(v[0], v[1], v[2], 2);
  assert_true(p > 1.8 && p < 2.2);
  double extrapolated = tx_richardson(v[1], v[2], 2, p);
  assert_true(fabs(extrapolated - exact) < 0.1 * fabs(v[2] - exact));
}

static void test_hertz(void** state) {
  (void)state;
  // nu = 0.5: (16/9) E sqrt(R) d^(3/2)
  double f = tx_hertz_force(5e3, 0.5, 0.02, 0.002);
  assert_true(fabs(f - 16.0 / 9.0 * 5e3 * sqrt(0.02) * pow(0.002, 1.5)) < 1e-15);
  assert_true(fabs(f - 0.1124365) < 1e-6); // N
  // nu = 0: (4/3) E sqrt(R) d^(3/2)
  assert_true(fabs(tx_hertz_force(3.0, 0.0, 4.0, 1.0) - 8.0) < 1e-12);
  assert_true(tx_hertz_force(5e3, 0.5, 0.02, 0) == 0);
  assert_true(tx_hertz_force(5e3, 0.5, 0.02, -1e-3) == 0);
  assert_true(fabs(tx_hertz_contact_radius(0.02, 0.002) - sqrt(0.02 * 0.002)) < 1e-15);
}

static void test_richardson(void** state) {
  (void)state;
  double f[3];
  for (int l = 0; l < 3; l++) {
    double h = 0.4 / (1 << l);
    f[l] = 1 + 3 * h * h;
  }
  assert_true(fabs(tx_observed_order(f[0], f[1], f[2], 2) - 2) < 1e-12);
  assert_true(fabs(tx_richardson(f[1], f[2], 2, 2) - 1) < 1e-12);
  // differences that grow, or change sign: no order
  assert_true(isnan(tx_observed_order(1, 1.1, 1.3, 2)));
  assert_true(isnan(tx_observed_order(1, 1.1, 1.05, 2)));
}

static void test_bad_arguments(void** state) {
  (void)state;
  tx_hemisphere_mesh m;
  assert_false(tx_hemisphere_build(0.02, 0, &m));
  assert_non_null(strstr(tx_error(), "cells"));
  assert_false(tx_hemisphere_build(-1, 4, &m));
  assert_false(tx_hemisphere_build(NAN, 4, &m));
  assert_null(m.v);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_counts_base_pole_sphere), cmocka_unit_test(test_conforming),
      cmocka_unit_test(test_volume_converges),        cmocka_unit_test(test_hertz),
      cmocka_unit_test(test_richardson),              cmocka_unit_test(test_bad_arguments),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
