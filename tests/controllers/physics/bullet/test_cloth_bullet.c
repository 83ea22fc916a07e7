// The Bullet skin patch through its C interface: particle and triangle
// counts, a hanging patch that sags and settles, the HIP contact that a
// 0.5 mm sphere cannot slip through, rupture that opens a hole, NaN and
// blow-up recovery, bad definitions, and steps that never allocate.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/physics/bullet/cloth.h"
#include "tactus/model.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "tests/alloc_count.h"

// under the sanitizers the long runs below are cut short (their logic is the same)
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SANITIZED 1
#else
#define SANITIZED 0
#endif

// the solver make() builds with: the default (implicit), or XPBD at its old
// real-time setting (ten substeps of one iteration a 60 Hz step)
static int solver = TX_CLOTH_IMPLICIT;

static tx_cloth* make(int res, double gravity, double rupture) {
  tx_cloth_def d = tx_cloth_def_default();
  d.solver = solver;
  if (solver == TX_CLOTH_XPBD) d.max_substep = 1.0 / 600;
  d.res[0] = d.res[1] = res;
  d.gravity = gravity;
  d.rupture_tension = rupture;
  tx_cloth* c = tx_cloth_create(&d);
  if (!c) fail_msg("%s", tx_error());
  return c;
}

static int centre(const tx_cloth* c) {
  int res = tx_cloth_get_def(c)->res[0];
  return (res / 2) * res + res / 2;
}

static bool all_finite(const tx_cloth* c) {
  int n = tx_cloth_particle_count(c);
  float* x = malloc(sizeof(float) * 3 * (size_t)n);
  tx_cloth_positions(c, x);
  bool ok = true;
  for (int i = 0; i < 3 * n; i++) ok &= isfinite(x[i]) != 0;
  free(x);
  return ok;
}

// the papers' two densities: 42 x 42 and 102 x 102 particles over 10 x 10 cm
static void counts_match_the_papers(void** state) {
  (void)state;
  tx_cloth* c = make(42, 0, 20);
  assert_int_equal(tx_cloth_particle_count(c), 1764);
  assert_int_equal(tx_cloth_triangle_count(c), 3362);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * 3362);
  assert_int_equal(tx_cloth_triangles(c, tri), 3362);
  // every triangle faces +y at rest, and the spacing is the size over 41 cells
  float* x = malloc(sizeof(float) * 3 * 1764);
  tx_cloth_positions(c, x);
  for (int t = 0; t < 3362; t++) {
    const float* a = &x[3 * tri[3 * t]];
    const float* b = &x[3 * tri[3 * t + 1]];
    const float* cc = &x[3 * tri[3 * t + 2]];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
    double ny = u[2] * v[0] - u[0] * v[2];
    assert_true(ny > 0);
  }
  assert_float_equal(x[3] - x[0], 0.1 / 41, 1e-7);
  assert_float_equal(x[0], -0.05, 1e-7);
  free(x);
  free(tri);
  tx_cloth_destroy(c);

  c = make(102, 0, 20);
  assert_int_equal(tx_cloth_particle_count(c), 10404);
  assert_int_equal(tx_cloth_triangle_count(c), 2 * 101 * 101);
  tx_cloth_destroy(c);
}

