// The membrane's heat on its particle grid (controllers/membrane/membrane_heat.h)
// against what it must do exactly and a closed form: a uniform field stays;
// with insulated edges and no perfusion the heat deposited is all in the
// field (and, once boiling, in the field or the vapour) to round-off; a point
// source in a perfused thin plate settles to P / (2 pi k t) K0(r / L); a
// particle at the vaporisation temperature is capped there and leaves the
// solve; bad definitions are refused; a step never allocates.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/membrane/membrane_heat.h"
#include "tactus/model.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/alloc_count.h"

// IT'IS v4.1 fat, the class's defaults
static tx_membrane_heat_def fat(int n, bool insulated, double perfusion_ml_min_kg) {
  tx_membrane_heat_def d = {.nx = n, .nz = n, .spacing = 0.001, .thickness = 0.001, .vaporisation_k = 373.15, .insulated = insulated};
  d.tissue = (tx_tissue){.k = 0.21, .rho = 911, .c = 2348, .perfusion = tx_perfusion_coefficient(perfusion_ml_min_kg, 911),
                         .t_arterial = TX_BODY_TEMPERATURE_K};
  d.damage = (tx_arrhenius){7.39e39, 2.577e5};
  return d;
}

static tx_membrane_heat* make(const tx_membrane_heat_def* d) {
  tx_membrane_heat* h = tx_membrane_heat_create(d);
  if (!h) fail_msg("%s", tx_error());
  return h;
}

// insulated and unperfused, a uniform 330 K stays 330 K exactly; held and
// perfused, the body's temperature stays
static void uniform_field_stays(void** state) {
  (void)state;
  tx_membrane_heat_def d = fat(21, true, 0);
  tx_membrane_heat* h = make(&d);
  for (int i = 0; i < h->n; i++) h->t[i] = 330;
  for (int k = 0; k < 100; k++) assert_int_equal(tx_membrane_heat_step(h, 5.0), 0);
  for (int i = 0; i < h->n; i++) assert_true(h->t[i] == 330);
  tx_membrane_heat_destroy(h);
  d = fat(21, false, 33);
  h = make(&d);
  for (int k = 0; k < 100; k++) tx_membrane_heat_step(h, 5.0);
  for (int i = 0; i < h->n; i++) assert_true(h->t[i] == TX_BODY_TEMPERATURE_K);
  tx_membrane_heat_destroy(h);
}

// insulated, unperfused: what the source put in is the field's content, to
// round-off, whatever the field and the steps (substeps included); a hole
// (triangles gone) changes where the heat goes, not how much there is
static void energy_is_conserved(void** state) {
  (void)state;
  tx_membrane_heat_def d = fat(31, true, 0);
  tx_membrane_heat* h = make(&d);
  srand(7);
  for (int i = 0; i < h->n; i++) h->t[i] = 310.15 + 20.0 * rand() / RAND_MAX;
  const double c0 = tx_membrane_heat_content(h);
  float* x = calloc((size_t)h->n * 3, sizeof(float));
  for (int i = 0; i < h->n; i++) x[3 * i] = (float)(i % 31 * 1e-3), x[3 * i + 2] = (float)(i / 31 * 1e-3);
  for (int k = 0; k < 200; k++) {
    if (k == 100) { // the middle cell's two triangles gone: its four edges lose one each
      int32_t* tri = malloc(sizeof(int32_t) * 6 * 30 * 30);
      int m = 0;
      for (int cz = 0; cz < 30; cz++)
        for (int cx = 0; cx < 30; cx++) {
          if (cx == 15 && cz == 15) continue;
          int a = cx + 31 * cz, b = a + 1, c = a + 31, e = c + 1;
          int32_t t[6] = {a, b, e, a, e, c};
          memcpy(tri + 3 * m, t, sizeof t), m += 2;
        }
      tx_membrane_heat_edges(h, tri, m);
      free(tri);
    }
    tx_membrane_heat_source(h, x, (double[3]){0.012, 0, 0.017}, 0.002, k < 150 ? 0.005 : 0);
    assert_int_equal(tx_membrane_heat_step(h, k % 2 ? 0.5 : 7.0), 0); // 7 s: several substeps
  }
  double c1 = tx_membrane_heat_content(h), err = fabs(c1 - c0 - h->energy) / h->energy;
  print_message("  deposited %.6f J, the field gained %.6f J: relative difference %.2e\n", h->energy, c1 - c0, err);
  assert_true(fabs(h->energy - 0.005 * (75 * 0.5 + 75 * 7.0)) < 1e-12);
  assert_true(err < 1e-12);
  free(x);
  tx_membrane_heat_destroy(h);
}

