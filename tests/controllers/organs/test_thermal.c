// The organs' bioheat solver (controllers/organs/thermal.h) and the
// cautery-heat study's closed forms (studies/experiments/cautery_heat.h):
// a uniform field stays, heat is conserved in an insulated block, perfusion
// decays a rise at the discrete rate, a step far past the stable one stays
// bounded, Arrhenius damage integrates its rate, the band steps only the
// heated region and matches the full update, boiling caps the temperature
// and keeps the energy; the closed forms against quadrature and their
// point-source limits; the solver converges on the quick levels; refinement
// keeps the volume and embeds points exactly; no allocation in a step; bad
// meshes and files refused with one line; tetrahedra removed leave a
// solver that steps as one built on what is left.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/alloc_count.h"

#include "controllers/organs/removal.h"
#include "controllers/organs/thermal.h"
#include "studies/experiments/cautery_heat.h"

#include <tactus/model.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// a block of n^3 cells, half width 5 mm, liver (perfusion as given)
static tx_thermal* block(int n, double perfusion, const tx_arrhenius* d, double dt, double** xo, int* nodes) {
  double* x;
  int *tet, nn, nt;
  assert_true(tx_heat_block(0.005, n, &x, &nn, &tet, &nt));
  tx_tissue t = tx_tissue_liver();
  t.perfusion = perfusion;
  tx_thermal* h = tx_thermal_create(x, nn, tet, nt, &t, d, dt);
  assert_non_null(h);
  free(tet);
  if (xo) *xo = x;
  else free(x);
  if (nodes) *nodes = nn;
  return h;
}

static double heat_content(const tx_thermal* h) { // J above T_a
  tx_tissue t = tx_tissue_liver();
  const double *T = tx_thermal_temperature(h), *v = tx_thermal_volume(h);
  double e = 0;
  for (int i = 0; i < tx_thermal_nodes(h); i++) e += t.rho * t.c * v[i] * (T[i] - t.t_arterial);
  return e;
}

static void uniform_field_stays(void** state) {
  (void)state;
  tx_thermal* h = block(4, tx_tissue_liver().perfusion, NULL, 0.1, NULL, NULL);
  for (int s = 0; s < 50; s++) tx_thermal_step(h);
  for (int i = 0; i < tx_thermal_nodes(h); i++) assert_true(tx_thermal_temperature(h)[i] == TX_BODY_TEMPERATURE_K);
  tx_thermal_destroy(h);
}

// insulated (no node held), no perfusion: all of P t stays in the block
static void heat_is_conserved(void** state) {
  (void)state;
  double total = 0;
  tx_thermal* h = block(5, 0, NULL, 0.1, NULL, NULL);
  for (int i = 0; i < tx_thermal_nodes(h); i++) total += tx_thermal_volume(h)[i];
  assert_true(fabs(total - 1e-6) < 1e-15); // the 1 cm cube
  tx_thermal_source(h, (const double[3]){0.001, -0.0005, 0.002}, 0.001, 1.0);
  for (int s = 0; s < 10; s++) tx_thermal_step(h);
  print_message("  1 W for 1 s: %.12f J in the block, %.12f J deposited\n", heat_content(h), tx_thermal_energy(h));
  assert_true(fabs(heat_content(h) - 1.0) < 1e-9);
  assert_true(fabs(tx_thermal_energy(h) - 1.0) < 1e-12);
  tx_thermal_destroy(h);
}

// a uniform rise decays by (1 - h w / (rho c)) a substep: no conduction
static void perfusion_decays_a_rise(void** state) {
  (void)state;
  tx_tissue t = tx_tissue_liver();
  tx_thermal* h = block(3, t.perfusion, NULL, 1.0, NULL, NULL);
  double* T = tx_thermal_temperature_mut(h);
  for (int i = 0; i < tx_thermal_nodes(h); i++) T[i] = t.t_arterial + 10;
  for (int s = 0; s < 20; s++) tx_thermal_step(h);
  int n = 20 * tx_thermal_substeps(h);
  double sub = 1.0 / tx_thermal_substeps(h), want = 10 * pow(1 - sub * t.perfusion / (t.rho * t.c), n);
  double got = tx_thermal_temperature(h)[0] - t.t_arterial;
  print_message("  after 20 s: %.9f K (discrete %.9f, continuous %.9f)\n", got, want, 10 * exp(-20 * t.perfusion / (t.rho * t.c)));
  assert_true(fabs(got - want) < 1e-9);
  assert_true(fabs(got - 10 * exp(-20 * t.perfusion / (t.rho * t.c))) < 0.005 * got); // explicit Euler's O(dt)
  tx_thermal_destroy(h);
}