// a fixed-border patch under gravity hangs: the centre goes down, the border
// stays, and after a second it no longer moves; nothing tears by itself. The
// real-time default (implicit) sags what the converged XPBD solver does, 2.91 mm
// at 42 x 42 (docs/skin.md), and Hencky's membrane (3.0 mm) within 5 %
static void hanging_patch_sags_and_settles(void** state) {
  (void)state;
  tx_cloth_def d = tx_cloth_def_default();
  d.gravity = 9.81;
  d.settle_time = 0;    // watch it fall from flat
  d.rupture_tension = 0;
  tx_cloth* c = tx_cloth_create(&d);
  assert_non_null(c);
  double p[3], corner[3], before = 0;
  for (int s = 0; s < 120; s++) {
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    if (s == 89) tx_cloth_particle(c, centre(c), p), before = p[1];
  }
  tx_cloth_particle(c, centre(c), p);
  tx_cloth_particle(c, 0, corner);
  print_message("  centre sags %.2f mm\n", -p[1] * 1e3);
  assert_true(fabs(-p[1] - 2.91e-3) < 0.03 * 2.91e-3); // the converged sag
  assert_true(fabs(-p[1] - 3.0e-3) < 0.05 * 3.0e-3);  // Hencky's
  assert_true(fabs(p[1] - before) < 1e-5);    // settled: under 10 um over the last half second
  assert_float_equal(corner[1], 0, 1e-9);     // the border holds
  assert_float_equal(corner[0], -0.05, 1e-7);
  assert_int_equal(tx_cloth_torn(c), 0);
  tx_cloth_destroy(c);

  // with settle_time, the patch starts hanging and rupture counts from there:
  // at a rupture tension of 1 N/m, which the hanging patch holds more than
  // near its border, it does not tear by its weight
  const double weak = 1;
  c = make(42, 9.81, weak);
  tx_cloth_particle(c, centre(c), p);
  assert_true(p[1] < -0.0025);
  double most = 0; // the largest tension per unit length of a stretch link: the weight alone passes the criterion
  for (int id = 0; id < tx_cloth_link_total(c); id++) {
    int32_t e[2];
    tx_cloth_link_ends(c, id, e);
    if (abs(e[1] - e[0]) == 1 || abs(e[1] - e[0]) == 42) most = fmax(most, tx_cloth_link_tension(c, id) / (0.1 / 41));
  }
  print_message("  hanging: a stretch link carries up to %.2f N/m, the rupture tension is %.2f N/m\n", most, weak);
  assert_true(most > weak);
  for (int s = 0; s < 60; s++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  assert_int_equal(tx_cloth_torn(c), 0);
  tx_cloth_destroy(c);
}

// a 0.5 mm HIP between particles 2.5 mm apart still meets the skin: pressed
// 3 mm below the mid-plane, the skin under it stays radius + half the
// thickness further down, and the skin never pulls it
static void hip_cannot_slip_between_particles(void** state) {
  (void)state;
  tx_cloth* c = make(42, 0, 0); // no rupture: contact only
  const double r = 0.0005, rc = r + 0.5 * 0.004;
  // in the middle of a cell, as far from the particles as it gets
  double h[3] = {0.00125, 0.01, 0.00125};
  assert_int_equal(tx_cloth_set_hip(c, h, r), TX_CLOTH_OK);
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  for (int s = 0; s <= 160; s++) {
    h[1] = 0.01 - 0.013 * s / 160.0; // down to -3 mm
    tx_cloth_set_hip(c, h, r);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  }
  // the lowest particle near the HIP is below it by about the contact distance
  double lowest = 1, p[3];
  for (int i = 0; i < tx_cloth_particle_count(c); i++) {
    tx_cloth_particle(c, i, p);
    if (fabs(p[0] - h[0]) < 0.004 && fabs(p[2] - h[2]) < 0.004 && p[1] < lowest) lowest = p[1];
  }
  print_message("  HIP at %.2f mm, skin under it at %.2f mm\n", h[1] * 1e3, lowest * 1e3);
  assert_true(lowest <= h[1] - rc + 2e-4);
  assert_true(lowest > h[1] - rc - 0.002);
  double f[3];
  tx_cloth_contact_force(c, f);
  // the skin never pulls the HIP (here the cone the cell stretched into holds it on its walls)
  assert_true(f[1] >= 0 && isfinite(f[0]) && isfinite(f[2]));
  tx_cloth_destroy(c);
}

// a skin that never tears holds the HIP: pressed 1.25 cm into the middle of a
// cell (its links stretched to almost five times their length, pulling the
// triangle over the HIP across the sphere within one solve), the skin is still
// under it and pushes back. (The HIP used to get through after 1.1 cm.)
static void untorn_skin_holds_the_hip(void** state) {
  (void)state;
  tx_cloth* c = make(42, 0, 0);
  double h[3] = {0, 0.01, 0};
  for (int s = 0; s <= 300; s++) { // 5 mm/s from 0.5 s: y = -12.5 mm at 5 s
    double t = s / 60.0;
    h[1] = t < 0.5 ? 0.01 : 0.01 - 0.005 * (t - 0.5);
    assert_int_equal(tx_cloth_set_hip(c, h, 0.0005), TX_CLOTH_OK);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    double f[3];
    tx_cloth_contact_force(c, f);
    if (h[1] < -0.003) assert_true(f[1] > 0); // in contact all the way
  }
  assert_int_equal(tx_cloth_torn(c), 0);
  assert_true(h[1] < -0.0124);
  // every particle within 3 mm across of the HIP is below it
  double p[3];
  for (int i = 0; i < tx_cloth_particle_count(c); i++) {
    tx_cloth_particle(c, i, p);
    if (fabs(p[0] - h[0]) < 0.003 && fabs(p[2] - h[2]) < 0.003) assert_true(p[1] < h[1]);
  }
  tx_cloth_destroy(c);
}

// pushed far enough, links break, their triangles leave, and the HIP passes through
static void rupture_opens_a_hole(void** state) {
  (void)state;
  tx_cloth* c = make(42, 0, 20);
  const int total = tx_cloth_triangle_count(c);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * (size_t)total);
  double h[3] = {0.0003, 0.005, 0.0002};
  int torn_at = -1;
  for (int s = 0; s < 600 && torn_at < 0; s++) {
    h[1] = 0.005 - 0.00008 * s; // 4.8 mm/s down
    tx_cloth_set_hip(c, h, 0.0005);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    if (tx_cloth_torn(c) > 0) torn_at = s;
  }
  assert_true(torn_at > 0);
  int live = tx_cloth_triangles(c, tri);
  print_message("  torn at HIP y = %.2f mm: %d links, %d of %d triangles left\n", h[1] * 1e3, tx_cloth_torn(c), live,
                total);
  assert_true(live < total);
  assert_true(live >= total - 8 * tx_cloth_torn(c)); // each torn link takes at most 2 triangles, bending ones none
  // no live triangle uses a torn link: every live triangle's edges are under the limit
  // and the HIP goes on down through the hole, the skin springing back behind it
  for (int s = 0; s < 120; s++) {
    h[1] -= 0.0001;
    tx_cloth_set_hip(c, h, 0.0005);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  }
  // every particle still in the mesh is well above the HIP: it went through a hole
  live = tx_cloth_triangles(c, tri);
  double lowest = 1, p[3];
  for (int k = 0; k < 3 * live; k++) {
    tx_cloth_particle(c, tri[k], p);
    if (p[1] < lowest) lowest = p[1];
  }
  print_message("  HIP at %.2f mm, the lowest particle of the %d live triangles at %.2f mm\n", h[1] * 1e3, live,
                lowest * 1e3);
  assert_true(lowest > h[1] + 0.005);
  double f[3];
  tx_cloth_contact_force(c, f);
  assert_float_equal(f[1], 0, 1e-12); // no contact once through
  free(tri);
  tx_cloth_destroy(c);
}

// step s of the HIP pushing the centre particle up from 4 mm below at 6 mm/s
static tx_cloth_status pull_step(tx_cloth* c, int s) {
  double h[3] = {0.1 / 41 * 21 - 0.05, -0.004 + 0.0001 * s, 0.1 / 41 * 21 - 0.05};
  tx_cloth_set_hip(c, h, 0.0005);
  return tx_cloth_step(c, 1.0 / 60);
}

// the HIP pushing one particle out of the patch: once the membrane tension
// there passes rupture_tension links break, and only the triangles they
// bordered leave
static void overstretched_link_breaks(void** state) {
  (void)state;
  tx_cloth* c = make(42, 0, 20);
  int links = tx_cloth_link_count(c), steps = 0;
  while (tx_cloth_torn(c) == 0 && steps < 300) assert_int_equal(pull_step(c, steps), TX_CLOTH_OK), steps++;
  assert_true(tx_cloth_torn(c) > 0);
  print_message("  membrane tension %.1f N/m at the tear\n", tx_cloth_peak_tension(c));
  assert_true(tx_cloth_peak_tension(c) >= 20); // the tear came from the criterion
  int32_t* tri = malloc(sizeof(int32_t) * 3 * 3362);
  int live = tx_cloth_triangles(c, tri);
  int removed = links - tx_cloth_link_count(c);
  print_message("  after %d steps: %d links torn (%d removed with bending ones), %d of 3362 triangles left\n", steps,
                tx_cloth_torn(c), removed, live);
  assert_true(live < 3362);
  assert_true(3362 - live <= 2 * tx_cloth_torn(c)); // a torn link takes at most two triangles
  assert_true(removed >= tx_cloth_torn(c));         // bending links over a torn one go with it
  free(tri);
  tx_cloth_destroy(c);
}

// a NaN in one particle, or a particle flung at 1 km/s, is found after the
// next substep; the patch goes back to the last good state
static void faults_are_recovered(void** state) {
  (void)state;
  tx_cloth* c = make(42, 9.81, 20);
  for (int s = 0; s < 10; s++) tx_cloth_step(c, 1.0 / 60);
  double before[3], after[3], nan3[3] = {NAN, 0, 0}, zero[3] = {0, 0, 0};
  tx_cloth_particle(c, 100, before);
  int torn = tx_cloth_torn(c);
  assert_true(tx_cloth_poke(c, 100, nan3, zero));
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_FAULT);
  assert_int_equal(tx_cloth_faults(c), 1);
  assert_true(all_finite(c));
  tx_cloth_particle(c, 100, after);
  for (int a = 0; a < 3; a++) assert_float_equal(after[a], before[a], 1e-9);
  assert_int_equal(tx_cloth_torn(c), torn);

  // a blow-up: a particle flung 50 m away tears links on the way, which come back with the state
  double x[3], still[3] = {0, 0, 0};
  tx_cloth_particle(c, centre(c), x);
  x[1] += 50;
  assert_true(tx_cloth_poke(c, centre(c), x, still));
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_FAULT);
  assert_int_equal(tx_cloth_faults(c), 2);
  assert_int_equal(tx_cloth_torn(c), torn);
  assert_true(all_finite(c));
  // and it carries on normally
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  tx_cloth_destroy(c);
}