// K0 by its integral: K0(x) = int_0^inf exp(-x cosh u) du; the trapezoidal
// rule converges geometrically on this smooth, fast decaying integrand
static double bessel_k0(double x) {
  const double du = 1e-3;
  double sum = 0.5 * exp(-x);
  for (double u = du; u < 30; u += du) {
    double f = exp(-x * cosh(u));
    sum += f;
    if (f < 1e-300) break;
  }
  return sum * du;
}

// a point source P in a perfused thin plate settles to
//   T - T_a = P / (2 pi k t) K0(r / L),  L = sqrt(k / (w_b rho_b c_b))
// (the 2-D Pennes equation's Green's function). Fat: L = 10.5 mm. The plate
// is 161 x 161 particles at 1 mm, held at T_a at +-80 mm (7.6 L; K0 there is
// 2e-3 of its value at 20 mm, and the held edge's image lowers the field
// nearer in by about that); the source is one particle's q. The time
// constant is rho c / w_b rho_b c_b = 1124 s, and the slowest mode decays
// faster than that (it diffuses too), so 9000 s (8 of them) settle it to
// 3e-4. Where the grid resolves the field (r of 3 spacings and more), the
// 5-point stencil's error is O(s^2 / r^2) of the curvature: a few tenths of
// a percent at 3 mm, so 1 % holds
static void point_source_matches_k0(void** state) {
  (void)state;
  const int n = 161, mid = n / 2;
  tx_membrane_heat_def d = fat(n, false, 33);
  tx_membrane_heat* h = make(&d);
  const double p = 0.01, kt = d.tissue.k * d.thickness, l = sqrt(d.tissue.k / d.tissue.perfusion);
  h->q[mid + n * mid] = p;
  const double dt = h->dt_max;
  int steps = (int)ceil(9000 / dt);
  for (int k = 0; k < steps; k++) tx_membrane_heat_step(h, dt);
  print_message("  L = %.2f mm, %d steps of %.2f s; peak %.3f K\n", l * 1e3, steps, dt, h->t[mid + n * mid]);
  const int rs[] = {3, 5, 10, 20, 30};
  double worst = 0;
  for (int k = 0; k < 5; k++) {
    int r = rs[k];
    double want = p / (2 * M_PI * kt) * bessel_k0(r * d.spacing / l);
    double along = h->t[mid + r + n * mid] - d.tissue.t_arterial, across = h->t[mid + n * (mid + r)] - d.tissue.t_arterial;
    // on the diagonal too (r sqrt 2)
    int dg = (int)lround(r / sqrt(2.0));
    double wdiag = p / (2 * M_PI * kt) * bessel_k0(dg * sqrt(2.0) * d.spacing / l);
    double diag = h->t[mid + dg + n * (mid + dg)] - d.tissue.t_arterial;
    double e1 = along / want - 1, e2 = across / want - 1, e3 = diag / wdiag - 1;
    print_message("  r %2d mm: closed form %.4f K, grid %.4f K (along x), %.4f (z), diagonal %.4f vs %.4f: %+.2f %%, %+.2f %%, %+.2f %%\n", r,
                  want, along, across, diag, wdiag, 100 * e1, 100 * e2, 100 * e3);
    worst = fmax(worst, fmax(fabs(e1), fmax(fabs(e2), fabs(e3))));
  }
  print_message("  worst relative error %.3f %%\n", 100 * worst);
  assert_true(worst < 0.01);
  tx_membrane_heat_destroy(h);
}