// a step of 100 s on a 1 mm mesh: split within the bound, bounded
static void long_step_is_split_and_stable(void** state) {
  (void)state;
  tx_thermal* h = block(10, tx_tissue_liver().perfusion, NULL, 100, NULL, NULL);
  assert_true(tx_thermal_substeps(h) * tx_thermal_stable_dt(h) >= 100 * (1 - 1e-12));
  assert_true(tx_thermal_substeps(h) > 1);
  tx_thermal_source(h, (const double[3]){0, 0, 0}, 0.001, 0.2);
  double prev = 0;
  for (int s = 0; s < 5; s++) {
    tx_thermal_step(h);
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < tx_thermal_nodes(h); i++)
      lo = fmin(lo, tx_thermal_temperature(h)[i]), hi = fmax(hi, tx_thermal_temperature(h)[i]);
    assert_true(lo >= TX_BODY_TEMPERATURE_K - 1e-9); // no undershoot: the update is monotone at this step
    assert_true(isfinite(hi) && hi < TX_BODY_TEMPERATURE_K + 200 && hi >= prev - 1e-9);
    prev = hi;
  }
  tx_thermal_destroy(h);
}

static void arrhenius_integrates_its_rate(void** state) {
  (void)state;
  tx_arrhenius d = tx_arrhenius_liver();
  // at 37 C, Omega = 1 takes about an hour; at 60 C about 3 s
  double rest = tx_arrhenius_rate(&d, TX_BODY_TEMPERATURE_K), hot = tx_arrhenius_rate(&d, 333.15);
  print_message("  rate at 37 C %.3g 1/s, at 60 C %.3g 1/s\n", rest, hot);
  assert_true(rest > 1e-4 && rest < 1e-3 && hot > 0.1 && hot < 1);
  assert_true(fabs(hot - 7.39e39 * exp(-2.577e5 / (TX_GAS_CONSTANT * 333.15))) < 1e-12 * hot);
  tx_thermal* h = block(3, 0, &d, 0.01, NULL, NULL);
  double* T = tx_thermal_temperature_mut(h);
  for (int i = 0; i < tx_thermal_nodes(h); i++) T[i] = 333.15;
  for (int s = 0; s < 100; s++) tx_thermal_step(h);
  double omega = tx_thermal_damage(h)[0] + tx_thermal_damage_rest(h);
  assert_true(fabs(omega - hot) < 1e-9 * hot);
  assert_true(fabs(tx_thermal_damage_rest(h) - rest) < 1e-9 * rest);
  tx_thermal_destroy(h);
}

// the band steps the heated region only and agrees with every node's step
static void band_matches_full_update(void** state) {
  (void)state;
  tx_arrhenius d = tx_arrhenius_liver();
  int n;
  tx_thermal *full = block(20, tx_tissue_liver().perfusion, &d, 0.05, NULL, &n),
             *band = block(20, tx_tissue_liver().perfusion, &d, 0.05, NULL, NULL);
  tx_thermal_band(band, 1e-3);
  for (int s = 0; s < 20; s++) {
    const double c[3] = {0.0005 * (s % 7), 0, 0};
    tx_thermal_source(full, c, 0.0007, s < 15 ? 2.0 : 0);
    tx_thermal_source(band, c, 0.0007, s < 15 ? 2.0 : 0);
    tx_thermal_step(full), tx_thermal_step(band);
  }
  double diff = 0, ddiff = 0, peak = 0;
  for (int i = 0; i < n; i++) {
    diff = fmax(diff, fabs(tx_thermal_temperature(full)[i] - tx_thermal_temperature(band)[i]));
    ddiff = fmax(ddiff, fabs(tx_thermal_damage(full)[i] - tx_thermal_damage(band)[i]));
    peak = fmax(peak, tx_thermal_temperature(full)[i] - TX_BODY_TEMPERATURE_K);
  }
  print_message("  peak rise %.2f K; band and full differ by %.3g K and %.3g in Omega; the band stepped %d of %d nodes\n",
                peak, diff, ddiff, tx_thermal_stepped(band), n);
  assert_true(peak > 10);
  assert_true(diff < 2e-3 && ddiff < 1e-6); // about the band
  assert_true(tx_thermal_stepped(band) > 0 && tx_thermal_stepped(band) < n / 2);
  tx_thermal_destroy(full);
  tx_thermal_destroy(band);
}