// a fault in the step that tears puts the links and triangles back; the
// step again without the fault tears (the HIP starts it where the faulty
// step left it, so it is not the same step: see tx_cloth_step)
static void restore_brings_links_back(void** state) {
  (void)state;
  tx_cloth* a = make(42, 0, 20);
  int steps = 0;
  while (tx_cloth_torn(a) == 0 && steps < 300) pull_step(a, steps), steps++;
  assert_true(tx_cloth_torn(a) > 0);

  tx_cloth* b = make(42, 0, 20);
  const int links = tx_cloth_link_count(b);
  for (int s = 0; s < steps - 1; s++) assert_int_equal(pull_step(b, s), TX_CLOTH_OK);
  assert_int_equal(tx_cloth_torn(b), 0);
  double nan3[3] = {NAN, NAN, NAN}, v[3] = {0, 0, 0};
  tx_cloth_poke(b, 5 * 42 + 5, nan3, v);
  assert_int_equal(pull_step(b, steps - 1), TX_CLOTH_FAULT);
  assert_int_equal(tx_cloth_torn(b), 0);
  assert_int_equal(tx_cloth_link_count(b), links);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * 3362);
  assert_int_equal(tx_cloth_triangles(b, tri), 3362);
  assert_int_equal(pull_step(b, steps - 1), TX_CLOTH_OK);
  assert_true(tx_cloth_torn(b) > 0);
  double pa[3], pb[3];
  tx_cloth_particle(a, 7 * 42 + 9, pa);
  tx_cloth_particle(b, 7 * 42 + 9, pb);
  for (int k = 0; k < 3; k++) assert_float_equal(pa[k], pb[k], 1e-4);
  free(tri);
  tx_cloth_destroy(a);
  tx_cloth_destroy(b);
}

// every field of the definition is checked; NaN, Inf and out-of-range values are refused
static void bad_definitions_are_refused(void** state) {
  (void)state;
  tx_cloth_def d = tx_cloth_def_default();
  assert_int_equal(tx_cloth_def_check(&d), 0);
  double* fields[] = {&d.size[0],         &d.size[1],      &d.center[0], &d.center[1],       &d.center[2],
                      &d.thickness,       &d.mass,         &d.stretch_stiffness, &d.bend_stiffness, &d.damping,
                      &d.gravity,         &d.rupture_tension, &d.max_substep, &d.max_speed,   &d.settle_time,
                      &d.clamp_radius,    &d.pretension,   &d.rupture_length};
  const double bad[] = {NAN, INFINITY, -INFINITY, -1, 1e12};
  for (size_t f = 0; f < sizeof fields / sizeof fields[0]; f++)
    for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++) {
      tx_cloth_def e = tx_cloth_def_default();
      double* field = (double*)((char*)&e + ((char*)fields[f] - (char*)&d));
      *field = bad[b];
      if (bad[b] == -1 && (field == &e.center[0] || field == &e.center[1] || field == &e.center[2])) continue;
      if (tx_cloth_def_check(&e) == 0) fail_msg("field %zu = %g passed", f, bad[b]);
      assert_non_null(strstr(tx_error(), "skin: "));
      assert_null(tx_cloth_create(&e));
    }
  int* counts[] = {&d.res[0], &d.res[1], &d.iterations};
  const int bad_counts[] = {0, 1, -5, 100000};
  for (size_t f = 0; f < 3; f++)
    for (size_t b = 0; b < 4; b++) {
      tx_cloth_def e = tx_cloth_def_default();
      *(int*)((char*)&e + ((char*)counts[f] - (char*)&d)) = bad_counts[b];
      if (f == 2 && bad_counts[b] == 1) continue; // one iteration is allowed
      assert_int_equal(tx_cloth_def_check(&e), -1);
    }
  // bad step and HIP arguments change nothing
  tx_cloth* c = make(42, 0, 20);
  double h[3] = {NAN, 0, 0}, ok[3] = {0, 0.01, 0};
  assert_int_equal(tx_cloth_set_hip(c, h, 0.0005), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_hip(c, ok, -1), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_hip(c, ok, NAN), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_step(c, NAN), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_step(c, 0), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_step(c, 2), TX_CLOTH_BAD);
  assert_true(strstr(tx_error(), "dt") != NULL);
  assert_true(all_finite(c));
  tx_cloth_destroy(c);
}

// the derivation of docs/skin.md: under a pretension T every stretch link
// of spacing s carries k s T / K and every diagonal k s sqrt(2) T / K
// (K = 3 k + 4 k_bend), and the membrane tension the rupture check sees is
// T, at both densities; the flat patch stays flat
static void pretension_is_the_membrane_tension(void** state) {
  (void)state;
  for (int res = 21; res <= 41; res += 20) {
    tx_cloth_def d = tx_cloth_def_default();
    d.res[0] = d.res[1] = res;
    d.pretension = 100;
    d.rupture_tension = 0;
    d.rupture_length = 0.01; // two spacings or more at both densities
    d.max_substep = 2e-5; // converged: k w h^2 under 0.1
    d.iterations = 8;
    tx_cloth* c = tx_cloth_create(&d);
    assert_non_null(c);
    assert_int_equal(tx_cloth_step(c, 1e-3), TX_CLOTH_OK);
    const double s = 0.1 / (res - 1), K = 3 * d.stretch_stiffness + 4 * d.bend_stiffness;
    const int mid = (res / 2) * res + res / 2;
    int seen = 0;
    for (int id = 0; id < tx_cloth_link_total(c); id++) {
      int32_t e[2];
      assert_true(tx_cloth_link_ends(c, id, e));
      if (e[0] != mid && e[1] != mid) continue;
      int gap = abs(e[1] - e[0]);
      double want = gap == 1 || gap == res ? d.stretch_stiffness * s * 100 / K
                  : gap == 2 || gap == 2 * res ? d.bend_stiffness * 2 * s * 100 / K
                                               : d.stretch_stiffness * s * sqrt(2) * 100 / K;
      assert_float_equal(tx_cloth_link_tension(c, id), want, 0.01 * want);
      seen++;
    }
    assert_int_equal(seen, 12);
    double t = tx_cloth_membrane_tension(c, mid), p[3];
    print_message("  %d x %d: membrane tension %.2f N/m for T = 100 N/m\n", res, res, t);
    assert_float_equal(t, 100, 1);
    tx_cloth_particle(c, mid, p);
    assert_float_equal(p[1], 0, 1e-7);
    int32_t e[2];
    assert_false(tx_cloth_link_ends(c, -1, e));
    assert_false(tx_cloth_link_ends(c, tx_cloth_link_total(c), e));
    assert_true(isnan(tx_cloth_membrane_tension(c, -1)));
    tx_cloth_destroy(c);
  }
  // a pretension of half the biaxial modulus or more is refused
  tx_cloth_def d = tx_cloth_def_default();
  d.pretension = 0.5 * (3 * d.stretch_stiffness + 4 * d.bend_stiffness) * 1.01;
  assert_int_equal(tx_cloth_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "pretension"));
}