// a hot source boils particles: none above the cap, each boiled one out of
// the solve at T_a, its heat accounted as boiled; insulated and unperfused,
// deposited = content + boiled to round-off; the rest cool by conduction
static void boiling_caps_and_marks(void** state) {
  (void)state;
  tx_membrane_heat_def d = fat(21, true, 0);
  tx_membrane_heat* h = make(&d);
  float* x = calloc((size_t)h->n * 3, sizeof(float));
  for (int i = 0; i < h->n; i++) x[3 * i] = (float)(i % 21 * 1e-3), x[3 * i + 2] = (float)(i / 21 * 1e-3);
  const int mid = 10 + 21 * 10;
  int boiled = 0, first = -1;
  double peak = 0;
  for (int k = 0; k < 400; k++) {
    tx_membrane_heat_source(h, x, (double[3]){0.010, 0, 0.010}, 0.001, 5);
    int b = tx_membrane_heat_step(h, 1e-3);
    for (int j = 0; j < b; j++) {
      assert_int_equal(h->gone[h->boiled_now[j]], 1);
      assert_true(h->t[h->boiled_now[j]] == d.tissue.t_arterial);
      if (first < 0) first = h->boiled_now[j], print_message("  first boiled at %.3f s: particle %d\n", (k + 1) * 1e-3, first);
    }
    boiled += b;
    peak = fmax(peak, h->peak);
    for (int i = 0; i < h->n; i++) assert_true(h->t[i] <= d.vaporisation_k);
    if (b) assert_true(h->peak == d.vaporisation_k);
  }
  assert_int_equal(first, mid); // the source's centre first
  assert_true(boiled > 1);
  assert_true(peak == d.vaporisation_k);
  assert_false(tx_membrane_heat_live(h, mid));
  // gone particles take no heat: the source goes to the rest
  double err = fabs(tx_membrane_heat_content(h) + h->boiled - h->energy) / h->energy;
  print_message("  %d boiled; deposited %.4f J = content + boiled to %.1e\n", boiled, h->energy, err);
  assert_true(err < 1e-12);
  assert_true(tx_membrane_heat_damaged(h) >= boiled * 1e-6);
  tx_membrane_heat_destroy(h);
  free(x);
}

static void bad_definitions_are_refused(void** state) {
  (void)state;
  tx_membrane_heat_def good = fat(5, false, 33), d;
  d = good, d.nx = 1;
  assert_null(tx_membrane_heat_create(&d));
  d = good, d.spacing = 0;
  assert_null(tx_membrane_heat_create(&d));
  d = good, d.tissue.k = NAN;
  assert_null(tx_membrane_heat_create(&d));
  d = good, d.tissue.perfusion = -1;
  assert_null(tx_membrane_heat_create(&d));
  d = good, d.vaporisation_k = d.tissue.t_arterial;
  assert_null(tx_membrane_heat_create(&d));
  print_message("  %s\n", tx_error());
  assert_non_null(strstr(tx_error(), "vaporisation"));
}

static void steps_never_allocate(void** state) {
  (void)state;
  tx_membrane_heat_def d = fat(31, false, 33);
  tx_membrane_heat* h = make(&d);
  float* x = calloc((size_t)h->n * 3, sizeof(float));
  int32_t tri[6] = {0, 1, 32, 0, 32, 31};
  counting = 1;
  for (int k = 0; k < 50; k++) {
    tx_membrane_heat_source(h, x, (double[3]){0.001, 0, 0.001}, 0.002, 30);
    tx_membrane_heat_step(h, 0.01);
  }
  tx_membrane_heat_edges(h, tri, 2);
  tx_membrane_heat_step(h, 0.01);
  counting = 0;
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
  free(x);
  tx_membrane_heat_destroy(h);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(uniform_field_stays),
      cmocka_unit_test(energy_is_conserved),
      cmocka_unit_test(point_source_matches_k0),
      cmocka_unit_test(boiling_caps_and_marks),
      cmocka_unit_test(bad_definitions_are_refused),
      cmocka_unit_test(steps_never_allocate),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