// boiling: nothing above the cap, the heat past it counted
static void boiling_caps_and_keeps_the_energy(void** state) {
  (void)state;
  tx_thermal* h = block(6, 0, NULL, 0.05, NULL, NULL);
  tx_thermal_cap(h, TX_VAPORISATION_K);
  tx_thermal_source(h, (const double[3]){0, 0, 0}, 0.0005, 20);
  for (int s = 0; s < 20; s++) tx_thermal_step(h);
  int reached = 0;
  for (int i = 0; i < tx_thermal_nodes(h); i++) {
    assert_true(tx_thermal_temperature(h)[i] <= TX_VAPORISATION_K);
    reached += tx_thermal_reached(h)[i];
  }
  print_message("  20 W for 1 s: %d nodes boiled, %.4f J boiling, %.4f J in the block\n", reached, tx_thermal_boiled(h),
                heat_content(h));
  assert_true(reached > 0 && tx_thermal_boiled(h) > 0);
  assert_true(fabs(heat_content(h) + tx_thermal_boiled(h) - 20.0) < 1e-9);
  tx_thermal_destroy(h);
}

// the perfused closed form against the convolution by quadrature:
// theta(r) = (2 pi / r) int rho q(rho) L/(4 pi k) (e^-|r-rho|/L - e^-(r+rho)/L) drho
static void closed_forms_against_quadrature(void** state) {
  (void)state;
  const double P = 0.5, s = 0.0015, k = 0.52, L = 0.003;
  const double rs[] = {0.2 * s, s, 3 * s, 6 * s};
  for (int i = 0; i < 4; i++) {
    double r = rs[i], sum = 0;
    const int N = 20000;
    double hh = 10 * s / N;
    for (int j = 0; j <= N; j++) { // Simpson
      double rho = j * hh, q = P * pow(2 * M_PI * s * s, -1.5) * exp(-rho * rho / (2 * s * s));
      double f = rho * q * L / (4 * M_PI * k) * (exp(-fabs(r - rho) / L) - exp(-(r + rho) / L));
      sum += f * (j == 0 || j == N ? 1 : j % 2 ? 4 : 2);
    }
    double quad = 2 * M_PI / r * sum * hh / 3, closed = tx_heat_gauss_perfused(r, P, s, k, L);
    print_message("  r = %.2f mm: closed %.8f K, quadrature %.8f K\n", r * 1e3, closed, quad);
    assert_true(fabs(closed - quad) < 1e-7 * quad);
  }
  // point-source limits far from a narrow source
  double alpha = 1.4e-7, r = 0.004, t = 10;
  double point = P / (4 * M_PI * k * r) * erfc(r / sqrt(4 * alpha * t));
  assert_true(fabs(tx_heat_gauss_transient(r, t, P, 1e-6, k, alpha) - point) < 1e-4 * point);
  assert_true(fabs(tx_heat_gauss_perfused(r, P, 1e-6, k, L) - P * exp(-r / L) / (4 * M_PI * k * r)) < 1e-4 * point);
  // the steady Gaussian: the transient at t -> infinity is the perfused with L -> infinity
  double steady = tx_heat_gauss_perfused(r, P, s, k, 1e6);
  assert_true(fabs(tx_heat_gauss_transient(r, 1e13, P, s, k, alpha) - steady) < 1e-5 * steady);
}

static void converges_on_the_quick_levels(void** state) {
  (void)state;
  for (int perf = 0; perf < 2; perf++) {
    double prev = INFINITY;
    for (int l = 0; l < 2; l++) {
      tx_heat_case c = tx_heat_case_default(perf);
      c.cells = (perf ? 12 : 10) << l;
      tx_heat_result r;
      assert_true(tx_heat_run(&c, false, &r));
      print_message("  %s, h = %.0f mm: error %.3f%%\n", perf ? "perfused" : "transient", r.h_m * 1e3, 100 * r.error);
      assert_true(r.error < prev / 3); // second order: about 4 times smaller
      prev = r.error;
    }
    assert_true(prev < 0.035);
  }
}