// a load pushes its particle; a bad index or force is refused and changes
// nothing; the clamp radius holds every particle beyond it
static void loads_and_the_circular_clamp(void** state) {
  (void)state;
  tx_cloth_def d = tx_cloth_def_default();
  d.res[0] = d.res[1] = 21;
  d.clamp_radius = 0.03;
  d.rupture_tension = 0;
  tx_cloth* c = tx_cloth_create(&d);
  assert_non_null(c);
  const int mid = 10 * 21 + 10;
  double f[3] = {0, -0.05, 0}, bad[3] = {NAN, 0, 0}, huge[3] = {0, 2e6, 0};
  assert_int_equal(tx_cloth_set_load(c, mid, f), TX_CLOTH_OK);
  assert_int_equal(tx_cloth_set_load(c, -1, f), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_load(c, 21 * 21, f), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_load(c, mid, bad), TX_CLOTH_BAD);
  assert_non_null(strstr(tx_error(), "load"));
  assert_int_equal(tx_cloth_set_load(c, mid, huge), TX_CLOTH_BAD);
  for (int s = 0; s < 60; s++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  double p[3], q[3];
  tx_cloth_particle(c, mid, p);
  assert_true(p[1] < -0.001); // pushed down by the load
  // (3, 10) is 3.5 cm from the centre: clamped; (5, 10) at 2.5 cm is free and follows
  tx_cloth_particle(c, 10 * 21 + 3, q);
  assert_float_equal(q[1], 0, 1e-9);
  tx_cloth_particle(c, 10 * 21 + 5, q);
  assert_true(q[1] < -1e-5);
  // the load removed, the patch springs back
  double zero[3] = {0, 0, 0};
  assert_int_equal(tx_cloth_set_load(c, mid, zero), TX_CLOTH_OK);
  for (int s = 0; s < 120; s++) tx_cloth_step(c, 1.0 / 60);
  tx_cloth_particle(c, mid, q);
  assert_true(q[1] > 0.5 * p[1]);
  tx_cloth_destroy(c);
}

// a spring settles where the load it stands for does: a load F pushes the
// centre down to x_l; a zero-length spring of k to x_l + F / k pulls with F
// exactly there, so its equilibrium (the implicit solve with the spring's
// energy and Hessian) is the same point. Bad springs are refused.
static void a_spring_settles_where_its_load_does(void** state) {
  (void)state;
  tx_cloth_def d = tx_cloth_def_default();
  d.res[0] = d.res[1] = 21;
  d.rupture_tension = 0;
  const int mid = 10 * 21 + 10;
  const double f[3] = {0, -0.05, 0}, k = 50;
  tx_cloth* c = tx_cloth_create(&d);
  assert_non_null(c);
  assert_int_equal(tx_cloth_set_load(c, mid, f), TX_CLOTH_OK);
  for (int s = 0; s < 90; s++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  double xl[3], xs[3], a[3];
  tx_cloth_particle(c, mid, xl);
  tx_cloth_destroy(c);
  c = tx_cloth_create(&d);
  for (int e = 0; e < 3; e++) a[e] = xl[e] + f[e] / k;
  assert_int_equal(tx_cloth_set_spring(c, mid, a, k), TX_CLOTH_OK);
  for (int s = 0; s < 90; s++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  tx_cloth_particle(c, mid, xs);
  print_message("the centre under a 0.05 N load: %.4f mm; under the spring standing for it: %.4f mm\n", xl[1] * 1e3,
                xs[1] * 1e3);
  assert_true(xl[1] < -0.001);
  assert_float_equal(xs[1], xl[1], 0.01 * fabs(xl[1]));
  const double nan3[3] = {NAN, 0, 0};
  assert_int_equal(tx_cloth_set_spring(c, -1, a, k), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_spring(c, 21 * 21, a, k), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_spring(c, mid, a, -1), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_spring(c, mid, a, 2e9), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_set_spring(c, mid, nan3, k), TX_CLOTH_BAD);
  assert_non_null(strstr(tx_error(), "spring"));
  tx_cloth_destroy(c);
}

// stepping, with contact, rupture and a recovered fault, allocates nothing
static void steps_never_allocate(void** state) {
  (void)state;
#ifdef TX_NO_ALLOC_COUNT
  (void)counting;
  (void)allocations;
  skip();
#else
  tx_cloth* c = make(42, 9.81, 20);
  float* x = malloc(sizeof(float) * 3 * 1764);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * 3362);
  double h[3] = {0, 0.005, 0};
  tx_cloth_set_hip(c, h, 0.0005);
  tx_cloth_step(c, 1.0 / 60); // Bullet's node tree settles its spare nodes here
  allocations = 0;
  counting = 1;
  for (int s = 0; s < 600; s++) {
    h[1] = 0.005 - 0.0001 * s;
    tx_cloth_set_hip(c, h, 0.0005);
    tx_cloth_step(c, 1.0 / 60);
    tx_cloth_positions(c, x);
    tx_cloth_triangles(c, tri);
  }
  double nan3[3] = {NAN, 0, 0}, zero[3] = {0, 0, 0};
  tx_cloth_poke(c, 50, nan3, zero);
  tx_cloth_step(c, 1.0 / 60);
  counting = 0;
  assert_true(tx_cloth_torn(c) > 0);
  assert_int_equal(tx_cloth_faults(c), 1);
  assert_int_equal(allocations, 0);
  free(x);
  free(tri);
  tx_cloth_destroy(c);
#endif
}

// the implicit skin is unconditionally stable: links 5 x 10^5 times stiffer
// (1e9 N/m, the largest allowed) than the default, pierced 1 cm, never fault,
// stay finite and push back
static void implicit_is_stable_when_stiff(void** state) {
  (void)state;
  tx_cloth_def d = tx_cloth_def_default();
  d.stretch_stiffness = 1e9;
  d.bend_stiffness = 1e7;
  d.rupture_tension = 0;
  tx_cloth* c = tx_cloth_create(&d);
  assert_non_null(c);
  double h[3] = {0.001, 0.003, 0.0007}, f[3] = {0, 0, 0};
  const int steps = SANITIZED ? 40 : 150;
  for (int s = 0; s < steps; s++) {
    h[1] = 0.003 - 0.013 * s / steps; // from above the skin to 1 cm into it
    tx_cloth_set_hip(c, h, 0.0005);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    tx_cloth_contact_force(c, f);
    assert_true(isfinite(f[0]) && isfinite(f[1]) && isfinite(f[2]));
  }
  assert_int_equal(tx_cloth_faults(c), 0);
  assert_true(all_finite(c));
  print_message("  k = 1e9 N/m: %.1f N at HIP y = %.1f mm\n", f[1], h[1] * 1e3);
  assert_true(f[1] > 0);
  tx_cloth_destroy(c);
}

// where the skin tore, between steps: the step that tears reports the HIP
// centre where the rupture criterion was met, linear in the peak tension
// between the last check before the tear and the tear's (with one substep a
// step, the two steps' peaks); the steps before report none
static void rupture_is_located_between_steps(void** state) {
  (void)state;
  const double tc = 20;
  tx_cloth* c = make(42, 0, tc);
  double h[3] = {0.0003, 0.005, 0.0002}, at[3], prev_peak = 0, prev_y = h[1];
  bool torn = false;
  for (int s = 0; s < 600 && !torn; s++) {
    h[1] = 0.005 - 0.00008 * s;
    tx_cloth_set_hip(c, h, 0.0005);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    const double peak = tx_cloth_peak_tension(c);
    torn = tx_cloth_torn(c) > 0;
    assert_int_equal(tx_cloth_broke_at(c, at), torn);
    if (torn) {
      assert_true(prev_peak < tc && peak >= tc);
      const double u = (tc - prev_peak) / (peak - prev_peak), want = prev_y + u * (h[1] - prev_y);
      print_message("  torn between HIP y = %.4f and %.4f mm (%.1f, %.1f N/m): at %.4f mm\n", prev_y * 1e3, h[1] * 1e3,
                    prev_peak, peak, at[1] * 1e3);
      assert_true(at[1] <= prev_y && at[1] >= h[1]);
      assert_float_equal(at[1], want, 1e-9);
      assert_float_equal(at[0], h[0], 1e-9);
      assert_float_equal(at[2], h[2], 1e-9);
    } else
      assert_true(at[0] == 0 && at[1] == 0 && at[2] == 0);
    prev_peak = peak;
    prev_y = h[1];
  }
  assert_true(torn);
  // the next step tears no more or tears on; either way it reports only its own
  h[1] -= 0.00008;
  tx_cloth_set_hip(c, h, 0.0005);
  int before = tx_cloth_torn(c);
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  assert_int_equal(tx_cloth_broke_at(c, at), tx_cloth_torn(c) > before);
  tx_cloth_destroy(c);
}

// a skin that never tears is never passed: pressed 3 cm down at 1 cm/s over
// a cell's middle and over a particle, every particle under the HIP's
// cross-section stays below it and the force keeps growing (to 1 cm at every
// step; to 3 cm above half its largest: over a particle the skin wraps the
// sphere past 2.6 cm, and the force is the links' whole reaction there)
static void untorn_skin_holds_to_3cm(void** state) {
  (void)state;
  const double at[2][2] = {{0, 0}, {0.00125, 0.00125}}; // the default 42 x 42: a cell's middle, a particle
  for (int k = 0; k < 2; k++) {
    tx_cloth* c = make(42, 0, 0);
    double h[3] = {at[k][0], 0.0026, at[k][1]}, f[3], last = 0, most = 0;
    int s = 0;
    const double bottom = SANITIZED ? -0.006 : -0.03;
    for (; h[1] > bottom; s++) {
      h[1] = 0.0026 - 0.01 * s / 60.0;
      assert_int_equal(tx_cloth_set_hip(c, h, 0.0005), TX_CLOTH_OK);
      assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
      tx_cloth_contact_force(c, f);
      if (h[1] < -0.001) {
        // it grows at every step to 1 cm; beyond, with the links several times their length,
        // the skin wraps the sphere, the particles the contact holds change, and the force
        // jumps by up to a third when one lets go (docs/skin.md)
        const double keep = h[1] > -0.01 ? 0.99 * last : 0.5 * most;
        if (!(f[1] >= keep && f[1] > 0))
          fail_msg("HIP at %.2f mm: force %.4f N after %.4f N", h[1] * 1e3, f[1], most);
        last = f[1];
        most = fmax(most, f[1]);
      }
    }
    double p[3];
    for (int i = 0; i < tx_cloth_particle_count(c); i++) {
      tx_cloth_particle(c, i, p);
      double dx = p[0] - h[0], dz = p[2] - h[2];
      if (dx * dx + dz * dz < 0.003 * 0.003 && !(p[1] < h[1])) fail_msg("particle %d at %.2f mm, above the HIP", i, p[1] * 1e3);
    }
    print_message("  HIP over %s, %.1f cm down: %.2f N, the skin still under it\n", k ? "a particle" : "a cell's middle",
                  -bottom * 100, last);
    assert_int_equal(tx_cloth_torn(c), 0);
    tx_cloth_destroy(c);
  }
}

// a HIP pressed into the implicit skin at the study's 1 cm/s and then held
// still a second rests on it: no link tears and the force is steady. The face
// contact leaves the skin's corners just beyond its 1 % touch test, so a
// contact found afresh each substep let the free solve carry the tensed skin
// up through the stopped HIP and the contact throw it back: stopped 5 mm in
// it tore 8 links in the first stopped step, stopped 2.5 mm in the force
// flipped between 11 and 136 mN every step
static void stopped_hip_rests_in_the_skin(void** state) {
  (void)state;
  const double depths[2] = {0.0025, 0.005};
  for (int k = 0; k < 2; k++) {
    tx_cloth_def d = tx_cloth_def_default();
    d.res[0] = d.res[1] = 41;
    d.size[0] = d.size[1] = 0.1;
    d.rupture_tension = 150;
    d.rupture_length = 0.01;
    tx_cloth* c = tx_cloth_create(&d);
    if (!c) fail_msg("%s", tx_error());
    double pos[3] = {0, 0.003, 0}, f[3], moving = 0;
    for (; pos[1] > -depths[k]; pos[1] -= 0.01 / 60) {
      tx_cloth_set_hip(c, pos, 0.0005);
      assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
      tx_cloth_contact_force(c, f);
      moving = f[1];
    }
    const int torn = tx_cloth_torn(c);
    double lo = 1e9, hi = 0, prev = NAN, flip = 0;
    for (int s = 0; s < 60; s++) {
      assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
      tx_cloth_contact_force(c, f);
      if (s > 0) flip = fmax(flip, fabs(f[1] - prev) / fmax(fabs(prev), 1e-6)); // between stopped steps
      prev = f[1];
      lo = fmin(lo, f[1]), hi = fmax(hi, f[1]);
    }
    print_message("  stopped %.1f mm in: %.1f mN pressing, %.1f to %.1f mN at rest (largest step-to-step change %.1f %%), "
                  "%d links torn pressing, %d at rest\n",
                  depths[k] * 1e3, moving * 1e3, lo * 1e3, hi * 1e3, flip * 100, torn, tx_cloth_torn(c) - torn);
    assert_int_equal(tx_cloth_torn(c), 0);
    assert_true(lo > 0.005);
    assert_true(flip < 0.05);
    assert_true(hi - lo < 0.05 * hi);
    assert_true(all_finite(c));
    tx_cloth_destroy(c);
  }
}

// From the tear on, the skin does not push a HIP that pierced it (the papers'
// force goes back to zero at rupture; collision.hip's "Pierced"): the default
// skin and its balance reading, a HIP driven through it straight down at
// 1 and 5 cm/s and obliquely (a needle's tip): at the tear's step and every
// step of the 200 ms after it, the force on the HIP along its travel is
// under 10 mN (the torn flaps closing on it pushed it with up to 1.7 N in the
// two steps after the tear; here, before the pierce, 0.29 N at 1 cm/s, the
// skin still pressing the HIP after its first link tore)
static void pierced_hip_is_not_pushed(void** state) {
  (void)state;
  const double vel[4][3] = {{0, -0.01, 0}, {0, -0.05, 0}, {0.004, -0.005, 0}, {0.02, -0.03, 0.005}};
  for (int k = 0; k < 4; k++) {
    tx_cloth_def d = tx_cloth_def_default();
    tx_cloth* c = tx_cloth_create(&d);
    if (!c) fail_msg("%s", tx_error());
    const double v = sqrt(vel[k][0] * vel[k][0] + vel[k][1] * vel[k][1] + vel[k][2] * vel[k][2]);
    double h[3] = {0.0003, 0.003, 0.0002}, f[3], worst = 0, before = 0;
    int tear = -1, worst_at = -1;
    for (int s = 0; s < 600 && (tear < 0 || s <= tear + 12); s++) {
      for (int a = 0; a < 3; a++) h[a] += vel[k][a] / 60;
      tx_cloth_set_hip(c, h, 0.0005);
      assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
      tx_cloth_contact_force(c, f);
      const double along = -(f[0] * vel[k][0] + f[1] * vel[k][1] + f[2] * vel[k][2]) / v;
      if (tear < 0 && tx_cloth_torn(c) > 0) tear = s;
      if (tear < 0) before = fmax(before, along);
      else if (fabs(along) > worst) worst = fabs(along), worst_at = s - tear;
    }
    print_message("  HIP at (%.0f, %.0f, %.0f) mm/s: %.3f N before the tear, from it on at most %.4f N%s\n",
                  vel[k][0] * 1e3, vel[k][1] * 1e3, vel[k][2] * 1e3, before, worst, worst_at >= 0 ? "" : " (0 every step)");
    assert_true(tear > 0);
    assert_true(before > 0.1); // it did push the skin until the tear
    assert_true(worst < 0.01);
    assert_int_equal(tx_cloth_pierces(c), 1);
    tx_cloth_destroy(c);
  }
}

// A piece cut off from the patch is freed: jaws take a 3 x 3 block of
// particles and lift it until the skin tears around it, then let go. The
// block, held only by the jaws, is then cut off: it leaves the solve (it no
// longer moves, it has no links), the contact and the mesh (no live triangle
// has a corner in it), its particles keep their indices, and every live
// triangle still names particles of the patch, which stays where it is
static void detached_piece_is_freed(void** state) {
  (void)state;
  tx_cloth* c = make(42, 0, 80);
  const int n = tx_cloth_particle_count(c), total = tx_cloth_triangle_count(c), mid = centre(c);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * (size_t)total);
  int block[9], nb = 0;
  for (int dz = -1; dz <= 1; dz++)
    for (int dx = -1; dx <= 1; dx++) block[nb++] = mid + dz * 42 + dx;
  double x0[9][3];
  for (int k = 0; k < 9; k++) tx_cloth_particle(c, block[k], x0[k]);
  int s = 0;
  for (; s < 180; s++) { // up at 6 cm/s until the block is held by the jaws alone
    for (int k = 0; k < 9; k++) {
      double x[3] = {x0[k][0], x0[k][1] + 0.001 * (s + 1), x0[k][2]};
      assert_int_equal(tx_cloth_pin(c, block[k], x), TX_CLOTH_OK);
    }
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    assert_int_equal(tx_cloth_freed_count(c), 0); // the jaws hold it: not cut off
    double at[3];
    assert_false(tx_cloth_broke_at(c, at)); // torn by the pull, nowhere near a HIP: no HIP place to report
    if (x0[0][1] + 0.001 * (s + 1) > 0.03) break;
  }
  const int torn = tx_cloth_torn(c);
  print_message("  lifted 3 cm: %d links torn\n", torn);
  assert_true(torn > 0);
  assert_int_equal(tx_cloth_torn_pulled(c), torn);
  for (int k = 0; k < 9; k++) assert_true(tx_cloth_unpin(c, block[k]));
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  const int freed = tx_cloth_freed_count(c);
  print_message("  let go: %d particles in %d piece(s) freed, %d links left\n", freed, tx_cloth_pieces_freed(c),
                tx_cloth_link_count(c));
  assert_true(freed >= 9);
  assert_true(tx_cloth_pieces_freed(c) >= 1);
  for (int k = 0; k < 9; k++) assert_true(tx_cloth_freed(c, block[k]));
  assert_false(tx_cloth_freed(c, 0));
  assert_false(tx_cloth_freed(c, -1));
  assert_false(tx_cloth_freed(c, n));
  double before[9][3], p[3];
  for (int k = 0; k < 9; k++) tx_cloth_particle(c, block[k], before[k]);
  assert_int_equal(tx_cloth_pin(c, block[0], before[0]), TX_CLOTH_BAD); // not the skin's any more
  for (int t = 0; t < 30; t++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  for (int k = 0; k < 9; k++) { // frozen where it was cut off: it falls into nothing
    tx_cloth_particle(c, block[k], p);
    for (int a = 0; a < 3; a++) assert_float_equal(p[a], before[k][a], 0);
  }
  assert_int_equal(tx_cloth_freed_count(c), freed);
  const int live = tx_cloth_triangles(c, tri);
  for (int k = 0; k < 3 * live; k++) {
    assert_true(tri[k] >= 0 && tri[k] < n);
    assert_false(tx_cloth_freed(c, tri[k]));
  }
  for (int id = 0; id < tx_cloth_link_total(c); id++) { // no live link reaches a freed particle
    int32_t e[2];
    assert_true(tx_cloth_link_ends(c, id, e));
    if (tx_cloth_freed(c, e[0]) || tx_cloth_freed(c, e[1])) assert_float_equal(tx_cloth_link_tension(c, id), 0, 0);
  }
  // the patch left behind settles flat, every particle of its mesh back near the plane
  double lowest = 1, highest = -1;
  for (int k = 0; k < 3 * live; k++) {
    tx_cloth_particle(c, tri[k], p);
    lowest = fmin(lowest, p[1]), highest = fmax(highest, p[1]);
  }
  print_message("  the patch's mesh: %d triangles, y from %.2f to %.2f mm\n", live, lowest * 1e3, highest * 1e3);
  assert_true(all_finite(c));
  free(tri);
  tx_cloth_destroy(c);
}

#if !SANITIZED // the converged solves take some 20 s under the sanitizers
// the force read as the patch's momentum balance is the fixed border's
// reaction, the quasi-static force that holds the patch (sum of k (l - l0)
// along every link to the border, read here from the links apart from the
// reading): 41 x 41, 10 cm, pressed over a particle at 1 cm/s to 5 mm, at
// the real-time settings (two Newton steps, CG to 1e-2) and converged (20,
// 1e-7). The held particles' own imbalance reads some 9 % more, converged or
// not (printed, docs/validation.md)
static double pressed_force(int reading, int newton, double cg_tol, double* border) {
  tx_cloth_def d = tx_cloth_def_default();
  const int res = 41;
  d.res[0] = d.res[1] = res;
  d.size[0] = d.size[1] = 0.1;
  d.rupture_tension = 150;
  d.rupture_length = 0.01;
  d.reading = reading;
  d.newton_steps = newton;
  d.cg_tolerance = cg_tol;
  d.cg_iterations = 5000;
  tx_cloth* c = tx_cloth_create(&d);
  if (!c) fail_msg("%s", tx_error());
  double pos[3] = {0, 0.003, 0}, f[3] = {0, 0, 0};
  for (; pos[1] > 0.0025 - 0.005; pos[1] -= 0.01 / 60) {
    tx_cloth_set_hip(c, pos, 0.0005);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    tx_cloth_contact_force(c, f);
  }
  assert_int_equal(tx_cloth_torn(c), 0);
  *border = 0;
  for (int l = 0; l < tx_cloth_link_total(c); l++) {
    int32_t e[2];
    assert_true(tx_cloth_link_ends(c, l, e));
    bool fixed[2];
    for (int k = 0; k < 2; k++) {
      const int ix = e[k] % res, iz = e[k] / res;
      fixed[k] = ix == 0 || iz == 0 || ix == res - 1 || iz == res - 1;
    }
    if (fixed[0] == fixed[1]) continue;
    double a[3], b[3];
    tx_cloth_particle(c, e[fixed[0] ? 0 : 1], a); // the border's end
    tx_cloth_particle(c, e[fixed[0] ? 1 : 0], b);
    const double len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    *border -= tx_cloth_link_tension(c, l) * (b[1] - a[1]) / len; // the link pulls the border down; the HIP pushes down
  }
  tx_cloth_destroy(c);
  return f[1];
}

static void balance_reads_the_converged_force(void** state) {
  (void)state;
  double bb, hb, rb, rh;
  const double bal = pressed_force(TX_CLOTH_BALANCE, 2, 1e-2, &bb), held = pressed_force(TX_CLOTH_HELD, 2, 1e-2, &hb);
  const double ref = pressed_force(TX_CLOTH_BALANCE, 20, 1e-7, &rb), ref_held = pressed_force(TX_CLOTH_HELD, 20, 1e-7, &rh);
  print_message("  at 5 mm, real time: balance %.1f mN, held %.1f mN, the border %.1f mN; converged: balance %.1f mN, "
                "held %.1f mN, the border %.1f mN\n",
                bal * 1e3, held * 1e3, bb * 1e3, ref * 1e3, ref_held * 1e3, rb * 1e3);
  assert_true(fabs(bal - bb) < 0.01 * bb); // the border's reaction, to 1 %
  assert_true(fabs(ref - rb) < 0.01 * rb);
  assert_true(fabs(bal - ref) < 0.02 * ref); // the real-time reading is the converged one
}
#endif

// the two-level preconditioner (coarse_block) solves the same system in fewer
// CG iterations, before and after the skin tears (its coarse matrix is built
// from the links there are): 41 x 41, 10 cm, pressed over a particle at 1 cm/s
// to 5 mm, then on through the tear at some 10 mm
static void press_through(int coarse, double* f5, int* cg, int* torn) {
  tx_cloth_def d = tx_cloth_def_default();
  d.res[0] = d.res[1] = 41;
  d.size[0] = d.size[1] = 0.1;
  d.rupture_tension = 150;
  d.rupture_length = 0.01;
  d.coarse_block = coarse;
  tx_cloth* c = tx_cloth_create(&d);
  if (!c) fail_msg("%s", tx_error());
  double pos[3] = {0, 0.003, 0}, f[3];
  *cg = 0;
  *f5 = NAN;
  for (int s = 0; pos[1] > 0.0025 - 0.013; s++, pos[1] -= 0.01 / 60) {
    tx_cloth_set_hip(c, pos, 0.0005);
    assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
    tx_cloth_solve_info si;
    tx_cloth_solve_stats(c, &si);
    *cg += si.cg_iterations;
    tx_cloth_contact_force(c, f);
    if (isnan(*f5) && pos[1] <= 0.0025 - 0.005) *f5 = f[1];
  }
  *torn = tx_cloth_torn(c);
  assert_true(all_finite(c));
  tx_cloth_destroy(c);
}

static void two_level_preconditioner(void** state) {
  (void)state;
  double f0, f4;
  int cg0, cg4, t0, t4;
  press_through(0, &f0, &cg0, &t0);
  press_through(4, &f4, &cg4, &t4);
  print_message("  block Jacobi: %d CG iterations, %.1f mN at 5 mm, %d torn; two-level (4 x 4 blocks): %d, %.1f mN, %d torn\n",
                cg0, f0 * 1e3, t0, cg4, f4 * 1e3, t4);
  assert_true(fabs(f4 - f0) < 0.01 * f0);
  assert_true(t0 > 0 && t4 > 0);
  assert_true(cg4 < 0.6 * cg0);
  tx_cloth_def d = tx_cloth_def_default();
  d.coarse_block = 1;
  assert_int_equal(tx_cloth_def_check(&d), -1);
}

// the faults, restore, rupture and allocation tests again with the XPBD solver
#if !SANITIZED
static int use_xpbd(void** state) {
  (void)state;
  solver = TX_CLOTH_XPBD;
  return 0;
}
static int use_implicit(void** state) {
  (void)state;
  solver = TX_CLOTH_IMPLICIT;
  return 0;
}
#endif

// a pinned particle goes where it is put, in a straight line across the
// step's substeps, its neighbours follow part way; unpinned it falls back
// with the rest. Bad pins are refused, and a fault keeps the pin
static void pinned_particles_follow(void** state) {
  (void)state;
  tx_cloth* c = make(22, 0, 0);
  const int i = centre(c);
  double x0[3], x[3], nb[3], bad[3] = {0, NAN, 0};
  tx_cloth_particle(c, i, x0);
  assert_int_equal(tx_cloth_pin(c, -1, x0), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_pin(c, i, bad), TX_CLOTH_BAD);
  assert_int_equal(tx_cloth_pin(c, 0, x0), TX_CLOTH_BAD); // a border corner: fixed
  assert_non_null(strstr(tx_error(), "fixed"));
  assert_false(tx_cloth_unpin(c, i)); // not pinned
  double up[3] = {x0[0], x0[1] + 0.004, x0[2]};
  assert_int_equal(tx_cloth_pin(c, i, up), TX_CLOTH_OK);
  assert_int_equal(tx_cloth_pinned(c), 1);
  for (int s = 0; s < 30; s++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  tx_cloth_particle(c, i, x);
  tx_cloth_particle(c, i + 1, nb);
  for (int a = 0; a < 3; a++) assert_float_equal(x[a], up[a], 1e-9);
  assert_true(nb[1] > 0.0005 && nb[1] < 0.004); // the tent
  // a fault restores the last good state; the pin holds on
  double far[3] = {nb[0], nb[1] + 50, nb[2]}, still[3] = {0, 0, 0};
  assert_true(tx_cloth_poke(c, i + 1, far, still));
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_FAULT);
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  tx_cloth_particle(c, i, x);
  for (int a = 0; a < 3; a++) assert_float_equal(x[a], up[a], 1e-9);
  assert_true(tx_cloth_unpin(c, i));
  assert_int_equal(tx_cloth_pinned(c), 0);
  for (int s = 0; s < 180; s++) tx_cloth_step(c, 1.0 / 60);
  tx_cloth_particle(c, i, x);
  assert_true(fabs(x[1] - x0[1]) < 0.0005);
  assert_true(all_finite(c));
  tx_cloth_destroy(c);
}

// a particle removed (boiled away): its 12 links go (4 stretch, 4 shear, 4
// bending for an inner one, the bending links across it with them), its 8
// triangles leave the mesh, nothing counts as torn, it is frozen; the patch
// steps on, finite, and the removal survives a fault's restore
static void removed_particle_leaves_a_hole(void** state) {
  (void)state;
  tx_cloth* c = make(11, 0, 0);
  const int i = centre(c), links = tx_cloth_link_count(c), tris = tx_cloth_triangle_count(c);
  int32_t* tri = malloc(sizeof(int32_t) * 3 * (size_t)tris);
  int gone = tx_cloth_remove_particle(c, i);
  // 4 stretch, 4 shear, 4 bending at i, and the bending links through i (2 along x, 2 along z, centred on i)
  print_message("  removed %d links, %d triangles left of %d\n", gone, tx_cloth_triangles(c, tri), tris);
  assert_int_equal(gone, 4 + 4 + 4 + 2);
  assert_int_equal(tx_cloth_link_count(c), links - gone);
  int m = tx_cloth_triangles(c, tri);
  assert_int_equal(m, tris - 8); // the 2 x 2 cells around it, two triangles each
  for (int t = 0; t < 3 * m; t++) assert_true(tri[t] != i);
  assert_int_equal(tx_cloth_torn(c), 0);
  assert_true(tx_cloth_freed(c, i));
  assert_int_equal(tx_cloth_pieces_freed(c), 0);
  assert_int_equal(tx_cloth_remove_particle(c, i), 0); // once only
  assert_int_equal(tx_cloth_remove_particle(c, -1), 0);
  assert_int_equal(tx_cloth_remove_particle(c, 11 * 11), 0);
  for (int k = 0; k < 30; k++) assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_OK);
  assert_true(all_finite(c));
  assert_int_equal(tx_cloth_triangles(c, tri), tris - 8);
  // a fault goes back to the patch without it
  tx_cloth_poke(c, i + 2, (double[3]){NAN, 0, 0}, (double[3]){0, 0, 0});
  assert_int_equal(tx_cloth_step(c, 1.0 / 60), TX_CLOTH_FAULT);
  assert_int_equal(tx_cloth_link_count(c), links - gone);
  assert_int_equal(tx_cloth_triangles(c, tri), tris - 8);
  assert_true(all_finite(c));
  free(tri);
  tx_cloth_destroy(c);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(counts_match_the_papers),
      cmocka_unit_test(hanging_patch_sags_and_settles),
      cmocka_unit_test(hip_cannot_slip_between_particles),
      cmocka_unit_test(untorn_skin_holds_the_hip),
      cmocka_unit_test(rupture_opens_a_hole),
      cmocka_unit_test(overstretched_link_breaks),
      cmocka_unit_test(faults_are_recovered),
      cmocka_unit_test(restore_brings_links_back),
      cmocka_unit_test(bad_definitions_are_refused),
      cmocka_unit_test(pretension_is_the_membrane_tension),
      cmocka_unit_test(loads_and_the_circular_clamp),
      cmocka_unit_test(a_spring_settles_where_its_load_does),
      cmocka_unit_test(steps_never_allocate),
      cmocka_unit_test(implicit_is_stable_when_stiff),
      cmocka_unit_test(untorn_skin_holds_to_3cm),
      cmocka_unit_test(rupture_is_located_between_steps),
      cmocka_unit_test(pinned_particles_follow),
      cmocka_unit_test(stopped_hip_rests_in_the_skin),
      cmocka_unit_test(two_level_preconditioner),
      cmocka_unit_test(pierced_hip_is_not_pushed),
      cmocka_unit_test(detached_piece_is_freed),
      cmocka_unit_test(removed_particle_leaves_a_hole),
#if !SANITIZED
      cmocka_unit_test(balance_reads_the_converged_force), // the same code paths as above, but for the links' solve; minutes under the sanitizers
      cmocka_unit_test_setup_teardown(pinned_particles_follow, use_xpbd, use_implicit),
      cmocka_unit_test_setup_teardown(rupture_opens_a_hole, use_xpbd, use_implicit),
      cmocka_unit_test_setup_teardown(faults_are_recovered, use_xpbd, use_implicit),
      cmocka_unit_test_setup_teardown(restore_brings_links_back, use_xpbd, use_implicit),
      cmocka_unit_test_setup_teardown(steps_never_allocate, use_xpbd, use_implicit),
#endif
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
