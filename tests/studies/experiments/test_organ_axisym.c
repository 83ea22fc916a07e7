// The hemisphere's axisymmetric continuum reference on answers known in
// closed form: the banded Cholesky solve against a tridiagonal system's exact
// solution; Hertz's force recovered as d/R -> 0 (a finite body's correction
// vanishes there), the hemisphere stiffer than Hertz's half space and more so
// deeper; the force converged under refinement; bad arguments refused.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "studies/experiments/organ_axisym.h"
#include "studies/experiments/organ_hemisphere.h"

#include <math.h>
#include <stdlib.h>

// -x_{i-1} + 2 x_i - x_{i+1} = b_i with x = i (i + 1): b_i = -2 inside, the ends' neighbours 0
static void test_band_cholesky(void** state) {
  (void)state;
  enum { N = 50, KD = 3 };
  double a[N * (KD + 1)] = {0}, b[N];
  for (int i = 0; i < N; i++) {
    a[i * (KD + 1) + KD] = 2;
    if (i > 0) a[i * (KD + 1) + KD - 1] = -1;
  }
  for (int i = 0; i < N; i++) {
    double x = i * (i + 1.0), xm = i > 0 ? (i - 1) * (double)i : 0, xp = i < N - 1 ? (i + 1) * (i + 2.0) : 0;
    b[i] = 2 * x - xm - xp;
  }
  assert_true(tx_band_cholesky(a, N, KD));
  tx_band_solve(a, N, KD, b);
  for (int i = 0; i < N; i++) assert_true(fabs(b[i] - i * (i + 1.0)) < 1e-9 * (1 + i * i));
  // not positive definite
  double z[4 * (KD + 1)] = {0};
  z[KD] = 1, z[(KD + 1) + KD] = -1;
  assert_false(tx_band_cholesky(z, 4, KD));
}

static void test_hertz_limit_and_finite_body(void** state) {
  (void)state;
  const double R = 0.02, E = 5e3, nu = 0.45;
  tx_axisym* a = tx_axisym_create(R, E, nu, 16, 2);
  assert_non_null(a);
  double f = 0, prev = 0;
  const double dr[] = {0.0005, 0.003, 0.02, 0.1};
  for (int i = 0; i < 4; i++) {
    assert_true(tx_axisym_indent(a, dr[i] * R, 0, &f));
    double ratio = f / tx_hertz_force(E, nu, R, dr[i] * R);
    if (i == 0) assert_true(fabs(ratio - 1) < 0.05);  // Hertz's half space, d/R -> 0
    assert_true(ratio > prev);                        // the fixed base stiffens it more the deeper
    assert_true(ratio - 1 < 1.2 * sqrt(dr[i]));       // and by the order of sqrt(d/R) (its base's pull)
    prev = ratio;
    assert_true(tx_axisym_contact_nodes(a) >= 2);
    // the pole is at the flat, never through it (contact is on nodes: the
    // axis node may sink a little under its neighbours' pressure)
    double pole = tx_axisym_surface_uz(a, 0);
    assert_true(pole <= -dr[i] * R * (1 - 1e-9) && pole > -1.15 * dr[i] * R);
    // the base rim does not move; the surface sinks less away from the pole
    assert_true(fabs(tx_axisym_surface_uz(a, M_PI / 2)) < 1e-15);
    assert_true(tx_axisym_surface_uz(a, 0.5) > pole && tx_axisym_surface_uz(a, 0.5) < 0);
  }
  tx_axisym_destroy(a);
  // converged: twice the elements change the force at d/R = 0.1 by under 1 %
  double f8 = 0, f16 = 0;
  tx_axisym* c = tx_axisym_create(R, E, nu, 8, 2);
  tx_axisym* d = tx_axisym_create(R, E, nu, 16, 2);
  assert_true(c && d && tx_axisym_indent(c, 0.1 * R, 0, &f8) && tx_axisym_indent(d, 0.1 * R, 0, &f16));
  assert_true(fabs(f8 / f16 - 1) < 0.01);
  tx_axisym_destroy(c), tx_axisym_destroy(d);
  // linear in E
  tx_axisym* e = tx_axisym_create(R, 2 * E, nu, 8, 2);
  assert_true(e && tx_axisym_indent(e, 0.1 * R, 0, &f));
  assert_true(fabs(f / (2 * f8) - 1) < 1e-9);
  tx_axisym_destroy(e);
}

// a tool's tip (a sphere of 5 mm on the 2 cm hemisphere): the contact is
// small beside the body, so Hertz for the two curvatures, R = Ri R / (Ri + R),
// holds at every d/R <= 0.1 (the continuum is 2 to 5 % over it); a flat at the
// same depths is far stiffer than its Hertz (the body's finite size)
static void test_sphere_indenter_meets_hertz(void** state) {
  (void)state;
  const double R = 0.02, Ri = 0.005, E = 5e3, nu = 0.45, reff = Ri * R / (Ri + R);
  tx_axisym* a = tx_axisym_create(R, E, nu, 32, 2);
  assert_non_null(a);
  double f = 0;
  for (int i = 1; i <= 5; i++) {
    double d = 0.02 * i * reff;
    assert_true(tx_axisym_indent(a, d, Ri, &f));
    double ratio = f / tx_hertz_force(E, nu, reff, d);
    assert_true(ratio > 0.97 && ratio < 1.07);
    // the contact's edge where Hertz puts it, a = sqrt(R d), to within a node or two
    assert_true(tx_axisym_contact_nodes(a) >= 5);
  }
  double flat = 0;
  assert_true(tx_axisym_indent(a, 0.1 * R, 0, &flat));
  assert_true(flat / tx_hertz_force(E, nu, R, 0.1 * R) > 1.2);
  assert_false(tx_axisym_indent(a, 0.001, -1, &f));
  tx_axisym_destroy(a);
}

static void test_bad_arguments(void** state) {
  (void)state;
  assert_null(tx_axisym_create(0, 5e3, 0.45, 8, 2));
  assert_null(tx_axisym_create(0.02, 5e3, 0.5, 8, 2));
  assert_null(tx_axisym_create(0.02, 5e3, 0.45, 1, 2));
  assert_null(tx_axisym_create(0.02, 5e3, 0.45, 8, 4));
  tx_axisym* a = tx_axisym_create(0.02, 5e3, 0.45, 4, 2);
  double f = 0;
  assert_false(tx_axisym_indent(a, 0.9 * 0.02, 0, &f));  // the contact past the nodes kept
  tx_axisym_destroy(a);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_band_cholesky), cmocka_unit_test(test_hertz_limit_and_finite_body),
                                     cmocka_unit_test(test_sphere_indenter_meets_hertz),
                                     cmocka_unit_test(test_bad_arguments)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