static void refinement_keeps_volume_and_embeds(void** state) {
  (void)state;
  double *x, *x2;
  int *tet, *t2, n, nt, n2, nt2;
  assert_true(tx_heat_block(0.005, 2, &x, &n, &tet, &nt));
  assert_true(tx_tet_refine(x, n, tet, nt, &x2, &n2, &t2, &nt2));
  assert_int_equal(nt2, 8 * nt);
  assert_int_equal(n2, 5 * 5 * 5); // the 2-cell lattice's edges' midpoints: the 4-cell lattice
  tx_tissue ts = tx_tissue_liver();
  tx_thermal *a = tx_thermal_create(x, n, tet, nt, &ts, NULL, 1), *b = tx_thermal_create(x2, n2, t2, nt2, &ts, NULL, 1);
  assert_non_null(a), assert_non_null(b);
  double va = 0, vb = 0;
  for (int i = 0; i < n; i++) va += tx_thermal_volume(a)[i];
  for (int i = 0; i < n2; i++) vb += tx_thermal_volume(b)[i];
  assert_true(fabs(va - vb) < 1e-12 * va);
  // points embedded through two refinements reproduce themselves
  const float pts[] = {0.001f, 0.002f, -0.003f, -0.0049f, 0.0f, 0.0041f, 0.0052f, 0.0f, 0.0f};
  int et[12];
  float ew[12];
  double *xf;
  int nf, *tf, ntf;
  assert_true(tx_thermal_refine_embed(x, n, tet, nt, 2, pts, 3, &xf, &nf, &tf, &ntf, et, ew));
  assert_int_equal(ntf, 64 * nt);
  for (int v = 0; v < 3; v++) {
    double p[3] = {0, 0, 0}, sum = 0;
    for (int k = 0; k < 4; k++) {
      sum += ew[4 * v + k];
      for (int c = 0; c < 3; c++) p[c] += ew[4 * v + k] * xf[3 * et[4 * v + k] + c];
    }
    assert_true(fabs(sum - 1) < 1e-5);
    for (int c = 0; c < 3; c++) assert_true(fabs(p[c] - pts[3 * v + c]) < 1e-8);
    if (v < 2)
      for (int k = 0; k < 4; k++) assert_true(ew[4 * v + k] > -1e-5); // inside: inside its tetrahedron
  }
  tx_thermal_destroy(a), tx_thermal_destroy(b);
  free(x), free(tet), free(x2), free(t2), free(xf), free(tf);
}

static void no_allocation_in_a_step(void** state) {
  (void)state;
  tx_arrhenius d = tx_arrhenius_liver();
  tx_thermal* h = block(6, tx_tissue_liver().perfusion, &d, 0.01, NULL, NULL);
  tx_thermal_band(h, 1e-3);
  tx_thermal_cap(h, TX_VAPORISATION_K);
  counting = 1;
  for (int s = 0; s < 20; s++) {
    tx_thermal_source(h, (const double[3]){0.0001 * s, 0, 0}, 0.001, s < 10 ? 5 : 0);
    tx_thermal_step(h);
  }
  counting = 0;
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
  tx_thermal_destroy(h);
}

static void bad_meshes_and_files(void** state) {
  (void)state;
  const double x[] = {0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 1e-3, 1e-3, 0};
  const int flat[] = {0, 1, 2, 4}; // four nodes in z = 0
  const int out[] = {0, 1, 2, 7};
  const int ok[] = {0, 1, 2, 3};
  tx_tissue t = tx_tissue_liver();
  assert_null(tx_thermal_create(x, 5, flat, 1, &t, NULL, 0.01));
  assert_non_null(strstr(tx_error(), "degenerate"));
  assert_null(tx_thermal_create(x, 5, out, 1, &t, NULL, 0.01));
  assert_non_null(strstr(tx_error(), "node 7"));
  assert_null(tx_thermal_create(x, 4, ok, 1, &t, NULL, 0)); // no step
  t.k = 0;
  assert_null(tx_thermal_create(x, 4, ok, 1, &t, NULL, 0.01));
  assert_null(strchr(tx_error(), '\n'));
  double* xs;
  int n, *tets, nt;
  assert_false(tx_tetgen_read("/nonexistent/liver", &xs, &n, &tets, &nt));
  assert_non_null(strstr(tx_error(), "/nonexistent/liver.node"));
  float* v;
  int nv, *tri, ntri;
  assert_false(tx_obj_read("/nonexistent/liver.obj", &v, &nv, &tri, &ntri));
  assert_non_null(strstr(tx_error(), "/nonexistent/liver.obj"));
  // the committed assets read
  assert_true(tx_tetgen_read(TX_ASSETS "/lagb/liver", &xs, &n, &tets, &nt));
  assert_int_equal(n, 779), assert_int_equal(nt, 2896);
  free(xs), free(tets);
}

// a 4 x 2 x 2 block with the half x > 2 h removed, tetrahedron by
// tetrahedron, steps as a 2 x 2 x 2 block built alone from the same start
// (a hot node, no perfusion), to rounding; the removed nodes hold T_a, take
// no heat from a source on them (it goes to the nearest live node) and
// count no volume; a second removal of their nodes is refused; no allocation
static void removal_is_a_smaller_mesh(void** state) {
  (void)state;
  const double hh = 0.002;
  double *xa, *xb;
  int *ta, *tb, na, nb, ea, eb;
  assert_true(tx_block_mesh(4, 2, 2, hh, &xa, &na, &ta, &ea));
  assert_true(tx_block_mesh(2, 2, 2, hh, &xb, &nb, &tb, &eb));
  tx_tissue t = tx_tissue_liver();
  t.perfusion = 0;
  tx_thermal* a = tx_thermal_create(xa, na, ta, ea, &t, NULL, 0.5);
  tx_thermal* b = tx_thermal_create(xb, nb, tb, eb, &t, NULL, 0.5);
  assert_non_null(a), assert_non_null(b);
  int removed = 0;
  for (int e = 0; e < ea; e++) {
    double cx = 0;
    for (int k = 0; k < 4; k++) cx += xa[3 * ta[4 * e + k]] / 4;
    if (cx < 2 * hh) continue;
    counting = 1, allocations = 0;
    assert_true(tx_thermal_remove(a, ta + 4 * e));
    counting = 0;
#ifndef TX_NO_ALLOC_COUNT
    assert_int_equal(allocations, 0);
#endif
    removed++;
  }
  assert_int_equal(removed, ea / 2);
  // the same node in both: b's (i, j, k) is a's (i, j, k) for i <= 2
  int map[27];
  for (int k = 0; k <= 2; k++)
    for (int j = 0; j <= 2; j++)
      for (int i = 0; i <= 2; i++) map[i + 3 * (j + 3 * k)] = i + 5 * (j + 3 * k);
  double va = 0, vb = 0;
  for (int i = 0; i < na; i++) {
    bool kept = xa[3 * i] < 2 * hh + 1e-12;
    assert_true(tx_thermal_node_live(a, i) == kept);
    va += tx_thermal_volume(a)[i];
  }
  for (int i = 0; i < nb; i++) vb += tx_thermal_volume(b)[i];
  assert_true(fabs(va - vb) < 1e-12 * vb);
  tx_thermal_temperature_mut(a)[map[13]] += 10, tx_thermal_temperature_mut(b)[13] += 10;
  // a source on the removed half: its heat goes to the nearest live node
  double far[3] = {4 * hh, hh, hh};
  tx_thermal_source(a, far, 1e-5, 1);
  double near[3] = {2 * hh, hh, hh};
  tx_thermal_source(b, near, 1e-5, 1);
  for (int s = 0; s < 20; s++) tx_thermal_step(a), tx_thermal_step(b);
  const double *fa = tx_thermal_temperature(a), *fb = tx_thermal_temperature(b);
  double worst = 0;
  for (int i = 0; i < nb; i++) worst = fmax(worst, fabs(fa[map[i]] - fb[i]));
  for (int i = 0; i < na; i++)
    if (!tx_thermal_node_live(a, i)) assert_true(fa[i] == t.t_arterial);
  print_message("  half removed vs built alone: %.3g K apart at most (peak %.2f K)\n", worst, fb[13]);
  assert_true(worst < 1e-9);
  assert_true(fb[13] > t.t_arterial + 1);
  // out already, or out of range: refused
  assert_false(tx_thermal_remove(a, ta + 4 * (ea - 1)));
  int bad[4] = {0, 1, 2, na};
  assert_false(tx_thermal_remove(a, bad));
  tx_thermal_destroy(a), tx_thermal_destroy(b);
  free(xa), free(xb), free(ta), free(tb);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(uniform_field_stays),
      cmocka_unit_test(heat_is_conserved),
      cmocka_unit_test(perfusion_decays_a_rise),
      cmocka_unit_test(long_step_is_split_and_stable),
      cmocka_unit_test(arrhenius_integrates_its_rate),
      cmocka_unit_test(band_matches_full_update),
      cmocka_unit_test(boiling_caps_and_keeps_the_energy),
      cmocka_unit_test(closed_forms_against_quadrature),
      cmocka_unit_test(converges_on_the_quick_levels),
      cmocka_unit_test(refinement_keeps_volume_and_embeds),
      cmocka_unit_test(no_allocation_in_a_step),
      cmocka_unit_test(bad_meshes_and_files),
      cmocka_unit_test(removal_is_a_smaller_mesh),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
